/* src/tape.h: a flat register program compiled from the expression DAG.
 * Every DAG node needed gets one register; constants are loaded once at
 * compile time into the register image, variables are written by the
 * caller, and each instruction computes one node from registers.
 *
 * The program is immutable after compilation (and tape_hoist), so threads
 * share it; each thread runs it on its own register file, a copy of the
 * image made by tape_registers_new. Evaluation allocates nothing. */
#ifndef MECH_TAPE_H
#define MECH_TAPE_H

#include "expr.h"

/* ORDER TOP: tape_run switches on these. */
typedef enum {
    TOP_ADD, /* r[d] = r[a] + r[b] */
    TOP_MUL, /* r[d] = r[a] * r[b] */
    TOP_NEG, /* r[d] = -r[a] */
    TOP_SIN, /* r[d] = sin(r[a]) */
    TOP_COS, /* r[d] = cos(r[a]) */
    TOP_SINCOS, /* r[d] = sin(r[a]), r[b] = cos(r[a]): one sincos call */
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
