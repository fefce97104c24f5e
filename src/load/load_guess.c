/* src/load/load_guess.c: guesses of the unknowns from points placed in the
 * global frame (docs/format.md 8.1): the point guesses of `initial:` and
 * the drawing of the drawn form. Links are placed from what is known (the
 * ground, the driver, the angle and slider guesses): a link with a known
 * angle and one placed point places the others; a link with two placed
 * points gets its angle from them; a slider with its point and its guide
 * placed gets its displacement. A guess that places nothing is warned about. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

typedef struct placing {
    loader *ld;
    double (*pos)[2];        /* [points] global position, m */
    unsigned char *placed;   /* [points] */
    signed char *from_guess; /* [points] index + 1 into ld->pguess; 0: not a point guess */
    unsigned char *used;     /* [npguess] the guess placed something */
    double *angle;           /* [links] */
    unsigned char *turned;   /* [links] the angle is known */
    unsigned char *slid;     /* [joints] the displacement is known */
    int *pguess_of;          /* [points] index into ld->pguess, or -1 */
    int *locked_of;          /* [links] load_locked_sliders */
} placing;

/* [links] the locked slider whose block each link is (the first such joint),
 * or -1; one pass over the joints, so that callers looping over links stay
 * linear in the size (a chain of 10^4 loops). NULL when out of memory. */
int *load_locked_sliders(const mech_model *m)
{
    int *of = xcalloc((size_t)m->nlinks + 1, sizeof *of);
    if (!of)
        return NULL;
    for (int l = 0; l < m->nlinks; l++)
        of[l] = -1;
    for (int j = m->njoints - 1; j >= 0; j--)
        if (m->joints[j].kind == MECH_JOINT_SLIDER && m->joints[j].locked)
            of[m->joints[j].link[0]] = j;
    return of;
}

static void add_guess(loader *ld, int is_slider, int index, double value, mech_mark at)
{
    mech_model *m = ld->m;
    mech_guess *g = xrealloc_array(m->guesses, (size_t)m->nguesses + 1, sizeof *g);
    if (!g) {
        diag_nomem(ld->d, ld->file, at);
        return;
    }
    m->guesses = g;
    g[m->nguesses++] = (mech_guess){is_slider, index, value, at};
}

static void mark_used(placing *pl, int id)
{
    int g = pl->pguess_of[id];
    if (g >= 0 && pl->from_guess[id])
        pl->used[g] = 1;
}

/* Two points of link l placed apart, in the link and in the plane: their
 * indices in the link, or 0. */
static int two_placed(const placing *pl, const mech_link *l, int *a, int *b)
{
    for (int i = 0; i < l->npoints; i++) {
        if (!pl->placed[l->points[i].id])
            continue;
        for (int k = i + 1; k < l->npoints; k++) {
            const mech_point *p = &l->points[i], *q = &l->points[k];
            if (!pl->placed[q->id])
                continue;
            double dl = hypot(q->x - p->x, q->y - p->y);
            double dg = hypot(pl->pos[q->id][0] - pl->pos[p->id][0],
                              pl->pos[q->id][1] - pl->pos[p->id][1]);
            double size = fmax(fmax(fabs(p->x), fabs(p->y)), fmax(fabs(q->x), fabs(q->y)));
            if (dl > 1e-12 * fmax(size, 1e-9) && dg > 1e-12 * fmax(size, 1e-9)) {
                *a = i;
                *b = k;
                return 1;
            }
        }
    }
    return 0;
}

/* Link li with its angle known and one point placed: place the others. */
static int place_link(placing *pl, int li)
{
    const mech_link *l = &pl->ld->m->links[li];
    int anchor = -1, changed = 0;
    for (int i = 0; i < l->npoints && anchor < 0; i++)
        if (pl->placed[l->points[i].id])
            anchor = i;
    if (anchor < 0)
        return 0;
    const mech_point *o = &l->points[anchor];
    double c = cos(pl->angle[li]), s = sin(pl->angle[li]);
    for (int i = 0; i < l->npoints; i++) {
        const mech_point *p = &l->points[i];
        if (pl->placed[p->id])
            continue;
        double dx = p->x - o->x, dy = p->y - o->y;
        pl->pos[p->id][0] = pl->pos[o->id][0] + c * dx - s * dy;
        pl->pos[p->id][1] = pl->pos[o->id][1] + s * dx + c * dy;
        pl->placed[p->id] = 1;
        mark_used(pl, o->id);
        changed = 1;
    }
    return changed;
}

