/* src/cmd_sweep.c: `mech sweep`, a grid of variants of one mechanism, or
 * --random N samples within the parameters' tolerances (docs/batch.md).
 * Each variant builds its model with some `parameters:` replaced, solves it
 * (through the sweep's one analysis: sweep_variants.c, variant_regs.c), and
 * reduces the table to the metrics asked for.
 * Variants run on worker threads; rows come out in variant order, so the
 * result does not depend on the workers, and --shard K/M splits the grid
 * over machines (variant index i % M == K) with the index as first column
 * for a deterministic merge (sort -n). */
#include <errno.h>
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_manifest.h"
#include "cmd_rows.h"
#include "commands.h"
#include "internal.h"
#include "output.h"
#include "sweep_random.h"
#include "sweep_variants.h"
#include "flywheel.h"

const char cmd_sweep_help[] =
    "usage: mech sweep FILE --vary NAME=FROM:TO:COUNT [--vary ...] [--list NAME=A,B,...]\n"
    "                  [--metric M ...] [-o OUT.csv] [-j N] [--shard K/M] [--forces]\n"
    "       mech sweep FILE --random N [--seed S] [--metric M ...] [options as above]\n"
    "                  [--index-offset N] [--resume] [--unsolvable-ok]\n"
    "\n"
    "Solve a grid of variants of one mechanism, changing its named parameters\n"
    "(the file's 'parameters:'), and write one summary row per variant: the\n"
    "variant's index, its parameter values, its status, and the metrics.\n"
    "A variant that cannot assemble over the driver range is reported as such\n"
    "(status 'no-assembly', 'singular' or 'self-locking' when joint friction\n"
    "locks it), not as a failure of the run. The CSV is mech solve's: headers\n"
    "'name [unit]', values in SI (r=30mm is 0.03 under 'r [m]'; bare numbers '-';\n"
    "transmission angles in rad).\n"
    "\n"
    "options:\n"
    "  --vary NAME=FROM:TO:COUNT  COUNT values from FROM to TO (inclusive); a unit\n"
    "                    may follow the numbers, the same on both: l=130mm:150mm:5\n"
    "  --list NAME=A,B,...        the given values (each may carry a unit)\n"
    "                    several --vary/--list make a grid (every combination)\n"
    "  --random N        N variants with every parameter that has a tolerance\n"
    "                    (r: {value: 40 mm, tolerance: 0.05 mm}) drawn uniformly\n"
    "                    within value +- tolerance, independently (a Monte Carlo\n"
    "                    check of 'mech solve --tolerances'); not with --vary/--list\n"
    "  --seed S          the samples' seed, 0 to 2^64-1 (default 1): the same seed\n"
    "                    gives the same rows, whatever -j and --shard\n"
    "  --metric M        a summary of one output column over the sweep; M is\n"
    "                    range:COL (max - min, e.g. range:x_B.s, the stroke),\n"
    "                    max:COL, min:COL, maxabs:COL (e.g. maxabs:driver.torque,\n"
    "                    the peak torque), or transmission:LINK1,LINK2 (the\n"
    "                    smallest angle between the two links, 0..pi/2 rad, e.g. the\n"
    "                    transmission angle of a four-bar: coupler,rocker), or\n"
    "                    flywheel:CS (the flywheel inertia, kg*m^2, for the\n"
    "                    coefficient of speed fluctuation CS over the file's\n"
    "                    driver range, one full turn; needs --forces)\n"
    "                    (default: the number of rows solved)\n"
    "  -o FILE           write the summary CSV to FILE (default: standard output)\n"
    "  -j, --jobs N      worker threads (default: the processors this process may\n"
    "                    run on: its CPU affinity, as set by taskset or Slurm)\n"
    "  --shard K/M       only the variants with index % M == K; the CSV then starts\n"
    "                    with a '# mech-manifest' line, for mech merge\n"
    "  --index-offset N  number the variants from N (a grid that continues another\n"
    "                    in one index space for mech merge; also writes the manifest)\n"
    "  --resume          continue OUT.partial, the rows of a run that was stopped\n"
    "                    (rows are written there as they finish; needs -o)\n"
    "  --unsolvable-ok   exit 0 also when no variant could be solved (they are rows\n"
    "                    with their status); bad input and I/O still fail\n"
    "  --forces          also the force analysis (needed for driver.torque metrics)\n"
    "  -q, --quiet       no progress report (a bar on a terminal, else a line every\n"
    "                    5 s)\n"
    "  -h, --help        show this help\n"
    "\n"
    "exit status: 0 the sweep ran and at least one variant was solved, 1 no variant\n"
    "could be solved (the rows are still written), 2 bad usage or an invalid file,\n"
    "parameter or metric column, 3 a file cannot be read or written, or out of memory\n";

enum { MAX_VARY = 32, MAX_GRID = 8, MAX_METRICS = 32 };

