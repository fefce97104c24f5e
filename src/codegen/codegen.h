/* src/codegen/codegen.h: mech codegen: the standalone C of one mechanism around the runtime's text.
 * The stage's one header: what its modules share with each other and with
 * the later stages (docs/architecture.md, "Stages"). */
#ifndef MECH_CODEGEN_STAGE_H
#define MECH_CODEGEN_STAGE_H

#include <stdio.h>

#include "solve.h"
#include "study.h"

/* ==== codegen ==== */
/* codegen.c: `mech codegen`, a standalone C11 solver for one mechanism
 * (docs/codegen.md). codegen_init analyses the mechanism as `mech solve`
 * does (the same solver plan: the blocks the outputs need, the same tape
 * roots); the emitters print the header and the source: straight-line code
 * for the residual, the Jacobian and the rate right-hand sides, tables for
 * the block triangular form's dense solves, and the Newton, condition and
 * branch logic of src/solve/solve.c and src/solve/continuation.c. */
/* Largest number of unknowns solved that codegen writes code for (the
 * dense blocks and the straight-line code grow with it). */
enum { CODEGEN_MAX_UNKNOWNS = 400 };

typedef struct codegen_options {
    const char *prefix;      /* C identifier prefix of the public names ("fourbar") */
    const char *header;      /* the header's name as #included by the source, or NULL:
                                the source declares everything itself */
    int all_blocks;          /* 1: solve every unknown, not only those the outputs need */
    int forces;              /* 1: the kinetostatics too, -1: not, 0: as the file's outputs say */
    int friction;            /* MECH_FRICTION_ON, _OFF or _BOTH (with forces) */
    int anonymous;           /* 1: the comments name neither the file nor its title, so
                                that files of one mechanism give one source (mech solve
                                --jit's cache) */
    const sys_leaves *leaves; /* non-NULL: one solver for a sweep's variants: the system
                                has these leaves (variant_regs.c's) and the source reads
                                every number a variant may change from the state
                                (P_numbers) instead of literals */
} codegen_options;

typedef struct codegen {
    const mech_model *m;     /* borrowed */
    codegen_options opt;
    char lower[64], upper[64]; /* the prefix, as given and upper-cased */
    solver_plan sp;          /* what mech solve would solve */
    blocklu_plan bp;         /* block triangular form of the solved Jacobian (any block size) */
    column_layout cols;      /* the kinematic output columns, as mech solve names them */
    char **col_ident;        /* [cols.ncols] enum identifier of each column */
    char **unk_ident;        /* [sp.ns] enum identifier of each solved unknown */
    /* expression emission (codegen_expr.c) */
    int *phase;              /* [DAG nodes] phase (0 driver alone, 1 position, 2 velocity,
                                3 acceleration) whose function computes the node, -1: none */
    int *keep;               /* [DAG nodes] slot in the state's keep[] for a node used by a
                                later phase, -1: none */
    int nkeep;
    int leaf0, nleaf;        /* the leaves' slots in keep[] (after the kept nodes) */
    int *point_at;           /* [nlinks] first point of each link in rt_numbers.points */
    int *driver_only;        /* [DAG nodes] 1: depends on the driver q alone, 0 not, -1 unknown */
    int *unk_col;            /* [n] solved column of each unknown of the system, -1: not solved */
    /* forces (codegen_forces.c) */
    int want_forces;         /* the joint reactions are generated too */
    int fp_ready;            /* fp was initialised (to free) */
    forces_plan fp;          /* the interpreter's force system: columns, pattern, its blocks */
} codegen;

/* Analyse m for code generation: MECH_OK, or MECH_EINPUT (redundant
 * constraints, too many unknowns, an expression the emitter does not know)
 * or MECH_ENOMEM, with the message in d. */
int codegen_init(codegen *g, const mech_model *m, const codegen_options *o, mech_diag *d);
void codegen_free(codegen *g);

/* Emitters for write_file_whole: ctx is the codegen; 0, or -1 when a
 * write failed. */
int codegen_emit_header(FILE *f, const void *ctx);
int codegen_emit_source(FILE *f, const void *ctx);

/* ---- codegen_expr.c: the DAG as C statements ---------------------------- */

/* Assign each node of the three phases' roots a phase and keep slots;
 * MECH_OK, MECH_EINPUT (an unknown node kind or a variable outside the
 * solved set, with the message in d) or MECH_ENOMEM. */
int codegen_expr_plan(codegen *g, mech_diag *d);
/* The functions eval_driver, eval_position, eval_velocity, eval_accel; 0 or -1. */
int codegen_expr_emit(const codegen *g, FILE *f);
/* codegen_expr.c: the tables and the call of each law of time the DAG holds as
 * an opaque function (rt_law.h), before the phases that call them. */
void codegen_laws_emit(const codegen *g, FILE *f);
/* The function kinematics: link frames, output columns, branch values. */
int codegen_kin_emit(const codegen *g, FILE *f);
/* build/gen/rt_text.c (Makefile, tools/c_lines.awk): the text of the runtime
 * libmech shares with the generated code, src/runtime/rt_NAME.h as codegen_rt_NAME,
 * one line each, NULL-terminated. */
extern const char *const codegen_rt_base[];
extern const char *const codegen_rt_blocklu[];
extern const char *const codegen_rt_newton[];
extern const char *const codegen_rt_frame[];
extern const char *const codegen_rt_forces[];
extern const char *const codegen_rt_law[];
extern const char *const codegen_rt_solver[];

/* ---- codegen_forces.c: the kinetostatics ---------------------------------- */

/* The interpreter's force plan for g (g->want_forces); MECH_OK or an error in d. */
int codegen_forces_plan(codegen *g, mech_diag *d);
/* Header: the force enum (P_NF, the force statuses); the state's force fields. */
void codegen_forces_enums(const codegen *g, FILE *f);
void codegen_forces_state(const codegen *g, FILE *f);
/* Source: the force tables and functions, then the fixed force solve; 0 or -1. */
int codegen_forces_emit(const codegen *g, FILE *f);

/* ---- codegen_state_loads.c: the loads that depend on the motion ---------- */

/* MECH_OK, or MECH_EINPUT for an input or operation the emitter does not know. */
int codegen_sl_check(const codegen *g, mech_diag *d);
/* The state's register file (nothing without such loads). */
void codegen_sl_state(const codegen *g, FILE *f);
/* force_state_loads(s, F, q, qd, qdd): the register program; 0 or -1. */
int codegen_sl_emit(const codegen *g, FILE *f);

/* "1.5", "(-2)", as a C double literal that reads back to v. */
void codegen_number(char *buf, size_t size, double v);
/* "x, y" of point i of link l: literals, or the variant's (opt.leaves). */
void codegen_point_xy(const codegen *g, int l, int i, char *buf, size_t size);

/* ---- one solver for a sweep's variants (opt.leaves) ------------------------ */

/* The numbers P_numbers takes, of variant model mv solved through view (an
 * analysis of g's structure: variant_regs.c's): pointers into view and
 * two arrays of its own (the points, the guesses). */
typedef struct codegen_numbers {
    struct rt_numbers n;
    double *points, *guess;
} codegen_numbers;
/* 0, or -1 out of memory. */
int codegen_numbers_fill(const codegen *g, const mech_analysis *view, const mech_model *mv,
                         codegen_numbers *out);
void codegen_numbers_free(codegen_numbers *c);

#endif
