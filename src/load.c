/* src/load.c: YAML document tree -> mech_model, validating as it goes.
 *
 * Schema (docs/format.md is the user's description of it):
 *   name: str                       required
 *   description: str
 *   units: {quantity: unit}         default units for bare numbers
 *   parameters: {name: expr}        named values, usable in later expressions
 *   gravity: [gx, gy]               acceleration
 *   ground: {point: [x, y]}         required, fixed points in the global frame
 *   links: {name: {points: {point: [x, y] | {length, angle, from}},
 *                  symbol, mass, center, inertia}}            required
 *   joints: [{revolute: P, links: [a, b], name, friction, pin_radius}
 *          | {slider: P, link, on, through, angle, rotation, name, symbol, friction}]
 *   driver: {link | slider, angle | displacement, speed, acceleration}  required
 *   initial: {link or slider name: value}
 *   branch: [{points: [A, B, C], turn: ccw | cw}]
 *   loops: [[A, B, C, A] | "A B C A"]
 *   loads: [{force: [fx, fy], link, at} | {torque, link}
 *         | {distributed, link, from, to, direction}]
 *   outputs: {points: [...], links: [...], sliders: [...], forces: bool}
 *
 * Every problem is recorded with its file:line:column and loading goes on,
 * so one run reports all the errors it can find. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

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
    unsigned char *link_failed; /* [links allocated] errors were reported about the link's
                                   points or joints: skip checks that would only echo them */
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
} loader;

static int find_point(const loader *ld, const char *name) { return name_map_get(&ld->point_map, name); }
static int find_link(const loader *ld, const char *name) { return name_map_get(&ld->link_map, name); }
static int find_joint(const loader *ld, const char *name) { return name_map_get(&ld->joint_map, name); }

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

/* The links carrying point `id`: carrier_link[*first .. *end - 1]; empty
 * without the index. Joints and loads name points of links; looking them up
 * here keeps a file with 10^6 ground points and many joints linear. */
static void carriers_of(const loader *ld, int id, int *first, int *end)
{
    *first = *end = 0;
    if (id >= 0 && id < ld->carrier_ids) {
        *first = ld->carrier_start[id];
        *end = ld->carrier_start[id + 1];
    }
}

/* Index of point `id` in link `li`, or -1 (binary search among the carriers). */
static int point_in_link(const loader *ld, int li, int id)
{
    if (ld->carrier_ids == 0)
        return model_point_in_link(&ld->m->links[li], id);
    int lo, end;
    carriers_of(ld, id, &lo, &end);
    for (int hi = end; lo < hi;) {
        int mid = lo + (hi - lo) / 2;
        if (ld->carrier_link[mid] < li)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < end && ld->carrier_link[lo] == li ? ld->carrier_point[lo] : -1;
}

static int err(loader *ld, const ynode *n, const char *fmt, ...) MECH_PRINTF(3, 4);
static int err(loader *ld, const ynode *n, const char *fmt, ...)
{
    char buf[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return diag_error(ld->d, ld->file, n ? n->mark : (mech_mark){0, 0}, "%s", buf);
}

/* ---- shape checks -------------------------------------------------- */

static int want_kind(loader *ld, const ynode *n, ynode_kind kind, const char *what)
{
    if (n->kind == kind)
        return 1;
    err(ld, n, "%s must be %s, not %s", what, ynode_kind_name(kind), ynode_kind_name(n->kind));
    return 0;
}

static int is_allowed(const char *key, const char *const *allowed, size_t nallowed)
{
    for (size_t a = 0; a < nallowed; a++)
        if (strcmp(allowed[a], key) == 0)
            return 1;
    return 0;
}

/* Check a mapping's keys: scalars, no duplicates, and either all in `allowed`
 * (a mapping of keywords) or, when `allowed` is NULL, names of `noun`s (a
 * mapping such as the links or the points of a link; `where` may be NULL).
 * Returns 1 when the mapping can be read (even with unknown keys). */
static int check_map(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                     const char *where, const char *noun)
{
    if (!want_kind(ld, map, YNODE_MAP, where ? where : noun))
        return 0;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i];
        if (k->kind != YNODE_SCALAR) {
            if (!noun)  /* else the caller reports it as an invalid name */
                err(ld, k, "a key in %s must be a plain name", where);
            continue;
        }
        const ynode *o = k->dup_of;  /* found by yamltree.c */
        if (o && noun)
            err(ld, k, "duplicate %s '%s'%s%s (first given at line %d)", noun, k->text,
                where ? " in " : "", where ? where : "", o->mark.line);
        else if (o)
            err(ld, k, "duplicate key '%s' in %s (first given at line %d)", k->text, where,
                o->mark.line);
        if (!allowed || is_allowed(k->text, allowed, nallowed))
            continue;
        const char *near = nearest_name(k->text, allowed, nallowed);
        if (near) {
            err(ld, k, "unknown key '%s' in %s (did you mean '%s'?)", k->text, where, near);
            continue;
        }
        char list[400];
        size_t n = 0;
        list[0] = '\0';
        for (size_t a = 0; a < nallowed && n < sizeof list; a++)
            n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", a ? ", " : "", allowed[a]);
        err(ld, k, "unknown key '%s' in %s (expected %s%s)", k->text, where,
            nallowed == 1 ? "" : "one of: ", list);
    }
    return 1;
}

static int check_keys(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                      const char *where)
{
    return check_map(ld, map, allowed, nallowed, where, NULL);
}

/* A key of `map` that is not allowed but is a likely typo of `key` (already
 * reported as such): then `key` is not "missing" as well. */
static int misspelt(const ynode *map, const char *key, const char *const *allowed,
                    size_t nallowed)
{
    for (size_t i = 0; map && map->kind == YNODE_MAP && i < map->n; i++) {
        const ynode *k = map->items[2 * i];
        if (k->kind != YNODE_SCALAR || is_allowed(k->text, allowed, nallowed))
            continue;
        const char *near = nearest_name(k->text, allowed, nallowed);
        if (near && strcmp(near, key) == 0)
            return 1;
    }
    return 0;
}

/* The key node of `key` in a mapping (for messages about the key itself). */
static const ynode *key_of(const ynode *map, const char *key)
{
    for (size_t i = 0; map && map->kind == YNODE_MAP && i < map->n; i++) {
        const ynode *k = map->items[2 * i];
        if (k->kind == YNODE_SCALAR && strcmp(k->text, key) == 0)
            return k;
    }
    return NULL;
}

/* Does an expression use a parameter whose own definition failed? Then its
 * error would only repeat that one. */
static int uses_bad_param(const loader *ld, const char *text)
{
    if (ld->bad_params.count == 0)
        return 0;
    for (const char *s = text; *s;) {
        if (!(isalpha((unsigned char)*s) || *s == '_')) {
            s++;
            continue;
        }
        size_t n = 0;
        while (isalnum((unsigned char)s[n]) || s[n] == '_')
            n++;
        char word[MAX_NAME + 1];
        if (n <= MAX_NAME) {
            memcpy(word, s, n);
            word[n] = '\0';
            if (name_map_get(&ld->bad_params, word) >= 0)
                return 1;
        }
        s += n;
    }
    return 0;
}

static int valid_name(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n > MAX_NAME || !(isalpha((unsigned char)s[0]) || s[0] == '_'))
        return 0;
    for (size_t i = 1; i < n; i++)
        if (!(isalnum((unsigned char)s[i]) || s[i] == '_'))
            return 0;
    return 1;
}

/* A name (of a link, point, joint or parameter): a scalar identifier. */
static const char *get_name(loader *ld, const ynode *n, const char *what)
{
    if (!want_kind(ld, n, YNODE_SCALAR, what))
        return NULL;
    if (strlen(n->text) > MAX_NAME) {
        err(ld, n, "%s is too long (%zu characters; at most %d)", what, strlen(n->text),
            MAX_NAME);
        return NULL;
    }
    if (!valid_name(n->text)) {
        err(ld, n, "%s '%s' is not a valid name (use letters, digits and '_', starting with a letter)",
            what, n->text);
        return NULL;
    }
    return n->text;
}

static char *get_string(loader *ld, const ynode *n, const char *what, size_t max)
{
    if (!want_kind(ld, n, YNODE_SCALAR, what))
        return NULL;
    if (n->len > max) {
        err(ld, n, "%s is too long (at most %zu characters)", what, max);
        return NULL;
    }
    return xstrdup(n->text);
}

/* Evaluate a quantity; the error points into the scalar where it can. */
static int get_quantity(loader *ld, const ynode *n, quantity q, const char *what, double *out)
{
    if (!want_kind(ld, n, YNODE_SCALAR, what))
        return 0;
    char msg[256];
    size_t pos = 0;
    if (quantity_eval(n->text, q, &ld->env, out, msg, sizeof msg, &pos) == 0)
        return 1;
    if (uses_bad_param(ld, n->text))
        return 0;
    mech_mark at = n->mark;
    if (!strchr(n->text, '\n'))
        at.col += (int)pos + (n->quoted ? 1 : 0);
    diag_error(ld->d, ld->file, at, "%s: %s", what, msg);
    return 0;
}