/* Link li's angle from two placed points: a guess. */
static int turn_link(placing *pl, int li)
{
    const mech_link *l = &pl->ld->m->links[li];
    int a, b;
    if (!two_placed(pl, l, &a, &b))
        return 0;
    const mech_point *p = &l->points[a], *q = &l->points[b];
    double global = atan2(pl->pos[q->id][1] - pl->pos[p->id][1],
                          pl->pos[q->id][0] - pl->pos[p->id][0]);
    pl->angle[li] = global - atan2(q->y - p->y, q->x - p->x);
    pl->turned[li] = 1;
    int g = pl->pguess_of[q->id] >= 0 && pl->from_guess[q->id] ? q->id : p->id;
    mark_used(pl, p->id);
    mark_used(pl, q->id);
    mech_mark at = pl->pguess_of[g] >= 0 ? pl->ld->pguess[pl->pguess_of[g]].mark : l->mark;
    add_guess(pl->ld, 0, li, pl->angle[li], at);
    return 1;
}

/* Slider j's displacement from its placed point and guide: a guess. */
static int slide(placing *pl, int j)
{
    const mech_model *m = pl->ld->m;
    const mech_joint *jt = &m->joints[j];
    const mech_link *block = &m->links[jt->link[0]], *guide = &m->links[jt->link[1]];
    int b = block->points[jt->point[0]].id, t = guide->points[jt->point[1]].id;
    if (!pl->placed[b] || !pl->placed[t] || !pl->turned[jt->link[1]])
        return 0;
    double a = pl->angle[jt->link[1]] + jt->angle;
    double s = (pl->pos[b][0] - pl->pos[t][0]) * cos(a) + (pl->pos[b][1] - pl->pos[t][1]) * sin(a);
    pl->slid[j] = 1;
    mark_used(pl, b);
    add_guess(pl->ld, 1, j, s, pl->pguess_of[b] >= 0 ? pl->ld->pguess[pl->pguess_of[b]].mark
                                                      : jt->mark);
    return 1;
}

/* Place what the known angles and points give, until nothing changes. */
static void propagate(placing *pl)
{
    const mech_model *m = pl->ld->m;
    for (int changed = 1; changed;) {
        changed = 0;
        for (int li = 1; li < m->nlinks; li++) {
            int j = pl->locked_of[li];
            if (!pl->turned[li] && j >= 0 && pl->turned[m->joints[j].link[1]]) {
                pl->angle[li] = pl->angle[m->joints[j].link[1]];  /* turns with its guide */
                pl->turned[li] = 1;
            }
            if (!pl->turned[li] && j < 0)
                changed |= turn_link(pl, li);
            if (pl->turned[li])
                changed |= place_link(pl, li);
        }
        for (int j = 0; j < m->njoints; j++)
            if (m->joints[j].kind == MECH_JOINT_SLIDER && !pl->slid[j])
                changed |= slide(pl, j);
    }
}

/* What is known before any point: the ground, the driver at start value q0,
 * the file's guesses. */
static void known_at_start(placing *pl, double q0)
{
    const mech_model *m = pl->ld->m;
    pl->turned[0] = 1;
    for (int i = 0; i < m->links[0].npoints; i++) {
        const mech_point *p = &m->links[0].points[i];
        pl->pos[p->id][0] = p->x;
        pl->pos[p->id][1] = p->y;
        pl->placed[p->id] = 1;
    }
    if (m->has_driver && m->driver.kind == MECH_DRIVE_ANGLE) {
        pl->angle[m->driver.index] = q0;
        pl->turned[m->driver.index] = 1;
    } else if (m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER) {
        pl->slid[m->driver.index] = 1;
    }
    for (int g = 0; g < m->nguesses; g++) {
        const mech_guess *gs = &m->guesses[g];
        if (gs->is_slider) {
            pl->slid[gs->index] = 1;
        } else {
            pl->angle[gs->index] = gs->value;
            pl->turned[gs->index] = 1;
        }
    }
}

