/* src/continuation.h: from one driver position to the next (docs/solver.md).
 *
 * Row 0 is found by Newton from the file's guesses (then from scattered
 * starts for the unknowns without a guess) on the declared branch. Each
 * later row is reached by continuation: predict x(q + h) from x, dx/dq and
 * d2x/dq2, correct by Newton, and accept only when the correction is small
 * next to the predicted move (else the solution may have jumped to another
 * assembly) and the declared branch still holds. A rejected step is halved,
 * down to a tiny fraction of the row spacing; what failed there is kept
 * for the failure diagnosis (diagnose.h). */
#ifndef MECH_CONTINUATION_H
#define MECH_CONTINUATION_H

#include "solve.h"

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

#endif
