/* src/cli/cmd_fit.c: `mech fit`, dimensional synthesis (docs/synthesis.md):
 * free parameters fitted so that solved output columns meet targets read
 * from a CSV, by least squares (cmd_fit_lm.c) from several starts; the best
 * solution written as a copy of the file with those parameters' values
 * replaced in its text (comments kept). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "base.h"
#include "output.h"
#include "study.h"

enum { MAX_FREE = 32, MAX_COLS = 64, MAX_SHOWN = 5 };
enum { MAX_TIMED = 512, MAX_VARS = MAX_FREE + MAX_TIMED };  /* free timing: rows, unknowns */

typedef struct fit_list {
    const char *v[MAX_COLS];
    int n;
} fit_list;

typedef struct fit_args {
    const char *file, *out, *target, *free;
    fit_list columns;            /* --column NAME (repeatable) */
    fit_list weights;            /* --weight NAME=W (repeatable) */
    int starts, jobs, quiet;
    int whole_range;             /* --whole-range */
    int free_timing;             /* --free-timing */
} fit_args;

/* A repeatable option's value appended to its list. */
static int read_list(const char *command, void *target, const char *val)
{
    fit_list *l = target;
    if (l->n == MAX_COLS)
        return cmd_usage_error(command, "at most 64 of these options, not more ('%s')", val);
    l->v[l->n++] = val;
    return -1;
}

#define AT(field) offsetof(fit_args, field)

static const cmd_opt options[] = {
    {.names = "--free", .kind = CMD_OPT_TEXT, .at = AT(free), .label = "--free LIST",
     .help = "the parameters to fit, comma-separated, each NAME or\n"
             "NAME=LO:HI with bounds (quantities, e.g. r=15mm:25mm;\n"
             "bare numbers are in the file's units)"},
    {.names = "--target", .kind = CMD_OPT_TEXT, .at = AT(target), .label = "--target CSV",
     .help = "the targets: a CSV whose first column is the driver\n"
             "position ('q [deg]') and whose other columns are named\n"
             "as mech solve's ('P.x [mm]', 'rocker.angle [deg]');\n"
             "an empty cell is no target there"},
    {.names = "--column", .kind = CMD_OPT_CALL, .at = AT(columns), .call = read_list,
     .label = "--column NAME",
     .help = "fit only this column of the CSV (repeatable; default:\n"
             "every column after the first)"},
    {.names = "--weight", .kind = CMD_OPT_CALL, .at = AT(weights), .call = read_list,
     .label = "--weight NAME=W",
     .help = "multiply column NAME's residuals (SI) by W (repeatable;\n"
             "default 1)"},
    {.names = "--starts", .kind = CMD_OPT_INT, .at = AT(starts), .lo = 1, .hi = 100000,
     .expect = "needs a whole number from 1 to 100000", .label = "--starts N",
     .help = "local fits from N starts: the file's values, then a\n"
             "Halton sequence over the bounds (a parameter without\n"
             "bounds keeps its value; default 16 when every free\n"
             "parameter has bounds, else 1)"},
    {.names = "--whole-range", .kind = CMD_OPT_FLAG, .at = AT(whole_range), .flag = 1,
     .label = "--whole-range",
     .help = "a constraint: the solution must assemble over the file's\n"
             "whole driver range (a crank from 0 to 360 deg turns\n"
             "fully: a Grashof crank); a solution that does not is\n"
             "rejected"},
    {.names = "--free-timing", .kind = CMD_OPT_FLAG, .at = AT(free_timing), .flag = 1,
     .label = "--free-timing",
     .help = "each target's driver position is an unknown too (the\n"
             "CSV's is its start): a path through the points, whatever\n"
             "the crank angle at each; needs position and rate columns"},
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output FILE",
     .help = "write the best solution as a copy of the mechanism file\n"
             "with the free parameters' values replaced (comments kept;\n"
             "written whole or not at all, never over an input)"},
    CMD_JOBS_ENTRY(AT(jobs)),
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = AT(quiet), .flag = 1,
     .label = "-q, --quiet", .help = "print only the best solution's summary"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_fit_spec = {
    .name = "fit",
    .summary = "fit parameters so that outputs meet targets (synthesis)",
    .usage = "usage: mech fit FILE --free NAME[=LO:HI],... --target TARGETS.csv\n"
             "                [--column NAME]... [--weight NAME=W]... [--starts N]\n"
             "                [--whole-range] [--free-timing] [-j N] [-o BEST.yaml]\n"
             "                [--quiet]\n"
             "       mech fit FILE [-o BEST.yaml]   (the file's fit: section)\n",
    .about = "Dimensional synthesis: find the values of the file's free parameters that\n"
             "make the solved outputs meet the targets at the targets' driver positions:\n"
             "path generation (a point's x and y), function generation (a link's angle\n"
             "against the input), motion generation (x, y and angle). Least squares by\n"
             "MINPACK's Levenberg-Marquardt (lmder) with the exact Jacobian from the\n"
             "sensitivities (docs/sensitivity.md); bounds by a change of variable; many\n"
             "starts. A start or a solution where the mechanism does not assemble at\n"
             "every target is rejected (docs/synthesis.md). The file's 'fit:' section\n"
             "(docs/format.md) states the same problem; the options replace its parts.\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 a solution found (the summary says how close it is), 1 no\n"
             "start assembles at every target, 2 invalid file, targets or usage, 3 a\n"
             "file cannot be read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech fit FILE --free NAME,... --target CSV)",
};

