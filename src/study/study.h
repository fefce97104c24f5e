/* src/study/study.h: the analysis and what is built on it: the result columns, the sweep,
 * parameter sweeps (grid, samples, metrics, variants), sensitivities, flywheel sizing. The stage's
 * one header: what its modules share with each other and with the later stages
 * (docs/architecture.md, "Stages"). */
#ifndef MECH_STUDY_STAGE_H
#define MECH_STUDY_STAGE_H

#include <stdint.h>
#include <stdio.h>

#include "forces.h"
#include "mech.h"
#include "equations.h"
#include "base.h"

/* ==== columns ==== */
/* columns.c: the one description of a result table's columns.
 *
 * A layout lists every column once: its name, its unit and where its value
 * comes from (a source and the object it belongs to). The same layout
 * names the table's columns, sizes its rows and fills them, so the three
 * can never disagree. It is built with the analysed system and read only
 * afterwards. */
/* ORDER SRC: columns_fill switches on these. */
typedef enum {
    SRC_DRIVER,          /* the driver position q */
    SRC_POINT,           /* obj: point name id; comp 0..5: x, y, vx, vy, ax, ay */
    SRC_LINK,            /* obj: link; comp 0..2: angle, omega, alpha */
    SRC_SLIDER,          /* obj: joint; comp 0..2: s, v, a */
    SRC_REACTION,        /* obj: joint; comp 0..3: Fx, Fy, F or N, M; set: 1 with
                            friction, 0 frictionless */
    SRC_DRIVE_LOAD,      /* the driver torque or force; set as above */
    SRC_POWER_RESIDUAL,  /* set as above */
    SRC_FRICTION_POWER,
    SRC_FRICTION_ITERATIONS,
    SRC_ITERATIONS,      /* diagnostics: Newton iterations of the row */
    SRC_RESIDUAL,
    SRC_RCOND,
    SRC_SUBSTEPS,
    SRC_SPRING,          /* obj: spring; comp 0..2: length (angle), rate, force (torque) */
    SRC_GEAR,            /* obj: gear pair; the tooth force along the line of action */
    SRC_CAM,             /* obj: cam pair; the contact force along the common normal */
    SRC_CAM_DESIGN       /* obj: cam pair; comp 0..3: its angle x, pressure angle,
                            radii of curvature of the pitch curve and the profile */
} column_source;

typedef struct column_desc {
    column_source src;
    int obj;             /* point id, link or joint (see column_source) */
    int comp;            /* component (see column_source) */
    int set;             /* reactions: 1 with friction, 0 frictionless */
    char *name;          /* owned */
    const char *unit;    /* static */
} column_desc;

/* Consecutive columns of one source object, filled together: the source
 * is evaluated once (a point's six motion values, a joint's reaction) and
 * the wanted components copied. Derived from the descriptors. */
typedef struct column_group {
    column_source src;
    int obj, set;
    int first;           /* first column */
    int n;               /* columns: components 0 .. n-1 of the source (the rates come
                            after the positions, the levels are nested) */
    int direct;          /* n is every component: the source writes into the row */
} column_group;

typedef struct column_layout {
    column_desc *cols;   /* [ncols] */
    int ncols;
    int cap;
    column_group *groups; /* [ngroups] the columns in runs of one source object */
    int ngroups;
} column_layout;

/* What a layout must hold. */
typedef struct column_request {
    const mech_outputs *outputs; /* the points, links and sliders */
    int level;           /* MECH_WANT_* bits: rates of points, links, sliders */
    int forces;          /* reactions, driver load, power residual */
    int friction;        /* 0 none, 1 friction columns, 2 also the frictionless set */
    int diagnostics;     /* iterations, residual, rcond, substeps */
} column_request;

/* The columns of the request's outputs. MECH_OK or MECH_ENOMEM. */
int columns_build(column_layout *cl, const mech_model *m, const column_request *rq);
void columns_free(column_layout *cl);
/* Give the table the layout's names and units (owned copies) and room for
 * nrows rows. MECH_OK or MECH_ENOMEM. */
int columns_make_table(const column_layout *cl, mech_table *t, int nrows);

