/* src/solve/solve.h: the numeric solve: linear solves (dense blocks or KLU), the link frames,
 * Newton and the rates, continuation along the sweep, diagnosis of failures. The stage's one
 * header: what its modules share with each other and with the later stages (docs/architecture.md,
 * "Stages"). */
#ifndef MECH_SOLVE_STAGE_H
#define MECH_SOLVE_STAGE_H

#include <klu.h>

#include "rt_blocklu.h"
#include "mech.h"
#include "rt_frame.h"
#include "equations.h"

/* ==== blocklu ==== */
/* blocklu.c: LU factors of a square sparse matrix whose block
 * triangular form has only small diagonal blocks (docs/solver.md, section
 * "Linear solves"). Each diagonal block is stored dense and factored with
 * partial pivoting; the entries above the blocks stay sparse. Analysis
 * (blocklu_plan) and the factors (blocklu) are apart, like KLU's symbolic
 * and numeric objects; factor, solve and the condition estimate allocate
 * nothing. The kernels are src/runtime/rt_blocklu.h's, which the generated code
 * (`mech codegen`) carries too. */
/* Largest diagonal block factored dense: beyond it KLU is used (linsys.c). */
enum { BLOCKLU_MAX_BLOCK = RT_MAX_BLOCK };

/* The analysis of a pattern: immutable once made, shared by every blocklu
 * factoring values of that pattern (one per thread). */
typedef struct blocklu_plan {
    int n, nblocks, largest;   /* order, number of blocks, largest block */
    int *P, *Q;                /* [n] A(P,Q) is upper block triangular (btf_order) */
    int *R;                    /* [nblocks+1] first row/column of each block */
    int *at;                   /* [nblocks] start of each block's dense storage in v */
    int nnz;
    int *where;                /* [nnz] slot in v of each entry of A (CSC order) */
    int nv;                    /* values: the dense blocks (ndense), then one slot per entry
                                  above the blocks */
    int *op, *oi;              /* [n+1], [above]: entries above the blocks, by permuted
                                  column: their permuted rows; values v[ndense + p] */
    int *oj;                   /* [above] the permuted column of each (a block's entries
                                  are op[R[k]] .. op[R[k+1]]-1: one loop for them) */
    int ndense;
    int dense_full;            /* every slot of the dense blocks is an entry of A (no
                                  structural zero to clear before factoring) */
    int pq_parity;             /* parity of P and Q together */
    rt_blocks rb;              /* the same as the runtime's table (rt_blocklu.h: the kernels) */
    int one_2x2;               /* one dense 2 x 2 block, nothing above (blocklu.c ONE_2X2) */
} blocklu_plan;

/* Factors of one matrix with an analysed pattern (per thread). */
typedef struct blocklu {
    const blocklu_plan *plan;  /* borrowed */
    double *v;                 /* [nv] block k x k column major, then the entries above */
    int *piv;                  /* [n] row swapped into each position within its block */
    double *anorm;             /* [nblocks] 1-norm of each block's columns (with the
                                  entries above the block) before factoring */
    double *colnorm;           /* [n] 1-norm of each column of A */
    double *w;                 /* [4 n + 3 largest] solve and estimator work */
    int swap_parity;           /* parity of the row swaps of the last factorisation */
    int singular_col;          /* column of A with a zero pivot, or -1 */
} blocklu;

/* Block triangular form of the pattern (Ap, Ai: CSC, n columns). Returns 0,
 * 1 when the pattern is structurally singular, 2 when some diagonal block is
 * larger than max_block (at most BLOCKLU_MAX_BLOCK), -1 when out of memory. */
int blocklu_analyze(blocklu_plan *b, int n, const int *Ap, const int *Ai, int max_block);
void blocklu_plan_free(blocklu_plan *b);
/* Workspace and factors for values of the plan's pattern; -1 when out of memory. */
int blocklu_init(blocklu *b, const blocklu_plan *plan);
void blocklu_free(blocklu *b);