/* ---- the problem from the command line ------------------------------ */

typedef struct fit_setup {
    fit_problem fp;
    const char *names[MAX_FREE];
    char *free_copy;
    const char *bound_text[MAX_FREE][2];  /* LO, HI as given, or NULL */
    char unit[MAX_FREE][32];
    mech_mark mark[MAX_FREE];
    double lo[MAX_VARS], hi[MAX_VARS], p0[MAX_FREE];  /* lo, hi: also the timing's */
    const char *cols[MAX_COLS];
    char col_unit[MAX_COLS][16];
    double weight[MAX_COLS];
    int csv_col[MAX_COLS];  /* the CSV's column of each target column */
    compare_table csv;
    double *q, *target;
    char target_path[4096];
    int bounds_given;  /* the bounds are the fit: section's, already in SI */
    int whole_range;
} fit_setup;

static void setup_free(fit_setup *s)
{
    free(s->free_copy);
    free(s->q);
    free(s->target);
    compare_table_free(&s->csv);
    fit_problem_free(&s->fp);
}

/* --free "r=15mm:25mm,l": names and bound texts (in place in a copy). */
static int split_free(fit_setup *s, const char *list)
{
    s->free_copy = xstrdup(list);
    if (!s->free_copy)
        return MECH_EXIT_IO;
    char *save = NULL;
    size_t len = strlen(list);
    if (len == 0 || list[0] == ',' || list[len - 1] == ',' || strstr(list, ",,"))
        return cmd_usage_error("fit", "--free needs parameter names separated by commas, "
                               "not '%s'", list);
    for (char *tok = strtok_r(s->free_copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int k = s->fp.nfree;
        if (k == MAX_FREE)
            return cmd_usage_error("fit", "--free: at most 32 parameters ('%s')", list);
        char *eq = strchr(tok, '=');
        s->bound_text[k][0] = s->bound_text[k][1] = NULL;
        if (eq) {
            *eq = '\0';
            char *colon = strchr(eq + 1, ':');
            if (!colon)
                return cmd_usage_error("fit", "--free: bounds are NAME=LO:HI, not '%s'", eq + 1);
            *colon = '\0';
            s->bound_text[k][0] = eq + 1;
            s->bound_text[k][1] = colon + 1;
        }
        for (int i = 0; i < k; i++)
            if (strcmp(s->names[i], tok) == 0)
                return cmd_usage_error("fit", "--free: parameter '%s' given twice", tok);
        s->names[k] = tok;
        s->fp.nfree++;
    }
    return -1;
}

/* A quantity "15mm", "0.5 rad", "15" (in the file's unit of `si_unit`) in
 * SI; 0, or -1 when it is not one of si_unit's dimension. */
static int parse_quantity(const mech_model *m, const char *text, const char *si_unit, double *v)
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
    dim d;
    const char *rest;
    char du[32];
    if (!unit_parse(end, &scale, &d, &rest) || *rest)
        return -1;
    dim_format(d, du, sizeof du);
    if (strcmp(du, si_unit) != 0)
        return -1;
    *v = x * scale;
    return 0;
}

/* The bounds of the free parameters, checked: lo < hi, the file's value
 * inside them. */
static int read_bounds(fit_setup *s, const mech_model *m)
{
    for (int k = 0; k < s->fp.nfree; k++) {
        if (s->bounds_given)
            continue;  /* the fit: section's, checked by the loader */
        s->lo[k] = -INFINITY;
        s->hi[k] = INFINITY;
        if (!s->bound_text[k][0])
            continue;
        for (int b = 0; b < 2; b++)
            if (parse_quantity(m, s->bound_text[k][b], s->unit[k], b ? &s->hi[k] : &s->lo[k])) {
                fprintf(stderr, "mech fit: --free: the bound '%s' of '%s' is not a quantity in "
                        "%s (the parameter's unit)\n", s->bound_text[k][b], s->names[k],
                        s->unit[k][0] ? s->unit[k] : "a bare number");
                return MECH_EXIT_INPUT;
            }
        if (!(s->lo[k] < s->hi[k])) {
            fprintf(stderr, "mech fit: --free: the bounds of '%s' are empty (%s:%s)\n",
                    s->names[k], s->bound_text[k][0], s->bound_text[k][1]);
            return MECH_EXIT_INPUT;
        }
        if (s->p0[k] < s->lo[k] || s->p0[k] > s->hi[k]) {
            char buf[32];
            double v = output_in_file_units(m, s->unit[k], s->p0[k], buf, sizeof buf);
            fprintf(stderr, "%s:%d:%d: error: the bounds %s:%s of '%s' exclude its value in "
                    "the file (%.10g %s), the first start\n", m->file, s->mark[k].line,
                    s->mark[k].col, s->bound_text[k][0], s->bound_text[k][1], s->names[k],
                    v, buf);
            return MECH_EXIT_INPUT;
        }
    }
    return -1;
}

