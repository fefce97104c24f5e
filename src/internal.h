/* src/internal.h: declarations shared by libmech's modules, not public. */
#ifndef MECH_INTERNAL_H
#define MECH_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "mech.h"

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

/* ---- util.c: checked allocation and small string helpers. */
void *xcalloc(size_t n, size_t size);           /* NULL on overflow or failure */
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
    double dvalue; /* d value / d seed: 1 for the seeded parameter itself, else through
                      its definition (forward mode; 0 when nothing is seeded) */
} expr_param;
typedef struct expr_env {
    const unit_defaults *units;
    const expr_param *params;
    int nparams;
    const name_map *param_index; /* name -> index into params, or NULL (linear search):
                                    a file may define many parameters */
    double *dvalue;              /* NULL, or where quantity_eval writes the derivative of
                                    the value it returns with respect to the seed */
} expr_env;
int quantity_eval(const char *text, quantity want, const expr_env *env,
                  double *value, char *err, size_t errsize, size_t *err_pos);
/* Evaluate a parameter definition: keeps its own dimension (or bare). */
int quantity_eval_param(const char *text, const expr_env *env, expr_param *out,
                        char *err, size_t errsize, size_t *err_pos);

/* load.c: mech_load_file_with, carrying d/d(seed) of every point's
 * coordinates into mech_point.dxy (forward mode through the quantity
 * expressions; the parameter named `seed` has derivative 1). */
int load_file_seeded(const char *path, const mech_override *ov, int nov, const char *seed,
                     mech_model **out, mech_diag *d);

/* load.c: a file read and parsed once (load_doc_read), then turned into
 * models with different parameter replacements (load_doc_model, as
 * mech_load_file_with; threads may share the document). */
typedef struct load_doc load_doc;
int load_doc_read(const char *path, load_doc **out, mech_diag *d);
int load_doc_model(const load_doc *doc, const mech_override *ov, int nov, mech_model **out,
                   mech_diag *d);
void load_doc_free(load_doc **doc);

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

/* ---- output.c: write_file_whole (src/output.h) */
#include "output.h"

/* ---- model.c */
int model_point_in_link(const mech_link *l, int name_id);  /* index or -1 */

#endif