typedef struct axis {
    char name[64];
    char **texts;    /* [count] parameter texts, e.g. "135 mm" */
    double *si;      /* [count] their values in SI (or the bare number) */
    char unit[32];   /* the SI unit of the values, "-" for bare numbers */
    int count;
    double nominal, tol;  /* --random: the file's value and tolerance (SI) */
} axis;

typedef enum { MET_RANGE, MET_MAX, MET_MIN, MET_MAXABS, MET_TRANSMISSION, MET_FLYWHEEL } metric_kind;

typedef struct metric {
    metric_kind kind;
    char col[128], col2[128];  /* column names (transmission: two link names) */
    char label[160];
    char unit[32];             /* of the column (transmission: rad) */
    double cs;                 /* flywheel: coefficient of speed fluctuation */
} metric;

typedef struct variant {
    long index;              /* offset included */
    const char *status;      /* ok, no-assembly, singular, invalid, error */
    int rows;
    double value[MAX_METRICS];
    char *messages;
    size_t msize;
} variant;

typedef struct sweep_run {
    const char *file;
    long offset;          /* --index-offset: variant i of the grid is row offset + i */
    int shard_k, shard_m; /* --shard K/M */
    axis axes[MAX_VARY];
    int naxes;
    metric metrics[MAX_METRICS];
    int nmetrics;
    int forces;
    long nrandom;         /* --random N (0: a grid) */
    uint64_t seed;        /* --seed S */
    long nvars;           /* variants in this shard */
    int quiet;            /* -q: no progress report */
    atomic_long done;     /* variants finished */
    cmd_progress progress;
    rowfile rows;         /* the rows as they finish (src/cmd_rows.h) */
} sweep_run;


/* "130mm" -> 130 and "mm" */
static int split_number(const char *s, double *v, char *unit, size_t size)
{
    char *end;
    *v = strtod(s, &end);
    if (end == s)
        return -1;
    while (*end == ' ')
        end++;
    snprintf(unit, size, "%s", end);
    return 0;
}

static int add_text(axis *a, const char *text)
{
    char **t = realloc(a->texts, (size_t)(a->count + 1) * sizeof *t);
    if (!t)
        return -1;
    a->texts = t;
    a->texts[a->count] = strdup(text);
    return a->texts[a->count++] ? 0 : -1;
}

/* The first control character of s (a byte below 32, or 127), or 0. The
 * values become CSV cells and terminal text: a newline would add rows. */
static int control_char(const char *s)
{
    for (; *s; s++)
        if ((unsigned char)*s < 32 || *s == 127)
            return (unsigned char)*s;
    return 0;
}

/* The SI values of axis a's texts and their unit, for the CSV (the solve
 * CSV's dialect: numbers in SI, the unit in the header). A value is a
 * quantity on its own: a number with a unit ("45mm", "0.5 rad/s") or a bare
 * number (unit "-", the file's unit where it is used); every value of one
 * parameter has the same dimension. 0, or a usage error printed (-1). */
static int axis_values(axis *a, const char *opt, const char *arg)
{
    unit_defaults u;
    unit_defaults_init(&u);
    expr_env env = {&u, NULL, 0, NULL};
    a->si = calloc((size_t)a->count, sizeof *a->si);
    if (!a->si)
        return -2;
    expr_param first = {0};
    for (int i = 0; i < a->count; i++) {
        expr_param p = {0};
        char err[256], msg[512], unit[32];
        size_t pos = 0;
        if (quantity_eval_param(a->texts[i], &env, &p, err, sizeof err, &pos) < 0 ||
            !isfinite(p.value)) {
            snprintf(msg, sizeof msg, "%s %s: value '%s' is not a number with a unit such as "
                     "45mm (%s)", opt, arg, a->texts[i], isfinite(p.value) ? err : "not finite");
            cmd_usage_error("sweep", "%s", msg);
            return -1;
        }
        if (p.bare)
            snprintf(unit, sizeof unit, "-");
        else
            dim_format(p.d, unit, sizeof unit);
        if (i == 0) {
            first = p;
            snprintf(a->unit, sizeof a->unit, "%s", unit);
        } else if (p.bare != first.bare || !dim_equal(p.d, first.d)) {
            snprintf(msg, sizeof msg, "%s %s: value '%s' is in %s, '%s' in %s; every value of "
                     "parameter '%s' has the same dimension", opt, arg, a->texts[i], unit,
                     a->texts[0], a->unit, a->name);
            cmd_usage_error("sweep", "%s", msg);
            return -1;
        }
        a->si[i] = p.value;
    }
    return 0;
}

