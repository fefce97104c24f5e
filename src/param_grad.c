/* src/param_grad.c: how the model's point coordinates depend on its
 * parameters: for each parameter p, d(x, y)/dp of every point, exact
 * (forward-mode derivatives through the quantity expressions, units.c),
 * from one seeded load of the file per parameter (load_file_seeded). Used
 * by `mech equations` (which numbers to name) and by the sensitivities. */
#include <stdlib.h>
#include <string.h>

#include "param_grad.h"

void pgrad_free(param_grad *g)
{
    if (!g)
        return;
    for (int k = 0; k < g->view.nparams; k++) {
        free(g->names ? g->names[k] : NULL);
        free(g->dxy ? g->dxy[k] : NULL);
    }
    free(g->names);
    free(g->values);
    free(g->units);
    free(g->dxy);
    memset(g, 0, sizeof *g);
}

/* The seeded model must be the same mechanism (it is the same file): the
 * same links with the same numbers of points. */
static int same_shape(const mech_model *a, const mech_model *b)
{
    if (a->nlinks != b->nlinks || a->nparams != b->nparams)
        return 0;
    for (int l = 0; l < a->nlinks; l++)
        if (a->links[l].npoints != b->links[l].npoints)
            return 0;
    return 1;
}

static int total_points(const mech_model *m)
{
    int n = 0;
    for (int l = 0; l < m->nlinks; l++)
        n += m->links[l].npoints;
    return n;
}

/* d(points)/d(parameter `name`) into dxy[2 * total points]. */
static int seeded(const mech_model *m, const mech_override *ov, int nov, const char *name,
                  double *dxy, mech_diag *d)
{
    mech_model *sm = NULL;
    int rc = load_file_seeded(m->file, ov, nov, name, &sm, d);
    if (rc != MECH_OK)
        return rc;
    if (!same_shape(m, sm)) {
        mech_model_free(&sm);
        return diag_error(d, m->file, (mech_mark){0, 0},
                          "the file changed while its parameters were differentiated");
    }
    int g = 0;
    for (int l = 0; l < sm->nlinks; l++)
        for (int i = 0; i < sm->links[l].npoints; i++, g++) {
            dxy[2 * g] = sm->links[l].points[i].dxy[0];
            dxy[2 * g + 1] = sm->links[l].points[i].dxy[1];
        }
    mech_model_free(&sm);
    return MECH_OK;
}

/* The seeded load carries derivatives into the points only. A parameter
 * that also sets a slider's angle, or a gear pair's radii or phase, would be
 * differentiated without that term: found by loading the file with the
 * parameter nudged, and refused. */
static int check_slider_angles(const mech_model *m, const mech_override *ov, int nov,
                               const mech_param *p, mech_diag *d)
{
    enum { MAX_OV = 64 };
    mech_override all[MAX_OV + 1];
    char text[96];
    double nudged = p->value != 0 ? p->value * (1 + 1e-7) : 1e-7;
    snprintf(text, sizeof text, "%.17g %s", nudged, p->unit);
    int n = 0;
    for (int i = 0; i < nov && n < MAX_OV; i++)
        if (strcmp(ov[i].name, p->name) != 0)
            all[n++] = ov[i];
    all[n++] = (mech_override){p->name, text};
    mech_diag quiet;
    mech_diag_init(&quiet);
    mech_model *nm = NULL;
    int rc = mech_load_file_with(m->file, all, n, &nm, &quiet);
    mech_diag_free(&quiet);
    if (rc != MECH_OK || nm->njoints != m->njoints) {
        mech_model_free(&nm);
        return MECH_OK;  /* nothing to compare; the seeded load said what it could */
    }
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER && nm->joints[j].angle != m->joints[j].angle) {
            rc = diag_error(d, m->file, m->joints[j].mark, "parameter '%s' sets the angle of "
                            "slider '%s': sensitivities through a slider's angle are not "
                            "computed", p->name, m->joints[j].name);
            mech_model_free(&nm);
            return rc;
        }
    for (int g = 0; g < m->ngears && nm->ngears == m->ngears; g++) {  /* gears.c's rows */
        const mech_gear *a = &m->gears[g], *b = &nm->gears[g];
        if (a->radius[0] != b->radius[0] || a->radius[1] != b->radius[1] ||
            a->offset[0] != b->offset[0] || a->offset[1] != b->offset[1]) {
            rc = diag_error(d, m->file, a->mark, "parameter '%s' sets the radii or the phase of "
                            "gear pair '%s': sensitivities through a gear pair are not computed",
                            p->name, a->name);
            mech_model_free(&nm);
            return rc;
        }
    }
    mech_model_free(&nm);
    return MECH_OK;
}

int pgrad_build(const mech_model *m, const mech_override *ov, int nov, const int *which,
                int nwhich, int check_angles, param_grad *g, mech_diag *d)
{
    memset(g, 0, sizeof *g);
    int np = which ? nwhich : m->nparams;
    size_t npts = 2 * (size_t)total_points(m) + 1;
    g->names = xcalloc((size_t)np + 1, sizeof *g->names);
    g->values = xcalloc((size_t)np + 1, sizeof *g->values);
    g->units = xcalloc((size_t)np + 1, sizeof *g->units);
    g->dxy = xcalloc((size_t)np + 1, sizeof *g->dxy);
    if (!g->names || !g->values || !g->units || !g->dxy)
        goto oom;
    for (int k = 0; k < np; k++) {
        const mech_param *p = &m->params[which ? which[k] : k];
        g->names[k] = xstrdup(p->name);
        g->values[k] = p->value;
        g->units[k] = p->unit;
        g->dxy[k] = xcalloc(npts, sizeof *g->dxy[k]);
        g->view.nparams = k + 1;
        if (!g->names[k] || !g->dxy[k])
            goto oom;
        int rc = seeded(m, ov, nov, p->name, g->dxy[k], d);
        if (rc == MECH_OK && check_angles)
            rc = check_slider_angles(m, ov, nov, p, d);
        if (rc != MECH_OK) {
            pgrad_free(g);
            return rc;
        }
    }
    g->view.names = (const char *const *)g->names;
    g->view.values = g->values;
    g->view.units = g->units;
    g->view.dxy = g->dxy;
    return MECH_OK;
oom:
    pgrad_free(g);
    return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
}
