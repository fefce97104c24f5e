/* src/study/variant_regs.c: one analysis per sweep. The base model's system is
 * built with the varied parameters chosen (system_coef.c, SYS_LEAF_POLAR:
 * the length and angle of each body vector that a varied parameter moves
 * are leaves, everything else folded as mech solve folds it) and analysed
 * once (blocks, tape, pattern, forces, columns). A variant is solved through
 * a view of that analysis (sweep.c): the base's structure with the
 * variant's numbers (its leaves' values among them), after checking that it
 * has the base's structure and the base's folded numbers. Decisions and what
 * forces a re-analysis: docs/batch.md ("One analysis per sweep"). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "study.h"

struct variant_base {
    mech_model *m;             /* the base model, owned */
    mech_analysis *a;          /* the analysis of m with the varied parameters' leaves */
    const mech_system *sys;    /* a's system */
    int nterms;                /* body terms of the loops, in loop order */
    const loop_term **term;    /* [nterms] */
    int *rvar, *avar;          /* [nterms] variable of the length / angle, or -1 (folded) */
    double *r0, *a0;           /* [nterms] the base's length and angle */
    sys_leaves leaves;         /* the system's leaves: SYS_LEAF_POLAR of the varied
                                  parameters (leaves.params owned) */
    int forces;                /* the analysis's forces flag */
};

/* Relative size of a difference in a folded number taken as rounding
 * (a polar point's angle recomputed by atan2 for another length). */
static const double FOLD_TOL = 1e-14;

void vbase_free(variant_base **pb)
{
    variant_base *b = pb ? *pb : NULL;
    if (!b)
        return;
    mech_analysis_free(&b->a);
    mech_model_free(&b->m);
    free(b->term);
    free(b->rvar);
    free(b->avar);
    free(b->r0);
    free(b->a0);
    free((int *)b->leaves.params);  /* allocated here (vbase_new) */
    free(b);
    *pb = NULL;
}

const mech_model *vbase_model(const variant_base *b) { return b->m; }

const sys_leaves *vbase_leaves(const variant_base *b) { return &b->leaves; }

int vbase_forces(const variant_base *b) { return b->forces; }

const mech_analysis *vbase_analysis(const variant_base *b) { return b->a; }

static int index_terms(variant_base *b)
{
    const loop_set *ls = &b->sys->loops;
    int total = ls->start[ls->nloops];
    b->term = xcalloc((size_t)total + 1, sizeof *b->term);
    b->rvar = xcalloc((size_t)total + 1, sizeof *b->rvar);
    b->avar = xcalloc((size_t)total + 1, sizeof *b->avar);
    b->r0 = xcalloc((size_t)total + 1, sizeof *b->r0);
    b->a0 = xcalloc((size_t)total + 1, sizeof *b->a0);
    if (!b->term || !b->rvar || !b->avar || !b->r0 || !b->a0)
        return -1;
    for (int k = 0; k < total; k++) {
        const loop_term *t = &ls->terms[k];
        if (t->kind != TERM_BODY)
            continue;
        int i = b->nterms++;
        b->term[i] = t;
        b->rvar[i] = sys_coef_var(b->sys, t, 0);
        b->avar[i] = sys_coef_var(b->sys, t, 1);
        double dx, dy;
        sys_body_vector(b->m, t, &dx, &dy, &b->r0[i], &b->a0[i]);
    }
    return 0;
}

