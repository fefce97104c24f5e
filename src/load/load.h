/* src/load/load.h: from YAML to mech_model: the tree, quantities and units, parameters as
 * expressions, laws of time, loads that depend on the motion, the model's lookups and release. The
 * stage's one header: what its modules share with each other and with the later stages
 * (docs/architecture.md, "Stages"). */
#ifndef MECH_LOAD_STAGE_H
#define MECH_LOAD_STAGE_H

#include <ctype.h>
#include <stddef.h>
#include <string.h>

#include "base.h"
#include "symbolic.h"
#include "rt_forces.h"
#include "rt_law.h"

/* ==== qparse ==== */
/* qparse.c: the one parser of quantity expressions (docs/format.md,
 * "Values and units"), its grammar and its dimensional analysis, shared by
 * three backends that build different things from it:
 *   units.c             a number now (quantity_eval), recorded over the parameters when
 *                       the loader asks (param_expr.h);
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
 * keeps its own payload in qv (v for numbers, h for a node or a register).
 * Every hook is called in the order the text is read, so the backends
 * build what they built as separate parsers, operation for operation. */
#define QPARSE_PI 3.14159265358979323846

typedef struct qv {
    double v;   /* the value (numbers), or the folded constant part */
    int h;      /* units.c: the value's handle in the parameter expressions (param_expr.h);
                   drivers.c: tree node (-1: a number); load_state_loads.c: register */
    dim d;
    int bare;   /* a number without unit whose quantity is not known yet */
} qv;

typedef struct qparse qparse;

