/* src/cli/cmd_merge.c: `mech merge -o OUT [--study FILE] SHARD...`, the shards
 * of a sweep (their CSVs) or of a batch (their summary tables) joined into
 * one file once their manifests (src/cli/cli.h) prove that they are
 * the pieces of one run, each present once and complete, and their rows
 * prove their content: each shard's digest line, each row's cells, a
 * sweep's parameters recomputed from the grid, a batch's CSVs against
 * their hashes (docs/batch.md, "What merge proves").
 *
 * It streams: the manifests are read first (the structure of the runs),
 * then each shard alone (pass 1: every row checked), then all at once
 * (pass 2: the row of index i taken from the shard that holds it, a k-way
 * merge whose next shard is computed, and the digests checked again), so
 * memory does not grow with the rows. Anything wrong is named, shard by
 * shard (a bounded number of lines), and nothing is written. */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "output.h"

typedef struct merge_args {
    const char *out;
    const char *study;
    cmd_operands shards;
} merge_args;

static const cmd_opt options[] = {
    {.names = "-o", .kind = CMD_OPT_TEXT, .at = offsetof(merge_args, out), .label = "-o FILE",
     .help = "the merged file (required; '-' for standard output);\n"
             "OUT.h5 or .hdf5: HDF5 (shards may be CSV or HDF5)"},
    {.names = "--study", .kind = CMD_OPT_TEXT, .at = offsetof(merge_args, study),
     .label = "--study FILE", .help = "the ranges of a study split with --index-offset"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_merge_spec = {
    .name = "merge",
    .summary = "join the shards of a sweep or batch, checking their manifests",
    .usage = "usage: mech merge -o OUT [--study FILE] SHARD...\n",
    .about = "Join the outputs of the shards of one run (mech sweep --shard K/M -o CSV, or\n"
             "mech batch --shard K/M -o TABLE) into OUT, rows in index order. Each shard\n"
             "starts with a '# mech-manifest' line and ends with a '# mech-digest' line;\n"
             "merge checks that all come from the same run (version, arguments, input file\n"
             "hash, grid hash), that every shard K/M of it is given exactly once and is\n"
             "complete, that its rows are those its digest line was written for, each with\n"
             "the header's fields and its shard's index in order (a sweep's parameter\n"
             "values recomputed from the grid), that every index 0..N-1 appears exactly\n"
             "once, and that the headers agree. Runs numbered with --index-offset merge\n"
             "into one index space; --study FILE lists the ranges of the whole study\n"
             "('OFFSET COUNT' per line), so that a range with no shard at all is named.\n"
             "For batch summaries, every file solved must have its CSV (with that many\n"
             "rows and the bytes its shard hashed) in the run's --out-dir. Anything wrong\n"
             "is an error naming the shard (\"shard 2/4 missing\", \"shard 2/4 unfinished:\n"
             "37 of 500 rows\": fewer rows than its manifest, or a SHARD not there whose\n"
             "SHARD.partial is, left by a killed run), and nothing is written.\n"
             "OUT has no manifest: it equals the output of the same run without --shard.\n",
    .opts = options,
    .column = 20,
    .exits = "exit status: 0 merged, 2 bad usage or shards that do not make one run (the\n"
             "messages say which), 3 a file cannot be read or written\n",
    .file_at = offsetof(merge_args, shards),
};

enum {
    LINE_MAX_BYTES = 1 << 20,  /* a longer line is no line of a shard */
    MAX_NAMED = 3,             /* bad rows named per shard (the rest counted) */
    MAX_RANGES = 8             /* missing shards named as ranges, then "..." */
};

typedef struct shard {
    const char *path;   /* as given; or SHARD.partial, read when SHARD is not there */
    char *partial;      /* SHARD.partial (owned) when that was read */
    manifest man;
    int run;            /* its run in merge.runs; -1 when not merged (foreign) */
    FILE *text;         /* an HDF5 shard's lines (cmd_h5_shard_text), made once */
    FILE *f;            /* pass 2 */
    line_digest d;      /* pass 2: its lines so far */
    long nrows;         /* pass 2: rows read */
} shard;

typedef struct run {
    int ref;            /* its first shard (the one others are compared with) */
    int nshards, m;     /* shards given, and M of its shards' K/M */
    long lo, hi;        /* its indices lo .. hi-1 */
    int accepted;
    int *by_k;          /* [m] pass 2: the shard of each K */
    mech_sweep *sweep;  /* a sweep's grid, its parameters recomputed per row */
    int has_grid;
} run;

typedef struct merge {
    shard *shards;
    int n;
    run *runs;
    int nruns;
    int batch;          /* summaries of mech batch, not CSVs of mech sweep */
    const char *study;  /* --study FILE */
    long total;         /* indices 0 .. total-1 */
    char *header;       /* the reference header (the first merged shard's) */
    const char *header_path;  /* that shard's file */
    int ncells;         /* its cells */
    char out_dir[4096]; /* a batch's --out-dir, "" when none */
    char *line;         /* the line being read, [cap] */
    size_t cap;
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

static int oom(void)
{
    fprintf(stderr, "mech merge: out of memory\n");
    return MECH_EXIT_IO;
}

/* "shard K/M (path)" */
static const char *name(const shard *s, char *buf, size_t size)
{
    snprintf(buf, size, "shard %d/%d (%s)", s->man.shard_k, s->man.shard_m, s->path);
    return buf;
}

/* ---- reading ------------------------------------------------------------ */

static const char *kind_of(mode_t mode)
{
    return S_ISFIFO(mode) ? "a FIFO" : S_ISDIR(mode) ? "a directory"
           : S_ISCHR(mode) ? "a character device" : S_ISSOCK(mode) ? "a socket"
           : S_ISBLK(mode) ? "a block device" : "not a regular file";
}

/* path opened for reading when it is a regular file: never blocks on a
 * FIFO (opened without waiting for a writer, then refused). NULL with
 * errno, or with *kind set when it is something else. */
static FILE *open_regular(const char *path, const char **kind)
{
    *kind = NULL;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    struct stat st;
    if (fd < 0)
        return NULL;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        *kind = kind_of(st.st_mode);
        close(fd);
        errno = EINVAL;
        return NULL;
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    FILE *f = fdopen(fd, "r");
    if (!f)
        close(fd);
    return f;
}

/* f, shard s's file, when it is HDF5: its lines as its CSV would hold them
 * (made once, then read again from the start: each open has its own FILE
 * on a dup of the descriptor; shards are read one at a time but in pass
 * 2, where each is opened once). NULL, with the problem named. */
static FILE *h5_lines(merge *g, shard *s, FILE *f)
{
    fclose(f);
    if (!s->text && !(s->text = cmd_h5_shard_text(s->path))) {
        complain(g, "%s: an HDF5 file that is not a shard mech wrote (see the message above)",
                 s->path);
        return NULL;
    }
    int fd = dup(fileno(s->text));
    FILE *t = fd >= 0 ? fdopen(fd, "r") : NULL;
    if (!t && fd >= 0)
        close(fd);
    if (t)
        rewind(t);
    else
        fprintf(stderr, "mech merge: cannot read %s again: %s\n", s->path, strerror(errno));
    return t;
}

/* The file of shard s: SHARD, or when it is not there but SHARD.partial
 * is (a run killed before its end), that one, so the shard is named as
 * unfinished rather than unreadable. NULL with the problem printed (an
 * error counted for a file that is not a regular one). */
static FILE *open_shard(merge *g, shard *s)
{
    const char *kind;
    FILE *f = open_regular(s->path, &kind);
    if (!f && !kind && errno == ENOENT && !s->partial) {
        size_t n = strlen(s->path) + 9;
        if ((s->partial = malloc(n))) {
            snprintf(s->partial, n, "%s.partial", s->path);
            if ((f = open_regular(s->partial, &kind)) || kind)
                s->path = s->partial;
            else
                errno = ENOENT;  /* the message is about SHARD, which is not there */
        }
    } else if (!f && !kind && errno == ENOENT && s->partial) {
        f = open_regular(s->partial, &kind);
    }
    if (!f && kind)
        complain(g, "%s is %s, not a shard's file (a regular file written by mech sweep or "
                 "mech batch); not read", s->path, kind);
    else if (!f)
        fprintf(stderr, "mech merge: cannot read %s: %s\n", s->path, strerror(errno));
    else if (output_file_is_h5(s->path))
        f = h5_lines(g, s, f);
    return f;
}

/* The next line of f into g->line, without its newline (nor a carriage
 * return before it: CRLF files are read as LF). Its length; -1 at the end
 * of the file, -2 for a last line without its newline (cut by a kill), -3
 * for a line longer than LINE_MAX_BYTES, -4 out of memory. */
static long read_line(merge *g, FILE *f)
{
    size_t n = 0;
    for (;;) {
        if (g->cap - n < 2) {
            if (g->cap >= LINE_MAX_BYTES)
                return -3;
            size_t cap = g->cap ? 2 * g->cap : 4096;
            char *b = realloc(g->line, cap);
            if (!b)
                return -4;
            g->line = b;
            g->cap = cap;
        }
        if (!fgets(g->line + n, (int)(g->cap - n), f))
            return n ? -2 : -1;
        n += strlen(g->line + n);
        if (n && g->line[n - 1] == '\n') {
            g->line[--n] = '\0';
            if (n && g->line[n - 1] == '\r')
                g->line[--n] = '\0';
            return (long)n;
        }
    }
}

/* Every shard's manifest (its first line). -1, or the exit status. */
static int read_manifests(merge *g)
{
    int code = -1;
    for (int i = 0; i < g->n; i++) {
        shard *s = &g->shards[i];
        int before = g->errors;
        FILE *f = open_shard(g, s);
        if (!f) {
            if (g->errors == before)  /* unreadable (not a FIFO, named as such) */
                code = MECH_EXIT_IO;
            continue;
        }
        long n = read_line(g, f);
        if (n == -4)
            code = oom();
        else if (n < 0 || manifest_parse(g->line, &s->man) != 0)
            complain(g, "%s: no '# mech-manifest' line at the top (not the output of mech "
                     "sweep or mech batch with --shard, or an unfinished one, or one written "
                     "by an older mech)", s->path);
        fclose(f);
    }
    return code;
}

/* ---- the runs: which shards are one run, which are foreign -------------- */

/* What differs between two manifests of one index range, as "its ..." */
static const char *difference(const manifest *m, const manifest *m0)
{
    return strcmp(m->command, m0->command) ? "command differs"
           : strcmp(m->version, m0->version) ? "mech version differs"
           : m->input != m0->input ? "input file (its contents) differs"
           : m->grid != m0->grid ? "grid differs"
           : m->total != m0->total ? "number of variants differs"
           : m->offset != m0->offset ? "--index-offset differs"
           : strcmp(m->tol, m0->tol) ? "tolerances differ"
           : strcmp(m->args, m0->args) ? "arguments differ" : NULL;
}

static void group_runs(merge *g)
{
    for (int i = 0; i < g->n; i++) {
        shard *s = &g->shards[i];
        int r = 0;
        while (r < g->nruns && !manifest_same_run(&g->shards[g->runs[r].ref].man, &s->man))
            r++;
        if (r == g->nruns) {
            run *u = &g->runs[g->nruns++];
            memset(u, 0, sizeof *u);
            u->ref = i;
            u->m = s->man.shard_m;
            u->lo = s->man.offset;
            u->hi = s->man.offset + s->man.total;
        }
        s->run = r;
        g->runs[r].nshards++;
    }
}

static void name_input_difference(merge *g, const shard *s, const shard *s0, char *out,
                                  size_t size);

/* The runs merged: the one with the most shards first, then each that
 * covers other indices and is of the same command and input; a run whose
 * indices overlap one merged is foreign: each of its shards is named
 * against it, and its missing shards are not (they are no part of this
 * merge). */
static void accept_runs(merge *g)
{
    int *order = malloc((size_t)g->nruns * sizeof *order + 1);
    if (!order) {
        complain(g, "out of memory");
        return;
    }
    for (int r = 0; r < g->nruns; r++)
        order[r] = r;
    for (int a = 1; a < g->nruns; a++)  /* most shards first, stable */
        for (int b = a; b > 0 && g->runs[order[b]].nshards > g->runs[order[b - 1]].nshards; b--) {
            int t = order[b];
            order[b] = order[b - 1];
            order[b - 1] = t;
        }
    char a[512], b[512], detail[512];
    for (int x = 0; x < g->nruns; x++) {
        run *u = &g->runs[order[x]];
        const shard *against = NULL;
        for (int y = 0; y < x && !against; y++) {
            const run *v = &g->runs[order[y]];
            const manifest *m = &g->shards[u->ref].man, *m0 = &g->shards[v->ref].man;
            if (v->accepted && ((u->lo < v->hi && v->lo < u->hi) ||
                                strcmp(m->command, m0->command) || m->input != m0->input ||
                                strcmp(m->version, m0->version)))
                against = &g->shards[v->ref];
        }
        u->accepted = !against;
        for (int i = 0; against && i < g->n; i++) {
            shard *s = &g->shards[i];
            if (s->run != order[x])
                continue;
            detail[0] = '\0';
            const char *what = difference(&s->man, &against->man);
            if (!strcmp(s->man.command, "batch") && !strcmp(against->man.command, "batch") &&
                s->man.input != against->man.input)
                name_input_difference(g, s, against, detail, sizeof detail);
            complain(g, "%s is not from the same run as %s: its %s%s", name(s, a, sizeof a),
                     name(against, b, sizeof b), what ? what : "index range overlaps", detail);
            s->run = -1;
        }
    }
    free(order);
}

/* "K" or "K1..K2" appended to buf */
static void put_range(char *buf, size_t size, long from, long to)
{
    size_t n = strlen(buf);
    if (from == to)
        snprintf(buf + n, size - n, "%s%ld", n ? ", " : "", from);
    else
        snprintf(buf + n, size - n, "%s%ld..%ld", n ? ", " : "", from, to);
}

typedef struct kpos {
    long k;
    int i;              /* the shard's place on the command line */
} kpos;

static int by_k(const void *a, const void *b)
{
    const kpos *x = a, *y = b;
    return x->k != y->k ? (x->k > y->k) - (x->k < y->k) : (x->i > y->i) - (x->i < y->i);
}

/* The K not in ks[0 .. nk) (sorted) of 0 .. m-1, as ranges on one line
 * (bounded, whatever M a manifest says). */
static void name_missing(merge *g, const run *u, const kpos *ks, long nk)
{
    char list[1024] = "";
    long missing = 0, ranges = 0, next = 0;
    for (long j = 0; j <= nk; j++) {
        long k = j < nk ? ks[j].k : u->m;
        if (k > next) {
            missing += k - next;
            if (ranges++ < MAX_RANGES)
                put_range(list, sizeof list, next, k - 1);
        }
        if (k + 1 > next)
            next = k + 1;
    }
    char where[96] = "";
    if (u->lo)
        snprintf(where, sizeof where, " of the run with --index-offset %ld", u->lo);
    if (missing == 1)
        complain(g, "shard %s/%d%s missing", list, u->m, where);
    else if (missing > 1)
        complain(g, "shards %s%s of %d%s missing (%ld of %d shards)", list,
                 ranges > MAX_RANGES ? ", ..." : "", u->m, where, missing, u->m);
}

/* Run r's shards: one M, every K of it once. */
static void check_shard_set(merge *g, int r)
{
    run *u = &g->runs[r];
    kpos *ks = malloc((size_t)u->nshards * sizeof *ks + 1);
    long nk = 0;
    char a[512], b[512];
    if (!ks) {
        complain(g, "out of memory");
        return;
    }
    for (int i = 0; i < g->n; i++) {
        const shard *s = &g->shards[i];
        if (s->run != r)
            continue;
        if (s->man.shard_m != u->m)
            complain(g, "%s splits the run in %d shards, %s in %d", name(&g->shards[u->ref], a, sizeof a),
                     u->m, name(s, b, sizeof b), s->man.shard_m);
        else
            ks[nk++] = (kpos){s->man.shard_k, i};
    }
    qsort(ks, (size_t)nk, sizeof *ks, by_k);
    for (long j = 1; j < nk; j++)
        if (ks[j].k == ks[j - 1].k)
            complain(g, "shard %ld/%d given twice (%s)", ks[j].k, u->m, g->shards[ks[j].i].path);
    name_missing(g, u, ks, nk);
    free(ks);
}

/* ---- the study: the ranges of the whole index space --------------------- */

/* --study FILE: lines "OFFSET COUNT" (blank lines and '#' comments
 * skipped), in order, each starting where the one before ends. The merged
 * runs must be exactly these ranges: a range without a run is named.
 * -1, or the exit status. */
static int check_study(merge *g)
{
    const char *kind;
    FILE *f = open_regular(g->study, &kind);
    if (!f) {
        if (kind)
            return complain(g, "--study %s is %s, not a file", g->study, kind), MECH_EXIT_INPUT;
        fprintf(stderr, "mech merge: cannot read %s: %s\n", g->study, strerror(errno));
        return MECH_EXIT_IO;
    }
    long n, lineno = 0, end = 0;
    while ((n = read_line(g, f)) >= 0 || n == -2) {
        long off, count;
        char extra;
        lineno++;
        if (g->line[strspn(g->line, " \t")] == '\0' || g->line[strspn(g->line, " \t")] == '#')
            continue;
        if (sscanf(g->line, "%ld %ld %c", &off, &count, &extra) != 2 || off < 0 || count < 1 ||
            count > MANIFEST_MAX_TOTAL) {
            complain(g, "%s:%ld: expected OFFSET COUNT (whole numbers, COUNT >= 1), not '%.60s'",
                     g->study, lineno, g->line);
            continue;
        }
        if (off != end)
            complain(g, "%s:%ld: the range starts at %ld, where the one before ends at %ld "
                     "(the ranges follow one another from 0)", g->study, lineno, off, end);
        end = off + count;
        int found = 0;
        for (int r = 0; r < g->nruns; r++) {
            const run *u = &g->runs[r];
            if (!u->accepted || u->hi <= off || u->lo >= end)
                continue;
            found = 1;
            if (u->lo != off || u->hi != end)
                complain(g, "%s:%ld: the range %ld..%ld, but the run with --index-offset %ld "
                         "(%s) has the indices %ld..%ld", g->study, lineno, off, end - 1, u->lo,
                         g->shards[u->ref].path, u->lo, u->hi - 1);
        }
        if (!found)
            complain(g, "%s:%ld: range %ld..%ld (--index-offset %ld, %ld variants) missing: no "
                     "shard of it given", g->study, lineno, off, end - 1, off, count);
        if (n == -2)
            break;
    }
    fclose(f);
    if (end == 0)
        complain(g, "%s: no range (lines 'OFFSET COUNT')", g->study);
    for (int r = 0; r < g->nruns; r++)
        if (g->runs[r].accepted && g->runs[r].hi > end)
            complain(g, "the run with --index-offset %ld (%s) has indices beyond the study's "
                     "%ld", g->runs[r].lo, g->shards[g->runs[r].ref].path, end);
    g->total = end;
    return -1;
}

static void gap(merge *g, long from, long to)
{
    if (from == to)
        complain(g, "index %ld is in no shard", from);
    else
        complain(g, "indices %ld..%ld are in no shard", from, to);
}

/* Every index 0 .. total-1 in one merged run (they do not overlap); the
 * gaps as ranges. */
static void check_coverage(merge *g)
{
    long next = 0, end = 0;
    for (int r = 0; r < g->nruns; r++)
        if (g->runs[r].accepted && g->runs[r].hi > end)
            end = g->runs[r].hi;
    if (!g->study)
        g->total = end;
    for (;;) {  /* the runs in the order of their indices */
        const run *first = NULL;
        for (int r = 0; r < g->nruns; r++)
            if (g->runs[r].accepted && g->runs[r].lo >= next && (!first || g->runs[r].lo < first->lo))
                first = &g->runs[r];
        if (!first)
            break;
        if (first->lo > next)
            gap(g, next, first->lo - 1);
        next = first->hi;
    }
    if (g->total > next)
        gap(g, next, g->total - 1);
}

/* ---- pass 1: each shard's rows ------------------------------------------ */

typedef struct shard_check {
    merge *g;
    const shard *s;
    const run *u;
    long bad;           /* rows found wrong */
} shard_check;

static void bad_row(shard_check *c, long r, long line, const char *why)
{
    char a[512];
    if (c->bad++ < MAX_NAMED)
        complain(c->g, "%s: row %ld (line %ld): %s", name(c->s, a, sizeof a), r + 1, line, why);
    else
        c->g->errors++;
}

/* A batch row's CSV in the run's --out-dir: there, with steps + 1 lines,
 * and the bytes whose hash the summary holds. */
static void check_csv(shard_check *c, const batch_row *br)
{
    merge *g = c->g;
    if (!g->out_dir[0] || (strcmp(br->status, "ok") != 0 && strcmp(br->status, "kept") != 0))
        return;
    char path[8192];
    snprintf(path, sizeof path, "%s/%.*s.csv", g->out_dir, br->name_len, br->name);
    FILE *f = fopen(path, "rb");
    if (!f) {
        complain(g, "index %ld (%.*s) is %s in its summary, but %s cannot be read: %s", br->index,
                 br->name_len, br->name, br->status, path, strerror(errno));
        return;
    }
    char buf[65536];
    long lines = 0;
    uint64_t h = MANIFEST_HASH0;
    for (size_t n; (n = fread(buf, 1, sizeof buf, f)) > 0;) {
        h = manifest_hash(h, buf, n);
        for (const char *p = buf; (p = memchr(p, '\n', n - (size_t)(p - buf))); p++)
            lines++;
    }
    fclose(f);
    if (lines != br->steps + 1)
        complain(g, "index %ld (%.*s): %s has %ld rows, its summary says %ld", br->index,
                 br->name_len, br->name, path, lines - 1, br->steps);
    else if (br->has_csv && h != br->csv)
        complain(g, "index %ld (%.*s): %s is not the CSV its shard wrote (its bytes differ "
                 "from the hash in the summary: edited or replaced?)", br->index, br->name_len,
                 br->name, path);
}

/* Row r (the line in g->line, len bytes) of shard c->s, whose index must
 * be `want`. */
static void check_row(shard_check *c, long r, long line, long len, long want)
{
    char why[256];
    const char *row = c->g->line;
    long idx;
    batch_row br;
    int bad;
    if (c->g->batch) {
        bad = batch_row_parse(row, (size_t)len, 1, &br, why, sizeof why) != 0;
        idx = br.index;
    } else {
        bad = csv_row_shape(row, (size_t)len, c->g->ncells, why, sizeof why) != 0;
        idx = csv_row_index(row, (size_t)len);
    }
    if (!bad && idx != want)
        bad = snprintf(why, sizeof why, "index %ld where this shard's row %ld has %ld (a row "
                       "of another shard, out of order or repeated)", idx, r + 1, want) > 0;
    if (!bad && !c->g->batch && c->u->has_grid)
        bad = sweep_row_content(c->u->sweep, row, (size_t)len, why, sizeof why) != 0;
    if (bad)
        bad_row(c, r, line, why);
    else if (c->g->batch)
        check_csv(c, &br);
}

/* The rows of a file left by a killed run (SHARD.partial): counted, for
 * the message. */
static long count_partial_rows(merge *g, FILE *f)
{
    long n, rows = 0;
    while ((n = read_line(g, f)) >= 0 || n == -3)
        rows += n >= 0 && g->line[0] != '#';
    return rows;
}

/* Shard s read through: header, rows, digest line. */
static void check_shard(merge *g, shard *s)
{
    char a[512];
    const run *u = &g->runs[s->run];
    long want = manifest_shard_rows(s->man.total, s->man.shard_k, s->man.shard_m);
    FILE *f = open_shard(g, s);
    if (!f) {
        complain(g, "%s: cannot be read again", name(s, a, sizeof a));
        return;
    }
    line_digest d;
    digest_init(&d);
    long n = read_line(g, f), line = 1, rows = 0;
    digest_line(&d, g->line, n > 0 ? (size_t)n : 0);
    if ((n = read_line(g, f)) < 0 || strcmp(g->line, g->header) != 0)
        complain(g, "%s: its header differs from that of %s", name(s, a, sizeof a),
                 g->header_path);
    digest_line(&d, g->line, n > 0 ? (size_t)n : 0);
    line++;
    if (s->partial) {
        complain(g, "shard %d/%d unfinished: %ld of %ld rows (%s)", s->man.shard_k,
                 s->man.shard_m, count_partial_rows(g, f), want, s->path);
        fclose(f);
        return;
    }
    shard_check c = {g, s, u, 0};
    int trailer = 0, cut = 0;
    long trailer_rows = -1;
    uint64_t trailer_h = 0;
    while ((n = read_line(g, f)) != -1) {
        line++;
        if (n < 0) {
            cut = n == -2;
            if (n != -2)
                complain(g, "%s: line %ld %s", name(s, a, sizeof a), line,
                         n == -3 ? "is longer than 1 MiB" : "cannot be read (out of memory)");
            break;
        }
        if (trailer) {
            complain(g, "%s: line %ld after its digest line", name(s, a, sizeof a), line);
            break;
        }
        if (digest_parse(g->line, DIGEST_TRAILER, &trailer_rows, &trailer_h) == 0) {
            trailer = 1;
            continue;
        }
        digest_line(&d, g->line, (size_t)n);
        if (g->batch && strncmp(g->line, "# mech-inputs ", 14) == 0)
            continue;  /* the input files' hashes (in the digest) */
        if (rows < want)
            check_row(&c, rows, line, n, s->man.offset + s->man.shard_k + rows * s->man.shard_m);
        rows++;
    }
    fclose(f);
    if (!trailer && rows < want)  /* cut by a kill, or short */
        complain(g, "shard %d/%d unfinished: %ld of %ld rows (%s)%s", s->man.shard_k,
                 s->man.shard_m, rows, want, s->path, cut ? ", its last line cut" : "");
    else if (rows != want || s->man.rows != want)
        complain(g, "%s: %ld rows, its manifest says %ld (edited)", name(s, a, sizeof a), rows,
                 want);
    else if (!trailer)
        complain(g, "%s: no '# mech-digest' line at its end (cut off, or written by an older "
                 "mech)", name(s, a, sizeof a));
    else if (trailer_rows != rows || trailer_h != d.h)
        complain(g, "%s: its rows do not match its digest line (a row, the manifest or the "
                 "header was edited after mech wrote it)", name(s, a, sizeof a));
}

/* The reference header (of the first merged run's first shard), its cells;
 * a batch's --out-dir; each sweep run's grid. -1, or the exit status. */
static int prepare_checks(merge *g)
{
    const run *u0 = NULL;
    for (int r = 0; r < g->nruns && !u0; r++)
        if (g->runs[r].accepted)
            u0 = &g->runs[r];
    if (!u0)
        return -1;
    const shard *s0 = &g->shards[u0->ref];
    FILE *f = open_shard(g, &g->shards[u0->ref]);
    long n = f ? read_line(g, f) : -1;
    if (n >= 0)
        n = read_line(g, f);
    if (f)
        fclose(f);
    if (n < 0) {
        complain(g, "%s: no header line", s0->path);
        return -1;
    }
    if (!(g->header = strdup(g->line)))
        return oom();
    g->header_path = s0->path;
    g->ncells = csv_cells(g->header, strlen(g->header));
    if (g->batch) {
        if (batch_out_dir_of_manifest(&s0->man, g->out_dir, sizeof g->out_dir) != 0)
            complain(g, "%s: its manifest's arguments are not those of a mech batch (edited?)",
                     s0->path);
        return -1;
    }
    for (int r = 0; r < g->nruns; r++) {
        run *u = &g->runs[r];
        if (!u->accepted)
            continue;
        u->has_grid = sweep_of_manifest(&g->shards[u->ref].man, &u->sweep) == 0;
        if (!u->has_grid)
            complain(g, "%s: its manifest's arguments do not give a grid that hashes to its "
                     "grid= (edited?)", g->shards[u->ref].path);
        else if (mech_sweep_nparams(u->sweep) + 3 > g->ncells)
            complain(g, "%s: its header has %d columns, fewer than its %d parameters need",
                     g->shards[u->ref].path, g->ncells, mech_sweep_nparams(u->sweep));
    }
    return -1;
}

/* ---- a batch's input files: which one differs ------------------------- */

/* The "# mech-inputs files=N per=P H,H,..." line of shard s into *hashes
 * (malloc'ed, *nb of them); 0, or -1 when it has none. */
static int read_inputs(merge *g, shard *s, long *files, long *per, uint64_t **hashes, long *nb)
{
    FILE *f = open_shard(g, s);
    long n;
    int used = 0;
    *hashes = NULL;
    while (f && (n = read_line(g, f)) != -1)
        if (n >= 0 && sscanf(g->line, "# mech-inputs files=%ld per=%ld %n", files, per, &used) == 2 &&
            used > 0 && *per > 0) {
            const char *p = g->line + used;
            *nb = 0;
            *hashes = malloc((strlen(p) / 16 + 1) * sizeof **hashes);
            for (char *end; *hashes && *p; p = *end == ',' ? end + 1 : end) {
                (*hashes)[(*nb)++] = strtoull(p, &end, 16);
                if (end == p)
                    break;
            }
            break;
        }
    if (f)
        fclose(f);
    return *hashes ? 0 : -1;
}

/* The name of the file of index idx, from the row that holds it in any
 * shard given (buf "" when none does). */
static void file_name_of(merge *g, long idx, char *buf, size_t size)
{
    buf[0] = '\0';
    for (int i = 0; i < g->n && !buf[0]; i++) {
        shard *s = &g->shards[i];
        if (idx % s->man.shard_m != s->man.shard_k)
            continue;
        FILE *f = open_shard(g, s);
        batch_row br;
        char why[128];
        long n;
        while (f && (n = read_line(g, f)) != -1 && !buf[0])
            if (n >= 0 && batch_row_parse(g->line, (size_t)n, 1, &br, why, sizeof why) == 0 &&
                br.index == idx)
                snprintf(buf, size, "%.*s", br.name_len, br.name);
        if (f)
            fclose(f);
    }
}

/* ": FILE (index I)": the first input file whose hash differs between the
 * two shards' inputs lines (out "" when they cannot tell). */
static void name_input_difference(merge *g, const shard *s, const shard *s0, char *out,
                                  size_t size)
{
    long fa, pa, na, fb, pb, nb;
    uint64_t *ha, *hb;
    out[0] = '\0';
    if (read_inputs(g, (shard *)s, &fa, &pa, &ha, &na) != 0)
        return;
    if (read_inputs(g, (shard *)s0, &fb, &pb, &hb, &nb) == 0 && fa == fb && pa == pb && na == nb)
        for (long b = 0; b < na; b++) {
            if (ha[b] == hb[b])
                continue;
            char file[256];
            long lo = b * pa, hi = lo + pa - 1 < fa - 1 ? lo + pa - 1 : fa - 1;
            file_name_of(g, lo, file, sizeof file);
            if (lo == hi)
                snprintf(out, size, ": %s (index %ld)", file[0] ? file : "the file", lo);
            else
                snprintf(out, size, ": one of the files of index %ld..%ld (%s, ...)", lo, hi,
                         file[0] ? file : "?");
            break;
        }
    free(ha);
    free(hb);
}

/* ---- pass 2: the rows in index order ------------------------------------ */

/* RLIMIT_NOFILE raised to its hard limit: a merge holds every shard open. */
static void raise_open_files(void)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_NOFILE, &rl) == 0 && rl.rlim_cur < rl.rlim_max) {
        rl.rlim_cur = rl.rlim_max;
        setrlimit(RLIMIT_NOFILE, &rl);
    }
}

