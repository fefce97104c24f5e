/* src/equations/check.c: the structural check of a loaded model, mech_check
 * (connectivity, Gruebler-Kutzbach mobility, unknowns against equations,
 * links joined twice, rigid triangles). */
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "base.h"
#include "load.h"
#include "equations.h"

static int root_of(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Links not joined to the ground through any chain of joints. */
static int check_connected(const mech_model *m, int *parent, mech_diag *d)
{
    for (int i = 0; i < m->nlinks; i++)
        parent[i] = i;
    for (int j = 0; j < m->njoints; j++)
        parent[root_of(parent, m->joints[j].link[0])] = root_of(parent, m->joints[j].link[1]);
    int bad = 0;
    for (int i = 1; i < m->nlinks; i++)
        if (root_of(parent, i) != root_of(parent, 0)) {
            diag_error(d, m->file, m->links[i].mark,
                       "link '%s' is not connected to the ground by any chain of joints",
                       m->links[i].name);
            bad = 1;
        }
    return !bad;
}

/* A moving link held by a single joint turns (or slides) freely, unless it is
 * the driven one. */
static int report_dangling(const mech_model *m, const int *njoints_of, mech_diag *d)
{
    int found = 0;
    for (int i = 1; i < m->nlinks; i++) {
        if (njoints_of[i] == 1 && !drivers_move_link(m, i)) {
            diag_error(d, m->file, m->links[i].mark,
                       "link '%s' is attached by a single joint, so nothing fixes its position: "
                       "join it to another link or drive it", m->links[i].name);
            found = 1;
        }
    }
    return found;
}

/* Freedoms a joint removes between its two links. */
static int joint_constraints(const mech_joint *j)
{
    return j->kind == MECH_JOINT_SLIDER && !j->locked ? 1 : 2;
}

typedef struct link_pair {
    int a, b;    /* link indices, a < b */
    int joint;   /* first joint between them */
    int second;  /* another joint between them, or -1 */
    int cons;    /* freedoms removed by all the joints between them */
} link_pair;

static int cmp_pair(const void *x, const void *y)
{
    const link_pair *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->joint < q->joint ? -1 : p->joint > q->joint;
}

static int cmp_int(const void *x, const void *y)
{
    int a = *(const int *)x, b = *(const int *)y;
    return a < b ? -1 : a > b;
}

/* Three links pinned to each other in a triangle: one rigid body. */
static void note_triangle(const mech_model *m, const link_pair *e[3], mech_diag *d)
{
    int l[3] = {e[0]->a, e[0]->b, e[1]->a == e[0]->a || e[1]->a == e[0]->b ? e[1]->b : e[1]->a};
    int j[3] = {e[0]->joint, e[1]->joint, e[2]->joint};
    qsort(l, 3, sizeof *l, cmp_int);
    qsort(j, 3, sizeof *j, cmp_int);
    diag_note(d, m->file, m->joints[j[2]].mark,
              "links '%s', '%s' and '%s' are pinned to each other in a triangle (joints '%s', "
              "'%s' and '%s'): together they are one rigid body", m->links[l[0]].name,
              m->links[l[1]].name, m->links[l[2]].name, m->joints[j[0]].name,
              m->joints[j[1]].name, m->joints[j[2]].name);
}

/* The workspace of report_rigid: the pairs of links joined by some joint,
 * and the pairs pinned once as edges directed from their lower-ranked end
 * (degree, then index) in compressed rows. */
typedef struct rigid_work {
    link_pair *pairs;  /* [njoints] pairs of links; the first np are distinct */
    int np;
    int *deg;          /* [nlinks] pairs pinned once at each link */
    int *start;        /* [nlinks + 1] out[start[u] .. start[u+1]-1]: edges from u */
    int *out;          /* [njoints] pair index, by lower-ranked end */
    int *mark;         /* [nlinks] u + 1 when adjacent to u */
    int *via;          /* [nlinks] that pair's index */
} rigid_work;

/* One entry per pair of links, with the freedoms its joints remove, sorted
 * by link indices; sets w->np. */
static void rigid_pairs(const mech_model *m, rigid_work *w)
{
    int nj = m->njoints, np = 0;
    link_pair *pairs = w->pairs;
    for (int i = 0; i < nj; i++) {
        const mech_joint *jt = &m->joints[i];
        int a = jt->link[0] < jt->link[1] ? jt->link[0] : jt->link[1];
        int b = jt->link[0] < jt->link[1] ? jt->link[1] : jt->link[0];
        pairs[i] = (link_pair){a, b, i, -1, joint_constraints(jt)};
    }
    qsort(pairs, (size_t)nj, sizeof *pairs, cmp_pair);
    for (int i = 0; i < nj; i++) {
        link_pair *last = np ? &pairs[np - 1] : NULL;
        if (last && last->a == pairs[i].a && last->b == pairs[i].b) {
            if (last->second < 0)
                last->second = pairs[i].joint;
            last->cons += pairs[i].cons;
        } else {
            pairs[np++] = pairs[i];
        }
    }
    w->np = np;
}

/* Notes on pairs joined twice with no relative motion left, while found < 3;
 * returns the new count. */
static int report_joined_twice(const mech_model *m, const rigid_work *w, int found,
                               mech_diag *d)
{
    for (int i = 0; i < w->np && found < 3; i++) {
        const link_pair *p = &w->pairs[i];
        if (p->second < 0 || p->cons < 3)
            continue;
        const mech_joint *ja = &m->joints[p->joint], *jb = &m->joints[p->second];
        diag_note(d, m->file, jb->mark,
                  "links '%s' and '%s' are joined twice (joints '%s' and '%s'): together they "
                  "are one rigid body", m->links[p->a].name, m->links[p->b].name, ja->name,
                  jb->name);
        found++;
    }
    return found;
}

/* Link u ranks lower than link v: fewer pins, or as many and a lower index. */
static int ranks_lower(const int *deg, int u, int v)
{
    return deg[u] < deg[v] || (deg[u] == deg[v] && u < v);
}

/* The pairs that are each pinned once, as edges directed from the
 * lower-ranked end: w->deg, w->start, w->out (w->mark is left zero). */
static void direct_pins(const mech_model *m, rigid_work *w)
{
    const link_pair *pairs = w->pairs;
    int np = w->np, *deg = w->deg, *start = w->start;
    for (int i = 0; i < np; i++)
        if (pairs[i].cons == 2)
            deg[pairs[i].a]++, deg[pairs[i].b]++;
    for (int i = 0; i < np; i++)
        if (pairs[i].cons == 2)
            start[(ranks_lower(deg, pairs[i].a, pairs[i].b) ? pairs[i].a : pairs[i].b) + 1]++;
    for (int v = 0; v < m->nlinks; v++)
        start[v + 1] += start[v];
    int *fill = w->mark;  /* borrowed, reset below */
    for (int i = 0; i < np; i++)
        if (pairs[i].cons == 2) {
            int u = ranks_lower(deg, pairs[i].a, pairs[i].b) ? pairs[i].a : pairs[i].b;
            w->out[start[u] + fill[u]++] = i;
        }
    memset(w->mark, 0, (size_t)m->nlinks * sizeof *w->mark);
}

/* Notes on triangles of pairs that are each pinned once, while found < 3
 * (each triangle is found once, from its lowest-ranked link); returns the
 * new count. */
static int report_triangles(const mech_model *m, rigid_work *w, int found, mech_diag *d)
{
    const link_pair *pairs = w->pairs;
    const int *start = w->start, *out = w->out;
    int *mark = w->mark, *via = w->via;
    for (int u = 0; u < m->nlinks && found < 3; u++) {
        for (int k = start[u]; k < start[u + 1]; k++) {
            const link_pair *e = &pairs[out[k]];
            int v = e->a == u ? e->b : e->a;
            mark[v] = u + 1;
            via[v] = out[k];
        }
        for (int k = start[u]; k < start[u + 1] && found < 3; k++) {
            const link_pair *e = &pairs[out[k]];
            int v = e->a == u ? e->b : e->a;
            for (int t = start[v]; t < start[v + 1] && found < 3; t++) {
                const link_pair *f = &pairs[out[t]];
                int x = f->a == v ? f->b : f->a;
                if (mark[x] == u + 1) {
                    const link_pair *tri[3] = {e, f, &pairs[via[x]]};
                    note_triangle(m, tri, d);
                    found++;
                }
            }
        }
    }
    return found;
}

/* Rigid sub-structures that explain an over-constraint: two links joined by
 * joints that leave them no relative motion, or three links pinned to each
 * other in a triangle. Notes name at most three; O(J log J + J^1.5).
 * Returns how many were found (d may be NULL: count only). */
static int report_rigid(const mech_model *m, mech_diag *d)
{
    int nj = m->njoints, found = 0;
    rigid_work w = {0};
    w.pairs = xcalloc((size_t)nj, sizeof *w.pairs);
    w.deg = xcalloc((size_t)m->nlinks, sizeof *w.deg);
    w.start = xcalloc((size_t)m->nlinks + 1, sizeof *w.start);
    w.out = xcalloc((size_t)nj, sizeof *w.out);
    w.mark = xcalloc((size_t)m->nlinks, sizeof *w.mark);
    w.via = xcalloc((size_t)m->nlinks, sizeof *w.via);
    if (w.pairs && w.deg && w.start && w.out && w.mark && w.via) {
        rigid_pairs(m, &w);
        found = report_joined_twice(m, &w, found, d);
        direct_pins(m, &w);
        found = report_triangles(m, &w, found, d);
    }
    free(w.pairs);
    free(w.deg);
    free(w.start);
    free(w.out);
    free(w.mark);
    free(w.via);
    return found;
}

static void count_joints(const mech_model *m, mech_summary *s, int *njoints_of)
{
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (jt->kind == MECH_JOINT_REVOLUTE)
            s->nrevolute++;
        else if (jt->locked)
            s->nprismatic++;
        else
            s->npin_in_slot++;
        njoints_of[jt->link[0]]++;
        njoints_of[jt->link[1]]++;
    }
}

