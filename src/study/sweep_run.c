/* src/study/sweep_run.c: mech_sweep (include/mech.h), `mech sweep` as a call:
 * the grid or samples (sweep_grid.c) and the metrics (sweep_metrics.c)
 * checked once against the file, then every variant of the shard solved on
 * worker threads (through the sweep's one analysis: sweep_variants.c,
 * variant_regs.c) and reduced to one row, which goes to the caller's sink
 * at once: nothing of a variant is kept once its row is out, so a sweep of
 * 10^7 variants holds no more than one of a few (docs/batch.md). */
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "study.h"

int sweep_arg_error(mech_diag *d, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return diag_error(d, MECH_SWEEP_ARGUMENTS, (mech_mark){0, 0}, "%s", msg);
}

int mech_sweep_options_init(mech_sweep_options *o, size_t size)
{
    if (!o)
        return MECH_EINPUT;
    if (size != sizeof *o) {  /* the one layout so far (0.2) */
        memset(o, 0, size < sizeof o->size ? size : sizeof o->size);
        return MECH_EINPUT;
    }
    memset(o, 0, sizeof *o);
    o->size = sizeof *o;
    o->seed = 1;
    o->shard_m = 1;
    return MECH_OK;
}

int mech_sweep_new(mech_sweep **out)
{
    *out = xcalloc(1, sizeof **out);
    if (!*out)
        return MECH_ENOMEM;
    mech_sweep_options_default(&(*out)->opt);
    return MECH_OK;
}

void mech_sweep_free(mech_sweep **s)
{
    if (!s || !*s)
        return;
    grid_free(*s);
    sweep_shared_free(&(*s)->shared);
    free((*s)->path);
    free(*s);
    *s = NULL;
}

static int before_prepare(const mech_sweep *s, mech_diag *d)
{
    return s->prepared ? sweep_arg_error(d, "mech_sweep_prepare was called: the parameters and "
                                         "metrics come before it, and it comes once")
                       : MECH_OK;
}

int mech_sweep_vary(mech_sweep *s, const char *spec, mech_diag *d)
{
    int rc = before_prepare(s, d);
    return rc == MECH_OK ? grid_add(s, spec, 0, d) : rc;
}

int mech_sweep_list(mech_sweep *s, const char *spec, mech_diag *d)
{
    int rc = before_prepare(s, d);
    return rc == MECH_OK ? grid_add(s, spec, 1, d) : rc;
}

int mech_sweep_metric(mech_sweep *s, const char *spec, mech_diag *d)
{
    int rc = before_prepare(s, d);
    return rc == MECH_OK ? metric_add(s, spec, d) : rc;
}

/* ---- prepare: the file and the metrics checked once ------------------- */

static int check_options(const mech_sweep *s, mech_diag *d)
{
    const mech_sweep_options *o = &s->opt;
    if (o->nrandom > 0 && s->ngrid > 0)
        return sweep_arg_error(d, "--random samples the parameters that have a tolerance; it "
                               "does not combine with --vary or --list");
    if (s->ngrid == 0 && o->nrandom == 0)
        return sweep_arg_error(d, "nothing to vary: give --vary NAME=FROM:TO:COUNT, --list or "
                               "--random N");
    if (o->nrandom < 0 || o->nrandom > SWEEP_MAX_VARIANTS)
        return sweep_arg_error(d, "--random needs a number of variants from 1 to 10^7, not %ld",
                               o->nrandom);
    if (o->shard_m < 1 || o->shard_k < 0 || o->shard_k >= o->shard_m || o->index_offset < 0 ||
        o->nthreads < 0)
        return sweep_arg_error(d, "a shard K/M needs 0 <= K < M, an index offset and a number "
                               "of threads >= 0 (shard %d/%d, offset %ld, %d threads)",
                               o->shard_k, o->shard_m, o->index_offset, o->nthreads);
    return MECH_OK;
}

/* --random: the axes are the file's parameters that have a tolerance. */
static int random_axes(mech_sweep *s, mech_diag *d)
{
    mech_model *m = NULL;
    int rc = mech_load_file(s->path, &m, d);
    if (rc == MECH_OK)
        rc = grid_random_axes(s, m, d);
    mech_model_free(&m);
    return rc;
}

/* The columns of the base variant's table, known without solving anything
 * (mech_analysis_header), even when it cannot assemble; the note that the
 * forces are all zero (no mass, no load) is made here, once for the sweep.
 * An empty t when the base does not even build: every variant says why. */