static int parse_vary(sweep_run *r, const char *arg, int is_list)
{
    const char *opt = is_list ? "--list" : "--vary";
    char msg[256];
    int cc = control_char(arg);
    if (cc) {
        snprintf(msg, sizeof msg, "%s: a control character (byte 0x%02x) in the value; "
                 "parameter values are text on one line", opt, (unsigned)cc);
        return cmd_usage_error("sweep", "%s", msg);
    }
    if (r->naxes == MAX_GRID)
        return cmd_usage_error("sweep", "at most 8 --vary/--list options ('%s')", arg);
    const char *eq = strchr(arg, '=');
    if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof r->axes[0].name)
        return cmd_usage_error("sweep", "expected NAME=..., not '%s'", arg);
    axis *a = &r->axes[r->naxes];
    memset(a, 0, sizeof *a);
    snprintf(a->name, sizeof a->name, "%.*s", (int)(eq - arg), arg);
    for (int k = 0; k < r->naxes; k++)
        if (strcmp(r->axes[k].name, a->name) == 0) {
            snprintf(msg, sizeof msg, "%s %s: parameter '%s' is already varied by an earlier "
                     "--vary or --list (give all its values in one option)", opt, arg, a->name);
            return cmd_usage_error("sweep", "%s", msg);
        }
    char *spec = strdup(eq + 1), *save = NULL;
    int bad = 0, oom = !spec;
    if (!oom && is_list) {
        for (char *w = strtok_r(spec, ",", &save); w && !oom; w = strtok_r(NULL, ",", &save))
            oom = add_text(a, w) < 0;
        bad = a->count == 0;
    } else if (!oom) {
        char *from = strtok_r(spec, ":", &save), *to = strtok_r(NULL, ":", &save);
        char *count = strtok_r(NULL, ":", &save), *end = NULL;
        double f, t;
        char uf[32], ut[32];
        long n = count ? strtol(count, &end, 10) : 0;
        bad = !from || !to || !count || *end || n < 1 || n > 1000000 ||
              split_number(from, &f, uf, sizeof uf) < 0 ||
              split_number(to, &t, ut, sizeof ut) < 0 || strcmp(uf, ut) != 0;
        for (long i = 0; !bad && !oom && i < n; i++) {
            char text[96];
            double v = n == 1 ? f : f + (t - f) * (double)i / (double)(n - 1);
            snprintf(text, sizeof text, "%.15g%s%s", v, uf[0] ? " " : "", uf);
            oom = add_text(a, text) < 0;
        }
    }
    free(spec);
    int av = !bad && !oom ? axis_values(a, opt, arg) : 0;
    oom |= av == -2;
    if (av == -1)
        bad = 2;
    if (bad || oom) {  /* the axis is not kept: free its texts here */
        for (int i = 0; i < a->count; i++)
            free(a->texts[i]);
        free(a->texts);
        free(a->si);
        a->texts = NULL;
        a->si = NULL;
        a->count = 0;
    }
    if (bad == 2)
        return MECH_EXIT_INPUT;
    if (oom)
        return fprintf(stderr, "mech sweep: out of memory\n"), MECH_EXIT_IO;
    if (bad)
        return cmd_usage_error("sweep", is_list ? "--list needs NAME=A,B,..., not '%s'"
                                   : "--vary needs NAME=FROM:TO:COUNT with the same unit on "
                                     "FROM and TO, not '%s'", arg);
    r->naxes++;
    return -1;
}

static int parse_metric(sweep_run *r, const char *arg)
{
    static const struct { const char *prefix; metric_kind kind; } kinds[] = {
        {"range:", MET_RANGE}, {"max:", MET_MAX}, {"min:", MET_MIN},
        {"maxabs:", MET_MAXABS}, {"transmission:", MET_TRANSMISSION}, {"flywheel:", MET_FLYWHEEL}};
    if (r->nmetrics == MAX_METRICS)
        return cmd_usage_error("sweep", "at most 32 metrics ('%s')", arg);
    metric *mt = &r->metrics[r->nmetrics];
    memset(mt, 0, sizeof *mt);
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        size_t n = strlen(kinds[k].prefix);
        if (strncmp(arg, kinds[k].prefix, n) != 0 || !arg[n])
            continue;
        mt->kind = kinds[k].kind;
        snprintf(mt->label, sizeof mt->label, "%s", arg);
        for (char *c = mt->label; *c; c++)  /* the label is a CSV header cell */
            if (*c == ',')
                *c = '/';
        if (mt->kind == MET_TRANSMISSION) {
            const char *comma = strchr(arg + n, ',');
            if (!comma || comma == arg + n || !comma[1])
                return cmd_usage_error("sweep", "transmission:LINK1,LINK2, not '%s'", arg);
            snprintf(mt->col, sizeof mt->col, "%.*s.angle", (int)(comma - arg - n), arg + n);
            snprintf(mt->col2, sizeof mt->col2, "%s.angle", comma + 1);
        } else if (mt->kind == MET_FLYWHEEL) {
            char *end;
            mt->cs = strtod(arg + n, &end);
            if (*end || !(mt->cs > 0 && mt->cs < 1))
                return cmd_usage_error("sweep", "flywheel:CS needs 0 < CS < 1, not '%s'", arg);
            snprintf(mt->col, sizeof mt->col, "driver.torque");
        } else {
            snprintf(mt->col, sizeof mt->col, "%s", arg + n);
        }
        r->nmetrics++;
        return -1;
    }
    return cmd_usage_error("sweep", "unknown metric '%s' (range:, max:, min:, maxabs:, transmission:, flywheel:)", arg);
}