static int get_count(loader *ld, const ynode *n, const char *what, long lo, long hi, long *out)
{
    if (!want_kind(ld, n, YNODE_SCALAR, what))
        return 0;
    char *end;
    errno = 0;
    long v = strtol(n->text, &end, 10);
    if (end == n->text || *end != '\0' || errno) {
        /* a whole number too big for a long, or written 1e12: out of range, not
         * "not a whole number" */
        double x = strtod(n->text, &end);
        int whole = end != n->text && *end == '\0' && (isinf(x) || x == floor(x)) && !isnan(x);
        if (whole && (x < (double)lo || x > (double)hi))
            err(ld, n, "%s must be between %ld and %ld, not %s", what, lo, hi, n->text);
        else if (whole)
            err(ld, n, "%s must be written with digits only, not '%s'", what, n->text);
        else
            err(ld, n, "%s must be a whole number, not '%s'", what, n->text);
        return 0;
    }
    if (v < lo || v > hi) {
        err(ld, n, "%s must be between %ld and %ld, not %ld", what, lo, hi, v);
        return 0;
    }
    *out = v;
    return 1;
}

static int get_bool(loader *ld, const ynode *n, const char *what, int *out)
{
    static const char *const yes[] = {"true", "yes", "on"}, *const no[] = {"false", "no", "off"};
    if (!want_kind(ld, n, YNODE_SCALAR, what))
        return 0;
    for (size_t i = 0; i < 3; i++) {
        if (strcmp(n->text, yes[i]) == 0)
            return *out = 1, 1;
        if (strcmp(n->text, no[i]) == 0)
            return *out = 0, 1;
    }
    err(ld, n, "%s must be true or false, not '%s'", what, n->text);
    return 0;
}

static int get_vec2(loader *ld, const ynode *n, quantity q, const char *what, double out[2])
{
    if (n->kind != YNODE_SEQ) {
        err(ld, n, "%s must be a list of two values [x, y], not %s", what,
            ynode_kind_name(n->kind));
        return 0;
    }
    if (n->n != 2) {
        err(ld, n, "%s must be a list of two values [x, y], not of %zu", what, n->n);
        return 0;
    }
    int ok = get_quantity(ld, n->items[0], q, what, &out[0]);
    return get_quantity(ld, n->items[1], q, what, &out[1]) && ok;
}

/* Past the cap on errors, a message is only counted: do not spend time on it. */
static int errors_full(const loader *ld)
{
    return ld->d->nerrors >= (ld->d->max_errors ? ld->d->max_errors : 100);
}

/* Report a name that is not among the candidates: say the nearest one, or
 * list them all when there are few (`kinds` is the plural of `kind`). */
static void err_unknown(loader *ld, const ynode *n, const char *kind, const char *kinds,
                        const char *name, const char *const *cands, size_t ncands)
{
    /* Suggestions cost an edit distance per candidate: not among 10^5 links,
     * nor for messages past the cap, which are only counted */
    if (errors_full(ld))
        return (void)err(ld, n, "unknown %s '%s'", kind, name);
    const char *near = ncands <= MAX_SUGGEST ? nearest_name(name, cands, ncands) : NULL;
    if (near)
        return (void)err(ld, n, "unknown %s '%s' (did you mean '%s'?)", kind, name, near);
    if (ncands == 0)
        return (void)err(ld, n, "unknown %s '%s' (there are no %s)", kind, name, kinds);
    if (ncands > 12)
        return (void)err(ld, n, "unknown %s '%s'", kind, name);
    char list[12 * (MAX_NAME + 2) + 1];
    size_t len = 0;
    list[0] = '\0';
    for (size_t i = 0; i < ncands && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", cands[i]);
    err(ld, n, "unknown %s '%s' (the %s are: %s)", kind, name, kinds, list);
}

static int find_link_or_report(loader *ld, const ynode *n, const char *what)
{
    const char *name = get_name(ld, n, what);
    if (!name)
        return -1;
    int li = find_link(ld, name);
    if (li >= 0 || ld->links_bad)
        return li;
    if (errors_full(ld))
        return err(ld, n, "unknown link"), -1;
    const char **names = xcalloc((size_t)ld->m->nlinks, sizeof *names);
    for (int i = 0; names && i < ld->m->nlinks; i++)
        names[i] = ld->m->links[i].name;
    err_unknown(ld, n, "link", "links", name, names, names ? (size_t)ld->m->nlinks : 0);
    free(names);
    return -1;
}

static int find_point_or_report(loader *ld, const ynode *n, const char *what)
{
    const char *name = get_name(ld, n, what);
    if (!name)
        return -1;
    int id = find_point(ld, name);
    if (id < 0 && !ld->links_bad && !ld->points_bad)
        err_unknown(ld, n, "point", "points", name, (const char *const *)ld->m->point_names,
                    (size_t)ld->m->npoint_names);
    return id;
}

/* ---- units and parameters ----------------------------------------- */

static void load_units(loader *ld, const ynode *map)
{
    const char *keys[NQUANTITIES];
    for (int q = 1; q < NQUANTITIES; q++)
        keys[q - 1] = quantity_get((quantity)q)->key;
    if (!check_keys(ld, map, keys, NQUANTITIES - 1, "units"))
        return;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        int q = k->kind == YNODE_SCALAR ? quantity_by_key(k->text) : -1;
        if (q < 0 || !want_kind(ld, v, YNODE_SCALAR, "a unit"))
            continue;
        double scale;
        dim d;
        const char *end;
        if (!unit_parse(v->text, &scale, &d, &end) || *end != '\0') {
            err(ld, v, "unknown unit '%s' for %s", v->text, k->text);
            continue;
        }
        const quantity_info *qi = quantity_get((quantity)q);
        if (!dim_equal(d, qi->d)) {
            const char *noun = NULL;
            for (int o = 0; o < NQUANTITIES; o++)
                if (dim_equal(d, quantity_get((quantity)o)->d))
                    noun = quantity_get((quantity)o)->noun;
            char u[64];
            dim_format(d, u, sizeof u);
            if (noun)
                err(ld, v, "'%s' is not a unit of %s (it measures %s; %s is in %s)", v->text,
                    k->text, noun, k->text, qi->si_unit);
            else
                err(ld, v, "'%s' is not a unit of %s (it is in %s; %s is in %s)", v->text,
                    k->text, u, k->text, qi->si_unit);
            continue;
        }
        ld->units.scale[q] = scale;
    }
}

/* What a name already means in an expression, or NULL if it is free. */
static const char *reserved_name(const char *s)
{
    static const char *const words[] = {"sqrt", "sin", "cos", "tan", "atan2"};
    if (strcmp(s, "pi") == 0)
        return "the constant";
    for (size_t i = 0; i < COUNT(words); i++)
        if (strcmp(s, words[i]) == 0)
            return "the function";
    return unit_is_name(s, strlen(s)) ? "the unit" : NULL;
}

static void load_parameters(loader *ld, const ynode *map)
{
    if (!check_map(ld, map, NULL, 0, "'parameters'", "parameter"))
        return;
    if (map->n > MAX_PARAMS)
        return (void)err(ld, map, "too many parameters (%zu; at most %d)", map->n, MAX_PARAMS);
    mech_model *m = ld->m;
    m->params = xcalloc(map->n, sizeof *m->params);
    ld->params = xcalloc(map->n, sizeof *ld->params);
    if (!m->params || !ld->params) {
        err(ld, map, "out of memory");
        return;
    }
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = get_name(ld, k, "parameter name");
        if (!name)
            continue;
        const char *taken = reserved_name(name);
        if (taken) {
            err(ld, k, "parameter name '%s' is already %s '%s' in expressions; choose another "
                       "name", name, taken, name);
            continue;
        }
        if (k->dup_of)
            continue; /* duplicate key, already reported */
        if (!want_kind(ld, v, YNODE_SCALAR, "a parameter value"))
            continue;
        expr_param p = {0};
        char msg[256];
        size_t pos = 0;
        const char *text = v->text;
        for (int o = 0; o < ld->nov; o++)
            if (strcmp(ld->ov[o].name, name) == 0) {
                text = ld->ov[o].text;
                ld->ov_used[o] = 1;
            }
        if (text != v->text && quantity_eval_param(text, &ld->env, &p, msg, sizeof msg, &pos) < 0) {
            diag_error(ld->d, ld->file, v->mark, "parameter '%s' replaced by '%s': %s", name,
                       text, msg);
            continue;
        }
        if (text == v->text && quantity_eval_param(v->text, &ld->env, &p, msg, sizeof msg, &pos) < 0) {
            int echo = uses_bad_param(ld, v->text);
            if (name_map_put(&ld->bad_params, k->text, 1) < 0 || echo)
                continue;
            mech_mark at = v->mark;
            at.col += (int)pos + (v->quoted ? 1 : 0);
            diag_error(ld->d, ld->file, at, "parameter '%s': %s", name, msg);
            continue;
        }
        mech_param *mp = &m->params[m->nparams];
        mp->name = xstrdup(name);
        if (!mp->name || name_map_put(&ld->param_map, mp->name, m->nparams) < 0) {
            free(mp->name);
            mp->name = NULL;
            err(ld, k, "out of memory");
            continue;
        }
        mp->value = p.value;
        mp->mark = k->mark;
        p.name = mp->name;
        ld->params[m->nparams++] = p;
        ld->env.nparams = m->nparams;
        ld->env.params = ld->params;
        ld->env.param_index = &ld->param_map;
    }
}