int vbase_new(mech_model *base, const char *const *names, int nnames, int with_forces,
              variant_base **out, mech_diag *d)
{
    *out = NULL;
    variant_base *b = xcalloc(1, sizeof *b);
    int *which = xcalloc((size_t)nnames + 1, sizeof *which);
    if (!b || !which) {
        free(b);
        free(which);
        diag_nomem(d, base->file, (mech_mark){0, 0});
        mech_model_free(&base);
        return MECH_ENOMEM;
    }
    b->m = base;
    int rc = MECH_OK;
    for (int i = 0; i < nnames && rc == MECH_OK; i++) {
        which[i] = -1;
        for (int k = 0; k < base->nparams; k++)
            if (strcmp(base->params[k].name, names[i]) == 0)
                which[i] = k;
        if (which[i] < 0)
            rc = diag_error(d, base->file, (mech_mark){0, 0}, "no parameter '%s'", names[i]);
    }
    mech_system *sys = NULL;
    b->leaves = (sys_leaves){SYS_LEAF_POLAR, which, nnames};  /* owns which */
    b->forces = with_forces;
    if (rc == MECH_OK)
        rc = sys_new_with(base, &b->leaves, &sys, d);
    if (rc == MECH_OK) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.forces = with_forces;
        rc = analysis_new_with(base, &o, sys, &b->a, d);  /* owns sys */
    }
    if (rc == MECH_OK) {
        b->sys = analysis_system(b->a);
        if (index_terms(b) < 0) {
            diag_nomem(d, base->file, (mech_mark){0, 0});
            rc = MECH_ENOMEM;
        }
    }
    if (rc != MECH_OK) {
        vbase_free(&b);
        return rc;
    }
    *out = b;
    return MECH_OK;
}

/* ---- the same structure ------------------------------------------------- */

#define SAME(f) (a->f == v->f)

static int same_links(const mech_model *a, const mech_model *v)
{
    for (int l = 0; l < a->nlinks; l++) {
        const mech_link *x = &a->links[l], *y = &v->links[l];
        /* a mass or inertia going to or from 0 changes "nothing loads" */
        if (x->npoints != y->npoints || x->has_mass != y->has_mass ||
            (x->mass == 0.0) != (y->mass == 0.0) || (x->inertia == 0.0) != (y->inertia == 0.0))
            return 0;
        for (int i = 0; i < x->npoints; i++)
            if (x->points[i].id != y->points[i].id)
                return 0;
    }
    for (int j = 0; j < a->njoints; j++) {
        const mech_joint *x = &a->joints[j], *y = &v->joints[j];
        /* the guide's angle is folded into the slider's terms */
        if (x->kind != y->kind || x->link[0] != y->link[0] || x->link[1] != y->link[1] ||
            x->point[0] != y->point[0] || x->point[1] != y->point[1] || x->angle != y->angle ||
            x->locked != y->locked || (x->friction == 0.0) != (y->friction == 0.0))
            return 0;
    }
    return 1;
}

static int same_lists(const mech_model *a, const mech_model *v)
{
    const mech_driver *x = &a->driver, *y = &v->driver;
    if (x->kind != y->kind || x->index != y->index || x->nvalues != y->nvalues ||
        memcmp(x->values, y->values, (size_t)x->nvalues * sizeof *x->values) != 0)
        return 0;  /* the rows: the analysis holds the driver positions */
    for (int i = 0; i < a->nguesses; i++)
        if (a->guesses[i].is_slider != v->guesses[i].is_slider ||
            a->guesses[i].index != v->guesses[i].index)
            return 0;
    for (int i = 0; i < a->nbranches; i++) {
        const mech_branch *p = &a->branches[i], *q = &v->branches[i];
        if (p->kind != q->kind || memcmp(p->point, q->point, sizeof p->point) != 0 ||
            p->slider != q->slider || p->sign != q->sign || p->first_only != q->first_only)
            return 0;
    }
    for (int i = 0; i < a->nloops; i++)
        if (a->loops[i].npoints != v->loops[i].npoints ||
            memcmp(a->loops[i].points, v->loops[i].points,
                   (size_t)a->loops[i].npoints * sizeof *a->loops[i].points) != 0)
            return 0;
    for (int i = 0; i < a->nloads; i++)
        if (a->loads[i].kind != v->loads[i].kind || a->loads[i].link != v->loads[i].link ||
            memcmp(a->loads[i].point, v->loads[i].point, sizeof a->loads[i].point) != 0)
            return 0;
    for (int i = 0; i < a->nsprings; i++) {
        const mech_spring *p = &a->springs[i], *q = &v->springs[i];
        if (p->kind != q->kind || memcmp(p->link, q->link, sizeof p->link) != 0 ||
            memcmp(p->point, q->point, sizeof p->point) != 0 || p->joint != q->joint)
            return 0;
    }
    const mech_outputs *o = &a->outputs, *w = &v->outputs;
    return o->npoints == w->npoints && o->nlinks == w->nlinks && o->nsliders == w->nsliders &&
           o->forces == w->forces &&
           (!o->npoints || !memcmp(o->points, w->points, (size_t)o->npoints * sizeof *o->points)) &&
           (!o->nlinks || !memcmp(o->links, w->links, (size_t)o->nlinks * sizeof *o->links)) &&
           (!o->nsliders ||
            !memcmp(o->sliders, w->sliders, (size_t)o->nsliders * sizeof *o->sliders));
}

