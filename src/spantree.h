/* src/spantree.h: the breadth-first spanning tree of the link/joint graph,
 * rooted at the ground; built once per system (system.c). The automatic
 * loops are closed by its off-tree joints (loops.c), and the link frames
 * are placed along it, each from its parent (kinematics.c), so each point
 * is reached by the shortest chain of links. */
#ifndef MECH_SPANTREE_H
#define MECH_SPANTREE_H

#include "mech.h"

typedef struct span_tree {
    int *order;         /* [norder] links reached, in breadth-first order, ground excluded */
    int norder;
    int *parent_joint;  /* [nlinks] joint to the parent link (-1: the ground, unreachable) */
    int *parent_link;   /* [nlinks] (-1 likewise) */
    int *depth;         /* [nlinks] joints from the ground (-1: unreachable) */
} span_tree;

/* 0, or -1 when out of memory. Links not connected to the ground keep
 * depth -1 (loops.c reports them). */
int span_tree_build(const mech_model *m, span_tree *t);
void span_tree_free(span_tree *t);

#endif