/* Every merged shard open, past its manifest and header (digested), and
 * each run's shard of each K. -1, or the exit status. */
static int open_all(merge *g)
{
    raise_open_files();
    for (int r = 0; r < g->nruns; r++)
        if (g->runs[r].accepted && !(g->runs[r].by_k = calloc((size_t)g->runs[r].m, sizeof(int))))
            return oom();
    for (int i = 0; i < g->n; i++) {
        shard *s = &g->shards[i];
        if (s->run < 0)
            continue;
        if (!(s->f = open_shard(g, s))) {
            struct rlimit rl;
            if ((errno == EMFILE || errno == ENFILE) && getrlimit(RLIMIT_NOFILE, &rl) == 0)
                fprintf(stderr, "mech merge: cannot hold %d shards open at once (at most %llu "
                        "open files: raise the hard limit, ulimit -Hn)\n", g->n,
                        (unsigned long long)rl.rlim_cur);
            return MECH_EXIT_IO;
        }
        digest_init(&s->d);
        for (int k = 0; k < 2; k++) {
            long n = read_line(g, s->f);
            digest_line(&s->d, g->line, n > 0 ? (size_t)n : 0);
        }
        g->runs[s->run].by_k[s->man.shard_k] = i;
    }
    return -1;
}

/* A line without a batch table's index and CSV hash (as mech batch alone
 * writes it). */
