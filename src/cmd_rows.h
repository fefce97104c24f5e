/* src/cmd_rows.h: the rows of a sweep as they finish, in a file beside the
 * output (OUT.partial) that survives a killed run and that --resume
 * continues; at the end read back, put in index order and written whole to
 * OUT (docs/batch.md, section "Nothing computed is lost"). */
#ifndef MECH_CMD_ROWS_H
#define MECH_CMD_ROWS_H

#include <pthread.h>
#include <stdio.h>

#include "cmd_manifest.h"

typedef struct rowfile {
    FILE *f;               /* OUT.partial, or an anonymous temporary file */
    char *path;            /* OUT.partial (owned), NULL for the temporary file */
    const char *command;   /* "sweep", for messages */
    char *head;            /* the manifest line and the header line, owned */
    long first, step;      /* row i has the index first + i * step ... */
    long count;            /* ... for i < count */
    unsigned char *done;   /* [count / 8 + 1] bit i: row i is in the file */
    long ndone;
    pthread_mutex_t lock;  /* one row (and its messages) at a time */
} rowfile;

/* Opens the rows of a run whose file starts with `head` (the manifest line
 * and the CSV header, each with its newline). out NULL, "-" or an existing
 * file that is not a regular one (/dev/null, a FIFO): a temporary file.
 * Else OUT.partial: a new file; one that exists is refused unless
 * resume, which keeps its complete rows when its head is the same (a row cut
 * by the kill is dropped). Returns -1 when open, else the exit status (the
 * problem printed). */
int rows_open(rowfile *rf, const char *command, const char *out, int resume, const char *head,
              long first, long step, long count);
/* 1 when row i is already in the file (resumed). */
int rows_done(const rowfile *rf, long i);
/* Appends row i (line with its newline) and flushes it; then prints
 * messages (may be NULL) on standard error, under the same lock so the
 * blocks of two rows do not mix. */
void rows_put(rowfile *rf, long i, const char *line, const char *messages);
/* Writes OUT whole: the manifest line when with_manifest, the header, and
 * the rows in index order; then removes OUT.partial. *nok: the rows whose
 * field `status_field` (0-based) is "ok". Returns the exit status. */
int rows_finish(rowfile *rf, const char *out, int with_manifest, int status_field, long *nok);
/* Closes the file and frees rf (OUT.partial stays unless finished). */
void rows_close(rowfile *rf);

#endif
