/* src/load/load_tree.c: the loader's shared walking of the YAML tree: errors
 * with the node's file:line:col, shape checks of mappings (unknown keys,
 * typos, duplicates), reading names, strings, quantities, counts, booleans
 * and [x, y] pairs, and looking up links, points and sliders by name with a
 * "did you mean" when the name is unknown. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* The links carrying point `id`: carrier_link[*first .. *end - 1]; empty
 * without the index. Joints and loads name points of links; looking them up
 * here keeps a file with 10^6 ground points and many joints linear. */
void load_carriers_of(const loader *ld, int id, int *first, int *end)
{
    *first = *end = 0;
    if (id >= 0 && id < ld->carrier_ids) {
        *first = ld->carrier_start[id];
        *end = ld->carrier_start[id + 1];
    }
}

/* Index of point `id` in link `li`, or -1 (binary search among the carriers). */
int load_point_in_link(const loader *ld, int li, int id)
{
    if (ld->carrier_ids == 0)
        return model_point_in_link(&ld->m->links[li], id);
    int lo, end;
    load_carriers_of(ld, id, &lo, &end);
    for (int hi = end; lo < hi;) {
        int mid = lo + (hi - lo) / 2;
        if (ld->carrier_link[mid] < li)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < end && ld->carrier_link[lo] == li ? ld->carrier_point[lo] : -1;
}

/* Offset of the first control character (a byte below 0x20 or 0x7f) in
 * s[0..len-1] other than those in `allowed`, or -1. */
static long control_char(const char *s, size_t len, const char *allowed)
{
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)s[i];
        if ((c < 0x20 || c == 0x7f) && !(c && strchr(allowed, c)))
            return (long)i;
    }
    return -1;
}

/* The message quotes names and text from the file: its control characters
 * are written \xNN, so that it stays one printable line. */
int load_err(loader *ld, const ynode *n, const char *fmt, ...)
{
    char buf[900], out[4 * sizeof buf];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    size_t k = 0;
    for (const char *s = buf; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c < 0x20 || c == 0x7f)
            k += (size_t)snprintf(out + k, sizeof out - k, "\\x%02x", c);
        else
            out[k++] = (char)c;
    }
    out[k] = '\0';
    return diag_error(ld->d, ld->file, n ? n->mark : (mech_mark){0, 0}, "%s", out);
}

int load_nomem(loader *ld, const ynode *n)
{
    return diag_nomem(ld->d, ld->file, n ? n->mark : (mech_mark){0, 0});
}

/* ---- shape checks -------------------------------------------------- */

int load_want_kind(loader *ld, const ynode *n, ynode_kind kind, const char *what)
{
    if (n->kind == kind)
        return 1;
    load_err(ld, n, "%s must be %s, not %s", what, ynode_kind_name(kind), ynode_kind_name(n->kind));
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
int load_check_map(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                   const char *where, const char *noun)
{
    if (!load_want_kind(ld, map, YNODE_MAP, where ? where : noun))
        return 0;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i];
        if (k->kind != YNODE_SCALAR) {
            if (!noun)  /* else the caller reports it as an invalid name */
                load_err(ld, k, "a key in %s must be a plain name", where);
            continue;
        }
        const ynode *o = k->dup_of;  /* found by yamltree.c */
        if (o && noun)
            load_err(ld, k, "duplicate %s '%s'%s%s (first given at line %d)", noun, k->text,
                     where ? " in " : "", where ? where : "", o->mark.line);
        else if (o)
            load_err(ld, k, "duplicate key '%s' in %s (first given at line %d)", k->text, where,
                     o->mark.line);
        if (!allowed || is_allowed(k->text, allowed, nallowed))
            continue;
        const char *near = nearest_name(k->text, allowed, nallowed);
        if (near) {
            load_err(ld, k, "unknown key '%s' in %s (did you mean '%s'?)", k->text, where, near);
            continue;
        }
        char list[400];
        size_t n = 0;
        list[0] = '\0';
        for (size_t a = 0; a < nallowed && n < sizeof list; a++)
            n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", a ? ", " : "", allowed[a]);
        load_err(ld, k, "unknown key '%s' in %s (expected %s%s)", k->text, where,
                 nallowed == 1 ? "" : "one of: ", list);
    }
    return 1;
}

