/* src/cli/cmd_rows.c: a sweep's rows as they finish, kept in OUT.partial in
 * blocks with check lines (a killed run loses at most the rows of the last
 * second), continued by --resume after checking every row, and at the end
 * written whole to OUT in index order (src/cli/cli.h). */
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "base.h"
#include "output.h"

/* A block is written when this many bytes wait, or this long after the
 * last write: at 3 200 processes each writes a few times a second, not once
 * per row (docs/batch.md, "Nothing computed is lost"). */
enum { BLOCK_BYTES = 65536, CHECK_LINE = 64 };
static const double FLUSH_SECONDS = 1.0;

static int oom(const rowfile *rf)
{
    fprintf(stderr, "mech %s: out of memory\n", rf->command);
    return MECH_EXIT_IO;
}

static int io_error(const rowfile *rf, const char *what, const char *path)
{
    fprintf(stderr, "mech %s: cannot %s %s: %s\n", rf->command, what, path, strerror(errno));
    return MECH_EXIT_IO;
}

static const char *file_name(const rowfile *rf)
{
    return rf->path ? rf->path : "the temporary file";
}

/* The whole of fd into a NUL-terminated buffer (*len bytes). */
static char *read_all(int fd, size_t *len)
{
    size_t cap = 65536, n = 0;
    char *buf = malloc(cap + 1);
    for (ssize_t got; buf; n += (size_t)got) {
        if (n == cap) {
            char *b = realloc(buf, 2 * cap + 1);
            if (!b)
                free(buf);
            buf = b;
            cap *= 2;
            if (!buf)
                break;
        }
        got = pread(fd, buf + n, cap - n, (off_t)n);
        if (got < 0 && errno == EINTR)
            got = 0;
        else if (got <= 0) {
            if (got < 0) {
                free(buf);
                buf = NULL;
            }
            break;
        }
    }
    if (buf)
        buf[n] = '\0';
    *len = n;
    return buf;
}

/* n bytes at offset at: 0, or an errno. */
static int write_all(int fd, const char *p, size_t n, off_t at)
{
    while (n > 0) {
        ssize_t w = pwrite(fd, p, n, at);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return w < 0 ? errno : EIO;
        p += w;
        n -= (size_t)w;
        at += w;
    }
    return 0;
}

int rows_block_line(char *buf, size_t size, long rows, const line_digest *d)
{
    return digest_format(buf, size, DIGEST_BLOCK, rows, d->h);
}

/* A line of buf from p to its newline (a CR before it left out): its
 * length, and *next the start of the following line; -1 when cut. */
static long line_at(const char *buf, size_t len, size_t p, size_t *next)
{
    const char *nl = memchr(buf + p, '\n', len - p);
    if (!nl)
        return -1;
    size_t n = (size_t)(nl - (buf + p));
    *next = (size_t)(nl + 1 - buf);
    return (long)(n > 0 && buf[p + n - 1] == '\r' ? n - 1 : n);
}

static int is_block_line(const char *s, size_t n, long nrows, const line_digest *d)
{
    char text[128];
    long rows;
    uint64_t h;
    size_t np = strlen(DIGEST_BLOCK);
    if (n < np || n >= sizeof text || memcmp(s, DIGEST_BLOCK, np) != 0)
        return n >= np && memcmp(s, DIGEST_BLOCK, np) == 0 ? 0 : -1;
    memcpy(text, s, n);
    text[n] = '\0';
    return digest_parse(text, DIGEST_BLOCK, &rows, &h) == 0 && rows == nrows && h == d->h;
}

long rows_scan_blocks(const char *buf, size_t len, size_t from, long first_line,
                      const line_digest *seed,
                      void (*row)(void *ctx, const char *r, size_t n, long line),
                      void (*bad)(void *ctx, long from_line, long to_line, long rows), void *ctx)
{
    line_digest d = *seed;
    size_t start = from, p = from, next;
    long start_line = first_line, line = first_line, nrows = 0, n;
    for (; p < len && (n = line_at(buf, len, p, &next)) >= 0; p = next, line++) {
        int check = is_block_line(buf + p, (size_t)n, nrows, &d);
        if (check < 0) {  /* a row of the block */
            digest_line(&d, buf + p, (size_t)n);
            nrows++;
            continue;
        }
        if (check == 0) {
            bad(ctx, start_line, line, nrows);
        } else {
            size_t q = start, qn;
            for (long l = start_line; l < line; l++, q = qn)
                row(ctx, buf + q, (size_t)line_at(buf, len, q, &qn), l);
        }
        d = *seed;
        nrows = 0;
        start = next;
        start_line = line + 1;
    }
    return nrows;
}

