/* src/study/columns.c: the result table's column layout (columns.h): built once
 * from the model's outputs, then used to name, size and fill the rows. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "study.h"
#include "load.h"
#include "forces.h"

void columns_free(column_layout *cl)
{
    for (int i = 0; i < cl->ncols; i++)
        free(cl->cols[i].name);
    free(cl->cols);
    free(cl->groups);
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

static int kinematic_columns(column_layout *cl, const mech_model *m, const mech_outputs *o,
                             int level)
{
    static const char *const pt_sfx[] = {".x", ".y", ".vx", ".vy", ".ax", ".ay"};
    static const char *const pt_unit[] = {"m", "m", "m/s", "m/s", "m/s^2", "m/s^2"};
    static const char *const link_sfx[] = {".angle", ".omega", ".alpha"};
    static const char *const link_unit[] = {"rad", "rad/s", "rad/s^2"};
    static const char *const slide_sfx[] = {".s", ".v", ".a"};
    static const char *const slide_unit[] = {"m", "m/s", "m/s^2"};
    int time = m->driver.kind == MECH_DRIVE_TIME;  /* drivers as laws of t */
    int rc = add(cl, SRC_DRIVER, 0, 0, time ? "t" : "q", "",
                 time ? "s" : m->driver.kind == MECH_DRIVE_ANGLE ? "rad" : "m");
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
    static const char *const cam_sfx[] = {".x", ".pressure_angle", ".rho_pitch", ".rho_profile"};
    static const char *const cam_unit[] = {"rad", "rad", "m", "m"};
    for (int i = 0; i < o->ncams; i++)  /* a cam's design quantities (docs/cams.md 3) */
        for (int k = 0; k < 4; k++)
            rc |= add(cl, SRC_CAM_DESIGN, o->cams[i], k, m->cams->cam[o->cams[i]].name,
                      cam_sfx[k], cam_unit[k]);
    /* each driven coordinate, after the outputs when they do not list it
       (the sweep's own coordinate is q) */
    for (int k = 0; k < m->ndrivers; k++) {
        const mech_motion *mo = &m->drivers[k];
        int angle = mo->kind == MECH_DRIVE_ANGLE, listed = drivers_is_sweep(m, k);
        for (int i = 0; angle && i < o->nlinks; i++)
            listed |= o->links[i] == mo->index;
        for (int i = 0; !angle && i < o->nsliders; i++)
            listed |= o->sliders[i] == mo->index;
        if (!listed)
            rc |= add_levels(cl, level, angle ? SRC_LINK : SRC_SLIDER, mo->index,
                             drivers_name(m, k), angle ? link_sfx : slide_sfx,
                             angle ? link_unit : slide_unit);
    }
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
    for (int k = 0; k < m->ndrivers; k++) {  /* one load per driver: the sweep's own is */
        int angle = m->drivers[k].kind == MECH_DRIVE_ANGLE;  /* "driver.torque" */
        snprintf(name, sizeof name, "%s%s", angle ? ".torque" : ".force", suffix);
        rc |= add(cl, SRC_DRIVE_LOAD, k, 0, drivers_is_sweep(m, k) ? "driver" : drivers_name(m, k),
                  name, angle ? "N*m" : "N");
    }
    rc |= add(cl, SRC_POWER_RESIDUAL, 0, 0, "power.residual", suffix, "-");
    for (int c = first; !rc && c < cl->ncols; c++)
        cl->cols[c].set = set;
    return rc;
}