/* The target columns: --column's, the fit: section's, or every CSV column
 * after the first. */
static int choose_columns(fit_setup *s, const fit_args *a, const model_fit *mf)
{
    const compare_table *t = &s->csv;
    fit_list file_cols = {{0}, 0};
    if (!a->columns.n && mf && mf->ncolumns)
        for (int j = 0; j < mf->ncolumns && j < MAX_COLS; j++)
            file_cols.v[file_cols.n++] = mf->columns[j];
    const fit_list *cl = a->columns.n ? &a->columns : &file_cols;
    if (t->ncols < 2 || t->nrows < 1) {
        fprintf(stderr, "mech fit: %s: the targets need a driver column, a target column "
                "and a row at least\n", s->target_path);
        return MECH_EXIT_INPUT;
    }
    int n = cl->n ? cl->n : (int)t->ncols - 1;
    if (n > MAX_COLS)
        n = MAX_COLS;
    for (int j = 0; j < n; j++) {
        const char *name = cl->n ? cl->v[j] : t->names[j + 1];
        s->csv_col[j] = -1;
        for (size_t c = 1; c < t->ncols; c++)
            if (strcmp(t->names[c], name) == 0)
                s->csv_col[j] = (int)c;
        if (s->csv_col[j] < 0) {
            fprintf(stderr, "mech fit: target column %s: %s has no such column\n", name,
                    s->target_path);
            return MECH_EXIT_INPUT;
        }
        s->cols[j] = name;
        s->weight[j] = cl == &file_cols && file_cols.n ? mf->weights[j] : 1.0;
    }
    s->fp.ncols = n;
    for (int w = 0; w < a->weights.n; w++) {
        const char *eq = strchr(a->weights.v[w], '=');
        char *end = NULL;
        double x = eq ? strtod(eq + 1, &end) : NAN;
        int found = 0;
        for (int j = 0; eq && j < n; j++)
            if (strncmp(s->cols[j], a->weights.v[w], (size_t)(eq - a->weights.v[w])) == 0 &&
                s->cols[j][eq - a->weights.v[w]] == '\0') {
                s->weight[j] = x;
                found = 1;
            }
        if (!eq || !end || *end || !(x >= 0.0) || !isfinite(x) || !found)
            return cmd_usage_error("fit", "--weight needs COLUMN=W, a target column and a "
                                   "number >= 0, not '%s'", a->weights.v[w]);
    }
    return -1;
}

/* The CSV's driver and target values in SI, checked against the units of
 * mech solve's columns. */
static int convert_targets(fit_setup *s)
{
    const compare_table *t = &s->csv;
    int nq = (int)t->nrows, nc = s->fp.ncols;
    s->q = xcalloc((size_t)nq, sizeof *s->q);
    s->target = xcalloc((size_t)nq * (size_t)nc, sizeof *s->target);
    if (!s->q || !s->target)
        return MECH_EXIT_IO;
    for (int j = -1; j < nc; j++) {
        int c = j < 0 ? 0 : s->csv_col[j];
        const char *si = j < 0 ? s->fp.qunit : s->col_unit[j], *u = t->units[c];
        double scale = 1.0;
        dim d;
        const char *rest = u;
        char du[32] = "";
        if (*u && (!unit_parse(u, &scale, &d, &rest) || *rest)) {
            fprintf(stderr, "mech fit: %s: column '%s': unknown unit '%s'\n", s->target_path,
                    t->names[c], u);
            return MECH_EXIT_INPUT;
        }
        if (*u)
            dim_format(d, du, sizeof du);
        if (strcmp(du, si) != 0 && !(*u == '\0' && strcmp(si, "-") == 0)) {
            fprintf(stderr, "mech fit: %s: column '%s' is in '%s', where mech solve's is in "
                    "%s (write the unit in the header: '%s [%s]')\n", s->target_path, t->names[c], u,
                    si, t->names[c], si);
            return MECH_EXIT_INPUT;
        }
        for (int i = 0; i < nq; i++) {
            double v = t->values[(size_t)i * t->ncols + (size_t)c] * scale;
            if (j < 0 && isnan(v)) {
                fprintf(stderr, "mech fit: %s: row %d has no driver position\n", s->target_path,
                        i + 2);
                return MECH_EXIT_INPUT;
            }
            if (j < 0)
                s->q[i] = v;
            else
                s->target[(size_t)i * nc + j] = v;
        }
    }
    if (strcmp(t->names[0], "q") != 0 && strcmp(t->names[0], "t") != 0) {
        fprintf(stderr, "mech fit: %s: the first column must be the driver position 'q' (or "
                "the time 't'), as in mech solve's CSV, not '%s'\n", s->target_path, t->names[0]);
        return MECH_EXIT_INPUT;
    }
    s->fp.nq = nq;
    s->fp.q = s->q;
    s->fp.target = s->target;
    if (nq * nc < s->fp.nfree) {
        fprintf(stderr, "mech fit: %d target values for %d free parameters: give at least as "
                "many targets as parameters\n", nq * nc, s->fp.nfree);
        return MECH_EXIT_INPUT;
    }
    return -1;
}