/* The position i of the row whose index is idx, or -1 when it is not a row
 * of this shard. */
static long row_slot(const rowfile *rf, long idx)
{
    if (idx < rf->first || (idx - rf->first) % rf->step != 0)
        return -1;
    long i = (idx - rf->first) / rf->step;
    return i < rf->count ? i : -1;
}

static void mark(rowfile *rf, long i)
{
    rf->done[i / 8] |= (unsigned char)(1u << (i % 8));
    rf->ndone++;
}

int rows_done(const rowfile *rf, long i)
{
    return rf->done[i / 8] >> (i % 8) & 1;
}

/* ---- writing, in blocks ------------------------------------------------ */

/* The block and its check line out with one write (the lock held). After
 * a failed write nothing more is written: rows_finish reports it. */
static void write_block(rowfile *rf)
{
    if (rf->brows == 0)
        return;
    if (!rf->write_errno) {
        size_t n = rf->blen + (size_t)rows_block_line(rf->block + rf->blen, CHECK_LINE, rf->brows, &rf->bd);
        rf->write_errno = write_all(rf->fd, rf->block, n, rf->end);
        if (!rf->write_errno) {
            rf->end += (off_t)n;
            rf->saved += rf->brows;
        }
    }
    rf->blen = 0;
    rf->brows = 0;
    rf->bd = rf->head_digest;
    rf->last_write = clock_seconds();
}

/* The timer: a block waiting for more than FLUSH_SECONDS is written, so a
 * slow sweep's rows reach the disk as surely as a fast one's. */
static void *flush_timer(void *arg)
{
    rowfile *rf = arg;
    pthread_mutex_lock(&rf->lock);
    while (!rf->stop) {
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        ts.tv_nsec += 250000000L;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&rf->wake, &rf->lock, &ts);
        if (rf->brows > 0 && clock_seconds() - rf->last_write >= FLUSH_SECONDS)
            write_block(rf);
    }
    pthread_mutex_unlock(&rf->lock);
    return NULL;
}

static void start_timer(rowfile *rf)
{
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&rf->wake, &ca);
    pthread_condattr_destroy(&ca);
    rf->last_write = clock_seconds();
    rf->timer_on = pthread_create(&rf->timer, NULL, flush_timer, rf) == 0;
    if (!rf->timer_on)
        pthread_cond_destroy(&rf->wake);
}

static void stop_timer(rowfile *rf)
{
    if (!rf->timer_on)
        return;
    pthread_mutex_lock(&rf->lock);
    rf->stop = 1;
    pthread_cond_signal(&rf->wake);
    pthread_mutex_unlock(&rf->lock);
    pthread_join(rf->timer, NULL);
    pthread_cond_destroy(&rf->wake);
    rf->timer_on = 0;
}

void rows_put(rowfile *rf, long i, const char *line, const char *messages)
{
    size_t n = strlen(line);
    pthread_mutex_lock(&rf->lock);
    if (rf->blen + n + CHECK_LINE > rf->bcap)
        write_block(rf);
    if (rf->blen + n + CHECK_LINE > rf->bcap) {  /* a row longer than a block */
        char *b = realloc(rf->block, rf->blen + n + CHECK_LINE);
        if (b) {
            rf->block = b;
            rf->bcap = rf->blen + n + CHECK_LINE;
        } else if (!rf->write_errno) {
            rf->write_errno = ENOMEM;
        }
    }
    if (rf->blen + n + CHECK_LINE <= rf->bcap) {
        memcpy(rf->block + rf->blen, line, n);
        digest_line(&rf->bd, line, n && line[n - 1] == '\n' ? n - 1 : n);
        rf->blen += n;
        rf->brows++;
    }
    mark(rf, i);
    if (rf->blen >= BLOCK_BYTES)
        write_block(rf);
    if (messages && *messages)
        fputs(messages, stderr);
    pthread_mutex_unlock(&rf->lock);
}

