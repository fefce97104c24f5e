/* src/solve/assembly.c: is the assembly the one the file means? Once per
 * sweep, after it, from a few positions kept along it (docs/solver.md
 * section 9): the first position against the `initial:` guesses (or a
 * stated pose), and the signs of a degenerate assembly that a sweep solves
 * without complaint: a moving point on a ground point, a slider that does
 * not slide, two pinned links folded onto each other, outputs that do not
 * move. Each is a warning of its own kind (fail_is_suspect_assembly),
 * which `--strict` makes an error. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"

static const double PI = 3.14159265358979323846;

/* Guesses further than these from the first position are reported: an
 * angle, and a slide as a fraction of the mechanism's largest length. */
static const double GUESS_ANGLE = 45.0 * 3.14159265358979323846 / 180.0;
static const double GUESS_SLIDE = 0.5;
/* Still, or on each other: within this fraction of the largest length, or
 * 100 Newton tolerances (the default's rounding, 1e-12, is far below it;
 * a micrometre part of a kilometre mechanism, tests/hard/mixed-scale.yaml,
 * far above). */
static const double STILL = 1e-10;

static double still_fraction(const solver_plan *sp) { return fmax(STILL, 100.0 * sp->opt.tol); }

int assembly_samples_init(assembly_samples *s, int ns, int nq)
{
    memset(s, 0, sizeof *s);
    s->ns = ns;
    s->x = xcalloc((size_t)ASSEMBLY_SAMPLES * (size_t)(ns > 0 ? ns : 1), sizeof *s->x);
    if (!s->x)
        return -1;
    int k = nq < ASSEMBLY_SAMPLES ? nq : ASSEMBLY_SAMPLES;
    for (int i = 0; i < k; i++)  /* spread over the rows, the first and last among them */
        s->row[i] = k > 1 ? (int)((long long)i * (nq - 1) / (k - 1)) : 0;
    s->nrows = k;
    s->next_row = k > 0 ? s->row[0] : -1;
    return 0;
}

void assembly_samples_free(assembly_samples *s)
{
    free(s->x);
    memset(s, 0, sizeof *s);
}

void assembly_take(assembly_samples *s, int row, double q, const double *x)
{
    while (s->next < s->nrows && s->row[s->next] < row)  /* rows lost in a gap */
        s->next++;
    if (s->next < s->nrows && s->row[s->next] == row) {
        if (row == 0)
            s->has_first = 1;
        s->q[s->n] = q;
        memcpy(s->x + (size_t)s->n * (size_t)s->ns, x, (size_t)s->ns * sizeof *x);
        s->n++;
        s->next++;
    }
    s->next_row = s->next < s->nrows ? s->row[s->next] : INT_MAX;
}

/* Place every link at the kept position k: the frames in sv->ks. */
static void place_sample(solver *sv, const assembly_samples *s, int k)
{
    const solver_plan *sp = sv->p;
    const double *x = s->x + (size_t)k * (size_t)s->ns;
    for (int i = 0; i < sp->ns; i++)
        sv->pos[sp->col[i]] = x[i];
    sv->pos[sp->n] = s->q[k];
    sv->generation++;  /* the published state is no longer this */
    kin_place_all(&sp->tree, &sv->ks, sv->pos);
}

static const char *link_name(const mech_model *m, int l) { return m->links[l].name; }

/* ---- a: the first position against the guesses ---------------------------- */

/* slot[var]: where unknown var is among the solved ones, -1 when it is not
 * solved (one array per sweep: a chain of 10^4 loops has 2 10^4 guesses). */
static int *solved_slots(const solver_plan *sp)
{
    int *slot = xcalloc((size_t)sp->n + 1, sizeof *slot);
    for (int v = 0; slot && v < sp->n; v++)
        slot[v] = -1;
    for (int i = 0; slot && i < sp->ns; i++)
        slot[sp->col[i]] = i;
    return slot;
}

