/* src/load/load_fit.c: the loader's `fit:` section, mech fit's problem as the
 * file states it (docs/synthesis.md, docs/format.md section 13):
 *
 *   fit:
 *     free:                      # parameters to fit: bounds [LO, HI], or ~
 *       r: [15 mm, 25 mm]
 *       l: ~
 *     target: targets.csv        # relative to this file's folder
 *     columns: [P.x, P.y]        # default: every column after the first
 *     weights: {P.y: 2}          # default 1
 *     starts: 16
 *     whole-range: true          # the solution assembles over the driver's range
 *     free-timing: true          # each target's driver position an unknown too
 *     constraints:               # inequalities on the parameters, kept by the fit
 *       - "r + d <= l + b"
 *     transmission: {links: [coupler, rocker], min: 30 deg}
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "load.h"

void model_fit_free_all(model_fit *f)
{
    if (!f)
        return;
    for (int k = 0; k < f->nfree; k++)
        free(f->free[k].name);
    free(f->free);
    free(f->target);
    for (int j = 0; j < f->ncolumns; j++)
        free(f->columns[j]);
    free(f->columns);
    free(f->weights);
    for (int c = 0; c < f->ncons; c++)
        free(f->cons[c].text);
    free(f->cons);
    free(f->trans_a);
    free(f->trans_b);
    free(f);
}

/* One bound of parameter k: a quantity of its dimension (a bare number only
 * for a bare parameter). */
static int bound(loader *ld, const ynode *n, int k, double *out)
{
    const mech_param *p = &ld->m->params[k];
    if (!load_want_kind(ld, n, YNODE_SCALAR, "a bound"))
        return -1;
    expr_param q = {0};
    char msg[256];
    size_t pos = 0;
    if (quantity_eval_param(n->text, &ld->env, &q, msg, sizeof msg, &pos) < 0)
        return load_err(ld, n, "bound of '%s': %s", p->name, msg), -1;
    char du[32] = "";
    if (!q.bare)
        dim_format(q.d, du, sizeof du);
    if (q.bare != (p->unit[0] == '\0') || strcmp(du, p->unit) != 0)
        return load_err(ld, n, "bound of '%s' must be %s%s, as the parameter", p->name,
                        p->unit[0] ? "a quantity in " : "a bare number",
                        p->unit), -1;
    *out = q.value;
    return 0;
}

static void free_params(loader *ld, model_fit *f, const ynode *map)
{
    if (!load_check_map(ld, map, NULL, 0, "'fit: free'", "parameter"))
        return;
    f->free = xcalloc(map->n + 1, sizeof *f->free);
    if (!f->free)
        return (void)load_nomem(ld, map);
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        int found = -1;
        for (int p = 0; p < ld->m->nparams; p++)
            if (strcmp(ld->m->params[p].name, k->text) == 0)
                found = p;
        if (found < 0) {
            load_err(ld, k, "fit: '%s' is not one of the file's parameters", k->text);
            continue;
        }
        model_fit_free *fr = &f->free[f->nfree];
        fr->lo = -INFINITY;
        fr->hi = INFINITY;
        fr->mark = k->mark;
        if (!(v->kind == YNODE_SCALAR && (strcmp(v->text, "~") == 0 || v->len == 0 ||
                                          strcmp(v->text, "null") == 0))) {
            if (v->kind != YNODE_SEQ || v->n != 2) {
                load_err(ld, v, "fit: the bounds of '%s' are [LO, HI] (or ~ for none)", k->text);
                continue;
            }
            if (bound(ld, v->items[0], found, &fr->lo) < 0 ||
                bound(ld, v->items[1], found, &fr->hi) < 0)
                continue;
            if (!(fr->lo < fr->hi)) {
                load_err(ld, v, "fit: the bounds of '%s' are empty (LO must be below HI)",
                         k->text);
                continue;
            }
            double x = ld->m->params[found].value;
            if (ld->nov == 0 && (x < fr->lo || x > fr->hi)) {  /* mech fit's trials replace it */
                load_err(ld, v, "fit: the bounds of '%s' exclude its value (the first start)",
                         k->text);
                continue;
            }
        }
        if (!(fr->name = xstrdup(k->text)))
            return (void)load_nomem(ld, k);
        f->nfree++;
    }
}

static void columns(loader *ld, model_fit *f, const ynode *seq)
{
    if (!load_want_kind(ld, seq, YNODE_SEQ, "a list of target columns"))
        return;
    f->columns = xcalloc(seq->n + 1, sizeof *f->columns);
    f->weights = xcalloc(seq->n + 1, sizeof *f->weights);
    if (!f->columns || !f->weights)
        return (void)load_nomem(ld, seq);
    for (size_t i = 0; i < seq->n; i++) {
        char *c = load_get_string(ld, seq->items[i], "a target column", 200, 0);
        if (!c)
            continue;
        f->weights[f->ncolumns] = 1.0;
        f->columns[f->ncolumns++] = c;
    }
}