/* Each spring's length (or angle), its rate and its force (or torque). */
static int spring_columns(column_layout *cl, const mech_model *m)
{
    static const char *const lin[] = {".length", ".rate", ".force"};
    static const char *const lin_unit[] = {"m", "m/s", "N"};
    static const char *const tor[] = {".angle", ".rate", ".torque"};
    static const char *const tor_unit[] = {"rad", "rad/s", "N*m"};
    int rc = 0;
    for (int i = 0; i < m->nsprings; i++) {
        int torsion = m->springs[i].kind == MECH_SPRING_TORSION;
        rc |= add_levels(cl, MECH_WANT_ALL, SRC_SPRING, i, m->springs[i].name,
                         torsion ? tor : lin, torsion ? tor_unit : lin_unit);
    }
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
    rc |= spring_columns(cl, m);
    for (int i = 0; i < m->ngears; i++)  /* each mesh's tooth force (docs/forces.md) */
        rc |= add(cl, SRC_GEAR, i, 0, m->gears[i].name, ".W", "N");
    for (int i = 0; i < model_ncams(m); i++)  /* each cam's contact force (docs/cams.md 6) */
        rc |= add(cl, SRC_CAM, i, 0, m->cams->cam[i].name, ".F", "N");
    for (int j = 0; j < m->njoints; j++)
        free(label[j]);
    free(label);
    return rc;
}

static int same_object(const column_desc *a, const column_desc *b)
{
    return a->src == b->src && a->obj == b->obj && a->set == b->set;
}

/* Values a source gives: a point's motion 6, a link's or slider's 3, a
 * reaction 4, anything else 1. */
static int source_width(column_source src)
{
    switch (src) {
    case SRC_POINT: return 6;
    case SRC_LINK: case SRC_SLIDER: case SRC_SPRING: return 3;
    case SRC_REACTION: case SRC_CAM_DESIGN: return 4;
    default: return 1;
    }
}

/* Runs of columns of one source object, components 0, 1, ... in order. */
static int make_groups(column_layout *cl)
{
    cl->groups = xcalloc((size_t)cl->ncols + 1, sizeof *cl->groups);
    if (!cl->groups)
        return -1;
    column_group *g = NULL;
    for (int c = 0; c < cl->ncols; c++) {
        const column_desc *d = &cl->cols[c];
        if (!g || !same_object(&cl->cols[g->first], d) || d->comp != g->n) {
            g = &cl->groups[cl->ngroups++];
            *g = (column_group){d->src, d->obj, d->set, c, 0, 0};
        }
        g->n++;
        g->direct = g->n == source_width(g->src);
    }
    for (int k = 0; k < cl->ngroups; k++)
        if (cl->cols[cl->groups[k].first].comp != 0)
            return -1;  /* a layout this module did not make */
    return 0;
}

int columns_build(column_layout *cl, const mech_model *m, const column_request *rq)
{
    memset(cl, 0, sizeof *cl);
    int rc = kinematic_columns(cl, m, rq->outputs, rq->level);
    if (!rc && rq->forces)
        rc = dynamic_columns(cl, m, rq);
    if (!rc && rq->diagnostics)
        rc = add(cl, SRC_ITERATIONS, 0, 0, "iterations", "", "-") |
             add(cl, SRC_RESIDUAL, 0, 0, "residual", "", "m") |
             add(cl, SRC_RCOND, 0, 0, "rcond", "", "-") |
             add(cl, SRC_SUBSTEPS, 0, 0, "substeps", "", "-");
    if (!rc)
        rc = make_groups(cl);
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
    t->values = xcalloc_large((size_t)nrows * (size_t)cl->ncols + 1, sizeof *t->values);
    return t->values ? MECH_OK : MECH_ENOMEM;
}

/* ---- filling a row -------------------------------------------------------- */

static void slider_values(const solver *sv, int joint, double *v)
{
    int var = sv->p->tree.slide_var[joint];
    v[0] = var >= 0 ? sv->pos[var] : 0.0;
    v[1] = var >= 0 ? sv->vel[var] : 0.0;
    v[2] = var >= 0 ? sv->acc[var] : 0.0;
}

/* A joint's reaction: Fx, Fy, F (revolute: the magnitude) or N, M. */
static void reaction_values(const row_sources *rs, int joint, int set, double *r)
{
    forces_joint(rs->fc, rs->sv, joint, set, &r[0], &r[1], &r[2], &r[3]);
    if (rs->fc->p->m->joints[joint].kind != MECH_JOINT_SLIDER)
        r[2] = hypot(r[0], r[1]);
}