/* What one row is filled from: the published solver state, the forces
 * (NULL without forces), and the row's diagnostics. */
typedef struct row_sources {
    const solver *sv;
    const forces *fc;
    int iterations;
    int substeps;
} row_sources;

/* Fill one row (ncols values) from the sources. */
void columns_fill(const column_layout *cl, const row_sources *rs, double *row);

/* sweep.c: MECH_OK when every value of a row of a's table (at driver
 * position q) is a finite number, else MECH_ESOLVE with an error in d
 * naming the first column that is not. */
int analysis_check_finite(const mech_analysis *a, double q, const double *out, mech_diag *d);

/* ==== sweep_random ==== */
/* sweep_random.c: the samples of `mech sweep --random N` (sweep_random.c). */
/* A number uniform in [-1, 1] for (seed, variant index, parameter k): a
 * function of the three alone (counter-based), so a variant's sample does
 * not depend on the order, the threads or the shard that draws it. */
double sweep_random_unit(uint64_t seed, long index, int k);

/* ==== sweep_variants ==== */
/* sweep_variants.c: one variant of a sweep (sweep_variants.c). */
/* One sweep's shared parts: its file parsed once, and the analysis its
 * variants share (built by the first variant with the names it varies).
 * NULL when out of memory. Freed with sweep_shared_free (NULL is fine). */
typedef struct sweep_shared sweep_shared;
sweep_shared *sweep_shared_new(const char *file, int forces);
void sweep_shared_free(sweep_shared **sh);

/* Load the sweep's file with the parameter replacements ov[0..nov-1],
 * check it and solve its sweep (options: the defaults, forces as the
 * sweep's) into *t; the status and messages are those of
 * mech_load_file_with, mech_check and mech_solve. With `model` non-NULL
 * the variant's model (NULL when it could not be loaded) is handed over in
 * *model, for the metrics that need it (flywheel:CS, the driver's speed);
 * the caller frees it. Thread safe: the parsed file and the base are
 * shared. */
int sweep_variant_solve(sweep_shared *sh, const mech_override *ov, int nov, mech_table *t,
                        mech_model **model, mech_diag *d);

/* How many of the sweep's variants were solved through its one analysis
 * and how many were analysed on their own (re-analysed). */
void sweep_variant_counts(const sweep_shared *sh, long *shared, long *alone);

/* Another solver of the variants than the interpreter (mech sweep's
 * compiled one, src/cli/cmd_codegen_jit.c): solve(ctx, b, view, mv, t, d) solves
 * variant mv through view (b's analysis with mv's numbers) into t, with
 * any notes in d: MECH_OK, or VBASE_INTERPRET (nothing in t or d): the
 * interpreter solves it. Called from the sweep's worker threads. */
/* The analysed base of a sweep, shared read only by the variants
 * (variant_regs.c, below). */
typedef struct variant_base variant_base;
typedef struct sweep_engine {
    int (*solve)(void *ctx, const variant_base *b, const mech_analysis *view,
                 const mech_model *mv, mech_table *t, mech_diag *d);
    void *ctx;
} sweep_engine;
/* After mech_sweep_prepare: the variants through the base go to e (NULL:
 * the interpreter), which must outlive mech_sweep_run. */
void sweep_set_engine(mech_sweep *s, const sweep_engine *e);
void sweep_shared_set_engine(sweep_shared *sh, const sweep_engine *e);

/* ==== variant_regs ==== */
/* variant_regs.c: one analysis per sweep (variant_regs.c): the system
 * of the sweep's base model analysed once with the lengths and angles that
 * the varied parameters move as leaves (SYS_LEAF_POLAR), and each variant
 * solved through a view of that analysis with its own numbers. */
/* sweep.c: an analysis built on a system made beforehand (owned by the
 * analysis from here on, also on failure; NULL: built as mech_analysis_new). */
int analysis_new_with(const mech_model *m, const mech_solve_options *o, mech_system *sys,
                      mech_analysis **out, mech_diag *d);
