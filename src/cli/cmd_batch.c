/* src/cli/cmd_batch.c: `mech batch`, many mechanism files solved on worker
 * threads (docs/batch.md).
 *
 * Each file is independent: its own model, solver and diagnostics, written
 * to a memory stream and printed as one block when the file is done (so a
 * failing file never garbles the others, and nothing piles up in memory);
 * the table is in list order whatever the number of workers. With -o TABLE
 * each row also goes to TABLE.partial as its file finishes, so a killed run
 * leaves a record mech merge can name. Work is handed out by an atomic
 * counter; --shard K/M keeps only the files whose index i satisfies
 * i % M == K, for running one batch over several machines (GNU Parallel,
 * Slurm job arrays). */
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "output.h"
#include "base.h"

typedef struct job {
    const char *path;
    const char *name;    /* NAME: its base name without .yaml, in path ... */
    int name_len;        /* ... name_len bytes (no copy: memory per file is small) */
    char *csv;           /* --out-dir: DIR/NAME.csv, owned */
    char *golden_path;   /* --golden: GOLDEN/NAME.csv, owned */
    int code;            /* exit status of this file */
    int kept;            /* --skip-existing: DIR/NAME.csv was there, not solved */
    int recorded;        /* kept: its numbers from the row an earlier run wrote */
    int has_csv;         /* csv_hash: FNV-1a 64 of DIR/NAME.csv as written or kept */
    uint64_t csv_hash;
    long index;          /* position in the whole list (before --shard) */
    int steps;
    double worst_residual, us_per_step;
    const char *golden;  /* "-", "match", "DIFFER", "missing", "error" */
    char *messages;      /* diagnostics, printed when the file is done */
    size_t msize;
} job;

typedef struct batch {
    job *jobs;
    int njobs;
    atomic_int done;
    const char *out_dir, *golden_dir;
    compare_options cmp;
    int forces;
    int strict;               /* --strict: a suspect assembly fails the file */
    int engine;               /* --engine: CMD_ENGINE_* */
    int skip_existing;
    cmd_progress progress;    /* files done, on standard error */
    int quiet;
    const manifest *mf;       /* --shard: the table's manifest, else NULL */
    pthread_mutex_t lock;     /* one finished file at a time: its row, its messages */
    FILE *partial;            /* -o TABLE: TABLE.partial, rows as files finish */
    char *partial_path;       /* owned */
    line_digest head_digest;  /* of the table's head: each row's check line starts here */
    uint64_t *inputs;         /* --shard: [ninputs] hashes of the list's files, `per` each */
    long ninputs, per, nfiles;
} batch;

static void base_name(const char *path, const char **name, int *len)
{
    const char *b = strrchr(path, '/');
    b = b ? b + 1 : path;
    size_t n = strlen(b);
    if (n > 5 && strcmp(b + n - 5, ".yaml") == 0)
        n -= 5;
    else if (n > 4 && strcmp(b + n - 4, ".yml") == 0)
        n -= 4;
    *name = b;
    *len = n > 65535 ? 65535 : (int)n;
}

static int exit_of(int rc)
{
    return cmd_exit_status(rc);  /* out of memory: 3, with IO */
}

static void compare_golden(const batch *b, job *jb, const mech_table *t, const char *csv,
                           FILE *msg)
{
    const char *golden = jb->golden_path;
    if (access(golden, R_OK) != 0) {
        jb->golden = "missing";
        fprintf(msg, "%s: no golden file %s\n", jb->path, golden);
        if (jb->code == MECH_EXIT_OK)
            jb->code = MECH_EXIT_SOLVE;
        return;
    }
    int st = compare_result_file(t, csv, golden, &b->cmp, NULL, NULL);
    jb->golden = st == MECH_OK ? "match" : st == COMPARE_DIFFER ? "DIFFER" : "error";
    if (st != MECH_OK) {  /* again, to say what differs */
        compare_options o = b->cmp;
        o.table = 1;
        fprintf(msg, "%s: differs from %s:\n", jb->path, golden);
        compare_result_file(t, csv, golden, &o, msg, msg);
    }
    if (st != MECH_OK && jb->code == MECH_EXIT_OK)
        jb->code = compare_exit_status(st);
}

/* A file kept by --skip-existing: its CSV's hash and rows (steps), and
 * unless an earlier run's row gave them (jb->recorded), no residual nor
 * time (nan): the table says what is known, not 0. */
static void keep_job(job *jb)
{
    jb->kept = 1;
    if (!jb->golden)
        jb->golden = "-";
    FILE *f = fopen(jb->csv, "rb");
    char buf[65536];
    long lines = 0;
    uint64_t h = MANIFEST_HASH0;
    for (size_t n; f && (n = fread(buf, 1, sizeof buf, f)) > 0;) {
        h = manifest_hash(h, buf, n);
        for (const char *p = buf; (p = memchr(p, '\n', n - (size_t)(p - buf))); p++)
            lines++;
    }
    int same = jb->recorded && jb->has_csv && h == jb->csv_hash && jb->steps == lines - 1;
    jb->csv_hash = h;
    jb->has_csv = f && !ferror(f);
    if (f)
        fclose(f);
    if (same)
        return;  /* the row of the run that wrote this very CSV */
    jb->steps = lines > 0 ? (int)(lines - 1) : 0;
    jb->worst_residual = jb->us_per_step = NAN;
    jb->recorded = 0;
}

