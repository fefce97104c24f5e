/* src/symbolic/symbolic.h: symbolic expressions (a hash-consed DAG with derivatives) and the
 * register tape compiled from them. The stage's one header: what its modules share with each other
 * and with the later stages (docs/architecture.md, "Stages"). */
#ifndef MECH_SYMBOLIC_STAGE_H
#define MECH_SYMBOLIC_STAGE_H

#include <stddef.h>
#include <stdio.h>

/* ==== expr ==== */
/* expr.c: the symbolic expression DAG (hash-consed, simplifying on
 * construction), its derivatives, direct evaluation and printing. */
/* ORDER OP: expr_eval, expr_diff, expr_print and tape.c switch on these. */
typedef enum {
    EX_CONST, /* value */
    EX_VAR,   /* variable number `var` (see expr_ctx.nvars) */
    EX_ADD,   /* a + b */
    EX_MUL,   /* a * b */
    EX_NEG,   /* -a */
    EX_SIN,   /* sin(a) */
    EX_COS,   /* cos(a) */
    EX_CALL   /* fns[var].eval(data, order, a): the order-th derivative of an opaque
                 function of one argument (value = order); a law of time that the
                 DAG's operations cannot write (docs/motion-programs.md) */
} expr_op;

/* An opaque function of one argument known to a context: eval gives its
 * value (order 0) and its derivatives (order 1, 2, ...), NaN where it is
 * not defined. The DAG differentiates a call by the chain rule; the tape
 * calls eval; the code generator refuses it (its name in the message). */
typedef struct expr_fn {
    double (*eval)(const void *data, int order, double x);
    const void *data;
    const char *name;
} expr_fn;

typedef int ex; /* a node: index into expr_ctx.nodes */

typedef struct expr_node {
    expr_op op;
    int var;          /* EX_VAR: variable number */
    ex a, b;          /* operands (-1 if unused) */
    double value;     /* EX_CONST */
    int memo;         /* scratch for traversals: value valid when stamp matches */
    unsigned stamp;
} expr_node;

typedef struct expr_ctx {
    expr_node *nodes;   /* [count] of [cap] */
    size_t count, cap;
    int *table;         /* [tcap] hash table of node ids, -1 empty */
    size_t tcap;
    unsigned stamp;     /* traversal counter */
    int failed;         /* out of memory: every constructor then returns ex 0 */
    ex zero, one;
    expr_fn *fns;       /* [nfns] the functions EX_CALL nodes name */
    int nfns;
} expr_ctx;

int expr_init(expr_ctx *c);
void expr_free(expr_ctx *c);

ex expr_const(expr_ctx *c, double v);
/* The node (op, var, a, b, v) if the DAG already holds it, else -1: what
 * the constructors below would return for it, without making it (operands
 * as the constructors store them: -1 where unused, value 0 but for
 * EX_CONST). */
ex expr_find(const expr_ctx *c, expr_op op, int var, ex a, ex b, double v);
ex expr_var(expr_ctx *c, int var);
ex expr_add(expr_ctx *c, ex a, ex b);
ex expr_sub(expr_ctx *c, ex a, ex b);
ex expr_mul(expr_ctx *c, ex a, ex b);
ex expr_neg(expr_ctx *c, ex a);
ex expr_sin(expr_ctx *c, ex a);
ex expr_cos(expr_ctx *c, ex a);
/* The function fn of the context (expr_fn_add) or its order-th derivative, of a. */
ex expr_call(expr_ctx *c, int fn, int order, ex a);
/* The number of (eval, data) in c's table, added when new; -1 when out of memory. */
int expr_fn_add(expr_ctx *c, const expr_fn *fn);

static inline const expr_node *expr_at(const expr_ctx *c, ex e) { return &c->nodes[e]; }
static inline int expr_is_const(const expr_ctx *c, ex e, double v)
{
    return c->nodes[e].op == EX_CONST && c->nodes[e].value == v;
}

/* d e / d var, symbolic (memoised within one call). */
ex expr_diff(expr_ctx *c, ex e, int var);
/* Does e contain variable var? Appends the variables of e to vars[] (each
 * once, ascending is not guaranteed) and returns their number. */
int expr_vars(expr_ctx *c, ex e, int *vars, int max);
/* Evaluate by walking the DAG (reference for the tape). */
double expr_eval(expr_ctx *c, ex e, const double *vars);

/* Print e; names[var] give variable names. latex: 0 text, 1 LaTeX. */
typedef struct expr_names {
    const char *const *text;   /* [nvars] */
    const char *const *latex;  /* [nvars] */
} expr_names;
void expr_print(const expr_ctx *c, ex e, const expr_names *names, int latex, FILE *out);

/* ==== tape ==== */
/* tape.c: a flat register program compiled from the expression DAG.
 * Every DAG node needed gets one register; constants are loaded once at
 * compile time into the register image, variables are written by the
 * caller, and each instruction computes one node from registers.
 *
 * The program is immutable after compilation (and tape_hoist), so threads
 * share it; each thread runs it on its own register file, a copy of the
 * image made by tape_registers_new. Evaluation allocates nothing. */
