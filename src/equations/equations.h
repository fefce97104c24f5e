/* src/equations/equations.h: the loop-closure equations: spanning tree, loops, the symbolic system
 * and its rows, gear pairs, the structural check, their printing. The stage's one header: what its
 * modules share with each other and with the later stages (docs/architecture.md, "Stages"). */
#ifndef MECH_EQUATIONS_STAGE_H
#define MECH_EQUATIONS_STAGE_H

#include "mech.h"
#include "base.h"
#include "symbolic.h"
#include "load.h"
#include "rt_forces.h"

/* ==== spantree ==== */
/* spantree.c: the breadth-first spanning tree of the link/joint graph,
 * rooted at the ground; built once per system (system.c). The automatic
 * loops are closed by its off-tree joints (loops.c), and the link frames
 * are placed along it, each from its parent (kinematics.c), so each point
 * is reached by the shortest chain of links. */
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

/* ==== rows ==== */
/* rows.c: the one description of the equation system's rows, as
 * columns.h describes the table's columns.
 *
 * Each row is a loop's x or y closure, a gear pair's rolling condition, a
 * cam pair's lift or a driver's law, in that order; its descriptor says which, whose (the
 * loop, gear or driver) and where that is in the file. The system
 * (system.c) is built from the descriptors; `mech equations` (print.c),
 * the diagnostics (diagnose.c), the drivers' structure check (drivers.c)
 * and the structure counts (model.c) read them, and the force analysis
 * (forces.c) names its gear and driver columns with the same words, so
 * nothing else derives the row layout. */
typedef enum { ROW_LOOP_X, ROW_LOOP_Y, ROW_GEAR, ROW_CAM, ROW_DRIVER } row_kind;
enum { ROW_KINDS = 5 };

typedef struct row_desc {
    row_kind kind;
    int owner;       /* LOOP_X, LOOP_Y: the loop (of the system's loop set); GEAR: the
                        gear pair (m->gears); CAM: the cam pair (m->cams); DRIVER:
                        the driver (m->drivers) */
    mech_mark mark;  /* the owner's place in the file ({0, 0}: a loop found
                        automatically) */
} row_desc;

/* The rows of model m with nloops loops, per kind into count[] (may be
 * NULL): 2 per loop, 1 per gear pair, 1 per cam, 1 per driver that is not the sweep
 * variable itself (drivers.h). Returns the total. */
int rows_count(const mech_model *m, int nloops, int *count);
/* The descriptors in row order ([rows_count] entries, at least one
 * allocated); loops_listed: the loops are the file's (their marks). NULL
 * when out of memory. */
row_desc *rows_build(const mech_model *m, int nloops, int loops_listed);

/* The owner of row r of system s in words: "loop 2 (A-B-C-D-A)",
 * "gear pair 'g12'", "driver 'crank'". */
const char *rows_owner(const mech_system *s, int r, char *buf, size_t size);
/* "gear pair 'g12'" (GEAR) or "driver 'crank'" (DRIVER): a constraint
 * that is not a loop, named from the model alone. */
const char *rows_constraint(const mech_model *m, row_kind kind, int owner, char *buf,
                            size_t size);
/* Rows a and b of s belong to one owner (a loop's x and y rows do). */
int rows_same_owner(const mech_system *s, int a, int b);

/* ==== system ==== */
/* system.c: the equation system built once per mechanism: unknowns,
 * loops, the symbolic residual and its derivatives, and the compiled tape. */
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

/* One build of the equations (sys_new_with) with a choice of leaves: the
 * numbers that some chosen parameters move (the model's parameter
 * expressions say which: param_expr.h) are variables of the DAG, every other
 * number is folded to a constant. The form says what the leaves are: */
typedef enum {
    SYS_LEAF_POLAR,    /* a body vector r (cos, sin)(theta + a) with r and a leaves when a
                          chosen parameter moves them (sys_coef), their values taken from
                          a model by the plan (sys_leaf_value): the sweep's registers; with
                          no parameter chosen, the solver's system (mech_system_new) */
    SYS_LEAF_NAMED,    /* the same leaves named for printing: the parameter itself (`r`), or
                          |AB| and <AB described in coef_desc; the parameters are the first
                          leaves (mech equations) */
    SYS_LEAF_CARTESIAN /* R(theta) (P1 - P0), every point's coordinates leaves (SYS_COORD):
                          the sensitivities differentiate through them, and d/d(parameter)
                          of the coordinates is sys.dxy */
} sys_leaf_form;

