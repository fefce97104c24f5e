/* src/equations/loops.c: independent loops of the link/joint graph, as vector sums.
 * Loops listed in the file (walks of point names) are checked: every step
 * must lie on one link or cross one slider, the walk must cross real joints,
 * and the loops must be independent and as many as the graph has. Without
 * them, a cycle basis comes from a breadth-first spanning tree rooted at the
 * ground: each joint off the tree closes one loop. */
#include <stdlib.h>
#include <string.h>

#include "equations.h"

int loops_attach(const mech_joint *j, int l) { return j->link[0] == l ? j->point[0] : j->point[1]; }

void loops_free(loop_set *ls)
{
    free(ls->terms);
    free(ls->start);
    memset(ls, 0, sizeof *ls);
}

typedef struct term_buf {
    loop_term *t;
    int n, cap;
} term_buf;

static int push(term_buf *b, loop_term t)
{
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 64;
        loop_term *nt = xrealloc_array(b->t, (size_t)cap, sizeof *nt);
        if (!nt)
            return -1;
        b->t = nt;
        b->cap = cap;
    }
    b->t[b->n++] = t;
    return 0;
}

static int push_body(term_buf *b, int link, int p0, int p1)
{
    if (p0 == p1)
        return 0;
    return push(b, (loop_term){TERM_BODY, link, p0, p1, -1, 0});
}

/* Cross joint j from link `from` to the other link: a slider adds +-s dir. */
static int push_crossing(term_buf *b, const mech_joint *j, int ji, int from)
{
    if (j->kind != MECH_JOINT_SLIDER)
        return 0;
    return push(b, (loop_term){TERM_SLIDE, -1, -1, -1, ji, from == j->link[1] ? +1 : -1});
}

/* ---- automatic: cycle basis from the BFS spanning tree (spantree.c) --- */

/* The loop closed by off-tree joint ji: cross ji from a to b, climb from b
 * to the common ancestor, descend to a. Body vectors join consecutive
 * crossings within each link. */
static int cycle_terms(const mech_model *m, const span_tree *g, int ji, term_buf *b, int *path)
{
    const mech_joint *jt = &m->joints[ji];
    int a = jt->link[0], c = jt->link[1];
    /* crossings: list of (joint, from-link) */
    int n = 0;
    path[n++] = ji;
    path[n++] = a;
    int x = a, y = c, nup = 0;
    int *down = path + 2 * (m->njoints + 1);  /* second half: the a-side chain */
    while (x != y) {  /* climb the deeper side until both meet */
        if (g->depth[y] >= g->depth[x]) {
            path[n++] = g->parent_joint[y];
            path[n++] = y;
            y = g->parent_link[y];
        } else {
            down[nup++] = x;
            x = g->parent_link[x];
        }
    }
    for (int k = nup - 1; k >= 0; k--) {  /* descend from the ancestor to a */
        path[n++] = g->parent_joint[down[k]];
        path[n++] = g->parent_link[down[k]];
    }
    /* path holds (joint, from) pairs; the link after crossing k is the
     * "other" side, and it is left by crossing k+1 (cyclically) */
    int ncross = n / 2;
    for (int k = 0; k < ncross; k++) {
        const mech_joint *jk = &m->joints[path[2 * k]];
        int from = path[2 * k + 1];
        int to = jk->link[0] == from ? jk->link[1] : jk->link[0];
        if (push_crossing(b, jk, path[2 * k], from) < 0)
            return -1;
        const mech_joint *jn = &m->joints[path[2 * ((k + 1) % ncross)]];
        if (push_body(b, to, loops_attach(jk, to), loops_attach(jn, to)) < 0)
            return -1;
    }
    return 0;
}

static int build_automatic(const mech_model *m, const span_tree *g, loop_set *ls, mech_diag *d)
{
    term_buf b = {0};
    int nloops = m->njoints - m->nlinks + 1, rc = MECH_EINPUT;
    int *path = xcalloc(4 * ((size_t)m->njoints + 1) + 4, sizeof *path);
    char *tree = xcalloc((size_t)m->njoints + 1, 1);  /* 1: a tree edge */
    ls->start = xcalloc((size_t)(nloops > 0 ? nloops : 0) + 1, sizeof *ls->start);
    if (!path || !tree || !ls->start) {
        rc = diag_nomem(d, m->file, (mech_mark){0, 0});
        goto fail;
    }
    for (int l = 0; l < m->nlinks; l++) {
        if (g->parent_joint[l] >= 0)
            tree[g->parent_joint[l]] = 1;
        if (g->depth[l] < 0) {
            diag_error(d, m->file, m->links[l].mark, "link '%s' is not connected to the ground",
                       m->links[l].name);
            goto fail;
        }
    }
    for (int j = 0; j < m->njoints; j++) {
        if (tree[j])
            continue;
        if (cycle_terms(m, g, j, &b, path) < 0) {
            rc = diag_nomem(d, m->file, (mech_mark){0, 0});
            goto fail;
        }
        ls->start[++ls->nloops] = b.n;
    }
    ls->terms = b.t;
    free(tree);
    free(path);
    return MECH_OK;
fail:
    free(tree);
    free(path);
    free(b.t);
    loops_free(ls);
    return rc;
}