/* ---- --resume: the rows of OUT.partial that check ----------------------- */

/* The file's first two lines are the head (ends CRLF or LF): the offset
 * after them, else 0. */
static size_t head_matches(const rowfile *rf, const char *buf, size_t len)
{
    size_t p = 0, hp = 0, next, hnext;
    for (int k = 0; k < 2; k++, p = next, hp = hnext) {
        long n = line_at(buf, len, p, &next), hn = line_at(rf->head, rf->head_len, hp, &hnext);
        if (n < 0 || n != hn || memcmp(buf + p, rf->head + hp, (size_t)n) != 0)
            return 0;
    }
    return p;
}

typedef struct resumed {
    rowfile *rf;
    char *out;             /* the head and the rows kept, rewritten over the file */
    size_t olen;
    line_digest d;
    long kept, dropped;
    int told;              /* problems named (the first few) */
} resumed;

static void told(resumed *c, long from, long to, long rows, const char *why)
{
    if (c->told++ >= 5)
        return;
    if (from == to)
        fprintf(stderr, "mech %s: %s:%ld: row dropped (solved again): %s\n", c->rf->command,
                c->rf->path, from, why);
    else
        fprintf(stderr, "mech %s: %s:%ld-%ld: %ld row%s dropped (solved again): %s\n",
                c->rf->command, c->rf->path, from, to, rows, rows == 1 ? "" : "s", why);
}

static void resume_row(void *ctx, const char *r, size_t n, long line)
{
    resumed *c = ctx;
    rowfile *rf = c->rf;
    char why[256];
    long i = row_slot(rf, csv_row_index(r, n));
    int bad = csv_row_shape(r, n, rf->ncells, why, sizeof why) != 0;
    if (!bad && i < 0)
        bad = snprintf(why, sizeof why, "not a row of this shard") > 0;
    else if (!bad && rows_done(rf, i))
        bad = snprintf(why, sizeof why, "a variant given twice") > 0;
    else if (!bad && rf->check)
        bad = rf->check(rf->check_ctx, r, n, why, sizeof why) != 0;
    if (bad) {
        c->dropped++;
        told(c, line, line, 1, why);
        return;
    }
    mark(rf, i);
    memcpy(c->out + c->olen, r, n);
    c->out[c->olen + n] = '\n';
    c->olen += n + 1;
    digest_line(&c->d, r, n);
    c->kept++;
}

static void resume_bad(void *ctx, long from, long to, long rows)
{
    resumed *c = ctx;
    c->dropped += rows;
    told(c, from, to, rows, "their block's check line does not match them (edited?)");
}

/* The rows of the partial file that check kept (marked done) and written
 * back as one block; the rest dropped and named. -1, or the exit status
 * when it is not this run's. */
static int resume_rows(rowfile *rf)
{
    size_t len;
    char *buf = read_all(rf->fd, &len);
    if (!buf)
        return io_error(rf, "read", rf->path);
    size_t body = head_matches(rf, buf, len);
    if (!body) {
        fprintf(stderr, "mech %s: %s is not a part of this run (its manifest or header "
                "differs: other arguments, input file or version); remove it or write "
                "another -o\n", rf->command, rf->path);
        free(buf);
        return MECH_EXIT_INPUT;
    }
    resumed c = {rf, malloc(rf->head_len + len + CHECK_LINE), 0, rf->head_digest, 0, 0, 0};
    if (!c.out)
        return free(buf), oom(rf);
    memcpy(c.out, rf->head, rf->head_len);
    c.olen = rf->head_len;
    rows_scan_blocks(buf, len, body, 3, &rf->head_digest, resume_row, resume_bad, &c);
    free(buf);
    if (c.kept > 0)
        c.olen += (size_t)rows_block_line(c.out + c.olen, CHECK_LINE, c.kept, &c.d);
    if (c.dropped > 0)
        fprintf(stderr, "mech %s: %s: %ld row%s dropped%s, %ld kept; the dropped variants "
                "are solved again\n", rf->command, rf->path, c.dropped,
                c.dropped == 1 ? "" : "s", c.told > 5 ? " (the first 5 problems named)" : "",
                c.kept);
    int e = write_all(rf->fd, c.out, c.olen, 0);
    free(c.out);
    if (e || ftruncate(rf->fd, (off_t)c.olen) != 0) {
        errno = e ? e : errno;
        return io_error(rf, "rewrite", rf->path);
    }
    rf->end = (off_t)c.olen;
    rf->saved = c.kept;
    return -1;
}