static void put_unindexed(const merge *g, const char *line, size_t len, int header, FILE *f)
{
    for (int cut = 0; g->batch && cut < 2; cut++) {
        while (len > 0 && line[len - 1] != ' ')
            len--;
        while (len > 0 && line[len - 1] == ' ')
            len--;
    }
    if (g->batch && header) {  /* the header's "golden" keeps its padding */
        const char *gold = strstr(line, "golden");
        if (gold && (size_t)(gold - line) + 7 <= len + 2)
            len = (size_t)(gold - line) + 7;
    }
    fwrite(line, 1, len, f);
    fputc('\n', f);
}

/* The next row of shard s, which must have index idx; 0, or -1 (the shard
 * changed since pass 1). */
static int next_row(merge *g, shard *s, long idx, long *len)
{
    long n;
    while ((n = read_line(g, s->f)) >= 0 && g->batch && strncmp(g->line, "# mech-inputs ", 14) == 0)
        digest_line(&s->d, g->line, (size_t)n);
    if (n < 0)
        return -1;
    digest_line(&s->d, g->line, (size_t)n);
    s->nrows++;
    *len = n;
    long got = csv_row_index(g->line, (size_t)n);
    if (g->batch) {
        batch_row br;
        char why[64];
        got = batch_row_parse(g->line, (size_t)n, 1, &br, why, sizeof why) == 0 ? br.index : -1;
    }
    return got == idx ? 0 : -1;
}

