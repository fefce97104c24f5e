/* src/cmd_merge.c: `mech merge -o OUT SHARD...`, the shards of a sweep
 * (their CSVs) or of a batch (their summary tables) joined into one file
 * once their manifests (src/cmd_manifest.h) prove that they are the pieces
 * of one run, each present once and complete (docs/batch.md, "Manifests and
 * mech merge"). Anything wrong is named, shard by shard, and nothing is
 * written. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cmd_manifest.h"
#include "commands.h"
#include "output.h"

const char cmd_merge_help[] =
    "usage: mech merge -o OUT SHARD...\n"
    "\n"
    "Join the outputs of the shards of one run (mech sweep --shard K/M -o CSV, or\n"
    "mech batch --shard K/M -o TABLE) into OUT, rows in index order. Each shard\n"
    "starts with a '# mech-manifest' line; merge checks that all come from the same\n"
    "run (version, arguments, input file hash, grid hash), that every shard K/M of\n"
    "it is given exactly once and is complete, that every index 0..N-1 appears\n"
    "exactly once, and that the headers agree. Runs numbered with --index-offset\n"
    "merge into one index space. For batch summaries, every file solved must have\n"
    "its CSV (with that many rows) in the run's --out-dir. Anything wrong is an\n"
    "error naming the shard (\"shard 2/4 missing\", \"shard 2/4 unfinished: 37 of\n"
    "500 rows\": fewer rows than its manifest, or a SHARD not there whose\n"
    "SHARD.partial is, left by a killed run), and nothing is written.\n"
    "OUT has no manifest: it equals the output of the same run without --shard.\n"
    "\n"
    "options:\n"
    "  -o FILE           the merged file (required; '-' for standard output)\n"
    "  -h, --help        show this help\n"
    "\n"
    "exit status: 0 merged, 2 bad usage or shards that do not make one run (the\n"
    "messages say which), 3 a file cannot be read or written\n";

typedef struct shard {
    const char *path;   /* as given; or SHARD.partial, read when SHARD is not there */
    char *partial;      /* SHARD.partial (owned) when that was read */
    char *buf;          /* the whole file */
    manifest man;
    char *header;       /* the header line, in buf */
    long nrows;
} shard;

typedef struct merge {
    shard *shards;
    int n;
    int batch;          /* summaries of mech batch, not CSVs of mech sweep */
    long total;         /* indices 0 .. total-1 */
    const char **rows;  /* [total] the row of each index, in a shard's buf */
    int errors;
} merge;

static void complain(merge *g, const char *fmt, ...) CMD_PRINTF(2, 3);
static void complain(merge *g, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "mech merge: ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    g->errors++;
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 16, n = 0, got;
    char *buf = malloc(cap + 1);
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0)
        if ((n += got) == cap) {
            char *b = realloc(buf, 2 * cap + 1);
            if (!b)
                free(buf);
            buf = b;
            cap *= 2;
        }
    int bad = ferror(f);
    fclose(f);
    if (buf && bad) {
        free(buf);
        errno = EIO;
        return NULL;
    }
    if (buf)
        buf[n] = '\0';
    return buf;
}

/* The index of a row: its first field in a sweep ("12,"), its last in a
 * batch's table (" 12"). */
static long row_index(const merge *g, const char *row)
{
    const char *s = row;
    if (g->batch && (s = strrchr(row, ' ')))
        s++;
    char *end;
    long idx = s ? strtol(s, &end, 10) : -1;
    return !s || end == s || *end != (g->batch ? '\0' : ',') ? -1 : idx;
}

/* "shard K/M (path)" */
static const char *name(const shard *s, char *buf, size_t size)
{
    snprintf(buf, size, "shard %d/%d (%s)", s->man.shard_k, s->man.shard_m, s->path);
    return buf;
}

/* The file of shard s: SHARD, or when it is not there but SHARD.partial
 * is (a run killed before its end), that one, so the shard is named as
 * unfinished rather than unreadable. */