/* OUT.partial opened (resume) or created; -1, or the exit status. */
static int open_partial(rowfile *rf, const char *out, int resume)
{
    size_t n = strlen(out) + 9;
    if (!(rf->path = malloc(n)))
        return oom(rf);
    snprintf(rf->path, n, "%s.partial", out);
    int fd = open(rf->path, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    int existed = fd < 0 && errno == EEXIST;
    if (existed && resume)
        fd = open(rf->path, O_RDWR | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (existed && !resume) {
        fprintf(stderr, "mech %s: %s exists (the rows of a run that stopped before the end?): "
                "give --resume to continue it, or remove it\n", rf->command, rf->path);
        return MECH_EXIT_INPUT;
    }
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd), errno = EINVAL;
        return io_error(rf, "open", rf->path);
    }
    rf->fd = fd;
    if (existed)
        return resume_rows(rf);
    if ((errno = write_all(fd, rf->head, rf->head_len, 0)) != 0)
        return io_error(rf, "write", rf->path);
    rf->end = (off_t)rf->head_len;
    return -1;
}

int rows_open(rowfile *rf, const char *command, const char *out, int resume, const char *head,
              long first, long step, long count, rows_check_fn check, const void *ctx)
{
    memset(rf, 0, sizeof *rf);
    pthread_mutex_init(&rf->lock, NULL);
    rf->fd = -1;
    rf->command = command;
    rf->first = first;
    rf->step = step;
    rf->count = count;
    rf->check = check;
    rf->check_ctx = ctx;
    rf->head = strdup(head);
    rf->done = calloc((size_t)count / 8 + 1, 1);
    rf->bcap = BLOCK_BYTES + 4096 + CHECK_LINE;
    rf->block = malloc(rf->bcap);
    if (!rf->head || !rf->done || !rf->block) {
        int code = oom(rf);
        rows_close(rf);
        return code;
    }
    rf->head_len = strlen(head);
    digest_init(&rf->head_digest);
    size_t p = 0, next;
    for (int k = 0; k < 2; k++, p = next) {
        long n = line_at(head, rf->head_len, p, &next);
        digest_line(&rf->head_digest, head + p, (size_t)n);
        if (k == 1)
            rf->ncells = csv_cells(head + p, (size_t)n);
    }
    rf->bd = rf->head_digest;
    struct stat st;  /* a device, a FIFO, a directory: no OUT.partial beside it */
    int regular = out && strcmp(out, "-") != 0 && (stat(out, &st) != 0 || S_ISREG(st.st_mode));
    int code = -1;
    if (regular) {
        code = open_partial(rf, out, resume);
    } else if (resume) {
        fprintf(stderr, "mech %s: --resume needs -o FILE, a regular file (%s is not)\n",
                command, out ? out : "-");
        code = MECH_EXIT_INPUT;
    } else if (!(rf->tmp = tmpfile()) ||
               (errno = write_all(rf->fd = fileno(rf->tmp), head, rf->head_len, 0)) != 0) {
        code = io_error(rf, "create", "a temporary file");
    } else {
        rf->end = (off_t)rf->head_len;
    }
    if (code < 0)
        start_timer(rf);
    else
        rows_close(rf);  /* nothing is left open or allocated when it fails */
    return code;
}

/* ---- rows recorded by an earlier run (mech batch --skip-existing) ------- */

/* path read whole when it is a regular file (never waiting on a FIFO). */
static char *read_regular(const char *path, size_t *len)
{
    struct stat st;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOFOLLOW);
    char *buf = fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode) ? read_all(fd, len) : NULL;
    if (fd >= 0)
        close(fd);
    return buf;
}

