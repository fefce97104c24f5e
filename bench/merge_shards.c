/* bench/merge_shards.c: the M shards of a made-up sweep of A x B variants
 * (--vary a=0:1:A --vary b=0:1:B, bare numbers), written as `mech sweep
 * --shard K/M` writes them (manifest with the grid's hash, rows in index
 * order, digest line; src/cli/cli.h), with made-up metrics: rows for
 * timing `mech merge` at 10^6 and 10^7 rows without solving them
 * (bench/bench_merge.sh; tests/merge_forge.py gen is the same in Python).
 *   merge_shards DIR M A B VERSION  ->  DIR/s.K.csv */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

/* The shortest "%.Ng" of x that reads back as x (as mech sweep writes). */
static void shortest(double x, char *buf, size_t size)
{
    for (int p = 1; p <= 17; p++) {
        snprintf(buf, size, "%.*g", p, x);
        if (strtod(buf, NULL) == x)
            return;
    }
}

/* Axis values: texts "%.15g" of i / (n - 1), their SI values' shortest
 * forms in cells, and the axis into the grid hash. */
static char (*axis(const char *name, long n, uint64_t *grid))[32]
{
    char (*cells)[32] = malloc((size_t)n * sizeof *cells), text[64];
    *grid = manifest_hash(*grid, name, strlen(name) + 1);
    for (long i = 0; cells && i < n; i++) {
        snprintf(text, sizeof text, "%.15g", 0.0 + (1.0 - 0.0) * (double)i / (double)(n - 1));
        *grid = manifest_hash(*grid, text, strlen(text) + 1);
        shortest(strtod(text, NULL), cells[i], sizeof cells[i]);
    }
    return cells;
}

int main(int argc, char **argv)
{
    if (argc != 6)
        return fprintf(stderr, "usage: merge_shards DIR M A B VERSION\n"), 2;
    int m = atoi(argv[2]);
    long a = atol(argv[3]), b = atol(argv[4]), total = a * b;
    uint64_t grid = MANIFEST_HASH0;
    char (*ca)[32] = axis("a", a, &grid), (*cb)[32] = axis("b", b, &grid);
    const char *header = "variant [-],a [-],b [-],status [-],rows [-],range:x [m]";
    if (!ca || !cb || m < 1 || a < 2 || b < 2)
        return fprintf(stderr, "merge_shards: bad arguments or out of memory\n"), 2;
    for (int k = 0; k < m; k++) {
        char path[4096], line[256], trailer[96];
        snprintf(path, sizeof path, "%s/s.%d.csv", argv[1], k);
        FILE *f = fopen(path, "w");
        if (!f)
            return perror(path), 3;
        long rows = manifest_shard_rows(total, k, m);
        line_digest d;
        digest_init(&d);
        int n = snprintf(line, sizeof line, "# mech-manifest version=%s command=sweep shard=%d/%d "
                         "rows=%ld total=%ld offset=0 input=0123456789abcdef grid=%016llx tol=- "
                         "args=--vary a=0:1:%ld --vary b=0:1:%ld --metric range:x", argv[5], k,
                         m, rows, total, (unsigned long long)grid, a, b);
        fprintf(f, "%s\n%s\n", line, header);
        digest_line(&d, line, (size_t)n);
        digest_line(&d, header, strlen(header));
        for (long v = k; v < total; v += m) {
            n = snprintf(line, sizeof line, "%ld,%s,%s,ok,361,%.17g", v, ca[v / b], cb[v % b],
                         0.01 + (double)v * 1e-9);
            digest_line(&d, line, (size_t)n);
            fputs(line, f);
            fputc('\n', f);
        }
        digest_format(trailer, sizeof trailer, DIGEST_TRAILER, rows, d.h);
        fputs(trailer, f);
        if (fclose(f) != 0)
            return perror(path), 3;
    }
    free(ca);
    free(cb);
    return 0;
}