/* One file, start to end; everything it says goes to jb->messages. */
static void run_job(const batch *b, job *jb)
{
    struct stat there;
    if (b->skip_existing && b->out_dir && stat(jb->csv, &there) == 0 && S_ISREG(there.st_mode)) {
        keep_job(jb);  /* solved by an earlier run of this batch */
        return;
    }
    FILE *msg = open_memstream(&jb->messages, &jb->msize);
    FILE *out = msg ? msg : stderr;
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    mech_summary sum;
    mech_table t = {0};
    mech_solve_stats st = {0};
    jb->golden = "-";
    int rc = mech_load_file(jb->path, &m, &d);
    if (rc == MECH_OK)
        rc = mech_check(m, &sum, &d);
    if (rc == MECH_OK) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.forces = b->forces;
        rc = cmd_jit_solve(m, &o, &t, &st, &d, b->engine, out, jb->path);
        if (strncmp(cmd_jit_how(), "compiled", 8) == 0)
            fprintf(out, "%s: solver %s\n", jb->path, cmd_jit_how());
        if (b->strict && cmd_strict_assembly(&d) > 0 && rc == MECH_OK)
            rc = MECH_ESOLVE;
    }
    mech_diag_print(&d, out);
    mech_diag_free(&d);
    if (rc == MECH_ESOLVE && t.nrows < t.nrequested)  /* a partial sweep (issue 17) */
        fprintf(out, "%s: %d of %d rows solved, %d gap%s\n", jb->path, t.nrows, t.nrequested,
                t.ngaps, t.ngaps == 1 ? "" : "s");
    jb->code = exit_of(rc);
    jb->steps = st.steps;
    jb->worst_residual = st.worst_residual;
    jb->us_per_step = st.steps ? st.seconds / st.steps * 1e6 : 0.0;
    if (rc == MECH_OK && b->out_dir) {
        mech_diag_init(&d);
        if (mech_table_write_csv(&t, jb->csv, &d) != MECH_OK)
            jb->code = MECH_EXIT_IO;
        jb->csv_hash = MANIFEST_HASH0;  /* what mech merge checks the CSV against */
        jb->has_csv = jb->code == MECH_EXIT_OK && manifest_hash_file(&jb->csv_hash, jb->csv) == 0;
        mech_diag_print(&d, out);
        mech_diag_free(&d);
    }
    /* the table in memory against the golden file: no temporary file */
    if (rc == MECH_OK && b->golden_dir && jb->code == MECH_EXIT_OK)
        compare_golden(b, jb, &t, b->out_dir ? jb->csv : jb->path, out);
    mech_table_free(&t);
    mech_model_free(&m);
    if (msg)
        fclose(msg);
}

/* ---- checks before anything is solved (docs/cli.md, section Files) ---- */

static int by_name(const void *a, const void *b)
{
    const job *x = *(const job *const *)a, *y = *(const job *const *)b;
    int c = memcmp(x->name, y->name, (size_t)(x->name_len < y->name_len ? x->name_len : y->name_len));
    if (!c)
        c = (x->name_len > y->name_len) - (x->name_len < y->name_len);
    return c ? c : (x < y ? -1 : x > y);
}

static int same_name(const job *x, const job *y)
{
    return x->name_len == y->name_len && memcmp(x->name, y->name, (size_t)x->name_len) == 0;
}

/* Two files with the same NAME would both write DIR/NAME.csv. */
static int refuse_collisions(const batch *b)
{
    const job **order = malloc((size_t)b->njobs * sizeof *order + 1);
    if (!order)
        return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_INPUT;
    for (int i = 0; i < b->njobs; i++)
        order[i] = &b->jobs[i];
    qsort(order, (size_t)b->njobs, sizeof *order, by_name);
    int code = -1;
    for (int i = 1; i < b->njobs; i++)
        if (same_name(order[i - 1], order[i])) {
            fprintf(stderr, "mech batch: %s and %s would both be written to %s; nothing "
                    "solved (give files with distinct names)\n", order[i - 1]->path,
                    order[i]->path, order[i]->csv);
            code = MECH_EXIT_INPUT;
        }
    free(order);
    return code;
}

typedef struct file_id {
    dev_t dev;
    ino_t ino;
    const char *path;
} file_id;

static int by_id(const void *a, const void *b)
{
    const file_id *x = a, *y = b;
    if (x->dev != y->dev)
        return x->dev < y->dev ? -1 : 1;
    return x->ino < y->ino ? -1 : x->ino > y->ino;
}