static char *read_file_or_partial(shard *s)
{
    char *buf = slurp(s->path);
    if (buf || errno != ENOENT)
        return buf;
    size_t n = strlen(s->path) + 9;
    if (!(s->partial = malloc(n)))
        return NULL;
    snprintf(s->partial, n, "%s.partial", s->path);
    if ((buf = slurp(s->partial))) {
        s->path = s->partial;
        return buf;
    }
    errno = ENOENT;  /* the message is about SHARD, which is not there */
    return NULL;
}

/* Reads shard s: its manifest, header and rows (counted; NUL-terminated
 * lines; a last line without its end, cut by a kill, is not a row). 0, or
 * -1 with the problem printed (3 when unreadable). */
static int read_shard(merge *g, shard *s)
{
    if (!(s->buf = read_file_or_partial(s))) {
        fprintf(stderr, "mech merge: cannot read %s: %s\n", s->path, strerror(errno));
        return MECH_EXIT_IO;
    }
    char *nl = strchr(s->buf, '\n');
    if (nl)
        *nl = '\0';
    if (!nl || manifest_parse(s->buf, &s->man) != 0) {
        complain(g, "%s: no '# mech-manifest' line at the top (not the output of mech sweep "
                 "or mech batch with --shard, or an unfinished one)", s->path);
        return -1;
    }
    s->header = nl + 1;
    if (!(nl = strchr(s->header, '\n'))) {
        complain(g, "%s: no header line", s->path);
        return -1;
    }
    *nl = '\0';
    for (char *p = nl + 1; *p; p = nl + 1) {
        if (!(nl = strchr(p, '\n'))) {
            *p = '\0';  /* cut off: the row count says the shard is unfinished */
            break;
        }
        *nl = '\0';
        s->nrows++;
    }
    return 0;
}

/* Every shard's manifest against the first's run, the shards of each K/M. */
static void check_runs(merge *g)
{
    const shard *s0 = &g->shards[0];
    char a[512], b[512];
    for (int i = 1; i < g->n; i++) {
        const manifest *m = &g->shards[i].man, *m0 = &s0->man;
        const char *what = strcmp(m->command, m0->command) ? "command"
                           : strcmp(m->version, m0->version) ? "mech version"
                           : m->input != m0->input ? "input file (its contents)"
                           : m->grid != m0->grid ? "grid" : m->total != m0->total ? "number of variants"
                           : strcmp(m->args, m0->args) ? "arguments" : NULL;
        if (what && !(m->offset != m0->offset && !strcmp(m->command, m0->command)))
            complain(g, "%s is not from the same run as %s: its %s differs", name(&g->shards[i], a, sizeof a),
                     name(s0, b, sizeof b), what);
        if (strcmp(g->shards[i].header, s0->header) != 0)
            complain(g, "%s: its header differs from that of %s", name(&g->shards[i], a, sizeof a),
                     name(s0, b, sizeof b));
    }
    for (int i = 0; i < g->n; i++) {  /* each run: every K of its M once */
        const shard *s = &g->shards[i];
        int first = 1;
        for (int j = 0; j < i; j++)
            first &= !manifest_same_run(&g->shards[j].man, &s->man);
        for (int j = 0; first && j < g->n; j++) {
            const shard *t = &g->shards[j];
            if (manifest_same_run(&t->man, &s->man) && t->man.shard_m != s->man.shard_m)
                complain(g, "%s splits the run in %d shards, %s in %d", name(t, a, sizeof a),
                         t->man.shard_m, name(s, b, sizeof b), s->man.shard_m);
        }
        for (int k = 0; first && k < s->man.shard_m; k++) {
            int seen = 0;
            for (int j = 0; j < g->n; j++) {
                const shard *t = &g->shards[j];
                if (!manifest_same_run(&t->man, &s->man) || t->man.shard_k != k ||
                    t->man.shard_m != s->man.shard_m)
                    continue;
                if (seen++)
                    complain(g, "shard %d/%d given twice (%s)", k, s->man.shard_m, t->path);
            }
            if (!seen && s->man.offset)
                complain(g, "shard %d/%d of the run with --index-offset %ld missing", k,
                         s->man.shard_m, s->man.offset);
            else if (!seen)
                complain(g, "shard %d/%d missing", k, s->man.shard_m);
        }
    }
}