typedef struct sys_leaves {
    sys_leaf_form form;
    const int *params;  /* [nparams] the chosen parameters (indices into the model's) */
    int nparams;
} sys_leaves;

/* What leaf variable SYS_NVARS(n) + k stands for. */
typedef enum { LEAF_PARAM, LEAF_LENGTH, LEAF_ANGLE, LEAF_COORD } sys_leaf_kind;
typedef struct sys_coef {
    sys_leaf_kind kind;
    int link, p0, p1;   /* LENGTH, ANGLE: the vector from point p0 to p1 of link `link`;
                           COORD: point p0 of `link`, coordinate p1 (0 x, 1 y) */
    int param;          /* PARAM: the parameter (index into the model's) */
} sys_coef;

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
/* Leaf k is variable SYS_NVARS(n) + k; SYS_LEAF_CARTESIAN: point gp's
 * coordinates (gp = point_base[link] + index) are SYS_COORD(n, gp) and + 1. */
#define SYS_COORD(n, gp) (SYS_NVARS(n) + 2 * (gp))

struct mech_system {
    const mech_model *model;   /* borrowed; must outlive the system */
    int n;                     /* unknowns */
    int m;                     /* equations (rows.h: 2 per loop, 1 per gear pair, 1 per
                                  driver that is not the sweep): n, or more with redundant
                                  constraints (solved in the least-squares sense) */
    row_desc *rows;            /* [m] what each row is, whose and where (rows.h) */
    int nrows_of[ROW_KINDS];   /* rows of each kind */
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
    ex *f;                     /* [m] residual rows, as rows[] describes them */
    int *Jp;                   /* [n+1] column pointers of the m x n Jacobian df/dx (CSC) */
    int *Ji;                   /* [nnz] row indices, ascending within a column */
    ex *Jx;                    /* [nnz] nonzero expressions */
    int nnz;
    ex *fq;                    /* [m] df/dq */
    ex *vel;                   /* [m] velocity right-hand side  -df/dq qdot */
    ex *acc;                   /* [m] acceleration right-hand side */
    sys_leaf_form form;
    int nparams;               /* the parameters chosen (sys_leaves) */
    int *param;                /* [nparams] their indices in the model */
    double **dxy;              /* [nparams] d(point coordinates)/d(param[k]): 2 per point,
                                  link by link (the model's parameter expressions) */
    double *grad;              /* [2 nparams] work: a length's and an angle's gradient */
    int *point_base;           /* [nlinks + 1] global index of each link's first point */
    int nvars;                 /* variables in the DAG: SYS_NVARS(n) + leaves */
    int nnames;                /* entries of names and latex (SYS_LEAF_NAMED: nvars) */
    char **coef_desc;          /* [nvars - SYS_NVARS(n)] SYS_LEAF_NAMED: what a leaf is
                                  ("length of E - B in link 'tray' = 564.97 mm"), or NULL
                                  for a parameter */
    sys_coef *coef;            /* [nvars - SYS_NVARS(n)] what each leaf is */
    tape tp;                   /* compiled evaluator of every row, by the first sys_eval_* */
    double *reg;               /* [tp.nreg] its registers, for sys_eval_* (so those
                                  are not for threads sharing the system; the solver
                                  compiles its own tape and keeps registers per state) */
};

/* The equations of m with the leaves lv (mech_system_new: no parameter
 * chosen). Only the system with no leaves has its own tape, compiled by the
 * first sys_eval_*; the solver plan compiles a polar system's. */
int sys_new_with(const mech_model *m, const sys_leaves *lv, mech_system **out, mech_diag *d);

/* system_coef.c: the leaves (point_base, the chosen parameters and their
 * d(points)/dp; the named parameters) and the body vector of loop term t. */
int sys_leaves_init(mech_system *s, const sys_leaves *lv);
void sys_body_term(mech_system *s, const loop_term *t, ex *x, ex *y);
/* The value of leaf variable var in model m (a model with s's structure: the
 * system's own or a sweep variant's). */
double sys_leaf_value(const mech_system *s, const mech_model *m, int var);
/* SYS_LEAF_POLAR: the variable of body term t's length (is_angle 0) or
 * angle (1) when it is a leaf, else -1. */
