/* src/output/fit_plot.c: the figure of a fit (docs/synthesis.md, "The
 * figure"): the solved curve of the target columns' objects against the
 * targets as points, and for `mech fit --plot` the start's curve dashed.
 * One function draws it for the three places it appears: `mech fit
 * --plot` (the best solution and the start), and `mech plot` and `mech
 * report` of a file with a fit: section (the file's own curve, so the
 * figure of a fitted file, mech fit -o's, shows how it meets the targets). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "study.h"  /* first: output.h declares fit_setup after it */
#include "output.h"

/* What the figure draws: up to FIGURE_ITEMS points' paths (a point whose x
 * and y are both targets), else up to FIGURE_ITEMS target columns of the
 * first one's unit against the driver; each as up to three series: the
 * curve, the start's (dashed), the targets (points). */
enum { FIGURE_ITEMS = 2 };

typedef struct fit_items {
    int path;                 /* 1: paths (y against x), 0: against the driver */
    int n;                    /* items */
    int cx[FIGURE_ITEMS], cy[FIGURE_ITEMS];  /* target columns: x (or the column), y */
    char name[FIGURE_ITEMS][64];
} fit_items;

static void choose_items(const fit_setup *s, fit_items *pl)
{
    memset(pl, 0, sizeof *pl);
    for (int j = 0; j < s->fp.ncols && pl->n < FIGURE_ITEMS; j++) {
        const char *c = s->cols[j], *dot = strrchr(c, '.');
        if (!dot || strcmp(dot, ".x") != 0)
            continue;
        for (int k = 0; k < s->fp.ncols; k++) {
            const char *d = s->cols[k];
            if (strncmp(d, c, (size_t)(dot - c)) == 0 && strcmp(d + (dot - c), ".y") == 0) {
                pl->cx[pl->n] = j;
                pl->cy[pl->n] = k;
                snprintf(pl->name[pl->n++], sizeof pl->name[0], "%.*s", (int)(dot - c), c);
                break;
            }
        }
    }
    pl->path = pl->n > 0;
    for (int j = 0; !pl->path && j < s->fp.ncols && pl->n < FIGURE_ITEMS; j++)
        if (strcmp(s->col_unit[j], s->col_unit[0]) == 0) {
            pl->cx[pl->n] = pl->cy[pl->n] = j;
            snprintf(pl->name[pl->n++], sizeof pl->name[0], "%s", s->cols[j]);
        }
}

/* The rows of a solved sweep into the figure's table from row *at: column
 * `to + c` gets t's column cols[c]; a row of NaN (a break of the curves)
 * where the sweep has a gap and after the sweep. */
static void put_sweep(double *v, int ncol, int *at, const mech_table *t, const int *cols,
                      int ncols, int to)
{
    int skipped = 0, g = 0;
    for (int r = 0; r < t->nrows; r++) {
        int brk = 0;
        while (g < t->ngaps && t->gaps[g].first_row <= r + skipped) {
            skipped += t->gaps[g].last_row - t->gaps[g].first_row + 1;
            g++;
            brk = r > 0;
        }
        if (brk)
            (*at)++;  /* a row of NaN */
        double *row = v + (size_t)(*at)++ * (size_t)ncol;
        row[0] = mech_table_get(t, r, 0);
        for (int c = 0; c < ncols; c++)
            row[to + c] = cols[c] < 0 ? NAN : mech_table_get(t, r, cols[c]);
    }
    (*at)++;
}

/* Each item's columns of sweep t (the same rows for every item) into the
 * series k (0 the curve, 1 the start) of the figure's table. */
static void put_curves(const fit_setup *s, const fit_items *pl, const mech_table *t, int k,
                       double *v, int ncol, int *at)
{
    int per = pl->path ? 2 : 1;
    for (int it = 0; it < pl->n; it++) {
        int cols[2], start = *at;
        for (int xy = 0; xy < per; xy++)
            cols[xy] = mech_table_column(t, s->cols[xy ? pl->cy[it] : pl->cx[it]]);
        put_sweep(v, ncol, at, t, cols, per, 1 + 3 * per * it + per * k);
        if (it + 1 < pl->n)
            *at = start;
    }
}

/* The targets as rows of series 2 at their driver positions; returns the
 * number of targets drawn (both coordinates given, for a path). */
static int put_targets(const fit_setup *s, const fit_items *pl, const double *timing, double *v,
                       int ncol, int *at)
{
    int per = pl->path ? 2 : 1, ndots = 0;
    for (int i = 0; i < s->fp.nq; i++, (*at)++) {
        double *row = v + (size_t)*at * (size_t)ncol;
        row[0] = timing ? timing[i] : s->q[i];
        for (int it = 0; it < pl->n; it++) {
            double x = s->target[(size_t)i * s->fp.ncols + pl->cx[it]];
            double y = s->target[(size_t)i * s->fp.ncols + pl->cy[it]];
            row[1 + 3 * per * it + 2 * per] = x;
            if (per == 2)
                row[1 + 3 * per * it + 2 * per + 1] = y;
            ndots += !isnan(x) && !isnan(y);
        }
    }
    return ndots;
}

static const char *display(const char *si, double *scale)
{
    *scale = strcmp(si, "m") == 0 ? 1e3 : strcmp(si, "rad") == 0 ? 180.0 / 3.14159265358979323846 : 1.0;
    return strcmp(si, "m") == 0 ? "mm" : strcmp(si, "rad") == 0 ? "deg" : si;
}