/* No DIR/NAME.csv may be an input: a mechanism file or a golden file. */
static int refuse_inputs(const batch *b)
{
    file_id *ids = malloc((size_t)b->njobs * 2 * sizeof *ids + 1);
    if (!ids)
        return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_INPUT;
    size_t n = 0;
    struct stat st;
    for (int i = 0; i < b->njobs; i++) {
        const job *jb = &b->jobs[i];
        if (stat(jb->path, &st) == 0)
            ids[n++] = (file_id){st.st_dev, st.st_ino, jb->path};
        if (jb->golden_path && stat(jb->golden_path, &st) == 0)
            ids[n++] = (file_id){st.st_dev, st.st_ino, jb->golden_path};
    }
    qsort(ids, n, sizeof *ids, by_id);
    int code = -1;
    for (int i = 0; i < b->njobs; i++) {
        const job *jb = &b->jobs[i];
        if (stat(jb->csv, &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        file_id key = {st.st_dev, st.st_ino, NULL};
        const file_id *hit = bsearch(&key, ids, n, sizeof *ids, by_id);
        if (hit) {
            fprintf(stderr, "mech batch: the output %s is the input file %s; not overwriting "
                    "it, nothing solved\n", jb->csv, hit->path);
            code = MECH_EXIT_INPUT;
        }
    }
    free(ids);
    return code;
}

/* DIR/NAME.csv and the golden paths of every job; then no two outputs the
 * same, no output an input, DIR created. Returns -1 to go on, else the exit
 * status. */
static int prepare_outputs(batch *b)
{
    for (int i = 0; i < b->njobs; i++) {
        job *jb = &b->jobs[i];
        const char *dirs[2] = {b->out_dir, b->golden_dir};
        char **paths[2] = {&jb->csv, &jb->golden_path};
        for (int k = 0; k < 2; k++) {
            if (!dirs[k])
                continue;
            size_t len = strlen(dirs[k]) + (size_t)jb->name_len + 6;
            if (!(*paths[k] = malloc(len)))
                return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_INPUT;
            snprintf(*paths[k], len, "%s/%.*s.csv", dirs[k], jb->name_len, jb->name);
        }
    }
    if (!b->out_dir)
        return -1;
    int code = refuse_collisions(b);
    if (code < 0)
        code = refuse_inputs(b);
    if (code < 0 && cmd_make_dir(b->out_dir) != 0) {
        fprintf(stderr, "mech batch: cannot create the directory %s: %s\n", b->out_dir,
                strerror(errno));
        code = MECH_EXIT_IO;
    }
    return code;
}

/* The summary table; a shard's (indexed) starts with its manifest line
 * and ends each row with its index in the whole list, for mech merge. */
static void put_head(const manifest *mf, FILE *out)
{
    if (mf)
        manifest_write(mf, out);
    fprintf(out, "%-28s %-6s %7s %12s %12s %-7s%s\n", "file", "status", "steps", "worst res m",
            "us/step", "golden", mf ? " index csv" : "");
}

enum { ROW_BYTES = 65536 + 256 };  /* a row: the name (up to 65535 bytes) and the numbers */

/* The row of jb into row[ROW_BYTES], without its newline: its length. A
 * shard's row ends with the index in the whole list and the CSV's hash. */
static size_t format_row(const job *jb, const manifest *mf, char *row)
{
    static const char *const words[] = {"ok", "FAILED", "INPUT", "IO"};
    int n = snprintf(row, ROW_BYTES, "%-28.*s %-6s %7d %12.3g %12.3g %s", jb->name_len, jb->name,
                     jb->kept ? "kept" : jb->code >= 0 && jb->code <= 3 ? words[jb->code] : "?",
                     jb->steps, jb->worst_residual, jb->us_per_step, jb->golden ? jb->golden : "-");
    if (mf && jb->has_csv)
        n += snprintf(row + n, ROW_BYTES - (size_t)n, " %ld %016" PRIx64, jb->index, jb->csv_hash);
    else if (mf)
        n += snprintf(row + n, ROW_BYTES - (size_t)n, " %ld -", jb->index);
    return (size_t)n;
}

static void put_line(FILE *out, line_digest *d, const char *line, size_t n)
{
    fwrite(line, 1, n, out);
    fputc('\n', out);
    digest_line(d, line, n);
}

/* The hashes of the list's files, for mech merge to name the one that
 * differs between two shards: "# mech-inputs files=N per=P H,H,...". */
static void put_inputs(const batch *b, FILE *out, line_digest *d)
{
    char *line = NULL;
    size_t size = 0;
    FILE *mem = open_memstream(&line, &size);
    if (!mem)
        return;
    fprintf(mem, "# mech-inputs files=%ld per=%ld ", b->nfiles, b->per);
    for (long k = 0; k < b->ninputs; k++)
        fprintf(mem, "%s%016" PRIx64, k ? "," : "", b->inputs[k]);
    if (fclose(mem) == 0)
        put_line(out, d, line, size);
    free(line);
}

static int emit_table(FILE *out, const void *ctx)
{
    const batch *b = ctx;
    char *row = malloc(ROW_BYTES), *head = NULL;
    size_t hsize = 0;
    FILE *mem = open_memstream(&head, &hsize);
    line_digest d;
    digest_init(&d);
    if (!row || !mem) {
        free(row);
        if (mem)
            fclose(mem);
        free(head);
        return -1;
    }
    put_head(b->mf, mem);
    fclose(mem);
    for (char *p = head, *nl; (nl = strchr(p, '\n')); p = nl + 1)
        put_line(out, &d, p, (size_t)(nl - p));
    for (int i = 0; i < b->njobs; i++)
        put_line(out, &d, row, format_row(&b->jobs[i], b->mf, row));
    if (b->mf) {  /* a shard's table: what mech merge checks it against */
        char trailer[64];
        put_inputs(b, out, &d);
        digest_format(trailer, sizeof trailer, DIGEST_TRAILER, b->njobs, d.h);
        fputs(trailer, out);
    }
    free(row);
    free(head);
    return ferror(out) ? -1 : 0;
}

/* The rows an earlier run of this shard recorded (its TABLE, or the
 * TABLE.partial a kill left), for the files --skip-existing keeps: their
 * steps, residual, time and golden, when the row's CSV hash is that of
 * the CSV still there (keep_job). */
static void recorded_row(void *ctx, const char *r, size_t n, long line)
{
    static const char *const goldens[] = {"-", "match", "DIFFER", "missing", "error"};
    batch *b = ctx;
    batch_row br;
    char why[128];
    (void)line;
    if (batch_row_parse(r, n, 1, &br, why, sizeof why) != 0 || br.index % b->mf->shard_m !=
        b->mf->shard_k || (br.index - b->mf->shard_k) / b->mf->shard_m >= b->njobs)
        return;
    job *jb = &b->jobs[(br.index - b->mf->shard_k) / b->mf->shard_m];
    if (jb->index != br.index || br.steps > 2147483647L)
        return;
    jb->recorded = 1;
    jb->steps = (int)br.steps;
    jb->worst_residual = br.residual;
    jb->us_per_step = br.us_per_step;
    jb->csv_hash = br.csv;
    jb->has_csv = br.has_csv;
    for (size_t k = 0; k < sizeof goldens / sizeof goldens[0]; k++)
        if (!strcmp(br.golden, goldens[k]))
            jb->golden = goldens[k];
}

/* The table's head (manifest and header lines) into *head, and its digest. */
static int make_head(batch *b, char **head)
{
    size_t size = 0;
    FILE *mem = open_memstream(head, &size);
    if (!mem)
        return -1;
    put_head(b->mf, mem);
    if (fclose(mem) != 0)
        return -1;
    digest_init(&b->head_digest);
    for (char *p = *head, *nl; (nl = strchr(p, '\n')); p = nl + 1)
        digest_line(&b->head_digest, p, (size_t)(nl - p));
    return 0;
}

/* -o TABLE, a regular file (or a new name): TABLE.partial created with the
 * head, for the rows as they finish. An old one (a killed run's) is
 * replaced: the table is made again from this run. -1, or the exit status. */
static int open_partial(batch *b, const char *table, const char *head)
{
    struct stat st;
    if (!table || !strcmp(table, "-") || (stat(table, &st) == 0 && !S_ISREG(st.st_mode)))
        return -1;  /* standard output, a device, a FIFO: the table at the end only */
    size_t n = strlen(table) + 9;
    if (!(b->partial_path = malloc(n)))
        return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_IO;
    snprintf(b->partial_path, n, "%s.partial", table);
    if (lstat(b->partial_path, &st) == 0 && !S_ISREG(st.st_mode)) {
        fprintf(stderr, "mech batch: %s exists and is not a regular file; not replacing it "
                "(remove it or write another -o)\n", b->partial_path);
        return MECH_EXIT_INPUT;
    }
    if (lstat(b->partial_path, &st) == 0)
        unlink(b->partial_path);
    int fd = open(b->partial_path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0 && !(b->partial = fdopen(fd, "w")))
        close(fd);
    if (b->partial) {
        fputs(head, b->partial);
        fflush(b->partial);
    }
    if (!b->partial || ferror(b->partial)) {
        fprintf(stderr, "mech batch: cannot create %s: %s\n", b->partial_path, strerror(errno));
        return MECH_EXIT_IO;
    }
    return -1;
}

/* The summary as a table of columns (text cells for the file, the status
 * and the golden), the numbers unrounded; MECH_OK or MECH_ENOMEM. */
static int summary_columns(const batch *b, compare_table *t)
{
    static const char *const names[] = {"file", "status", "steps", "worst_residual",
                                        "us_per_step", "golden"};
    static const char *const units[] = {"-", "-", "-", "m", "us", "-"};
    static const char *const words[] = {"ok", "FAILED", "INPUT", "IO"};
    size_t nc = 6, nr = (size_t)b->njobs;
    memset(t, 0, sizeof *t);
    t->names = calloc(nc, sizeof *t->names);
    t->units = calloc(nc, sizeof *t->units);
    t->values = malloc((nr * nc + 1) * sizeof *t->values);
    t->word = malloc((nr * nc + 1) * sizeof *t->word);
    char *name = malloc(65536);
    int bad = !t->names || !t->units || !t->values || !t->word || !name;
    t->ncols = bad ? 0 : nc;
    for (size_t c = 0; c < t->ncols; c++)
        bad |= !(t->names[c] = strdup(names[c])) || !(t->units[c] = strdup(units[c]));
    for (size_t i = 0; !bad && i < nr; i++, t->nrows++) {
        const job *jb = &b->jobs[i];
        int *w = t->word + i * nc;
        double *v = t->values + i * nc;
        snprintf(name, 65536, "%.*s", jb->name_len, jb->name);
        w[0] = compare_table_intern(t, name);
        w[1] = compare_table_intern(t, jb->kept ? "kept" : jb->code >= 0 && jb->code <= 3
                                                            ? words[jb->code] : "?");
        w[5] = compare_table_intern(t, jb->golden ? jb->golden : "-");
        w[2] = w[3] = w[4] = -1;
        v[0] = v[1] = v[5] = NAN;
        v[2] = jb->steps;
        v[3] = jb->worst_residual;
        v[4] = jb->us_per_step;
        bad = w[0] < 0 || w[1] < 0 || w[5] < 0;
    }
    free(name);
    return bad ? MECH_ENOMEM : MECH_OK;
}

/* -o TABLE.h5: the summary as HDF5 (output_write_h5_table); MECH_OK, or
 * an error status with d. */
static int write_table_h5(const batch *b, const char *table, mech_diag *d)
{
    compare_table t;
    int rc = summary_columns(b, &t);
    const char *keys[] = {"mech_version", "command"}, *values[] = {MECH_VERSION, "batch"};
    if (rc == MECH_OK)
        rc = output_write_h5_table(&t, table, keys, values, 2, d);
    else
        diag_nomem(d, table, (mech_mark){0, 0});
    compare_table_free(&t);
    return rc;
}

/* The table written whole to TABLE (or standard output), then TABLE.partial
 * removed; MECH_EXIT_OK or MECH_EXIT_IO. */
static int write_table(batch *b, const char *table)
{
    int partial_bad = b->partial && (fflush(b->partial) != 0 || ferror(b->partial));
    if (partial_bad)
        fprintf(stderr, "mech batch: cannot write %s (the rows as they finished)\n",
                b->partial_path);
    mech_diag d;
    mech_diag_init(&d);
    int rc = table && output_is_h5_name(table) ? write_table_h5(b, table, &d)
             : write_file_whole(table ? table : "-", emit_table, b, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK && b->partial_path)
        unlink(b->partial_path);
    return rc == MECH_OK && !partial_bad ? MECH_EXIT_OK : MECH_EXIT_IO;
}

/* A file solved; its row (to TABLE.partial) and its messages out at once,
 * so memory holds no messages of finished files. */
static void batch_job(void *ctx, long i)
{
    batch *b = ctx;
    job *jb = &b->jobs[i];
    run_job(b, jb);
    pthread_mutex_lock(&b->lock);
    if (b->partial) {  /* the row and its check line, on disk now: a kill keeps it */
        static char row[ROW_BYTES];  /* under the lock */
        char check[64];
        size_t n = format_row(jb, b->mf, row);
        line_digest d = b->head_digest;
        digest_line(&d, row, n);
        rows_block_line(check, sizeof check, 1, &d);
        fwrite(row, 1, n, b->partial);
        fputc('\n', b->partial);
        fputs(check, b->partial);
        fflush(b->partial);
    }
    if (!b->quiet && jb->messages && jb->msize)
        fputs(jb->messages, stderr);
    pthread_mutex_unlock(&b->lock);
    free(jb->messages);
    jb->messages = NULL;
    cmd_progress_update(&b->progress, atomic_fetch_add(&b->done, 1) + 1, b->njobs);
}

/* The command line of mech batch (cmd_opts_parse). */
typedef struct batch_opts {
    cmd_operands files;       /* FILE... (grown by --files-from) */
    int nthreads, quiet;
    cmd_shard shard;          /* --shard K/M */
    int unsolvable_ok, forces, skip_existing, strict;
    int engine;               /* --engine: CMD_ENGINE_* */
    const char *files_from;   /* --files-from LIST */
    const char *table;        /* -o TABLE */
    const char *out_dir, *golden_dir;
    double rtol, atol;        /* the golden comparison's */
} batch_opts;

#define AT(field) offsetof(batch_opts, field)

static const cmd_opt options[] = {
    CMD_JOBS_ENTRY(AT(nthreads)),
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(table), .flags = CMD_RUN_ONLY,
     .label = "-o, --output TABLE",
     .help = "write the table to TABLE (whole, when all are done;\n"
             "meanwhile each row goes to TABLE.partial as its file\n"
             "finishes); default: standard output; TABLE.h5 or\n"
             ".hdf5: HDF5 (not with --shard)"},
    {.names = "--files-from", .kind = CMD_OPT_TEXT, .at = AT(files_from), .flags = CMD_RUN_ONLY,
     .label = "--files-from LIST",
     .help = "also the files named in LIST, one path per line ('-':\n"
             "standard input), after those given as arguments"},
    {.names = "--out-dir", .kind = CMD_OPT_TEXT, .at = AT(out_dir), .label = "--out-dir DIR",
     .help = "write DIR/NAME.csv for each FILE (NAME = its base name\n"
             "without .yaml; DIR created if missing; two files with\n"
             "the same NAME are refused); without it nothing is written"},
    {.names = "--golden", .kind = CMD_OPT_TEXT, .at = AT(golden_dir), .label = "--golden DIR",
     .help = "compare each result with DIR/NAME.csv (mech compare)"},
    {.names = "--rtol", .kind = CMD_OPT_REAL, .at = AT(rtol), .lo = 0, .hi = DBL_MAX,
     .expect = "needs a number >= 0", .label = "--rtol R, --atol A",
     .help = "tolerances of the golden comparison (1e-9, 1e-12)"},
    {.names = "--atol", .kind = CMD_OPT_REAL, .at = AT(atol), .lo = 0, .hi = DBL_MAX,
     .expect = "needs a number >= 0"},
    {.names = "--shard", .kind = CMD_OPT_CALL, .at = AT(shard), .call = cmd_read_shard,
     .flags = CMD_RUN_ONLY, .label = "--shard K/M",
     .help = "solve only the files with index % M == K (0 <= K < M),\n"
             "to split one batch over M machines; the table then starts\n"
             "with a '# mech-manifest' line and an index column, for\n"
             "mech merge"},
    {.names = "--skip-existing", .kind = CMD_OPT_FLAG, .at = AT(skip_existing), .flag = 1,
     .flags = CMD_RUN_ONLY, .label = "--skip-existing",
     .help = "a file whose DIR/NAME.csv exists is not solved again\n"
             "(status 'kept'; with --out-dir)"},
    {.names = "--unsolvable-ok", .kind = CMD_OPT_FLAG, .at = AT(unsolvable_ok), .flag = 1,
     .flags = CMD_RUN_ONLY, .label = "--unsolvable-ok",
     .help = "a file that cannot be solved is a result (FAILED in the\n"
             "table), not a failure: exit 0 unless a file is invalid,\n"
             "unreadable or differs from its golden"},
    {.names = "--forces", .kind = CMD_OPT_FLAG, .at = AT(forces), .flag = 1, .label = "--forces",
     .help = "also the force analysis, for every file"},
    CMD_STRICT_ENTRY(AT(strict)),
    CMD_ENGINE_ENTRY(AT(engine)),
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = AT(quiet), .flag = 1,
     .flags = CMD_RUN_ONLY, .label = "-q, --quiet",
     .help = "no progress report (a bar on a terminal, else a line every\n"
             "5 s) and no per-file messages, only the table"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_batch_spec = {
    .name = "batch",
    .summary = "solve many files on worker threads, with golden comparisons",
    .usage = "usage: mech batch FILE... [-j N] [--out-dir DIR] [--golden DIR] [--shard K/M]\n"
             "                  [--rtol R] [--atol A] [--forces] [-q] [--files-from LIST]\n"
             "                  [--skip-existing] [--unsolvable-ok] [--strict] [-o TABLE]\n"
             "                  [--engine auto|compiled|interpreted]\n",
    .about = "Solve many mechanism files on N worker threads, each exactly as 'mech solve\n"
             "FILE' would, and print a summary table: file, status, steps, worst residual,\n"
             "time per step, and the golden comparison. A failing file does not stop or\n"
             "change the others. Each file's messages are printed when it is done.\n",
    .opts = options,
    .column = 20,
    .exits = "exit status: 0 every file solved (and matched its golden), 1 some file could\n"
             "not be solved or differs from its golden, 2 bad usage or an invalid file,\n"
             "3 a file cannot be read or written\n",
    .file_at = AT(files),
};

/* The options into b and *bo. -1 when fine, else the exit status (the
 * problem printed). */
static int parse_batch_args(int argc, char **argv, batch *b, batch_opts *bo)
{
    int code = cmd_opts_parse(&cmd_batch_spec, argc, argv, bo);
    if (code >= 0)
        return code;
    if (bo->files.n == 0 && !bo->files_from)
        return cmd_usage_error("batch", "%s", "no files given (usage: mech batch FILE... [-j N])");
    if (bo->skip_existing && !bo->out_dir)
        return cmd_usage_error("batch", "%s", "--skip-existing needs --out-dir DIR");
    if (bo->shard.given && bo->table && output_is_h5_name(bo->table))
        return cmd_usage_error("batch", "%s", "--shard with -o TABLE.h5: a shard's table is "
                               "text, for mech merge (its rows are checked as text); write "
                               "-o TABLE and mech merge -o OUT");
    b->out_dir = bo->out_dir;
    b->golden_dir = bo->golden_dir;
    b->cmp.rtol = bo->rtol;
    b->cmp.atol = bo->atol;
    b->forces = bo->forces;
    b->strict = bo->strict;
    b->engine = bo->engine;
    b->skip_existing = bo->skip_existing;
    return -1;
}

/* --files-from LIST: its lines (one path each; blank lines skipped)
 * appended to *files, which grows; the text stays in *text (owned). -1
 * when read, else the exit status. */
static int read_list(const char *list, char **text, const char ***files, int *nfiles)
{
    FILE *f = strcmp(list, "-") == 0 ? stdin : fopen(list, "r");
    size_t size = 0;
    FILE *mem = f ? open_memstream(text, &size) : NULL;
    char buf[65536];
    for (size_t n; mem && (n = fread(buf, 1, sizeof buf, f)) > 0;)
        fwrite(buf, 1, n, mem);
    int bad = !f || ferror(f);
    if (f && f != stdin)
        fclose(f);
    if (bad || !mem) {
        if (mem)
            fclose(mem);
        fprintf(stderr, "mech batch: cannot read the list %s: %s\n", list,
                f ? "read error" : strerror(errno));
        return MECH_EXIT_IO;
    }
    if (fclose(mem) != 0)
        return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_IO;
    for (char *line = *text, *nl; *line; line = nl + 1) {
        nl = line + strcspn(line, "\n");
        int last = *nl == '\0';
        *nl = '\0';
        if (*line) {
            const char **grown = realloc(*files, (size_t)(*nfiles + 2) * sizeof *grown);
            if (!grown)
                return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_IO;
            *files = grown;
            (*files)[(*nfiles)++] = line;
        }
        if (last)
            break;
    }
    if (*nfiles == 0)
        return cmd_usage_error("batch", "no files given (the list %s is empty)", list);
    return -1;
}

/* The input hash of a shard's table: every file of the whole list, in
 * order, its path and the hash of its bytes, so a file edited between two
 * shards makes them two runs to mech merge. An unreadable file is hashed as
 * such (its row says IO). */
static uint64_t hash_inputs(batch *b, const char **files, int nfiles)
{
    uint64_t h = MANIFEST_HASH0;
    b->nfiles = nfiles;  /* and each block of `per` files' hash: mech merge names the file */
    b->per = nfiles > 4096 ? (nfiles + 4095) / 4096 : 1;
    b->ninputs = (nfiles + b->per - 1) / b->per;
    b->inputs = malloc((size_t)b->ninputs * sizeof *b->inputs + 1);
    for (int i = 0; i < nfiles; i++) {
        uint64_t content = MANIFEST_HASH0;
        unsigned char bytes[8];
        if (manifest_hash_file(&content, files[i]) != 0)
            content = 0;  /* no file hashes to 0 in practice; "unreadable" */
        for (int k = 0; k < 8; k++)
            bytes[k] = (unsigned char)(content >> (8 * k));
        h = manifest_hash(h, files[i], strlen(files[i]) + 1);
        h = manifest_hash(h, bytes, sizeof bytes);
        if (b->inputs && i % b->per == 0)
            b->inputs[i / b->per] = MANIFEST_HASH0;
        if (b->inputs)
            b->inputs[i / b->per] = manifest_hash(manifest_hash(b->inputs[i / b->per], files[i],
                                                                strlen(files[i]) + 1), bytes, 8);
    }
    return h;
}

/* A manifest argument: an option that changes a row, with its value (a
 * file is in the list's hash). */
static void manifest_arg(void *ctx, const cmd_opt *o, const char *name, const char *value)
{
    if (!o || (o->flags & CMD_RUN_ONLY))
        return;
    manifest_add_arg(ctx, name);
    if (value)
        manifest_add_arg(ctx, value);
}

/* The manifest of a shard's table: the whole list (its paths and contents)
 * as the input hash, the options that change a row as the arguments. */
static manifest *make_manifest(batch *b, const batch_opts *bo, int argc, char **argv,
                               const char **files, int nfiles)
{
    manifest *mf = calloc(1, sizeof *mf);
    if (!mf)
        return NULL;
    snprintf(mf->version, sizeof mf->version, "%s", MECH_VERSION);
    snprintf(mf->command, sizeof mf->command, "batch");
    mf->shard_k = bo->shard.k;
    mf->shard_m = bo->shard.m;
    mf->rows = b->njobs;
    mf->total = nfiles;
    mf->grid = MANIFEST_HASH0;
    mf->input = hash_inputs(b, files, nfiles);
    cmd_opts_each(&cmd_batch_spec, argc, argv, manifest_arg, mf);
    return mf;
}

/* The jobs of every file given; their outputs checked over all of them, so
 * that shards merged later cannot collide either; then only this shard's
 * jobs are kept. -1 when fine, else the exit status. */
static int make_jobs(batch *b, const batch_opts *bo, const char **files, int nfiles)
{
    b->jobs = calloc((size_t)nfiles, sizeof *b->jobs);
    if (!b->jobs)
        return fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_IO;
    for (int i = 0; i < nfiles; i++) {
        job *jb = &b->jobs[b->njobs++];
        jb->index = i;
        jb->path = files[i];
        base_name(files[i], &jb->name, &jb->name_len);
    }
    int code = prepare_outputs(b), kept = 0;
    for (int i = 0; i < b->njobs; i++)
        if (code < 0 && i % bo->shard.m == bo->shard.k) {
            b->jobs[kept++] = b->jobs[i];
        } else {
            free(b->jobs[i].csv);
            free(b->jobs[i].golden_path);
        }
    b->njobs = kept;
    return code;
}

/* The summary table; the worst outcome: a failed solve or differing golden
 * (1) outranks invalid input (2) and unreadable files (3), then success. */
static int report_jobs(batch *b, const batch_opts *bo)
{
    int code = MECH_EXIT_OK;
    for (int i = 0; i < b->njobs; i++) {
        job *jb = &b->jobs[i];
        free(jb->csv);
        free(jb->golden_path);
        int unsolved = jb->code == MECH_EXIT_SOLVE && !strcmp(jb->golden ? jb->golden : "-", "-");
        if (unsolved && bo->unsolvable_ok)
            continue;  /* a result: FAILED in the table */
        if (jb->code == MECH_EXIT_SOLVE || (code == MECH_EXIT_OK && jb->code != MECH_EXIT_OK))
            code = jb->code;
    }
    int written = write_table(b, bo->table);
    return written != MECH_EXIT_OK && code == MECH_EXIT_OK ? written : code;
}

int cmd_batch(int argc, char **argv)
{
    batch b;
    memset(&b, 0, sizeof b);
    compare_options_default(&b.cmp);
    b.cmp.table = 0;
    batch_opts bo = {.nthreads = parallel_default_jobs(), .shard = {0, 1, 0}, .rtol = b.cmp.rtol,
                     .atol = b.cmp.atol};
    pthread_mutex_init(&b.lock, NULL);
    char *list = NULL;
    manifest *mf = NULL;
    int code = parse_batch_args(argc, argv, &b, &bo);
    const char **files = bo.files.v;
    int nfiles = bo.files.n;
    if (code < 0 && bo.files_from)
        code = read_list(bo.files_from, &list, &files, &nfiles);
    if (code < 0)
        code = cmd_refuse_input("batch", bo.table, files, nfiles);
    if (code < 0 && bo.files_from)
        code = cmd_refuse_input("batch", bo.table, &bo.files_from, 1);
    if (code < 0)
        code = make_jobs(&b, &bo, files, nfiles);
    if (code < 0 && bo.shard.given && !(mf = make_manifest(&b, &bo, argc, argv, files, nfiles)))
        code = (fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_IO);
    b.mf = mf;
    b.quiet = bo.quiet;
    char *head = NULL;
    if (code < 0 && make_head(&b, &head) != 0)
        code = (fprintf(stderr, "mech batch: out of memory\n"), MECH_EXIT_IO);
    if (code < 0 && mf && b.skip_existing && bo.table)  /* before TABLE.partial is replaced */
        rows_read_recorded(bo.table, head, &b.head_digest, recorded_row, &b);
    if (code < 0)
        code = open_partial(&b, bo.table, head);
    free(head);
    if (code < 0) {
        cmd_progress_init(&b.progress, "batch", "files", bo.quiet);
        parallel_run(b.njobs, bo.nthreads, batch_job, &b);
        cmd_progress_done(&b.progress);
        code = report_jobs(&b, &bo);
    }
    if (b.partial)
        fclose(b.partial);
    free(b.partial_path);
    pthread_mutex_destroy(&b.lock);
    free(mf);
    free(b.inputs);
    free(b.jobs);
    free(files);
    free(list);
    return code;
}

int batch_out_dir_of_manifest(const manifest *m, char *dir, size_t size)
{
    char **words = NULL;
    batch_opts bo = {.shard = {0, 1, 0}};
    int rc = manifest_args_parse(m, &cmd_batch_spec, &bo, &words);
    dir[0] = '\0';
    if (rc == 0 && bo.out_dir)
        snprintf(dir, size, "%s", bo.out_dir);
    free(bo.files.v);
    free(words);
    return rc;
}