/* The free parameters of the file's fit: section (names, bounds in SI). */
static int free_of_file(fit_setup *s, const model_fit *mf)
{
    if (!mf || !mf->nfree)
        return cmd_usage_error("fit", "%s", "--free NAME,... is needed (or a 'fit:' section "
                               "with 'free:' in the file): which parameters to fit");
    if (mf->nfree > MAX_FREE)
        return cmd_usage_error("fit", "%s", "at most 32 free parameters");
    for (int k = 0; k < mf->nfree; k++) {
        s->names[k] = mf->free[k].name;
        s->lo[k] = mf->free[k].lo;
        s->hi[k] = mf->free[k].hi;
    }
    s->fp.nfree = mf->nfree;
    s->bounds_given = 1;
    return -1;
}

/* The targets' CSV: --target, or the fit: section's (relative to the file's
 * folder), refused when it is also the output. */
static int target_path(fit_setup *s, const fit_args *a, const model_fit *mf)
{
    const char *t = a->target ? a->target : mf ? mf->target : NULL;
    if (!t)
        return cmd_usage_error("fit", "%s", "--target CSV is needed (or 'target:' in the "
                               "file's 'fit:' section): what to fit to");
    const char *slash = strrchr(a->file, '/');
    int rel = !a->target && t[0] != '/' && slash;
    int len = rel ? (int)(slash - a->file) + 1 : 0;
    if ((size_t)snprintf(s->target_path, sizeof s->target_path, "%.*s%s", len, a->file, t) >=
        sizeof s->target_path)
        return cmd_usage_error("fit", "the targets' path is too long: %s", t);
    const char *inputs[2] = {a->file, s->target_path};
    return cmd_refuse_input("fit", a->out, inputs, 2);
}

static int setup(fit_setup *s, const fit_args *a, mech_model **m)
{
    int code = cmd_load_checked(a->file, m);
    if (code != MECH_EXIT_OK)
        return code;
    const model_fit *mf = (*m)->fit;
    code = a->free ? split_free(s, a->free) : free_of_file(s, mf);
    if (code < 0)
        code = target_path(s, a, mf);
    if (code >= 0)
        return code;
    s->whole_range = a->whole_range || (mf && mf->whole_range);
    s->fp.free_timing = a->free_timing || (mf && mf->free_timing);
    mech_diag d;
    mech_diag_init(&d);
    int rc = compare_read_csv(s->target_path, &s->csv, &d);
    if (rc == MECH_OK) {
        code = choose_columns(s, a, mf);
        if (code >= 0) {
            mech_diag_free(&d);
            return code;
        }
        s->fp.path = a->file;
        s->fp.names = s->names;
        s->fp.unit = s->unit;
        s->fp.mark = s->mark;
        s->fp.cols = s->cols;
        s->fp.col_unit = s->col_unit;
        s->fp.weight = s->weight;
        rc = fit_prepare(&s->fp, s->p0, &d);
    }
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return cmd_exit_status(rc);
    code = convert_targets(s);
    if (code >= 0)
        return code;
    if (s->fp.free_timing && s->fp.nq > MAX_TIMED)
        return cmd_usage_error("fit", "free timing: at most 512 target rows%s", "");
    if (s->fp.nq * s->fp.ncols < fit_nvars(&s->fp)) {
        fprintf(stderr, "mech fit: %d target values for %d unknowns (free timing: one per "
                "row too): give more targets\n", s->fp.nq * s->fp.ncols, fit_nvars(&s->fp));
        return MECH_EXIT_INPUT;
    }
    for (int j = s->fp.nfree; j < fit_nvars(&s->fp); j++) {
        s->lo[j] = -INFINITY;
        s->hi[j] = INFINITY;
    }
    return read_bounds(s, *m);
}

/* ---- the starts --------------------------------------------------------- */

typedef struct fit_start {
    double p[MAX_VARS];   /* the parameters, then (free timing) the driver positions */
    double objective;     /* sum of squared weighted residuals; INFINITY: rejected */
    int rc, info;
    long solves;
} fit_start;

typedef struct fit_runs {
    fit_setup *s;
    fit_start *st;
} fit_runs;

/* The radical inverse of i in base b: the Halton sequence's coordinate. */
static double halton(long i, int b)
{
    double f = 1.0, r = 0.0;
    for (; i > 0; i /= b) {
        f /= b;
        r += f * (double)(i % b);
    }
    return r;
}

static const int primes[MAX_FREE] = {2,  3,  5,  7,  11, 13, 17, 19, 23, 29, 31,
                                     37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79,
                                     83, 89, 97, 101, 103, 107, 109, 113, 127, 131};