/* Each shard's rows into g->rows: counted against its manifest, each index
 * of its run and shard, none twice. */
static void place_rows(merge *g)
{
    char a[512];
    for (int i = 0; i < g->n; i++) {
        const shard *s = &g->shards[i];
        long want = manifest_shard_rows(s->man.total, s->man.shard_k, s->man.shard_m);
        if (s->nrows < want || s->partial)  /* a run killed, or its file cut */
            complain(g, "shard %d/%d unfinished: %ld of %ld rows (%s)", s->man.shard_k,
                     s->man.shard_m, s->nrows, want, s->path);
        else if (s->nrows != s->man.rows || s->nrows != want)
            complain(g, "%s: %ld rows, its manifest says %ld (edited)", name(s, a, sizeof a),
                     s->nrows, want);
        const char *p = s->header + strlen(s->header) + 1;
        int bad = 0;  /* the first few bad rows of a shard are named */
        for (long r = 0; r < s->nrows; r++, p += strlen(p) + 1) {
            long idx = row_index(g, p), local = idx - s->man.offset;
            int foreign = idx < 0 || local < 0 || local >= s->man.total ||
                          local % s->man.shard_m != s->man.shard_k;
            if (!foreign && !g->rows[idx]) {
                g->rows[idx] = p;
                continue;
            }
            if (bad++ < 3)
                complain(g, foreign ? "%s: row %ld (index %ld) is not a row of this shard"
                                    : "%s: row %ld (index %ld) is also in another shard",
                         name(s, a, sizeof a), r + 1, idx);
            else
                g->errors++;
        }
    }
}

/* Every index 0 .. total-1 has its row; the missing ones as ranges. */
static void check_coverage(merge *g)
{
    for (long i = 0; i < g->total; i++) {
        if (g->rows[i])
            continue;
        long j = i;
        while (j + 1 < g->total && !g->rows[j + 1])
            j++;
        if (j == i)
            complain(g, "index %ld is in no shard", i);
        else
            complain(g, "indices %ld..%ld are in no shard", i, j);
        i = j;
    }
}

/* The value of option opt in a manifest's escaped arguments, unescaped
 * into out (size bytes); 0, or -1 when absent. */
static int manifest_option(const char *args, const char *opt, char *out, size_t size)
{
    char tok[4096];
    int want = 0;
    for (const char *p = args; *p;) {
        size_t n = 0;
        for (; *p && *p != ' '; p++) {
            char c = *p;
            if (c == '\\' && p[1] == 'x' && p[2] && p[3]) {
                char hex[3] = {p[2], p[3], 0};
                c = (char)strtol(hex, NULL, 16);
                p += 3;
            } else if (c == '\\' && p[1]) {
                c = *++p;
            }
            if (n + 1 < sizeof tok)
                tok[n++] = c;
        }
        tok[n] = '\0';
        if (*p == ' ')
            p++;
        if (want)
            return snprintf(out, size, "%s", tok), 0;
        want = strcmp(tok, opt) == 0;
    }
    return -1;
}

/* A batch summary's rows against the CSVs in the run's --out-dir: each file
 * solved (ok, kept) has DIR/NAME.csv, and an ok one has steps + 1 lines. */
static void check_out_dir(merge *g)
{
    char dir[4096], path[8192], name_[256], status[16];
    if (manifest_option(g->shards[0].man.args, "--out-dir", dir, sizeof dir) != 0)
        return;
    for (long i = 0; i < g->total; i++) {
        int steps = -1;
        if (!g->rows[i] || sscanf(g->rows[i], "%255s %15s %d", name_, status, &steps) < 2 ||
            (strcmp(status, "ok") != 0 && strcmp(status, "kept") != 0))
            continue;
        snprintf(path, sizeof path, "%s/%s.csv", dir, name_);
        FILE *f = fopen(path, "r");
        if (!f) {
            complain(g, "index %ld (%s) is %s in its summary, but %s cannot be read: %s", i, name_,
                     status, path, strerror(errno));
            continue;
        }
        long lines = 0;
        for (int c; (c = getc(f)) != EOF;)
            lines += c == '\n';
        fclose(f);
        if (!strcmp(status, "ok") && lines != steps + 1L)
            complain(g, "index %ld (%s): %s has %ld rows, its summary says %d", i, name_, path,
                     lines - 1, steps);
    }
}