static void check_guess(const solver *sv, const int *slot, const double *x0, const mech_guess *g,
                        mech_diag *d)
{
    const solver_plan *sp = sv->p;
    const mech_model *m = sp->m;
    int var = g->is_slider ? sp->sys->joint_var[g->index] : sp->sys->link_var[g->index];
    int i = var >= 0 && var < sp->n ? slot[var] : -1;
    if (i < 0)  /* the driver's own coordinate, or not solved */
        return;
    if (!g->is_slider) {
        double off = remainder(x0[i] - g->value, 2.0 * PI);
        if (fabs(off) > GUESS_ANGLE)
            diag_add(d, MECH_SEV_WARNING, MECH_FAIL_FAR_FROM_GUESS, m->file, g->mark,
                     "link '%s' is at %.1f deg in the first position, %s %.1f deg (%.0f "
                     "deg off): the mechanism assembled another way than guessed; guesses "
                     "for the links next to it (or a branch:) choose the assembly",
                     link_name(m, g->index), remainder(x0[i], 2.0 * PI) * 180.0 / PI,
                     fail_words(MECH_FAIL_FAR_FROM_GUESS), g->value * 180.0 / PI,
                     fabs(off) * 180.0 / PI);
        return;
    }
    double off = x0[i] - g->value;
    if (fabs(off) > GUESS_SLIDE * sp->lref)
        diag_add(d, MECH_SEV_WARNING, MECH_FAIL_FAR_FROM_GUESS, m->file, g->mark,
                 "slider '%s' is at %.4g mm in the first position, %s %.4g mm (%.4g mm "
                 "off): the mechanism assembled another way than guessed; guesses for "
                 "the links next to it (or a branch:) choose the assembly",
                 m->joints[g->index].name, x0[i] * 1e3, fail_words(MECH_FAIL_FAR_FROM_GUESS),
                 g->value * 1e3, fabs(off) * 1e3);
}

int assembly_check_pose(solver *sv, double q, const double *x, const double *pose,
                        double tol, mech_diag *d)
{
    const solver_plan *sp = sv->p;
    const mech_model *m = sp->m;
    assembly_samples one = {.ns = sp->ns, .n = 1, .q = {q}, .x = (double *)x};
    place_sample(sv, &one, 0);
    int far = 0;
    for (int id = 0; id < m->npoint_names; id++) {
        double p[2];
        if (isnan(pose[2 * id]) || sp->tree.point_link[id] <= 0)
            continue;
        kin_point(&sp->tree, &sv->ks, id, p, NULL, NULL);
        double off = hypot(p[0] - pose[2 * id], p[1] - pose[2 * id + 1]);
        if (!(off <= tol)) {
            const mech_link *l = &m->links[sp->tree.point_link[id]];
            diag_add(d, MECH_SEV_WARNING, MECH_FAIL_FAR_FROM_GUESS, m->file,
                     l->points[sp->tree.point_index[id]].mark,
                     "the first position has point '%s' (link '%s') at (%.4g, %.4g) mm, "
                     "%.4g mm %s (%.4g, %.4g) mm: the mechanism assembled another way "
                     "than drawn", m->point_names[id], l->name, p[0] * 1e3, p[1] * 1e3,
                     off * 1e3, fail_words(MECH_FAIL_FAR_FROM_GUESS), pose[2 * id] * 1e3,
                     pose[2 * id + 1] * 1e3);
            far++;
        }
    }
    return far;
}

/* ---- b-e: over the whole sweep --------------------------------------------- */

/* The positions of every point name at each kept position: P[(k np + id) 2 + 0/1]. */
static double *sample_points(solver *sv, const assembly_samples *s)
{
    const kin_tree *t = &sv->p->tree;
    int np = sv->p->m->npoint_names;
    double *P = xcalloc((size_t)s->n * (size_t)np * 2 + 1, sizeof *P);
    for (int k = 0; P && k < s->n; k++) {
        place_sample(sv, s, k);
        for (int id = 0; id < np; id++)
            kin_point(t, &sv->ks, id, P + ((size_t)k * np + id) * 2, NULL, NULL);
    }
    return P;
}