/* The first two lines of buf are head: the offset after them, else 0. */
static size_t after_head(const char *buf, size_t len, const char *head)
{
    size_t hl = strlen(head);
    return len >= hl && memcmp(buf, head, hl) == 0 ? hl : 0;
}

static void ignore_bad(void *ctx, long from, long to, long rows)
{
    (void)ctx, (void)from, (void)to, (void)rows;
}

/* A whole table: its rows (the lines but '#' ones) when the digest line
 * at its end matches every line before it. */
static void whole_table_rows(const char *buf, size_t len, size_t body,
                             void (*row)(void *ctx, const char *r, size_t n, long line), void *ctx)
{
    line_digest d;
    size_t p = 0, next;
    long n, rows, line = 1;
    uint64_t h;
    char text[128];
    digest_init(&d);
    for (; (n = line_at(buf, len, p, &next)) >= 0; p = next, line++) {
        size_t np = strlen(DIGEST_TRAILER);
        if (n >= (long)np && n < (long)sizeof text && memcmp(buf + p, DIGEST_TRAILER, np) == 0) {
            memcpy(text, buf + p, (size_t)n);
            text[n] = '\0';
            break;
        }
        digest_line(&d, buf + p, (size_t)n);
    }
    if (n < 0 || digest_parse(text, DIGEST_TRAILER, &rows, &h) != 0 || h != d.h)
        return;
    for (p = body, line = 3; p < len && (n = line_at(buf, len, p, &next)) >= 0; p = next, line++)
        if (buf[p] != '#')
            row(ctx, buf + p, (size_t)n, line);
}

void rows_read_recorded(const char *table, const char *head, const line_digest *head_digest,
                        void (*row)(void *ctx, const char *r, size_t n, long line), void *ctx)
{
    size_t len, body, n = strlen(table) + 9;
    char *buf = read_regular(table, &len), *partial = malloc(n);
    if (buf && (body = after_head(buf, len, head)) > 0)
        whole_table_rows(buf, len, body, row, ctx);
    free(buf);
    if (!partial)
        return;
    snprintf(partial, n, "%s.partial", table);
    if ((buf = read_regular(partial, &len)) && (body = after_head(buf, len, head)) > 0)
        rows_scan_blocks(buf, len, body, 3, head_digest, row, ignore_bad, ctx);
    free(buf);
    free(partial);
}

/* ---- the end: OUT in index order ---------------------------------------- */

typedef struct ordered {
    const rowfile *rf;
    const char *buf;       /* the file read back, len bytes */
    size_t len;
    size_t *start;         /* [count] 1 + where row i starts in buf, 0: not found */
    long found, nok, bad;
    int status_field;
    int with_manifest;
} ordered;

/* Field k of the row at s (n bytes) is "ok" (the fields have no commas). */
static int field_is_ok(const char *s, size_t n, int k)
{
    const char *end = s + n;
    for (; k > 0 && s < end; s++)
        k -= *s == ',';
    return end - s >= 2 && s[0] == 'o' && s[1] == 'k' && (end - s == 2 || s[2] == ',');
}

static void finish_row(void *ctx, const char *r, size_t n, long line)
{
    ordered *o = ctx;
    long i = row_slot(o->rf, csv_row_index(r, n));
    (void)line;
    if (i >= 0 && !o->start[i]) {
        o->start[i] = (size_t)(r - o->buf) + 1;
        o->nok += field_is_ok(r, n, o->status_field);
        o->found++;
    }
}

static void finish_bad(void *ctx, long from, long to, long rows)
{
    ordered *o = ctx;
    (void)from, (void)to;
    o->bad += rows + 1;
}

static void put_line(FILE *f, line_digest *d, const char *s, size_t n)
{
    fwrite(s, 1, n, f);
    fputc('\n', f);
    digest_line(d, s, n);
}