/* Each shard's remaining lines: its digest line, which must match again. */
static int digests_again(merge *g)
{
    for (int i = 0; i < g->n; i++) {
        shard *s = &g->shards[i];
        long n, rows = -1;
        uint64_t h = 0;
        if (!s->f)
            continue;
        while ((n = read_line(g, s->f)) >= 0 && digest_parse(g->line, DIGEST_TRAILER, &rows, &h) != 0)
            digest_line(&s->d, g->line, (size_t)n);
        if (n < 0 || rows != s->nrows || h != s->d.h)
            return -1;
    }
    return 0;
}

static int emit_merged(FILE *f, const void *ctx)
{
    merge *g = (merge *)ctx;
    char a[512];
    put_unindexed(g, g->header, strlen(g->header), 1, f);
    int r = -1;
    for (long i = 0; i < g->total; i++) {
        if (r < 0 || i >= g->runs[r].hi)
            for (r = 0; !(g->runs[r].accepted && g->runs[r].lo <= i && i < g->runs[r].hi); r++)
                ;
        const run *u = &g->runs[r];
        shard *s = &g->shards[u->by_k[(i - u->lo) % u->m]];
        long len;
        if (next_row(g, s, i, &len) != 0) {
            fprintf(stderr, "mech merge: %s changed while it was merged (index %ld); nothing "
                    "written\n", name(s, a, sizeof a), i);
            return -1;
        }
        put_unindexed(g, g->line, (size_t)len, 0, f);
    }
    if (digests_again(g) != 0) {
        fprintf(stderr, "mech merge: a shard changed while it was merged (its digest no "
                "longer matches); nothing written\n");
        return -1;
    }
    return ferror(f) ? -1 : 0;
}