/* Why point guess g placed nothing. */
static void warn_unused(placing *pl, int g)
{
    loader *ld = pl->ld;
    const point_guess *pg = &ld->pguess[g];
    const char *name = ld->m->point_names[pg->id];
    if (load_point_in_link(ld, 0, pg->id) >= 0) {
        diag_warning(ld->d, ld->file, pg->mark, "the initial guess for point '%s' has no "
                     "effect: '%s' is a point of the ground, which does not move", name, name);
        return;
    }
    if (!pl->from_guess[pg->id]) {
        diag_warning(ld->d, ld->file, pg->mark, "the initial guess for point '%s' has no "
                     "effect: the ground, the driver and the other guesses already place it",
                     name);
        return;
    }
    int first, end, turned = 1;
    load_carriers_of(ld, pg->id, &first, &end);
    for (int k = first; k < end; k++)
        turned &= pl->turned[ld->carrier_link[k]];
    if (turned)
        diag_warning(ld->d, ld->file, pg->mark, "the initial guess for point '%s' has no "
                     "effect: the links that carry it have their angles from the driver or "
                     "the other guesses", name);
    else
        diag_warning(ld->d, ld->file, pg->mark, "the initial guess for point '%s' has no "
                     "effect: no link that carries it has a second point placed by the "
                     "ground, the driver or the other guesses (guess one more point of one "
                     "of its links)", name);
}

/* The point guesses, not yet placed by what is known, placed as guessed. */
static void place_point_guesses(placing *pl)
{
    for (int g = 0; g < pl->ld->npguess; g++) {
        int id = pl->ld->pguess[g].id;
        pl->pguess_of[id] = g;
        if (pl->placed[id])
            continue;
        pl->pos[id][0] = pl->ld->pguess[g].xy[0];
        pl->pos[id][1] = pl->ld->pguess[g].xy[1];
        pl->placed[id] = 1;
        pl->from_guess[id] = 1;
    }
}

/* The drawn positions of the points still unplaced. */
static void place_drawn(placing *pl)
{
    for (int id = 0; id < pl->ld->m->npoint_names; id++)
        if (!pl->placed[id] && load_drawn_at(pl->ld, id, pl->pos[id]))
            pl->placed[id] = 1;
}

/* ---- the drawn driver value ------------------------------------------ */

/* A link's angle at the drawing, from two of its drawn points; 0 when it
 * has none apart. */
static int drawn_link_angle(const loader *ld, int li, double *angle)
{
    const mech_link *l = &ld->m->links[li];
    if (li == 0)
        return *angle = 0.0, 1;
    for (int i = 0; i < l->npoints; i++)
        for (int k = i + 1; k < l->npoints; k++) {
            double p[2], q[2];
            const mech_point *a = &l->points[i], *b = &l->points[k];
            if (!load_drawn_at(ld, a->id, p) || !load_drawn_at(ld, b->id, q) ||
                hypot(b->x - a->x, b->y - a->y) == 0.0)
                continue;
            *angle = atan2(q[1] - p[1], q[0] - p[0]) - atan2(b->y - a->y, b->x - a->x);
            return 1;
        }
    return 0;
}

/* The driver's value at the drawing; 0 when it cannot be told. */
static int drawn_driver_value(const loader *ld, double *q)
{
    const mech_model *m = ld->m;
    if (m->driver.kind == MECH_DRIVE_ANGLE)
        return drawn_link_angle(ld, m->driver.index, q);
    const mech_joint *j = &m->joints[m->driver.index];
    const mech_link *block = &m->links[j->link[0]], *guide = &m->links[j->link[1]];
    double b[2], t[2], g;
    if (!load_drawn_at(ld, block->points[j->point[0]].id, b) ||
        !load_drawn_at(ld, guide->points[j->point[1]].id, t) ||
        !drawn_link_angle(ld, j->link[1], &g))
        return 0;
    *q = (b[0] - t[0]) * cos(g + j->angle) + (b[1] - t[1]) * sin(g + j->angle);
    return 1;
}