static void weights(loader *ld, model_fit *f, const ynode *map)
{
    if (!load_check_map(ld, map, NULL, 0, "'fit: weights'", "target column"))
        return;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        char *end = NULL;
        double w = v->kind == YNODE_SCALAR ? strtod(v->text, &end) : NAN;
        if (!end || *end || !(w >= 0.0) || !isfinite(w)) {
            load_err(ld, v, "fit: the weight of '%s' must be a number >= 0", k->text);
            continue;
        }
        int found = 0;
        for (int j = 0; j < f->ncolumns; j++)
            if (strcmp(f->columns[j], k->text) == 0) {
                f->weights[j] = w;
                found = 1;
            }
        if (!found)
            load_err(ld, k, "fit: weight of '%s', which is not in 'columns' (list the "
                     "target columns to weigh them)", k->text);
    }
}

/* The comparison of a constraint: its one "<=" or ">=" (or "<", ">"), at
 * *at with length *len; 1 when the smaller side is the left. 0: none, or
 * more than one (-1). */
static int comparison(const char *t, size_t *at, size_t *len, int *left_smaller)
{
    int found = 0;
    for (size_t i = 0; t[i]; i++) {
        if (t[i] != '<' && t[i] != '>')
            continue;
        if (found) {
            *at = i;
            return -1;
        }
        found = 1;
        *at = i;
        *left_smaller = t[i] == '<';
        *len = t[i + 1] == '=' ? 2 : 1;
        i += *len - 1;
    }
    return found;
}

/* One constraint "LEFT <= RIGHT" (or >=): g = smaller - larger, parsed as
 * the one quantity expression "(smaller) - (larger)", so that the
 * parser's own rules hold (a bare number takes the other side's unit; two
 * dimensions are "cannot subtract"), and recorded over the parameters:
 * its handle gives dg/dp exactly (param_expr.c). An error is placed at the
 * column of the text where it is. */
static void constraint(loader *ld, model_fit *f, const ynode *n)
{
    if (!load_want_kind(ld, n, YNODE_SCALAR, "a constraint (\"EXPR <= EXPR\")"))
        return;
    const char *t = n->text;
    size_t at = 0, len = 0, tl = strlen(t);
    int left_smaller = 1, cmp = comparison(t, &at, &len, &left_smaller);
    mech_mark mk = n->mark;
    int inline_text = !strchr(t, '\n');
    if (cmp <= 0) {
        if (cmp < 0 && inline_text)
            mk.col += (int)at + (n->quoted ? 1 : 0);
        diag_error(ld->d, ld->file, mk, "fit: constraint '%s' %s: write one inequality, "
                   "\"EXPR <= EXPR\" or \"EXPR >= EXPR\"", t, cmp < 0 ? "has more than one "
                   "comparison" : "is not an inequality");
        return;
    }
    const char *small = left_smaller ? t : t + at + len, *large = left_smaller ? t + at + len : t;
    size_t ns = left_smaller ? at : tl - at - len, nl = left_smaller ? tl - at - len : at;
    size_t off_s = (size_t)(small - t), off_l = (size_t)(large - t);
    char *text = xcalloc(ns + nl + 8, 1);
    if (!text)
        return (void)load_nomem(ld, n);
    /* "(" small ")-(" large ")": small at 1, large at ns + 4 */
    snprintf(text, ns + nl + 8, "(%.*s)-(%.*s)", (int)ns, small, (int)nl, large);
    expr_env rec = ld->env;
    rec.record = ld->m->pexpr;
    expr_param g = {0}, side = {0};
    char msg[256];
    size_t pos = 0;
    int rc = quantity_eval_param(text, &rec, &g, msg, sizeof msg, &pos);
    if (rc < 0) {
        size_t col = pos < 1 ? 0 : pos < ns + 1 ? off_s + pos - 1
                   : pos < ns + 4 ? at
                   : pos < ns + nl + 4 ? off_l + pos - ns - 4 : tl;
        if (inline_text)
            mk.col += (int)col + (n->quoted ? 1 : 0);
        diag_error(ld->d, ld->file, mk, "fit: constraint '%s': %s%s", t, msg,
                   strstr(msg, "cannot") ? " (both sides of a constraint must be quantities "
                   "of one dimension)" : "");
        free(text);
        return;
    }
    model_fit_con *c = &f->cons[f->ncons];
    c->g = g.value;
    c->h = g.root;
    c->unit[0] = '\0';
    if (!g.bare)
        dim_format(g.d, c->unit, sizeof c->unit);
    if (strcmp(c->unit, "-") == 0 || strcmp(c->unit, "1") == 0)
        c->unit[0] = '\0';
    /* the sides' sizes (not recorded) */
    c->scale = 0.0;
    for (int k = 0; k < 2; k++) {
        snprintf(text, ns + nl + 8, "%.*s", k ? (int)nl : (int)ns, k ? large : small);
        if (quantity_eval_param(text, &ld->env, &side, msg, sizeof msg, &pos) == 0 &&
            fabs(side.value) > c->scale)
            c->scale = fabs(side.value);
    }
    free(text);
    c->mark = n->mark;
    if (!(c->text = xstrdup(t)))
        return (void)load_nomem(ld, n);
    f->ncons++;
}

