/* src/forces.h: kinetostatics (docs/forces.md). Newton-Euler equations of
 * every moving link with D'Alembert inertia loads from the solved motion;
 * unknowns are the joint reactions and the driver torque or force. The
 * sparse pattern is fixed: analysed once (linsys.c), factored per step. */
#ifndef MECH_FORCES_H
#define MECH_FORCES_H

#include "solve.h"

/* What one column of the force system is. */
typedef enum { FC_FX, FC_FY, FC_NORMAL, FC_MOMENT, FC_DRIVE, FC_GEAR } fc_kind;

/* The force system of a mechanism (fixed: built once, read only, shared). */
typedef struct forces_plan {
    const mech_model *m;
    int friction;           /* 1: Coulomb friction of the joints is applied */
    int has_friction;       /* some joint has a friction coefficient */
    int want_frictionless;  /* the frictionless reactions are output too (y0) */
    int nrows;              /* 3 per moving link */
    int ncols;
    fc_kind *kind;          /* [ncols] */
    int *joint;             /* [ncols] joint of a reaction column (-1: the driver;
                               -1 - k: driver k of `drivers:`; FC_GEAR: the gear pair) */
    int gcol;               /* first tooth-force column (one per gear pair, before the
                               drivers', which stay last) */
    int ndrive;             /* driver columns, the last ones: 1, or the `drivers:` */
    int *jcol;              /* [njoints] first column of each joint */
    int *Ap, *Ai;           /* [ncols+1], [nnz] */
    int *slot;              /* [nnz] where column c's k-th entry, in the order
                               column_entries makes them, goes: Ax[slot[Ap[c] + k]] */
    int nnz;
    double speed_eps;       /* smoothing of sign(relative speed), rad/s */
    linsys_plan lp;         /* analysis of the pattern */
} forces_plan;

/* One thread's force solve: values, factors, the friction iteration. */
typedef struct forces {
    const forces_plan *p;   /* borrowed */
    int have_previous;      /* y holds the last step's reactions (friction start) */
    double *Ax;             /* [nnz] */
    double *b, *y, *y0;     /* [nrows] right-hand side; solution; frictionless solution */
    double *ynext;          /* [nrows] friction iterate */
    double *aa_g, *aa_r;    /* [nrows] Anderson: the last image G(y) and residual */
    double *aa_dg, *aa_dr;  /* [3 nrows] their last differences (a ring) */
    double *g, *vg, *ag;    /* [2 nlinks] centres of mass and their rates, this step */
    double *fric;           /* [nrows] friction loads moved to the right-hand side */
    double *cscale;         /* [ncols] column equilibration */
    double *sl_reg;         /* registers of the loads that depend on the motion, or NULL */
    linsys ls;              /* factors of the force system */
    /* per step results */
    int iterations;         /* friction fixed-point iterations */
    double residual0;       /* power balance, frictionless, relative (0 when y0 was not
                               solved: friction on and its columns not wanted) */
    double residual;        /* power balance with friction (friction losses included) */
    double friction_power;  /* W dissipated by joint friction */
    double drive_power;     /* W supplied by the driver */
    double rcond;           /* reciprocal condition at the first step, or when last checked */
    int condition_known;    /* rcond computed (forces_solve, at the first step) */
} forces;

/* The force system of the mechanism the solver plan solves (every link's
 * motion: the plan must solve all blocks). friction: MECH_FRICTION_*. */
int forces_plan_init(forces_plan *fp, const solver_plan *sp, int friction, mech_diag *d);
void forces_plan_free(forces_plan *fp);
int forces_init(forces *fc, const forces_plan *fp);  /* 0, or -1 out of memory */
void forces_free(forces *fc);

/* Forces at the published position of sv (positions, velocities and
 * accelerations of every link). Returns 0, or -1 when the force system is
 * singular (redundant constraints): fc->rcond says how badly. */
int forces_solve(forces *fc, const solver *sv);

/* Reaction of joint j on the receiving link (docs/forces.md), ground frame:
 * fx, fy and, for sliders, the normal force n and moment mo; from the
 * friction solution (with_friction) or the frictionless one. */
void forces_joint(const forces *fc, const solver *sv, int j, int with_friction, double *fx,
                  double *fy, double *n, double *mo);
/* Tooth force of gear pair i along its line of action (gears.h), N: the
 * sign of its tangential part F (on link[1], along t). */
double forces_gear(const forces *fc, int i, int with_friction);
/* The load of driver k: 0 for `driver:`, 0 .. ndrive-1 for `drivers:`. */
double forces_drive_of(const forces *fc, int with_friction, int k);
/* After forces_solve returned -1: the names of the joints involved. */
void forces_singular_joints(forces *fc, char *buf, size_t size);

#endif