static int base_columns(const mech_sweep *s, const mech_model *m, mech_table *t, mech_diag *d)
{
    mech_diag local;
    mech_diag_init(&local);
    mech_summary sum;
    int rc = mech_check(m, &sum, &local);
    if (rc == MECH_OK && (s->nmetrics > 0 || s->opt.forces) && m->has_driver) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.forces = s->opt.forces;
        mech_analysis *a = NULL;
        rc = mech_analysis_new(m, &o, &a, &local);
        if (rc == MECH_OK)
            rc = mech_analysis_header(a, t);
        mech_analysis_free(&a);
    }
    for (size_t i = 0; i < local.count; i++)
        if (local.entries[i].severity == MECH_SEV_NOTE &&
            strstr(local.entries[i].message, "no link has a mass"))
            diag_note(d, MECH_SWEEP_ARGUMENTS, (mech_mark){0, 0}, "variant 0: %s",
                      local.entries[i].message);
    mech_diag_free(&local);
    return rc == MECH_ENOMEM ? MECH_ENOMEM : MECH_OK;
}

/* The file loads with the first variant's parameters (the others change
 * numbers, not names), and every metric names columns its table has. */
static int check_base(mech_sweep *s, mech_diag *d)
{
    mech_override ov[SWEEP_MAX_AXES];
    sweep_text text[SWEEP_MAX_AXES];
    grid_overrides(s, s->opt.index_offset, ov, text);
    mech_model *m = NULL;
    mech_table t = {0};
    mech_diag load;
    mech_diag_init(&load);
    int rc = mech_load_file_with(s->path, ov, s->naxes, &m, &load);
    if (rc == MECH_EINPUT)
        grid_bare_values(s, d);
    for (size_t i = 0; i < load.count; i++)
        diag_copy(d, &load.entries[i]);
    mech_diag_free(&load);
    if (rc == MECH_OK)
        rc = base_columns(s, m, &t, d);
    if (rc == MECH_OK)
        rc = metric_check(s, &t, d);
    mech_table_free(&t);
    mech_model_free(&m);
    return rc;
}

/* The rows shard K/M of `total` variants holds (i % M == K). */
static long shard_rows(long total, int k, int m)
{
    return total > k ? (total - k + m - 1) / m : 0;
}

int mech_sweep_prepare(mech_sweep *s, const char *path, const mech_sweep_options *o,
                       mech_diag *d)
{
    int rc = before_prepare(s, d);
    if (rc != MECH_OK)
        return rc;
    s->prepared = 1;  /* once, whatever comes of it */
    if (o && o->size != sizeof *o)
        return sweep_arg_error(d, "the sweep options' size is %zu, and this library (%s) knows "
                               "%zu: set them with mech_sweep_options_init(&o, sizeof o) first",
                               o->size, MECH_VERSION, sizeof *o);
    if (o)
        s->opt = *o;
    if (!(s->path = xstrdup(path)))
        return MECH_ENOMEM;
    rc = check_options(s, d);
    if (rc == MECH_OK && s->opt.nrandom > 0)
        rc = random_axes(s, d);
    if (rc == MECH_OK)
        rc = grid_total(s, d);
    if (rc == MECH_OK)
        rc = check_base(s, d);
    if (rc == MECH_OK && !(s->shared = sweep_shared_new(path, s->opt.forces)))
        rc = MECH_ENOMEM;
    if (rc != MECH_OK)
        return rc;
    s->count = shard_rows(s->total, s->opt.shard_k, s->opt.shard_m);
    s->ready = 1;
    return MECH_OK;
}

void sweep_set_engine(mech_sweep *s, const sweep_engine *e)
{
    if (s->shared)
        sweep_shared_set_engine(s->shared, e);
}

long mech_sweep_total(const mech_sweep *s)
{
    return s->total;
}

long mech_sweep_count(const mech_sweep *s)
{
    return s->count;
}

int mech_sweep_nparams(const mech_sweep *s)
{
    return s->naxes;
}

const char *mech_sweep_param(const mech_sweep *s, int k, const char **unit)
{
    if (k < 0 || k >= s->naxes)
        return NULL;
    if (unit)
        *unit = s->axes[k].unit;
    return s->axes[k].name;
}

int mech_sweep_nmetrics(const mech_sweep *s)
{
    return s->nmetrics;
}

const char *mech_sweep_metric_label(const mech_sweep *s, int k, const char **unit)
{
    if (k < 0 || k >= s->nmetrics)
        return NULL;
    if (unit)
        *unit = s->metrics[k].unit[0] ? s->metrics[k].unit : "-";
    return s->metrics[k].label;
}