int sys_coef_var(const mech_system *s, const loop_term *t, int is_angle);
/* Body term t's vector in model m: components, length and angle, as the
 * systems write it (variant_regs.c compares a variant's with the base's). */
void sys_body_vector(const mech_model *m, const loop_term *t, double *dx, double *dy, double *r,
                     double *a);

/* Evaluation through the system's tape (compiled by the first call; no
 * allocation after it; NaN when it cannot be: out of memory, or a system
 * with leaves). The velocity and acceleration phases reuse the position
 * phase's registers, so they must follow a position evaluation at the same
 * x and q. */
void sys_eval_position(mech_system *s, const double *x, double q, double *f, double *Jx);
/* The system's tape s->tp and registers s->reg, compiled if not yet: 0, or
 * -1 (out of memory, or a system with leaves). */
int sys_compile_tape(mech_system *s);
void sys_eval_velocity_rhs(mech_system *s, double qdot, double *rhs);
void sys_eval_accel_rhs(mech_system *s, const double *xdot, double qdot, double qddot,
                        double *rhs);

/* loops.c: the loops from the file (checked) or a cycle basis (the joints
 * off the spanning tree t). */
int loops_build(const mech_model *m, const span_tree *t, loop_set *ls, mech_diag *d);
void loops_free(loop_set *ls);
/* Attachment point of joint j on link l (point index in l). */
int loops_attach(const mech_joint *j, int l);

/* ==== gears ==== */
/* gears.c: gear pairs and racks (higher pairs): their constraint rows
 * after the loop rows of the residual, the geometry of the tooth force for
 * the kinetostatics, and their description for mech check
 * (docs/format.md section "Gears", docs/forces.md section 9). */
/* The constraint row of gear pair i (an expression in the link angles and
 * slider displacements of s; its place among the rows: rows.h), metres:
 *   PAIR: r_a (th_a - th_arm - o_a) + sign r_b (th_b - th_arm - o_b)
 *         (sign +1 external, -1 internal)
 *   RACK: s - o_s - side r (th_p - th_arm - o_p) */
ex gears_row(mech_system *s, int i);

/* The tooth force of gear pair i as the force system reads it (rt_forces.h
 * rt_gear_contact): its pitch point p, the common tangent t there (n
 * rotated +90 deg, n the unit from link[0]'s centre through p) and the unit
 * r that pushes link[1] away from link[0]'s teeth (along n or against it).
 * The force on link[1] is F t + |F| tan(pressure angle) r (the line of
 * action of the flank that carries it), its opposite on link[0]; F is the
 * force system's unknown. */
void gears_rt(const mech_model *m, int i, rt_gear *out);

/* check.c: the higher pairs' terms of Gruebler's count, " - 2 gears - 1 cam"
 * (empty without any), as mech check's summary and its error show them. */
void check_higher_pairs_text(const mech_summary *s, char *buf, size_t size);

/* Gear pair i in words, as mech check shows it. */
void gears_describe(const mech_model *m, int i, char *buf, size_t size);

/* ==== cams ==== */
/* cams.c: cam-follower pairs (higher pairs, docs/cams.md): the row of cam
 * i after the gear rows,
 *   coordinate - c0 - rise s(x),  x = sense (th_cam - th_arm - start),
 * the coordinate the follower's slider displacement (m) or its angle on
 * the arm (rad); s the program (an opaque call, law_expr: its derivatives
 * exact, the generated code's the runtime's rt_law.h). */
ex cams_row(mech_system *s, int i);
/* Cam pair i in words, as mech check shows it. */
void cams_describe(const mech_model *m, int i, char *buf, size_t size);
/* Its design quantities (the worst of each and where), as mech check shows them. */
void cams_design(const mech_model *m, int i, char *buf, size_t size);

/* ==== driver_checks ==== */
/* The drivers against the structure (driver_checks.c). check.c: the error
 * of a mechanism with `mobility` degrees of freedom and a different number
 * of drivers: the drivers in conflict, or the links left free. */
void drivers_report_count(const mech_model *m, int mobility, mech_diag *d);
/* solve.c, when the system with drivers is structurally singular: an error
 * naming the drivers that over-determine their part of the mechanism and
 * the unknowns left free (a maximum matching of rows and unknowns and its
 * Dulmage-Mendelsohn parts). MECH_EINPUT, or MECH_ENOMEM. */
int drivers_report_structure(const mech_system *s, mech_diag *d);

#endif
