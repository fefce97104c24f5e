/* src/qparse.h: the one parser of quantity expressions (docs/format.md,
 * "Values and units"), its grammar and its dimensional analysis, shared by
 * three backends that build different things from it:
 *   units.c             a number now (quantity_eval), with d/d(seed) beside it;
 *   drivers.c           a law of time t (a small LAW_* tree, parts without t folded);
 *   load_state_loads.c  a register program of the motion (NAME.MEMBER, t, more functions).
 *
 * Grammar:
 *   expr  := term  (('+' | '-') term)*
 *   term  := unary (('*' | '/') unary)*
 *   unary := ('-' | '+') unary | power              (so -r^2 is -(r^2))
 *   power := atom ('^' ['-'] integer)?
 *   atom  := number [unit] | NAME.MEMBER | func '(' expr [',' expr] ')'
 *          | name | '(' expr ')'
 * The core reads the text, keeps the dimension and the "bare" flag of every
 * value (a number without unit: a pure number under * and /, the other
 * operand's default unit under + and -), reports errors at their byte
 * offset, and asks the backend (qparse_ops) for the values: a constant, a
 * negation, a sum, a product or quotient, an integer power, a scaling (a bare
 * value adopting a unit), a function, and the names it knows. The backend
 * keeps its own payload in qv (v and dv for numbers, h for a node or a
 * register). Every hook is called in the order the text is read, so the
 * backends build what they built as separate parsers, operation for
 * operation. */
#ifndef MECH_QPARSE_H
#define MECH_QPARSE_H

#include <ctype.h>
#include <stddef.h>
#include <string.h>

#include "internal.h"

#define QPARSE_PI 3.14159265358979323846

typedef struct qv {
    double v;   /* the value (numbers), or the folded constant part */
    double dv;  /* units.c: d v / d seed */
    int h;      /* drivers.c: tree node (-1: a number); load_state_loads.c: register */
    dim d;
    int bare;   /* a number without unit whose quantity is not known yet */
} qv;

typedef struct qparse qparse;

typedef struct qparse_ops {
    /* a constant v (dv: its derivative); the core sets d and bare */
    qv (*constant)(qparse *p, double v, double dv);
    /* The unit after the number at u (u starts a word): 1 with *scale, *d,
     * *end; 0: no unit, the number is bare (the word is read next); -1: failed. */
    int (*unit)(qparse *p, const char *u, double *scale, dim *d, const char **end);
    /* A word that the backend knows before pi and the parameters (the time
     * t): 1 and *out, or 0. NULL: none. */
    int (*word)(qparse *p, const char *at, size_t n, qv *out);
    /* NAME.MEMBER (no space around the dot); NULL: no dotted names. */
    qv (*dotted)(qparse *p, const char *at, size_t n, const char *mem, size_t mlen);
    /* called before the arguments of a function are read; NULL: nothing */
    void (*call_start)(qparse *p, const char *name, size_t n);
    /* the function name(a) or name(a, b) (two), the ')' read; at: the name */
    qv (*call)(qparse *p, const char *name, size_t n, const char *at, qv a, qv b, int two);
    qv (*neg)(qparse *p, qv a);
    /* a bare value taking the unit k times the SI unit (+, -, the result) */
    qv (*scale)(qparse *p, qv a, double k);
    /* a + b or a - b (op), units already unified; the core keeps a's d and bare */
    qv (*add)(qparse *p, qv a, qv b, char op, const char *at);
    /* a * b or a / b (op); the core sets d and bare after */
    qv (*mul)(qparse *p, qv a, qv b, char op, const char *at);
    /* a ^ e; the core sets d and bare after */
    qv (*powi)(qparse *p, qv a, int e, const char *at);
    /* the end of the message "unknown name 'x'..." */
    const char *unknown_name;
    /* "unit 'mm' without a number" for a unit name alone */
    int unit_alone;
    /* an exponent of 100 or more is an error (else the digits stop there) */
    int strict_exponent;
    /* dimensions with powers beyond +-99 are errors (else they wrap) */
    int checked_dims;
    /* what the text is, in "unexpected 'x' after the value" */
    const char *after;
} qparse_ops;

struct qparse {
    const char *start, *s;
    const expr_env *env;   /* parameters, default units */
    const qparse_ops *ops;
    void *ctx;             /* the backend's */
    char *err;
    size_t errsize;
    size_t err_pos;
    int failed;
    int depth;
};

void qparse_init(qparse *p, const char *text, const expr_env *env, const qparse_ops *ops,
                 void *ctx, char *err, size_t errsize);
/* expr then the end of the text ("unexpected 'x' after the ..."); check p->failed */
qv qparse_run(qparse *p);
void qparse_fail(qparse *p, const char *at, const char *fmt, ...) MECH_PRINTF(3, 4);

/* Under + and - (and two-argument functions): a bare operand takes the
 * other's unit; else equal dimensions, or "cannot WHAT A and B". 0, or -1
 * when it failed. */
int qparse_unify(qparse *p, qv *a, qv *b, const char *at, const char *what);
/* the default scale (SI per bare unit) of dimension d */
double qparse_default_scale(const qparse *p, dim d);
/* "a length (m)", "a pure number", "a quantity in kg*m" */
void qparse_describe(dim d, char *buf, size_t size);
/* sqrt(a) at `at`: its dimension *half; -1 (reported) when a power of a's
 * is odd or, if value_known, a.v < 0 */
int qparse_sqrt_dim(qparse *p, qv a, const char *at, int value_known, dim *half);

/* the length of the word (letter or _, then letters, digits, _) at s, 0 if none */
static inline size_t qparse_ident_len(const char *s)
{
    size_t n = 0;
    if (!(isalpha((unsigned char)s[0]) || s[0] == '_'))
        return 0;
    while (isalnum((unsigned char)s[n]) || s[n] == '_')
        n++;
    return n;
}

/* the n bytes at name are the word fn */
static inline int qparse_is_fn(const char *name, size_t n, const char *fn)
{
    return n == strlen(fn) && memcmp(name, fn, n) == 0;
}

static inline const char *qparse_skip(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    return s;
}

/* Dimensions whose powers beyond +-99 become DIM_BAD, which sticks
 * (units.c: m^257 must not read as m). */
enum { QDIM_MAX = 99, QDIM_BAD = 127 };
dim qdim_add(dim a, dim b, int sign);
dim qdim_scale(dim a, int k);
int qdim_is_bad(dim a);

#endif
