/* src/cli/cmd_sweep.c: `mech sweep`, a grid of variants of one mechanism, or
 * --random N samples within the parameters' tolerances (docs/batch.md): the
 * command line of mech_sweep (src/study/sweep_run.c: the grid, the samples, the
 * metrics and the variants on worker threads are the library's). Here: the
 * options, the rows as CSV lines streamed to OUT.partial (cmd_rows.c), the
 * manifest of a shard (--shard K/M: variant index i % M == K, the index as
 * first column, for mech merge), the progress, the exit status. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "study.h"

typedef struct sweep_args {
    const char *file, *out;
    mech_sweep *sweep;          /* --vary, --list, --metric as they come */
    mech_sweep_options opt;     /* --forces, --random, --seed, -j */
    cmd_shard shard;            /* --shard K/M */
    long index_offset;          /* --index-offset N (-1: not given) */
    int quiet, resume, unsolvable_ok;
    int engine;                 /* --engine: CMD_ENGINE_* */
} sweep_args;

/* The messages of the sweep's library calls: its own arguments' errors as
 * usage errors ("mech sweep: MESSAGE (see 'mech sweep --help')"), the rest
 * (the file's, the notes) as mech_diag_print writes them. */
static void print_diag(const mech_diag *d)
{
    for (size_t i = 0; i < d->count; i++) {
        const mech_diag_entry *e = &d->entries[i];
        if (e->severity == MECH_SEV_ERROR && strcmp(e->file, MECH_SWEEP_ARGUMENTS) == 0) {
            cmd_usage_error("sweep", "%s", e->message);
        } else {
            mech_diag one = {(mech_diag_entry *)e, 1, 1, 0, 0, 0};
            mech_diag_print(&one, stderr);
        }
    }
    if (d->truncated)
        fprintf(stderr, "(%zu errors in all; only the first %zu are shown)\n", d->nerrors,
                d->max_errors ? d->max_errors : (size_t)100);
}

/* The exit status of a library call (its messages printed); -1 when fine. */
static int sweep_status(int rc, mech_diag *d)
{
    print_diag(d);
    if (rc == MECH_ENOMEM && d->nerrors == 0)
        fprintf(stderr, "mech sweep: out of memory\n");
    mech_diag_free(d);
    return rc == MECH_OK ? -1 : cmd_exit_status(rc);
}

/* --vary, --list, --metric: into the sweep (CMD_OPT_CALL). */
static int add_to_sweep(void *target, const char *value,
                        int (*add)(mech_sweep *, const char *, mech_diag *))
{
    mech_sweep **s = target;
    mech_diag d;
    mech_diag_init(&d);
    return sweep_status(add(*s, value, &d), &d);
}

static int read_vary(const char *command, void *target, const char *value)
{
    (void)command;
    return add_to_sweep(target, value, mech_sweep_vary);
}

static int read_list(const char *command, void *target, const char *value)
{
    (void)command;
    return add_to_sweep(target, value, mech_sweep_list);
}

static int read_metric(const char *command, void *target, const char *value)
{
    (void)command;
    return add_to_sweep(target, value, mech_sweep_metric);
}

#define AT(field) offsetof(sweep_args, field)