/* ---- the metrics' columns, checked before the grid --------------------- */

/* 0 when column `col` of metric mt is in t; else a usage error naming it,
 * with the nearest column when it looks like a typo. */
static int check_column(const metric *mt, const char *col, const mech_table *t, int r_forces)
{
    if (mech_table_column(t, col) >= 0)
        return 0;
    char msg[512];
    const char *near = NULL;
    const char **names = t->ncolumns <= 1000 ? xcalloc((size_t)t->ncolumns, sizeof *names) : NULL;
    for (int c = 0; names && c < t->ncolumns; c++)
        names[c] = t->columns[c].name;
    if (names)
        near = nearest_name(col, names, (size_t)t->ncolumns);
    snprintf(msg, sizeof msg, "--metric %s: no column '%s' in the output of 'mech solve "
             "FILE%s'%s%s%s%s", mt->label, col, r_forces ? " --forces" : "",
             near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "",
             mt->kind == MET_TRANSMISSION ? "; transmission: takes two moving links" : "");
    free(names);
    return cmd_usage_error("sweep", "%s", msg);
}

/* Every metric names columns the variants' tables will have: those of the
 * base model m (the file with the first variant's values; parameters change
 * numbers, not names), which its analysis knows without solving anything
 * (mech_analysis_header), even when the base variant cannot assemble. The note that forces
 * are all zero (no mass, no load) is printed here, once for the grid.
 * Returns -1 when all are there (or the columns cannot be known: the base
 * does not even build, and every variant will say why), else the exit
 * status. */
static int check_metrics(sweep_run *r, const mech_model *m)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_summary sum;
    int rc = mech_check(m, &sum, &d);
    mech_table t = {0};
    if (rc == MECH_OK && (r->nmetrics > 0 || r->forces) && m->has_driver) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.forces = r->forces;
        mech_analysis *a = NULL;
        rc = mech_analysis_new(m, &o, &a, &d);
        if (rc == MECH_OK)
            rc = mech_analysis_header(a, &t);
        mech_analysis_free(&a);
    }
    for (size_t i = 0; i < d.count; i++)
        if (d.entries[i].severity == MECH_SEV_NOTE &&
            strstr(d.entries[i].message, "no link has a mass"))
            fprintf(stderr, "mech sweep: note: variant 0: %s\n", d.entries[i].message);
    mech_diag_free(&d);
    int code = -1;
    if (rc == MECH_ENOMEM) {
        fprintf(stderr, "mech sweep: out of memory\n");
        code = MECH_EXIT_IO;
    }
    for (int k = 0; code < 0 && t.ncolumns > 0 && k < r->nmetrics; k++) {
        const metric *mt = &r->metrics[k];
        if (check_column(mt, mt->col, &t, r->forces) != 0 ||
            (mt->kind == MET_TRANSMISSION && check_column(mt, mt->col2, &t, r->forces) != 0))
            code = MECH_EXIT_INPUT;
    }
    for (int k = 0; code < 0 && k < r->nmetrics; k++) {  /* the header's units */
        metric *mt = &r->metrics[k];
        int c = mech_table_column(&t, mt->col);
        snprintf(mt->unit, sizeof mt->unit, "%s", mt->kind == MET_TRANSMISSION ? "rad"
                 : mt->kind == MET_FLYWHEEL ? "kg*m^2"
                 : c >= 0 && t.columns[c].unit ? t.columns[c].unit : "-");
    }
    mech_table_free(&t);
    return code;
}

/* ---- one variant ------------------------------------------------------ */

/* --random: parameter k of variant v (offset included), SI. */
static double random_value(const sweep_run *r, long v, int k)
{
    const axis *a = &r->axes[k];
    return a->nominal + a->tol * sweep_random_unit(r->seed, v, k);
}

typedef char override_text[64];

/* The parameter texts of variant v (offset included): axis k's index is a
 * mixed-radix digit; --random: the sample in SI with its unit, in text[k]. */
static void variant_overrides(const sweep_run *r, long v, mech_override *ov, override_text *text)
{
    if (r->nrandom > 0) {
        for (int k = 0; k < r->naxes; k++) {
            const axis *a = &r->axes[k];
            snprintf(text[k], sizeof text[k], "%.17g%s%s", random_value(r, v, k),
                     strcmp(a->unit, "-") ? " " : "", strcmp(a->unit, "-") ? a->unit : "");
            ov[k].name = a->name;
            ov[k].text = text[k];
        }
        return;
    }
    v -= r->offset;
    for (int k = r->naxes - 1; k >= 0; k--) {
        const axis *a = &r->axes[k];
        ov[k].name = a->name;
        ov[k].text = a->texts[v % a->count];
        v /= a->count;
    }
}

