/* src/system.h: the equation system built once per mechanism: unknowns,
 * loops, the symbolic residual and its derivatives, and the compiled tape. */
#ifndef MECH_SYSTEM_H
#define MECH_SYSTEM_H

#include "expr.h"
#include "spantree.h"
#include "internal.h"
#include "tape.h"

/* A piece of one loop's vector sum. */
typedef enum { TERM_BODY, TERM_SLIDE } loop_term_kind;
typedef struct loop_term {
    loop_term_kind kind;
    int link;        /* BODY: the link; the vector runs from point p0 to p1 */
    int p0, p1;      /* BODY: point indices in the link */
    int joint;       /* SLIDE: the slider joint */
    int sign;        /* SLIDE: +1 guide->mover (+s dir), -1 mover->guide */
} loop_term;

typedef struct loop_set {
    loop_term *terms;   /* [start[nloops]] */
    int *start;         /* [nloops + 1] terms of loop k: start[k] .. start[k+1]-1 */
    int nloops;
    int from_file;      /* 1 when the file listed the loops */
} loop_set;

/* Unknown kinds */
typedef enum { UNK_ANGLE, UNK_SLIDE } unknown_kind;

/* Variable numbering inside the DAG, for n unknowns:
 *   0..n-1 positions x, n the driver q,
 *   n+1..2n velocities xdot, 2n+1 qdot, 2n+2 qddot. */
#define SYS_VAR_Q(n) (n)
#define SYS_VAR_XDOT(n, i) ((n) + 1 + (i))
#define SYS_VAR_QDOT(n) (2 * (n) + 1)
#define SYS_VAR_QDDOT(n) (2 * (n) + 2)
#define SYS_NVARS(n) (2 * (n) + 3)

struct mech_system {
    const mech_model *model;   /* borrowed; must outlive the system */
    int n;                     /* unknowns */
    int m;                     /* equations, 2 per loop: n, or more with redundant
                                  constraints (solved in the least-squares sense) */
    unknown_kind *unk_kind;    /* [n] */
    int *unk_index;            /* [n] link index (ANGLE) or joint index (SLIDE) */
    int *link_var;             /* [nlinks] unknown of the link's angle, or -1 */
    int *joint_var;            /* [njoints] unknown of a slider's displacement, or -1 */
    ex *link_angle;            /* [nlinks] expression of each link's angle */
    ex *slide;                 /* [njoints] expression of each slider's displacement */
    char **names;              /* [SYS_NVARS(n)] text names of variables */
    char **latex;              /* [SYS_NVARS(n)] LaTeX names */
    span_tree span;            /* breadth-first spanning tree of the links */
    loop_set loops;
    expr_ctx ex;
    ex *f;                     /* [m] residual rows; row 2k, 2k+1 = loop k, x and y */
    int *Jp;                   /* [n+1] column pointers of the m x n Jacobian df/dx (CSC) */
    int *Ji;                   /* [nnz] row indices, ascending within a column */
    ex *Jx;                    /* [nnz] nonzero expressions */
    int nnz;
    ex *fq;                    /* [m] df/dq */
    ex *vel;                   /* [m] velocity right-hand side  -df/dq qdot */
    ex *acc;                   /* [m] acceleration right-hand side */
    tape tp;                   /* compiled evaluator of every row */
    double *reg;               /* [tp.nreg] its registers, for sys_eval_* (so those
                                  are not for threads sharing the system; the solver
                                  compiles its own tape and keeps registers per state) */
};

/* Evaluation through the tape (no allocation). The velocity and
 * acceleration phases reuse the position phase's registers, so they must
 * follow a position evaluation at the same x and q. */
void sys_eval_position(mech_system *s, const double *x, double q, double *f, double *Jx);
void sys_eval_velocity_rhs(mech_system *s, double qdot, double *rhs);
void sys_eval_accel_rhs(mech_system *s, const double *xdot, double qdot, double qddot,
                        double *rhs);

/* loops.c: the loops from the file (checked) or a cycle basis (the joints
 * off the spanning tree t). */
int loops_build(const mech_model *m, const span_tree *t, loop_set *ls, mech_diag *d);
void loops_free(loop_set *ls);
/* Attachment point of joint j on link l (point index in l). */
int loops_attach(const mech_joint *j, int l);

#endif