/* A view of `base` for model mv (the same structure, other numbers): the
 * plans' structure is base's, shared and read only; every number the plans
 * take from a model (solver_plan_numbers, forces_plan_numbers: the length
 * scale, the step units, the link frames' attachment points, the leaves'
 * values, the friction's speed scale) is mv's, computed by the functions the
 * set-up uses. NULL when out of memory. Solve it with mech_analysis_solve;
 * free it with analysis_view_free (not mech_analysis_free). */
mech_analysis *analysis_view_new(const mech_analysis *base, const mech_model *mv);
void analysis_view_free(mech_analysis **view);
const mech_system *analysis_system(const mech_analysis *a);
/* Its solver plan, and its force plan (NULL without forces): the numbers a
 * compiled solver of its structure takes (codegen_numbers_fill). */
const solver_plan *analysis_solver_plan(const mech_analysis *a);
const forces_plan *analysis_forces_plan(const mech_analysis *a);
/* The assembly's checks (assembly.c) of the positions smp kept from a
 * sweep of a made elsewhere (mech solve's compiled rows), with the
 * warnings the interpreter's sweep gives to d. 0, or -1 out of memory. */
int analysis_assembly_check(const mech_analysis *a, assembly_samples *smp, mech_diag *d);
/* Its driver positions, *n of them. */
const double *analysis_positions(const mech_analysis *a, int *n);

/* The base: model `base` (checked; owned from here on, also on failure),
 * the parameters names[0..nnames-1] that the variants change, forces as
 * mech_solve_options.forces. MECH_OK, or why not (the variants are then
 * analysed one by one). */
int vbase_new(mech_model *base, const char *const *names, int nnames, int forces,
              variant_base **out, mech_diag *d);
void vbase_free(variant_base **b);

enum { VBASE_REANALYSE = -1000, VBASE_INTERPRET = -1001 };
/* Solve the variant model mv (loaded and checked) through the base's
 * analysis into *t; VBASE_REANALYSE (nothing in t or d) when mv's
 * structure or a number the analysis folded differs from the base's, or
 * a length the base has as a leaf is exactly 0 (docs/batch.md, "One
 * analysis per sweep"); else mech_analysis_solve's status. Thread safe. */
int vbase_solve(const variant_base *b, const mech_model *mv, const sweep_engine *e,
                mech_table *t, mech_diag *d);
const mech_model *vbase_model(const variant_base *b);
/* The leaves its system was built with (the varied parameters). */
const sys_leaves *vbase_leaves(const variant_base *b);
/* Its forces flag (mech_solve_options.forces). */
int vbase_forces(const variant_base *b);
/* The base's own analysis: its numbers are the base model's (set-up). */
const mech_analysis *vbase_analysis(const variant_base *b);

/* ==== sensitivity ==== */
/* sensitivity.c: the sensitivity plan (sensitivity.c): the symbolic
 * derivatives of the loop equations and of the outputs by the parameters,
 * compiled once, evaluated per row and parameter (sens_row). Private to
 * sensitivity.c and sensitivity_table.c. */
/* Tangent maps (sens_plan.map): variable -> the variable of its derivative, or -1. */
enum { MAP_T, MAP_P0, MAP_P1, MAP_P2, MAP_P, NMAPS };
/* Kinds of output (sens_output_expr). */
enum { SENS_POINT, SENS_LINK, SENS_SLIDER };

typedef struct sens_plan {
    mech_system *sys;     /* SYS_LEAF_CARTESIAN: coordinates are leaves; sys->dxy[k] is
                             d(coordinates)/d(each parameter asked for) */
    int n, npoints;       /* unknowns; points of all links */
    /* variables beyond the system's (sys->nvars): x'' [n], dC/dp [2 npoints],
       X = dx/dp [n], V = dx'/dp [n], A = dx''/dp [n] */
    int v_xdd, v_D, v_X, v_V, v_A, nvars;
    int *map[NMAPS];      /* [nvars] each */
    ex *g[3];             /* [m] P0 f, P1 T f, P2 T T f */
    ex *ox, *oy;          /* [nlinks] frame origins along the spanning tree */
    ex *out;              /* [nout] output roots: P e, P T e, P T T e per output */
    int nout, capout;
    int *vars;            /* [nvars] workspace of expr_vars */
    tape tp;              /* phases: J and P0 f; P1 T f; P2 T T f; outputs */
    double *reg;          /* [tp.nreg] */
    double *lu;           /* [n * n] LU of J, row-major */
    int *piv;             /* [n] */
    double *rhs;          /* [n] */
} sens_plan;

