/* src/expr.h: the symbolic expression DAG (hash-consed, simplifying on
 * construction), its derivatives, direct evaluation and printing. */
#ifndef MECH_EXPR_H
#define MECH_EXPR_H

#include <stddef.h>
#include <stdio.h>

/* ORDER OP: expr_eval, expr_diff, expr_print and tape.c switch on these. */
typedef enum {
    EX_CONST, /* value */
    EX_VAR,   /* variable number `var` (see expr_ctx.nvars) */
    EX_ADD,   /* a + b */
    EX_MUL,   /* a * b */
    EX_NEG,   /* -a */
    EX_SIN,   /* sin(a) */
    EX_COS    /* cos(a) */
} expr_op;

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
} expr_ctx;

int expr_init(expr_ctx *c);
void expr_free(expr_ctx *c);

ex expr_const(expr_ctx *c, double v);
ex expr_var(expr_ctx *c, int var);
ex expr_add(expr_ctx *c, ex a, ex b);
ex expr_sub(expr_ctx *c, ex a, ex b);
ex expr_mul(expr_ctx *c, ex a, ex b);
ex expr_neg(expr_ctx *c, ex a);
ex expr_sin(expr_ctx *c, ex a);
ex expr_cos(expr_ctx *c, ex a);

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

#endif