/* ORDER TOP: tape_run switches on these. */
typedef enum {
    TOP_ADD, /* r[d] = r[a] + r[b] */
    TOP_MUL, /* r[d] = r[a] * r[b] */
    TOP_NEG, /* r[d] = -r[a] */
    TOP_SIN, /* r[d] = sin(r[a]) */
    TOP_COS, /* r[d] = cos(r[a]) */
    TOP_SINCOS, /* r[d] = sin(r[a]), r[b] = cos(r[a]): one sincos call */
    TOP_CALL,   /* r[d] = fns[b].eval(data, c, r[a]) (b, c are no registers) */
    /* superinstructions (tape_compile fuses a MUL or ADD whose result has
       one use into its user; the same roundings in the same order) */
    TOP_MULADD, /* r[d] = r[a] * r[b] + r[c] */
    TOP_MULMUL, /* r[d] = r[a] * r[b] * r[c] */
    TOP_ADDADD  /* r[d] = r[a] + r[b] + r[c] */
} tape_op;

/* 20 bytes. Packing the operation into the destination's word (16 bytes)
 * or into a byte array beside (17) saved 3-4 bytes an instruction (60-80
 * bytes a loop of a chain, under 2 % of its memory) but cost one or two
 * instructions a dispatch (the four-bar +56 per step, docs/performance.md):
 * not kept. */
typedef struct tape_ins {
    int op;             /* tape_op (TOP_DROPPED: removed while fusing) */
    int d, a, b, c;     /* c: the third operand of a superinstruction */
} tape_ins;

enum { TOP_DROPPED = 15 };

enum { TAPE_MAX_PHASES = 4 };

typedef struct tape {
    double *reg0;       /* compiling only: [nreg] the constants' register image; then
                           NULL, the constants kept as the list below */
    int nreg;
    int nconst;         /* registers holding a nonzero constant (the others start 0) */
    int *const_reg;     /* [nconst] their registers */
    double *const_val;  /* [nconst] their values */
    tape_ins *ins;      /* [nins] instructions, grouped by phase */
    int nins;
    int phase_start[TAPE_MAX_PHASES + 1]; /* phase k: phase_start[k] .. phase_start[k+1]-1 */
    int phase_split[TAPE_MAX_PHASES];     /* phase k's instructions before this one depend
                                             only on the invariant variables (tape_hoist) */
    int nphases;
    int *var_reg;       /* [nvars] register of each variable (-1: not used) */
    int nvars;
    int *node_reg;      /* [nnodes] register of a DAG node, -1 when not compiled (or,
                           after tape_fuse, computed inside a superinstruction) */
    size_t nnodes;
    expr_fn *fns;       /* [nfns] a copy of the context's functions (TOP_CALL) */
    int nfns;
} tape;

/* Compile phases of roots: roots[k][0..nroots[k]-1] for k < nphases. Nodes
 * computed in an earlier phase are not recomputed later. */
int tape_compile(tape *t, expr_ctx *c, int nvars, int nphases, const ex *const *roots,
                 const int *nroots);
void tape_free(tape *t);
/* Move the instructions of a phase that depend only on constants and the
 * variables with invariant[var] != 0 to its start, so that they can be run
 * once while the other variables change (tape_run_invariant). */
void tape_hoist(tape *t, int phase, const unsigned char *invariant);
/* Superinstructions: an ADD or MUL whose result has one use, by an ADD or
 * MUL of the same phase and the same part (hoisted or not), is computed
 * there: (x * y) + z, (x * y) * z, (x + y) + z, the same two roundings in
 * the same order (addition and multiplication commute exactly), so no value
 * changes; one dispatch fewer. The roots (the registers the caller reads)
 * are kept. The registers are then renumbered densely (those of the fused
 * results are gone), in the same order: register files made before are
 * stale (make them after). Call after tape_hoist; 0, or -1
 * when out of memory (the tape is then unchanged and still correct). */
int tape_fuse(tape *t, const ex *const *roots, const int *nroots);
/* Run the instructions of one phase; or only its invariant part, or only
 * the rest (valid while the invariant variables have not changed). */
void tape_run(const tape *t, double *reg, int phase);
void tape_run_invariant(const tape *t, double *reg, int phase);
void tape_run_variant(const tape *t, double *reg, int phase);
/* A register file for this tape (zeros and the constants; free() it), or NULL. */
double *tape_registers_new(const tape *t);
static inline double tape_value(const tape *t, const double *reg, ex e)
{
    return reg[t->node_reg[e]];
}
static inline void tape_set_var(const tape *t, double *reg, int var, double v)
{
    if (t->var_reg[var] >= 0)
        reg[t->var_reg[var]] = v;
}

#endif