/* The plan for the parameters which[0..nwhich-1] of m. MECH_OK or an error
 * in d (a parameter that moves a slider's angle or a gear pair's numbers,
 * redundant constraints). */
int sens_plan_new(sens_plan *sp, const mech_model *m, const int *which, int nwhich,
                  mech_diag *d);
void sens_plan_free(sens_plan *sp);
/* The position expression of an output: a point (obj = name id, comp 0 x,
 * 1 y), a link's angle or a slider's displacement (obj = index). */
int sens_output_expr(sens_plan *sp, int kind, int obj, int comp, ex *e);
/* Add P e, P T e, P T T e as output roots *first_root .. + 2. */
int sens_add_output(sens_plan *sp, ex e, int *first_root);
int sens_plan_compile(sens_plan *sp, mech_diag *d);
/* state: x [n], q, x' [n], q', q'' (SYS_NVARS order), then x'' [n]. out[nout]:
 * the outputs' derivatives by parameter `param` (index into the plan's).
 * 0, or -1 when J is singular there. */
int sens_row(sens_plan *sp, const double *state, int param, double *out);
/* sensitivity_table.c: the table of m at the driver positions q[0..nq-1]
 * (in order; mech_analysis_solve) with the columns d(COL)/d(NAME) of
 * mech_sensitivity for the parameters names[0..nnames-1] (mech fit).
 * MECH_OK; MECH_ESOLVE when a row is missing (the table holds the rows
 * solved, without derivatives); or an error in d. */
int sens_table_at(const mech_model *m, const mech_solve_options *o, const double *q, int nq,
                  const char *const *names, int nnames, mech_table *table, mech_diag *d);

/* ==== fit ==== */
/* fit.c: the least-squares problem of mech fit (docs/synthesis.md):
 * residuals r[i ncols + j] = weight[j] (y_j(p; q_i) - target[i][j]) of the
 * solved position columns cols[] at the driver positions q[] (an angle's
 * difference taken in (-pi, pi]; a NaN target contributes 0), the free
 * parameters p = the file's parameters names[], and the exact Jacobian
 * from the sensitivities. Each evaluation loads the file with the
 * parameters replaced (mech_load_file_with) and solves the targets' rows
 * in order (continuation from one to the next). */
typedef struct fit_problem {
    const char *path;          /* the mechanism file, borrowed */
    int nfree;
    const char **names;        /* [nfree] free parameters, borrowed */
    char (*unit)[32];          /* [nfree] their SI units (fit_prepare) */
    mech_mark *mark;           /* [nfree] their keys in the file (fit_prepare) */
    int nq;                    /* target rows */
    const double *q;           /* [nq] driver positions, SI, in sweep order */
    int ncols;
    const char **cols;         /* [ncols] target columns ("P.x"), borrowed */
    char (*col_unit)[16];      /* [ncols] their SI units (fit_prepare) */
    char qunit[16];            /* the driver's SI unit (fit_prepare) */
    const double *target;      /* [nq * ncols] SI, row-major; NaN: none */
    const double *weight;      /* [ncols] or NULL (all 1) */
    char *outputs;             /* the objects the columns need, "P,rocker"; owned */
    long nsolves;              /* evaluations so far */
    unsigned long seed;        /* 0: the Halton starts as they are; else each coordinate
                                  shifted by a random fraction of its bounds (mod 1) drawn
                                  from this seed (--seed) */
    int free_timing;           /* 1: the driver positions are unknowns too, p[nfree + i]
                                  (q is then only the start); dr/dq from the rates */
    /* called by fit_eval after each evaluation that assembles, with the
     * count of solves so far and the objective sum r^2 there (bench/bench_fit.c
     * traces the objective against the solves); NULL: none */
    void (*observe)(void *ctx, long nsolves, double objective);
    void *observe_ctx;
    /* the constraints of the file's fit: section (fit_prepare), as values
     * g <= 0 after the target residuals: the ncons expressions, then with
     * a transmission one per target row, g_i = min - asin|sin(a_i - b_i)| */
    int ncons;                 /* expression constraints */
    int trans;                 /* 1: a transmission constraint (its links' angles solved) */
    char trans_a[64], trans_b[64];  /* its links: set before fit_prepare (--transmission),
                                  else fit_prepare takes the file's */
    double trans_min;          /* its least angle, rad */
    double *con_scale;         /* [ncons] the size each tolerance is relative to; owned */
} fit_problem;