/* Factor the values Ax (the analysed pattern). Returns 0, or -1 for a zero
 * pivot or a value that is not finite (b->singular_col says where). */
int blocklu_factor(blocklu *b, const double *Ax);
/* x := A^-1 x with the last factors. */
void blocklu_solve(blocklu *b, double *x);
/* Smallest reciprocal 1-norm condition of the diagonal blocks, each block's
 * inverse measured against its whole columns: 1 / (|A(:,b)|_1 |A_bb^-1|_1).
 * The inverse's norm is exact for blocks up to 8x8 (column by column),
 * Hager's estimate for larger ones. */
double blocklu_rcond(blocklu *b);
/* Reciprocal 1-norm condition of the whole A (Hager's estimate with whole
 * solves): with many blocks in a chain it can be far smaller than the
 * blocks', since errors pass from block to block. */
double blocklu_rcond_whole(blocklu *b);
/* Lower bounds of both without their solves (rt_blocks_rcond_bounds):
 * 1 when a bound stands for an exact value, 0 when both are exact. */
int blocklu_rcond_bounds(blocklu *b, double *rcond, double *rcond_whole);
/* Smallest |pivot| / largest column 1-norm of its block, over the blocks
 * (cheap: no solves; tiny at an exactly singular matrix). */
double blocklu_pivot_ratio(const blocklu *b);
/* Sign of det A: +1, -1, 0. */
int blocklu_det_sign(const blocklu *b);

/* ==== linsys ==== */
/* linsys.c: the linear solves of a Newton or force system (docs/solver.md
 * "Linear solves"). One square sparse pattern is analysed once; each step
 * factors new values, estimates the condition and solves. When every
 * diagonal block of the block triangular form is small (planar mechanisms:
 * one or two loops per block) the blocks are factored dense (blocklu.c);
 * otherwise, or when asked, by SuiteSparse KLU. As in KLU, the analysis
 * (linsys_plan, shared) and the factors (linsys, per thread) are apart. */
/* The analysis of one pattern (immutable once made; threads share it). */
typedef struct linsys_plan {
    int n;
    int *Ap, *Ai;              /* the pattern (not owned) */
    int use_klu;               /* 0: dense blocks, 1: KLU */
    blocklu_plan blu;
    klu_common common;         /* the settings every factorisation copies */
    klu_symbolic *sym;         /* read only after klu_analyze */
    int q_parity;              /* parity of KLU's fixed column order */
} linsys_plan;

/* Factors of values of a plan's pattern: one per thread. */
typedef struct linsys {
    const linsys_plan *plan;   /* borrowed */
    blocklu blu;
    klu_common common;         /* KLU writes its status here: one per thread */
    klu_numeric *num;
    int factored;              /* the last factorisation succeeded */
    double pivot_ratio_factor; /* klu_rcond at the last full klu_factor */
    int perm_parity;           /* of the row and column orders of KLU's factors */
    unsigned char *seen;       /* [n] permutation parity work */
    int factorizations;        /* full factorisations (every dense-block one) */
    int refactorizations;      /* klu_refactor with the previous pivot order */
} linsys;

/* Analyse the n x n pattern (CSC; kept by reference). method is
 * MECH_LINEAR_AUTO or MECH_LINEAR_KLU. Returns 0, 1 when the pattern is
 * structurally singular, -1 when out of memory or KLU fails. */
int linsys_plan_init(linsys_plan *lp, int n, int *Ap, int *Ai, int method);
void linsys_plan_free(linsys_plan *lp);
/* Factors and workspace for the plan's pattern: 0, or -1 out of memory. */
int linsys_init(linsys *ls, const linsys_plan *lp);
void linsys_free(linsys *ls);

/* Factor the values Ax. Returns 0, or -1 when singular or not finite. */
int linsys_factor(linsys *ls, double *Ax);
/* Reciprocal 1-norm condition with the current factors (0 when not
 * factored): of the worst diagonal block against its whole columns
 * (blocklu_rcond; KLU: of the whole matrix), and of the whole matrix. They
 * differ when errors pass along a chain of blocks: the first says whether
 * the position is singular, the second how far rounding reaches (NULL:
 * not wanted, saves whole solves). */