/* ---- the whole merge ------------------------------------------------------ */

static int problems(const merge *g)
{
    fprintf(stderr, "mech merge: %d problem%s; nothing written\n", g->errors,
            g->errors == 1 ? "" : "s");
    return MECH_EXIT_INPUT;
}

/* OUT.h5: the merged CSV text as HDF5 (cmd_h5.c), with the first merged
 * run's version, command and input digest; no manifest, as the CSV. */
static int write_h5(merge *g, const char *out)
{
    if (g->batch) {
        fprintf(stderr, "mech merge: %s: the summary tables of mech batch --shard merge into "
                "text only (their rows are checked as text); write -o TABLE without .h5, "
                "nothing written\n", out);
        return MECH_EXIT_INPUT;
    }
    const run *u = g->runs;
    while (!u->accepted)
        u++;
    char *mline = NULL;
    size_t size = 0;
    FILE *m = open_memstream(&mline, &size);
    if (!m)
        return oom();
    manifest_write(&g->shards[u->ref].man, m);
    if (fclose(m) != 0)
        return free(mline), oom();
    if (size && mline[size - 1] == '\n')
        mline[size - 1] = '\0';
    h5_head h = {"merge", mline, g->header, NULL, 0};
    int code = cmd_h5_write_text(&h, out, emit_merged, g);
    free(mline);
    return code;
}