/* Start i: the file's values (i = 0), else the Halton point i of the
 * bounds (an unbounded parameter keeps the file's value). */
static void start_point(const fit_setup *s, long i, double *p)
{
    for (int k = 0; k < s->fp.nfree; k++) {
        int b = isfinite(s->lo[k]) && isfinite(s->hi[k]);
        p[k] = i == 0 || !b ? s->p0[k] : s->lo[k] + (s->hi[k] - s->lo[k]) * halton(i, primes[k]);
    }
    for (int j = 0; s->fp.free_timing && j < s->fp.nq; j++)
        p[s->fp.nfree + j] = s->q[j];  /* the CSV's driver positions */
}

static void run_start(void *ctx, long i)
{
    fit_runs *runs = ctx;
    fit_setup *s = runs->s;
    fit_start *st = &runs->st[i];
    fit_problem fp = s->fp;  /* this thread's: its own count of solves */
    fp.nsolves = 0;
    double *r = xcalloc((size_t)fit_nres(&fp), sizeof *r);
    start_point(s, i, st->p);
    st->objective = INFINITY;
    st->rc = r ? fit_lm(&fp, s->lo, s->hi, st->p, r, &st->objective, &st->info) : MECH_ENOMEM;
    if (st->rc == MECH_OK && s->whole_range) {
        mech_diag d;
        mech_diag_init(&d);
        st->rc = fit_check_range(&fp, st->p, &d);  /* a violated constraint: rejected */
        mech_diag_free(&d);
    }
    if (st->rc != MECH_OK)
        st->objective = INFINITY;
    st->solves = fp.nsolves;
    free(r);
}

static int by_objective(const void *a, const void *b)
{
    const fit_start *x = a, *y = b;
    return (x->objective > y->objective) - (x->objective < y->objective);
}

/* Two solutions are one when every parameter agrees to 1e-6 of its bounds'
 * width (or of its value, unbounded). */
static int same_solution(const fit_setup *s, const double *p, const double *q)
{
    for (int k = 0; k < s->fp.nfree; k++) {
        double w = isfinite(s->hi[k] - s->lo[k]) ? s->hi[k] - s->lo[k] : fabs(p[k]) + 1e-9;
        if (fabs(p[k] - q[k]) > 1e-6 * w)
            return 0;
    }
    return 1;
}

/* ---- the summary -------------------------------------------------------- */

static void print_params(const fit_setup *s, const mech_model *m, const double *p, FILE *out)
{
    for (int k = 0; k < s->fp.nfree; k++) {
        char buf[32];
        double v = output_in_file_units(m, s->unit[k], p[k], buf, sizeof buf);
        fprintf(out, "  %-12s %.12g %s", s->names[k], v, buf);
        if (isfinite(s->lo[k])) {
            double lo = output_in_file_units(m, s->unit[k], s->lo[k], buf, sizeof buf);
            double hi = output_in_file_units(m, s->unit[k], s->hi[k], buf, sizeof buf);
            double w = s->hi[k] - s->lo[k];
            fprintf(out, "   (bounds %.10g .. %.10g %s%s)", lo, hi, buf,
                    p[k] - s->lo[k] <= 1e-6 * w   ? ", at the lower bound"
                    : s->hi[k] - p[k] <= 1e-6 * w ? ", at the upper bound"
                                                  : "");
        }
        fputc('\n', out);
    }
}

/* The worst target error (in the file's units) of the solution p. */
static void print_errors(fit_setup *s, const mech_model *m, const double *p, FILE *out)
{
    int nr = fit_nres(&s->fp);
    double *r = xcalloc((size_t)nr, sizeof *r);
    mech_diag d;
    mech_diag_init(&d);
    if (r && fit_eval(&s->fp, p, r, NULL, &d) == MECH_OK) {
        for (int j = 0; j < s->fp.ncols; j++) {
            double worst = 0.0, sum = 0.0, w = s->weight[j] > 0 ? s->weight[j] : 1.0;
            int at = 0, cnt = 0;
            for (int i = 0; i < s->fp.nq; i++) {
                if (isnan(s->target[(size_t)i * s->fp.ncols + j]))
                    continue;
                double e = fabs(r[i * s->fp.ncols + j]) / w;
                sum += e * e;
                cnt++;
                if (e >= worst) {
                    worst = e;
                    at = i;
                }
            }
            char bu[32], bq[32];
            double we = output_in_file_units(m, s->col_unit[j], worst, bu, sizeof bu);
            double rms = output_in_file_units(m, s->col_unit[j], sqrt(sum / (cnt ? cnt : 1)),
                                              bu, sizeof bu);
            double qw = s->fp.free_timing ? p[s->fp.nfree + at] : s->q[at];
            double qat = output_in_file_units(m, s->fp.qunit, qw, bq, sizeof bq);
            fprintf(out, "  %-12s worst error %.3g %s (at %s = %.6g %s), rms %.3g %s\n",
                    s->cols[j], we, bu, s->csv.names[0], qat, bq, rms, bu);
        }
    }
    mech_diag_free(&d);
    free(r);
}