static int emit_ordered(FILE *f, const void *ctx)
{
    const ordered *o = ctx;
    const rowfile *rf = o->rf;
    size_t p = 0, next;
    line_digest d;
    digest_init(&d);
    for (int k = 0; k < 2; k++, p = next) {
        long n = line_at(rf->head, rf->head_len, p, &next);
        if (k == 1 || o->with_manifest)
            put_line(f, &d, rf->head + p, (size_t)n);
    }
    for (long i = 0; i < rf->count; i++) {
        size_t s = o->start[i] - 1;
        put_line(f, &d, o->buf + s, (size_t)line_at(o->buf, o->len, s, &next));
    }
    if (o->with_manifest) {
        char trailer[CHECK_LINE];
        digest_format(trailer, sizeof trailer, DIGEST_TRAILER, rf->count, d.h);
        fputs(trailer, f);
    }
    return ferror(f) ? -1 : 0;
}

/* OUT.h5: the ordered CSV text as HDF5 (cmd_h5.c), the head's manifest
 * line and header as attributes. The exit status. */
static int write_h5(const ordered *o, const char *out)
{
    const rowfile *rf = o->rf;
    size_t p = 0, next;
    long n1 = line_at(rf->head, rf->head_len, p, &next);
    char *mline = n1 >= 0 ? strndup(rf->head, (size_t)n1) : NULL;
    long n2 = mline ? line_at(rf->head, rf->head_len, next, &p) : -1;
    char *header = n2 >= 0 ? strndup(rf->head + next, (size_t)n2) : NULL;
    int code = header ? -1 : oom(rf);
    h5_head h = {rf->command, mline, header, rf->input, o->with_manifest};
    if (code < 0)
        code = cmd_h5_write_text(&h, out, emit_ordered, o);
    free(mline);
    free(header);
    return code;
}

int rows_finish(rowfile *rf, const char *out, int with_manifest, int status_field, long *nok)
{
    stop_timer(rf);
    write_block(rf);
    if (rf->write_errno) {
        errno = rf->write_errno;
        return io_error(rf, "write", file_name(rf));
    }
    size_t len;
    char *buf = read_all(rf->fd, &len);
    ordered o = {rf, buf, len, calloc((size_t)rf->count + 1, sizeof *o.start), 0, 0, 0,
                 status_field, with_manifest};
    if (!buf || !o.start) {
        free(buf);
        free(o.start);
        return oom(rf);
    }
    rows_scan_blocks(buf, len, rf->head_len, 3, &rf->head_digest, finish_row, finish_bad, &o);
    *nok = o.nok;
    int code = -1;
    if (o.bad)
        fprintf(stderr, "mech %s: %s changed while the sweep ran (a block's check line does "
                "not match its rows); run again with --resume\n", rf->command, file_name(rf));
    else if (o.found != rf->count)  /* a row that could not be written (disk full) */
        fprintf(stderr, "mech %s: %ld of %ld rows in %s; run again with --resume\n",
                rf->command, o.found, rf->count, file_name(rf));
    else
        code = MECH_EXIT_OK;
    if (code == MECH_EXIT_OK && out && output_is_h5_name(out)) {
        code = write_h5(&o, out);
    } else if (code == MECH_EXIT_OK) {
        mech_diag d;
        mech_diag_init(&d);
        int rc = write_file_whole(out ? out : "-", emit_ordered, &o, &d);
        mech_diag_print(&d, stderr);
        mech_diag_free(&d);
        code = rc == MECH_OK ? MECH_EXIT_OK : MECH_EXIT_IO;
    }
    free(buf);
    free(o.start);
    if (code != MECH_EXIT_OK)
        return MECH_EXIT_IO;  /* OUT.partial stays: --resume writes OUT again */
    if (rf->path && unlink(rf->path) == 0) {
        free(rf->path);
        rf->path = NULL;
    }
    return MECH_EXIT_OK;
}

void rows_close(rowfile *rf)
{
    stop_timer(rf);
    if (rf->tmp)
        fclose(rf->tmp);
    else if (rf->head && rf->fd >= 0)  /* opened (a rowfile only zeroed has no head) */
        close(rf->fd);
    free(rf->path);
    free(rf->head);
    free(rf->done);
    free(rf->block);
    pthread_mutex_destroy(&rf->lock);
    memset(rf, 0, sizeof *rf);
    rf->fd = -1;
}
