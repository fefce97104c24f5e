/* src/output/fit_setup.c: mech fit's problem stated (docs/synthesis.md):
 * the free parameters and their bounds (--free's text, or the file's fit:
 * section), the targets' CSV read and converted to SI, the columns and
 * weights, checked, into a fit_problem (src/study/fit.c); and mech_fit, the
 * library's whole fit (include/mech.h), for the Python module and any
 * caller. The command (src/cli/cmd_fit.c) and mech_fit state the problem
 * with these functions and run it with fit_run_starts. In this stage, not
 * study's: the targets are read by compare_read_csv. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "study.h"  /* first: output.h declares fit_setup after it */
#include "output.h"

void fit_setup_free(fit_setup *s)
{
    free(s->free_copy);
    free(s->q);
    free(s->target);
    compare_table_free(&s->csv);
    fit_problem_free(&s->fp);
}

/* "r=15mm:25mm,l": names and bound texts (in place in a copy). */
static int split_free(fit_setup *s, const char *file, const char *list, mech_diag *d)
{
    mech_mark none = {0, 0};
    s->free_copy = xstrdup(list);
    if (!s->free_copy)
        return diag_nomem(d, file, none);
    char *save = NULL;
    size_t len = strlen(list);
    if (len == 0 || list[0] == ',' || list[len - 1] == ',' || strstr(list, ",,"))
        return diag_error(d, file, none, "--free needs parameter names separated by commas, "
                          "not '%s'", list);
    for (char *tok = strtok_r(s->free_copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int k = s->fp.nfree;
        if (k == FIT_MAX_FREE)
            return diag_error(d, file, none, "--free: at most 32 parameters ('%s')", list);
        char *eq = strchr(tok, '=');
        s->bound_text[k][0] = s->bound_text[k][1] = NULL;
        if (eq) {
            *eq = '\0';
            char *colon = strchr(eq + 1, ':');
            if (!colon)
                return diag_error(d, file, none, "--free: bounds are NAME=LO:HI, not '%s'",
                                  eq + 1);
            *colon = '\0';
            s->bound_text[k][0] = eq + 1;
            s->bound_text[k][1] = colon + 1;
        }
        for (int i = 0; i < k; i++)
            if (strcmp(s->names[i], tok) == 0)
                return diag_error(d, file, none, "--free: parameter '%s' given twice", tok);
        s->names[k] = tok;
        s->fp.nfree++;
    }
    return MECH_OK;
}

/* A quantity "15mm", "0.5 rad", "15" (in the file's unit of `si_unit`) in
 * SI; 0, or -1 when it is not one of si_unit's dimension. */
int output_parse_quantity(const mech_model *m, const char *text, const char *si_unit, double *v)
{
    char *end;
    double x = strtod(text, &end);
    if (end == text || !isfinite(x))
        return -1;
    while (*end == ' ')
        end++;
    if (!*end) {
        char buf[32];
        double f = si_unit[0] ? output_in_file_units(m, si_unit, 1.0, buf, sizeof buf) : 1.0;
        *v = x / f;
        return 0;
    }
    double scale;
    dim dm;
    const char *rest;
    char du[32];
    if (!unit_parse(end, &scale, &dm, &rest) || *rest)
        return -1;
    dim_format(dm, du, sizeof du);
    if (strcmp(du, si_unit) != 0)
        return -1;
    *v = x * scale;
    return 0;
}

/* The bounds of the free parameters, checked: lo < hi, the file's value
 * inside them. */
static int read_bounds(fit_setup *s, const mech_model *m, mech_diag *d)
{
    mech_mark none = {0, 0};
    for (int k = 0; k < s->fp.nfree; k++) {
        if (s->bounds_given)
            continue;  /* the fit: section's, checked by the loader */
        s->lo[k] = -INFINITY;
        s->hi[k] = INFINITY;
        if (!s->bound_text[k][0])
            continue;
        for (int b = 0; b < 2; b++)
            if (output_parse_quantity(m, s->bound_text[k][b], s->unit[k], b ? &s->hi[k] : &s->lo[k]))
                return diag_error(d, m->file, none, "--free: the bound '%s' of '%s' is not a "
                                  "quantity in %s (the parameter's unit)", s->bound_text[k][b],
                                  s->names[k], s->unit[k][0] ? s->unit[k] : "a bare number");
        if (!(s->lo[k] < s->hi[k]))
            return diag_error(d, m->file, none, "--free: the bounds of '%s' are empty (%s:%s)",
                              s->names[k], s->bound_text[k][0], s->bound_text[k][1]);
        if (s->p0[k] < s->lo[k] || s->p0[k] > s->hi[k]) {
            char buf[32];
            double v = output_in_file_units(m, s->unit[k], s->p0[k], buf, sizeof buf);
            return diag_error(d, m->file, s->mark[k], "the bounds %s:%s of '%s' exclude its "
                              "value in the file (%.10g %s), the first start",
                              s->bound_text[k][0], s->bound_text[k][1], s->names[k], v, buf);
        }
    }
    return MECH_OK;
}

/* The target columns: the request's, the fit: section's, or every CSV
 * column after the first. */
static int choose_columns(fit_setup *s, const fit_request *rq, const model_fit *mf,
                          mech_diag *d)
{
    const compare_table *t = &s->csv;
    const char *file_cols[FIT_MAX_COLS];
    int nfile = 0;
    mech_mark none = {0, 0};
    if (!rq->ncolumns && mf && mf->ncolumns)
        for (int j = 0; j < mf->ncolumns && j < FIT_MAX_COLS; j++)
            file_cols[nfile++] = mf->columns[j];
    const char *const *cl = rq->ncolumns ? rq->columns : file_cols;
    int ncl = rq->ncolumns ? rq->ncolumns : nfile;
    if (t->ncols < 2 || t->nrows < 1)
        return diag_error(d, s->target_path, none, "the targets need a driver column, a target "
                          "column and a row at least");
    int n = ncl ? ncl : (int)t->ncols - 1;
    if (n > FIT_MAX_COLS)
        n = FIT_MAX_COLS;
    for (int j = 0; j < n; j++) {
        const char *name = ncl ? cl[j] : t->names[j + 1];
        s->csv_col[j] = -1;
        for (size_t c = 1; c < t->ncols; c++)
            if (strcmp(t->names[c], name) == 0)
                s->csv_col[j] = (int)c;
        if (s->csv_col[j] < 0)
            return diag_error(d, s->target_path, none, "target column %s: the targets have no "
                              "such column", name);
        s->cols[j] = name;
        s->weight[j] = !rq->ncolumns && nfile ? mf->weights[j] : 1.0;
    }
    s->fp.ncols = n;
    for (int w = 0; w < rq->nweights; w++) {
        const char *text = rq->weights[w], *eq = strchr(text, '=');
        char *end = NULL;
        double x = eq ? strtod(eq + 1, &end) : NAN;
        int found = 0;
        for (int j = 0; eq && j < n; j++)
            if (strncmp(s->cols[j], text, (size_t)(eq - text)) == 0 &&
                s->cols[j][eq - text] == '\0') {
                s->weight[j] = x;
                found = 1;
            }
        if (!eq || !end || *end || !(x >= 0.0) || !isfinite(x) || !found)
            return diag_error(d, s->target_path, none, "--weight needs COLUMN=W, a target "
                              "column and a number >= 0, not '%s'", text);
    }
    return MECH_OK;
}

/* The CSV's driver and target values in SI, checked against the units of
 * mech solve's columns. */
static int convert_targets(fit_setup *s, mech_diag *d)
{
    const compare_table *t = &s->csv;
    int nq = (int)t->nrows, nc = s->fp.ncols;
    mech_mark none = {0, 0};
    s->q = xcalloc((size_t)nq, sizeof *s->q);
    s->target = xcalloc((size_t)nq * (size_t)nc, sizeof *s->target);
    if (!s->q || !s->target)
        return diag_nomem(d, s->target_path, none);
    for (int j = -1; j < nc; j++) {
        int c = j < 0 ? 0 : s->csv_col[j];
        const char *si = j < 0 ? s->fp.qunit : s->col_unit[j], *u = t->units[c];
        double scale = 1.0;
        dim dm;
        const char *rest = u;
        char du[32] = "";
        if (*u && (!unit_parse(u, &scale, &dm, &rest) || *rest))
            return diag_error(d, s->target_path, none, "column '%s': unknown unit '%s'",
                              t->names[c], u);
        if (*u)
            dim_format(dm, du, sizeof du);
        if (strcmp(du, si) != 0 && !(*u == '\0' && strcmp(si, "-") == 0))
            return diag_error(d, s->target_path, none, "column '%s' is in '%s', where mech "
                              "solve's is in %s (write the unit in the header: '%s [%s]')",
                              t->names[c], u, si, t->names[c], si);
        for (int i = 0; i < nq; i++) {
            double v = t->values[(size_t)i * t->ncols + (size_t)c] * scale;
            if (j < 0 && isnan(v))
                return diag_error(d, s->target_path, (mech_mark){i + 2, 1}, "row %d has no "
                                  "driver position", i + 2);
            if (j < 0)
                s->q[i] = v;
            else
                s->target[(size_t)i * nc + j] = v;
        }
    }
    if (strcmp(t->names[0], "q") != 0 && strcmp(t->names[0], "t") != 0)
        return diag_error(d, s->target_path, none, "the first column must be the driver "
                          "position 'q' (or the time 't'), as in mech solve's CSV, not '%s'",
                          t->names[0]);
    s->fp.nq = nq;
    s->fp.q = s->q;
    s->fp.target = s->target;
    if (nq * nc < s->fp.nfree)
        return diag_error(d, s->target_path, none, "%d target values for %d free parameters: "
                          "give at least as many targets as parameters", nq * nc, s->fp.nfree);
    return MECH_OK;
}

/* The free parameters of the file's fit: section (names, bounds in SI). */
static int free_of_file(fit_setup *s, const char *file, const model_fit *mf, mech_diag *d)
{
    mech_mark none = {0, 0};
    if (!mf || !mf->nfree)
        return diag_error(d, file, none, "--free NAME,... is needed (or a 'fit:' section with "
                          "'free:' in the file): which parameters to fit");
    if (mf->nfree > FIT_MAX_FREE)
        return diag_error(d, file, none, "at most 32 free parameters");
    for (int k = 0; k < mf->nfree; k++) {
        s->names[k] = mf->free[k].name;
        s->lo[k] = mf->free[k].lo;
        s->hi[k] = mf->free[k].hi;
    }
    s->fp.nfree = mf->nfree;
    s->bounds_given = 1;
    return MECH_OK;
}

/* The targets' CSV: the request's, or the fit: section's (relative to the
 * file's folder). */
static int target_path(fit_setup *s, const fit_request *rq, const model_fit *mf, mech_diag *d)
{
    mech_mark none = {0, 0};
    const char *t = rq->target ? rq->target : mf ? mf->target : NULL;
    if (!t)
        return diag_error(d, rq->file, none, "--target CSV is needed (or 'target:' in the "
                          "file's 'fit:' section): what to fit to");
    const char *slash = strrchr(rq->file, '/');
    int rel = !rq->target && t[0] != '/' && slash;
    int len = rel ? (int)(slash - rq->file) + 1 : 0;
    if ((size_t)snprintf(s->target_path, sizeof s->target_path, "%.*s%s", len, rq->file, t) >=
        sizeof s->target_path)
        return diag_error(d, rq->file, none, "the targets' path is too long: %s", t);
    return MECH_OK;
}

/* --transmission A,B,MIN: the links (fit_prepare checks them) and the least
 * angle (a bare number in the file's angle unit), 0 < MIN < 90 deg. */
static int transmission(fit_setup *s, const mech_model *m, const char *text, mech_diag *d)
{
    const char *c1 = strchr(text, ','), *c2 = c1 ? strchr(c1 + 1, ',') : NULL;
    double v = NAN;
    if (!c1 || !c2 || strchr(c2 + 1, ',') || c1 == text || c2 == c1 + 1 ||
        c1 - text >= (long)sizeof s->fp.trans_a || c2 - c1 - 1 >= (long)sizeof s->fp.trans_b ||
        output_parse_quantity(m, c2 + 1, "rad", &v) < 0)
        return diag_error(d, m->file, (mech_mark){0, 0}, "--transmission needs LINK,LINK,MIN "
                          "(two moving links and the least angle, e.g. coupler,rocker,30deg), "
                          "not '%s'", text);
    if (!(v > 0.0 && v < 1.5707963267948966))
        return diag_error(d, m->file, (mech_mark){0, 0}, "--transmission: the least angle "
                          "must lie between 0 and 90 deg, not '%s'", c2 + 1);
    snprintf(s->fp.trans_a, sizeof s->fp.trans_a, "%.*s", (int)(c1 - text), text);
    snprintf(s->fp.trans_b, sizeof s->fp.trans_b, "%.*s", (int)(c2 - c1 - 1), c1 + 1);
    s->fp.trans_min = v;
    return MECH_OK;
}

int fit_setup_read(fit_setup *s, const fit_request *rq, const mech_model *m, mech_diag *d)
{
    const model_fit *mf = m->fit;
    int rc = rq->free ? split_free(s, rq->file, rq->free, d) : free_of_file(s, rq->file, mf, d);
    if (rc == MECH_OK)
        rc = target_path(s, rq, mf, d);
    if (rc != MECH_OK)
        return rc;
    s->whole_range = rq->whole_range || (mf && mf->whole_range);
    s->fp.free_timing = rq->free_timing || (mf && mf->free_timing);
    rc = compare_read_csv(s->target_path, &s->csv, d);
    if (rc == MECH_OK)
        rc = choose_columns(s, rq, mf, d);
    if (rc != MECH_OK)
        return rc;
    if (rq->transmission && (rc = transmission(s, m, rq->transmission, d)) != MECH_OK)
        return rc;
    s->fp.path = rq->file;
    s->fp.names = s->names;
    s->fp.unit = s->unit;
    s->fp.mark = s->mark;
    s->fp.cols = s->cols;
    s->fp.col_unit = s->col_unit;
    s->fp.weight = s->weight;
    rc = fit_prepare(&s->fp, s->p0, d);
    if (rc == MECH_OK)
        rc = convert_targets(s, d);
    if (rc != MECH_OK)
        return rc;
    if (s->fp.free_timing && s->fp.nq > FIT_MAX_TIMED)
        return diag_error(d, s->target_path, (mech_mark){0, 0}, "free timing: at most 512 "
                          "target rows");
    if (s->fp.nq * s->fp.ncols < fit_nvars(&s->fp))
        return diag_error(d, s->target_path, (mech_mark){0, 0}, "%d target values for %d "
                          "unknowns (free timing: one per row too): give more targets",
                          s->fp.nq * s->fp.ncols, fit_nvars(&s->fp));
    for (int j = s->fp.nfree; j < fit_nvars(&s->fp); j++) {
        s->lo[j] = -INFINITY;
        s->hi[j] = INFINITY;
    }
    return read_bounds(s, m, d);
}

int fit_setup_starts(const fit_setup *s, const mech_model *m, int asked, int *n, mech_diag *d)
{
    int bounded = 1, any = 0;  /* every free parameter has bounds; one has */
    for (int k = 0; k < s->fp.nfree; k++) {
        bounded &= isfinite(s->lo[k]) && isfinite(s->hi[k]);
        any |= isfinite(s->lo[k]) && isfinite(s->hi[k]);
    }
    *n = asked ? asked : m->fit && m->fit->starts ? m->fit->starts : bounded ? 16 : 1;
    if (*n > 1 && !any)
        return diag_error(d, m->file, (mech_mark){0, 0}, "%d starts need bounds on a free "
                          "parameter at least (NAME=LO:HI)", *n);
    return MECH_OK;
}

/* ---- mech_fit (include/mech.h) ----------------------------------------- */

void mech_fit_options_default(mech_fit_options *o)
{
    memset(o, 0, sizeof *o);
}

void mech_fit_result_free(mech_fit_result *r)
{
    if (!r)
        return;
    for (int k = 0; k < r->nfree; k++)
        free(r->names[k]);
    for (int j = 0; j < r->ncolumns; j++)
        free(r->columns[j]);
    for (int c = 0; c < r->nconstraints; c++)
        free(r->constraints[c]);
    free(r->names);
    free(r->values);
    free(r->columns);
    free(r->worst_error);
    free(r->constraints);
    free(r->margins);
    memset(r, 0, sizeof *r);
}

/* The best start's parameters, its worst error per column and its
 * constraints' margins into r. */
static int fill_result(fit_setup *s, const mech_model *m, const fit_start *best,
                       mech_fit_result *r)
{
    int nf = s->fp.nfree, nc = s->fp.ncols, nk = s->fp.ncons + (s->fp.trans ? 1 : 0);
    r->names = xcalloc((size_t)nf + 1, sizeof *r->names);
    r->values = xcalloc((size_t)nf + 1, sizeof *r->values);
    r->columns = xcalloc((size_t)nc + 1, sizeof *r->columns);
    r->worst_error = xcalloc((size_t)nc + 1, sizeof *r->worst_error);
    r->constraints = xcalloc((size_t)nk + 1, sizeof *r->constraints);
    r->margins = xcalloc((size_t)nk + 1, sizeof *r->margins);
    double *res = xcalloc((size_t)fit_nres(&s->fp), sizeof *res);
    if (!r->names || !r->values || !r->columns || !r->worst_error || !r->constraints ||
        !r->margins || !res) {
        free(res);
        return MECH_ENOMEM;
    }
    for (int k = 0; k < nf; k++) {
        if (!(r->names[k] = xstrdup(s->names[k])))
            break;
        r->values[k] = best->p[k];
        r->nfree++;
    }
    mech_diag quiet;
    mech_diag_init(&quiet);
    int rc = r->nfree == nf ? fit_eval(&s->fp, best->p, res, NULL, &quiet) : MECH_ENOMEM;
    mech_diag_free(&quiet);
    for (int j = 0; rc == MECH_OK && j < nc; j++) {
        double w = s->weight[j] > 0 ? s->weight[j] : 1.0, worst = 0.0;
        for (int i = 0; i < s->fp.nq; i++)
            if (!isnan(s->target[(size_t)i * nc + j]) && fabs(res[i * nc + j]) / w > worst)
                worst = fabs(res[i * nc + j]) / w;
        if (!(r->columns[j] = xstrdup(s->cols[j])))
            rc = MECH_ENOMEM;
        else
            r->worst_error[r->ncolumns++] = worst;
    }
    int base = s->fp.nq * nc;
    for (int c = 0; rc == MECH_OK && c < nk; c++) {
        char label[256];
        double margin;
        if (c < s->fp.ncons) {
            snprintf(label, sizeof label, "%s", m->fit->cons[c].text);
            margin = -res[base + c];
        } else {
            snprintf(label, sizeof label, "transmission %s/%s", s->fp.trans_a, s->fp.trans_b);
            margin = INFINITY;
            for (int i = 0; i < s->fp.nq; i++)
                margin = fmin(margin, -res[base + s->fp.ncons + i]);
        }
        if (!(r->constraints[c] = xstrdup(label)))
            rc = MECH_ENOMEM;
        else
            r->margins[r->nconstraints++] = margin;
    }
    free(res);
    return rc == MECH_ESOLVE ? MECH_OK : rc;  /* accepted: it assembled a moment ago */
}

int mech_fit(const char *path, const mech_fit_options *o, mech_fit_result *r, mech_diag *d)
{
    mech_fit_options def;
    if (!o) {
        mech_fit_options_default(&def);
        o = &def;
    }
    memset(r, 0, sizeof *r);
    if (!path)
        return diag_error(d, NULL, (mech_mark){0, 0}, "mech_fit: no file");
    double t0 = clock_seconds();
    fit_setup *s = xcalloc(1, sizeof *s);
    mech_model *m = NULL;
    mech_summary sm;
    if (!s)
        return diag_nomem(d, path, (mech_mark){0, 0});
    int rc = mech_load_file(path, &m, d);
    if (rc == MECH_OK)
        rc = mech_check(m, &sm, d);
    fit_request rq = {path, o->free, o->target, o->columns, o->ncolumns, o->weights,
                      o->nweights, o->whole_range, o->free_timing, o->transmission};
    if (rc == MECH_OK)
        rc = fit_setup_read(s, &rq, m, d);
    int n = 1;
    if (rc == MECH_OK)
        rc = fit_setup_starts(s, m, o->starts, &n, d);
    fit_start *st = rc == MECH_OK ? xcalloc((size_t)n, sizeof *st) : NULL;
    if (rc == MECH_OK && !st)
        rc = diag_nomem(d, path, (mech_mark){0, 0});
    if (rc == MECH_OK) {
        s->fp.seed = o->seed;
        rc = fit_run_starts(&s->fp, s->lo, s->hi, s->p0, s->whole_range, n, o->jobs, st);
        if (rc == MECH_ENOMEM)
            rc = diag_nomem(d, path, (mech_mark){0, 0});
    }
    if (rc == MECH_OK) {
        r->starts = n;
        for (int i = 0; i < n; i++) {
            r->solves += st[i].solves;
            r->accepted += st[i].rc == MECH_OK;
            r->violated += st[i].rc == MECH_ESOLVE && st[i].info == -2;
        }
        r->info = st[0].info;
        r->objective = st[0].objective;
        if (!r->accepted) {
            rc = diag_fail(d, MECH_FAIL_NO_ASSEMBLY, path, (mech_mark){0, 0}, "mech fit: no "
                           "start assembles at every target%s%s: no solution (%d starts, %d "
                           "violating a constraint)", s->whole_range ? " and over the whole "
                           "range" : "", fit_ncons(&s->fp) ? " within the constraints" : "", n,
                           r->violated);
        } else {
            rc = fill_result(s, m, &st[0], r);
            if (rc == MECH_ENOMEM)
                rc = diag_nomem(d, path, (mech_mark){0, 0});
        }
    }
    r->seconds = clock_seconds() - t0;
    free(st);
    mech_model_free(&m);
    fit_setup_free(s);
    free(s);
    return rc;
}
