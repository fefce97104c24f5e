/* src/output/output.c: result tables, their CSV files, and how every output file
 * is written (docs/cli.md, section Files).
 *
 * A regular file (or a new one) is written to a temporary file beside it,
 * created exclusively with an unpredictable name (mkstemp), flushed to disk
 * and renamed over the target only when every byte is out: a reader never
 * sees half a file and a failed run leaves an older file untouched. A
 * symbolic link is followed: its target is replaced, the link stays. A FIFO,
 * a character device (/dev/null, a terminal) or "-" (standard output) is
 * written straight through; anything else that is not a regular file (a
 * directory, a socket, a block device) is refused. The temporary files
 * being written are kept in a table that a handler of SIGTERM, SIGINT and
 * SIGHUP reads to remove them before the process dies (SIGKILL cannot be
 * caught: a stale temporary file is harmless, its name is random).
 *
 * Numbers are printed as the shortest decimal that reads back as the same
 * double (fmt_double, src/base/fmt.c). */
#define _XOPEN_SOURCE 700  /* realpath (glibc hides it under _POSIX_C_SOURCE alone) */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base.h"
#include "output.h"

/* The header, then each row built in a buffer (the numbers by fmt_double,
 * the shortest text that reads back the same) and written at once. */
static int write_rows(const mech_table *t, FILE *f)
{
    for (int c = 0; c < t->ncolumns; c++)
        fprintf(f, "%s%s [%s]", c ? "," : "", t->columns[c].name, t->columns[c].unit);
    fputc('\n', f);
    size_t cap = (size_t)t->ncolumns * FMT_DOUBLE_MAX + 2;
    char *row = malloc(cap);
    if (!row)
        return -1;
    for (int r = 0; r < t->nrows && !ferror(f); r++) {
        size_t n = 0;
        for (int c = 0; c < t->ncolumns; c++) {
            if (c)
                row[n++] = ',';
            n += (size_t)fmt_double(mech_table_get(t, r, c), row + n);
        }
        row[n++] = '\n';
        fwrite(row, 1, n, f);
    }
    free(row);
    return ferror(f) ? -1 : 0;
}

/* ---- temporary files the signal handler removes ----------------------- */

/* One slot per temporary file being written: state LIVE_FREE, LIVE_BUSY
 * (claimed, path being filled in or taken out) or LIVE_SET (path is a file
 * to remove). The handler reads only slots in LIVE_SET; a lock-free atomic
 * int is safe to read in a signal handler. More files at once than slots
 * (more than 1024 worker threads) go unregistered. */
enum { LIVE_FREE, LIVE_BUSY, LIVE_SET, LIVE_SLOTS = 1100 };

static struct live_slot {
    atomic_int state;
    char path[PATH_MAX];  /* the temporary file, NUL-terminated */
} live[LIVE_SLOTS];

static int live_add(const char *path)
{
    size_t n = strlen(path);
    if (n >= PATH_MAX)
        return -1;
    for (int i = 0; i < LIVE_SLOTS; i++) {
        int expect = LIVE_FREE;
        if (atomic_compare_exchange_strong(&live[i].state, &expect, LIVE_BUSY)) {
            memcpy(live[i].path, path, n + 1);
            atomic_store(&live[i].state, LIVE_SET);
            return i;
        }
    }
    return -1;
}

static void live_remove(int slot)
{
    if (slot >= 0)
        atomic_store(&live[slot].state, LIVE_FREE);
}

/* Creating a temporary file and registering it is one step the handler
 * waits for: a thread in it has the signals blocked and counts itself in
 * `creating`; the handler, in another thread, sets `dying` and waits until
 * no thread is in the step before it looks at the slots. A thread that
 * starts the step after `dying` creates nothing. Without this, a file made
 * just before the handler looked and registered just after was left behind
 * by a killed `mech batch` (seen 4 times in 5). */
static atomic_int creating, dying;

static void caught_signals(sigset_t *set)
{
    sigemptyset(set);
    sigaddset(set, SIGTERM);
    sigaddset(set, SIGINT);
    sigaddset(set, SIGHUP);
}

/* mkstemp(tmp), registered for the handler in *slot; -1 with errno. */
static int create_registered(char *tmp, int *slot)
{
    sigset_t set, old;
    caught_signals(&set);
    pthread_sigmask(SIG_BLOCK, &set, &old);
    atomic_fetch_add(&creating, 1);
    int fd = -1, e = EINTR;
    if (!atomic_load(&dying)) {
        fd = mkstemp(tmp);  /* O_EXCL, mode 0600, unpredictable name */
        e = errno;
        *slot = fd >= 0 ? live_add(tmp) : -1;
    }
    atomic_fetch_sub(&creating, 1);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    errno = e;
    return fd;
}

