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

void load_fit(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"free", "target", "columns", "weights", "starts",
                                       "whole-range", "free-timing"};
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
}
