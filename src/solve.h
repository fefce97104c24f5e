/* src/solve.h: the numerical core of the sweep and the forces: the plan
 * (the subset of unknowns to solve, its tape and pattern analysis; built
 * once, shared) and the state (x, rates, registers, factors; per thread),
 * with one driver position's Newton solve and its rate solves. */
#ifndef MECH_SOLVE_H
#define MECH_SOLVE_H

#include "kinematics.h"
#include "linsys.h"
#include "system.h"

typedef enum {
    STEP_OK,
    STEP_NO_ASSEMBLY,  /* Newton does not converge: the loops cannot close */
    STEP_SINGULAR,     /* converged (or stuck) where the Jacobian is singular */
    STEP_JUMP,         /* converged far from the prediction: possibly another branch */
    STEP_BRANCH        /* converged on the other side of a declared branch */
} step_status;

/* What is fixed for a mechanism and a choice of outputs (built once by
 * solver_plan_init, then read only: threads share it). */
typedef struct solver_plan {
    mech_system *sys;          /* owned */
    const mech_model *m;
    mech_solve_options opt;
    int level;                 /* MECH_WANT_* bits actually computed */
    double lref;               /* largest length of the mechanism, m */
    double ftol;               /* residual tolerance, m */

    /* the solved subset: blocks of the block triangular form that outputs need */
    int n;                     /* all unknowns */
    int ns;                    /* unknowns solved */
    int nr;                    /* equations solved: ns, or more with redundant ones */
    int aug;                   /* 1: least squares ([I J; J^T 0]), redundant constraints */
    int *col;                  /* [ns] unknown of each solved column */
    int *row;                  /* [nr] equation of each solved row */
    int nblocks, nblocks_solved;
    int N;                     /* order of the factored matrix: ns, or nr + ns */
    int *Ap, *Ai;              /* [N+1], [nnz] pattern of the factored matrix */
    double *Ax0;               /* [nnz] its constant values (least squares: the identity
                                  block), the image every state starts from */
    int nnz;
    int nnzJ;                  /* nonzeros of the solved part of the Jacobian */
    int *jpos;                 /* [2 nnzJ] least squares: where each J value goes in Ax */
    tape tp;                   /* evaluator of the solved rows only (no registers) */
    ex *proot, *vroot, *aroot; /* roots of the three phases */
    int *preg, *vreg, *areg;   /* [nr + nnzJ], [nr], [nr] their registers in tp */
    int *xreg, *xdreg;         /* [ns] register of each solved unknown and of its rate
                                  (-1: the tape does not read it) */
    double *unit;              /* [ns] 1 for an angle, lref for a slide (step sizes) */
    linsys_plan lp;            /* analysis of the factored matrix's pattern */
    kin_tree tree;             /* link frames: the spanning tree, active links */
} solver_plan;

/* What changes from one driver position to the next: one per thread. */
typedef struct solver {
    const solver_plan *p;      /* borrowed: must outlive the state */
    double *reg;               /* [p->tp.nreg] the tape's registers */
    double tape_q;             /* driver position of the registers' invariant part */
    double *Ax;                /* [nnz] values, columns equilibrated */
    double *Jv;                /* [nnzJ] the Jacobian's values, in J's CSC order */
    double *rhs;               /* [N] solve work */
    double *cscale;            /* [ns] column scaling of the last factorisation */
    linsys ls;                 /* factors of the equilibrated Jacobian */
    double rcond;              /* reciprocal condition at the last converged position
                                  (the worst diagonal block's) */
    double rcond_whole;        /* the whole Jacobian's (the rounding floor of Newton's
                                  step): far smaller along a chain of blocks */

    double *pos, *vel, *acc;   /* [n+1] variable values (n = driver), SI */
    double *x;                 /* [ns] current solved unknowns */
    double *xq, *xqq;          /* [ns] dx/dq and d2x/dq2 at x */
    double *f, *ft;            /* [nr] residuals */
    double *dx, *xt;           /* [ns] work */
    double resid;              /* |f|inf at x */
    int iters;                 /* Newton iterations of the last solve */

    int generation;            /* counts changes of x and its rates */
    int published;             /* generation of the last full publish (-1: none) */
    double pub_q, pub_qd, pub_qdd; /* and its driver state */
    kin_state ks;              /* link frames at the published position */
} solver;

/* Build the system of a checked model, choose the blocks the outputs need,
 * compile their tape and analyse their pattern. */
int solver_plan_init(solver_plan *sp, const mech_model *m, const mech_solve_options *o,
                     mech_diag *d);
void solver_plan_free(solver_plan *sp);
/* The same with a system built beforehand (SYS_NUMERIC or SYS_REGISTERS, of
 * m), owned by the plan from here on, also when this fails; NULL: built
 * here. The length scale lref of m (tolerances, slide steps). */
int solver_plan_init_with(solver_plan *sp, const mech_model *m, const mech_solve_options *o,
                          mech_system *sys, mech_diag *d);
double solver_largest_length(const mech_model *m);
/* plan_compact.c: free what only the set-up needed (the system's DAG,
 * symbolic rows and tape, LaTeX names, the tape's node map and roots); the
 * plan still solves, but codegen and sys_eval_* can no longer use it. */
void solver_plan_compact(solver_plan *sp);

/* A numeric state for the plan (allocates everything a step needs). */
int solver_init(solver *sv, const solver_plan *sp);
void solver_free(solver *sv);


/* Newton from sv->x at driver position q; on STEP_OK the factors are those
 * of the converged Jacobian. */
step_status solver_newton(solver *sv, double q);
/* dx/dq and d2x/dq2 at the converged position (both always: the predictor
 * uses them). */
void solver_rates(solver *sv);
/* Scatter x, and the rates for driver speed qd and acceleration qdd, into
 * pos, vel, acc and update the link frames. */
void solver_publish(solver *sv, double q, double qd, double qdd);  /* again: no work */

/* Sign of det of the factored matrix (+1, -1, 0 singular): a change between
 * two positions means the sweep crossed a singular one. */
int solver_det_sign(solver *sv);
/* -df/dq (the velocity right-hand side for q' = 1) at the last position
 * evaluated, for the nr solved rows. */
void solver_velocity_rhs(solver *sv, double *out);

/* |v|inf, and the size of a change of the solved unknowns (angles in rad,
 * slides in units of lref). */
double vec_norm_inf(const double *v, int n);
double solver_step_size(const solver_plan *sp, const double *dx);

#endif