static int check_model(const mech_model *m, mech_summary *s, mech_diag *d)
{
    memset(s, 0, sizeof *s);
    s->nlinks = m->nlinks;
    s->ndrivers = m->has_driver ? m->ndrivers : 0;
    int *work = xcalloc((size_t)m->nlinks, sizeof *work);
    int *njoints_of = xcalloc((size_t)m->nlinks, sizeof *njoints_of);
    if (!work || !njoints_of) {
        free(work);
        free(njoints_of);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    count_joints(m, s, njoints_of);
    s->ngears = m->ngears;
    for (int g = 0; g < m->ngears; g++)  /* a mesh holds a gear as a joint does */
        for (int k = 0; k < 2; k++)
            njoints_of[m->gears[g].link[k]]++;
    s->ncams = model_ncams(m);
    for (int c = 0; c < s->ncams; c++)  /* and a cam's contact its cam and follower */
        njoints_of[m->cams->cam[c].cam]++, njoints_of[m->cams->cam[c].follower]++;
    int joints = m->njoints;
    int nangles = m->nlinks - 1 - s->nprismatic;
    int nsliders = s->nprismatic + s->npin_in_slot;
    s->nunknowns = nangles + nsliders - s->ndrivers;
    s->nloops = joints - m->nlinks + 1;
    /* a driver counts as the coordinate it fixes ("- 1 driver" among the
       unknowns), not as its row */
    int rows[ROW_KINDS];
    rows_count(m, s->nloops, rows);
    s->nequations = rows[ROW_LOOP_X] + rows[ROW_LOOP_Y] + rows[ROW_GEAR] + rows[ROW_CAM];
    s->mobility = 3 * (m->nlinks - 1) - 2 * (s->nrevolute + s->nprismatic) - s->npin_in_slot -
                  m->ngears - s->ncams;
    size_t before = d->nerrors, first = d->count;
    int connected = check_connected(m, work, d);
    int dangling = report_dangling(m, njoints_of, d);
    /* drivers with rows (laws) name the drivers in excess or the links left
       free; a sweep of the driver's own value has only that one driver, so a
       wrong count is the linkage's (below) */
    if (connected && !dangling && s->mobility != s->ndrivers && s->mobility > 0 &&
        rows[ROW_DRIVER] > 0) {
        drivers_report_count(m, s->mobility, d);
    } else if (connected && !dangling && s->mobility != s->ndrivers) {
        mech_mark at = m->has_driver ? m->driver.mark : (mech_mark){0, 0};
        int excess = s->mobility - s->ndrivers, abs_excess = excess < 0 ? -excess : excess;
        char gruebler[192];
        char mesh[64];
        check_higher_pairs_text(s, mesh, sizeof mesh);
        snprintf(gruebler, sizeof gruebler, "%d degree%s of freedom (Gruebler: 3*(%d-1) - 2*%d "
                 "- %d%s = %d) but %d driver%s, so %d unknown%s for %d loop equations",
                 s->mobility, s->mobility == 1 || s->mobility == -1 ? "" : "s", m->nlinks,
                 s->nrevolute + s->nprismatic, s->npin_in_slot, mesh, s->mobility, s->ndrivers,
                 s->ndrivers == 1 ? "" : "s", s->nunknowns, s->nunknowns == 1 ? "" : "s", s->nequations);
        if (excess > 0) {
            diag_error(d, m->file, at,
                       "under-constrained: the mechanism has %s; %d more degree%s of freedom "
                       "must be fixed (add a link or a joint%s)", gruebler, abs_excess,
                       abs_excess == 1 ? "" : "s",
                       s->npin_in_slot ? ", or lock a slider's rotation" : "");
        } else if (report_rigid(m, NULL) > 0) {
            diag_error(d, m->file, at,
                       "over-constrained: the mechanism has %s; its joints remove %d degree%s "
                       "of freedom too many (remove a joint%s)", gruebler, abs_excess,
                       abs_excess == 1 ? "" : "s",
                       s->nprismatic ? ", or free a slider's rotation" : "");
            report_rigid(m, d);
        } else {
            /* no rigid sub-structure: the extra constraints may be redundant
               (a parallelogram's extra link); the solver finds out */
            diag_add(d, MECH_SEV_WARNING, MECH_FAIL_REDUNDANT, m->file, at,
                     "over-constrained by the count: the mechanism has %s; %d constraint%s "
                     "too many, so it moves only if %s redundant (as a parallelogram's "
                     "extra link is): the solver checks this at every position",
                     gruebler, abs_excess, abs_excess == 1 ? "" : "s",
                     abs_excess == 1 ? "it is" : "they are");
        }
    }
    if (!m->has_driver)
        diag_error(d, m->file, (mech_mark){0, 0}, "the mechanism has no driver");
    free(work);
    free(njoints_of);
    return d->nerrors > before ? diag_status_since(d, first, MECH_EINPUT) : MECH_OK;
}

void check_higher_pairs_text(const mech_summary *s, char *buf, size_t size)
{
    int n = snprintf(buf, size, "%s", "");
    if (s->ngears)
        n = snprintf(buf, size, " - %d gear%s", s->ngears, s->ngears == 1 ? "" : "s");
    if (s->ncams && n >= 0 && (size_t)n < size)
        snprintf(buf + n, size - (size_t)n, " - %d cam%s", s->ncams, s->ncams == 1 ? "" : "s");
}

int mech_check(const mech_model *m, mech_summary *s, mech_diag *d)
{
    mech_summary unused;
    mech_diag own, *dd = api_diag(d, &own);
    int rc = m ? check_model(m, s ? s : &unused, dd) : api_null(dd, "mech_check", "m");
    api_diag_end(d, &own);
    return rc;
}

