/* src/output.h: output files written whole or not at all (src/output.c;
 * the policy is docs/cli.md, section Files). */
#ifndef MECH_OUTPUT_H
#define MECH_OUTPUT_H

#include <stdio.h>

#include "mech.h"

/* Write what emit(f, ctx) prints (it returns 0 on success) to `path`:
 *   "-"                      standard output;
 *   a FIFO, a character device  opened and written straight through;
 *   a regular file or a new name  a temporary file beside it (mkstemp, mode
 *                            0666 less the umask), fsync'ed and renamed over
 *                            it when complete, removed on failure or on
 *                            SIGTERM/SIGINT/SIGHUP (output_catch_signals);
 *   a symbolic link          the same for its target (the link stays);
 *   anything else            refused (a directory, a socket, a block device).
 * Returns MECH_OK, or MECH_EIO / MECH_ENOMEM with the message in d.
 * Thread-safe. */
int write_file_whole(const char *path, int (*emit)(FILE *, const void *), const void *ctx,
                     mech_diag *d);

/* 1 when write_file_whole has reported a failed write to standard output
 * (so src/main.c does not report it again). */
int output_stdout_reported(void);

/* Handlers of SIGTERM, SIGINT and SIGHUP (those not ignored) that remove
 * the temporary files being written, then die of the signal. Call once at
 * start-up, before any thread. */
void output_catch_signals(void);

#endif