/* ---- points and links --------------------------------------------- */

static int intern_point(loader *ld, const char *name)
{
    mech_model *m = ld->m;
    int id = find_point(ld, name);
    if (id >= 0)
        return id;
    if ((m->npoint_names & (m->npoint_names - 1)) == 0) {
        size_t cap = m->npoint_names ? 2 * (size_t)m->npoint_names : 4;
        char **p = xrealloc_array(m->point_names, cap, sizeof *p);
        if (!p)
            return -1;
        m->point_names = p;
    }
    char *copy = xstrdup(name);
    if (!copy || name_map_put(&ld->point_map, copy, m->npoint_names) < 0) {
        free(copy);
        return -1;
    }
    m->point_names[m->npoint_names] = copy;
    return m->npoint_names++;
}

/* The index of point `name` among the points of `l` read so far, or -1;
 * `index` (name -> index, or NULL) keeps a link of 10^6 points linear. */
static int point_of_link(const mech_link *l, const name_map *index, const char *name)
{
    if (index)
        return name_map_get(index, name);
    for (int i = 0; i < l->npoints; i++)
        if (l->points[i].name && strcmp(l->points[i].name, name) == 0)
            return i;
    return -1;
}

/* A point: [x, y] or {length, angle, from}. `l` holds the points read so far. */
static int load_point_coords(loader *ld, const mech_link *l, const name_map *index,
                             const ynode *v, const char *what, double *x, double *y)
{
    if (v->kind == YNODE_SEQ) {
        double xy[2];
        if (!get_vec2(ld, v, Q_LENGTH, what, xy))
            return 0;
        *x = xy[0];
        *y = xy[1];
        return 1;
    }
    if (v->kind != YNODE_MAP) {
        err(ld, v, "%s must be [x, y] or {length: ..., angle: ...}", what);
        return 0;
    }
    static const char *const keys[] = {"length", "angle", "from"};
    check_keys(ld, v, keys, COUNT(keys), what);
    const ynode *len = ymap_get(v, "length"), *ang = ymap_get(v, "angle"), *from = ymap_get(v, "from");
    if (!len || !ang) {
        err(ld, v, "%s: missing '%s' (polar form needs length and angle)", what,
            len ? "angle" : "length");
        return 0;
    }
    double r, a, x0 = 0, y0 = 0;
    int ok = get_quantity(ld, len, Q_LENGTH, what, &r);
    ok = get_quantity(ld, ang, Q_ANGLE, what, &a) && ok;
    if (from) {
        const char *fname = get_name(ld, from, "'from'");
        int i = fname ? point_of_link(l, index, fname) : -1;
        if (i >= 0) {
            x0 = l->points[i].x;
            y0 = l->points[i].y;
        }
        if (fname && i < 0) {
            err(ld, from, "'from: %s' must name a point listed earlier in link '%s'", fname,
                l->name);
            ok = 0;
        }
    }
    if (!ok)
        return 0;  /* r or a may be unset */
    *x = x0 + r * cos(a);
    *y = y0 + r * sin(a);
    return 1;
}

/* The points of a link; returns 0 when some point had an error. A point with
 * wrong coordinates is kept (at 0, 0) so that its name still joins links and
 * the error is not echoed by every use of the name. */
static int load_points(loader *ld, mech_link *l, const ynode *map)
{
    char where[128];
    snprintf(where, sizeof where, "link '%s'", l->name);
    if (map->kind != YNODE_MAP) {
        ld->points_bad = 1;
        return err(ld, map, "the points of link '%s' must be a mapping from point name to "
                            "coordinates (such as 'A: [20, 0]'), not %s", l->name,
                   ynode_kind_name(map->kind)), 0;
    }
    size_t errors = ld->d->nerrors;
    check_map(ld, map, NULL, 0, where, "point");
    int max = l->is_ground ? MAX_GROUND_POINTS : MAX_POINTS_PER_LINK;
    if (map->n > (size_t)max) {
        err(ld, map, "link '%s' has %zu points; at most %d", l->name, map->n, max);
        return 0;
    }
    l->points = xcalloc(map->n, sizeof *l->points);
    if (!l->points) {
        err(ld, map, "out of memory");
        return 0;
    }
    name_map index = {0};  /* point name -> index, for 'from' */
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = get_name(ld, k, "point name");
        if (!name)
            ld->points_bad = 1;
        if (!name || k->dup_of)
            continue;  /* invalid or duplicate (reported) */
        char what[128];
        snprintf(what, sizeof what, "point '%s' of link '%s'", name, l->name);
        mech_point *p = &l->points[l->npoints];
        if (!load_point_coords(ld, l, &index, v, what, &p->x, &p->y))
            p->x = p->y = 0;
        p->name = xstrdup(name);
        p->id = intern_point(ld, name);
        p->mark = k->mark;
        if (!p->name || p->id < 0 || name_map_put(&index, p->name, l->npoints) < 0) {
            err(ld, k, "out of memory");
            break;
        }
        l->npoints++;
    }
    name_map_free(&index);
    return ld->d->nerrors == errors;
}

static const char *const link_keys[] = {"points", "symbol", "mass", "center", "inertia"};

static void load_mass(loader *ld, mech_link *l, const ynode *map)
{
    const ynode *mass = ymap_get(map, "mass"), *center = ymap_get(map, "center"),
                *inertia = ymap_get(map, "inertia");
    if (!mass && !center && !inertia)
        return;
    char what[128];
    if (!mass && misspelt(map, "mass", link_keys, COUNT(link_keys)))
        return;  /* reported as a typo */
    if (!mass) {
        err(ld, center ? center : inertia, "link '%s' has '%s' but no 'mass'", l->name,
            center ? "center" : "inertia");
        return;
    }
    snprintf(what, sizeof what, "mass of link '%s'", l->name);
    if (!get_quantity(ld, mass, Q_MASS, what, &l->mass))
        return;
    if (l->mass < 0)
        err(ld, mass, "%s is negative", what);
    if ((!center && misspelt(map, "center", link_keys, COUNT(link_keys))) ||
        (!inertia && misspelt(map, "inertia", link_keys, COUNT(link_keys))))
        return;
    if (!center || !inertia) {
        err(ld, mass, "link '%s' has a mass but no '%s' (give both center and inertia)", l->name,
            center ? "inertia" : "center");
        return;
    }
    snprintf(what, sizeof what, "center of mass of link '%s'", l->name);
    if (center->kind == YNODE_SCALAR && valid_name(center->text)) {
        int found = 0;
        for (int i = 0; i < l->npoints; i++)
            if (strcmp(l->points[i].name, center->text) == 0) {
                l->center[0] = l->points[i].x;
                l->center[1] = l->points[i].y;
                found = 1;
            }
        if (!found) {
            err(ld, center, "%s: '%s' is not a point of link '%s'", what, center->text, l->name);
            return;
        }
    } else if (!load_point_coords(ld, l, NULL, center, what, &l->center[0], &l->center[1])) {
        return;
    }
    snprintf(what, sizeof what, "inertia of link '%s'", l->name);
    if (!get_quantity(ld, inertia, Q_INERTIA, what, &l->inertia))
        return;
    if (l->inertia < 0) {
        err(ld, inertia, "%s is negative", what);
        return;
    }
    l->has_mass = 1;
}

static void load_ground(loader *ld, const ynode *map)
{
    mech_link *g = &ld->m->links[0];
    g->name = xstrdup("ground");
    g->is_ground = 1;
    if (g->name)
        name_map_put(&ld->link_map, g->name, 0);
    if (map) {
        g->mark = map->mark;
        if (!load_points(ld, g, map))
            ld->link_failed[0] = 1;
    }
}

static void load_link(loader *ld, mech_link *l, const ynode *k, const ynode *v)
{
    l->name = xstrdup(k->text);
    l->mark = k->mark;
    if (!l->name)
        return (void)err(ld, k, "out of memory");
    char where[128];
    snprintf(where, sizeof where, "link '%s'", l->name);
    unsigned char *failed = &ld->link_failed[l - ld->m->links];
    if (v->kind != YNODE_MAP) {
        *failed = 1;
        return (void)err(ld, v, "link '%s' must be a mapping with its 'points' (and optionally "
                                "'mass', 'center', 'inertia', 'symbol'), not %s", l->name,
                         ynode_kind_name(v->kind));
    }
    check_keys(ld, v, link_keys, COUNT(link_keys), where);
    const ynode *points = ymap_get(v, "points"), *sym = ymap_get(v, "symbol");
    if (!points) {
        *failed = 1;
        if (!misspelt(v, "points", link_keys, COUNT(link_keys)))
            err(ld, k, "link '%s' has no 'points'", l->name);
    } else if (!load_points(ld, l, points)) {
        *failed = 1;
    }
    if (sym)
        l->symbol = get_string(ld, sym, "symbol", 32);
    load_mass(ld, l, v);
}