static double metric_value(const metric *mt, const mech_table *t, const mech_model *m, FILE *msg)
{
    flywheel_figures fw;
    char why[200];
    if (mt->kind == MET_FLYWHEEL && flywheel_compute(t, m, mt->cs, &fw, why, sizeof why) < 0)
        return fprintf(msg, "metric %s: %s\n", mt->label, why), NAN;
    if (mt->kind == MET_FLYWHEEL && !fw.full_cycle)
        fprintf(msg, "metric %s: the rows are not one full turn\n", mt->label);
    int c = mech_table_column(t, mt->col), c2 = -1;
    if (mt->kind == MET_TRANSMISSION)
        c2 = mech_table_column(t, mt->col2);
    if (c < 0 || (mt->kind == MET_TRANSMISSION && c2 < 0)) {
        fprintf(msg, "metric %s: no column %s in the output (see 'mech solve --outputs')\n",
                mt->label, c < 0 ? mt->col : mt->col2);
        return NAN;
    }
    double lo = INFINITY, hi = -INFINITY, big = 0.0, tmin = INFINITY;
    for (int i = 0; i < t->nrows; i++) {
        double x = mech_table_get(t, i, c);
        lo = fmin(lo, x);
        hi = fmax(hi, x);
        big = fmax(big, fabs(x));
        if (c2 >= 0) {  /* angle between the link axes, folded to 0..pi/2 */
            double d = fabs(remainder(x - mech_table_get(t, i, c2), 3.14159265358979323846));
            tmin = fmin(tmin, fmin(d, 3.14159265358979323846 - d));
        }
    }
    switch (mt->kind) {
    case MET_RANGE: return hi - lo;
    case MET_MAX: return hi;
    case MET_MIN: return lo;
    case MET_MAXABS: return big;
    case MET_TRANSMISSION: return tmin;  /* rad, as every angle of the CSVs */
    case MET_FLYWHEEL: return fw.inertia;
    }
    return NAN;
}

static void run_variant(const sweep_run *r, variant *var)
{
    FILE *msg = open_memstream(&var->messages, &var->msize);
    FILE *out = msg ? msg : stderr;
    mech_override ov[MAX_VARY];
    override_text text[MAX_VARY];
    variant_overrides(r, var->index, ov, text);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    mech_model *m = NULL;
    int rc = sweep_variant_solve(r->file, ov, r->naxes, r->forces, &t, &m, &d);
    int singular = 0, locking = 0;
    for (size_t i = 0; i < d.count; i++) {  /* the errors say what failed, not the notes */
        const char *msgtext = d.entries[i].message ? d.entries[i].message : "";
        if (d.entries[i].severity != MECH_SEV_ERROR)
            continue;
        singular |= strstr(msgtext, "singular") != NULL;
        locking |= strstr(msgtext, "friction does not converge") != NULL;
    }
    fprintf(out, "variant %ld:", var->index);
    for (int k = 0; k < r->naxes; k++)
        fprintf(out, " %s=%s", ov[k].name, ov[k].text);
    fputc('\n', out);
    mech_diag_print(&d, out);
    mech_diag_free(&d);
    if (rc == MECH_ESOLVE && t.nrequested > 0)  /* a partial sweep (issue 17) */
        fprintf(out, "%d of %d rows solved, %d gap%s\n", t.nrows, t.nrequested, t.ngaps,
                t.ngaps == 1 ? "" : "s");
    var->rows = t.nrows;
    var->status = rc == MECH_OK ? "ok"
                  : rc == MECH_ESOLVE ? (locking ? "self-locking" : singular ? "singular" : "no-assembly")
                  : rc == MECH_EIO ? "error" : "invalid";
    for (int k = 0; k < r->nmetrics; k++)
        var->value[k] = rc == MECH_OK ? metric_value(&r->metrics[k], &t, m, out) : NAN;
    mech_table_free(&t);
    mech_model_free(&m);
    if (msg)
        fclose(msg);
}

/* ---- output ------------------------------------------------------------ */

/* ",CELL": quoted as RFC 4180 says ("a ""b"", c") when it holds a comma, a
 * quote or a line end, so a text cell cannot split into more cells or rows. */