int load_check_keys(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                    const char *where)
{
    return load_check_map(ld, map, allowed, nallowed, where, NULL);
}

/* A key of `map` that is not allowed but is a likely typo of `key` (already
 * reported as such): then `key` is not "missing" as well. */
int load_misspelt(const ynode *map, const char *key, const char *const *allowed,
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
const ynode *load_key_of(const ynode *map, const char *key)
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
int load_uses_bad_param(const loader *ld, const char *text)
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

int load_valid_name(const char *s)
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
const char *load_get_name(loader *ld, const ynode *n, const char *what)
{
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
        return NULL;
    if (strlen(n->text) > MAX_NAME) {
        load_err(ld, n, "%s is too long (%zu characters; at most %d)", what, strlen(n->text),
                 MAX_NAME);
        return NULL;
    }
    long at = control_char(n->text, n->len, "");
    if (at >= 0) {
        load_err(ld, n, "%s '%s' contains a control character (byte 0x%02x at character %ld); "
                        "use letters, digits and '_', starting with a letter", what, n->text,
                 (unsigned char)n->text[at], at + 1);
        return NULL;
    }
    if (!load_valid_name(n->text)) {
        load_err(ld, n, "%s '%s' is not a valid name (use letters, digits and '_', starting with a letter)",
                 what, n->text);
        return NULL;
    }
    return n->text;
}

/* A text of at most `max` bytes, without control characters (they would
 * reach the terminal, SVG and LaTeX as they are) except line breaks and
 * tabs when `lines`. */
char *load_get_string(loader *ld, const ynode *n, const char *what, size_t max, int lines)
{
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
        return NULL;
    if (n->len > max) {
        load_err(ld, n, "%s is too long (at most %zu characters)", what, max);
        return NULL;
    }
    long at = control_char(n->text, n->len, lines ? "\n\t" : "");
    if (at >= 0) {
        load_err(ld, n, "%s contains a control character (byte 0x%02x at character %ld); "
                        "write %sprintable characters only", what, (unsigned char)n->text[at],
                 at + 1, lines ? "" : "one line of ");
        return NULL;
    }
    return xstrdup(n->text);
}

/* Evaluate a quantity; the error points into the scalar where it can. */
int load_get_quantity(loader *ld, const ynode *n, quantity q, const char *what, double *out)
{
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
        return 0;
    char msg[256];
    size_t pos = 0;
    if (quantity_eval(n->text, q, &ld->env, out, msg, sizeof msg, &pos) == 0)
        return 1;
    if (load_uses_bad_param(ld, n->text))
        return 0;
    mech_mark at = n->mark;
    if (!strchr(n->text, '\n'))
        at.col += (int)pos + (n->quoted ? 1 : 0);
    diag_error(ld->d, ld->file, at, "%s: %s", what, msg);
    return 0;
}

int load_get_quantity_expr(loader *ld, const ynode *n, quantity q, const char *what,
                           double *out, int *root)
{
    *root = PX_FIXED;
    ld->env.record = ld->m->pexpr;
    ld->env.root = root;
    int ok = load_get_quantity(ld, n, q, what, out);
    ld->env.record = NULL;
    ld->env.root = NULL;
    return ok;
}

int load_get_vec2_expr(loader *ld, const ynode *n, quantity q, const char *what, double out[2],
                       int root[2])
{
    root[0] = root[1] = PX_FIXED;
    if (n->kind != YNODE_SEQ || n->n != 2)
        return load_get_vec2(ld, n, q, what, out);  /* reports the shape */
    int ok = load_get_quantity_expr(ld, n->items[0], q, what, &out[0], &root[0]);
    return load_get_quantity_expr(ld, n->items[1], q, what, &out[1], &root[1]) && ok;
}

pxq load_expr(loader *ld, px_op op, double k, pxq a, pxq b, pxq c, double value)
{
    if (!ld->m->pexpr)
        return pxq_fixed(value);
    return pexpr_make(ld->m->pexpr, op, k, a, b, c, value);
}

int load_get_count(loader *ld, const ynode *n, const char *what, long lo, long hi, long *out)
{
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
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
            load_err(ld, n, "%s must be between %ld and %ld, not %s", what, lo, hi, n->text);
        else if (whole)
            load_err(ld, n, "%s must be written with digits only, not '%s'", what, n->text);
        else
            load_err(ld, n, "%s must be a whole number, not '%s'", what, n->text);
        return 0;
    }
    if (v < lo || v > hi) {
        load_err(ld, n, "%s must be between %ld and %ld, not %ld", what, lo, hi, v);
        return 0;
    }
    *out = v;
    return 1;
}