/* The sweep starts at the drawn driver value: inside the range, or reduced
 * modulo a turn into a range of a full turn. 0 when reported. */
static int drawn_start(loader *ld)
{
    mech_model *m = ld->m;
    const mech_driver *dr = &m->driver;
    double q, lo = INFINITY, hi = -INFINITY, turn = 2.0 * 3.14159265358979323846;
    if (!m->has_driver || dr->kind == MECH_DRIVE_TIME || !drawn_driver_value(ld, &q))
        return 1;
    for (int i = 0; i < dr->nvalues; i++)
        lo = fmin(lo, dr->values[i]), hi = fmax(hi, dr->values[i]);
    double slack = 1e-9 * fmax(fabs(hi - lo), dr->kind == MECH_DRIVE_ANGLE ? 1.0 : 1e-6);
    if (dr->kind == MECH_DRIVE_ANGLE && hi - lo >= turn - slack)
        q = lo + fmod(fmod(q - lo, turn) + turn, turn);
    if (q < lo - slack || q > hi + slack) {
        int angle = dr->kind == MECH_DRIVE_ANGLE;
        double k = angle ? 180.0 / 3.14159265358979323846 : 1e3;
        const char *u = angle ? "deg" : "mm";
        diag_error(ld->d, ld->file, dr->mark, "the drawing puts the driver at %.6g %s, outside "
                   "its range %.6g to %.6g %s (draw it inside, or widen the range)", q * k, u,
                   lo * k, hi * k, u);
        return 0;
    }
    m->has_start = 1;
    m->start_q = fmin(fmax(q, lo), hi);
    return 1;
}

/* ---- the guesses ------------------------------------------------------ */

void load_guesses_from_points(loader *ld)
{
    mech_model *m = ld->m;
    if ((!ld->drawn && !ld->npguess) || ld->d->nerrors || !ld->m->npoint_names)
        return;
    if (ld->drawn && !drawn_start(ld))
        return;
    size_t np = (size_t)m->npoint_names, nl = (size_t)m->nlinks;
    placing pl = {ld};
    pl.pos = xcalloc(np, sizeof *pl.pos);
    pl.placed = xcalloc(np, 1);
    pl.from_guess = xcalloc(np, 1);
    pl.pguess_of = xcalloc(np, sizeof *pl.pguess_of);
    pl.used = xcalloc((size_t)ld->npguess + 1, 1);
    pl.angle = xcalloc(nl, sizeof *pl.angle);
    pl.turned = xcalloc(nl, 1);
    pl.slid = xcalloc((size_t)m->njoints + 1, 1);
    pl.locked_of = load_locked_sliders(m);
    if (pl.pos && pl.placed && pl.from_guess && pl.pguess_of && pl.used && pl.angle &&
        pl.turned && pl.slid && pl.locked_of) {
        for (size_t i = 0; i < np; i++)
            pl.pguess_of[i] = -1;
        double q0 = m->has_start ? m->start_q : m->has_driver ? m->driver.values[0] : 0.0;
        known_at_start(&pl, q0);
        propagate(&pl);
        place_point_guesses(&pl);
        propagate(&pl);
        for (int g = 0; g < ld->npguess; g++)
            if (!pl.used[g])
                warn_unused(&pl, g);
        place_drawn(&pl);
        propagate(&pl);
    } else {
        diag_nomem(ld->d, ld->file, (mech_mark){0, 0});
    }
    void *blocks[] = {pl.pos, pl.placed, pl.from_guess, pl.pguess_of, pl.used, pl.angle,
                      pl.turned, pl.slid, pl.locked_of};
    for (size_t i = 0; i < COUNT(blocks); i++)
        free(blocks[i]);
}