static void put_cell(FILE *f, const char *s)
{
    fputc(',', f);
    if (!s[strcspn(s, ",\"\r\n")]) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

/* The index into axis k of variant v (offset included, as variant_overrides). */
static int axis_index(const sweep_run *r, long v, int k)
{
    v -= r->offset;
    for (int j = r->naxes - 1; j > k; j--)
        v /= r->axes[j].count;
    return (int)(v % r->axes[k].count);
}

/* The shortest "%.Ng" of x that reads back as x: 0.04, not
 * 0.040000000000000001 (the value is exact either way). */
static const char *shortest(double x, char *buf, size_t size)
{
    for (int p = 1; p <= 17; p++) {
        snprintf(buf, size, "%.*g", p, x);
        if (strtod(buf, NULL) == x)
            break;
    }
    return buf;
}

static void write_header(const sweep_run *r, FILE *f)
{
    char cell[256];
    fprintf(f, "variant [-]");
    for (int k = 0; k < r->naxes; k++) {
        snprintf(cell, sizeof cell, "%s [%s]", r->axes[k].name, r->axes[k].unit);
        put_cell(f, cell);
    }
    fprintf(f, ",status [-],rows [-]");
    for (int k = 0; k < r->nmetrics; k++) {
        snprintf(cell, sizeof cell, "%s [%s]", r->metrics[k].label,
                 r->metrics[k].unit[0] ? r->metrics[k].unit : "-");
        put_cell(f, cell);
    }
    fputc('\n', f);
}

enum { ROW_SIZE = 32 * (MAX_VARY + MAX_METRICS + 4) };

/* Variant v's row, with its newline, into row[ROW_SIZE]. */
static void format_row(const sweep_run *r, const variant *v, char *row)
{
    char cell[64];
    size_t n = (size_t)snprintf(row, ROW_SIZE, "%ld", v->index);
    for (int k = 0; k < r->naxes; k++)
        n += (size_t)snprintf(row + n, ROW_SIZE - n, ",%s",
                              shortest(r->nrandom > 0 ? random_value(r, v->index, k)
                                       : r->axes[k].si[axis_index(r, v->index, k)],
                                       cell, sizeof cell));
    n += (size_t)snprintf(row + n, ROW_SIZE - n, ",%s,%d", v->status, v->rows);
    for (int k = 0; k < r->nmetrics; k++)
        n += (size_t)snprintf(row + n, ROW_SIZE - n, ",%.17g", v->value[k]);
    snprintf(row + n, ROW_SIZE - n, "\n");
}

/* Row i of this shard (variant offset + K + i*M) solved, its row appended
 * to the rows file and, when it was not solved, its messages printed:
 * nothing of a variant is kept once its row is out. */
static void sweep_job(void *ctx, int i)
{
    sweep_run *r = ctx;
    if (rows_done(&r->rows, i))
        return;  /* resumed: in the partial file already */
    variant v;
    memset(&v, 0, sizeof v);
    v.index = r->offset + r->shard_k + (long)i * r->shard_m;
    char row[ROW_SIZE];
    run_variant(r, &v);
    format_row(r, &v, row);
    rows_put(&r->rows, i, row, strcmp(v.status, "ok") != 0 ? v.messages : NULL);
    free(v.messages);
    cmd_progress_update(&r->progress, (int)(atomic_fetch_add(&r->done, 1) + 1), (int)r->nvars);
}

static void free_run(sweep_run *r)
{
    for (int k = 0; k < r->naxes; k++) {
        for (int i = 0; i < r->axes[k].count; i++)
            free(r->axes[k].texts[i]);
        free(r->axes[k].texts);
        free(r->axes[k].si);
    }
    rows_close(&r->rows);
}

/* The command line of mech sweep into r (and so). -1 when fine, else the
 * exit status (the problem printed). */
typedef struct sweep_opts {
    const char *out;
    long nthreads;
    int sharded;          /* --shard or --index-offset: a part of a larger run */
    int resume, unsolvable_ok;
    int argc;
    char **argv;
} sweep_opts;

/* The options that take a value, and those of them that do not change the
 * rows (left out of the manifest's arguments). */
static int takes_value(const char *a)
{
    static const char *const opts[] = {"--vary", "--list", "--metric", "-o", "-j", "--jobs",
                                       "--shard", "--index-offset", "--random", "--seed"};
    for (size_t k = 0; k < sizeof opts / sizeof opts[0]; k++)
        if (!strcmp(a, opts[k]))
            return 1;
    return 0;
}

static int leaves_rows_alone(const char *a)
{
    static const char *const opts[] = {"-o", "-j", "--jobs", "--shard", "--index-offset", "-q",
                                       "--quiet", "--resume", "--unsolvable-ok"};
    for (size_t k = 0; k < sizeof opts / sizeof opts[0]; k++)
        if (!strcmp(a, opts[k]))
            return 1;
    return 0;
}

static int sweep_option(sweep_run *r, sweep_opts *so, const char *a, const char *v)
{
    char *end;
    if (!strcmp(a, "--vary") || !strcmp(a, "--list"))
        return parse_vary(r, v, a[2] == 'l');
    if (!strcmp(a, "--metric"))
        return parse_metric(r, v);
    if (!strcmp(a, "--random")) {
        r->nrandom = strtol(v, &end, 10);
        if (end == v || *end || r->nrandom < 1 || r->nrandom > 10000000)
            return cmd_usage_error("sweep", "--random needs a number of variants from 1 to 10^7, "
                                   "not '%s'", v);
        return -1;
    }
    if (!strcmp(a, "--seed")) {
        errno = 0;
        unsigned long long sd = strtoull(v, &end, 10);
        if (end == v || *end || errno || v[0] == '-')
            return cmd_usage_error("sweep", "--seed needs a whole number from 0 to 2^64-1, "
                                   "not '%s'", v);
        r->seed = (uint64_t)sd;
        return -1;
    }
    if (!strcmp(a, "-o")) {
        so->out = v;
    } else if (!strcmp(a, "-j") || !strcmp(a, "--jobs")) {
        so->nthreads = strtol(v, &end, 10);
        if (*end || so->nthreads < 1 || so->nthreads > 1024)
            return cmd_usage_error("sweep", "-j needs a number of workers from 1 to 1024, not '%s'", v);
    } else if (!strcmp(a, "--shard")) {
        so->sharded = 1;
        if (cmd_parse_shard(v, &r->shard_k, &r->shard_m) < 0)
            return cmd_usage_error("sweep", "--shard needs K/M with 0 <= K < M, not '%s'", v);
    } else if (!strcmp(a, "--index-offset")) {
        so->sharded = 1;
        r->offset = strtol(v, &end, 10);
        if (end == v || *end || r->offset < 0 || r->offset > 1000000000000L)
            return cmd_usage_error("sweep", "--index-offset needs a whole number from 0 to 10^12, "
                                   "not '%s'", v);
    }
    return -1;
}

static int sweep_flag(sweep_run *r, sweep_opts *so, const char *a)
{
    if (!strcmp(a, "--forces"))
        r->forces = 1;
    else if (!strcmp(a, "-q") || !strcmp(a, "--quiet"))
        r->quiet = 1;
    else if (!strcmp(a, "--resume"))
        so->resume = 1;
    else if (!strcmp(a, "--unsolvable-ok"))
        so->unsolvable_ok = 1;
    else if (a[0] == '-' && a[1])
        return cmd_usage_error("sweep", "unknown option '%s'", a);
    else if (r->file)
        return cmd_usage_error("sweep", "one file at a time ('%s' is a second file)", a);
    else
        r->file = a;
    return -1;
}

static int parse_sweep_args(int argc, char **argv, sweep_run *r, sweep_opts *so)
{
    int code = -1;
    for (int i = 1; i < argc && code < 0; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int takes = takes_value(a);
        if (cmd_wants_help(a))
            return fputs(cmd_sweep_help, stdout), MECH_EXIT_OK;
        if (takes && !v)
            return cmd_usage_error("sweep", "option '%s' needs a value", a);
        code = takes ? sweep_option(r, so, a, v) : sweep_flag(r, so, a);
        if (takes)
            i++;
    }
    if (code < 0 && !r->file)
        code = cmd_usage_error("sweep", "%s", "no file given (usage: mech sweep FILE --vary NAME=FROM:TO:COUNT)");
    if (code < 0 && r->nrandom > 0 && r->naxes > 0)
        code = cmd_usage_error("sweep", "%s", "--random samples the parameters that have a "
                               "tolerance; it does not combine with --vary or --list");
    if (code < 0 && r->naxes == 0 && r->nrandom == 0)
        code = cmd_usage_error("sweep", "%s", "nothing to vary: give --vary NAME=FROM:TO:COUNT, "
                               "--list or --random N");
    if (code < 0 && so->resume && (!so->out || !strcmp(so->out, "-")))
        code = cmd_usage_error("sweep", "%s", "--resume needs -o FILE (it continues FILE.partial)");
    if (code < 0)
        code = cmd_refuse_input("sweep", so->out, &r->file, 1);
    return code;
}

/* The file and the parameter names, checked once before the grid (the
 * first variant loads, the metrics name columns it has). -1 when fine. */
static int check_base(sweep_run *r)
{
    mech_override ov[MAX_VARY];
    override_text text[MAX_VARY];
    variant_overrides(r, r->offset, ov, text);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_file_with(r->file, ov, r->naxes, &m, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    int code = rc == MECH_OK ? check_metrics(r, m) : cmd_exit_status(rc);
    mech_model_free(&m);
    return code;
}

/* The manifest line of this run (src/cmd_manifest.h) and the CSV header
 * into *head (malloc'ed); -1, or the exit status. */
static int make_head(const sweep_run *r, const sweep_opts *so, long total, char **head)
{
    manifest *mf = calloc(1, sizeof *mf);
    size_t size = 0;
    FILE *f = mf ? open_memstream(head, &size) : NULL;
    if (!f)
        return free(mf), fprintf(stderr, "mech sweep: out of memory\n"), MECH_EXIT_IO;
    snprintf(mf->version, sizeof mf->version, "%s", MECH_VERSION);
    snprintf(mf->command, sizeof mf->command, "sweep");
    mf->shard_k = r->shard_k;
    mf->shard_m = r->shard_m;
    mf->rows = r->nvars;
    mf->total = total;
    mf->offset = r->offset;
    mf->input = mf->grid = MANIFEST_HASH0;
    int code = -1;
    if (manifest_hash_file(&mf->input, r->file) != 0)
        code = (fprintf(stderr, "mech sweep: cannot read %s: %s\n", r->file, strerror(errno)), MECH_EXIT_IO);
    for (int k = 0; k < r->naxes; k++) {  /* the grid: names, units and every value */
        const axis *a = &r->axes[k];
        mf->grid = manifest_hash(mf->grid, a->name, strlen(a->name) + 1);
        for (int i = 0; i < a->count; i++)
            mf->grid = manifest_hash(mf->grid, a->texts[i], strlen(a->texts[i]) + 1);
    }
    if (r->nrandom > 0) {  /* the samples: N and the seed (the file's bytes are hashed) */
        char text[64];
        snprintf(text, sizeof text, "random %ld seed %llu", r->nrandom,
                 (unsigned long long)r->seed);
        mf->grid = manifest_hash(mf->grid, text, strlen(text) + 1);
    }
    for (int i = 1; i < so->argc; i++)  /* the file by its contents, not its path */
        if (leaves_rows_alone(so->argv[i]))
            i += takes_value(so->argv[i]);
        else if (so->argv[i] != r->file)
            manifest_add_arg(mf, so->argv[i]);
    manifest_write(mf, f);
    write_header(r, f);
    free(mf);
    if (fclose(f) != 0 && code < 0)
        code = (fprintf(stderr, "mech sweep: out of memory\n"), MECH_EXIT_IO);
    return code;
}

/* This shard's variants of the grid, solved on worker threads, each row
 * out as soon as it is known; then OUT written in index order; exit 1 when
 * none was solved (unless --unsolvable-ok). */
static int run_variants(sweep_run *r, const sweep_opts *so, long total)
{
    char *head = NULL;
    r->nvars = manifest_shard_rows(total, r->shard_k, r->shard_m);
    int code = make_head(r, so, total, &head);
    if (code < 0)
        code = rows_open(&r->rows, "sweep", so->out, so->resume, head,
                         r->offset + r->shard_k, r->shard_m, r->nvars);
    free(head);
    if (code >= 0)
        return code;
    atomic_store(&r->done, r->rows.ndone);
    cmd_progress_init(&r->progress, "sweep", "variants", r->quiet);
    cmd_run_parallel((int)r->nvars, (int)so->nthreads, sweep_job, r);
    cmd_progress_done(&r->progress);
    long shared, alone;
    sweep_variant_counts(&shared, &alone);
    if (!r->quiet && shared + alone > 0)  /* docs/batch.md, "One analysis per sweep" */
        fprintf(stderr, "mech sweep: %ld variant%s solved through the sweep's one analysis, "
                "%ld analysed on %s own\n", shared, shared == 1 ? "" : "s", alone,
                alone == 1 ? "its" : "their");
    long nok = 0;
    code = rows_finish(&r->rows, so->out, so->sharded, 1 + r->naxes, &nok);
    if (code == MECH_EXIT_OK && r->nvars > 0 && nok == 0) {
        fprintf(stderr, "mech sweep: none of the %ld variants could be solved\n", r->nvars);
        code = so->unsolvable_ok ? MECH_EXIT_OK : MECH_EXIT_SOLVE;
    }
    return code;
}

/* --random: the axes are the file's parameters that have a tolerance. -1
 * when there is one at least, else the exit status (the problem printed). */
static int random_axes(sweep_run *r)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_file(r->file, &m, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return cmd_exit_status(rc);
    int code = -1;
    for (int k = 0; k < m->nparams && code < 0; k++) {
        const mech_param *p = &m->params[k];
        if (!(p->tol > 0.0))
            continue;
        if (r->naxes == MAX_VARY) {
            code = cmd_usage_error("sweep", "%s", "--random: more than 32 parameters with a "
                                   "tolerance");
            break;
        }
        axis *a = &r->axes[r->naxes++];
        memset(a, 0, sizeof *a);
        snprintf(a->name, sizeof a->name, "%s", p->name);
        snprintf(a->unit, sizeof a->unit, "%s", p->unit[0] ? p->unit : "-");
        a->nominal = p->value;
        a->tol = p->tol;
    }
    if (code < 0 && r->naxes == 0)
        code = cmd_usage_error("sweep", "--random: no parameter of '%s' has a tolerance (give "
                               "one as r: {value: 40 mm, tolerance: 0.05 mm})", r->file);
    mech_model_free(&m);
    return code;
}

int cmd_sweep(int argc, char **argv)
{
    sweep_run r;
    memset(&r, 0, sizeof r);
    r.shard_m = 1;
    r.seed = 1;
    sweep_opts so = {NULL, cmd_default_jobs(), 0, 0, 0, argc, argv};
    int code = parse_sweep_args(argc, argv, &r, &so);
    if (code < 0 && r.nrandom > 0)
        code = random_axes(&r);
    long total = r.nrandom > 0 ? r.nrandom : 1;
    for (int k = 0; code < 0 && r.nrandom == 0 && k < r.naxes; k++)
        if ((total *= r.axes[k].count) > 10000000)
            code = cmd_usage_error("sweep", "%s", "more than 10^7 variants");
    if (code < 0)
        code = check_base(&r);
    if (code < 0)
        code = run_variants(&r, &so, total);
    free_run(&r);
    return code;
}