/* Async-signal-safe: unlink the live temporary files, then die of the same
 * signal (SA_RESETHAND restored the default action; the signal, blocked
 * while the handler runs, is delivered when it returns). */
static void on_signal(int sig)
{
    int e = errno;
    atomic_store(&dying, 1);
    while (atomic_load(&creating) > 0)
        ;  /* another thread is between mkstemp and its registration */
    for (int i = 0; i < LIVE_SLOTS; i++)
        if (atomic_load(&live[i].state) == LIVE_SET)
            unlink(live[i].path);
    errno = e;
    raise(sig);
}

void output_catch_signals(void)
{
    static const int sigs[] = {SIGTERM, SIGINT, SIGHUP};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction old, sa;
        if (sigaction(sigs[i], NULL, &old) != 0 || old.sa_handler == SIG_IGN)
            continue;  /* nohup: an ignored signal stays ignored */
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESETHAND;
        sigaction(sigs[i], &sa, NULL);
    }
}

/* ---- writing ----------------------------------------------------------- */

static pthread_once_t mask_once = PTHREAD_ONCE_INIT;
static mode_t file_mask;  /* the process's umask, read once */

/* umask cannot be read without being set: it is 0 for a moment, which is
 * safe because only write_file_whole creates files while workers run, and
 * it waits for this (pthread_once). */
static void read_umask(void)
{
    file_mask = umask(0);
    umask(file_mask);
}

static int io_error(mech_diag *d, const char *path, const char *what, int e)
{
    char buf[128];
    return diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "%s: %s", what,
                     diag_strerror(e ? e : EIO, buf, sizeof buf));
}

/* emit into f, then flush (and with sync, fsync) and close f; 0 or an errno. */
static int emit_close(FILE *f, int (*emit)(FILE *, const void *), const void *ctx, int sync)
{
    errno = 0;
    int bad = emit(f, ctx) != 0 || fflush(f) != 0 || ferror(f);
    int e = bad ? (errno ? errno : EIO) : 0;
    if (!bad && sync && fsync(fileno(f)) != 0) {
        bad = 1;
        e = errno;
    }
    if (fclose(f) != 0 && !bad)
        e = errno ? errno : EIO;
    return e;
}

/* A FIFO or a character device: opened and written, never replaced. */
static int write_through(const char *path, int (*emit)(FILE *, const void *), const void *ctx,
                         mech_diag *d)
{
    int fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        int e = errno;
        if (fd >= 0)
            close(fd);
        return io_error(d, path, "cannot open the output", e);
    }
    int e = emit_close(f, emit, ctx, 0);
    return e ? io_error(d, path, "cannot write the output", e) : MECH_OK;
}

/* The temporary file fd (named tmp) filled: by emit through a stream, or
 * by emit_path, a writer that opens the file by its name (HDF5), then
 * synced here; fd is closed either way. 0 or an errno. */
static int fill_temporary(int fd, const char *tmp, int (*emit)(FILE *, const void *),
                          int (*emit_path)(const char *, const void *), const void *ctx)
{
    int e = fchmod(fd, 0666 & ~file_mask) != 0 ? errno : 0;  /* as fopen would create it */
    if (emit_path) {
        if (!e && emit_path(tmp, ctx) != 0)
            e = errno ? errno : EIO;
        if (!e && fsync(fd) != 0)  /* the same file: the writer reopened it by name */
            e = errno;
        if (close(fd) != 0 && !e)
            e = errno;
        return e;
    }
    FILE *f = NULL;
    if (!e && !(f = fdopen(fd, "w")))
        e = errno;
    if (!f) {
        close(fd);
        return e;
    }
    return emit_close(f, emit, ctx, 1);
}

/* A regular file `target` (which may not exist yet; not a symbolic link):
 * a temporary file beside it, filled by emit or emit_path (fill_temporary)
 * and renamed over it when complete. Messages name `path`, the name the
 * user gave. */
static int write_replacing(const char *path, const char *target,
                           int (*emit)(FILE *, const void *),
                           int (*emit_path)(const char *, const void *), const void *ctx,
                           mech_diag *d)
{
    size_t n = strlen(target) + sizeof ".tmpXXXXXX";
    char *tmp = malloc(n);
    if (!tmp)
        return diag_nomem(d, path, (mech_mark){0, 0});
    snprintf(tmp, n, "%s.tmpXXXXXX", target);
    pthread_once(&mask_once, read_umask);
    int slot = -1;
    int fd = create_registered(tmp, &slot);
    if (fd < 0) {
        int e = errno;
        free(tmp);
        return io_error(d, path, "cannot create the output file", e);
    }
    int e = fill_temporary(fd, tmp, emit, emit_path, ctx);
    if (!e && rename(tmp, target) != 0)
        e = errno;
    if (e)
        unlink(tmp);
    live_remove(slot);
    free(tmp);
    return e ? io_error(d, path, "cannot write the output file", e) : MECH_OK;
}

