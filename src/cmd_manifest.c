/* src/cmd_manifest.c: the manifest line of a sharded output (hashes,
 * escaped arguments, writing and reading it back); the format is in
 * src/cmd_manifest.h and docs/batch.md. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_manifest.h"
#include "mech.h"

uint64_t manifest_hash(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= UINT64_C(0x100000001b3);  /* the FNV 64-bit prime */
    }
    return h;
}

int manifest_hash_file(uint64_t *h, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    unsigned char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        *h = manifest_hash(*h, buf, n);
    int bad = ferror(f);
    fclose(f);
    if (bad)
        errno = EIO;
    return bad ? -1 : 0;
}

void manifest_add_arg(manifest *m, const char *arg)
{
    size_t n = strlen(m->args), cap = sizeof m->args;
    if (n && n + 1 < cap)
        m->args[n++] = ' ';
    for (const unsigned char *s = (const unsigned char *)arg; *s && n + 5 < cap; s++) {
        if (*s < 32 || *s == 127)
            n += (size_t)snprintf(m->args + n, cap - n, "\\x%02x", *s);
        else if (*s == ' ' || *s == '\\')
            n += (size_t)snprintf(m->args + n, cap - n, "\\%c", *s);
        else
            m->args[n++] = (char)*s;
    }
    m->args[n] = '\0';
}

void manifest_write(const manifest *m, FILE *f)
{
    fprintf(f, MANIFEST_PREFIX "version=%s command=%s shard=%d/%d rows=%ld total=%ld "
            "offset=%ld input=%016" PRIx64 " grid=%016" PRIx64 " args=%s\n", m->version,
            m->command, m->shard_k, m->shard_m, m->rows, m->total, m->offset, m->input,
            m->grid, m->args);
}

int manifest_parse(const char *line, manifest *m)
{
    memset(m, 0, sizeof *m);
    size_t np = strlen(MANIFEST_PREFIX);
    if (strncmp(line, MANIFEST_PREFIX, np) != 0)
        return -1;
    int used = 0;
    int n = sscanf(line + np, "version=%31s command=%15s shard=%d/%d rows=%ld total=%ld "
                   "offset=%ld input=%" SCNx64 " grid=%" SCNx64 " args=%n", m->version,
                   m->command, &m->shard_k, &m->shard_m, &m->rows, &m->total, &m->offset,
                   &m->input, &m->grid, &used);
    if (n != 9 || used == 0 || m->shard_m < 1 || m->shard_k < 0 || m->shard_k >= m->shard_m ||
        m->total < 0 || m->rows < 0 || m->offset < 0)
        return -1;
    snprintf(m->args, sizeof m->args, "%s", line + np + used);
    return 0;
}

int manifest_same_run(const manifest *a, const manifest *b)
{
    return strcmp(a->version, b->version) == 0 && strcmp(a->command, b->command) == 0 &&
           a->total == b->total && a->offset == b->offset && a->input == b->input &&
           a->grid == b->grid && strcmp(a->args, b->args) == 0;
}

long manifest_shard_rows(long total, int k, int m)
{
    return total > k ? (total - k + m - 1) / m : 0;
}