static void load_links(loader *ld, const ynode *map)
{
    mech_model *m = ld->m;
    if (map->kind != YNODE_MAP) {
        ld->links_bad = 1;
        return (void)err(ld, map, "'links' must be a mapping from each link's name to its "
                                  "points (such as 'crank: {points: {O: [0, 0], A: [20, 0]}}'), "
                                  "not %s", ynode_kind_name(map->kind));
    }
    check_map(ld, map, NULL, 0, NULL, "link");
    if (map->n == 0) {
        ld->links_bad = 1;
        err(ld, map, "'links' is empty: a mechanism needs at least one moving link");
        return;
    }
    if (map->n >= MAX_LINKS) {
        err(ld, map, "too many links (%zu; at most %d moving links)", map->n, MAX_LINKS - 1);
        return;
    }
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = get_name(ld, k, "link name");
        if (!name || k->dup_of)
            continue;
        if (strcmp(name, "ground") == 0) {
            err(ld, k, "'ground' is the fixed link: give its points under the top-level 'ground' key");
            continue;
        }
        if (name_map_put(&ld->link_map, name, m->nlinks) < 0)
            return (void)err(ld, k, "out of memory");
        load_link(ld, &m->links[m->nlinks++], k, v);
    }
}

/* ---- joints --------------------------------------------------------- */

static mech_joint *new_joint(loader *ld)
{
    mech_model *m = ld->m;
    if ((m->njoints & (m->njoints - 1)) == 0) {
        size_t cap = m->njoints ? 2 * (size_t)m->njoints : 4;
        mech_joint *j = xrealloc_array(m->joints, cap, sizeof *j);
        if (!j)
            return NULL;
        m->joints = j;
    }
    mech_joint *j = &m->joints[m->njoints++];
    memset(j, 0, sizeof *j);
    return j;
}

static void set_joint_name(loader *ld, mech_joint *j, const ynode *name_node, const char *deflt)
{
    mech_model *m = ld->m;
    if (name_node) {
        const char *name = get_name(ld, name_node, "joint name");
        if (name) {
            int other = find_joint(ld, name);
            if (other >= 0)
                err(ld, name_node, "duplicate joint name '%s' (first used at line %d)", name,
                    m->joints[other].mark.line);
            else
                j->name = xstrdup(name);
        }
        if (j->name) {
            name_map_put(&ld->joint_map, j->name, (int)(j - m->joints));
            return;
        }
    }
    /* a default name, made unique with a suffix; the suffixes below the one
     * remembered for this default are all taken (a pin on 10^5 links would
     * otherwise try 2, 3, ... again for each of its joints) */
    char buf[MAX_NAME + 16];
    int k = name_map_get(&ld->next_suffix, deflt);
    snprintf(buf, sizeof buf, "%s", deflt);
    for (k = k < 2 ? 2 : k; find_joint(ld, buf) >= 0; k++)
        snprintf(buf, sizeof buf, "%s_%d", deflt, k);
    j->name = xstrdup(buf);
    if (!j->name)
        return;
    name_map_put(&ld->joint_map, j->name, (int)(j - m->joints));
    int first = find_joint(ld, deflt);  /* its name outlives the map: a stable key */
    if (first >= 0)
        name_map_put(&ld->next_suffix, m->joints[first].name, k);
}

static int get_friction(loader *ld, const ynode *map, mech_joint *j)
{
    const ynode *f = ymap_get(map, "friction"), *r = ymap_get(map, "pin_radius");
    if (f && get_quantity(ld, f, Q_NUMBER, "friction coefficient", &j->friction) &&
        (j->friction < 0 || j->friction > 10))
        err(ld, f, "friction coefficient %g is out of range (0 to 10)", j->friction);
    if (r && get_quantity(ld, r, Q_LENGTH, "pin radius", &j->pin_radius) && j->pin_radius < 0)
        err(ld, r, "pin radius is negative");
    if (j->friction > 0 && j->kind == MECH_JOINT_REVOLUTE && !r)
        return err(ld, key_of(map, "friction"), "revolute joint '%s' has friction but no "
                                                "'pin_radius' (the friction moment needs the "
                                                "pin radius)", j->name), 0;
    return 1;
}

static void load_revolute(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"revolute", "links", "name", "friction", "pin_radius"};
    mech_model *m = ld->m;
    check_keys(ld, map, keys, COUNT(keys), "a revolute joint");
    const ynode *pn = ymap_get(map, "revolute"), *ln = ymap_get(map, "links");
    int id = find_point_or_report(ld, pn, "joint point");
    if (id < 0)
        return;
    int carriers[2], nc = 0;
    if (ln) {
        if (ln->kind != YNODE_SEQ || ln->n != 2) {
            err(ld, ln, "'links' of a revolute joint must list two links [a, b]");
            return;
        }
        for (int i = 0; i < 2; i++) {
            int li = find_link_or_report(ld, ln->items[i], "link");
            if (li < 0)
                return;
            if (point_in_link(ld, li, id) < 0) {
                err(ld, ln->items[i], "link '%s' has no point '%s'", m->links[li].name, pn->text);
                return;
            }
            carriers[nc++] = li;
        }
        if (carriers[0] == carriers[1]) {
            err(ld, ln, "a revolute joint joins two different links");
            return;
        }
    } else {
        int first, end;
        carriers_of(ld, id, &first, &end);
        for (int c = first; c < end; c++) {
            if (nc == 2) {
                err(ld, pn, "point '%s' is on more than two links; say which two this joint "
                            "joins with 'links: [a, b]'", pn->text);
                return;
            }
            carriers[nc++] = ld->carrier_link[c];
        }
        if (nc < 2) {
            err(ld, pn, "point '%s' is on only one link; a revolute joint needs it on two",
                pn->text);
            return;
        }
    }
    mech_joint *j = new_joint(ld);
    if (!j)
        return (void)err(ld, map, "out of memory");
    j->kind = MECH_JOINT_REVOLUTE;
    j->is_explicit = 1;
    j->mark = map->mark;
    for (int i = 0; i < 2; i++) {
        j->link[i] = carriers[i];
        j->point[i] = point_in_link(ld, carriers[i], id);
    }
    set_joint_name(ld, j, ymap_get(map, "name"), pn->text);
    get_friction(ld, map, j);
}

static int load_slider_joint(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"slider", "link", "on", "through", "angle",
                                       "rotation", "name", "symbol", "friction"};
    mech_model *m = ld->m;
    check_keys(ld, map, keys, COUNT(keys), "a slider joint");
    const ynode *pn = ymap_get(map, "slider"), *on = ymap_get(map, "on"),
                *through = ymap_get(map, "through"), *ln = ymap_get(map, "link"),
                *ang = ymap_get(map, "angle"), *rot = ymap_get(map, "rotation");
    const char *missing = !on ? "on" : !through ? "through" : !ang ? "angle" : NULL;
    if (missing)
        return err(ld, map, "slider joint is missing '%s' (%s)", missing,
                   !on ? "the link that carries the guide line"
                       : !through ? "a point of the guide link on the line"
                                  : "the line's direction"), 0;
    int id = find_point_or_report(ld, pn, "slider point");
    int guide = find_link_or_report(ld, on, "guide link");
    if (id < 0 || guide < 0)
        return 0;
    int mover = -1;
    if (ln) {
        mover = find_link_or_report(ld, ln, "sliding link");
        if (mover < 0)
            return 0;
        if (point_in_link(ld, mover, id) < 0)
            return err(ld, ln, "link '%s' has no point '%s'", m->links[mover].name, pn->text), 0;
    } else {
        int nc = 0, first, end;
        carriers_of(ld, id, &first, &end);
        for (int c = first; c < end; c++)
            if (ld->carrier_link[c] != guide)
                mover = ld->carrier_link[c], nc++;
        if (nc != 1)
            return err(ld, pn, "point '%s' is on %d links; say which one slides with "
                               "'link: name'", pn->text, nc), 0;
    }
    if (mover == guide)
        return err(ld, on, "a slider's link and its guide ('on') must differ"), 0;
    if (point_in_link(ld, guide, id) >= 0)
        return err(ld, pn, "the guide link '%s' also has a point '%s'; the sliding point "
                           "must be a point of the moving link only", m->links[guide].name,
                   pn->text), 0;
    int tid = find_point_or_report(ld, through, "'through' point");
    if (tid < 0)
        return 0;
    int tp = point_in_link(ld, guide, tid);
    if (tp < 0)
        return err(ld, through, "'through: %s' must be a point of the guide link '%s'",
                   through->text, m->links[guide].name), 0;
    mech_joint *j = new_joint(ld);
    if (!j)
        return err(ld, map, "out of memory"), 0;
    j->kind = MECH_JOINT_SLIDER;
    j->is_explicit = 1;
    j->mark = map->mark;
    j->link[0] = mover;
    j->point[0] = point_in_link(ld, mover, id);
    j->link[1] = guide;
    j->point[1] = tp;
    j->locked = 1;
    get_quantity(ld, ang, Q_ANGLE, "slider line angle", &j->angle);
    if (rot) {
        if (rot->kind == YNODE_SCALAR && strcmp(rot->text, "free") == 0)
            j->locked = 0;
        else if (!(rot->kind == YNODE_SCALAR && strcmp(rot->text, "locked") == 0))
            err(ld, rot, "rotation must be 'locked' (prismatic) or 'free' (pin in slot)");
    }
    char deflt[MAX_NAME + 3];
    snprintf(deflt, sizeof deflt, "s_%s", pn->text);
    set_joint_name(ld, j, ymap_get(map, "name"), deflt);
    const ynode *sym = ymap_get(map, "symbol");
    if (sym)
        j->symbol = get_string(ld, sym, "symbol", 32);
    get_friction(ld, map, j);
    return 1;
}

