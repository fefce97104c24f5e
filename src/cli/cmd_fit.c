/* src/cli/cmd_fit.c: `mech fit`, dimensional synthesis (docs/synthesis.md):
 * free parameters fitted so that solved output columns meet targets read
 * from a CSV, by least squares (src/study/fit_lm.c) from several starts; the best
 * solution written as a copy of the file with those parameters' values
 * replaced in its text (comments kept). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "study.h"  /* first: output.h (also cli.h's) declares fit_setup after it */
#include "cli.h"
#include "base.h"
#include "output.h"

enum { MAX_COLS = FIT_MAX_COLS, MAX_SHOWN = 5, MAX_FREE = FIT_MAX_FREE };

typedef struct fit_list {
    const char *v[MAX_COLS];
    int n;
} fit_list;

typedef struct fit_args {
    const char *file, *out, *target, *free, *transmission;
    const char *plot;            /* --plot FILE.svg */
    fit_list columns;            /* --column NAME (repeatable) */
    fit_list weights;            /* --weight NAME=W (repeatable) */
    int starts, jobs, quiet;
    int seed;                    /* --seed S: the starts' random shift (0: none) */
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
    {.names = "--seed", .kind = CMD_OPT_INT, .at = AT(seed), .lo = 0, .hi = 2147483647,
     .expect = "needs a whole number from 0 to 2147483647", .label = "--seed S",
     .help = "shift the Halton starts by a random fraction of the\n"
             "bounds drawn from S (another spread-out set of starts\n"
             "for each S; default 0: no shift). The first start is\n"
             "the file's values whatever S"},
    {.names = "--whole-range", .kind = CMD_OPT_FLAG, .at = AT(whole_range), .flag = 1,
     .label = "--whole-range",
     .help = "a constraint: the solution must assemble over the file's\n"
             "whole driver range (a crank from 0 to 360 deg turns\n"
             "fully: a Grashof crank); a solution that does not is\n"
             "rejected"},
    {.names = "--transmission", .kind = CMD_OPT_TEXT, .at = AT(transmission),
     .label = "--transmission A,B,M",
     .help = "a constraint that steers: the angle between links A and\n"
             "B stays within [M, 180 deg - M] at every target (e.g.\n"
             "coupler,rocker,40deg; replaces the fit: section's)"},
    {.names = "--free-timing", .kind = CMD_OPT_FLAG, .at = AT(free_timing), .flag = 1,
     .label = "--free-timing",
     .help = "each target's driver position is an unknown too (the\n"
             "CSV's is its start): a path through the points, whatever\n"
             "the crank angle at each; needs position and rate columns"},
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output FILE",
     .help = "write the best solution as a copy of the mechanism file\n"
             "with the free parameters' values replaced (comments kept;\n"
             "written whole or not at all, never over an input)"},
    {.names = "--plot", .kind = CMD_OPT_TEXT, .at = AT(plot), .label = "--plot FILE.svg",
     .help = "draw the targets, the best solution's curve over the\n"
             "file's driver range and the start's (dashed): the path\n"
             "of a point whose x and y are targets, else the first\n"
             "target column against the driver (docs/synthesis.md)"},
    CMD_JOBS_ENTRY(AT(jobs)),
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = AT(quiet), .flag = 1,
     .label = "-q, --quiet", .help = "print only the best solution's summary"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_fit_spec = {
    .name = "fit",
    .summary = "fit parameters so that outputs meet targets (synthesis)",
    .usage = "usage: mech fit FILE --free NAME[=LO:HI],... --target TARGETS.csv\n"
             "                [--column NAME]... [--weight NAME=W]... [--starts N] [--seed S]\n"
             "                [--whole-range] [--free-timing] [--transmission A,B,MIN]\n"
             "                [-j N] [-o BEST.yaml] [--plot FIT.svg] [--quiet]\n"
             "       mech fit FILE [-o BEST.yaml]   (the file's fit: section)\n",
    .about = "Dimensional synthesis: find the values of the file's free parameters that\n"
             "make the solved outputs meet the targets at the targets' driver positions:\n"
             "path generation (a point's x and y), function generation (a link's angle\n"
             "against the input), motion generation (x, y and angle). Least squares by\n"
             "MINPACK's Levenberg-Marquardt (lmder) with the exact Jacobian from the\n"
             "sensitivities (docs/sensitivity.md); bounds by a change of variable; many\n"
             "starts. A start or a solution where the mechanism does not assemble at\n"
             "every target is rejected (docs/synthesis.md). The file's 'fit:' section\n"
             "(docs/format.md) states the same problem; the options replace its parts.\n"
             "Its 'constraints:' (\"l / r >= 1.5\", \"r + d <= l + b\") and 'transmission:'\n"
             "(a least angle between two links) steer the fit and are checked after it: a\n"
             "result that violates one is never reported; their margins are printed.\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 a solution found (the summary says how close it is), 1 no\n"
             "start assembles at every target within the constraints, 2 invalid file,\n"
             "targets or usage, 3 a file cannot be read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech fit FILE --free NAME,... --target CSV)",
};

