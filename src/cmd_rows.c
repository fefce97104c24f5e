/* src/cmd_rows.c: a sweep's rows as they finish, kept in OUT.partial (a
 * killed run loses at most the rows being solved), continued by --resume,
 * and at the end written whole to OUT in index order (src/cmd_rows.h). */
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cmd_rows.h"
#include "commands.h"
#include "output.h"

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

/* The whole of f from its start into a NUL-terminated buffer (*len bytes). */
static char *read_all(FILE *f, size_t *len)
{
    size_t cap = 65536, n = 0, got;
    char *buf = malloc(cap + 1);
    rewind(f);
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0)
        if ((n += got) == cap) {
            char *b = realloc(buf, 2 * cap + 1);
            if (!b)
                free(buf);
            buf = b;
            cap *= 2;
        }
    if (buf && ferror(f)) {
        free(buf);
        return NULL;
    }
    if (buf)
        buf[n] = '\0';
    *len = n;
    return buf;
}

/* The position i of the row that starts at line (its first field the
 * index), or -1 when it is not a row of this shard. */
static long row_slot(const rowfile *rf, const char *line)
{
    char *end;
    long idx = strtol(line, &end, 10);
    if (end == line || *end != ',' || idx < rf->first || (idx - rf->first) % rf->step != 0)
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

/* The complete rows of the partial file kept (marked done), the rest cut
 * off; -1, or the exit status when it is not this run's. */
static int resume_rows(rowfile *rf)
{
    size_t len, hl = strlen(rf->head);
    char *buf = read_all(rf->f, &len);
    if (!buf)
        return io_error(rf, "read", rf->path);
    int code = -1;
    if (len < hl || memcmp(buf, rf->head, hl) != 0) {
        fprintf(stderr, "mech %s: %s is not a part of this run (its manifest or header "
                "differs: other arguments, input file or version); remove it or write "
                "another -o\n", rf->command, rf->path);
        code = MECH_EXIT_INPUT;
    }
    size_t keep = hl, lineno = 2;
    for (char *p = buf + hl, *nl; code < 0 && (nl = strchr(p, '\n')); p = nl + 1) {
        long i = row_slot(rf, p);
        lineno++;
        if (i < 0 || rows_done(rf, i)) {
            fprintf(stderr, "mech %s: %s:%zu: %s\n", rf->command, rf->path, lineno,
                    i < 0 ? "not a row of this shard" : "a variant given twice");
            code = MECH_EXIT_INPUT;
        } else {
            mark(rf, i);
            keep = (size_t)(nl + 1 - buf);
        }
    }
    free(buf);
    if (code < 0 && (fflush(rf->f) != 0 || ftruncate(fileno(rf->f), (off_t)keep) != 0 ||
                     fseek(rf->f, 0, SEEK_END) != 0))
        code = io_error(rf, "cut the unfinished row of", rf->path);
    return code;
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
        fd = open(rf->path, O_RDWR | O_NOFOLLOW | O_CLOEXEC);
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
    if (!(rf->f = fdopen(fd, "r+")))
        return close(fd), io_error(rf, "open", rf->path);
    if (existed)
        return resume_rows(rf);
    if (fputs(rf->head, rf->f) == EOF || fflush(rf->f) != 0)
        return io_error(rf, "write", rf->path);
    return -1;
}

int rows_open(rowfile *rf, const char *command, const char *out, int resume, const char *head,
              long first, long step, long count)
{
    memset(rf, 0, sizeof *rf);
    pthread_mutex_init(&rf->lock, NULL);
    rf->command = command;
    rf->first = first;
    rf->step = step;
    rf->count = count;
    rf->head = strdup(head);
    rf->done = calloc((size_t)count / 8 + 1, 1);
    if (!rf->head || !rf->done)
        return oom(rf);
    struct stat st;  /* a device, a FIFO, a directory: no OUT.partial beside it */
    int regular = out && strcmp(out, "-") != 0 && (stat(out, &st) != 0 || S_ISREG(st.st_mode));
    if (regular)
        return open_partial(rf, out, resume);
    if (resume) {
        fprintf(stderr, "mech %s: --resume needs -o FILE, a regular file (%s is not)\n",
                command, out ? out : "-");
        return MECH_EXIT_INPUT;
    }
    if (!(rf->f = tmpfile()) || fputs(head, rf->f) == EOF)
        return io_error(rf, "create", "a temporary file");
    return -1;
}

void rows_put(rowfile *rf, long i, const char *line, const char *messages)
{
    pthread_mutex_lock(&rf->lock);
    fputs(line, rf->f);
    fflush(rf->f);  /* on disk as soon as it is known: a kill loses no finished row */
    mark(rf, i);
    if (messages && *messages)
        fputs(messages, stderr);
    pthread_mutex_unlock(&rf->lock);
}

typedef struct ordered {
    const rowfile *rf;
    const char *buf;       /* the file read back */
    size_t *start;         /* [count] where row i starts in buf */
    size_t body;           /* where the header starts (after the manifest) */
    int with_manifest;
} ordered;

static int emit_ordered(FILE *f, const void *ctx)
{
    const ordered *o = ctx;
    const char *from = o->with_manifest ? o->buf : o->buf + o->body;
    fwrite(from, 1, (size_t)(strchr(o->buf + o->body, '\n') + 1 - from), f);
    for (long i = 0; i < o->rf->count; i++) {
        const char *s = o->buf + o->start[i];
        fwrite(s, 1, (size_t)(strchr(s, '\n') + 1 - s), f);
    }
    return ferror(f) ? -1 : 0;
}

/* Field k of the row at s is "ok" (the fields have no commas in them). */
static int field_is_ok(const char *s, int k)
{
    for (; k > 0 && *s && *s != '\n'; s++)
        k -= *s == ',';
    return strncmp(s, "ok,", 3) == 0 || strncmp(s, "ok\n", 3) == 0;
}

int rows_finish(rowfile *rf, const char *out, int with_manifest, int status_field, long *nok)
{
    size_t len;
    if (fflush(rf->f) != 0 || ferror(rf->f))
        return io_error(rf, "write", rf->path ? rf->path : "a temporary file");
    char *buf = read_all(rf->f, &len);
    ordered o = {rf, buf, calloc((size_t)rf->count + 1, sizeof *o.start), 0, with_manifest};
    if (!buf || !o.start) {
        free(buf);
        free(o.start);
        return oom(rf);
    }
    o.body = (size_t)(strchr(buf, '\n') + 1 - buf);  /* the head is this run's */
    char *p = strchr(buf + o.body, '\n') + 1, *nl;
    long found = 0;
    *nok = 0;
    for (; (nl = strchr(p, '\n')); p = nl + 1) {
        long i = row_slot(rf, p);
        if (i >= 0 && !o.start[i]) {
            o.start[i] = (size_t)(p - buf);
            *nok += field_is_ok(p, status_field);
            found++;
        }
    }
    if (found != rf->count) {  /* a row that could not be written (disk full) */
        fprintf(stderr, "mech %s: %ld of %ld rows in %s; run again with --resume\n",
                rf->command, found, rf->count, rf->path ? rf->path : "the temporary file");
        free(buf);
        free(o.start);
        return MECH_EXIT_IO;
    }
    mech_diag d;
    mech_diag_init(&d);
    int rc = write_file_whole(out ? out : "-", emit_ordered, &o, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    free(buf);
    free(o.start);
    if (rc != MECH_OK)
        return MECH_EXIT_IO;  /* OUT.partial stays: --resume writes OUT again */
    if (rf->path && unlink(rf->path) == 0) {
        free(rf->path);
        rf->path = NULL;
    }
    return MECH_EXIT_OK;
}

void rows_close(rowfile *rf)
{
    if (rf->f)
        fclose(rf->f);
    free(rf->path);
    free(rf->head);
    free(rf->done);
    pthread_mutex_destroy(&rf->lock);
    memset(rf, 0, sizeof *rf);
}