/* The margin of each constraint of the file's fit: section at p (>= 0:
 * met), in the file's units. */
static void print_margins(fit_setup *s, const mech_model *m, const double *p, FILE *out)
{
    const model_fit *mf = m->fit;
    if (!mf || !fit_ncons(&s->fp))
        return;
    double *r = xcalloc((size_t)fit_nres(&s->fp), sizeof *r);
    mech_diag d;
    mech_diag_init(&d);
    if (r && fit_eval(&s->fp, p, r, NULL, &d) == MECH_OK) {
        int base = s->fp.nq * s->fp.ncols;
        fprintf(out, "constraint margins (>= 0: met):\n");
        for (int c = 0; c < s->fp.ncons; c++) {
            char bu[32];
            double v = output_in_file_units(m, mf->cons[c].unit, -r[base + c], bu, sizeof bu);
            fprintf(out, "  %-24s margin %.6g%s%s%s\n", mf->cons[c].text, v, bu[0] ? " " : "",
                    bu, -r[base + c] <= fit_con_tolerance(&s->fp, c) ? "   (active: on the "
                    "boundary)" : "");
        }
        if (s->fp.trans) {
            double worst = INFINITY;
            int at = 0;
            for (int i = 0; i < s->fp.nq; i++)
                if (-r[base + s->fp.ncons + i] < worst) {
                    worst = -r[base + s->fp.ncons + i];
                    at = i;
                }
            char bu[32], bq[32], lab[128];
            double mn = output_in_file_units(m, "rad", mf->trans_min + worst, bu, sizeof bu);
            double v = output_in_file_units(m, "rad", worst, bu, sizeof bu);
            double qw = s->fp.free_timing ? p[s->fp.nfree + at] : s->q[at];
            double qat = output_in_file_units(m, s->fp.qunit, qw, bq, sizeof bq);
            snprintf(lab, sizeof lab, "transmission %s/%s", mf->trans_a, mf->trans_b);
            fprintf(out, "  %-24s margin %.6g %s (least %.6g %s, at %s = %.6g %s)\n", lab, v, bu,
                    mn, bu, s->csv.names[0], qat, bq);
        }
    }
    mech_diag_free(&d);
    free(r);
}

/* ---- the best solution as a file ----------------------------------------- */

typedef struct edited {
    const char *text;
    size_t len;
    size_t at[MAX_FREE][2];  /* [start, end) of each replaced value, sorted */
    char value[MAX_FREE][64];
    int n;
} edited;

static int emit_edited(FILE *f, const void *ctx)
{
    const edited *e = ctx;
    size_t pos = 0;
    for (int k = 0; k < e->n; k++) {
        fwrite(e->text + pos, 1, e->at[k][0] - pos, f);
        fputs(e->value[k], f);
        pos = e->at[k][1];
    }
    fwrite(e->text + pos, 1, e->len - pos, f);
    return ferror(f) ? -1 : 0;
}

/* The value text of the parameter whose key starts at line:col (1-based, as
 * the loader's marks):
 * "NAME: VALUE  # comment" or "NAME: {value: VALUE, tolerance: T}". */
static int find_value(const char *text, size_t len, mech_mark mk, size_t *from, size_t *to)
{
    size_t pos = 0;
    for (int line = 1; line < mk.line && pos < len; pos++)
        if (text[pos] == '\n')
            line++;
    pos += mk.col > 0 ? (size_t)mk.col - 1 : 0;
    if (pos >= len)
        return -1;
    const char *eol = memchr(text + pos, '\n', len - pos);
    size_t end = eol ? (size_t)(eol - text) : len, bol = pos;
    while (bol > 0 && text[bol - 1] != '\n')
        bol--;
    int depth = 0;  /* inside a flow mapping: {r: 20 mm, l: 60 mm} */
    for (size_t i = bol; i < pos; i++)
        depth += text[i] == '{' ? 1 : text[i] == '}' ? -1 : 0;
    const char *colon = memchr(text + pos, ':', end - pos);
    if (!colon)
        return -1;
    size_t v = (size_t)(colon - text) + 1;
    while (v < end && text[v] == ' ')
        v++;
    if (v < end && text[v] == '{') {
        const char *val = strstr(text + v, "value:");
        if (!val || (size_t)(val - text) >= end)
            return -1;
        v = (size_t)(val - text) + 6;
        while (v < end && text[v] == ' ')
            v++;
        size_t e = v;
        while (e < end && text[e] != ',' && text[e] != '}')
            e++;
        *from = v;
        *to = e;
    } else if (v < end && (text[v] == '"' || text[v] == '\'')) {
        const char *q = memchr(text + v + 1, text[v], end - v - 1);
        if (!q)
            return -1;
        *from = v;
        *to = (size_t)(q - text) + 1;
        return 0;
    } else {
        size_t e = v;
        while (e < end && !(text[e] == '#' && e > v && (text[e - 1] == ' ' || text[e - 1] == '\t')) &&
               !(depth > 0 && (text[e] == ',' || text[e] == '}')))
            e++;
        *from = v;
        *to = e;
    }
    while (*to > *from && (text[*to - 1] == ' ' || text[*to - 1] == '\t'))
        (*to)--;
    return *to > *from ? 0 : -1;
}

