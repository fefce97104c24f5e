/* src/forces/forces.h: kinetostatics: springs and dampers, the force system described as data and
 * solved, friction, power balance, the loads' program run per step. The stage's one header: what
 * its modules share with each other and with the later stages (docs/architecture.md, "Stages"). */
#ifndef MECH_FORCES_STAGE_H
#define MECH_FORCES_STAGE_H

#include "rt_forces.h"
#include "solve.h"
#include "load.h"

/* ==== springs ==== */
/* springs.c: springs and dampers evaluated from the solved motion
 * (docs/forces.md section 7): their length or angle, its rate, the force
 * or torque (the formulas, their loads and power: rt_forces.h). */
/* Spring i as the force system reads it (rt_forces.h): its ends (linear)
 * or links (torsional), free length or angle and coefficients. */
void springs_rt(const mech_model *m, int i, rt_spring *out);

/* Spring i at the published position of a solver (rt_spring_eval). */
typedef struct spring_state {
    double length;     /* m (LINEAR) or rad (TORSION: the relative angle) */
    double rate;       /* m/s or rad/s */
    double force;      /* N, tension positive, or N*m */
} spring_state;
void springs_eval(const mech_model *m, int i, const solver *sv, spring_state *st);

/* Spring i in words, as mech check and mech report show it: its name,
 * where it acts and its coefficients (SI; angles in deg). */
void springs_describe(const mech_model *m, int i, char *buf, size_t size);

/* ==== forces ==== */
/* forces.c: kinetostatics (docs/forces.md). Newton-Euler equations of
 * every moving link with D'Alembert inertia loads from the solved motion;
 * unknowns are the joint reactions and the driver torque or force. The
 * sparse pattern is fixed: analysed once (linsys.c), factored per step. */
/* Run the register program of the loads that depend on the motion
 * (state_loads.h, built at load time) at the published position of sv into
 * reg (state_loads_eval.c). s may be NULL. */
void state_loads_eval(const state_loads *s, const solver *sv, double *reg);

/* What one column of the force system is. */
typedef enum { FC_FX, FC_FY, FC_NORMAL, FC_MOMENT, FC_DRIVE, FC_GEAR, FC_CAM } fc_kind;

/* The numbers of the force system: what enters each row and column,
 * described once as the tables of rt_forces.h, which forces.c and the
 * generated code (codegen_forces.c writes them out) read alike. */
typedef struct forces_numbers_t {
    rt_fcol *cols;          /* [ncols] each unknown's entries: where and along what */
    rt_body *body;          /* [nlinks] masses, inertias, centres */
    rt_gear *gears;         /* [ngears] the tooth forces' geometry */
    rt_load *loads;         /* [nloads] constant loads (the first nconst), then those that
                               depend on the motion (registers of m->state_loads) */
    int nloads, nconst;
    rt_spring *springs;     /* [nsprings] */
    int nsprings;
    rt_friction *fric;      /* [nfric] the joints with a friction coefficient */
    int nfric;
    rt_drive *drive;        /* [ndrive] the drivers' coordinates (laws of time) */
    double grav[2];         /* gravity, m/s^2 */
    double lref;            /* largest length, m */
    double speed_eps;       /* smoothing of sign(relative speed), rad/s (a millionth of the
                               driver's speed; per lref for a slider driver) */
    double linear, turning; /* the power's scales: the driver's speed as a linear and as a
                               turning speed (rt_power) */
} forces_numbers_t;

/* The force system of a mechanism (fixed: built once, read only, shared):
 * its structure, and the numbers marked "number" (forces_plan_numbers). */
typedef struct forces_plan {
    const mech_model *m;    /* number: the model masses and loads are read from */
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
    int ccol;               /* first cam contact-force column (one per cam, after the
                               gears') */
    int ndrive;             /* driver columns, the last ones: 1, or the `drivers:` */
    int *jcol;              /* [njoints] first column of each joint */
    int *Ap, *Ai;           /* [ncols+1], [nnz] */
    int *slot;              /* [nnz] where column c's k-th entry, in the order
                               column_entries makes them, goes: Ax[slot[Ap[c] + k]] */
    int nnz;
    forces_numbers_t num;   /* number: the tables (forces_plan_numbers) */
    linsys_plan lp;         /* analysis of the pattern */
} forces_plan;

/* One thread's force solve: values, factors, the friction iteration. */
typedef struct forces {
    const forces_plan *p;   /* borrowed */
    double *Ax;             /* [nnz] */
    double *b, *y, *y0;     /* [nrows] right-hand side; solution; frictionless solution */
    double *ynext;          /* [nrows] friction iterate */
    double *aa_g, *aa_r;    /* [nrows] Anderson: the last image G(y) and residual */
    double *aa_dg, *aa_dr;  /* [3 nrows] their last differences (a ring) */
    double *g, *vg, *ag;    /* [2 nlinks] centres of mass and their rates, this step */
    double *fric;           /* [nrows] friction loads moved to the right-hand side */
    double *cscale;         /* [ncols] column equilibration */
    double *spr;            /* [RT_SPRING_STATE nsprings] the springs at this step */
    double *sl_reg;         /* registers of the loads that depend on the motion, or NULL */
    double *cam;            /* [4 ncams] each cam's contact point and outward unit normal
                               at this step, ground frame (rt_fcol_entries' table) */
    linsys ls;              /* factors of the force system */
    rt_forces_out out;      /* per step results (rt_forces.h): friction iterations, the
                               power balance with and without friction (residual0 0 when
                               y0 was not solved), the friction's and drivers' power;
                               have_previous: y holds the last step's reactions */
    double rcond;           /* reciprocal condition at the first step, or when last checked */
    int condition_known;    /* rcond computed (forces_solve, at the first step) */
} forces;

/* The force system of the mechanism the solver plan solves (every link's
 * motion: the plan must solve all blocks). friction: MECH_FRICTION_*. */
int forces_plan_init(forces_plan *fp, const solver_plan *sp, int friction, mech_diag *d);
void forces_plan_free(forces_plan *fp);
/* The plan's numbers from the solver plan's model (of the plan's structure:
 * its own, or a sweep variant's): the one place they are computed, by
 * forces_plan_init and by a sweep variant's view (fp->num then the view's
 * own: zeroed before, freed by forces_numbers_free). 0, or -1 out of
 * memory. */
int forces_plan_numbers(forces_plan *fp, const solver_plan *sp);
/* The numbers of fp's force system for model m (fp's, or a sweep variant's
 * of the same structure: tree, its kinematic tree; lref its largest
 * length); 0, or -1 out of memory. */
int forces_numbers(forces_numbers_t *fn, const forces_plan *fp, const mech_model *m,
                   const kin_tree *tree, double lref);
void forces_numbers_free(forces_numbers_t *fn);
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
/* Cam i's contact force along the common normal (+: pressing), N. */
double forces_cam(const forces *fc, int i, int with_friction);
/* The load of driver k: 0 for `driver:`, 0 .. ndrive-1 for `drivers:`. */
double forces_drive_of(const forces *fc, int with_friction, int k);
/* After forces_solve returned -1: the names of the joints involved. */
void forces_singular_joints(forces *fc, char *buf, size_t size);

#endif