/* The constraint values after the nq ncols target residuals. */
static inline int fit_ncons(const fit_problem *fp)
{
    return fp->ncons + (fp->trans ? fp->nq : 0);
}
static inline int fit_nres(const fit_problem *fp)
{
    return fp->nq * fp->ncols + fit_ncons(fp);
}
/* A constraint value g counts as violated above this (docs/synthesis.md 4). */
static inline double fit_con_tolerance(const fit_problem *fp, int c)
{
    double s = c < fp->ncons ? fp->con_scale[c] : 1.0;  /* the transmission's: 1 rad */
    return 1e-9 * (s > 1e-300 ? s : 1.0);
}
/* MECH_OK when every constraint value of r[fit_nres] (fit_eval's) holds to
 * its tolerance, else MECH_ESOLVE. */
int fit_feasible(const fit_problem *fp, const double *r);

/* The unknowns of the problem: the free parameters, and with free timing
 * one driver position per target row. */
static inline int fit_nvars(const fit_problem *fp)
{
    return fp->nfree + (fp->free_timing ? fp->nq : 0);
}

/* Load and check the file, find the free parameters (their values into
 * p0[nfree], units and marks into fp) and the columns (their units):
 * MECH_OK, or an error in d naming the unknown parameter or column. */
int fit_prepare(fit_problem *fp, double *p0, mech_diag *d);
/* r[fit_nres] at p[fit_nvars] (the target residuals, then the constraint
 * values g) and, when jac is not NULL, dr/dp into jac[k * fit_nres + row]
 * (column-major, MINPACK's layout). MECH_OK;
 * MECH_ESOLVE (nothing in d) when the mechanism does not assemble at
 * every target; MECH_ENOMEM. */
int fit_eval(fit_problem *fp, const double *p, double *r, double *jac, mech_diag *d);
/* The constraint whole-range: MECH_OK when the mechanism at p assembles at
 * every row of the file's own driver range (a crank from 0 to 360 deg: it
 * turns fully), else MECH_ESOLVE (nothing in d); one solve. */
int fit_check_range(fit_problem *fp, const double *p, mech_diag *d);
/* The file at p solved over its own driver range (positions of the
 * target columns' objects, fp->outputs) into *t: the traced curve of `mech
 * fit --plot`. MECH_OK; MECH_ESOLVE with the rows solved in *t (t->gaps
 * lists the missing ones) when it does not assemble everywhere; an error
 * in d (nothing in *t) when the file does not load. Not a counted solve. */
int fit_sweep(const fit_problem *fp, const double *p, mech_table *t, mech_diag *d);
/* The same sweep of the loaded, checked model m as it is (mech plot's and
 * mech report's figure of a file with a fit: section: its own curve). */
int fit_sweep_model(const fit_problem *fp, const mech_model *m, mech_table *t, mech_diag *d);
/* The objective F(p) = sum r^2 of the residuals fit_eval computes (r[nq
 * ncols] the workspace): MECH_OK, MECH_ESOLVE when the mechanism does not
 * assemble at every target, MECH_ENOMEM. For minimisers without gradients
 * (bench/bench_fit.c, NLopt): the same evaluation as the fit's. */
int fit_objective(fit_problem *fp, const double *p, double *r, double *objective, mech_diag *d);
void fit_problem_free(fit_problem *fp);

/* fit_lm.c: one local fit of fp from p[fit_nvars] (in: the start, in the
 * bounds lo[k] < hi[k], or both infinite: none; out: the solution) by
 * MINPACK's lmder with the bounds as a change of variable and the
 * constraints as a shifted penalty; r[fit_nres]: the solution's residuals
 * and constraint values, *objective the targets' sum of squares, *info
 * lmder's (-2: rejected, a constraint violated). MECH_OK; MECH_ESOLVE when
 * the start does not assemble at every target, or the solution does not
 * or violates a constraint; MECH_ENOMEM. */
