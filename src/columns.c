/* src/columns.c: the result table's column layout (columns.h): built once
 * from the model's outputs, then used to name, size and fill the rows. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "columns.h"

void columns_free(column_layout *cl)
{
    for (int i = 0; i < cl->ncols; i++)
        free(cl->cols[i].name);
    free(cl->cols);
    memset(cl, 0, sizeof *cl);
}

/* Append a column "base" + "suffix"; -1 when out of memory. */
static int add(column_layout *cl, column_source src, int obj, int comp, const char *base,
               const char *suffix, const char *unit)
{
    if (cl->ncols == cl->cap) {
        int cap = cl->cap ? 2 * cl->cap : 32;
        column_desc *more = xrealloc_array(cl->cols, (size_t)cap, sizeof *more);
        if (!more)
            return -1;
        cl->cols = more;
        cl->cap = cap;
    }
    size_t len = strlen(base) + strlen(suffix) + 1;
    char *name = malloc(len);
    if (!name)
        return -1;
    snprintf(name, len, "%s%s", base, suffix);
    cl->cols[cl->ncols++] = (column_desc){src, obj, comp, 1, name, unit};
    return 0;
}

/* Up to three columns of one object: the position, then the rates the
 * level asks for. */
static int add_levels(column_layout *cl, int level, column_source src, int obj, const char *base,
                      const char *const *suffix, const char *const *unit)
{
    int rc = add(cl, src, obj, 0, base, suffix[0], unit[0]);
    if (level & MECH_WANT_VELOCITY)
        rc |= add(cl, src, obj, 1, base, suffix[1], unit[1]);
    if (level & MECH_WANT_ACCELERATION)
        rc |= add(cl, src, obj, 2, base, suffix[2], unit[2]);
    return rc;
}

static int kinematic_columns(column_layout *cl, const mech_model *m, int level)
{
    static const char *const pt_sfx[] = {".x", ".y", ".vx", ".vy", ".ax", ".ay"};
    static const char *const pt_unit[] = {"m", "m", "m/s", "m/s", "m/s^2", "m/s^2"};
    static const char *const link_sfx[] = {".angle", ".omega", ".alpha"};
    static const char *const link_unit[] = {"rad", "rad/s", "rad/s^2"};
    static const char *const slide_sfx[] = {".s", ".v", ".a"};
    static const char *const slide_unit[] = {"m", "m/s", "m/s^2"};
    const mech_outputs *o = &m->outputs;
    int rc = add(cl, SRC_DRIVER, 0, 0, "q", "", m->driver.kind == MECH_DRIVE_ANGLE ? "rad" : "m");
    for (int i = 0; i < o->npoints; i++)
        for (int k = 0; k < 6; k++)
            if (k < 2 || (k < 4 ? level & MECH_WANT_VELOCITY : level & MECH_WANT_ACCELERATION))
                rc |= add(cl, SRC_POINT, o->points[i], k, m->point_names[o->points[i]],
                          pt_sfx[k], pt_unit[k]);
    for (int i = 0; i < o->nlinks; i++)
        rc |= add_levels(cl, level, SRC_LINK, o->links[i], m->links[o->links[i]].name, link_sfx,
                         link_unit);
    for (int i = 0; i < o->nsliders; i++)
        rc |= add_levels(cl, level, SRC_SLIDER, o->sliders[i], m->joints[o->sliders[i]].name,
                         slide_sfx, slide_unit);
    return rc;
}

/* Column base name of each joint: its name, or name(link,link) when
 * several joints share the name (three links on one pin). Counting the
 * names first keeps this linear in the number of joints. */
static char **joint_labels(const mech_model *m)
{
    char **label = xcalloc((size_t)m->njoints + 1, sizeof *label);
    name_map count = {0};
    int ok = label != NULL;
    for (int j = 0; ok && j < m->njoints; j++) {
        int c = name_map_get(&count, m->joints[j].name);
        ok = name_map_put(&count, m->joints[j].name, c < 0 ? 1 : c + 1) == 0;
    }
    for (int j = 0; ok && j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        size_t len = strlen(jt->name) + strlen(m->links[jt->link[0]].name) +
                     strlen(m->links[jt->link[1]].name) + 4;
        ok = (label[j] = malloc(len)) != NULL;
        if (ok && name_map_get(&count, jt->name) > 1)
            snprintf(label[j], len, "%s(%s,%s)", jt->name, m->links[jt->link[0]].name,
                     m->links[jt->link[1]].name);
        else if (ok)
            snprintf(label[j], len, "%s", jt->name);
    }
    name_map_free(&count);
    if (!ok && label) {
        for (int j = 0; j < m->njoints; j++)
            free(label[j]);
        free(label);
        label = NULL;
    }
    return label;
}

/* Reactions of every joint, the driver load and the power residual, of one
 * set (1 with friction, 0 frictionless, names suffixed ".nofriction"). */
static int force_columns(column_layout *cl, const mech_model *m, char **label, int set)
{
    static const char *const rev[] = {".Fx", ".Fy", ".F"};
    static const char *const sld[] = {".Fx", ".Fy", ".N", ".M"};
    char name[32];
    const char *suffix = set ? "" : ".nofriction";
    int rc = 0, first = cl->ncols;
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        int slider = jt->kind == MECH_JOINT_SLIDER, parts = slider && jt->locked ? 4 : 3;
        for (int k = 0; k < parts; k++) {
            snprintf(name, sizeof name, "%s%s", slider ? sld[k] : rev[k], suffix);
            rc |= add(cl, SRC_REACTION, j, k, label[j], name, k == 3 ? "N*m" : "N");
        }
    }
    if (m->driver.kind == MECH_DRIVE_ANGLE)
        rc |= add(cl, SRC_DRIVE_LOAD, 0, 0, "driver.torque", suffix, "N*m");
    else
        rc |= add(cl, SRC_DRIVE_LOAD, 0, 0, "driver.force", suffix, "N");
    rc |= add(cl, SRC_POWER_RESIDUAL, 0, 0, "power.residual", suffix, "-");
    for (int c = first; !rc && c < cl->ncols; c++)
        cl->cols[c].set = set;
    return rc;
}