/* ---- run: every variant of the shard ---------------------------------- */

typedef struct run {
    mech_sweep *s;
    const mech_sweep_sink *sink;
    pthread_mutex_t lock;   /* one sink->row at a time */
    atomic_long solved;
} run;

/* What failed, from the errors (not the notes) of a variant that could not
 * be solved. */
static mech_variant_status variant_status(int rc, const mech_diag *d)
{
    /* from the errors' kinds (the gravest), never their words */
    mech_fail_kind kind = rc == MECH_OK ? MECH_FAIL_NONE : mech_diag_failure(d);
    return fail_variant_status(rc != MECH_OK && kind == MECH_FAIL_NONE ? fail_of_status(rc) : kind);
}

/* Variant v->index solved and measured; what its load and solve said goes
 * to out ("variant 3: r=45 mm" first). */
static void solve_variant(const mech_sweep *s, mech_variant *v, double *metrics, FILE *out)
{
    mech_override ov[SWEEP_MAX_AXES];
    sweep_text text[SWEEP_MAX_AXES];
    grid_overrides(s, v->index, ov, text);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    mech_model *m = NULL;
    int rc = sweep_variant_solve(s->shared, ov, s->naxes, &t, &m, &d);
    fprintf(out, "variant %ld:", v->index);
    for (int k = 0; k < s->naxes; k++)
        fprintf(out, " %s=%s", ov[k].name, ov[k].text);
    fputc('\n', out);
    mech_diag_print(&d, out);
    if (rc == MECH_ESOLVE && t.nrequested > 0)  /* a partial sweep (issue 17) */
        fprintf(out, "%d of %d rows solved, %d gap%s\n", t.nrows, t.nrequested, t.ngaps,
                t.ngaps == 1 ? "" : "s");
    v->rows = t.nrows;
    v->status = variant_status(rc, &d);
    for (size_t i = 0; i < d.count && v->suspect == MECH_FAIL_NONE; i++) {
        const mech_diag_entry *e = &d.entries[i];
        if (e->severity == MECH_SEV_WARNING && fail_is_suspect_assembly(e->kind))
            v->suspect = e->kind;
    }
    for (int k = 0; k < s->nmetrics; k++)
        metrics[k] = rc == MECH_OK ? metric_value(&s->metrics[k], &t, m, out) : NAN;
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* Row i of the shard (variant offset + K + i*M): solved, handed over,
 * forgotten. */
static void variant_job(void *ctx, long i)
{
    run *r = ctx;
    const mech_sweep *s = r->s;
    if (r->sink->done && r->sink->done(r->sink->ctx, i))
        return;  /* resumed: the caller has it */
    double params[SWEEP_MAX_AXES], metrics[SWEEP_MAX_METRICS];
    mech_variant v = {.row = i, .params = params, .metrics = metrics};
    v.index = s->opt.index_offset + s->opt.shard_k + i * s->opt.shard_m;
    for (int k = 0; k < s->naxes; k++)
        params[k] = grid_value(s, v.index, k);
    char *messages = NULL;
    size_t size = 0;
    FILE *msg = open_memstream(&messages, &size);
    solve_variant(s, &v, metrics, msg ? msg : stderr);
    if (msg)
        fclose(msg);
    v.messages = messages ? messages : "";
    if (v.status == MECH_VARIANT_OK)
        atomic_fetch_add(&r->solved, 1);
    pthread_mutex_lock(&r->lock);
    r->sink->row(r->sink->ctx, &v);
    pthread_mutex_unlock(&r->lock);
    free(messages);
}

int mech_sweep_run(mech_sweep *s, const mech_sweep_sink *sink, mech_sweep_stats *stats,
                   mech_diag *d)
{
    if (!s->ready)
        return sweep_arg_error(d, "mech_sweep_run needs a sweep that mech_sweep_prepare "
                               "accepted");
    run r = {s, sink, PTHREAD_MUTEX_INITIALIZER, 0};
    int threads = s->opt.nthreads > 0 ? s->opt.nthreads : parallel_default_jobs();
    parallel_run(s->count, threads, variant_job, &r);
    pthread_mutex_destroy(&r.lock);
    if (stats) {
        stats->solved = atomic_load(&r.solved);
        sweep_variant_counts(s->shared, &stats->shared, &stats->alone);
    }
    return MECH_OK;
}