/* Cam i's design quantities at the cam's angle on its arm (cam_geometry). */
static void cam_design_values(int i, const solver *sv, double *v)
{
    const mech_model *m = sv->p->m;
    const mech_cam *c = &m->cams->cam[i];
    const rt_frame *F = sv->ks.F;
    cam_point g;
    double x = c->sense * (F[c->cam].th - F[c->arm].th - c->start);
    cam_geometry(m, c, x, &g);
    v[0] = x;
    v[1] = g.pressure;
    v[2] = g.rho_pitch;
    v[3] = g.rho_profile;
}

static void spring_values(int i, const solver *sv, double *v)
{
    spring_state st;
    springs_eval(sv->p->m, i, sv, &st);
    v[0] = st.length;
    v[1] = st.rate;
    v[2] = st.force;
}

/* Every component of a group's source object into v[0 .. width - 1]. */
static void source_values(const column_group *g, const row_sources *rs, double *v)
{
    const solver *sv = rs->sv;
    const kin_state *ks = &sv->ks;
    switch (g->src) {
    case SRC_DRIVER: v[0] = sv->pos[sv->p->n]; break;
    case SRC_POINT: kin_point(&sv->p->tree, ks, g->obj, v, v + 2, v + 4); break;
    case SRC_LINK:
        v[0] = ks->F[g->obj].th;
        v[1] = ks->F[g->obj].om;
        v[2] = ks->F[g->obj].al;
        break;
    case SRC_SLIDER: slider_values(sv, g->obj, v); break;
    case SRC_REACTION: reaction_values(rs, g->obj, g->set, v); break;
    case SRC_DRIVE_LOAD: v[0] = forces_drive_of(rs->fc, g->set, g->obj); break;
    case SRC_POWER_RESIDUAL: v[0] = g->set ? rs->fc->out.residual : rs->fc->out.residual0; break;
    case SRC_FRICTION_POWER: v[0] = rs->fc->out.friction_power; break;
    case SRC_FRICTION_ITERATIONS: v[0] = rs->fc->out.iterations; break;
    case SRC_ITERATIONS: v[0] = rs->iterations; break;
    case SRC_RESIDUAL: v[0] = sv->resid; break;
    case SRC_RCOND: v[0] = sv->rcond; break;
    case SRC_SUBSTEPS: v[0] = rs->substeps; break;
    case SRC_SPRING: spring_values(g->obj, sv, v); break;
    case SRC_GEAR: v[0] = forces_gear(rs->fc, g->obj, 1); break;
    case SRC_CAM: v[0] = forces_cam(rs->fc, g->obj, 1); break;
    case SRC_CAM_DESIGN: cam_design_values(g->obj, sv, v); break;
    }
}

void columns_fill(const column_layout *cl, const row_sources *rs, double *row)
{
    for (int k = 0; k < cl->ngroups; k++) {
        const column_group *g = &cl->groups[k];
        double v[6];  /* some components only (positions without rates): copied */
        source_values(g, rs, g->direct ? row + g->first : v);
        if (!g->direct)
            memcpy(row + g->first, v, (size_t)g->n * sizeof *v);
    }
}

/* ---- the table (include/mech.h) ----------------------------------------- */

void mech_table_free(mech_table *t)
{
    if (!t)
        return;
    for (int i = 0; i < t->ncolumns; i++) {
        free(t->columns[i].name);
        free(t->columns[i].unit);
    }
    free(t->columns);
    free(t->values);
    free(t->gaps);
    memset(t, 0, sizeof *t);
}

int mech_table_column(const mech_table *t, const char *name)
{
    if (!t || !name)
        return -1;
    for (int i = 0; i < t->ncolumns; i++)
        if (strcmp(t->columns[i].name, name) == 0)
            return i;
    return -1;
}