/* ---- the problem: fit_setup_read (src/output/fit_setup.c) ---------------- */

static int setup(fit_setup *s, const fit_args *a, mech_model **m)
{
    int code = cmd_load_checked(a->file, m);
    if (code != MECH_EXIT_OK)
        return code;
    fit_request rq = {a->file, a->free, a->target, a->columns.v, a->columns.n, a->weights.v,
                      a->weights.n, a->whole_range, a->free_timing, a->transmission};
    mech_diag d;
    mech_diag_init(&d);
    int rc = fit_setup_read(s, &rq, *m, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return cmd_exit_status(rc);
    const char *inputs[2] = {a->file, s->target_path};
    if (a->plot && (strcmp(a->plot, "-") == 0 || !a->plot[0]))
        return cmd_usage_error("fit", "--plot needs a file name for the SVG, not '%s'", a->plot);
    if (a->plot && a->out && strcmp(a->plot, a->out) == 0)
        return cmd_usage_error("fit", "--plot and -o name the same file '%s'", a->out);
    code = cmd_refuse_input("fit", a->plot, inputs, 2);
    return code >= 0 ? code : cmd_refuse_input("fit", a->out, inputs, 2);
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
    const model_fit *mf = m->fit;  /* the expressions' texts (ncons > 0: there is one) */
    if (!fit_ncons(&s->fp))
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
            char bu[32], bq[32], lab[160];
            double mn = output_in_file_units(m, "rad", s->fp.trans_min + worst, bu, sizeof bu);
            double v = output_in_file_units(m, "rad", worst, bu, sizeof bu);
            double qw = s->fp.free_timing ? p[s->fp.nfree + at] : s->q[at];
            double qat = output_in_file_units(m, s->fp.qunit, qw, bq, sizeof bq);
            snprintf(lab, sizeof lab, "transmission %s/%s", s->fp.trans_a, s->fp.trans_b);
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

/* ---- the plot of the fit (--plot) ---------------------------------------- */

/* --plot: the best solution p and the start solved over the file's driver
 * range, the targets as points, one SVG (fit_figure_write: whole or
 * nothing). -1, or an exit status. */
static int write_plot(fit_setup *s, const mech_model *m, const double *p, const char *path)
{
    mech_table tf = {0}, ts = {0};
    mech_diag d;
    mech_diag_init(&d);
    int rc = fit_sweep(&s->fp, p, &tf, &d);
    if (rc == MECH_OK || rc == MECH_ESOLVE)
        rc = fit_sweep(&s->fp, s->p0, &ts, &d);
    if (rc != MECH_OK && rc != MECH_ESOLVE) {
        mech_diag_print(&d, stderr);
        fprintf(stderr, "mech fit: --plot: the file cannot be solved over its range; no plot "
                "written\n");
    } else {
        char subtitle[160];
        snprintf(subtitle, sizeof subtitle, "%.80s: fitted (solid), start (dashed), targets "
                 "(points)", m->name ? m->name : s->fp.path);
        fit_curves c = {.curve = &tf, .curve_label = "fitted", .start = &ts,
                        .timing = s->fp.free_timing ? p + s->fp.nfree : NULL};
        mech_diag_free(&d);
        mech_diag_init(&d);
        rc = fit_figure_write(s, m, &c, subtitle, path, &d);
        mech_diag_print(&d, stderr);
    }
    mech_diag_free(&d);
    mech_table_free(&tf);
    mech_table_free(&ts);
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
    if (a->plot) {
        int code = write_plot(s, m, st[0].p, a->plot);
        if (code >= 0)
            return code;
        fprintf(out, "plotted      %s\n", a->plot);
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
    int n = 1;
    if (code < 0) {
        mech_diag d;
        mech_diag_init(&d);
        if (fit_setup_starts(s, m, a.starts, &n, &d) != MECH_OK)
            code = MECH_EXIT_INPUT;
        mech_diag_print(&d, stderr);
        mech_diag_free(&d);
    }
    if (code < 0) {
        fit_start *st = xcalloc((size_t)n, sizeof *st);
        double t0 = clock_seconds();
        s->fp.seed = (unsigned long)a.seed;
        int rc = st ? fit_run_starts(&s->fp, s->lo, s->hi, s->p0, s->whole_range, n, a.jobs, st)
                    : MECH_ENOMEM;
        if (rc == MECH_OK) {
            code = report(s, &a, m, st, n, clock_seconds() - t0);
        } else {
            fprintf(stderr, "mech fit: out of memory\n");
            code = MECH_EXIT_IO;
        }
        free(st);
    }
    mech_model_free(&m);
    fit_setup_free(s);
    free(s);
    return code;
}