static int dynamic_columns(column_layout *cl, const mech_model *m, const column_request *rq)
{
    char **label = joint_labels(m);
    if (!label)
        return -1;
    int rc = force_columns(cl, m, label, 1);
    if (rq->friction >= 1)
        rc |= add(cl, SRC_FRICTION_POWER, 0, 0, "friction.power", "", "W") |
              add(cl, SRC_FRICTION_ITERATIONS, 0, 0, "friction.iterations", "", "-");
    if (rq->friction == 2)
        rc |= force_columns(cl, m, label, 0);
    for (int j = 0; j < m->njoints; j++)
        free(label[j]);
    free(label);
    return rc;
}

int columns_build(column_layout *cl, const mech_model *m, const column_request *rq)
{
    memset(cl, 0, sizeof *cl);
    int rc = kinematic_columns(cl, m, rq->level);
    if (!rc && rq->forces)
        rc = dynamic_columns(cl, m, rq);
    if (!rc && rq->diagnostics)
        rc = add(cl, SRC_ITERATIONS, 0, 0, "iterations", "", "-") |
             add(cl, SRC_RESIDUAL, 0, 0, "residual", "", "m") |
             add(cl, SRC_RCOND, 0, 0, "rcond", "", "-") |
             add(cl, SRC_SUBSTEPS, 0, 0, "substeps", "", "-");
    if (rc) {
        columns_free(cl);
        return MECH_ENOMEM;
    }
    return MECH_OK;
}

int columns_make_table(const column_layout *cl, mech_table *t, int nrows)
{
    memset(t, 0, sizeof *t);
    t->columns = xcalloc((size_t)cl->ncols + 1, sizeof *t->columns);
    if (!t->columns)
        return MECH_ENOMEM;
    for (int c = 0; c < cl->ncols; c++, t->ncolumns++) {
        t->columns[c].name = xstrdup(cl->cols[c].name);
        t->columns[c].unit = xstrdup(cl->cols[c].unit);
        if (!t->columns[c].name || !t->columns[c].unit) {
            free(t->columns[c].name);
            free(t->columns[c].unit);
            return MECH_ENOMEM;
        }
    }
    t->values = xcalloc((size_t)nrows * (size_t)cl->ncols + 1, sizeof *t->values);
    return t->values ? MECH_OK : MECH_ENOMEM;
}

/* ---- filling a row -------------------------------------------------------- */

static double slider_value(const solver *sv, int joint, int comp)
{
    int var = sv->p->tree.slide_var[joint];
    const double *v = comp == 0 ? sv->pos : comp == 1 ? sv->vel : sv->acc;
    return var >= 0 ? v[var] : 0.0;
}

/* A joint's reaction (Fx, Fy, F or N, M) of one set, computed once for
 * its columns: the cache remembers the last joint and set. */
typedef struct reaction_cache {
    int joint, set;
    double r[4];
} reaction_cache;

static double reaction(const row_sources *rs, reaction_cache *rc, int joint, int comp, int set)
{
    if (joint != rc->joint || set != rc->set) {
        rc->joint = joint;
        rc->set = set;
        forces_joint(rs->fc, rs->sv, joint, set, &rc->r[0], &rc->r[1], &rc->r[2], &rc->r[3]);
        if (rs->fc->p->m->joints[joint].kind != MECH_JOINT_SLIDER)
            rc->r[2] = hypot(rc->r[0], rc->r[1]);
    }
    return rc->r[comp];
}

/* A point's motion is computed once for its (up to six) columns. */
void columns_fill(const column_layout *cl, const row_sources *rs, double *row)
{
    const solver *sv = rs->sv;
    const kin_state *ks = &sv->ks;
    double pva[6] = {0};
    int point = -1;
    reaction_cache rcache = {-1, -1, {0}};
    for (int c = 0; c < cl->ncols; c++) {
        const column_desc *d = &cl->cols[c];
        double v = 0.0;
        switch (d->src) {
        case SRC_DRIVER: v = sv->pos[sv->p->n]; break;
        case SRC_POINT:
            if (d->obj != point) {
                point = d->obj;
                kin_point(&sv->p->tree, ks, point, pva, pva + 2, pva + 4);
            }
            v = pva[d->comp];
            break;
        case SRC_LINK: v = (d->comp == 0 ? ks->th : d->comp == 1 ? ks->om : ks->al)[d->obj]; break;
        case SRC_SLIDER: v = slider_value(sv, d->obj, d->comp); break;
        case SRC_REACTION: v = reaction(rs, &rcache, d->obj, d->comp, d->set); break;
        case SRC_DRIVE_LOAD: v = forces_drive(rs->fc, d->set); break;
        case SRC_POWER_RESIDUAL: v = d->set ? rs->fc->residual : rs->fc->residual0; break;
        case SRC_FRICTION_POWER: v = rs->fc->friction_power; break;
        case SRC_FRICTION_ITERATIONS: v = rs->fc->iterations; break;
        case SRC_ITERATIONS: v = rs->iterations; break;
        case SRC_RESIDUAL: v = sv->resid; break;
        case SRC_RCOND: v = sv->rcond; break;
        case SRC_SUBSTEPS: v = rs->substeps; break;
        }
        row[c] = v;
    }
}
