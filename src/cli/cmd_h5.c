/* src/cli/cmd_h5.c: HDF5 for the tables that are text first (docs/cli.md,
 * "HDF5 output"): mech sweep's rows and mech merge's output are made as
 * their CSV (streamed, checked, ordered as always), then that text is read
 * back (compare_read_csv_stream) and written as HDF5 by the one writer
 * (output_write_h5_table: a temporary file renamed over OUT), the manifest
 * as root attributes; and the way back for mech merge: an HDF5 shard as
 * the lines of its CSV form, each number in the shortest form that reads
 * back as the same double, so that every check merge makes on a CSV shard
 * (manifest, header, rows, digest line) is made on it. */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"

/* x as mech sweep writes a number (fmt_double: the fewest digits that read
 * back, whole numbers below 1e17 with all their digits, nan and inf as
 * printf spells them) into buf: its length, 0 when it does not fit */
static size_t put_number(char *buf, size_t size, double x)
{
    char text[FMT_DOUBLE_MAX];
    size_t n = (size_t)fmt_double(x, text);
    if (n >= size)
        return 0;
    memcpy(buf, text, n + 1);
    return n;
}

/* Row r of t as a line of its canonical CSV form, with its newline, into
 * f (unless NULL) and into d. line[size] is workspace: no allocation per row. 0, or -1
 * when the row does not fit. */
static int put_row(const compare_table *t, size_t r, FILE *f, line_digest *d, char *line,
                   size_t size)
{
    size_t n = 0;
    for (size_t c = 0; c < t->ncols; c++) {
        const char *w = compare_cell_text(t, r, c);
        if (size - n < 48)
            return -1;
        if (c)
            line[n++] = ',';
        if (w && strlen(w) >= size - n)
            return -1;
        if (w)
            n += (size_t)snprintf(line + n, size - n, "%s", w);
        else
            n += put_number(line + n, size - n, t->values[r * t->ncols + c]);
    }
    if (f) {
        fwrite(line, 1, n, f);
        fputc('\n', f);
    }
    digest_line(d, line, n);
    return 0;
}

/* The digest line of the canonical form (manifest line, header, rows) of
 * t into buf, without its newline. 0, or -1 out of memory. */
static int canonical_digest(const compare_table *t, const char *mline, const char *header,
                            char *buf, size_t size)
{
    enum { LINE = 1 << 16 };
    char *line = malloc(LINE);
    line_digest d;
    digest_init(&d);
    digest_line(&d, mline, strlen(mline));
    digest_line(&d, header, strlen(header));
    int rc = line ? 0 : -1;
    for (size_t r = 0; rc == 0 && r < t->nrows; r++)
        rc = put_row(t, r, NULL, &d, line, LINE);
    int n = digest_format(buf, size, DIGEST_TRAILER, (long)t->nrows, d.h);
    if (n > 0 && (size_t)n < size && buf[n - 1] == '\n')
        buf[n - 1] = '\0';
    free(line);
    return rc;
}

enum { MAX_ATTRS = 16 };

typedef struct attrs {
    const char *key[MAX_ATTRS], *value[MAX_ATTRS];
    int n;
    char digest[24], shard[32], total[24], offset[24], grid[24], trailer[96];
    manifest man;
} attrs;

static void put(attrs *a, const char *key, const char *value)
{
    if (a->n < MAX_ATTRS) {
        a->key[a->n] = key;
        a->value[a->n++] = value;
    }
}

/* The root attributes of h: the manifest's fields (and, for a shard, its
 * lines: mech merge reads them back). 0, or -1 out of memory. */
static int make_attrs(attrs *a, const h5_head *h, const compare_table *t)
{
    memset(a, 0, sizeof *a);
    int has = h->manifest && manifest_parse(h->manifest, &a->man) == 0;
    snprintf(a->digest, sizeof a->digest, has ? "%016" PRIx64 : "-", a->man.input);
    put(a, "mech_version", has ? a->man.version : MECH_VERSION);
    put(a, "command", has ? a->man.command : h->command);
    put(a, "input", h->input ? h->input : "-");
    put(a, "input_digest", a->digest);
    put(a, "csv_header", h->header);
    if (!has || !h->shard)
        return 0;
    snprintf(a->shard, sizeof a->shard, "%d/%d", a->man.shard_k, a->man.shard_m);
    snprintf(a->total, sizeof a->total, "%ld", a->man.total);
    snprintf(a->offset, sizeof a->offset, "%ld", a->man.offset);
    snprintf(a->grid, sizeof a->grid, "%016" PRIx64, a->man.grid);
    put(a, "shard", a->shard);
    put(a, "total", a->total);
    put(a, "offset", a->offset);
    put(a, "grid", a->grid);
    put(a, "tol", a->man.tol[0] ? a->man.tol : "-");
    put(a, "args", a->man.args);
    put(a, "manifest", h->manifest);
    put(a, "digest", a->trailer);
    return canonical_digest(t, h->manifest, h->header, a->trailer, sizeof a->trailer);
}

int cmd_h5_write_text(const h5_head *h, const char *out, int (*emit)(FILE *, const void *),
                      const void *ctx)
{
    FILE *f = tmpfile();
    if (!f || emit(f, ctx) != 0 || fflush(f) != 0) {
        fprintf(stderr, "mech %s: cannot write a temporary file for %s: %s\n", h->command, out,
                strerror(errno ? errno : EIO));
        if (f)
            fclose(f);
        return MECH_EXIT_IO;
    }
    rewind(f);
    mech_diag d;
    mech_diag_init(&d);
    compare_table t;
    attrs a;
    int rc = compare_read_csv_stream(f, out, &t, &d);
    fclose(f);
    if (rc == MECH_OK && make_attrs(&a, h, &t) != 0)
        rc = diag_nomem(&d, out, (mech_mark){0, 0});
    if (rc == MECH_OK)
        rc = output_write_h5_table(&t, out, a.key, a.value, a.n, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    compare_table_free(&t);
    return rc == MECH_OK ? MECH_EXIT_OK : rc == MECH_EINPUT ? MECH_EXIT_INPUT : MECH_EXIT_IO;
}

/* ---- an HDF5 shard as text, for mech merge ------------------------------ */

FILE *cmd_h5_shard_text(const char *path)
{
    static const char *const names[] = {"manifest", "csv_header", "digest"};
    char *v[3];
    mech_diag d;
    mech_diag_init(&d);
    compare_table t;
    int rc = compare_read_h5(path, &t, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc != MECH_OK)
        return NULL;
    enum { LINE = 1 << 16 };
    char *line = malloc(LINE);
    FILE *f = line && output_h5_attrs(path, names, v, 3) == 0 ? tmpfile() : NULL;
    line_digest dg;
    digest_init(&dg);
    if (f && v[0])
        fprintf(f, "%s\n", v[0]);
    if (f && v[1])
        fprintf(f, "%s\n", v[1]);
    int fits = 1;
    for (size_t r = 0; f && fits && r < t.nrows; r++)
        fits = put_row(&t, r, f, &dg, line, LINE) == 0;
    if (f && v[2])
        fprintf(f, "%s\n", v[2]);
    if (f && (!fits || fflush(f) != 0 || ferror(f))) {
        fclose(f);
        f = NULL;
    }
    if (f)
        rewind(f);
    for (int i = 0; line && i < 3; i++)
        free(v[i]);
    free(line);
    compare_table_free(&t);
    return f;
}