typedef struct qparse_ops {
    /* a constant v; the core sets d and bare */
    qv (*constant)(qparse *p, double v);
    /* a use of the environment's parameter k; the core sets d and bare. NULL:
     * the parameter's value as a constant */
    qv (*param)(qparse *p, int k);
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

/* ==== param_expr ==== */
/* param_expr.c: the model's parameter expressions (param_expr.c).
 *
 * Beside every number the loader computes from a text that names a
 * parameter (a point's coordinates, a slider's angle, a gear pair's radii
 * and phase), the model keeps the expression it was computed by: a small
 * tree over parameter leaves, recorded operation for operation as the
 * quantity parser evaluated it (units.c) and as the loader combined the
 * results (a polar point's x0 + r cos(a), a gear's module times its teeth).
 * So the model knows, without reading its file again, what depends on which
 * parameter, and d(number)/d(parameter) is the tree's forward derivative,
 * taken with the same floating-point operations in the same order as the
 * numbers themselves. Numbers no parameter moves keep no tree (a handle
 * PX_FIXED or PX_FIXED_NEG: their derivative is +0 or -0, as the forward
 * rules give it). */
/* ORDER PX: px_deriv and pexpr_eval switch on these. */
typedef enum {
    PX_CONST,    /* k; its derivative is -0 when a (the sign) is 1, else +0 */
    PX_PARAM,    /* parameter a (index); d/dp: 1 for p itself, else its definition's */
    PX_NEG,      /* -a */
    PX_SCALE,    /* a * k: a bare value taking a unit, or a number times a count */
    PX_ADD,      /* a + b */
    PX_SUB,      /* a - b */
    PX_MUL,      /* a * b */
    PX_DIV,      /* a / b */
    PX_POWI,     /* a ^ k, k an integer */
    PX_SQRT,     /* sqrt(a) */
    PX_SIN,      /* sin(a) */
    PX_COS,      /* cos(a) */
    PX_TAN,      /* tan(a) */
    PX_ATAN2,    /* atan2(a, b) */
    PX_HYPOT,    /* hypot(a, b) */
    PX_POLAR_X,  /* a + b cos(c): the x of a polar point, a its `from` point's (0: none) */
    PX_POLAR_Y   /* a + b sin(c) */
} px_op;

/* Handles of numbers with no tree (no parameter moves them). */
enum { PX_FIXED = -1, PX_FIXED_NEG = -2 };

/* The numbers beside the points' that the loader keeps expressions of. */
typedef enum {
    PXN_SLIDER_ANGLE,  /* index j: joint j's angle (a slider's line) */
    PXN_GEAR,          /* index 4 g + k: gear g's radius[0], radius[1], offset[0], offset[1] */
    PXN_MASS,          /* index 4 l + k: link l's mass, inertia, center[0], center[1] */
    PXN_KINDS
} pxn_kind;

typedef struct px_node {
    px_op op;
    int a, b, c;    /* operands (node indices, smaller than the node's), -1 when unused;
                       PX_PARAM: a is the parameter; PX_CONST: a is the sign of its
                       derivative */
    double k;       /* PX_CONST: the value; PX_SCALE: the factor; PX_POWI: the exponent */
    double value;   /* the node's value as the loader computed it */
} px_node;

typedef struct param_exprs {
    px_node *node;      /* [n] operands before the nodes that use them */
    int n, cap;
    int nparams;
    int *def;           /* [nparams] handle of each parameter's definition */
    int **point;        /* [npoint_links] -> [2 * points] handles of x and y */
    int *npoint;        /* [npoint_links] entries of point[l] */
    int npoint_links;
    int *table[PXN_KINDS]; /* [ntable[kind]] handles of the other numbers (PX_FIXED beyond) */
    int ntable[PXN_KINDS];
    int failed;         /* out of memory while recording: the model is not loaded */
} param_exprs;

/* A number and its handle (a node index, PX_FIXED or PX_FIXED_NEG). */
typedef struct pxq {
    double v;
    int h;
} pxq;

static inline pxq pxq_fixed(double v) { return (pxq){v, PX_FIXED}; }

param_exprs *pexpr_new(void);
void pexpr_free(param_exprs *pe);

/* ---- recording (the loader, units.c) ---------------------------------- */

/* The number `value` computed as op(a, b, c) with k (unused operands:
 * pxq_fixed(0)). A node when some operand depends on a parameter, else a
 * fixed handle with the sign of the forward derivative. */
pxq pexpr_make(param_exprs *pe, px_op op, double k, pxq a, pxq b, pxq c, double value);
/* A use of parameter k, whose value is `value`. */
pxq pexpr_param(param_exprs *pe, int k, double value);
/* Where the loader keeps the handles of its numbers (the table grows). */
void pexpr_set_param(param_exprs *pe, int k, int h);
void pexpr_set_point(param_exprs *pe, int link, int index, int h_x, int h_y);
void pexpr_set(param_exprs *pe, pxn_kind kind, int index, int h);

/* ---- reading ---------------------------------------------------------- */

/* The handle of a number (PX_FIXED when none was kept); pe may be NULL (a
 * model without parameters). */
int pexpr_point(const param_exprs *pe, int link, int index, int comp);
int pexpr_get(const param_exprs *pe, pxn_kind kind, int index);

/* d(node)/d(parameter p) of every node into d[pe->n] (forward mode: the
 * derivative rules of px_deriv, node after node). */
void pexpr_derivatives(const param_exprs *pe, int p, double *d);
/* The derivative of handle h from pexpr_derivatives' d. */
static inline double pexpr_deriv_of(const double *d, int h)
{
    return h >= 0 ? d[h] : h == PX_FIXED_NEG ? -0.0 : 0.0;
}
/* Every node's value again, from the parameters' values pv[nparams] (the
 * model's, or others): the tree evaluated as the loader evaluated it. */
void pexpr_eval(const param_exprs *pe, const double *pv, double *out);

/* d(x, y)/d(parameter p) of every point of m, link by link (out[2 g] and
 * out[2 g + 1] for the g-th point counting from the ground's first); -1
 * when out of memory. */
int pexpr_point_gradient(const mech_model *m, int p, double *out);

/* ==== drivers ==== */
/* drivers.c: the drivers, each a law of the sweep variable
 * (docs/format.md section 7.3, docs/solver.md section 8).
 *
 * A law of time is a unit-checked expression of the sweep variable t, such
 * as "30 deg + 20 deg * sin(6.2832 * t / 1 s)", parsed at load time into a
 * small tree (mech_law) with every part that does not depend on t folded
 * to a number; `driver:` is the law q of its own value. The system
 * (system.c) turns each law into the expression DAG with q as the variable
 * and adds one row per driver that is not the sweep itself,
 *     g_i = coordinate_i - p_i(q) = 0,
 * after the loop and gear rows; the driven coordinates are ordinary
 * unknowns. */
enum { LAW_MAX_NODES = 2048 };  /* operations in one law (law_eval's buffer) */

/* ORDER LAW: law_eval (law_eval.c), law_expr and law_why switch on these.
 * The operations up to LAW_COS are the DAG's (expr.c): a law made of them
 * only enters the system as its expression, as the generated code does.
 * A law with any later one (docs/motion-programs.md) enters as one opaque
 * function of q (EX_CALL) whose value and derivatives law_eval gives. */
typedef enum {
    LAW_CONST, LAW_T, LAW_ADD, LAW_MUL, LAW_NEG, LAW_SIN, LAW_COS,
    LAW_DIV, LAW_EXP, LAW_LOG, LAW_SQRT, LAW_TAN, LAW_TANH, LAW_ATAN2, LAW_ABS, LAW_MIN,
    LAW_MAX, LAW_STEP, LAW_SIGN,
    LAW_PROGRAM  /* progs[b] of the variable a (a motion program, programs.c) */
} law_op;
_Static_assert((int)LAW_PROGRAM == (int)RT_LAW_PROGRAM && (int)LAW_DIV == (int)RT_LAW_DIV,
               "law_op and rt_law.h's RT_LAW_ in the same order");

/* a node: op (law_op), operands a, b (-1 when unused; LAW_PROGRAM: b is the
 * program), k (LAW_CONST: the value, SI); rt_law.h's, which evaluates it */
typedef rt_law_node law_node;

struct mech_program;

struct mech_law {
    law_node *nodes;  /* [n] operands come before the node that uses them */
    int n, cap;
    int root;
    int nomem;        /* parsing ran out of memory */
    char var;         /* the variable's name: 't' (a time), or 'u' (a program segment's
                         normalised variable, a pure number) */
    char name[72];    /* "p_crank": the law in printed equations and messages */
    struct mech_program **progs;  /* [nprogs] owned */
    const rt_program **rtprogs;   /* [nprogs] owned array: each program's rt view */
    int nprogs;
};

/* Parse the law `text`, a quantity `want` (Q_ANGLE or Q_LENGTH) of the
 * time t; names are the file's parameters (env), `t`, `pi`. 0 and *out on
 * success; -1 with a message in err and its byte offset in *err_pos
 * (MECH_ENOMEM when out of memory). */
int law_parse(const char *text, quantity want, const expr_env *env, struct mech_law **out,
              char *err, size_t errsize, size_t *err_pos);
void law_free(struct mech_law *l);
/* The law's value at time t (SI), and its first and second time derivatives
 * (by forward differentiation of the tree, independent of expr.c). */
double law_eval(const struct mech_law *l, double t, double *dt, double *dtt);
/* law_eval.c: the same, with the third derivative (NULL: not wanted), into
 * a caller's buffer buf[4 * l->n] (no allocation); NaN where the law or a
 * derivative is not defined. */
double law_eval3(const struct mech_law *l, double t, double *buf, double d[3]);
/* Is the law (and its first two derivatives) defined at t? 1; else 0 with
 * why it is not ("log of a negative number (-0.5)") in why. */
int law_defined(const struct mech_law *l, double t, char *why, size_t size);
/* Does the law use an operation the DAG does not have (LAW_DIV ...)? */
int law_is_opaque(const struct mech_law *l);
/* expr_fn's eval for an opaque law (data: the law): order 0, 1, 2, 3. */
double law_fn_eval(const void *data, int order, double t);
/* The law as an expression of the variable t in c. */
ex law_expr(const struct mech_law *l, expr_ctx *c, ex t);
/* Parse `text` as a law of the variable l->var into l (a new tree or one
 * under way), one of the quantities wants[0..nwants-1]; *got: which.
 * As law_parse otherwise. */
int law_parse_into(const char *text, const quantity *wants, int nwants, const expr_env *env,
                   struct mech_law *l, quantity *got, char *err, size_t errsize,
                   size_t *err_pos);
/* A new empty law of the variable var ('t' or 'u'), or NULL. */
struct mech_law *law_new(char var);
/* Append a node to l; its index, or -1 when out of memory or too long. */
int law_add_node(struct mech_law *l, law_op op, int a, int b, double k);

/* ---- programs.c: motion programs (docs/motion-programs.md) -------------
 * A displacement program over one period of its variable x (a law of t):
 * segments (dwell, rise, return) each over a span of x, with a standard
 * law or a user's f(u), u in [0, 1]. Repeats: s(x + P) = s(x) + net. */
typedef enum { PROG_DWELL, PROG_RISE, PROG_RETURN } prog_kind;
typedef enum {
    SHAPE_NONE = RT_SHAPE_NONE, SHAPE_CYCLOIDAL = RT_SHAPE_CYCLOIDAL,
    SHAPE_HARMONIC = RT_SHAPE_HARMONIC, SHAPE_345 = RT_SHAPE_345, SHAPE_4567 = RT_SHAPE_4567,
    SHAPE_MODTRAP = RT_SHAPE_MODTRAP, SHAPE_MODSINE = RT_SHAPE_MODSINE,
    SHAPE_USER = RT_SHAPE_USER, SHAPE_CUBIC = RT_SHAPE_CUBIC
} prog_shape;
enum { PROG_USER_MAX_NODES = RT_LAW_USER_MAX };  /* operations in a segment's f(u) */
/* a segment (rt_law.h): kind, shape, x0, span (SI of x), s0 (s at its
 * start), lift (signed), its pieces, its own law f(u) (user: the rt view;
 * user_law: the struct mech_law, owned), line and col in the file */
typedef rt_segment prog_segment;
typedef struct mech_program {
    prog_segment *seg;  /* [n] */
    int n;
    double start, period, net;  /* s at x = 0; the period; s(P) - s(0) */
    int continuity;     /* checked at load: 0 displacement, 1 + velocity, 2 + acceleration */
    double speed;       /* `speed:` dx/dt (x = speed * of), SI; 0 when not given */
    rt_program rt;      /* the view rt_law.h evaluates (set when loaded) */
} mech_program;
/* The normalised law of segment kind `shape`: f, f', f'', f''' at u. */
void prog_shape_eval(const prog_segment *sg, double u, double f[4]);
/* Fill a segment's pieces (modified trapezoid and sine). */
void prog_shape_init(prog_segment *sg);
/* s(x) and its derivatives d[0..3] in x. */
void program_eval(const mech_program *p, double x, double d[4]);
void program_free(struct mech_program *p);
/* A shape by its name in the file ("cycloidal", "3-4-5", ...), or SHAPE_NONE. */
prog_shape prog_shape_by_name(const char *name);
const char *prog_shape_name(prog_shape s);

/* ---- the one model of drivers ------------------------------------------
 * Driver k holds its coordinate x_k (a link angle or a slider
 * displacement, m->drivers[k]) to its law p_k(q) of the sweep variable q.
 * A driver whose law is q itself (`driver:`: the sweep variable is the
 * driver's own value) is the sweep: the system writes its coordinate as q,
 * with no unknown and no row, so it costs nothing over a fixed input.
 * Every other driver's coordinate is an unknown, and the driver adds one
 * row x_k - p_k(q) after the loop and gear rows (rows.h). */

/* Add the driver of `driver:`: the law q for the link or slider of
 * m->driver. 0, or -1 when out of memory. */
int drivers_add_sweep(mech_model *m);
/* Is driver k the one of `driver:`, whose law is the sweep variable itself? */
int drivers_is_sweep(const mech_model *m, int k);
/* The driver that is the sweep, or -1 (q is the time). */
int drivers_sweep(const mech_model *m);
/* The link whose angle, or the slider whose displacement, is the sweep
 * variable; -1 when none is. */
int drivers_sweep_link(const mech_model *m);
int drivers_sweep_slider(const mech_model *m);
/* The drivers that add a row: those that are not the sweep. */
int drivers_rows(const mech_model *m);
/* system.c: driver k's row x_k - p_k(q), from the link angle and slider
 * expressions of the system. */
ex drivers_row(const mech_model *m, int k, expr_ctx *c, const ex *link_angle, const ex *slide,
               ex q);
/* continuation.c: the guesses of the driven unknowns at q (link_var,
 * joint_var: the system's). */
void drivers_guess(const mech_model *m, const int *link_var, const int *joint_var, double q,
                   double *guess);
/* The first driver whose law (or its rate, or its second derivative) is
 * not defined at q, why in why; -1 when all are (sweep.c, at every row). */
int drivers_undefined(const mech_model *m, double q, char *why, size_t size);
/* The name of driver k ("crank" or the slider's name). */
const char *drivers_name(const mech_model *m, int k);
/* The driver of link l's angle or of slider joint j, or -1. */
int drivers_of_link(const mech_model *m, int l);
int drivers_of_slider(const mech_model *m, int j);
/* Does a driver move link l (its angle, or its slide along a guide)? */
int drivers_move_link(const mech_model *m, int l);
/* Do a and b (two loads of one file) have the same drivers with the same
 * laws, every number bit for bit? (The system folds the laws' numbers.) */
int drivers_same(const mech_model *a, const mech_model *b);

/* ---- free coordinates (docs/dynamics.md, docs/format.md 7.4) -----------
 * A driver of `drivers:` with `free: true` has no law of its own: its
 * coordinate moves as the loads make it move (mech simulate). For every
 * other command its law is value + speed (t - t0), t0 the sweep's first
 * time: it turns on at its initial speed. Its `load:` (a torque on the
 * driven link) is one more load of m->state_loads. */
typedef struct free_driver {
    int driver;        /* index in m->drivers */
    double value;      /* initial coordinate, rad or m */
    double speed;      /* initial rate, rad/s or m/s */
    int load;          /* index of its load in m->state_loads->loads, -1 when none */
    mech_mark mark;
} free_driver;

struct free_drivers {
    free_driver *d;    /* [n] */
    int n;
};

/* The law a + b t (a free driver's for the commands other than simulate). */
struct mech_law *law_linear(double a, double b);
/* Driver k of m is free: its entry in m->free_drivers, or NULL. */
const free_driver *drivers_free_of(const mech_model *m, int k);

/* model.c: free the model's drivers. */
void drivers_free(mech_model *m);

/* ==== state_loads ==== */
/* state_loads.c: loads that depend on the motion (docs/format.md
 * section 10.2, docs/forces.md section 7a). A load component written as an
 * expression of the state (B.vx, crank.angle, x_B.s, ...) is compiled at
 * load time (load_state_loads.c) into a flat register program: inputs read
 * from the solved motion, then one instruction per operation. Per step the
 * program runs once after the kinematics and before the force solve, on a
 * register file of the thread's own (forces.sl_reg): no allocation.
 *
 * Constant loads never come here: a component that reads as a constant
 * quantity stays a plain mech_load (today's code path, same numbers). */
/* The operations: rt_forces.h's (rt_sl_apply, which the generated code
 * calls too). */
typedef enum {
    SLOP_ADD = RT_SL_ADD, SLOP_SUB = RT_SL_SUB, SLOP_MUL = RT_SL_MUL, SLOP_DIV = RT_SL_DIV,
    SLOP_NEG = RT_SL_NEG, SLOP_POWI = RT_SL_POWI, SLOP_SIN = RT_SL_SIN, SLOP_COS = RT_SL_COS,
    SLOP_TAN = RT_SL_TAN, SLOP_ATAN2 = RT_SL_ATAN2, SLOP_SQRT = RT_SL_SQRT, SLOP_ABS = RT_SL_ABS,
    SLOP_MIN = RT_SL_MIN, SLOP_MAX = RT_SL_MAX, SLOP_EXP = RT_SL_EXP, SLOP_LOG = RT_SL_LOG,
    SLOP_TANH = RT_SL_TANH, SLOP_STEP = RT_SL_STEP, SLOP_SIGN = RT_SL_SIGN,
    SLOP_SMOOTHSIGN = RT_SL_SMOOTHSIGN
} sl_op;

/* What an input register reads from the solved motion. */
typedef enum {
    SLIN_PX, SLIN_PY, SLIN_PVX, SLIN_PVY, SLIN_PAX, SLIN_PAY,  /* point name id */
    SLIN_ANGLE, SLIN_OMEGA, SLIN_ALPHA,                          /* link index */
    SLIN_S, SLIN_SV, SLIN_SA,                                    /* slider joint index */
    SLIN_DRIVER, SLIN_DRIVER_SPEED, SLIN_DRIVER_ACCEL            /* the driver */
} sl_input_kind;

typedef struct sl_ins {
    int op;          /* sl_op */
    int d, a, b;     /* registers: d = op(a, b) (b unused: -1) */
    int k;           /* SLOP_POWI: the integer exponent */
} sl_ins;

typedef struct sl_input {
    int kind;        /* sl_input_kind */
    int index;       /* point name id, link or joint */
    int reg;
} sl_input;

typedef struct sl_load {
    int torque;      /* 0: force [fx, fy] at point `point` of `link`; 1: torque on `link`;
                        2: a force along the line from point of link to point2 of link2,
                        tension positive (pulls the two ends together) */
    int link;
    int point;       /* index of the point in the link (force, line) */
    int reg[2];      /* registers of fx, fy (force), of the torque or the tension ([0]) */
    mech_mark mark;
    int link2, point2; /* line: the other end */
} sl_load;

/* The compiled program of every motion-dependent load of a model (owned by
 * mech_model.state_loads; read only after loading: threads share it). */
typedef struct state_loads {
    double *reg0;    /* [nreg] register image: constants, zero elsewhere */
    unsigned char *fixed; /* [nreg] 1: a constant register */
    int nreg, capreg;
    sl_ins *ins;
    int nins, capins;
    sl_input *in;
    int nin, capin;
    sl_load *loads;
    int nloads, caploads;
} state_loads;

/* ---- building (load time) */
state_loads *state_loads_new(void);
void state_loads_free(state_loads *s);
int sl_const(state_loads *s, double v);              /* a register holding v, or -1 */
int sl_input_reg(state_loads *s, int kind, int index); /* one register per input, or -1 */
/* d = op(a, b): folded into a constant when a and b are constants. -1: no memory. */
int sl_emit(state_loads *s, int op, int a, int b, int k);
int sl_is_const(const state_loads *s, int reg);      /* register holds a fixed value */
int sl_add_load(state_loads *s, const sl_load *l);   /* 0, or -1 out of memory */
/* One operation on values (the evaluator's, used for folding too). */
double sl_apply(int op, double a, double b, int k);

/* ---- per step (state_loads_eval, forces.h) */
double *state_loads_registers(const state_loads *s);   /* a register file (free()), or NULL */
/* Load i in words, as mech check shows it: "force at T on link 'ram'". */
void state_loads_describe(const mech_model *m, int i, char *buf, size_t size);

/* ==== load ==== */
/* load.c: private to the loader (load.c, load_tree.c, load_links.c,
 * load_joints.c, load_motion.c, load_outputs.c): the loader's state and the
 * stages and helpers they share. Not for the other modules. */
enum {
    MAX_NAME = 64,            /* bytes in a name */
    MAX_LINKS = 1000000,      /* links with the ground: 999 999 moving */
    MAX_POINTS_PER_LINK = 10000,
    MAX_GROUND_POINTS = 1000000, /* the ground holds every fixed pivot: a chain of
                                    100 000 four-bars has 100 001 */
    MAX_STEPS = 1000000,      /* driver intervals in one sweep (docs/limits.md) */
    MAX_PARAMS = 100000,
    MAX_LOADS = 1000000,
    MAX_LOOPS = 1000,         /* listed loops: for the papers' mechanisms; larger ones */
    MAX_LOOP_POINTS = 1000,   /* leave 'loops' out (found automatically, linear time) */
    MAX_LIST = 4000000,       /* items in any other list */
    MAX_SUGGEST = 1000        /* names searched for a "did you mean" */
};

enum { LINK_FAILED = 1, LINK_UNPLACED = 2 };  /* bits of loader.link_failed */

/* A point of `drawing:` (load_drawn.c): its global position at the drawing. */
typedef struct drawn_point {
    const char *name;     /* borrowed from the tree; NULL: an extra (a centre of mass) */
    const ynode *node;    /* its [x, y] */
    mech_mark mark;
    double xy[2];         /* m */
    int on_link;          /* some link or the ground lists it */
} drawn_point;

/* A point guess of `initial:` (load_guess.c). */
typedef struct point_guess {
    int id;               /* point id */
    double xy[2];         /* m */
    mech_mark mark;
} point_guess;

typedef struct loader {
    const char *file;
    mech_diag *d;
    mech_model *m;
    unit_defaults units;
    expr_param *params;   /* [m->nparams] dimensions of the parameters */
    expr_env env;
    name_map point_map;   /* point name -> id */
    name_map link_map;    /* link name -> index */
    name_map joint_map;   /* joint name -> index */
    /* Follow-on errors are not reported: one mistake, one message. */
    unsigned char *link_failed; /* [links allocated] LINK_FAILED: errors were reported about
                                   the link's points or joints: skip checks that would only
                                   echo them; LINK_UNPLACED: some point's coordinates could
                                   not be read (an error elsewhere) and are taken as 0, 0 */
    int links_bad;        /* 'links' missing or unreadable: names of links are not known */
    int points_bad;       /* some link's points unreadable: names of points are not known */
    name_map bad_params;  /* parameters whose definition failed (keys borrowed from the tree) */
    name_map param_map;   /* parameter name -> index into params (keys borrowed) */
    int *carrier_start;   /* [npoint_names + 1] after the links: the links carrying point id */
    int *carrier_link;    /* are carrier_link[carrier_start[id] .. carrier_start[id + 1] - 1], */
    int *carrier_point;   /* ascending, with the point's index in each (carrier_point) */
    int carrier_ids;      /* point ids indexed (0: no index, search the links) */
    name_map next_suffix; /* default joint name -> next suffix to try (keys: joint names) */
    const mech_override *ov; /* [nov] parameter definitions replaced (mech sweep) */
    int nov;
    unsigned char *ov_used;  /* [nov] the file defines it */
    int angle_unit_given; /* 'units:' names the angle unit: bare driver angles are meant */
    int expressions;      /* keep the parameter expressions (mech_model.pexpr) */
    drawn_point *drawn;   /* [ndrawn] the drawn form's points, or NULL */
    int ndrawn;
    name_map drawn_map;   /* drawn point name -> index (keys borrowed from the tree) */
    ynode *drawn_root;    /* owned: the local form the drawn file stands for */
    point_guess *pguess;  /* [npguess] point guesses of `initial:` */
    int npguess;
} loader;

/* Index of a point, link or joint name, or -1. */
static inline int find_point(const loader *ld, const char *name)
{
    return name_map_get(&ld->point_map, name);
}
static inline int find_link(const loader *ld, const char *name)
{
    return name_map_get(&ld->link_map, name);
}
static inline int find_joint(const loader *ld, const char *name)
{
    return name_map_get(&ld->joint_map, name);
}

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

/* ---- load_tree.c: walking the YAML tree. Every reader reports its own
 *      error (file:line:col of the node) and returns 0, -1 or NULL. */
int load_err(loader *ld, const ynode *n, const char *fmt, ...) MECH_PRINTF(3, 4);
int load_nomem(loader *ld, const ynode *n);  /* "out of memory" at n; MECH_ENOMEM */
int load_want_kind(loader *ld, const ynode *n, ynode_kind kind, const char *what);
/* A mapping's keys: scalars, no duplicates, all in `allowed`, or (allowed
 * NULL) names of `noun`s. 1 when the mapping can be read. */
int load_check_map(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                   const char *where, const char *noun);
int load_check_keys(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                    const char *where);
int load_misspelt(const ynode *map, const char *key, const char *const *allowed,
                  size_t nallowed);
const ynode *load_key_of(const ynode *map, const char *key);
int load_uses_bad_param(const loader *ld, const char *text);
int load_valid_name(const char *s);
const char *load_get_name(loader *ld, const ynode *n, const char *what); /* borrowed */
/* caller frees; `lines`: line breaks and tabs allowed */
char *load_get_string(loader *ld, const ynode *n, const char *what, size_t max, int lines);
int load_get_quantity(loader *ld, const ynode *n, quantity q, const char *what, double *out);
/* The same, the value recorded over the parameters (the model's parameter
 * expressions, param_expr.h): *root its handle (PX_FIXED when no
 * parameter moves it, or when the file has no parameters). */
int load_get_quantity_expr(loader *ld, const ynode *n, quantity q, const char *what,
                           double *out, int *root);
int load_get_vec2_expr(loader *ld, const ynode *n, quantity q, const char *what, double out[2],
                       int root[2]);
/* A number computed from recorded ones (a polar point, a gear's radius). */
pxq load_expr(loader *ld, px_op op, double k, pxq a, pxq b, pxq c, double value);
int load_get_count(loader *ld, const ynode *n, const char *what, long lo, long hi, long *out);
/* load_fit.c: the `fit:` section into m->fit (docs/synthesis.md). */
void load_fit(loader *ld, const ynode *map);
int load_get_bool(loader *ld, const ynode *n, const char *what, int *out);
int load_get_vec2(loader *ld, const ynode *n, quantity q, const char *what, double out[2]);
int load_errors_full(const loader *ld);
void load_err_unknown(loader *ld, const ynode *n, const char *kind, const char *kinds,
                      const char *name, const char *const *cands, size_t ncands);
/* Index of the named link, point or slider joint, or -1 (reported). */
int load_find_link_or_report(loader *ld, const ynode *n, const char *what);
int load_find_point_or_report(loader *ld, const ynode *n, const char *what);
int load_slider_by_name(loader *ld, const ynode *n, const char *what);
void load_carriers_of(const loader *ld, int id, int *first, int *end);
int load_point_in_link(const loader *ld, int li, int id);
/* The links that may carry end k (point id, written pnode) of a two-point
 * element (a spring, a load along a line): links[k] when the file gives
 * `links` (it must carry the point; `what` names it in the message), else
 * every carrier of the point, at most max, into cand. Their count, or -1
 * when reported. */
int load_end_candidates(loader *ld, const ynode *links, int k, int id, const ynode *pnode,
                        const char *what, int *cand, int max);

/* ---- load_links.c: units, parameters, ground, links, their points and mass. */
void load_units(loader *ld, const ynode *map);
void load_parameters(loader *ld, const ynode *map);
void load_ground(loader *ld, const ynode *map);  /* map NULL: no 'ground' key */
void load_links(loader *ld, const ynode *map);

/* ---- load_joints.c: explicit revolutes and sliders, the implicit
 *      revolutes of shared point names, the carriers index. */
void load_index_carriers(loader *ld);
void load_joints(loader *ld, const ynode *seq);
void load_add_implicit_revolutes(loader *ld);
void load_check_link_points(loader *ld);
void load_warn_point_typos(loader *ld, const ynode *outputs);

/* ---- load_motion.c: driver, initial guesses, branch conditions, loops. */
void load_driver(loader *ld, const ynode *map);
/* A driver's (or the sweep's) range: a list or {from, to, steps} of q. */
void load_range(loader *ld, const ynode *n, quantity q, mech_driver *dr);
/* load_drivers.c: 'sweep: {time: RANGE}' and 'drivers: [...]' (laws of time) */
void load_sweep_drivers(loader *ld, const ynode *sweep, const ynode *drivers);
/* load_programs.c: `program:` of a driver's law (q: Q_ANGLE or Q_LENGTH),
 * into *out (the law of t, its last node the program). 1, or 0 reported. */
int load_program(loader *ld, const ynode *map, quantity q, const char *driver,
                 struct mech_law **out);
/* Program p as law l's only program (progs[0]; l owns it from then on): 1,
 * or 0 out of memory (p not taken). */
int law_take_program(struct mech_law *l, struct mech_program *p);
/* The same; of_cam: a cam's program (load_cams.c), whose variable is the
 * law's own, the cam angle (no 'of' or 'speed'). */
int load_program_as(loader *ld, const ynode *map, quantity q, const char *who, int of_cam,
                    struct mech_law **out);
void load_initial(loader *ld, const ynode *map);
/* load.c: the whole file at path, at most max bytes, checked before and while
 * reading (NULL with *rc set and the problem recorded in d). */
char *load_read_file(const char *path, size_t max, size_t *len, mech_diag *d, int *rc);
/* load_drawn.c: the tree of the local form a drawn file stands for (owned
 * by ld->drawn_root), NULL when reported; a point's drawn position (1 when
 * drawn). */
const ynode *load_drawn_tree(loader *ld, const ynode *root, const ynode *drawing);
int load_drawn_at(const loader *ld, int id, double xy[2]);
/* load_guess.c: the guesses the point guesses and the drawing give (after
 * the joints, the driver and `initial:`), the drawn driver value (the
 * start of the sweep), and the guesses that cannot act, warned about. */
void load_guesses_from_points(loader *ld);
int *load_locked_sliders(const mech_model *m);  /* [links] joint index or -1; free() it */
void load_branches(loader *ld, const ynode *seq);
void load_loops(loader *ld, const ynode *seq);

/* ---- load_outputs.c: loads and outputs. */
void load_loads(loader *ld, const ynode *seq);
void load_outputs(loader *ld, const ynode *map);
void load_default_outputs(mech_model *m);

/* ---- load_state_loads.c: loads that depend on the motion (docs/format.md 10.2).
 *      wanted: some component of a force [fx, fy] or torque does not read as a
 *      constant quantity; load_state_load compiles them into m->state_loads. */
int load_state_wanted(loader *ld, const ynode *value);
void load_state_load(loader *ld, const ynode *map, const ynode *value, int link, int point);
/* A force of size `value` (a force, constant or of the motion) along the
 * direction dir (rad, ground frame) at point `point` of `link`. */
void load_state_along(loader *ld, const ynode *map, const ynode *value, int link, int point,
                      double dir);
/* {force: TENSION, between: [P, Q], links: [a, b]}: a force along a line. */
void load_state_line(loader *ld, const ynode *map);

/* ---- load_springs.c: springs and dampers. */
void load_springs(loader *ld, const ynode *seq);

/* ---- load_gears.c: gear pairs and racks. */
void load_gears(loader *ld, const ynode *seq);
/* The pin where link g turns on link c (a revolute joint joining them, or a
 * point they share where g has one): the point indices in g and c; 0 when
 * there is none. */
int load_find_pivot(const loader *ld, int g, int c, int *pg, int *pc);

/* ---- load_cams.c: cam-follower pairs (docs/cams.md) ----------------------
 * A disc cam on link `cam`, turning on the `arm` (a revolute joint), and a
 * follower that the arm guides: translating (a locked slider of the
 * follower on the arm) or oscillating (a revolute joint of the follower on
 * the arm). The follower's coordinate (the slider's displacement, or the
 * follower's angle relative to the arm) is the program's lift at the cam's
 * angle: one row, coordinate - c0 - rise (s(x)) = 0, x = sense (th_cam -
 * th_arm - start) (src/equations/cams.c). */
typedef enum { CAM_TRANSLATING, CAM_OSCILLATING } cam_motion;
typedef enum { CAM_ROLLER, CAM_KNIFE_EDGE, CAM_FLAT_FACED } cam_contact;
typedef struct mech_cam {
    char *name;          /* owned */
    int cam, arm, follower;  /* links */
    int slider;          /* translating: the follower's slider joint; else -1 */
    int cam_pivot[2];    /* the cam's pivot: its point in the cam, in the arm */
    int follower_pivot[2]; /* oscillating: the follower's pivot in it and in the arm */
    int at;              /* oscillating roller or knife-edge: the follower's point at the
                            roller's centre or the knife's tip; else -1 */
    int face[2];         /* oscillating flat-faced: two points of the follower on its face */
    cam_motion motion;
    cam_contact contact;
    int sense;           /* +1: x grows as the cam turns counterclockwise on the arm */
    double start;        /* the cam's angle on the arm where x = 0, rad */
    double base, roller; /* the base circle's radius, the roller's (0: none), m */
    double friction;     /* the Coulomb coefficient at the contact (0: none) */
    double offset;       /* translating: the signed distance of the follower's line from
                            the cam's centre (+: the line passes to the centre's left,
                            looking along the line's direction), m */
    double c0;           /* the follower's coordinate at zero lift (m or rad) */
    int rise;            /* +1 or -1: the coordinate's change as the lift grows */
    struct mech_law *program; /* the lift s(x), a law of x: owned */
    double *points;      /* a cam given by its profile: [2 * npoints] the points in the
                            cam's frame, m (owned; cam_points.c), and the program is
                            the lift they give; NULL when the file gives the program */
    int npoints;
    mech_mark mark;
    /* the design quantities over the period (load_cams_place; docs/cams.md 3),
       each with its x where it is worst */
    double pressure_max, pressure_at;   /* the largest |pressure angle| */
    double rho_pitch_min, rho_pitch_at; /* the least radius of the pitch curve where
                                           convex (INFINITY: nowhere) */
    double rho_profile_min, rho_profile_at; /* the profile's least (signed) */
    double face_lo, face_hi;            /* flat-faced: the contact's extent on the face */
} mech_cam;
typedef struct model_cams {
    mech_cam *cam;       /* [n] */
    int n;
} model_cams;
static inline int model_ncams(const mech_model *m) { return m->cams ? m->cams->n : 0; }
void load_cams(loader *ld, const ynode *seq);

/* cam_geometry.c: cam c at the program's x (docs/cams.md 3). */
typedef struct cam_point {
    double x;            /* the program's variable: the cam's angle from 'start', rad */
    double s[4];         /* the lift and its first three derivatives in x */
    double pitch[2];     /* the trace point (roller's centre, knife's tip, flat face's foot
                            on its line) in the cam's own frame, m */
    double profile[2];   /* the contact point on the profile, in the cam's frame, m */
    double normal[2];    /* the common normal there, from the cam to the follower (unit,
                            in the cam's frame) */
    double pressure;     /* the angle from the trace point's motion to the common
                            normal, rad (0 for a flat face) */
    double rho_pitch;    /* the pitch curve's radius of curvature, m: + convex */
    double rho_profile;  /* the profile's */
    double face;         /* flat-faced: the contact's distance along the face from the
                            follower's line, m; else 0 */
} cam_point;
void cam_geometry(const mech_model *m, const mech_cam *c, double x, cam_point *g);
/* An oscillating flat face in the follower's frame: its unit direction w
 * (from its first point to its second); returns k = (A - P) . J w, its
 * line's signed distance from the follower's pivot P. */
double cam_face(const mech_model *m, const mech_cam *c, double w[2]);
/* cam_points.c: a cam given by its profile's points (docs/cams.md 7).
 * 'profile: [[x, y], ...]' or '{file: CSV}' into c->points (1, or 0 reported);
 * the least distance of their closed curve from the cam's centre into
 * c->base (1, or 0 reported; once the cam's pivot is known); the follower's
 * lift they give as c->program (after the follower is placed). */
int cam_points_load(loader *ld, const ynode *n, mech_cam *c);
int cam_points_base(loader *ld, mech_cam *c);
int cam_points_program(loader *ld, mech_cam *c);
/* The base positions that need the follower's guess (after the guesses). */
void load_cams_place(loader *ld);
void model_cams_free(model_cams *c);

#endif