static const double *at(const double *P, int np, int k, int id)
{
    return P + ((size_t)k * (size_t)np + (size_t)id) * 2;
}

/* The point name id is still over the kept positions. */
static int point_still(const double *P, int np, int n, int id, double tol)
{
    for (int k = 1; k < n; k++)
        if (!(hypot(at(P, np, k, id)[0] - at(P, np, 0, id)[0],
                    at(P, np, k, id)[1] - at(P, np, 0, id)[1]) <= tol))
            return 0;
    return 1;
}

/* A ground point and its x at the first kept position, sorted by x (the
 * pair carries x: no shared context, sweeps run on several threads). */
typedef struct ground_x {
    double x;
    int id;
} ground_x;

static int by_x(const void *a, const void *b)
{
    double xa = ((const ground_x *)a)->x, xb = ((const ground_x *)b)->x;
    return (xa > xb) - (xa < xb);
}

/* b: a moving point on a ground point at every kept position. The ground
 * points are sorted by x once, so that each moving point looks only at
 * those within tol of its x (a chain of 10^4 loops has 10^4 of each). */
static void check_on_ground(const solver *sv, const double *P, int n, double tol, mech_diag *d)
{
    const solver_plan *sp = sv->p;
    const mech_model *m = sp->m;
    int np = m->npoint_names, ng = 0;
    ground_x *g = xcalloc((size_t)np + 1, sizeof *g);
    if (!g)
        return;
    for (int id = 0; id < np; id++)
        if (sp->tree.point_link[id] == 0)
            g[ng++] = (ground_x){at(P, np, 0, id)[0], id};
    qsort(g, (size_t)ng, sizeof *g, by_x);
    for (int id = 0; id < np; id++) {
        int l = sp->tree.point_link[id], lo = 0, hi = ng;
        if (l <= 0)
            continue;
        double x = at(P, np, 0, id)[0];
        while (lo < hi) {  /* the first ground point with x >= x - tol */
            int mid = lo + (hi - lo) / 2;
            if (g[mid].x < x - tol)
                lo = mid + 1;
            else
                hi = mid;
        }
        for (int i = lo; i < ng && g[i].x <= x + tol; i++) {
            int k = 0;
            while (k < n && hypot(at(P, np, k, id)[0] - at(P, np, k, g[i].id)[0],
                                  at(P, np, k, id)[1] - at(P, np, k, g[i].id)[1]) <= tol)
                k++;
            if (k < n)
                continue;
            diag_add(d, MECH_SEV_WARNING, MECH_FAIL_ON_GROUND_POINT, m->file,
                     m->links[l].points[sp->tree.point_index[id]].mark,
                     "point '%s' of link '%s' %s '%s' over the whole sweep: the mechanism "
                     "assembled folded or degenerate (guesses in initial: for the links "
                     "around it choose the assembly)", m->point_names[id], link_name(m, l),
                     fail_words(MECH_FAIL_ON_GROUND_POINT), m->point_names[g[i].id]);
            break;
        }
    }
    free(g);
}

/* c: a slider whose displacement does not change. */
static void check_sliders(const solver *sv, const int *slot, const assembly_samples *s,
                          double tol, mech_diag *d)
{
    const solver_plan *sp = sv->p;
    const mech_model *m = sp->m;
    for (int j = 0; j < m->njoints; j++) {
        int var = sp->tree.slide_var[j];
        if (m->joints[j].kind != MECH_JOINT_SLIDER || var < 0 || var >= sp->n || slot[var] < 0)
            continue;
        int i = slot[var];
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < s->n; k++) {
            double v = s->x[(size_t)k * (size_t)s->ns + (size_t)i];
            lo = fmin(lo, v);
            hi = fmax(hi, v);
        }
        if (hi - lo <= tol)
            diag_add(d, MECH_SEV_WARNING, MECH_FAIL_STILL_SLIDER, m->file, m->joints[j].mark,
                     "slider '%s' (link '%s' on '%s') %s: its travel over the whole sweep "
                     "is 0 (%.4g mm), a degenerate assembly or a slider that does nothing",
                     m->joints[j].name, link_name(m, m->joints[j].link[0]),
                     link_name(m, m->joints[j].link[1]), fail_words(MECH_FAIL_STILL_SLIDER),
                     (hi - lo) * 1e3);
    }
}