static atomic_int stdout_reported;  /* a failed write of "-" was reported */

int output_stdout_reported(void)
{
    return atomic_load(&stdout_reported);
}

static const char *kind_name(mode_t mode)
{
    return S_ISDIR(mode) ? "a directory" : S_ISSOCK(mode) ? "a socket"
           : S_ISBLK(mode) ? "a block device" : "not a regular file";
}

int write_file_whole(const char *path, int (*emit)(FILE *, const void *), const void *ctx,
                     mech_diag *d)
{
    if (strcmp(path, "-") == 0) {
        errno = 0;
        if (emit(stdout, ctx) == 0 && fflush(stdout) == 0 && !ferror(stdout))
            return MECH_OK;
        atomic_store(&stdout_reported, 1);
        return io_error(d, path, "cannot write standard output", errno);
    }
    struct stat st;
    if (lstat(path, &st) != 0) {
        if (errno != ENOENT)
            return io_error(d, path, "cannot write the output", errno);
        return write_replacing(path, path, emit, NULL, ctx, d);  /* a new file */
    }
    char *target = NULL;
    if (S_ISLNK(st.st_mode)) {  /* its target is written; the link stays */
        target = realpath(path, NULL);
        if (!target || stat(target, &st) != 0) {
            int e = errno;
            free(target);
            return io_error(d, path, e == ENOENT ? "the symbolic link's target does not exist"
                                                 : "cannot follow the symbolic link", e);
        }
    }
    int rc;
    if (S_ISREG(st.st_mode))
        rc = write_replacing(path, target ? target : path, emit, NULL, ctx, d);
    else if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode))
        rc = write_through(path, emit, ctx, d);
    else {
        rc = diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "cannot write the output: %s, "
                       "not a regular file, a FIFO or a character device", kind_name(st.st_mode));
    }
    free(target);
    return rc;
}

int write_file_whole_by_name(const char *path, int (*emit_path)(const char *, const void *),
                             int (*emit)(FILE *, const void *), const void *ctx, mech_diag *d)
{
    if (strcmp(path, "-") == 0)
        return write_file_whole(path, emit, ctx, d);
    struct stat st;
    if (lstat(path, &st) != 0) {
        if (errno != ENOENT)
            return io_error(d, path, "cannot write the output", errno);
        return write_replacing(path, path, NULL, emit_path, ctx, d);  /* a new file */
    }
    if (!S_ISREG(st.st_mode))  /* a symbolic link, a FIFO, a device: through emit */
        return write_file_whole(path, emit, ctx, d);
    return write_replacing(path, path, NULL, emit_path, ctx, d);
}

static int emit_csv(FILE *f, const void *t) { return write_rows(t, f); }

int mech_table_write_csv(const mech_table *t, const char *path, mech_diag *d)
{
    mech_diag own, *dd = api_diag(d, &own);
    int rc = t && path ? write_file_whole(path, emit_csv, t, dd)
                       : api_null(dd, "mech_table_write_csv", t ? "path" : "t");
    api_diag_end(d, &own);
    return rc;
}

int mech_table_read(const char *path, mech_table *out, mech_diag *d)
{
    mech_diag own, *dd = api_diag(d, &own);
    int rc;
    if (!path || !out) {
        rc = api_null(dd, "mech_table_read", out ? "path" : "out");
        api_diag_end(d, &own);
        return rc;
    }
    memset(out, 0, sizeof *out);
    compare_table ct;
    rc = compare_read_csv(path, &ct, dd);
    if (rc == MECH_OK && (ct.ncols > INT_MAX || ct.nrows > (size_t)INT_MAX / (ct.ncols + 1)))
        rc = diag_fail(dd, MECH_FAIL_INPUT, path, (mech_mark){0, 0}, "the table is too large");
    if (rc == MECH_OK && !(out->columns = calloc(ct.ncols + 1, sizeof *out->columns)))
        rc = diag_nomem(dd, path, (mech_mark){0, 0});
    if (rc == MECH_OK) {  /* the names, units and values change owner */
        for (size_t c = 0; c < ct.ncols; c++) {
            out->columns[c] = (mech_column){ct.names[c], ct.units[c]};
            ct.names[c] = ct.units[c] = NULL;
        }
        out->ncolumns = (int)ct.ncols;
        out->nrows = out->nrequested = (int)ct.nrows;
        out->values = ct.values;
        ct.values = NULL;
    }
    compare_table_free(&ct);
    api_diag_end(d, &own);
    return rc;
}