/* ---- loops from the file -------------------------------------------- */

/* Record in row[] the crossing from link a to link b at pin `id`: the
 * revolutes at that point joining them, directly or through other links on
 * the same pin (three links on one pin are joined by two revolutes). Returns
 * 0 when no chain of revolutes at `id` joins a and b. Pins hold few links,
 * so a search over the joints at the point is cheap. */
static int add_crossing(const mech_model *m, int a, int b, int id, double *row)
{
    enum { MAXPIN = 64 };
    int link[MAXPIN], via[MAXPIN], prev[MAXPIN], nl = 0;  /* BFS over links on the pin */
    link[nl] = a, via[nl] = -1, prev[nl++] = -1;
    for (int head = 0; head < nl; head++) {
        if (link[head] == b) {
            for (int k = head; via[k] >= 0; k = prev[k]) {
                const mech_joint *j = &m->joints[via[k]];
                row[via[k]] += j->link[1] == link[k] ? 1.0 : -1.0;  /* crossed link[0] -> link[1] */
            }
            return 1;
        }
        for (int ji = 0; ji < m->njoints && nl < MAXPIN; ji++) {
            const mech_joint *j = &m->joints[ji];
            if (j->kind != MECH_JOINT_REVOLUTE || m->links[j->link[0]].points[j->point[0]].id != id)
                continue;
            int other = j->link[0] == link[head] ? j->link[1] : j->link[1] == link[head] ? j->link[0] : -1;
            int seen = other < 0;
            for (int k = 0; k < nl && !seen; k++)
                seen = link[k] == other;
            if (!seen)
                link[nl] = other, via[nl] = ji, prev[nl++] = head;
        }
    }
    return 0;
}

/* One step P -> Q: the links it starts and ends on, and the terms. */
static int walk_step(const mech_model *m, int P, int Q, term_buf *b, int *start_link,
                     int *end_link, int *slider)
{
    *slider = -1;
    for (int l = 0; l < m->nlinks; l++) {
        int i = model_point_in_link(&m->links[l], P), k = model_point_in_link(&m->links[l], Q);
        if (i >= 0 && k >= 0) {
            *start_link = *end_link = l;
            return push_body(b, l, i, k) < 0 ? -1 : 1;
        }
    }
    for (int ji = 0; ji < m->njoints; ji++) {
        const mech_joint *j = &m->joints[ji];
        if (j->kind != MECH_JOINT_SLIDER)
            continue;
        const mech_link *mover = &m->links[j->link[0]], *guide = &m->links[j->link[1]];
        int pm = model_point_in_link(mover, P), qg = model_point_in_link(guide, Q);
        int qm = model_point_in_link(mover, Q), pg = model_point_in_link(guide, P);
        if (pm == j->point[0] && qg >= 0) {          /* mover's P -> T -> Q on the guide */
            *start_link = j->link[0];
            *end_link = j->link[1];
            *slider = ji;
            if (push_crossing(b, j, ji, j->link[0]) < 0 || push_body(b, j->link[1], j->point[1], qg) < 0)
                return -1;
            return 1;
        }
        if (qm == j->point[0] && pg >= 0) {          /* guide's P -> T -> mover's Q */
            *start_link = j->link[1];
            *end_link = j->link[0];
            *slider = ji;
            if (push_body(b, j->link[1], pg, j->point[1]) < 0 || push_crossing(b, j, ji, j->link[1]) < 0)
                return -1;
            return 1;
        }
    }
    return 0;
}