static void constraints(loader *ld, model_fit *f, const ynode *seq)
{
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'fit: constraints' (a list of \"EXPR <= EXPR\")"))
        return;
    f->cons = xcalloc(seq->n + 1, sizeof *f->cons);
    if (!f->cons)
        return (void)load_nomem(ld, seq);
    for (size_t i = 0; i < seq->n; i++)
        constraint(ld, f, seq->items[i]);
}

/* transmission: {links: [A, B], min: 30 deg}: the angle between links A
 * and B (their `angle` outputs) stays within [min, 180 deg - min]. */
static void transmission(loader *ld, model_fit *f, const ynode *map)
{
    static const char *const keys[] = {"links", "min"};
    if (!load_check_keys(ld, map, keys, COUNT(keys), "'fit: transmission'"))
        return;
    const ynode *l = ymap_get(map, "links"), *mn = ymap_get(map, "min");
    if (!l || !mn) {
        load_err(ld, map, "fit: transmission needs 'links: [A, B]' and 'min: ANGLE'");
        return;
    }
    if (l->kind != YNODE_SEQ || l->n != 2) {
        load_err(ld, l, "fit: transmission: 'links' is two links, [A, B]");
        return;
    }
    for (int k = 0; k < 2; k++) {
        const ynode *v = l->items[k];
        int found = 0;
        for (int i = 1; v->kind == YNODE_SCALAR && i < ld->m->nlinks; i++)
            found |= strcmp(ld->m->links[i].name, v->text) == 0;
        if (!found) {
            load_err(ld, v, "fit: transmission: '%s' is not a moving link of the file",
                     v->kind == YNODE_SCALAR ? v->text : "?");
            return;
        }
    }
    double a = 0.0;
    if (!load_get_quantity(ld, mn, Q_ANGLE, "fit: transmission: min", &a))
        return;
    if (!(a > 0.0 && a < 1.5707963267948966)) {
        load_err(ld, mn, "fit: transmission: min must lie between 0 and 90 deg");
        return;
    }
    f->trans_a = xstrdup(l->items[0]->text);
    f->trans_b = xstrdup(l->items[1]->text);
    if (!f->trans_a || !f->trans_b)
        return (void)load_nomem(ld, map);
    f->trans_min = a;
    f->trans_mark = map->mark;
}

void load_fit(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"free", "target", "columns", "weights", "starts",
                                       "whole-range", "free-timing", "constraints",
                                       "transmission"};
    if (!load_check_keys(ld, map, keys, COUNT(keys), "'fit'"))
        return;
    model_fit *f = xcalloc(1, sizeof *f);
    if (!f)
        return (void)load_nomem(ld, map);
    ld->m->fit = f;
    f->mark = map->mark;
    const ynode *v;
    if ((v = ymap_get(map, "free")))
        free_params(ld, f, v);
    if ((v = ymap_get(map, "target")))
        f->target = load_get_string(ld, v, "'fit: target' (a CSV file)", 4000, 0);
    if ((v = ymap_get(map, "columns")))
        columns(ld, f, v);
    if ((v = ymap_get(map, "weights")))
        weights(ld, f, v);
    long n = 0;
    if ((v = ymap_get(map, "starts")) && load_get_count(ld, v, "'fit: starts'", 1, 100000, &n))
        f->starts = (int)n;
    if ((v = ymap_get(map, "whole-range")))
        load_get_bool(ld, v, "'fit: whole-range'", &f->whole_range);
    if ((v = ymap_get(map, "free-timing")))
        load_get_bool(ld, v, "'fit: free-timing'", &f->free_timing);
    if ((v = ymap_get(map, "constraints")))
        constraints(ld, f, v);
    if ((v = ymap_get(map, "transmission")))
        transmission(ld, f, v);
}