static int merge_shards(merge *g, const char *out)
{
    int code = read_manifests(g);
    if (code >= 0 || g->errors)
        return code >= 0 ? code : problems(g);
    if (!(g->runs = calloc((size_t)g->n, sizeof *g->runs)))
        return oom();
    group_runs(g);
    accept_runs(g);
    for (int r = 0; r < g->nruns; r++)  /* the merged runs' command (one, or foreign) */
        if (g->runs[r].accepted)
            g->batch = strcmp(g->shards[g->runs[r].ref].man.command, "batch") == 0;
    for (int r = 0; r < g->nruns; r++)
        if (g->runs[r].accepted)
            check_shard_set(g, r);
    if (g->study && (code = check_study(g)) >= 0)
        return code;
    if (!g->study)  /* (the study names its missing ranges) */
        check_coverage(g);
    if (g->errors)
        return problems(g);
    if ((code = prepare_checks(g)) >= 0)
        return code;
    for (int i = 0; i < g->n && !g->errors; i++)
        if (g->shards[i].run >= 0)
            check_shard(g, &g->shards[i]);
    if (g->errors)
        return problems(g);
    if ((code = open_all(g)) >= 0)
        return code;
    if (output_is_h5_name(out))
        return write_h5(g, out);
    mech_diag d;
    mech_diag_init(&d);
    int rc = write_file_whole(out, emit_merged, g, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return rc == MECH_OK ? MECH_EXIT_OK : MECH_EXIT_IO;
}

int cmd_merge(int argc, char **argv)
{
    merge_args a = {NULL, NULL, {NULL, 0}};
    merge g;
    memset(&g, 0, sizeof g);
    int code = cmd_opts_parse(&cmd_merge_spec, argc, argv, &a);
    if (code < 0 && !(g.shards = calloc((size_t)argc + 1, sizeof *g.shards)))
        code = (fprintf(stderr, "mech merge: out of memory\n"), MECH_EXIT_IO);
    for (int i = 0; code < 0 && i < a.shards.n; i++)
        g.shards[g.n++].path = a.shards.v[i];
    free(a.shards.v);
    const char *out = a.out;
    g.study = a.study;
    if (code < 0 && !out)
        code = cmd_usage_error("merge", "%s", "-o OUT is required (the merged file; - for standard output)");
    if (code < 0 && g.n == 0)
        code = cmd_usage_error("merge", "%s", "no shard files given");
    for (int i = 0; code < 0 && i < g.n; i++)
        code = cmd_refuse_input("merge", out, &g.shards[i].path, 1);
    if (code < 0 && g.study)
        code = cmd_refuse_input("merge", out, &g.study, 1);
    if (code < 0)
        code = merge_shards(&g, out);
    for (int i = 0; i < g.n; i++) {
        if (g.shards[i].f)
            fclose(g.shards[i].f);
        if (g.shards[i].text)
            fclose(g.shards[i].text);
        free(g.shards[i].partial);
    }
    for (int r = 0; r < g.nruns; r++) {
        free(g.runs[r].by_k);
        mech_sweep_free(&g.runs[r].sweep);
    }
    free(g.shards);
    free(g.runs);
    free(g.header);
    free(g.line);
    return code;
}