/* A slider that could not be made leaves its block with a single point:
 * that link is not also reported as having too few points. */
static void load_slider(loader *ld, const ynode *map)
{
    if (load_slider_joint(ld, map))
        return;
    const ynode *pn = ymap_get(map, "slider");
    int id = pn && pn->kind == YNODE_SCALAR ? find_point(ld, pn->text) : -1;
    int first, end;
    carriers_of(ld, id, &first, &end);
    for (int c = first; c < end; c++)
        ld->link_failed[ld->carrier_link[c]] = 1;
}

/* Index the links that carry each point name (see carriers_of); points are
 * all known once the links are read. */
static void index_carriers(loader *ld)
{
    mech_model *m = ld->m;
    size_t n = (size_t)m->npoint_names, total = 0;
    for (int li = 0; li < m->nlinks; li++)
        total += (size_t)m->links[li].npoints;
    ld->carrier_start = xcalloc(n + 2, sizeof *ld->carrier_start);
    ld->carrier_link = xcalloc(total, sizeof *ld->carrier_link);
    ld->carrier_point = xcalloc(total, sizeof *ld->carrier_point);
    if (!ld->carrier_start || !ld->carrier_link || !ld->carrier_point)
        return (void)err(ld, NULL, "out of memory");
    int *fill = ld->carrier_start + 1;  /* counts, then the next free slot of each id */
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++)
            if (m->links[li].points[p].id >= 0)
                fill[m->links[li].points[p].id + 1]++;
    for (size_t i = 0; i < n; i++)
        fill[i + 1] += fill[i];
    for (int li = 0; li < m->nlinks; li++)  /* in link order: each id's carriers ascend */
        for (int p = 0; p < m->links[li].npoints; p++) {
            int id = m->links[li].points[p].id;
            if (id < 0)
                continue;
            ld->carrier_link[fill[id]] = li;
            ld->carrier_point[fill[id]++] = p;
        }
    /* fill[id] is now the end of id's carriers, i.e. carrier_start[id + 1] */
    ld->carrier_start[0] = 0;
    ld->carrier_ids = (int)n;
}

static void load_joints(loader *ld, const ynode *seq)
{
    if (!want_kind(ld, seq, YNODE_SEQ, "'joints'"))
        return;
    if (seq->n > MAX_LIST)
        return (void)err(ld, seq, "too many joints (%zu; at most %d)", seq->n, MAX_LIST);
    for (size_t i = 0; i < seq->n; i++) {
        const ynode *j = seq->items[i];
        if (!want_kind(ld, j, YNODE_MAP, "a joint"))
            continue;
        const ynode *r = ymap_get(j, "revolute"), *s = ymap_get(j, "slider");
        if (r && s)
            err(ld, j, "a joint is either 'revolute' or 'slider', not both");
        else if (r)
            load_revolute(ld, j);
        else if (s)
            load_slider(ld, j);
        else
            err(ld, j, "a joint needs 'revolute: POINT' or 'slider: POINT'");
    }
}

/* Union-find over the links carrying one point name (local indices). */
static int uf_find(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

static int local_index(const int *carrier, int k, int link)
{
    for (int i = 0; i < k; i++)
        if (carrier[i] == link)
            return i;
    return -1;
}

/* Pin together the links that carry point `id` (carrier[0..k-1], point index
 * cpoint[]), adding revolutes to the first carrier where the explicit joints
 * at that point (joint indices ej[0..ne-1]) leave them apart. */
static void pin_carriers(loader *ld, int id, const int *carrier, const int *cpoint, int k,
                         const int *ej, int ne, int *parent)
{
    mech_model *m = ld->m;
    for (int i = 0; i < k; i++)
        parent[i] = i;
    for (int e = 0; e < ne; e++) {
        const mech_joint *j = &m->joints[ej[e]];
        int a = local_index(carrier, k, j->link[0]), b = local_index(carrier, k, j->link[1]);
        parent[uf_find(parent, a)] = uf_find(parent, b);
    }
    for (int c = 1; c < k; c++) {
        if (uf_find(parent, c) == uf_find(parent, 0))
            continue;
        parent[uf_find(parent, c)] = uf_find(parent, 0);
        mech_joint *j = new_joint(ld);
        if (!j)
            return (void)err(ld, NULL, "out of memory");
        j->kind = MECH_JOINT_REVOLUTE;
        j->link[0] = carrier[0];
        j->point[0] = cpoint[0];
        j->link[1] = carrier[c];
        j->point[1] = cpoint[c];
        j->mark = m->links[carrier[c]].points[cpoint[c]].mark;
        set_joint_name(ld, j, NULL, m->point_names[id]);
    }
}

/* Every point name on two or more links pins them together: add the revolute
 * joints that the explicit ones do not already provide. Linear in the number
 * of points (grouped by name in compressed-row form). */
static void add_implicit_revolutes(loader *ld)
{
    mech_model *m = ld->m;
    size_t n = (size_t)m->npoint_names, total = 0;
    for (int li = 0; li < m->nlinks; li++)
        total += (size_t)m->links[li].npoints;
    int nexplicit = m->njoints;
    int *start = xcalloc(n + 1, sizeof *start);          /* carriers of id: start[id]..start[id+1] */
    int *carrier = xcalloc(total, sizeof *carrier), *cpoint = xcalloc(total, sizeof *cpoint);
    int *estart = xcalloc(n + 1, sizeof *estart);        /* explicit revolutes by point id */
    int *ej = xcalloc((size_t)nexplicit, sizeof *ej);
    int *fill = xcalloc(n + 1, sizeof *fill), *parent = xcalloc(total, sizeof *parent);
    if (!start || !carrier || !cpoint || !estart || !ej || !fill || !parent) {
        err(ld, NULL, "out of memory");
        goto done;
    }
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++)
            start[m->links[li].points[p].id + 1]++;
    for (int ji = 0; ji < nexplicit; ji++)
        if (m->joints[ji].kind == MECH_JOINT_REVOLUTE)
            estart[m->links[m->joints[ji].link[0]].points[m->joints[ji].point[0]].id + 1]++;
    for (size_t i = 0; i < n; i++) {
        start[i + 1] += start[i];
        estart[i + 1] += estart[i];
    }
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++) {
            int id = m->links[li].points[p].id, at = start[id] + fill[id]++;
            carrier[at] = li;
            cpoint[at] = p;
        }
    memset(fill, 0, (n + 1) * sizeof *fill);
    for (int ji = 0; ji < nexplicit; ji++)
        if (m->joints[ji].kind == MECH_JOINT_REVOLUTE) {
            int id = m->links[m->joints[ji].link[0]].points[m->joints[ji].point[0]].id;
            ej[estart[id] + fill[id]++] = ji;
        }
    for (size_t id = 0; id < n; id++) {
        int k = start[id + 1] - start[id];
        if (k >= 2)
            pin_carriers(ld, (int)id, carrier + start[id], cpoint + start[id], k,
                         ej + estart[id], estart[id + 1] - estart[id], parent);
    }
done:
    free(start);
    free(carrier);
    free(cpoint);
    free(estart);
    free(ej);
    free(fill);
    free(parent);
}

/* Links need two points, unless a slider carries them (a piston block); a
 * link is held by at most one locked slider. One pass over the joints, with
 * per-link marks, so that many links or sliders stay linear. */
static void check_link_points(loader *ld)
{
    mech_model *m = ld->m;
    int *locked_by = xcalloc((size_t)m->nlinks, sizeof *locked_by); /* 1 + joint, or 0 */
    unsigned char *slides = xcalloc((size_t)m->nlinks, sizeof *slides);
    if (!locked_by || !slides) {
        err(ld, NULL, "out of memory");
        goto done;
    }
    for (int ji = 0; ji < m->njoints; ji++)
        if (m->joints[ji].kind == MECH_JOINT_SLIDER)
            slides[m->joints[ji].link[0]] = 1;
    for (int li = 1; li < m->nlinks; li++) {
        const mech_link *l = &m->links[li];
        if (l->npoints >= 2 || !l->name || ld->link_failed[li] || slides[li])
            continue;
        diag_error(ld->d, ld->file, l->mark,
                   "link '%s' has %d point%s; a link needs at least two (only a slider "
                   "block may have one)", l->name, l->npoints, l->npoints == 1 ? "" : "s");
    }
    for (int ji = 0; ji < m->njoints; ji++) {
        const mech_joint *j = &m->joints[ji];
        if (j->kind != MECH_JOINT_SLIDER || !j->locked)
            continue;
        int first = locked_by[j->link[0]] - 1;
        if (first < 0)
            locked_by[j->link[0]] = ji + 1;
        else
            diag_error(ld->d, ld->file, j->mark,
                       "link '%s' is held by two locked sliders ('%s' and '%s'); make one "
                       "'rotation: free'", m->links[j->link[0]].name, m->joints[first].name,
                       j->name);
    }
done:
    free(locked_by);
    free(slides);
}

/* ---- driver, guesses, branches, loops ------------------------------ */