static const cmd_opt options[] = {
    {.names = "--vary", .kind = CMD_OPT_CALL, .at = AT(sweep), .call = read_vary,
     .label = "--vary NAME=FROM:TO:COUNT",
     .help = "COUNT values from FROM to TO (inclusive); a unit\n"
             "may follow the numbers, the same on both: l=130mm:150mm:5"},
    {.names = "--list", .kind = CMD_OPT_CALL, .at = AT(sweep), .call = read_list,
     .label = "--list NAME=A,B,...",
     .help = "the given values (each may carry a unit)\n"
             "several --vary/--list make a grid (every combination)"},
    {.names = "--random", .kind = CMD_OPT_LONG, .at = AT(opt.nrandom), .lo = 1, .hi = 10000000,
     .expect = "needs a number of variants from 1 to 10^7", .label = "--random N",
     .help = "N variants with every parameter that has a tolerance\n"
             "(r: {value: 40 mm, tolerance: 0.05 mm}) drawn uniformly\n"
             "within value +- tolerance, independently (a Monte Carlo\n"
             "check of 'mech solve --tolerances'); not with --vary/--list"},
    {.names = "--seed", .kind = CMD_OPT_U64, .at = AT(opt.seed),
     .expect = "needs a whole number from 0 to 2^64-1", .label = "--seed S",
     .help = "the samples' seed, 0 to 2^64-1 (default 1): the same seed\n"
             "gives the same rows, whatever -j and --shard"},
    {.names = "--metric", .kind = CMD_OPT_CALL, .at = AT(sweep), .call = read_metric,
     .label = "--metric M",
     .help = "a summary of one output column over the sweep; M is\n"
             "range:COL (max - min, e.g. range:x_B.s, the stroke),\n"
             "max:COL, min:COL, maxabs:COL (e.g. maxabs:driver.torque,\n"
             "the peak torque), or transmission:LINK1,LINK2 (the\n"
             "smallest angle between the two links, 0..pi/2 rad, e.g. the\n"
             "transmission angle of a four-bar: coupler,rocker), or\n"
             "flywheel:CS (the flywheel inertia, kg*m^2, for the\n"
             "coefficient of speed fluctuation CS over the file's\n"
             "driver range, one full turn; needs --forces)\n"
             "(default: the number of rows solved)"},
    {.names = "-o", .kind = CMD_OPT_TEXT, .at = AT(out), .flags = CMD_RUN_ONLY,
     .label = "-o FILE",
     .help = "write the summary CSV to FILE (default: standard output);\n"
             "a FILE ending in .h5 or .hdf5: HDF5, the same columns and\n"
             "the manifest as attributes (OUT.partial stays CSV)"},
    CMD_JOBS_ENTRY(AT(opt.nthreads)),
    {.names = "--shard", .kind = CMD_OPT_CALL, .at = AT(shard), .call = cmd_read_shard,
     .flags = CMD_RUN_ONLY, .label = "--shard K/M",
     .help = "only the variants with index % M == K; the CSV then starts\n"
             "with a '# mech-manifest' line, for mech merge"},
    {.names = "--index-offset", .kind = CMD_OPT_LONG, .at = AT(index_offset), .lo = 0,
     .hi = 1e12, .flags = CMD_RUN_ONLY, .expect = "needs a whole number from 0 to 10^12",
     .label = "--index-offset N",
     .help = "number the variants from N (a grid that continues another\n"
             "in one index space for mech merge; also writes the manifest)"},
    {.names = "--resume", .kind = CMD_OPT_FLAG, .at = AT(resume), .flag = 1,
     .flags = CMD_RUN_ONLY, .label = "--resume",
     .help = "continue OUT.partial, the rows of a run that was stopped\n"
             "(rows are written there as they finish; needs -o)"},
    {.names = "--unsolvable-ok", .kind = CMD_OPT_FLAG, .at = AT(unsolvable_ok), .flag = 1,
     .flags = CMD_RUN_ONLY, .label = "--unsolvable-ok",
     .help = "exit 0 also when no variant could be solved (they are rows\n"
             "with their status); bad input and I/O still fail"},
    {.names = "--forces", .kind = CMD_OPT_FLAG, .at = AT(opt.forces), .flag = 1,
     .label = "--forces", .help = "also the force analysis (needed for driver.torque metrics)"},
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = AT(quiet), .flag = 1,
     .flags = CMD_RUN_ONLY, .label = "-q, --quiet",
     .help = "no progress report (a bar on a terminal, else a line every\n"
             "5 s)"},
    CMD_ENGINE_ENTRY(AT(engine)),
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_sweep_spec = {
    .name = "sweep",
    .summary = "solve a grid of variants of one mechanism, one summary row each",
    .usage = "usage: mech sweep FILE --vary NAME=FROM:TO:COUNT [--vary ...]\n"
             "                  [--list NAME=A,B,...] [--metric M ...] [-o OUT.csv] [-j N]\n"
             "                  [--shard K/M] [--forces] [--engine auto|compiled|interpreted]\n"
             "       mech sweep FILE --random N [--seed S] [--metric M ...] [options as above]\n"
             "                  [--index-offset N] [--resume] [--unsolvable-ok]\n",
    .about = "Solve a grid of variants of one mechanism, changing its named parameters\n"
             "(the file's 'parameters:'), and write one summary row per variant: the\n"
             "variant's index, its parameter values, its status, and the metrics.\n"
             "A variant that cannot assemble over the driver range is reported as such\n"
             "(status 'no-assembly', 'singular' or 'self-locking' when joint friction\n"
             "locks it), not as a failure of the run. The CSV is mech solve's: headers\n"
             "'name [unit]', values in SI (r=30mm is 0.03 under 'r [m]'; bare numbers '-';\n"
             "transmission angles in rad).\n",
    .opts = options,
    .column = 20,
    .exits = "exit status: 0 the sweep ran and at least one variant was solved, 1 no variant\n"
             "could be solved (the rows are still written), 2 bad usage or an invalid file,\n"
             "parameter or metric column, 3 a file cannot be read or written, or out of memory\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech sweep FILE --vary NAME=FROM:TO:COUNT)",
};