void linsys_condition(linsys *ls, double *Ax, double *rcond_blocks, double *rcond_whole);
/* Lower bounds of both with the current dense block factors
 * (blocklu_rcond_bounds): 1 when a bound stands for an exact value, 0 when
 * both are the exact values (one block of at most 2 x 2), -1 when none
 * were computed (KLU, or not factored). */
int linsys_condition_bounds(linsys *ls, double *rcond_blocks, double *rcond_whole);
/* Smallest pivot against the largest column (dense blocks: per block, of
 * the block's columns; KLU: klu_rcond). Not a condition estimate, but tiny
 * (about eps) at an exactly singular matrix; 0 when not factored. */
double linsys_pivot_ratio(linsys *ls);
/* x := A^-1 x with the current factors. */
void linsys_solve(linsys *ls, double *x);
/* Sign of det A with the current factors (+1, -1; 0 singular). */
int linsys_det_sign(const linsys *ls);
/* After a failed factorisation: a column with a zero pivot, or -1. */
int linsys_singular_col(const linsys *ls);
/* "dense blocks (largest 2x2)" or "KLU". */
const char *linsys_method_name(const linsys_plan *lp, char *buf, size_t size);

/* ==== kinematics ==== */
/* kinematics.c: from solved unknowns to link frames and point motion.
 *
 * The loop equations give link angles and slider displacements; the frame
 * origin of every link follows by walking a spanning tree of the joints
 * from the ground (the system's span_tree, breadth first, so each point is
 * reached by the shortest chain of links). Velocities and accelerations use the rigid-body and
 * sliding-point formulas, exact for the solved rates: rt_frame.h's, which the
 * generated code (`mech codegen`) carries too. */
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
    /* the numbers, from `model` (kin_tree_numbers; the owner allocates attach) */
    double *attach;     /* [4 nlinks] link l is placed from its parent through the joint's
                           point: at attach[4l], [4l+1] in the parent's frame (revolute: the
                           pin; slider: the guide's point), at [4l+2], [4l+3] in l's */
} kin_tree;

/* Positions, velocities and accelerations of every active link frame. */
typedef struct kin_state {
    rt_frame *F;            /* [nlinks] angle, its rates, origin and its rates (rt_frame.h);
                               cos and sin of cth (ground: 1, 0): computed by kin_update
                               for the links of kin_tree.keep_cs when th has changed, for
                               every link by kin_refresh_all */
    double *cth;            /* [nlinks] the angle F[l].c and F[l].s belong to */
    double *guide;          /* [3 (last slider joint + 1)] a slider's guide angle, its cos
                               and sin, kept while the angle does not change (a ground
                               guide: always) */
} kin_state;

/* The tree's structure (its model: the system's); kin_tree_free frees it. */
int kin_tree_build(kin_tree *t, const mech_system *s);
void kin_tree_free(kin_tree *t);
/* The tree's numbers from model m (of the system's structure: its own, or a
 * sweep variant's): the model points are read from, and attach (allocated
 * by the caller, 4 nlinks). */
void kin_tree_numbers(kin_tree *t, const mech_model *m);

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

/* Every link frame's position (rates 0) from pos (variables 0..n): the
 * checks of a whole assembly (assembly.c), not the sweep's steps. */
void kin_place_all(const kin_tree *t, kin_state *st, const double *pos);

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
/* The position p of point name_id, its velocity v and acceleration a (v, a
 * may be NULL: not computed; the branch conditions need positions only). */
void kin_point(const kin_tree *t, const kin_state *st, int name_id, double *p, double *v,
               double *a);

/* Point r (link frame) of link l: position p, velocity v, acceleration a. */
void kin_on_link(const kin_state *st, int l, const double *r, double *p, double *v, double *a);
/* c = cos th and s = sin th of link l, computed elsewhere (the solver's
 * tape): the next kin_update at angle th uses them instead of its own. */