/* The edited text loaded again: MECH_OK when its free parameters have the
 * values p (to 1e-12 relative: the text holds 15 digits), else an error in
 * d and nothing is written. */
static int check_edited(const fit_setup *s, const edited *e, const double *p, mech_diag *d)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    if (!f)
        return diag_nomem(d, s->fp.path, (mech_mark){0, 0});
    emit_edited(f, e);
    fclose(f);
    mech_model *m = NULL;
    mech_diag quiet;
    mech_diag_init(&quiet);
    int rc = text ? mech_load_string(text, size, s->fp.path, &m, &quiet) : MECH_ENOMEM;
    mech_diag_free(&quiet);
    for (int k = 0; rc == MECH_OK && k < s->fp.nfree; k++)
        for (int i = 0; i < m->nparams; i++)
            if (strcmp(m->params[i].name, s->names[k]) == 0 &&
                !(fabs(m->params[i].value - p[k]) <= 1e-12 * fabs(p[k]) + 1e-300))
                rc = MECH_EINPUT;
    mech_model_free(&m);
    free(text);
    if (rc != MECH_OK)
        return diag_error(d, s->fp.path, (mech_mark){0, 0}, "mech fit: the file with the "
                          "parameters' values replaced in its text does not load with those "
                          "values (a value written in a form this edit does not handle); no "
                          "file written");
    return MECH_OK;
}

