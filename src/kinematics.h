/* src/kinematics.h: from solved unknowns to link frames and point motion.
 *
 * The loop equations give link angles and slider displacements; the frame
 * origin of every link follows by walking a spanning tree of the joints
 * from the ground (the system's span_tree, breadth first, so each point is
 * reached by the shortest chain of links). Velocities and accelerations use the rigid-body and
 * sliding-point formulas, exact for the solved rates. */
#ifndef MECH_KINEMATICS_H
#define MECH_KINEMATICS_H

#include "system.h"

typedef struct kin_tree {
    const mech_model *model;
    int n;              /* unknowns of the system; variable n is the driver q */
    const span_tree *span; /* the system's spanning tree (borrowed): frames are placed
                              in its order, each from its parent */
    int *angle_var;     /* [nlinks] variable of the link angle: -1 zero (ground), 0..n */
    int *slide_var;     /* [njoints] variable of a slider's displacement, else -1 */
    int *point_link;    /* [npoint_names] the carrier link of a point name nearest the ground */
    int *point_index;   /* [npoint_names] the point's index in that link */
    unsigned char *active; /* [nlinks] frames to compute (kin_mark_point/link) */
    unsigned char *keep_cs; /* [nlinks] cos and sin kin_update keeps (kin_tree_finish):
                              the active links, their parents, the springs' links */
    double *attach;     /* [4 nlinks] link l is placed from its parent through the joint's
                           point: at attach[4l], [4l+1] in the parent's frame (revolute: the
                           pin; slider: the guide's point), at [4l+2], [4l+3] in l's */
} kin_tree;

/* Positions, velocities and accelerations of every active link frame. */
typedef struct kin_state {
    double *th, *om, *al;   /* [nlinks] angle, angular velocity, angular acceleration */
    double *c, *s;          /* [nlinks] cos and sin of cth (ground: 1, 0): computed by
                               kin_update for the links of kin_tree.keep_cs when th has
                               changed, for every link by kin_refresh_all */
    double *cth;            /* [nlinks] the angle c and s belong to */
    double *o, *vo, *ao;    /* [2 nlinks] frame origin and its rates */
    double *guide;          /* [3 (last slider joint + 1)] a slider's guide angle, its cos
                               and sin, kept while the angle does not change (a ground
                               guide: always) */
} kin_state;

int kin_tree_build(kin_tree *t, const mech_system *s);
void kin_tree_free(kin_tree *t);

/* Variables (unknowns 0..n-1) a quantity depends on: sets need[v] = 1 and
 * activates the link frames involved. */
void kin_need_point(kin_tree *t, int name_id, unsigned char *need);
void kin_need_link(kin_tree *t, int link, unsigned char *need);

int kin_state_init(kin_state *st, const mech_model *m);
void kin_state_free(kin_state *st);

/* Frames of the active links. pos, vel, acc hold the variables 0..n (n is
 * the driver); vel and acc may be NULL (rates not computed). */
void kin_update(const kin_tree *t, kin_state *st, const double *pos, const double *vel,
                const double *acc);

/* Position p[2], velocity v[2], acceleration a[2] of a point name (v or a may
 * be NULL when not computed): of a point on a link kin_update placed (the
 * outputs' and branches'), or after kin_refresh_all. kin_on_link: the same
 * for a link of keep_cs (forces: every link; springs: theirs). */
/* Once the active links are chosen: the links whose cos and sin kin_update
 * keeps (keep_cs). */
void kin_tree_finish(kin_tree *t);
/* cos and sin of every link's angle (kin_update keeps only those of
 * keep_cs): before kin_point on any link (diagnostics). The frames of links
 * not placed stay as they were. */
void kin_refresh_all(const kin_tree *t, kin_state *st);
void kin_point(const kin_tree *t, const kin_state *st, int name_id, double *p, double *v,
               double *a);

/* Point r (link frame) of link l: position p, velocity v, acceleration a. */
void kin_on_link(const kin_state *st, int l, const double *r, double *p, double *v, double *a);

#endif
