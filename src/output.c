/* src/output.c: result tables and their CSV files.
 *
 * A CSV is written to a temporary file beside the target and renamed over
 * it only when every byte is out, so a reader never sees half a file and a
 * failed run leaves an older file untouched. Numbers are printed with 17
 * significant digits: reading them back gives the same doubles. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "internal.h"

void mech_table_free(mech_table *t)
{
    if (!t)
        return;
    for (int i = 0; i < t->ncolumns; i++) {
        free(t->columns[i].name);
        free(t->columns[i].unit);
    }
    free(t->columns);
    free(t->values);
    free(t->gaps);
    memset(t, 0, sizeof *t);
}

int mech_table_column(const mech_table *t, const char *name)
{
    for (int i = 0; i < t->ncolumns; i++)
        if (strcmp(t->columns[i].name, name) == 0)
            return i;
    return -1;
}

static int write_rows(const mech_table *t, FILE *f)
{
    for (int c = 0; c < t->ncolumns; c++)
        fprintf(f, "%s%s [%s]", c ? "," : "", t->columns[c].name, t->columns[c].unit);
    fputc('\n', f);
    for (int r = 0; r < t->nrows; r++) {
        for (int c = 0; c < t->ncolumns; c++)
            fprintf(f, "%s%.17g", c ? "," : "", mech_table_get(t, r, c));
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}

int write_file_whole(const char *path, int (*emit)(FILE *, const void *), const void *ctx,
                     mech_diag *d)
{
    if (strcmp(path, "-") == 0) {
        if (emit(stdout, ctx) == 0 && fflush(stdout) == 0 && !ferror(stdout))
            return MECH_OK;
        return diag_error(d, path, (mech_mark){0, 0}, "cannot write to standard output: %s",
                          strerror(errno)), MECH_EIO;
    }
    size_t n = strlen(path) + 32;
    char *tmp = malloc(n);
    if (!tmp)
        return diag_error(d, path, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    /* beside the target (rename stays on one file system); 0666 less umask */
    snprintf(tmp, n, "%s.tmp%ld", path, (long)getpid());
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        int e = errno;
        if (fd >= 0) {
            close(fd);
            unlink(tmp);
        }
        free(tmp);
        return diag_error(d, path, (mech_mark){0, 0}, "cannot create the output file: %s",
                          strerror(e)), MECH_EIO;
    }
    int bad = emit(f, ctx) != 0 || ferror(f);
    int e = errno;
    if (fclose(f) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    if (!bad && rename(tmp, path) != 0) {
        bad = 1;
        e = errno;
    }
    if (bad) {
        unlink(tmp);
        free(tmp);
        return diag_error(d, path, (mech_mark){0, 0}, "cannot write the output file: %s",
                          strerror(e ? e : EIO)), MECH_EIO;
    }
    free(tmp);
    return MECH_OK;
}

static int emit_csv(FILE *f, const void *t) { return write_rows(t, f); }

int mech_table_write_csv(const mech_table *t, const char *path, mech_diag *d)
{
    return write_file_whole(path, emit_csv, t, d);
}
