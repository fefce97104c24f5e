/* src/equations/spantree.c: the breadth-first spanning tree of the links (spantree.h). */
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "equations.h"

void span_tree_free(span_tree *t)
{
    free(t->order);
    free(t->parent_joint);
    free(t->parent_link);
    free(t->depth);
    memset(t, 0, sizeof *t);
}

/* Joints of each link as compressed lists: adj[start[l] .. start[l+1]-1],
 * in joint order (so the tree does not depend on anything but the file). */
static int joint_lists(const mech_model *m, int **start, int **adj)
{
    *start = xcalloc((size_t)m->nlinks + 1, sizeof **start);
    *adj = xcalloc(2 * (size_t)m->njoints + 1, sizeof **adj);
    int *fill = xcalloc((size_t)m->nlinks + 1, sizeof *fill);
    if (!*start || !*adj || !fill) {
        free(fill);
        return -1;
    }
    for (int j = 0; j < m->njoints; j++)
        for (int side = 0; side < 2; side++)
            (*start)[m->joints[j].link[side] + 1]++;
    for (int l = 0; l < m->nlinks; l++)
        (*start)[l + 1] += (*start)[l];
    for (int j = 0; j < m->njoints; j++)
        for (int side = 0; side < 2; side++) {
            int l = m->joints[j].link[side];
            (*adj)[(*start)[l] + fill[l]++] = j;
        }
    free(fill);
    return 0;
}

static void breadth_first(const mech_model *m, span_tree *t, const int *start, const int *adj)
{
    for (int l = 0; l < m->nlinks; l++) {
        t->parent_joint[l] = -1;
        t->parent_link[l] = -1;
        t->depth[l] = l == 0 ? 0 : -1;
    }
    int head = 0, tail = 0, here = 0;  /* t->order is the queue */
    for (;;) {
        for (int k = start[here]; k < start[here + 1]; k++) {
            const mech_joint *jt = &m->joints[adj[k]];
            int there = jt->link[0] == here ? jt->link[1] : jt->link[0];
            if (t->depth[there] >= 0)
                continue;
            t->depth[there] = t->depth[here] + 1;
            t->parent_joint[there] = adj[k];
            t->parent_link[there] = here;
            t->order[tail++] = there;
        }
        if (head == tail)
            break;
        here = t->order[head++];
    }
    t->norder = tail;
}

int span_tree_build(const mech_model *m, span_tree *t)
{
    memset(t, 0, sizeof *t);
    size_t nl = (size_t)m->nlinks + 1;
    t->order = xcalloc(nl, sizeof *t->order);
    t->parent_joint = xcalloc(nl, sizeof *t->parent_joint);
    t->parent_link = xcalloc(nl, sizeof *t->parent_link);
    t->depth = xcalloc(nl, sizeof *t->depth);
    int *start = NULL, *adj = NULL;
    int ok = t->order && t->parent_joint && t->parent_link && t->depth &&
             joint_lists(m, &start, &adj) == 0;
    if (ok)
        breadth_first(m, t, start, adj);
    free(start);
    free(adj);
    if (!ok)
        span_tree_free(t);
    return ok ? 0 : -1;
}