/* Walk one listed loop; fills row[] (signed joint crossings) for the rank test. */
static int walk_loop(const mech_model *m, const mech_loop *lp, term_buf *b, double *row, mech_diag *d)
{
    int nsteps = lp->npoints - 1, first_link = -1, prev_link = -1, ok = 1;
    for (int s = 0; s < nsteps; s++) {
        int P = lp->points[s], Q = lp->points[s + 1], sl, el, slider;
        int r = walk_step(m, P, Q, b, &sl, &el, &slider);
        if (r < 0)
            return diag_nomem(d, m->file, lp->mark);
        if (r == 0) {
            diag_error(d, m->file, lp->marks[s + 1],
                       "loop step %s -> %s lies on no single link and crosses no slider",
                       m->point_names[P], m->point_names[Q]);
            ok = 0;
            continue;
        }
        if (slider >= 0)
            row[slider] += sl == m->joints[slider].link[0] ? 1.0 : -1.0;
        if (s == 0)
            first_link = sl;
        else if (prev_link >= 0 && prev_link != sl) {
            if (!add_crossing(m, prev_link, sl, P, row)) {
                diag_error(d, m->file, lp->marks[s],
                           "loop passes from link '%s' to link '%s' at '%s', but no joint joins "
                           "them there", m->links[prev_link].name, m->links[sl].name,
                           m->point_names[P]);
                ok = 0;
            }
        }
        prev_link = el;
    }
    if (ok && prev_link != first_link) {
        if (!add_crossing(m, prev_link, first_link, lp->points[0], row)) {
            diag_error(d, m->file, lp->marks[nsteps],
                       "loop closes from link '%s' to link '%s' at '%s', but no joint joins them "
                       "there", m->links[prev_link].name, m->links[first_link].name,
                       m->point_names[lp->points[0]]);
            ok = 0;
        }
    }
    return ok ? MECH_OK : MECH_EINPUT;
}

/* Rank of the loops' joint-crossing rows by forward elimination (the
 * entries are small integers; 1e-9 separates zero from the rest). Each row
 * is reduced by the earlier pivot rows in order, so it is zero exactly when
 * the loop is a combination of the loops before it. */
static int check_independent(const mech_model *m, double *rows, int nl, int nj, mech_diag *d)
{
    int *pivot = xcalloc((size_t)nl, sizeof *pivot);  /* pivot column of row r */
    if (!pivot)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    int rc = MECH_OK;
    for (int r = 0; r < nl && rc == MECH_OK; r++) {
        double *row = rows + (size_t)r * (size_t)nj;
        for (int p = 0; p < r; p++) {
            const double *pr = rows + (size_t)p * (size_t)nj;
            double f = row[pivot[p]] / pr[pivot[p]];
            if (f != 0.0)
                for (int c = 0; c < nj; c++)
                    row[c] -= f * pr[c];
        }
        int pc = 0;
        while (pc < nj && row[pc] < 1e-9 && row[pc] > -1e-9)
            pc++;
        if (pc == nj)
            rc = diag_error(d, m->file, m->loops[r].mark,
                            "loop %d is not independent: it is a combination of the loops "
                            "listed before it", r + 1);
        pivot[r] = pc;
    }
    free(pivot);
    return rc;
}

static int build_from_file(const mech_model *m, loop_set *ls, mech_diag *d)
{
    int needed = m->njoints - m->nlinks + 1;
    if (m->nloops != needed)
        return diag_error(d, m->file, m->loops[0].mark,
                          "the file lists %d loop%s but the mechanism has %d independent loops "
                          "(joints - links + 1 = %d - %d + 1)%s",
                          m->nloops, m->nloops == 1 ? "" : "s", needed, m->njoints, m->nlinks,
                          m->nloops < needed ? "; add the missing loops or remove 'loops' to find them automatically"
                                             : "; remove the extra loops");
    /* Each step of a listed loop searches the links and joints, and the rank
     * test is dense: bound both (docs/limits.md). Automatic loops are linear. */
    double steps = 0, points = 0;
    for (int k = 0; k < m->nloops; k++)
        steps += m->loops[k].npoints;
    for (int l = 0; l < m->nlinks; l++)
        points += m->links[l].npoints;
    if ((double)m->nloops * m->njoints > 1e7 || steps * (points + m->njoints) > 1e9)
        return diag_error(d, m->file, m->loops[0].mark,
                          "listed loops are for small mechanisms: %d loops over %d joints "
                          "and %.0f points is too much work to check; remove 'loops' to find "
                          "them automatically", m->nloops, m->njoints, points);
    term_buf b = {0};
    double *rows = xcalloc((size_t)m->nloops * (size_t)m->njoints, sizeof *rows);
    ls->start = xcalloc((size_t)m->nloops + 1, sizeof *ls->start);
    if (!rows || !ls->start) {
        free(rows);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    int rc = MECH_OK;
    for (int k = 0; k < m->nloops; k++) {
        if (walk_loop(m, &m->loops[k], &b, rows + (size_t)k * (size_t)m->njoints, d) != MECH_OK)
            rc = MECH_EINPUT;
        ls->start[++ls->nloops] = b.n;
    }
    if (rc == MECH_OK)
        rc = check_independent(m, rows, m->nloops, m->njoints, d);
    free(rows);
    ls->terms = b.t;
    ls->from_file = 1;
    if (rc != MECH_OK)
        loops_free(ls);
    return rc;
}

int loops_build(const mech_model *m, const span_tree *t, loop_set *ls, mech_diag *d)
{
    memset(ls, 0, sizeof *ls);
    return m->nloops > 0 ? build_from_file(m, ls, d) : build_automatic(m, t, ls, d);
}