/* The points of loop k (its body vectors' ends, name ids) at the kept
 * position: in line when each is within tol of the line through the two
 * that are furthest apart (then the loop encloses nothing). */
static int loop_flat_at(const solver *sv, const double *P, int kpos, int k, double tol)
{
    const mech_model *m = sv->p->m;
    const loop_set *ls = &sv->p->sys->loops;
    int np = m->npoint_names, ia = -1, ib = -1;
    double far = 0.0;
    for (int t = ls->start[k]; t < ls->start[k + 1]; t++)
        for (int u = t; u < ls->start[k + 1]; u++) {
            const loop_term *x = &ls->terms[t], *y = &ls->terms[u];
            if (x->kind != TERM_BODY || y->kind != TERM_BODY)
                continue;
            int a = m->links[x->link].points[x->p0].id, b = m->links[y->link].points[y->p1].id;
            double dist = hypot(at(P, np, kpos, a)[0] - at(P, np, kpos, b)[0],
                                at(P, np, kpos, a)[1] - at(P, np, kpos, b)[1]);
            if (dist > far)
                far = dist, ia = a, ib = b;
        }
    if (ia < 0 || !(far > tol))
        return 0;  /* no length: nothing to say */
    const double *pa = at(P, np, kpos, ia), *pb = at(P, np, kpos, ib);
    double ux = (pb[0] - pa[0]) / far, uy = (pb[1] - pa[1]) / far;
    for (int t = ls->start[k]; t < ls->start[k + 1]; t++) {
        const loop_term *x = &ls->terms[t];
        if (x->kind != TERM_BODY)
            continue;
        for (int e = 0; e < 2; e++) {
            const double *q = at(P, np, kpos, m->links[x->link].points[e ? x->p1 : x->p0].id);
            if (!(fabs((q[0] - pa[0]) * uy - (q[1] - pa[1]) * ux) <= tol))
                return 0;
        }
    }
    return 1;
}

/* "'upper', 'lower' and the ground": the moving links of loop k, then the
 * ground if in it; the first moving link returned (0: none). */
static int loop_links(const mech_model *m, const loop_set *ls, int k, char *buf, size_t size)
{
    size_t len = 0;
    int ground = 0, first = 0;
    buf[0] = '\0';
    for (int t = ls->start[k]; t < ls->start[k + 1] && len + 1 < size; t++) {
        const loop_term *x = &ls->terms[t];
        if (x->kind != TERM_BODY)
            continue;
        if (x->link == 0) {
            ground = 1;
            continue;
        }
        first = first ? first : x->link;
        int n = snprintf(buf + len, size - len, "%s'%s'", len ? ", " : "", m->links[x->link].name);
        len += n > 0 ? (size_t)n : 0;
    }
    if (ground && len + 1 < size)
        snprintf(buf + len, size - len, "%sthe ground", len ? " and " : "");
    return first;
}

/* d: a loop whose points lie in one line at every kept position: its links
 * folded onto each other (a toggle's lower link back on the upper one). */
static void check_folded(const solver *sv, const double *P, int n, double tol, mech_diag *d)
{
    const mech_model *m = sv->p->m;
    const loop_set *ls = &sv->p->sys->loops;
    for (int k = 0; k < ls->nloops; k++) {
        int kpos = 0;
        while (kpos < n && loop_flat_at(sv, P, kpos, k, tol))
            kpos++;
        if (kpos < n)
            continue;
        char links[300];
        int first = loop_links(m, ls, k, links, sizeof links);
        diag_add(d, MECH_SEV_WARNING, MECH_FAIL_FOLDED_LOOP, m->file, m->links[first].mark,
                 "loop %d (%s) is flat over the whole sweep, its links %s: every point of "
                 "it in one line, two of its links overlapping (guesses in initial: for "
                 "them choose the other assembly)", k + 1, links,
                 fail_words(MECH_FAIL_FOLDED_LOOP));
    }
}