static int write_best(const fit_setup *s, const mech_model *m, const double *p, const char *out)
{
    FILE *f = fopen(s->fp.path, "rb");
    if (!f) {
        fprintf(stderr, "mech fit: cannot read %s again\n", s->fp.path);
        return MECH_EXIT_IO;
    }
    size_t cap = 1 << 16, len = 0;
    char *text = malloc(cap);
    for (size_t got; text && (got = fread(text + len, 1, cap - len, f)) > 0;) {
        len += got;
        if (len == cap) {
            char *t = realloc(text, cap *= 2);
            if (!t) {
                free(text);
                text = NULL;
            }
            text = t;
        }
    }
    fclose(f);
    if (!text)
        return MECH_EXIT_IO;
    edited e = {text, len, {{0}}, {{0}}, 0};
    for (int k = 0; k < s->fp.nfree; k++) {
        size_t a, b;
        if (find_value(text, len, s->mark[k], &a, &b) < 0) {
            fprintf(stderr, "%s:%d:%d: error: mech fit: cannot find the value of parameter '%s' "
                    "in the text to replace it; no file written\n", s->fp.path,
                    s->mark[k].line, s->mark[k].col, s->names[k]);
            free(text);
            return MECH_EXIT_INPUT;
        }
        char buf[32];
        double v = output_in_file_units(m, s->unit[k], p[k], buf, sizeof buf);
        int i = e.n++;
        while (i > 0 && e.at[i - 1][0] > a) {  /* sorted by position */
            memcpy(e.at[i], e.at[i - 1], sizeof e.at[i]);
            memcpy(e.value[i], e.value[i - 1], sizeof e.value[i]);
            i--;
        }
        e.at[i][0] = a;
        e.at[i][1] = b;
        snprintf(e.value[i], sizeof e.value[i], "%.15g%s%s", v, s->unit[k][0] ? " " : "",
                 s->unit[k][0] ? buf : "");
    }
    mech_diag d;
    mech_diag_init(&d);
    int rc = check_edited(s, &e, p, &d);
    if (rc == MECH_OK)
        rc = write_file_whole(out, emit_edited, &e, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    free(text);
    return rc == MECH_OK ? -1 : cmd_exit_status(rc);
}

/* ---- the command -------------------------------------------------------- */

static int report(fit_setup *s, const fit_args *a, const mech_model *m, fit_start *st, int n,
                  double seconds)
{
    long solves = 0;
    int ok = 0, violated = 0;
    for (int i = 0; i < n; i++) {
        solves += st[i].solves;
        ok += st[i].rc == MECH_OK;
        violated += st[i].rc == MECH_ESOLVE && st[i].info == -2;
    }
    for (int i = 0; i < n; i++)
        if (st[i].rc != MECH_OK && st[i].rc != MECH_ESOLVE) {
            fprintf(stderr, "mech fit: out of memory\n");
            return MECH_EXIT_IO;
        }
    qsort(st, (size_t)n, sizeof *st, by_objective);
    FILE *out = stdout;
    fprintf(out, "mech fit: %s, %d free parameter%s, %d target row%s x %d column%s\n", a->file,
            s->fp.nfree, s->fp.nfree == 1 ? "" : "s", s->fp.nq, s->fp.nq == 1 ? "" : "s",
            s->fp.ncols, s->fp.ncols == 1 ? "" : "s");
    char viol[64] = "";
    if (fit_ncons(&s->fp))
        snprintf(viol, sizeof viol, ", %d of them violating a constraint", violated);
    fprintf(out, "starts       %d (%d assembled at every target%s%s, %d rejected%s)\n", n, ok,
            s->whole_range ? " and over the whole range" : "",
            fit_ncons(&s->fp) ? " within the constraints" : "", n - ok, viol);
    fprintf(out, "solves       %ld (each the file loaded and the targets' rows solved)\n",
            solves);
    fprintf(out, "time         %.3g s\n", seconds);
    if (!ok) {
        fprintf(stderr, "mech fit: no start assembles at every target%s%s: no solution (the "
                "bounds too narrow, a target past a limit position for every value tried, or "
                "the constraints exclude the fits found)%s\n",
                s->whole_range ? " and over the whole range" : "",
                fit_ncons(&s->fp) ? " within the constraints" : "",
                a->out ? ", no file written" : "");
        return MECH_EXIT_SOLVE;
    }
    static const char *const why[] = {
        "improper input", "the sum of squares cannot fall by more than 1e-15 (ftol)",
        "the relative step is below 1e-12 (xtol)", "both ftol and xtol",
        "the gradient is orthogonal to the residuals", "the evaluation limit",
        "ftol is too small", "xtol is too small", "gtol is too small"};
    int info = st[0].info;
    fprintf(out, "objective    %.6g (sum of squared weighted residuals, SI)\n", st[0].objective);
    fprintf(out, "stopped      %s%s (lmder info %d)\n",
            info >= 1 && info <= 4 ? "converged: " : "not converged: ",
            info >= 0 && info <= 8 ? why[info] : "interrupted", info);
    fprintf(out, "best solution:\n");
    print_params(s, m, st[0].p, out);
    if (s->fp.free_timing) {
        fprintf(out, "timing (the fitted driver position of each target row):\n ");
        for (int j = 0; j < s->fp.nq; j++) {
            char bq[32];
            double v = output_in_file_units(m, s->fp.qunit, st[0].p[s->fp.nfree + j], bq,
                                            sizeof bq);
            fprintf(out, " %.10g%s", v, j + 1 < s->fp.nq ? "" : " ");
            if (j + 1 == s->fp.nq)
                fprintf(out, "%s", bq);
        }
        fputc('\n', out);
    }
    fprintf(out, "target errors:\n");
    print_errors(s, m, st[0].p, out);
    print_margins(s, m, st[0].p, out);
    if (!a->quiet && ok > 1) {
        fprintf(out, "distinct solutions (best first):\n");
        int shown = 0;
        for (int i = 0; i < ok && shown < MAX_SHOWN; i++) {
            int dup = 0;
            for (int j = 0; j < i && !dup; j++)
                dup = same_solution(s, st[i].p, st[j].p);
            if (dup)
                continue;
            fprintf(out, "  %d. objective %.6g:", ++shown, st[i].objective);
            for (int k = 0; k < s->fp.nfree; k++) {
                char buf[32];
                double v = output_in_file_units(m, s->unit[k], st[i].p[k], buf, sizeof buf);
                fprintf(out, " %s=%.8g", s->names[k], v);
            }
            fputc('\n', out);
        }
    }
    if (a->out) {
        int code = write_best(s, m, st[0].p, a->out);
        if (code >= 0)
            return code;
        fprintf(out, "written      %s\n", a->out);
    }
    return MECH_EXIT_OK;
}

int cmd_fit(int argc, char **argv)
{
    fit_args a = {0};
    int code = cmd_opts_parse(&cmd_fit_spec, argc, argv, &a);
    if (code >= 0)
        return code;
    fit_setup *s = xcalloc(1, sizeof *s);
    mech_model *m = NULL;
    if (!s)
        return MECH_EXIT_IO;
    code = setup(s, &a, &m);
    if (code < 0) {
        int bounded = 1, any = 0;  /* every free parameter has bounds; one has */
        for (int k = 0; k < s->fp.nfree; k++) {
            bounded &= isfinite(s->lo[k]) && isfinite(s->hi[k]);
            any |= isfinite(s->lo[k]) && isfinite(s->hi[k]);
        }
        int n = a.starts                 ? a.starts
                : m->fit && m->fit->starts ? m->fit->starts
                : bounded                  ? 16
                                           : 1;
        if (n > 1 && !any) {
            fprintf(stderr, "mech fit: %d starts need bounds on a free parameter at least "
                    "(NAME=LO:HI)\n", n);
            code = MECH_EXIT_INPUT;
        } else {
            fit_start *st = xcalloc((size_t)n, sizeof *st);
            fit_runs runs = {s, st};
            double t0 = clock_seconds();
            if (st) {
                parallel_run(n, a.jobs ? a.jobs : parallel_default_jobs(), run_start, &runs);
                code = report(s, &a, m, st, n, clock_seconds() - t0);
            } else {
                code = MECH_EXIT_IO;
            }
            free(st);
        }
    }
    mech_model_free(&m);
    setup_free(s);
    free(s);
    return code;
}
