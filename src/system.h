/* src/system.h: the equation system built once per mechanism: unknowns,
 * loops, the symbolic residual and its derivatives, and the compiled tape. */
#ifndef MECH_SYSTEM_H
#define MECH_SYSTEM_H

#include "expr.h"
#include "spantree.h"
#include "internal.h"
#include "rows.h"
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

/* How the model's numbers enter the equations (sys_new_with). */
typedef enum {
    SYS_NUMERIC,   /* folded constants: the solver's system (mech_system_new) */
    SYS_NAMED,     /* the lengths and angles of body vectors that depend on parameters
                      are named leaves: the parameter itself (`r`), or |AB| and <AB
                      defined in coef_desc (mech equations); not compiled */
    SYS_CARTESIAN, /* each body vector written R(theta) (P1 - P0) with the points'
                      coordinates as variables (sensitivity.c); not compiled */
    SYS_REGISTERS  /* as SYS_NUMERIC, but the length and angle of a body vector that
                      depend on a parameter are variables (sys_coef), set per variant
                      in the registers (mech sweep: variant_regs.c); not compiled here,
                      the solver plan compiles it */
} sys_mode;

/* SYS_REGISTERS: coefficient variable SYS_NVARS(n) + k is the length
 * (is_angle 0) or the angle of the vector p0 -> p1 of link `link`. */
typedef struct sys_coef {
    int link, p0, p1;
    int is_angle;
} sys_coef;

/* The parameters and d(point coordinates)/d(parameter), from seeded loads
 * (load_file_seeded): what SYS_NAMED needs to see which numbers depend on
 * which parameter. */
typedef struct sys_params {
    int nparams;
    const char *const *names;   /* [nparams] */
    const double *values;       /* [nparams] SI */
    const char *const *units;   /* [nparams] their SI units ("" for a bare number) */
    double **dxy;               /* [nparams] -> [2 * points of all links, link by link] */
} sys_params;

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
/* SYS_NAMED: coefficient k is variable SYS_NVARS(n) + k (the parameters
 * first, then |AB| and <AB); SYS_CARTESIAN: point gp's coordinates (gp =
 * point_base[link] + index) are variables SYS_COORD(n, gp) and + 1. */
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
    sys_mode mode;
    const sys_params *params;  /* SYS_NAMED: borrowed */
    int *point_base;           /* [nlinks + 1] global index of each link's first point */
    int nvars;                 /* variables in the DAG: SYS_NVARS(n) + coefficients */
    int nnames;                /* entries of names and latex (SYS_NAMED: nvars) */
    char **coef_desc;          /* [nvars - SYS_NVARS(n)] SYS_NAMED: what a coefficient is
                                  ("length of E - B in link 'tray' = 564.97 mm"), or NULL
                                  for a parameter */
    struct param_grad *grad;   /* owned by mech_system_new_named, or NULL */
    sys_coef *coef;            /* [nvars - SYS_NVARS(n)] SYS_REGISTERS: the coefficients */
    tape tp;                   /* compiled evaluator of every row */
    double *reg;               /* [tp.nreg] its registers, for sys_eval_* (so those
                                  are not for threads sharing the system; the solver
                                  compiles its own tape and keeps registers per state) */
};

/* mech_system_new in another mode (SYS_NAMED needs params). */
int sys_new_with(const mech_model *m, sys_mode mode, const sys_params *params,
                 mech_system **out, mech_diag *d);

/* system_coef.c: the body vectors of SYS_NAMED and SYS_CARTESIAN, and
 * their coefficients (point_base, the parameters' names). */
int sys_coefficients_init(mech_system *s);
void sys_named_body(mech_system *s, const loop_term *t, ex *x, ex *y);
void sys_cartesian_body(mech_system *s, const loop_term *t, ex *x, ex *y);
void sys_register_body(mech_system *s, const loop_term *t, ex *x, ex *y);
/* SYS_REGISTERS: the variable of body term t's length (is_angle 0) or
 * angle (1) when it is a register leaf, else -1 (variant_regs.c sets it). */
int sys_coef_var(const mech_system *s, const loop_term *t, int is_angle);
/* Body term t's vector in model m: components, length and angle, as the
 * systems write it (variant_regs.c compares a variant's with the base's). */
void sys_body_vector(const mech_model *m, const loop_term *t, double *dx, double *dy, double *r,
                     double *a);

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