/* The command line into a (and its sweep's grid and metrics). -1 when
 * fine, else the exit status (the problem printed). */
static int parse_sweep_args(int argc, char **argv, sweep_args *a)
{
    int code = cmd_opts_parse(&cmd_sweep_spec, argc, argv, a);
    a->opt.shard_k = a->shard.k;
    a->opt.shard_m = a->shard.m;
    if (a->index_offset >= 0)
        a->opt.index_offset = a->index_offset;
    if (code < 0 && a->resume && (!a->out || !strcmp(a->out, "-")))
        code = cmd_usage_error("sweep", "%s", "--resume needs -o FILE (it continues FILE.partial)");
    if (code < 0)
        code = cmd_refuse_input("sweep", a->out, &a->file, 1);
    return code;
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

static void write_header(const mech_sweep *s, FILE *f)
{
    char cell[256];
    const char *unit;
    fprintf(f, "variant [-]");
    for (int k = 0; k < mech_sweep_nparams(s); k++) {
        const char *name = mech_sweep_param(s, k, &unit);
        snprintf(cell, sizeof cell, "%s [%s]", name, unit);
        put_cell(f, cell);
    }
    fprintf(f, ",status [-],rows [-]");
    for (int k = 0; k < mech_sweep_nmetrics(s); k++) {
        const char *label = mech_sweep_metric_label(s, k, &unit);
        snprintf(cell, sizeof cell, "%s [%s]", label, unit);
        put_cell(f, cell);
    }
    fputc('\n', f);
}

enum { ROW_SIZE = 32 * (SWEEP_MAX_AXES + SWEEP_MAX_METRICS + 4) };

/* Variant v's row, with its newline, into row[ROW_SIZE]. */
static void format_row(const mech_sweep *s, const mech_variant *v, char *row)
{
    char cell[FMT_DOUBLE_MAX];  /* the fewest digits that read back: 0.04 */
    size_t n = (size_t)snprintf(row, ROW_SIZE, "%ld", v->index);
    for (int k = 0; k < mech_sweep_nparams(s); k++) {
        fmt_double(v->params[k], cell);
        n += (size_t)snprintf(row + n, ROW_SIZE - n, ",%s", cell);
    }
    n += (size_t)snprintf(row + n, ROW_SIZE - n, ",%s,%d", mech_variant_status_name(v->status),
                          v->rows);
    for (int k = 0; k < mech_sweep_nmetrics(s) && n + FMT_DOUBLE_MAX + 2 < ROW_SIZE; k++) {
        row[n++] = ',';  /* the shortest text that reads back (fmt_double) */
        n += (size_t)fmt_double(v->metrics[k], row + n);
    }
    snprintf(row + n, ROW_SIZE - n, "\n");
}

/* The rows as they come from mech_sweep_run. */
typedef struct sweep_out {
    const mech_sweep *s;
    rowfile rows;          /* the rows as they finish (src/cli/cli.h) */
    cmd_progress progress;
    long done;             /* variants finished (resumed ones included) */
} sweep_out;

/* One variant's row appended to the rows file and, when it was not solved
 * or its assembly is suspect, its messages printed (mech_sweep_run calls
 * one at a time). */
static void put_row(void *ctx, const mech_variant *v)
{
    sweep_out *o = ctx;
    char row[ROW_SIZE];
    format_row(o->s, v, row);
    int say = v->status != MECH_VARIANT_OK || v->suspect != MECH_FAIL_NONE;
    rows_put(&o->rows, v->row, row, say ? v->messages : NULL);
    cmd_progress_update(&o->progress, (int)++o->done, (int)mech_sweep_count(o->s));
}

static int row_done(void *ctx, long row)
{
    return rows_done(&((sweep_out *)ctx)->rows, row);
}

/* A manifest argument: an option that changes the rows, with its value
 * (the file is hashed by its contents, not its path). */
static void manifest_arg(void *ctx, const cmd_opt *o, const char *name, const char *value)
{
    if (!o || (o->flags & CMD_RUN_ONLY))
        return;
    manifest_add_arg(ctx, name);
    if (value)
        manifest_add_arg(ctx, value);
}

/* The manifest's grid hash: the grid's names and every value's text; with
 * --random, N and the seed (the file's bytes are hashed as its input). */
static uint64_t grid_hash(const mech_sweep *s)
{
    uint64_t h = MANIFEST_HASH0;
    for (int k = 0; k < s->ngrid; k++) {
        const sweep_axis *ax = &s->axes[k];
        h = manifest_hash(h, ax->name, strlen(ax->name) + 1);
        for (int i = 0; i < ax->count; i++)
            h = manifest_hash(h, ax->texts[i], strlen(ax->texts[i]) + 1);
    }
    if (s->opt.nrandom > 0) {
        char text[64];
        snprintf(text, sizeof text, "random %ld seed %llu", s->opt.nrandom, s->opt.seed);
        h = manifest_hash(h, text, strlen(text) + 1);
    }
    return h;
}

/* The manifest line of this run (src/cli/cli.h) and the CSV header
 * into *head (malloc'ed); -1, or the exit status. */
static int make_head(const sweep_args *a, int argc, char **argv, char **head)
{
    const mech_sweep *s = a->sweep;
    manifest *mf = calloc(1, sizeof *mf);
    size_t size = 0;
    FILE *f = mf ? open_memstream(head, &size) : NULL;
    if (!f)
        return free(mf), fprintf(stderr, "mech sweep: out of memory\n"), MECH_EXIT_IO;
    snprintf(mf->version, sizeof mf->version, "%s", MECH_VERSION);
    snprintf(mf->command, sizeof mf->command, "sweep");
    mf->shard_k = a->opt.shard_k;
    mf->shard_m = a->opt.shard_m;
    mf->rows = mech_sweep_count(s);
    mf->total = mech_sweep_total(s);
    mf->offset = a->opt.index_offset;
    mf->input = MANIFEST_HASH0;
    mf->grid = grid_hash(s);
    int code = -1;
    if (manifest_hash_file(&mf->input, a->file) != 0)
        code = (fprintf(stderr, "mech sweep: cannot read %s: %s\n", a->file, strerror(errno)), MECH_EXIT_IO);
    if (code < 0 && sweep_tol_format(s, mf->tol, sizeof mf->tol) != 0)  /* the samples, for merge */
        code = cmd_usage_error("sweep", "%s", "--random: too many toleranced parameters for "
                               "the manifest");
    cmd_opts_each(&cmd_sweep_spec, argc, argv, manifest_arg, mf);
    manifest_write(mf, f);
    write_header(s, f);
    free(mf);
    if (fclose(f) != 0 && code < 0)
        code = (fprintf(stderr, "mech sweep: out of memory\n"), MECH_EXIT_IO);
    return code;
}

/* What --resume checks of a row of OUT.partial (src/cli/cli.h). */
static int row_checks(const void *sweep, const char *row, size_t len, char *why, size_t size)
{
    return sweep_row_content(sweep, row, len, why, size);
}

/* The compiled solver, and how many variants it solved, when it solved
 * some (as mech batch says of a file; docs/batch.md, "One compiled solver
 * per sweep"): the interpreter's runs say nothing more than before. */
static void solver_summary(cmd_jit_variants *jv)
{
    long compiled = 0, interpreted = 0;
    const char *how = jv ? cmd_jit_variants_how(jv, &compiled, &interpreted) : "";
    if (compiled > 0)
        fprintf(stderr, "mech sweep: solver %s: %ld variant%s compiled, %ld interpreted\n", how,
                compiled, compiled == 1 ? "" : "s", interpreted);
}

/* This shard's variants, solved on worker threads (mech_sweep_run), each
 * row out as soon as it is known; then OUT written in index order; exit 1
 * when none was solved (unless --unsolvable-ok). */
static int run_variants(sweep_args *a, int argc, char **argv)
{
    sweep_out o = {.s = a->sweep};
    char *head = NULL;
    long count = mech_sweep_count(a->sweep);
    int code = make_head(a, argc, argv, &head);
    if (code < 0)
        code = rows_open(&o.rows, "sweep", a->out, a->resume, head,
                         a->opt.index_offset + a->opt.shard_k, a->opt.shard_m, count,
                         row_checks, a->sweep);
    free(head);
    if (code >= 0)
        return code;
    o.rows.input = a->file;
    o.done = o.rows.ndone;
    cmd_progress_init(&o.progress, "sweep", "variants", a->quiet);
    mech_sweep_sink sink = {put_row, row_done, &o};
    mech_sweep_stats st = {0};
    mech_diag d;
    mech_diag_init(&d);
    cmd_jit_variants *jv = a->engine == CMD_ENGINE_INTERPRETED
                           ? NULL : cmd_jit_variants_new(a->engine, count - o.done, stderr);
    if (jv)
        sweep_set_engine(a->sweep, cmd_jit_variants_engine(jv));
    code = sweep_status(mech_sweep_run(a->sweep, &sink, &st, &d), &d);
    cmd_progress_done(&o.progress);
    if (code < 0 && !a->quiet && st.shared + st.alone > 0)  /* docs/batch.md */
        fprintf(stderr, "mech sweep: %ld variant%s solved through the sweep's one analysis, "
                "%ld analysed on %s own\n", st.shared, st.shared == 1 ? "" : "s", st.alone,
                st.alone == 1 ? "its" : "their");
    if (code < 0 && !a->quiet && st.shared > 0)
        solver_summary(jv);
    sweep_set_engine(a->sweep, NULL);
    cmd_jit_variants_free(&jv);
    long nok = 0;
    if (code < 0)
        code = rows_finish(&o.rows, a->out, a->shard.given || a->index_offset >= 0,
                           1 + mech_sweep_nparams(a->sweep), &nok);
    if (code == MECH_EXIT_OK && count > 0 && nok == 0) {
        fprintf(stderr, "mech sweep: none of the %ld variants could be solved\n", count);
        code = a->unsolvable_ok ? MECH_EXIT_OK : MECH_EXIT_SOLVE;
    }
    rows_close(&o.rows);
    return code;
}

int cmd_sweep(int argc, char **argv)
{
    sweep_args a = {.shard = {0, 1, 0}, .index_offset = -1};
    mech_sweep_options_default(&a.opt);
    if (mech_sweep_new(&a.sweep) != MECH_OK)
        return fprintf(stderr, "mech sweep: out of memory\n"), MECH_EXIT_IO;
    int code = parse_sweep_args(argc, argv, &a);
    if (code < 0) {
        mech_diag d;
        mech_diag_init(&d);
        code = sweep_status(mech_sweep_prepare(a.sweep, a.file, &a.opt, &d), &d);
    }
    if (code < 0)
        code = run_variants(&a, argc, argv);
    mech_sweep_free(&a.sweep);
    return code;
}

int sweep_of_manifest(const manifest *m, mech_sweep **out)
{
    char **words = NULL;
    sweep_args a = {.shard = {0, 1, 0}, .index_offset = -1};
    mech_sweep_options_default(&a.opt);
    *out = NULL;
    if (mech_sweep_new(&a.sweep) != MECH_OK)
        return -1;
    mech_sweep *s = a.sweep;
    int bad = manifest_args_parse(m, &cmd_sweep_spec, &a, &words) != 0;
    s->opt = a.opt;
    s->opt.index_offset = m->offset;
    bad = bad || (s->opt.nrandom > 0) != (m->tol[0] != '\0') ||
          (s->opt.nrandom > 0) == (s->ngrid > 0) || grid_hash(s) != m->grid ||
          (s->opt.nrandom > 0 && sweep_tol_parse(s, m->tol) != 0);
    free(words);
    if (bad)
        mech_sweep_free(&s);
    *out = s;
    return bad ? -1 : 0;
}