static int slider_by_name(loader *ld, const ynode *n, const char *what)
{
    const char *name = get_name(ld, n, what);
    if (!name)
        return -1;
    mech_model *m = ld->m;
    int ji = find_joint(ld, name);
    if (ji >= 0 && m->joints[ji].kind == MECH_JOINT_SLIDER)
        return ji;
    if (errors_full(ld))
        return err(ld, n, "unknown slider"), -1;
    const char **names = xcalloc((size_t)m->njoints, sizeof *names);
    size_t k = 0;
    for (int i = 0; names && i < m->njoints; i++)
        if (m->joints[i].kind == MECH_JOINT_SLIDER)
            names[k++] = m->joints[i].name;
    err_unknown(ld, n, "slider", "sliders", name, names, k);
    free(names);
    return -1;
}

static void load_range(loader *ld, const ynode *n, quantity q, mech_driver *dr)
{
    const char *what = q == Q_ANGLE ? "driver angle" : "driver displacement";
    if (n->kind == YNODE_SCALAR || n->kind == YNODE_SEQ) {
        size_t count = n->kind == YNODE_SCALAR ? 1 : n->n;
        if (count == 0 || count > MAX_STEPS)
            return (void)err(ld, n, "%s list must have 1 to %d values", what, MAX_STEPS);
        dr->values = xcalloc(count, sizeof *dr->values);
        if (!dr->values)
            return (void)err(ld, n, "out of memory");
        for (size_t i = 0; i < count; i++) {
            const ynode *v = n->kind == YNODE_SCALAR ? n : n->items[i];
            if (get_quantity(ld, v, q, what, &dr->values[i]))
                dr->nvalues++;
        }
        return;
    }
    static const char *const keys[] = {"from", "to", "steps"};
    check_keys(ld, n, keys, COUNT(keys), what);
    const ynode *from = ymap_get(n, "from"), *to = ymap_get(n, "to"), *steps = ymap_get(n, "steps");
    if (!from || !to || !steps)
        return (void)err(ld, n, "%s range is missing '%s' (write {from: ..., to: ..., steps: N})",
                         what, !from ? "from" : !to ? "to" : "steps");
    double a, b;
    long s;
    int ok = get_quantity(ld, from, q, what, &a);
    ok = get_quantity(ld, to, q, what, &b) && ok;
    ok = get_count(ld, steps, "'steps'", 1, MAX_STEPS, &s) && ok;
    if (!ok)
        return;
    if (!isfinite(b - a))  /* from -1e308 to 1e308: the positions would be inf and NaN */
        return (void)err(ld, n, "%s range is too wide (from %g to %g)", what, a, b);
    dr->values = xcalloc((size_t)s + 1, sizeof *dr->values);
    if (!dr->values)
        return (void)err(ld, n, "out of memory");
    for (long i = 0; i <= s; i++)  /* s intervals, s + 1 positions, both ends included */
        dr->values[i] = a + (b - a) * (double)i / (double)s;
    dr->nvalues = (int)s + 1;
}

static void load_driver(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"link", "slider", "angle", "displacement", "speed",
                                       "acceleration"};
    mech_model *m = ld->m;
    mech_driver *dr = &m->driver;
    if (!check_keys(ld, map, keys, COUNT(keys), "driver"))
        return;
    dr->mark = map->mark;
    const ynode *ln = ymap_get(map, "link"), *sn = ymap_get(map, "slider"),
                *ang = ymap_get(map, "angle"), *disp = ymap_get(map, "displacement"),
                *speed = ymap_get(map, "speed"), *acc = ymap_get(map, "acceleration");
    if (!ln && !sn)
        return (void)err(ld, map, "the driver needs 'link: NAME' (a link turned through "
                                  "'angle') or 'slider: NAME' (a slider moved through "
                                  "'displacement')");
    if (ln && sn) {
        const ynode *kl = key_of(map, "link"), *ks = key_of(map, "slider");
        const ynode *second = kl->mark.line > ks->mark.line ||
                              (kl->mark.line == ks->mark.line && kl->mark.col > ks->mark.col)
                                  ? kl : ks;
        return (void)err(ld, second, "the driver has both 'link' and 'slider'; give one: "
                                     "'link: NAME' to turn a link or 'slider: NAME' to move a "
                                     "slider");
    }
    quantity pos = ln ? Q_ANGLE : Q_LENGTH;
    if (ln) {
        dr->kind = MECH_DRIVE_ANGLE;
        dr->index = find_link_or_report(ld, ln, "driver link");
        if (dr->index == 0)
            return (void)err(ld, ln, "the ground is fixed and cannot be the driver; name the "
                                     "link that the motor turns");
        if (disp) {
            err(ld, key_of(map, "displacement"), "a link driver takes 'angle', not "
                                                 "'displacement' (that is for a slider driver)");
            if (!ang)
                return;
        }
        for (int ji = 0; dr->index > 0 && ji < m->njoints; ji++)
            if (m->joints[ji].kind == MECH_JOINT_SLIDER && m->joints[ji].locked &&
                m->joints[ji].link[0] == dr->index)
                return (void)err(ld, ln, "link '%s' cannot turn (it is held by locked slider "
                                         "'%s'); drive the slider instead",
                                 m->links[dr->index].name, m->joints[ji].name);
    } else {
        dr->kind = MECH_DRIVE_SLIDER;
        dr->index = slider_by_name(ld, sn, "driver slider");
        if (ang) {
            err(ld, key_of(map, "angle"), "a slider driver takes 'displacement', not 'angle' "
                                          "(that is for a link driver)");
            if (!disp)
                return;
        }
    }
    if (dr->index < 0)
        return;
    const ynode *range = ln ? ang : disp;
    if (!range)
        return (void)err(ld, map, "the driver has no '%s' (its range)", ln ? "angle" : "displacement");
    load_range(ld, range, pos, dr);
    dr->speed = 1.0;  /* documented default: 1 rad/s or 1 m/s */
    if (speed)
        get_quantity(ld, speed, ln ? Q_ANGULAR_SPEED : Q_SPEED, "driver speed", &dr->speed);
    if (acc)
        get_quantity(ld, acc, ln ? Q_ANGULAR_ACCELERATION : Q_ACCELERATION, "driver acceleration",
                     &dr->accel);
    m->has_driver = dr->nvalues > 0;
}

static void load_initial(loader *ld, const ynode *map)
{
    mech_model *m = ld->m;
    if (!check_map(ld, map, NULL, 0, "'initial'", "initial guess for"))
        return;
    m->guesses = xcalloc(map->n, sizeof *m->guesses);
    if (!m->guesses)
        return (void)err(ld, map, "out of memory");
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = get_name(ld, k, "initial guess name");
        if (!name || k->dup_of)
            continue;
        mech_guess *g = &m->guesses[m->nguesses];
        g->mark = k->mark;
        int li = find_link(ld, name), ji = find_joint(ld, name);
        if (li == 0)
            err(ld, k, "the ground does not move; it needs no initial guess");
        else if (li > 0 && m->has_driver && m->driver.kind == MECH_DRIVE_ANGLE &&
                 m->driver.index == li)
            err(ld, k, "'%s' is the driver; its angle comes from 'driver'", name);
        else if (li > 0) {
            g->index = li;
            if (get_quantity(ld, v, Q_ANGLE, "initial angle", &g->value))
                m->nguesses++;
        } else if (ji >= 0 && m->joints[ji].kind == MECH_JOINT_SLIDER) {
            g->is_slider = 1;
            g->index = ji;
            if (get_quantity(ld, v, Q_LENGTH, "initial displacement", &g->value))
                m->nguesses++;
        } else if (errors_full(ld)) {
            err(ld, k, "unknown link or slider");
        } else {
            size_t nn = (size_t)m->nlinks + (size_t)m->njoints, c = 0;
            const char **names = xcalloc(nn, sizeof *names);
            for (int j = 1; names && j < m->nlinks; j++)
                names[c++] = m->links[j].name;
            for (int j = 0; names && j < m->njoints; j++)
                if (m->joints[j].kind == MECH_JOINT_SLIDER)
                    names[c++] = m->joints[j].name;
            err_unknown(ld, k, "link or slider", "moving links and sliders", name, names, c);
            free(names);
        }
    }
}

static void load_branches(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!want_kind(ld, seq, YNODE_SEQ, "'branch'"))
        return;
    if (seq->n > MAX_LIST)
        return (void)err(ld, seq, "too many branch conditions (%zu; at most %d)", seq->n,
                         MAX_LIST);
    m->branches = xcalloc(seq->n, sizeof *m->branches);
    if (!m->branches)
        return (void)err(ld, seq, "out of memory");
    for (size_t i = 0; i < seq->n; i++) {
        static const char *const keys[] = {"points", "turn"};
        const ynode *b = seq->items[i];
        if (!check_keys(ld, b, keys, COUNT(keys), "a branch condition"))
            continue;
        const ynode *pts = ymap_get(b, "points"), *turn = ymap_get(b, "turn");
        if (!pts || !turn) {
            err(ld, b, "a branch condition needs 'points: [A, B, C]' and 'turn: ccw' or 'cw'");
            continue;
        }
        mech_branch *br = &m->branches[m->nbranches];
        br->mark = b->mark;
        if (pts->kind != YNODE_SEQ || pts->n != 3) {
            err(ld, pts, "'points' of a branch condition must list three points");
            continue;
        }
        int ok = 1;
        for (int k = 0; k < 3; k++)
            ok = (br->point[k] = find_point_or_report(ld, pts->items[k], "branch point")) >= 0 && ok;
        if (turn->kind == YNODE_SCALAR && strcmp(turn->text, "ccw") == 0)
            br->sign = 1;
        else if (turn->kind == YNODE_SCALAR && strcmp(turn->text, "cw") == 0)
            br->sign = -1;
        else
            ok = 0, err(ld, turn, "'turn' must be 'ccw' (counter-clockwise) or 'cw' (clockwise)");
        if (ok)
            m->nbranches++;
    }
}

