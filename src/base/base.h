/* src/base/base.h: the base every stage stands on: memory, names, diagnostics and failure kinds,
 * the public API's argument contract, worker threads and the clock. The stage's one header: what
 * its modules share with each other and with the later stages (docs/architecture.md, "Stages"). */
#ifndef MECH_BASE_STAGE_H
#define MECH_BASE_STAGE_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "mech.h"

/* ==== internal ==== */
/* declarations shared by libmech's modules, not public. */
#if defined(__GNUC__)
#define MECH_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define MECH_PRINTF(f, a)
#endif

/* ---- diag.c: strerror for any thread: the message of errno value e in
 *      buf[size] (POSIX strerror_r), returned. */
const char *diag_strerror(int e, char *buf, size_t size);

/* ---- diag.c: record a problem; returns MECH_EINPUT so a call site can be
 *      one `return diag_error(...)` line. */
int diag_error(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
    MECH_PRINTF(4, 5);
void diag_note(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
    MECH_PRINTF(4, 5);
void diag_warning(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
    MECH_PRINTF(4, 5);
/* ---- diag.c: the failure kinds (mech_fail_kind). diag_error records an
 *      error of kind MECH_FAIL_INPUT; diag_fail one of `kind`, and returns
 *      the library status of that kind (MECH_EINPUT, MECH_EIO, MECH_ENOMEM or
 *      MECH_ESOLVE); diag_nomem records "out of memory" (MECH_ENOMEM);
 *      diag_add any severity and kind (a warning that reports a kind:
 *      redundant constraints, a change point passed); diag_copy one entry
 *      as it is. */
int diag_fail(mech_diag *d, mech_fail_kind kind, const char *file, mech_mark at,
              const char *fmt, ...) MECH_PRINTF(5, 6);
int diag_nomem(mech_diag *d, const char *file, mech_mark at);
void diag_add(mech_diag *d, mech_severity sev, mech_fail_kind kind, const char *file,
              mech_mark at, const char *fmt, ...) MECH_PRINTF(6, 7);
void diag_copy(mech_diag *d, const mech_diag_entry *e);
/* The words a message states kind k in ("cannot assemble", "out of
 * memory", "a change point, where two assembly branches cross"). */
const char *fail_words(mech_fail_kind k);
/* 1 for the kinds of a suspect assembly (FAR_FROM_GUESS .. STILL_OUTPUTS): warnings that
 * `--strict` makes errors. */
int fail_is_suspect_assembly(mech_fail_kind k);
/* The library status a failure of kind k returns; the kind a status
 * stands for when nothing more is known (MECH_ESOLVE: no assembly). */
int fail_kind_status(mech_fail_kind k);
mech_fail_kind fail_of_status(int status);
/* The graver of the kind so far and one found (mech_diag_failure's rule;
 * on a tie the one so far); the gravest error kind of d's entries from
 * index first on. */
mech_fail_kind fail_graver(mech_fail_kind now, mech_fail_kind found);
mech_fail_kind diag_failure_since(const mech_diag *d, size_t first);
/* The library status of those errors (fail_kind_status of the gravest), or
 * `otherwise` when there is none. */
int diag_status_since(const mech_diag *d, size_t first, int otherwise);
/* The word of mech sweep's status column for a variant that failed with
 * kind k ("ok" for MECH_FAIL_NONE; docs/batch.md). */
/* mech sweep's status of a variant that failed with kind k. */
mech_variant_status fail_variant_status(mech_fail_kind k);

/* ---- util.c: checked allocation and small string helpers. */
void *xcalloc(size_t n, size_t size);           /* NULL on overflow or failure */
/* xcalloc for blocks of 8 MiB and more (result tables): huge-page aligned
 * and advised (util.c); free() it. */
void *xcalloc_large(size_t n, size_t size);
/* For tests of the out-of-memory paths: when > 0, it counts down at every
 * xcalloc, xrealloc_array and xstrdup of this thread, and the one that
 * brings it to 0 fails (later ones succeed). Thread-local: a test that sets
 * it does not disturb other threads. */
extern _Thread_local long xalloc_fail_countdown;
void *xrealloc_array(void *p, size_t n, size_t size);
char *xstrdup(const char *s);
/* *arrays[i] = sizes[i] zeroed doubles (size when sizes is NULL), for i < n.
 * 0, or -1 when out of memory (those allocated stay set: free them). */
int xcalloc_doubles(double **const *arrays, const size_t *sizes, size_t size, size_t n);
/* free() each of the n blocks. */
void free_all(void *const *blocks, size_t n);
#define COUNT_OF(a) (sizeof(a) / sizeof((a)[0]))
int edit_distance(const char *a, const char *b); /* Levenshtein, capped at 99 */
/* Parity of a permutation of 0..n-1 (0 even, 1 odd), by its cycles; seen:
 * n bytes of work. */
int permutation_parity(const int *perm, int n, unsigned char *seen);
/* Nearest of `names` to `word` when close enough to be a likely typo, else NULL. */
const char *nearest_name(const char *word, const char *const *names, size_t n);

/* A string -> int map with borrowed keys (open addressing), for name lookups
 * that must stay fast on mechanisms with 10^5 links. */
typedef struct name_map {
    const char **keys;  /* [cap] borrowed, NULL = empty slot */
    int *values;        /* [cap] */
    size_t cap, count;
} name_map;
int name_map_put(name_map *nm, const char *key, int value);  /* 0 ok, -1 no memory */
int name_map_get(const name_map *nm, const char *key);       /* value or -1 */
void name_map_free(name_map *nm);

/* ---- parallel.c: worker threads and the clock. */
/* job(ctx, i) for i = 0 .. njobs-1 on up to nthreads threads, each i once
 * (here when no thread can be made); returns when all are done. */
void parallel_run(long njobs, int nthreads, void (*job)(void *ctx, long i), void *ctx);
/* The CPUs of this process's affinity mask (else those online), 1..1024. */
int parallel_default_jobs(void);
/* Seconds on the monotonic clock (differences only). */
double clock_seconds(void);

/* fmt.c: v as the shortest decimal that strtod reads back as v (the
 * nearest of the shortest), laid out as %.17g; nan, inf, -0 as printf
 * writes them. Returns the length (at most FMT_DOUBLE_MAX - 1).
 * fmt_double_printf: the same text from printf's digits (slower; the
 * tests' reference). */
enum { FMT_DOUBLE_MAX = 32 };
int fmt_double(double v, char out[FMT_DOUBLE_MAX]);
int fmt_double_printf(double v, char out[FMT_DOUBLE_MAX]);

/* ---- units.c: physical dimensions, units and quantity expressions. */
enum { DIM_LENGTH, DIM_MASS, DIM_TIME, DIM_ANGLE, NDIMS };
typedef struct dim {
    signed char e[NDIMS]; /* exponents of m, kg, s, rad */
} dim;

/* The quantities a file may give; each has a default unit for bare numbers. */
typedef enum {
    Q_NUMBER, Q_LENGTH, Q_ANGLE, Q_MASS, Q_TIME, Q_FORCE, Q_TORQUE, Q_INERTIA,
    Q_SPEED, Q_ACCELERATION, Q_ANGULAR_SPEED, Q_ANGULAR_ACCELERATION,
    Q_FORCE_PER_LENGTH, Q_DAMPING, Q_TORSION_STIFFNESS, Q_TORSION_DAMPING,
    NQUANTITIES /* ORDER Q: keep quantity_table in units.c in step */
} quantity;

typedef struct quantity_info {
    const char *key;       /* name under `units:` */
    const char *noun;      /* for messages: "a length" */
    dim d;
    const char *si_unit;   /* printed SI unit */
} quantity_info;

const quantity_info *quantity_get(quantity q);
int quantity_by_key(const char *key);          /* -1 if none */

/* Default scale (SI per bare unit) of each quantity, set by `units:`. */
typedef struct unit_defaults {
    double scale[NQUANTITIES];
} unit_defaults;
void unit_defaults_init(unit_defaults *u);     /* all SI */
/* The file's `units:` as written (mech_model.units): each quantity's unit
 * ("mm", "deg"; "" where the file gives none) and its scale, SI per unit. */
typedef struct file_units {
    char text[NQUANTITIES][24];
    double scale[NQUANTITIES];
} file_units;
/* A value in SI of dimension d in the file's units: the unit's text into
 * buf and the scale (SI per unit) returned; the SI unit and 1 where the
 * file gives none of its parts. */
double file_units_of(const file_units *fu, dim d, char *buf, size_t size);

/* Parse a unit expression such as "kg*m^2" or "rad/s" at s; on success
 * sets *scale (SI per unit), *d, *end and returns 1; returns 0 if s does not
 * start with a known unit. */
int unit_parse(const char *s, double *scale, dim *d, const char **end);
int unit_is_name(const char *s, size_t len);
void dim_format(dim d, char *buf, size_t size);  /* "kg*m^2/s" */
int dim_equal(dim a, dim b);

/* Evaluate a quantity expression (number with unit, parameters, + - * / ^,
 * sqrt sin cos atan2, pi). Named parameters are looked up in `params`.
 * Returns 0 and sets *value (SI) on success; on failure returns -1 and
 * writes a message to err and the byte offset of the problem to *err_pos. */
typedef struct expr_param {
    const char *name;
    double value;
    dim d;
    int bare;  /* defined by a bare number: a pure number that adopts context */
    int root;  /* the definition's handle in the recorded expressions (param_expr.h) */
} expr_param;
typedef struct expr_env {
    const unit_defaults *units;
    const expr_param *params;
    int nparams;
    const name_map *param_index; /* name -> index into params, or NULL (linear search):
                                    a file may define many parameters */
    struct param_exprs *record;  /* NULL, or where the evaluation is recorded as a tree over
                                    the parameters (param_expr.h) */
    int *root;                   /* NULL, or where quantity_eval writes the handle of the
                                    value it returns in `record` */
} expr_env;
int quantity_eval(const char *text, quantity want, const expr_env *env,
                  double *value, char *err, size_t errsize, size_t *err_pos);
/* Evaluate a parameter definition: keeps its own dimension (or bare). */
int quantity_eval_param(const char *text, const expr_env *env, expr_param *out,
                        char *err, size_t errsize, size_t *err_pos);

/* load.c: a file read and parsed once (load_doc_read), then turned into
 * models with different parameter replacements (load_doc_model, as
 * mech_load_file_with; threads may share the document). */
typedef struct load_doc load_doc;
int load_doc_read(const char *path, load_doc **out, mech_diag *d);
int load_doc_model(const load_doc *doc, const mech_override *ov, int nov, mech_model **out,
                   mech_diag *d);
/* The same model without its parameter expressions (pexpr NULL, nothing
 * recorded): a sweep's variant needs only its numbers (the base's
 * expressions say what the varied parameters move). */
int load_doc_numbers(const load_doc *doc, const mech_override *ov, int nov, mech_model **out,
                     mech_diag *d);
void load_doc_free(load_doc **doc);

/* ---- the file's `fit:` section (src/load/load_fit.c, docs/synthesis.md):
 *      mech fit's problem as the file states it; the command line's options
 *      replace its parts. */
typedef struct model_fit_free {
    char *name;        /* a parameter of the file */
    double lo, hi;     /* bounds, SI; -INFINITY, INFINITY when none */
    mech_mark mark;
} model_fit_free;
typedef struct model_fit {
    model_fit_free *free;  /* [nfree] */
    int nfree;
    char *target;      /* the targets' CSV as written (relative: to the file's folder), or NULL */
    char **columns;    /* [ncolumns] the target columns, or none: every column */
    double *weights;   /* [ncolumns] */
    int ncolumns;
    int starts;        /* 0: the default */
    int whole_range;   /* 1: the solution must assemble over the file's whole range */
    int free_timing;   /* 1: each target row's driver position is an unknown too */
    struct model_fit_con *cons;  /* [ncons] constraints: "EXPR <= EXPR" (docs/synthesis.md 4) */
    int ncons;
    char *trans_a, *trans_b;     /* transmission: the two links, or NULL */
    double trans_min;            /* the least angle between them, rad (0 .. pi/2) */
    mech_mark trans_mark;
    mech_mark mark;
} model_fit;
/* One constraint g <= 0 of the fit: section, g = (the side that must be the
 * smaller) - (the other), in SI, at the values the file was loaded with. */
typedef struct model_fit_con {
    char *text;        /* as written */
    double g;          /* its value: <= 0 holds */
    double scale;      /* max(|left|, |right|), SI: the size the tolerance is relative to */
    int h;             /* g's handle in the model's parameter expressions (param_expr.h) */
    char unit[32];     /* g's SI unit ("" a pure number) */
    mech_mark mark;
} model_fit_con;
void model_fit_free_all(model_fit *f);  /* accepts NULL */

/* ---- yamltree.c: a bounded YAML document tree with marks. */
typedef enum { YNODE_SCALAR, YNODE_SEQ, YNODE_MAP } ynode_kind;
typedef struct ynode ynode;
struct ynode {
    ynode_kind kind;
    mech_mark mark;
    char *text;        /* SCALAR: value, NUL-terminated */
    size_t len;        /* SCALAR: bytes in text */
    int quoted;        /* SCALAR: was quoted in the source */
    ynode **items;     /* SEQ: [n] items; MAP: [2n] key, value pairs */
    size_t n;          /* SEQ: items; MAP: pairs */
    size_t nraw;       /* items stored (2n for a MAP) */
    const ynode *dup_of; /* SCALAR key of a MAP: the first key of that mapping with the
                            same text when this one repeats it, else NULL (found once,
                            in linear time, so large mappings are not quadratic) */
};

typedef struct yaml_limits {
    size_t max_bytes;      /* file size */
    int max_depth;         /* nesting of sequences and mappings */
    size_t max_nodes;
    size_t max_scalar;     /* bytes in one scalar */
} yaml_limits;
extern const yaml_limits yaml_default_limits;

/* Parse one YAML document. Returns the root (NULL on error, with the error
 * recorded in d). Aliases, anchors of collections, and multiple documents
 * are rejected. */
ynode *ytree_parse(const char *text, size_t len, const char *file,
                   const yaml_limits *lim, mech_diag *d);
void ytree_free(ynode *n);
ynode *ymap_get(const ynode *map, const char *key);      /* value or NULL */
const char *ynode_kind_name(ynode_kind k);
/* Trees built in code (the drawn form): a node (text: a SCALAR's, copied),
 * a child appended (freed on failure: -1), a deep copy; NULL: no memory. */
ynode *ynode_new(ynode_kind kind, const char *text, mech_mark mark);
int ynode_push(ynode *parent, ynode *child);
ynode *ytree_copy(const ynode *n);

/* ---- output.c: write_file_whole (src/output/output.h) */

/* ---- model.c */
int model_point_in_link(const mech_link *l, int name_id);  /* index or -1 */

/* ==== api ==== */
/* api.c: what libmech's public entry points share (src/base/api.c): the
 * argument contract of include/mech.h - a mech_diag for a caller who
 * passes none, the error for a required pointer that is NULL, the caller's
 * mech_solve_options read by the size it was compiled with. Private. */
/* d, or own (initialised here) when the caller passed NULL: the library's
 * code always has a diag to count its errors in. api_diag_end frees own
 * when it was used. */
mech_diag *api_diag(mech_diag *d, mech_diag *own);
void api_diag_end(const mech_diag *d, mech_diag *own);

/* MECH_EINPUT, with "FUNC: error: ARG is NULL ..." in d. */
int api_null(mech_diag *d, const char *func, const char *arg);

/* The replacements ov[0..nov-1] (NULL when nov is 0), each with a name and
 * a text: MECH_OK, or MECH_EINPUT with the message in d. */
int api_overrides(const char *func, const mech_override *ov, int nov, mech_diag *d);

/* The caller's options (NULL: the defaults) into *full, the library's
 * layout: the fields the caller's size covers, the defaults for those it
 * does not. MECH_OK, or MECH_EINPUT (with the message in d) when o->size
 * is not a size mech_solve_options_init accepts (the struct was not set by
 * it, or by a newer header than this library's). */
int api_options(const mech_solve_options *o, mech_solve_options *full, const char *func,
                mech_diag *d);

#endif