void kin_offer_cs(kin_state *st, int l, double th, double c, double s);

/* ==== solve ==== */
/* solve.c: the numerical core of the sweep and the forces: the plan
 * (the subset of unknowns to solve, its tape and pattern analysis; built
 * once, shared) and the state (x, rates, registers, factors; per thread),
 * with one driver position's Newton solve and its rate solves. */
typedef enum {
    STEP_OK,
    STEP_NO_ASSEMBLY,  /* Newton does not converge: the loops cannot close */
    STEP_SINGULAR,     /* converged (or stuck) where the Jacobian is singular */
    STEP_JUMP,         /* converged far from the prediction: possibly another branch */
    STEP_BRANCH        /* converged on the other side of a declared branch */
} step_status;

/* What is fixed for a mechanism and a choice of outputs (built once by
 * solver_plan_init, then read only: threads share it). Its structure (the
 * system, the blocks, the pattern, the tape's program, the tree) on one
 * side; on the other the numbers taken from a model, all of them computed by
 * solver_plan_numbers (marked "number" below), so that a sweep's variant
 * takes its own from its model through the same function. */
typedef struct solver_plan {
    mech_system *sys;          /* owned */
    const mech_model *m;       /* number: the model the numbers are of */
    mech_solve_options opt;
    int level;                 /* MECH_WANT_* bits actually computed */
    double lref;               /* number: largest length of the mechanism, m */
    double ftol;               /* number: residual tolerance, m */

    /* the solved subset: blocks of the block triangular form that outputs need */
    int n;                     /* all unknowns */
    int ns;                    /* unknowns solved */
    int nr;                    /* equations solved: ns, or more with redundant ones */
    int aug;                   /* 1: least squares ([I J; J^T 0]), redundant constraints */
    int exact_rcond;           /* MECH_RCOND=exact: no bounds first (condition_at_solution),
                                  to check that they decide as the exact values do */
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
    int *csreg;                /* [4 ncs] the link frames whose cos and sin of the angle
                                  the tape computes: the link, the registers of its
                                  angle's variable, of cos and of sin (solver_publish) */
    int ncs;
    int *xreg, *xdreg;         /* [ns] register of each solved unknown and of its rate
                                  (-1: the tape does not read it) */
    double *unit;              /* number [ns]: 1 for an angle, lref for a slide (step sizes) */
    double *leaf;              /* number [nleaf]: the system's leaves (a sweep's registers),
                                  set in every state's registers (solver_init) */
    int nleaf;                 /* sys->nvars - SYS_NVARS(n) */
    linsys_plan lp;            /* analysis of the factored matrix's pattern */
    kin_tree tree;             /* link frames: the spanning tree, active links; numbers:
                                  its model and attachment points */
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
    int rcond_exact;           /* 0: rcond and rcond_whole are lower bounds that gave the
                                  exact values' status and rounding floor
                                  (condition_at_solution); solver_rcond makes them exact */
    unsigned factorisations;   /* counts factor(): the bounds' factors are still there */
    unsigned rcond_factorisation; /* the factorisation the bounds were taken from */

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
/* The same with a system built beforehand (SYS_LEAF_POLAR, leaves or none, of
 * m), owned by the plan from here on, also when this fails; NULL: built
 * here. The length scale lref of m (tolerances, slide steps). */
int solver_plan_init_with(solver_plan *sp, const mech_model *m, const mech_solve_options *o,
                          mech_system *sys, mech_diag *d);
double solver_largest_length(const mech_model *m);
/* The plan's numbers from model m (of the plan's structure: its own, or a
 * sweep variant's): every field marked "number". The one place they are
 * computed: solver_plan_init calls it, and so does a sweep variant's view.
 * The arrays come from solver_numbers_alloc (0, or -1 out of memory) and
 * go with solver_numbers_free. */
int solver_numbers_alloc(solver_plan *sp);
void solver_plan_numbers(solver_plan *sp, const mech_model *m);
void solver_numbers_free(solver_plan *sp);
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
/* Free coordinates (mech simulate, docs/dynamics.md): Newton for
 * f(x, q) = shift[0..nr-1] (the solved rows; a driver's row x_k - p_k(q)
 * shifted by X_k - p_k(q) holds x_k at X_k), from sv->x. */
step_status solver_newton_shifted(solver *sv, double q, const double *shift);
/* After solver_newton_shifted, for the time as sweep variable (qdot 1,
 * qddot 0): sv->xq := x' from J x' = -f_q + vshift, sv->xqq := x'' from
 * J x'' = (the acceleration right-hand side at x') + ashift (NULL: 0);
 * solver_publish(sv, t, 1, 0) then publishes them. */
void solver_rates_shifted(solver *sv, const double *vshift, const double *ashift);
/* x'' again for another ashift at the same position and velocities (after
 * solver_rates_shifted; one solve). */
void solver_accel_shifted(solver *sv, const double *ashift);
/* Scatter x, and the rates for driver speed qd and acceleration qdd, into
 * pos, vel, acc and update the link frames. */
void solver_publish(solver *sv, double q, double qd, double qdd);  /* again: no work */

/* sv->rcond, exact: from the factors of the position it was bounded at,
 * when they are still the current ones (else the bound stays: a lower
 * bound of it). For what reports the value (--stats' smallest, the rcond
 * column, notes); the solve's decisions need only the bound. */
double solver_rcond(solver *sv);
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

/* ==== continuation ==== */
/* continuation.c: from one driver position to the next (docs/solver.md).
 *
 * Row 0 is found by Newton from the file's guesses (then from scattered
 * starts for the unknowns without a guess) on the declared branch. Each
 * later row is reached by continuation: predict x(q + h) from x, dx/dq and
 * d2x/dq2, correct by Newton, and accept only when the correction is small
 * next to the predicted move (else the solution may have jumped to another
 * assembly) and the declared branch still holds. A rejected step is halved,
 * down to a tiny fraction of the row spacing; what failed there is kept
 * for the failure diagnosis (diagnose.h). */
/* One thread's walk along the driver: its solver state and the base of
 * the continuation. */
typedef struct cont {
    solver sv;                 /* the numeric state (owned) */
    const mech_model *m;
    mech_diag *d;
    mech_solve_stats *st;      /* worst residual and condition are noted here */
    double qd, qdd;            /* driver speed and acceleration */
    /* the last accepted position and its rates (the continuation's base) */
    double qc;
    double *xc, *xqc, *xqqc;   /* [ns] */
    double *xqq_prev;          /* [ns] d2x/dq2 there: the predictor's third derivative */
    double q_prev;
    int have_prev;
    double *xpred;             /* [ns] */
    double pred_move;          /* size of xpred - xc (solver_step_size) */
    int try_sign;              /* sign of det J at the last converged attempt */
    /* row 0, kept to look for the assembly range after a failure */
    double q0, *x0, *xq0, *xqq0;
    double *guess;             /* [n] the file's guess of each unknown, NAN if none */
    double *xgap;              /* [ns] the last position before a gap (restarts) */
    double *xdrawn;            /* [ns] a drawn file's assembly at the drawing's driver value,
                                  where its guesses hold (assembly.c check a); else NULL */
    double *xqgap, *xqqgap;    /* [ns] its rates */
    int row_iters;             /* Newton iterations spent on the current row */
    int row_substeps;          /* extra continuation steps the row needed (refinement) */
    int det_sign;              /* sign of det J at the base (0: unknown) */
    double hcross;             /* a longer step may not change det J's sign: it is
                                  shortened (cont_try) */
    int crossings;             /* sign changes reported */
    int searching;             /* looking for assembly limits: no crossing reports */
    double fail_q;             /* where the last rejected attempt was */
    step_status fail_status;
    double fail_resid;         /* residual and worst row (rows.h) of the first rejected
                                  attempt */
    int fail_row;
    int fail_change_point;     /* the last singular position diagnosed was a change point */
    mech_fail_kind fail_kind;  /* what row 0's failure was reported as (cont_start) */
} cont;

/* A walk on the plan's mechanism; messages go to d, worst values to st. */
int cont_init(cont *c, const solver_plan *sp, mech_diag *d, mech_solve_stats *st);
void cont_free(cont *c);

/* Row 0 at q: MECH_OK, or MECH_ESOLVE with the reason reported. */
int cont_start(cont *c, double q);
/* After a gap, the row at q: Newton from the last position before the gap,
 * the guesses and scattered starts, on the declared branch; quiet. On
 * success (MECH_OK) the row is solved and becomes the base and row 0's copy
 * (for later diagnoses); angles are taken nearest to those before the gap. */
int cont_restart(cont *c, double q);
/* From the base (just set by cont_restart) back toward qback: the limit of
 * assembly between them, to within hmin (*found: the march failed before
 * qback); the base is left there. */
double cont_limit_behind(cont *c, double qback, double hmin, int *found);
/* Newton at q from x, with the checks of a first position (cont_try). */
step_status cont_solve_at(cont *c, double q, const double *x);
/* The row kept by cont_restart solved again and made the base. */
void cont_back_to_start(cont *c);
/* From the base to q by continuation, halving rejected steps down to hmin. */
step_status cont_advance(cont *c, double q, double hmin);
/* Make (q, x, x_q, x_qq) the base of the continuation. */
void cont_set_base(cont *c, double q, const double *x, const double *xq, const double *xqq);
/* March from the base in direction dir by steps h until assembly fails
 * or span is covered; the last position reached (a limit when *found). */
double cont_march(cont *c, double dir, double h, double span, int *found);
/* Starting values of attempt k (0: the guesses, else scattered). */
void cont_start_values(cont *c, int attempt, unsigned *rng);
/* Newton at qn from sv.x and the checks that make a step acceptable
 * (continuing: against the prediction). */
step_status cont_try(cont *c, double qn, int continuing);
/* Every declared branch condition holds at the published position (else
 * *which is the first that does not); continuing: not those that hold at
 * the first position only. */
int cont_branches_hold(cont *c, int *which, int continuing);

/* ==== assembly ==== */
/* assembly.c: is the assembly the one the file means (docs/solver.md
 * section 9)? Positions kept along a sweep, checked once after it: the
 * first against the guesses, the others for a degenerate assembly. Each
 * finding a warning of a suspect assembly's kind (fail_is_suspect_assembly). */
enum { ASSEMBLY_SAMPLES = 9 };

typedef enum {
    ASSEMBLY_CHECKED,          /* every check ran */
    ASSEMBLY_SKIPPED_PARTIAL,  /* only the guesses: the outputs need only some unknowns
                                  (the other links are not placed) */
    ASSEMBLY_SKIPPED_ONE,      /* only the guesses: fewer than two positions, or q still */
    ASSEMBLY_SKIPPED_MEMORY    /* only the guesses: out of memory for the points */
} assembly_status;

/* The positions kept: at most ASSEMBLY_SAMPLES rows spread over the sweep's
 * requested rows (the first and the last among them); those in a gap are
 * not kept. Allocated once per sweep. */
typedef struct assembly_samples {
    int ns;                    /* solved unknowns per position */
    int row[ASSEMBLY_SAMPLES]; /* the rows to keep */
    int nrows, next;           /* how many, the next one to look for */
    int next_row;              /* row[next], INT_MAX after the last: the sweep's one test */
    int n;                     /* positions kept */
    int has_first;             /* the first kept is row 0: the first position */
    const double *x_guessed;   /* the position the guesses are for, when not row 0 (a drawn
                                  file: the assembly at its drawing, cont.xdrawn) */
    double q[ASSEMBLY_SAMPLES];
    double *x;                 /* [ASSEMBLY_SAMPLES ns] */
    assembly_status skipped;   /* what assembly_check could do */
} assembly_samples;

/* For a sweep of nq requested rows of ns solved unknowns: 0, -1 out of memory. */
int assembly_samples_init(assembly_samples *s, int ns, int nq);
void assembly_samples_free(assembly_samples *s);
/* The sweep solved row `row` at q (x: its solved unknowns): kept when it is
 * one of the rows chosen. Call only when row >= s->next_row. */
void assembly_take(assembly_samples *s, int row, double q, const double *x);
/* The checks of the kept positions, their warnings to d (s->skipped says
 * which ran). Moves sv's frames: after the sweep. */
void assembly_check(solver *sv, assembly_samples *s, mech_diag *d);
/* The assembled position x (solved unknowns at q) against a stated pose:
 * pose[2 id], pose[2 id + 1] the global position of point name id, m (NAN:
 * not stated); a warning (MECH_FAIL_FAR_FROM_GUESS) for each moving point
 * further than tol (m) from it, naming the point and its link; how many. */
int assembly_check_pose(solver *sv, double q, const double *x, const double *pose,
                        double tol, mech_diag *d);

/* ==== diagnose ==== */
/* diagnose.c: why a position or a sweep failed, in a user's words:
 * assembly limits, singular positions (dead points, change points),
 * redundant constraints, branch jumps; each message names the driver
 * position and the rows' owners (rows.h) or the unknowns involved. */
/* "123.4 deg" or "0.1834 mm": the driver position as users think of it. */
const char *diagnose_q_text(const mech_model *m, double q, char *buf, size_t size);
/* "179.9995 deg and 180.0005 deg": two positions with the digits that
 * tell them apart. */
const char *diagnose_q_interval(const mech_model *m, double a, double b, char *buf,
                                size_t size);
/* "driver angle" or "driver displacement". */
const char *diagnose_driver_word(const mech_model *m);
/* "A-B-C turning clockwise", "D right of C", "B above O", "slider s positive". */
const char *diagnose_branch_text(const mech_model *m, const mech_branch *b, char *buf,
                                 size_t size);
/* The row (of the system: rows.h names it) that closes worst at the
 * current iterate. */
int diagnose_worst_row(const solver *sv);

/* How row 0's starts failed (cont_start): the first attempt (from the
 * guesses), the one that came closest to closing the loops (its x in
 * c->xgap), a declared branch condition violated (-1 none). */
typedef struct start_failure {
    step_status first;        /* the first attempt: status, residual, worst row */
    double resid;
    int row;                  /* of the system (rows.h) */
    double best_resid;        /* the attempt with the smallest residual, and whether the */
    int best_is_last;         /* solver still holds its state */
    int branch;
    int attempts;             /* starts tried */
} start_failure;

/* Row 0 could not be found at q: why, reported; the kind reported. */
mech_fail_kind diagnose_start(cont *c, double q, const start_failure *f);
/* The two moving links pinned together most nearly in line at the published
 * position, when the cosine of their angle is above cos_min: "arm1 and arm2
 * extended in line" (or "folded"); "" when none is. */
void diagnose_links_in_line(solver *sv, double cos_min, char *buf, size_t size);
/* The owners of the rows that depend at the current (nearly singular)
 * factors, e.g. "loop 1 (A-B-C-D-A), gear pair 'g'"; "" when unknown (a
 * large system). */
void diagnose_dependent_rows(const solver *sv, char *buf, size_t size);
/* A singular position at q: which unknowns are free, which rows depend;
 * MECH_FAIL_DEAD_POINT or MECH_FAIL_CHANGE_POINT. */
mech_fail_kind diagnose_singular(cont *c, double q);
/* Redundant constraints at row 0: which equations the others imply. */
void diagnose_redundant(cont *c, double q);
/* The sweep could not reach the row at q_row (row spacing hrow): the
 * assembly interval(s), the singular position, or the branch jump; the
 * kind reported. */
mech_fail_kind diagnose_failure(cont *c, double q_row, double hrow);

#endif