/* A loop written as a string: "A B D A", "A-B-D-A" or, when every point name
 * is one character, "ABDA". Splits into a fresh array of names. */
static int split_loop_string(loader *ld, const ynode *n, char ***out, int *count)
{
    const char *s = n->text;
    int spaced = strpbrk(s, " -,") != NULL;
    size_t cap = strlen(s) + 1;
    char **names = xcalloc(cap, sizeof *names);
    if (!names)
        return 0;
    int c = 0;
    while (*s) {
        if (*s == ' ' || *s == '-' || *s == ',') {
            s++;
            continue;
        }
        size_t len = spaced ? strcspn(s, " -,") : 1;
        names[c] = malloc(len + 1);
        if (!names[c])
            break;
        memcpy(names[c], s, len);
        names[c++][len] = '\0';
        s += len;
    }
    (void)ld;
    *out = names;
    *count = c;
    return 1;
}

static void load_loop(loader *ld, const ynode *n, mech_loop *lp)
{
    mech_model *m = ld->m;
    char **names = NULL;
    int count = 0, ok = 1;
    if (n->kind == YNODE_SCALAR) {
        if (!split_loop_string(ld, n, &names, &count))
            return (void)err(ld, n, "out of memory");
    } else if (n->kind != YNODE_SEQ) {
        return (void)err(ld, n, "a loop must be a list of point names [A, B, C, A] or a string \"A B C A\"");
    }
    int len = n->kind == YNODE_SCALAR ? count : (int)n->n;
    if (len > MAX_LOOP_POINTS) {
        for (int i = 0; i < count; i++)
            free(names[i]);
        free(names);
        return (void)err(ld, n, "loop too long (%d points; at most %d)", len, MAX_LOOP_POINTS);
    }
    lp->points = xcalloc((size_t)len, sizeof *lp->points);
    lp->marks = xcalloc((size_t)len, sizeof *lp->marks);
    lp->mark = n->mark;
    for (int i = 0; lp->points && lp->marks && i < len; i++) {
        const ynode *item = n->kind == YNODE_SEQ ? n->items[i] : n;
        const char *name = n->kind == YNODE_SEQ ? get_name(ld, item, "loop point") : names[i];
        lp->marks[i] = item->mark;
        int id = name ? find_point(ld, name) : -1;
        if (name && id < 0 && !ld->links_bad && !ld->points_bad)
            err_unknown(ld, item, "point", "points", name, (const char *const *)m->point_names,
                        (size_t)m->npoint_names);
        ok = ok && id >= 0;
        lp->points[i] = id;
    }
    lp->npoints = len;
    for (int i = 0; i < count; i++)
        free(names[i]);
    free(names);
    if (!ok || !lp->points)
        return;
    if (len < 4)
        err(ld, n, "a loop must visit at least three points and return to the first (e.g. [A, B, C, A])");
    else if (lp->points[0] != lp->points[len - 1])
        diag_error(ld->d, ld->file, lp->marks[len - 1],
                   "loop does not close: it starts at '%s' but ends at '%s' (end it with '%s')",
                   m->point_names[lp->points[0]], m->point_names[lp->points[len - 1]],
                   m->point_names[lp->points[0]]);
}

static void load_loops(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!want_kind(ld, seq, YNODE_SEQ, "'loops'"))
        return;
    if (seq->n > MAX_LOOPS)
        return (void)err(ld, seq, "too many loops listed (%zu; at most %d); leave 'loops' out "
                                  "and they are found automatically", seq->n, MAX_LOOPS);
    m->loops = xcalloc(seq->n, sizeof *m->loops);
    if (!m->loops)
        return (void)err(ld, seq, "out of memory");
    for (size_t i = 0; i < seq->n; i++)
        load_loop(ld, seq->items[i], &m->loops[m->nloops++]);
}

/* ---- loads and outputs --------------------------------------------- */

/* The link a load acts on: `link:` when given, else the only link with the point. */
static int load_target_link(loader *ld, const ynode *map, int point_id, const ynode *pnode)
{
    mech_model *m = ld->m;
    const ynode *ln = ymap_get(map, "link");
    if (ln) {
        int li = find_link_or_report(ld, ln, "loaded link");
        if (li >= 0 && point_id >= 0 && point_in_link(ld, li, point_id) < 0) {
            err(ld, pnode, "link '%s' has no point '%s'", m->links[li].name, pnode->text);
            return -1;
        }
        return li;
    }
    if (point_id < 0)
        return err(ld, map, "this load needs 'link: NAME'"), -1;
    int found = -1, nc = 0, first, end;
    carriers_of(ld, point_id, &first, &end);
    for (int c = first; c < end; c++)
        found = ld->carrier_link[c], nc++;
    if (nc != 1)
        return err(ld, pnode, "point '%s' is on %d links; say which one is loaded with 'link: NAME'",
                   pnode->text, nc), -1;
    return found;
}

static void load_one_load(loader *ld, const ynode *map, mech_load *l)
{
    static const char *const keys[] = {"force", "torque", "distributed", "link", "at",
                                       "from", "to", "direction"};
    if (!check_keys(ld, map, keys, COUNT(keys), "a load"))
        return;
    const ynode *f = ymap_get(map, "force"), *t = ymap_get(map, "torque"),
                *dl = ymap_get(map, "distributed");
    if ((f != NULL) + (t != NULL) + (dl != NULL) != 1)
        return (void)err(ld, map, "a load is exactly one of 'force', 'torque' or 'distributed'");
    l->mark = map->mark;
    int ok = 1;
    if (f) {
        l->kind = MECH_LOAD_FORCE;
        const ynode *at = ymap_get(map, "at");
        if (!at)
            return (void)err(ld, map, "a force needs 'at: POINT'");
        int id = find_point_or_report(ld, at, "load point");
        l->link = load_target_link(ld, map, id, at);
        ok = get_vec2(ld, f, Q_FORCE, "force", l->force) && id >= 0 && l->link >= 0;
        if (ok)
            l->point[0] = point_in_link(ld, l->link, id);
    } else if (t) {
        l->kind = MECH_LOAD_TORQUE;
        l->link = load_target_link(ld, map, -1, NULL);
        ok = get_quantity(ld, t, Q_TORQUE, "torque", &l->torque) && l->link >= 0;
    } else {
        l->kind = MECH_LOAD_DISTRIBUTED;
        const ynode *from = ymap_get(map, "from"), *to = ymap_get(map, "to"),
                    *dir = ymap_get(map, "direction");
        if (!from || !to)
            return (void)err(ld, map, "a distributed load needs 'from: POINT' and 'to: POINT'");
        int a = find_point_or_report(ld, from, "load start"), b = find_point_or_report(ld, to, "load end");
        l->link = load_target_link(ld, map, a, from);
        ok = get_quantity(ld, dl, Q_FORCE_PER_LENGTH, "distributed load", &l->intensity);
        l->direction = -1.57079632679489661923;  /* default: downwards (-90 deg) */
        if (dir)
            ok = get_quantity(ld, dir, Q_ANGLE, "load direction", &l->direction) && ok;
        if (ok && a >= 0 && b >= 0 && l->link >= 0) {
            l->point[0] = point_in_link(ld, l->link, a);
            l->point[1] = point_in_link(ld, l->link, b);
            if (l->point[1] < 0)
                ok = 0, err(ld, to, "link '%s' has no point '%s'", ld->m->links[l->link].name, to->text);
        } else {
            ok = 0;
        }
    }
    if (ok && l->link == 0)
        ok = 0, err(ld, map, "a load on the ground does nothing; put it on a moving link");
    if (ok)
        ld->m->nloads++;
}

static void load_loads(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!want_kind(ld, seq, YNODE_SEQ, "'loads'"))
        return;
    if (seq->n > MAX_LOADS)
        return (void)err(ld, seq, "too many loads (%zu; at most %d)", seq->n, MAX_LOADS);
    m->loads = xcalloc(seq->n, sizeof *m->loads);
    if (!m->loads)
        return (void)err(ld, seq, "out of memory");
    for (size_t i = 0; i < seq->n; i++)
        load_one_load(ld, seq->items[i], &m->loads[m->nloads]);
}

typedef int (*resolve_fn)(loader *ld, const ynode *n);

static int resolve_point(loader *ld, const ynode *n) { return find_point_or_report(ld, n, "output point"); }
static int resolve_link(loader *ld, const ynode *n) { return find_link_or_report(ld, n, "output link"); }
static int resolve_slider(loader *ld, const ynode *n) { return slider_by_name(ld, n, "output slider"); }