#define SAME_BITS(f) (memcmp(&p->f, &q->f, sizeof p->f) == 0)

/* The gear rows (gears.c) fold every pair's links, pivots, radii and phase
 * into the system: the same, bit for bit. */
static int same_gears(const mech_model *a, const mech_model *v)
{
    for (int i = 0; i < a->ngears; i++) {
        const mech_gear *p = &a->gears[i], *q = &v->gears[i];
        if (p->kind != q->kind || p->arm != q->arm || p->rack != q->rack ||
            p->internal != q->internal || p->side != q->side || !SAME_BITS(link) ||
            !SAME_BITS(pivot) || !SAME_BITS(arm_pivot) || !SAME_BITS(radius) ||
            !SAME_BITS(offset))
            return 0;
    }
    return 1;
}

/* The counts, kinds and indices the analysis was built on. */
static int same_structure(const mech_model *a, const mech_model *v)
{
    return SAME(nlinks) && SAME(njoints) && SAME(npoint_names) && SAME(has_driver) &&
           drivers_same(a, v) &&  /* the laws' numbers are folded into the tape */
           SAME(nguesses) && SAME(nbranches) && SAME(nloops) && SAME(nloads) &&
           SAME(nsprings) && SAME(ngears) && same_links(a, v) && same_lists(a, v) &&
           same_gears(a, v) &&
           !a->state_loads && !v->state_loads &&  /* see docs/batch.md */
           !a->cams && !v->cams;  /* a cam's numbers and program: each variant its own */
}

/* ---- a variant ------------------------------------------------------------ */

/* Variant mv's lengths and angles against the base's: 1 when every folded one
 * is the base's to rounding and no leaf length is exactly 0 (the solver's
 * system would drop its terms); the leaves' values are the view's numbers. */
static int same_folded_numbers(const variant_base *b, const mech_model *mv)
{
    const double two_pi = 6.28318530717958647692;
    for (int i = 0; i < b->nterms; i++) {
        double r, a;
        double dx, dy;
        sys_body_vector(mv, b->term[i], &dx, &dy, &r, &a);
        if (b->rvar[i] >= 0 ? r == 0.0 : fabs(r - b->r0[i]) > FOLD_TOL * b->r0[i])
            return 0;
        if (b->avar[i] < 0 && b->r0[i] != 0.0 &&
            fabs(remainder(a - b->a0[i], two_pi)) > FOLD_TOL)
            return 0;
    }
    return 1;
}

int vbase_solve(const variant_base *b, const mech_model *mv, const sweep_engine *e,
                mech_table *t, mech_diag *d)
{
    memset(t, 0, sizeof *t);
    if (!same_structure(b->m, mv) || !same_folded_numbers(b, mv))
        return VBASE_REANALYSE;
    mech_analysis *view = analysis_view_new(b->a, mv);
    if (!view)
        return diag_nomem(d, mv->file, (mech_mark){0, 0});
    int rc = e && e->solve ? e->solve(e->ctx, b, view, mv, t, d) : VBASE_INTERPRET;
    if (rc == VBASE_INTERPRET)
        rc = mech_analysis_solve(view, NULL, 0, t, NULL, d);
    analysis_view_free(&view);
    return rc;
}