int load_get_bool(loader *ld, const ynode *n, const char *what, int *out)
{
    static const char *const yes[] = {"true", "yes", "on"}, *const no[] = {"false", "no", "off"};
    if (!load_want_kind(ld, n, YNODE_SCALAR, what))
        return 0;
    for (size_t i = 0; i < 3; i++) {
        if (strcmp(n->text, yes[i]) == 0)
            return *out = 1, 1;
        if (strcmp(n->text, no[i]) == 0)
            return *out = 0, 1;
    }
    load_err(ld, n, "%s must be true or false, not '%s'", what, n->text);
    return 0;
}

/* Parentheses a scalar opens and does not close (< 0: closes more). */
static int open_parens(const ynode *n)
{
    int depth = 0;
    for (const char *c = n->kind == YNODE_SCALAR ? n->text : ""; *c; c++)
        depth += *c == '(' ? 1 : *c == ')' ? -1 : 0;
    return depth;
}

/* A flow list's commas split an unquoted expression such as min(a, b):
 * the items from the first that opens a parenthesis it does not close to
 * the one that closes it, joined again into "min(a, b)" in buf; 0 when
 * no item opens one. */
static int split_expression(const ynode *n, char *buf, size_t size)
{
    size_t i = 0;
    while (i < n->n && open_parens(n->items[i]) <= 0)
        i++;
    if (i == n->n)
        return 0;
    size_t len = 0;
    buf[0] = '\0';
    for (int depth = 0; i < n->n && len + 1 < size; i++) {
        int k = snprintf(buf + len, size - len, "%s%s", len ? ", " : "",
                         n->items[i]->kind == YNODE_SCALAR ? n->items[i]->text : "...");
        len += k > 0 ? (size_t)k : 0;
        if ((depth += open_parens(n->items[i])) <= 0)
            break;
    }
    return 1;
}

int load_get_vec2(loader *ld, const ynode *n, quantity q, const char *what, double out[2])
{
    if (n->kind != YNODE_SEQ) {
        load_err(ld, n, "%s must be a list of two values [x, y], not %s", what,
                 ynode_kind_name(n->kind));
        return 0;
    }
    char expr[200];
    if (n->n != 2 && split_expression(n, expr, sizeof expr)) {
        load_err(ld, n, "%s must be a list of two values [x, y], not of %zu: the commas of "
                 "an expression split it; quote it: '%s'", what, n->n, expr);
        return 0;
    }
    if (n->n != 2) {
        load_err(ld, n, "%s must be a list of two values [x, y], not of %zu", what, n->n);
        return 0;
    }
    int ok = load_get_quantity(ld, n->items[0], q, what, &out[0]);
    return load_get_quantity(ld, n->items[1], q, what, &out[1]) && ok;
}

/* Past the cap on errors, a message is only counted: do not spend time on it. */
int load_errors_full(const loader *ld)
{
    return ld->d->nerrors >= (ld->d->max_errors ? ld->d->max_errors : 100);
}