/* A line without a batch table's index (as mech batch alone writes it). */
static void put_unindexed(const merge *g, const char *line, FILE *f)
{
    const char *cut = g->batch ? strrchr(line, ' ') : NULL;
    if (cut && g->batch && line == g->shards[0].header)
        while (cut > line && cut[-1] == ' ')
            cut--;  /* the header's "golden " padding */
    fprintf(f, "%.*s\n", cut ? (int)(cut - line) : (int)strlen(line), line);
}

static int emit_merged(FILE *f, const void *ctx)
{
    const merge *g = ctx;
    put_unindexed(g, g->shards[0].header, f);
    for (long i = 0; i < g->total; i++)
        put_unindexed(g, g->rows[i], f);
    return ferror(f) ? -1 : 0;
}

/* The largest index + 1 over the runs, or -1 when too many to hold. */
static long index_space(const merge *g)
{
    long total = 0;
    for (int i = 0; i < g->n; i++) {
        const manifest *m = &g->shards[i].man;
        if (m->offset + m->total > total)
            total = m->offset + m->total;
    }
    return total > 100000000000L ? -1 : total;
}

static int merge_shards(merge *g, const char *out)
{
    int code = -1;
    for (int i = 0; i < g->n && code < 0; i++) {
        int rc = read_shard(g, &g->shards[i]);
        code = rc > 0 ? rc : -1;
    }
    if (code >= 0 || g->errors)
        return code >= 0 ? code : MECH_EXIT_INPUT;
    g->batch = strcmp(g->shards[0].man.command, "batch") == 0;
    check_runs(g);
    if (g->errors)
        return MECH_EXIT_INPUT;
    if ((g->total = index_space(g)) < 0 || !(g->rows = calloc((size_t)g->total + 1, sizeof *g->rows)))
        return fprintf(stderr, "mech merge: out of memory\n"), MECH_EXIT_IO;
    place_rows(g);
    if (!g->errors)
        check_coverage(g);
    if (!g->errors && g->batch)
        check_out_dir(g);
    if (g->errors) {
        fprintf(stderr, "mech merge: %d problem%s; nothing written\n", g->errors, g->errors == 1 ? "" : "s");
        return MECH_EXIT_INPUT;
    }
    mech_diag d;
    mech_diag_init(&d);
    int rc = write_file_whole(out, emit_merged, g, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return rc == MECH_OK ? MECH_EXIT_OK : MECH_EXIT_IO;
}

int cmd_merge(int argc, char **argv)
{
    const char *out = NULL;
    merge g;
    memset(&g, 0, sizeof g);
    g.shards = calloc((size_t)argc + 1, sizeof *g.shards);
    if (!g.shards)
        return fprintf(stderr, "mech merge: out of memory\n"), MECH_EXIT_IO;
    int code = -1;
    for (int i = 1; i < argc && code < 0; i++) {
        if (cmd_wants_help(argv[i]))
            code = (fputs(cmd_merge_help, stdout), MECH_EXIT_OK);
        else if (!strcmp(argv[i], "-o") && i + 1 < argc)
            out = argv[++i];
        else if (argv[i][0] == '-' && argv[i][1])
            code = cmd_usage_error("merge", "unknown option or option without a value '%s'", argv[i]);
        else
            g.shards[g.n++].path = argv[i];
    }
    if (code < 0 && !out)
        code = cmd_usage_error("merge", "%s", "-o OUT is required (the merged file; - for standard output)");
    if (code < 0 && g.n == 0)
        code = cmd_usage_error("merge", "%s", "no shard files given");
    for (int i = 0; code < 0 && i < g.n; i++)
        code = cmd_refuse_input("merge", out, &g.shards[i].path, 1);
    if (code < 0)
        code = merge_shards(&g, out);
    for (int i = 0; i < g.n; i++) {
        free(g.shards[i].buf);
        free(g.shards[i].partial);
    }
    free(g.shards);
    free(g.rows);
    return code;
}