static void load_name_list(loader *ld, const ynode *seq, const char *what, resolve_fn fn,
                           int **out, int *count)
{
    if (!want_kind(ld, seq, YNODE_SEQ, what))
        return;
    if (seq->n > MAX_LIST)
        return (void)err(ld, seq, "too many %s (%zu; at most %d)", what, seq->n, MAX_LIST);
    *out = xcalloc(seq->n, sizeof **out);
    if (!*out)
        return (void)err(ld, seq, "out of memory");
    for (size_t i = 0; i < seq->n; i++) {
        int v = fn(ld, seq->items[i]);
        if (v >= 0)
            (*out)[(*count)++] = v;
    }
}

static void default_outputs(mech_model *m)
{
    mech_outputs *o = &m->outputs;
    o->points = xcalloc((size_t)m->npoint_names, sizeof *o->points);
    o->links = xcalloc((size_t)m->nlinks, sizeof *o->links);
    o->sliders = xcalloc((size_t)m->njoints, sizeof *o->sliders);
    if (!o->points || !o->links || !o->sliders)
        return;
    for (int i = 0; i < m->npoint_names; i++)
        o->points[o->npoints++] = i;
    for (int i = 1; i < m->nlinks; i++)
        o->links[o->nlinks++] = i;
    for (int i = 0; i < m->njoints; i++)
        if (m->joints[i].kind == MECH_JOINT_SLIDER)
            o->sliders[o->nsliders++] = i;
}

static void load_outputs(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"points", "links", "sliders", "forces"};
    mech_outputs *o = &ld->m->outputs;
    if (!check_keys(ld, map, keys, COUNT(keys), "outputs"))
        return;
    const ynode *p = ymap_get(map, "points"), *l = ymap_get(map, "links"),
                *s = ymap_get(map, "sliders"), *f = ymap_get(map, "forces");
    if (p)
        load_name_list(ld, p, "'points'", resolve_point, &o->points, &o->npoints);
    if (l)
        load_name_list(ld, l, "'links'", resolve_link, &o->links, &o->nlinks);
    if (s)
        load_name_list(ld, s, "'sliders'", resolve_slider, &o->sliders, &o->nsliders);
    if (f)
        get_bool(ld, f, "'forces'", &o->forces);
}

/* ---- the document -------------------------------------------------- */

static void load_document(loader *ld, const ynode *root)
{
    static const char *const keys[] = {"name", "description", "units", "parameters", "gravity",
                                       "ground", "links", "joints", "driver", "initial",
                                       "branch", "loops", "loads", "outputs"};
    mech_model *m = ld->m;
    if (!check_keys(ld, root, keys, COUNT(keys), "the mechanism"))
        return;
    const ynode *v;
    static const char *const required[] = {"name", "ground", "links", "driver"};
    for (size_t i = 0; i < COUNT(required); i++)
        if (!ymap_get(root, required[i]) && !misspelt(root, required[i], keys, COUNT(keys)))
            err(ld, root, "missing '%s' (a mechanism file needs name, ground, links and driver)",
                required[i]);
    if ((v = ymap_get(root, "name")))
        m->name = get_string(ld, v, "'name'", 200);
    if ((v = ymap_get(root, "description")))
        m->description = get_string(ld, v, "'description'", 4000);
    if ((v = ymap_get(root, "units")))
        load_units(ld, v);
    if ((v = ymap_get(root, "parameters")))
        load_parameters(ld, v);
    if ((v = ymap_get(root, "gravity")))
        get_vec2(ld, v, Q_ACCELERATION, "gravity", m->gravity);
    const ynode *links = ymap_get(root, "links");
    size_t nlinks = 1 + (links && links->kind == YNODE_MAP ? links->n : 0);
    m->links = xcalloc(nlinks, sizeof *m->links);
    ld->link_failed = xcalloc(nlinks, sizeof *ld->link_failed);
    if (!m->links || !ld->link_failed)
        return (void)err(ld, root, "out of memory");
    m->nlinks = 1;
    if ((v = ymap_get(root, "ground")))
        load_ground(ld, v);
    else
        load_ground(ld, NULL);
    if (links)
        load_links(ld, links);
    else
        ld->links_bad = 1;
    index_carriers(ld);
    if ((v = ymap_get(root, "joints")))
        load_joints(ld, v);
    add_implicit_revolutes(ld);
    check_link_points(ld);
    if ((v = ymap_get(root, "driver")))
        load_driver(ld, v);
    if ((v = ymap_get(root, "initial")))
        load_initial(ld, v);
    if ((v = ymap_get(root, "branch")))
        load_branches(ld, v);
    if ((v = ymap_get(root, "loops")))
        load_loops(ld, v);
    if ((v = ymap_get(root, "loads")))
        load_loads(ld, v);
    if ((v = ymap_get(root, "outputs")))
        load_outputs(ld, v);
    else
        default_outputs(m);
}

static int load_string_with(const char *text, size_t len, const char *name,
                            const mech_override *ov, int nov, mech_model **out, mech_diag *d);

int mech_load_string(const char *text, size_t len, const char *name, mech_model **out,
                     mech_diag *d)
{
    return load_string_with(text, len, name, NULL, 0, out, d);
}

/* Overrides naming no parameter of the file. */
static void unused_overrides(loader *ld)
{
    for (int o = 0; o < ld->nov; o++)
        if (!ld->ov_used[o])
            diag_error(ld->d, ld->file, (mech_mark){0, 0},
                       "no parameter '%s' in the file's 'parameters:' to replace",
                       ld->ov[o].name);
}

static int load_string_with(const char *text, size_t len, const char *name,
                            const mech_override *ov, int nov, mech_model **out, mech_diag *d)
{
    *out = NULL;
    size_t errors_before = d->nerrors;
    ynode *root = ytree_parse(text, len, name, NULL, d);
    if (!root)
        return MECH_EINPUT;
    loader ld = {0};
    ld.file = name;
    ld.d = d;
    ld.ov = ov;
    ld.nov = nov;
    unsigned char used[64] = {0};
    ld.ov_used = used;
    if (nov > 64) {
        ytree_free(root);
        return diag_error(d, name, (mech_mark){0, 0}, "at most 64 parameter replacements");
    }
    ld.m = xcalloc(1, sizeof *ld.m);
    unit_defaults_init(&ld.units);
    ld.env.units = &ld.units;
    if (!ld.m) {
        ytree_free(root);
        return diag_error(d, name, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    }
    ld.m->file = xstrdup(name);
    if (root->kind != YNODE_MAP)
        err(&ld, root, "a mechanism file must be a mapping of keys ('name:', 'ground:', "
                       "'links:', 'driver:', ...), not %s", ynode_kind_name(root->kind));
    else
        load_document(&ld, root);
    unused_overrides(&ld);
    ytree_free(root);
    free(ld.params);
    free(ld.link_failed);
    name_map_free(&ld.bad_params);
    name_map_free(&ld.param_map);
    name_map_free(&ld.next_suffix);
    free(ld.carrier_start);
    free(ld.carrier_link);
    free(ld.carrier_point);
    name_map_free(&ld.point_map);
    name_map_free(&ld.link_map);
    name_map_free(&ld.joint_map);
    if (d->nerrors > errors_before) {
        mech_model_free(&ld.m);
        return MECH_EINPUT;
    }
    *out = ld.m;
    return MECH_OK;
}

/* Read a whole file into memory, refusing more than `max` bytes. */
static char *read_file(const char *path, size_t max, size_t *len, mech_diag *d, int *rc)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        *rc = MECH_EIO;
        char ebuf[128];
        diag_error(d, path, (mech_mark){0, 0}, "cannot open: %s",
                   diag_strerror(errno, ebuf, sizeof ebuf));
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap)
            break;  /* end of file or error */
        if (cap > max)
            break;
        char *bigger = realloc(buf, 2 * cap);
        if (!bigger) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = bigger;
        cap *= 2;
    }
    int failed = ferror(f);
    fclose(f);
    *rc = MECH_OK;
    if (!buf) {
        *rc = MECH_ENOMEM;
        diag_error(d, path, (mech_mark){0, 0}, "out of memory");
    } else if (failed) {
        *rc = MECH_EIO;
        diag_error(d, path, (mech_mark){0, 0}, "read error");
    } else if (n > max) {
        *rc = MECH_EINPUT;
        diag_error(d, path, (mech_mark){0, 0}, "file too large (more than %zu bytes)", max);
    }
    if (*rc != MECH_OK) {
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

int mech_load_file(const char *path, mech_model **out, mech_diag *d)
{
    *out = NULL;
    size_t len = 0;
    int rc;
    char *buf = read_file(path, yaml_default_limits.max_bytes, &len, d, &rc);
    if (!buf)
        return rc;
    rc = mech_load_string(buf, len, path, out, d);
    free(buf);
    return rc;
}

int mech_load_file_with(const char *path, const mech_override *ov, int nov, mech_model **out,
                        mech_diag *d)
{
    *out = NULL;
    size_t len = 0;
    int rc;
    char *buf = read_file(path, yaml_default_limits.max_bytes, &len, d, &rc);
    if (!buf)
        return rc;
    rc = load_string_with(buf, len, path, ov, nov, out, d);
    free(buf);
    return rc;
}