/* Report a name that is not among the candidates: say the nearest one, or
 * list them all when there are few (`kinds` is the plural of `kind`). */
void load_err_unknown(loader *ld, const ynode *n, const char *kind, const char *kinds,
                      const char *name, const char *const *cands, size_t ncands)
{
    /* Suggestions cost an edit distance per candidate: not among 10^5 links,
     * nor for messages past the cap, which are only counted */
    if (load_errors_full(ld))
        return (void)load_err(ld, n, "unknown %s '%s'", kind, name);
    const char *near = ncands <= MAX_SUGGEST ? nearest_name(name, cands, ncands) : NULL;
    if (near)
        return (void)load_err(ld, n, "unknown %s '%s' (did you mean '%s'?)", kind, name, near);
    if (ncands == 0)
        return (void)load_err(ld, n, "unknown %s '%s' (there are no %s)", kind, name, kinds);
    if (ncands > 12)
        return (void)load_err(ld, n, "unknown %s '%s'", kind, name);
    char list[12 * (MAX_NAME + 2) + 1];
    size_t len = 0;
    list[0] = '\0';
    for (size_t i = 0; i < ncands && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", cands[i]);
    load_err(ld, n, "unknown %s '%s' (the %s are: %s)", kind, name, kinds, list);
}

int load_find_link_or_report(loader *ld, const ynode *n, const char *what)
{
    const char *name = load_get_name(ld, n, what);
    if (!name)
        return -1;
    int li = find_link(ld, name);
    if (li >= 0 || ld->links_bad)
        return li;
    if (load_errors_full(ld))
        return load_err(ld, n, "unknown link"), -1;
    const char **names = xcalloc((size_t)ld->m->nlinks, sizeof *names);
    size_t known = 0;  /* a link whose name ran out of memory has none */
    for (int i = 0; names && i < ld->m->nlinks; i++)
        if (ld->m->links[i].name)
            names[known++] = ld->m->links[i].name;
    load_err_unknown(ld, n, "link", "links", name, names, known);
    free(names);
    return -1;
}

int load_find_point_or_report(loader *ld, const ynode *n, const char *what)
{
    const char *name = load_get_name(ld, n, what);
    if (!name)
        return -1;
    int id = find_point(ld, name);
    if (id < 0 && !ld->links_bad && !ld->points_bad)
        load_err_unknown(ld, n, "point", "points", name, (const char *const *)ld->m->point_names,
                         (size_t)ld->m->npoint_names);
    return id;
}

int load_slider_by_name(loader *ld, const ynode *n, const char *what)
{
    const char *name = load_get_name(ld, n, what);
    if (!name)
        return -1;
    mech_model *m = ld->m;
    int ji = find_joint(ld, name);
    if (ji >= 0 && m->joints[ji].kind == MECH_JOINT_SLIDER)
        return ji;
    if (load_errors_full(ld))
        return load_err(ld, n, "unknown slider"), -1;
    const char **names = xcalloc((size_t)m->njoints, sizeof *names);
    size_t k = 0;
    for (int i = 0; names && i < m->njoints; i++)
        if (m->joints[i].kind == MECH_JOINT_SLIDER)
            names[k++] = m->joints[i].name;
    load_err_unknown(ld, n, "slider", "sliders", name, names, k);
    free(names);
    return -1;
}

int load_end_candidates(loader *ld, const ynode *links, int k, int id, const ynode *pnode,
                        const char *what, int *cand, int max)
{
    if (links) {
        int li = load_find_link_or_report(ld, links->items[k], what);
        if (li < 0)
            return -1;
        if (load_point_in_link(ld, li, id) < 0)
            return load_err(ld, pnode, "link '%s' has no point '%s'", ld->m->links[li].name,
                            pnode->text), -1;
        cand[0] = li;
        return 1;
    }
    int first, end, n = 0;
    load_carriers_of(ld, id, &first, &end);
    for (int c = first; c < end && n < max; c++)
        cand[n++] = ld->carrier_link[c];
    return n;
}