int fit_lm(fit_problem *fp, const double *lo, const double *hi, double *p, double *r,
           double *objective, int *info);

enum { FIT_MAX_FREE = 32, FIT_MAX_TIMED = 512, FIT_MAX_VARS = FIT_MAX_FREE + FIT_MAX_TIMED };
typedef struct fit_start {
    double p[FIT_MAX_VARS];  /* the parameters, then (free timing) the driver positions */
    double objective;        /* the targets' sum of squares; INFINITY: rejected */
    int rc, info;            /* fit_lm's (then whole-range's) status, lmder's info */
    long solves;
} fit_start;
/* n local fits on jobs threads (0: the default): start 0 at p0, start i at
 * the Halton point i of the bounds (a parameter without bounds at p0); with
 * whole_range each solution must assemble over the file's range
 * (fit_check_range). st[n] sorted by objective (the rejected last).
 * MECH_OK, or MECH_ENOMEM (MECH_EINPUT: too many unknowns). */
int fit_run_starts(const fit_problem *fp, const double *lo, const double *hi, const double *p0,
                   int whole_range, int n, int jobs, fit_start *st);

/* ==== flywheel ==== */
/* flywheel.c: flywheel sizing from the driver torque over one cycle
 * (docs/forces.md section 8): the mean torque, the largest fluctuation of
 * the energy, and the inertia that keeps the speed within a coefficient of
 * speed fluctuation. Used by mech solve --stats and mech sweep --metric. */
typedef struct flywheel_figures {
    double mean_torque;  /* N*m: integral of T dq over the rows, / (q_last - q_first) */
    double fluctuation;  /* J: max - min of E(q) = integral of (T - mean) dq */
    double q_low, q_high;/* rad: where E is lowest and highest */
    double span;         /* rad: q_last - q_first */
    double speed;        /* rad/s: the driver's speed (its magnitude) */
    double inertia;      /* kg*m^2: fluctuation / (cs speed^2); NAN without cs or speed */
    int full_cycle;      /* 1: the rows cover one turn exactly, without gaps */
} flywheel_figures;

/* The figures of a solved table with a driver.torque column, crank driver
 * of model m; cs the coefficient of speed fluctuation (0: no inertia).
 * Trapezoidal rule on the rows. Returns 0, or -1 with the reason in why
 * (no torque column, a slider driver, fewer than two rows). */
int flywheel_compute(const mech_table *t, const mech_model *m, double cs, flywheel_figures *f,
                     char *why, size_t size);

/* Print the figures (mech solve --stats), with a note when the rows are
 * not one full turn. */
void flywheel_print(const flywheel_figures *f, double cs, FILE *out);

/* ==== sweep_plan ==== */
/* sweep_plan: the parts of a sweep (mech_sweep, include/mech.h):
 * what it varies (sweep_grid.c: a grid of parameter values, or random
 * samples within the tolerances), what it measures (sweep_metrics.c), and
 * the object that holds both and runs the variants (sweep_run.c). Private
 * to those files, and to mech sweep's manifest (cmd_sweep.c hashes the
 * grid's texts and writes the samples' tolerances) and the checks of the
 * rows read back (cmd_rowcheck.c: a row's parameters are grid_value's). */
enum {
    SWEEP_MAX_AXES = 32,     /* parameters of a variant (--random: with a tolerance) */
    SWEEP_MAX_GRID = 8,      /* --vary/--list options */
    SWEEP_MAX_METRICS = 32,
    SWEEP_MAX_VARIANTS = 10000000
};

/* One parameter of the sweep. */
typedef struct sweep_axis {
    char name[64];
    char **texts;         /* [count] its texts in the grid, e.g. "135 mm" */
    double *si;           /* [count] their values in SI (or the bare number) */
    char unit[32];        /* the SI unit of the values, "-" for bare numbers */
    char spec[160];       /* the option as given, "--vary c=0:1000:3" ("" for --random) */
    int count;            /* random: 0 */
    double nominal, tol;  /* random: the file's value and tolerance (SI) */
} sweep_axis;