/* The series, title and axis of the figure. */
static void describe_figure(const fit_setup *s, const fit_items *pl, const fit_curves *c,
                            int ndots, plot_figure *fg)
{
    int per = pl->path ? 2 : 1;
    memset(fg, 0, sizeof *fg);
    for (int it = 0; it < pl->n; it++)
        for (int k = 0; k < 3; k++) {
            if (k == 1 && !c->start)
                continue;
            int sr = fg->nseries++, col = 1 + 3 * per * it + per * k;
            fg->col[sr] = col;
            fg->ycol[sr] = col + 1;
            fg->dots[sr] = k == 2;
            snprintf(fg->label[sr], sizeof fg->label[sr], "%.24s%s%.20s",
                     pl->n > 1 ? pl->name[it] : "", pl->n > 1 ? " " : "",
                     k == 0 ? c->curve_label : k == 1 ? "start" : "targets");
        }
    snprintf(fg->name, sizeof fg->name, "fit");
    if (pl->path) {
        fg->kind = PLOT_PATH;
        snprintf(fg->title, sizeof fg->title, "Fit: the path%s of %.40s%s%.40s through %d target%s",
                 pl->n > 1 ? "s" : "", pl->name[0], pl->n > 1 ? ", " : "",
                 pl->n > 1 ? pl->name[1] : "", ndots, ndots == 1 ? "" : "s");
        snprintf(fg->ylabel, sizeof fg->ylabel, "y");
        snprintf(fg->yunit, sizeof fg->yunit, "mm");
        fg->yscale = 1e3;
    } else {
        double scale;
        const char *u = display(s->col_unit[pl->cx[0]], &scale);
        snprintf(fg->title, sizeof fg->title, "Fit: %.40s%s%.40s against the driver, %d target%s",
                 pl->name[0], pl->n > 1 ? ", " : "", pl->n > 1 ? pl->name[1] : "", ndots,
                 ndots == 1 ? "" : "s");
        snprintf(fg->ylabel, sizeof fg->ylabel, "%.40s", pl->n > 1 ? "value" : pl->name[0]);
        snprintf(fg->yunit, sizeof fg->yunit, "%s", u);
        fg->yscale = scale;
    }
}

int fit_figure_write(const fit_setup *s, const mech_model *m, const fit_curves *c,
                     const char *subtitle, const char *path, mech_diag *d)
{
    fit_items pl;
    choose_items(s, &pl);
    /* columns: q, then per item its three series (curve, start, targets),
     * each x and y for a path, one column against the driver */
    int per = pl.path ? 2 : 1, ncol = 1 + 3 * per * pl.n;
    const mech_table *st = c->start;
    int nrows = c->curve->nrows + c->curve->ngaps + 1 + (st ? st->nrows + st->ngaps + 1 : 0) +
                s->fp.nq + 1;
    mech_table t = {0};
    t.columns = xcalloc((size_t)ncol, sizeof *t.columns);
    t.values = xcalloc((size_t)nrows * (size_t)ncol, sizeof *t.values);
    if (!t.columns || !t.values) {
        free(t.columns);
        free(t.values);
        return diag_nomem(d, path, (mech_mark){0, 0});
    }
    t.ncolumns = ncol;
    for (size_t i = 0; i < (size_t)nrows * (size_t)ncol; i++)
        t.values[i] = NAN;
    int at = 0;
    put_curves(s, &pl, c->curve, 0, t.values, ncol, &at);
    if (st)
        put_curves(s, &pl, st, 1, t.values, ncol, &at);
    int ndots = put_targets(s, &pl, c->timing, t.values, ncol, &at);
    t.nrows = at;
    plot_figure fg;
    describe_figure(s, &pl, c, ndots, &fg);
    int rc = plot_figure_write(m, &t, &fg, subtitle, path, d);
    free(t.columns);
    free(t.values);
    return rc;
}

/* The reasons in why (errors) as warnings in d: the figure is left out,
 * the rest of the command's work goes on. */
static void left_out(const mech_diag *why, mech_diag *d)
{
    for (size_t i = 0; i < why->count; i++) {
        const mech_diag_entry *e = &why->entries[i];
        if (e->severity == MECH_SEV_ERROR)
            diag_add(d, MECH_SEV_WARNING, e->kind, e->file, e->mark, "the fit: section's figure "
                     "is left out: %s", e->message);
        else
            diag_copy(d, e);
    }
}

int fit_figure_of_model(const mech_model *m, const char *path, mech_diag *d)
{
    fit_setup *s = xcalloc(1, sizeof *s);
    if (!s)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    fit_request rq = {.file = m->file};
    mech_table curve = {0};
    mech_diag why;
    mech_diag_init(&why);
    int rc = fit_setup_read(s, &rq, m, &why);
    if (rc == MECH_OK) {
        rc = fit_sweep_model(&s->fp, m, &curve, &why);
        if (rc == MECH_ESOLVE && curve.nrows > 0)
            rc = MECH_OK;  /* a partial sweep: its curve breaks at the gaps */
        else if (rc == MECH_ESOLVE)
            diag_error(&why, m->file, (mech_mark){0, 0}, "the mechanism assembles nowhere over "
                       "its range");
    }
    if (rc == MECH_ENOMEM) {
        diag_nomem(d, m->file, (mech_mark){0, 0});
    } else if (rc != MECH_OK) {
        left_out(&why, d);
        rc = MECH_EINPUT;
    } else {
        char subtitle[160];
        snprintf(subtitle, sizeof subtitle, "%.80s: this file (solid), the fit: section's "
                 "targets (points)", m->name ? m->name : m->file);
        fit_curves c = {.curve = &curve, .curve_label = "this file"};
        rc = fit_figure_write(s, m, &c, subtitle, path, d);
    }
    mech_diag_free(&why);
    mech_table_free(&curve);
    fit_setup_free(s);
    free(s);
    return rc;
}