/* e: every output still: the points off the ground, the links (their
 * points), the sliders; *named counts the outputs that could move. */
static int outputs_still(const solver *sv, const double *P, int n, double tol, int *named)
{
    const solver_plan *sp = sv->p;
    const mech_model *m = sp->m;
    const mech_outputs *o = sp->opt.outputs ? sp->opt.outputs : &m->outputs;
    int np = m->npoint_names;
    *named = 0;
    for (int i = 0; i < o->npoints; i++)
        if (sp->tree.point_link[o->points[i]] > 0) {
            ++*named;
            if (!point_still(P, np, n, o->points[i], tol))
                return 0;
        }
    for (int i = 0; i < o->nlinks; i++) {
        const mech_link *l = &m->links[o->links[i]];
        if (l->is_ground)
            continue;
        ++*named;
        for (int p = 0; p < l->npoints; p++)
            if (!point_still(P, np, n, l->points[p].id, tol))
                return 0;
    }
    for (int i = 0; i < o->nsliders; i++) {
        const mech_joint *jt = &m->joints[o->sliders[i]];
        ++*named;
        int pt = m->links[jt->link[0]].points[jt->point[0]].id;
        if (!point_still(P, np, n, pt, tol))
            return 0;
    }
    return 1;
}

static void check_outputs(const solver *sv, const double *P, int n, double tol, mech_diag *d)
{
    const mech_model *m = sv->p->m;
    int named = 0;
    if (outputs_still(sv, P, n, tol, &named) && named > 0)
        diag_add(d, MECH_SEV_WARNING, MECH_FAIL_STILL_OUTPUTS, m->file, m->driver.mark,
                 "the %s %s: every output point, link and slider stays where it is over the "
                 "whole sweep (a degenerate assembly, or outputs: names the wrong parts)",
                 m->driver.kind == MECH_DRIVE_TIME ? "drivers' motion" : "driver's motion",
                 fail_words(MECH_FAIL_STILL_OUTPUTS));
}

void assembly_check(solver *sv, assembly_samples *s, mech_diag *d)
{
    const solver_plan *sp = sv->p;
    const mech_model *m = sp->m;
    int *slot = solved_slots(sp);
    if (!slot) {
        s->skipped = ASSEMBLY_SKIPPED_MEMORY;
        return;
    }
    const double *x_guessed = s->x_guessed ? s->x_guessed : s->has_first ? s->x : NULL;
    if (x_guessed)
        for (int g = 0; g < m->nguesses; g++)
            check_guess(sv, slot, x_guessed, &m->guesses[g], d);
    s->skipped = sp->ns < sp->n ? ASSEMBLY_SKIPPED_PARTIAL  /* links not solved: unplaced */
                 : s->n < 2 || s->q[s->n - 1] == s->q[0] ? ASSEMBLY_SKIPPED_ONE
                                                          : ASSEMBLY_CHECKED;
    double tol = still_fraction(sp) * sp->lref;
    double *P = s->skipped == ASSEMBLY_CHECKED ? sample_points(sv, s) : NULL;
    if (!P) {
        s->skipped = s->skipped == ASSEMBLY_CHECKED ? ASSEMBLY_SKIPPED_MEMORY : s->skipped;
        free(slot);
        return;
    }
    check_on_ground(sv, P, s->n, tol, d);
    check_sliders(sv, slot, s, tol, d);
    check_folded(sv, P, s->n, 100.0 * tol, d);
    check_outputs(sv, P, s->n, tol, d);
    free(P);
    free(slot);
}