typedef enum {
    MET_RANGE, MET_MAX, MET_MIN, MET_MAXABS, MET_TRANSMISSION, MET_FLYWHEEL
} sweep_metric_kind;

/* One summary of a variant's table. */
typedef struct sweep_metric {
    sweep_metric_kind kind;
    char col[128], col2[128];  /* column names (transmission: the two links' angles) */
    char label[160];           /* the spec, ',' made '/': a CSV header cell */
    char unit[32];             /* of the column (transmission: rad), set by prepare */
    double cs;                 /* flywheel: coefficient of speed fluctuation */
} sweep_metric;

struct mech_sweep {
    char *path;                /* the file (prepared) */
    mech_sweep_options opt;
    sweep_axis axes[SWEEP_MAX_AXES];
    int naxes;
    int ngrid;                 /* axes added by vary/list (before --random's) */
    sweep_metric metrics[SWEEP_MAX_METRICS];
    int nmetrics;
    long total, count;         /* variants in all, in this shard */
    int prepared;              /* mech_sweep_prepare was called ... */
    int ready;                 /* ... and accepted it: mech_sweep_run may go */
    sweep_shared *shared;      /* the parsed file and the analysis variants share */
};

/* ---- sweep_grid.c ---- */
/* One --vary ("NAME=FROM:TO:COUNT") or --list ("NAME=A,B,...") into a new
 * axis of s. MECH_OK, MECH_EINPUT or MECH_ENOMEM (the problem in d). */
int grid_add(mech_sweep *s, const char *spec, int is_list, mech_diag *d);
/* --random: an axis per parameter of m that has a tolerance. MECH_OK or
 * MECH_EINPUT (none, or more than SWEEP_MAX_AXES). */
int grid_random_axes(mech_sweep *s, const mech_model *m, mech_diag *d);
/* One such axis: its name, SI unit ("" or "-": a bare number), the file's
 * value and tolerance (SI); also mech merge's, from a manifest's tol=
 * (cmd_rowcheck.c). MECH_OK, or MECH_EINPUT past SWEEP_MAX_AXES. */
int grid_random_axis(mech_sweep *s, const char *name, const char *unit, double nominal,
                     double tol, mech_diag *d);
/* The variants in all: the product of the counts, or nrandom. MECH_OK, or
 * MECH_EINPUT above SWEEP_MAX_VARIANTS. */
int grid_total(mech_sweep *s, mech_diag *d);
/* Parameter k of variant `index` (index_offset included), SI. */
double grid_value(const mech_sweep *s, long index, int k);
/* The parameter texts of variant `index`: ov[k] = {name, text}, the text
 * in text[k] for random samples (SI with the unit). */
typedef char sweep_text[64];
void grid_overrides(const mech_sweep *s, long index, mech_override *ov, sweep_text *text);
void grid_free(mech_sweep *s);
/* The file does not load with the first variant's values: an error naming
 * each option whose values are bare numbers for a parameter the file gives
 * a unit (`--vary c=0:1000:3` for `c: 30 mm`); how many. */
int grid_bare_values(const mech_sweep *s, mech_diag *d);

/* ---- sweep_metrics.c ---- */
/* One --metric spec into s. MECH_OK or MECH_EINPUT. */
int metric_add(mech_sweep *s, const char *spec, mech_diag *d);
/* Every metric's columns in the header t (the base variant's columns,
 * forces as asked), each unit set. MECH_OK or MECH_EINPUT (a column missing,
 * with the nearest one when it looks like a typo). */
int metric_check(mech_sweep *s, const mech_table *t, mech_diag *d);
/* Metric mt of a variant's table t (m: its model); why it has none goes
 * to msg. NaN when it cannot be computed. */
double metric_value(const sweep_metric *mt, const mech_table *t, const mech_model *m, FILE *msg);

/* A problem with the sweep's arguments (the file MECH_SWEEP_ARGUMENTS);
 * returns MECH_EINPUT. */
int sweep_arg_error(mech_diag *d, const char *fmt, ...) MECH_PRINTF(2, 3);

#endif
