/* src/cli/cmd_manifest.c: the manifest line of a sharded output (hashes,
 * escaped arguments, writing and reading it back); the format is in
 * src/cli/cli.h and docs/batch.md. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
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
            "offset=%ld input=%016" PRIx64 " grid=%016" PRIx64 " tol=%s args=%s\n", m->version,
            m->command, m->shard_k, m->shard_m, m->rows, m->total, m->offset, m->input,
            m->grid, m->tol[0] ? m->tol : "-", m->args);
}

int manifest_parse(const char *line, manifest *m)
{
    memset(m, 0, sizeof *m);
    size_t np = strlen(MANIFEST_PREFIX);
    if (strncmp(line, MANIFEST_PREFIX, np) != 0)
        return -1;
    int used = 0;
    int n = sscanf(line + np, "version=%31s command=%15s shard=%d/%d rows=%ld total=%ld "
                   "offset=%ld input=%" SCNx64 " grid=%" SCNx64 " tol=%2047s args=%n",
                   m->version, m->command, &m->shard_k, &m->shard_m, &m->rows, &m->total,
                   &m->offset, &m->input, &m->grid, m->tol, &used);
    if (n != 10 || used == 0 || m->shard_m < 1 || m->shard_k < 0 || m->shard_k >= m->shard_m ||
        m->total < 0 || m->rows < 0 || m->offset < 0 || m->total > MANIFEST_MAX_TOTAL ||
        m->offset > MANIFEST_MAX_TOTAL)
        return -1;
    if (strcmp(m->tol, "-") == 0)
        m->tol[0] = '\0';
    snprintf(m->args, sizeof m->args, "%s", line + np + used);
    return 0;
}

int manifest_same_run(const manifest *a, const manifest *b)
{
    return strcmp(a->version, b->version) == 0 && strcmp(a->command, b->command) == 0 &&
           a->total == b->total && a->offset == b->offset && a->input == b->input &&
           a->grid == b->grid && strcmp(a->tol, b->tol) == 0 && strcmp(a->args, b->args) == 0;
}

long manifest_shard_rows(long total, int k, int m)
{
    return total > k ? (total - k + m - 1) / m : 0;
}

int manifest_args_split(const char *args, char ***argv, int *argc)
{
    size_t len = strlen(args), words = 1;
    for (const char *p = args; *p; p++)
        words += *p == ' ';
    char **v = malloc((words + 1) * sizeof *v + len + 1);
    if (!v)
        return -1;
    char *out = (char *)(v + words + 1);
    int n = 0;
    for (const char *p = args; *p;) {
        v[n++] = out;
        for (; *p && *p != ' '; p++) {
            char c = *p;
            if (c == '\\' && p[1] == 'x' && p[2] && p[3]) {
                char hex[3] = {p[2], p[3], 0};
                c = (char)strtol(hex, NULL, 16);
                p += 3;
            } else if (c == '\\' && p[1]) {
                c = *++p;
            }
            *out++ = c;
        }
        *out++ = '\0';
        if (*p == ' ')
            p++;
    }
    v[n] = NULL;
    *argv = v;
    *argc = n;
    return 0;
}

void digest_init(line_digest *d)
{
    d->h = MANIFEST_HASH0;
    d->lines = 0;
}

void digest_line(line_digest *d, const char *line, size_t len)
{
    d->h = manifest_hash(d->h, line, len);
    d->h = manifest_hash(d->h, "\n", 1);
    d->lines++;
}

int digest_format(char *buf, size_t size, const char *prefix, long rows, uint64_t h)
{
    return snprintf(buf, size, "%srows=%ld fnv1a64=%016" PRIx64 "\n", prefix, rows, h);
}

int digest_parse(const char *line, const char *prefix, long *rows, uint64_t *h)
{
    size_t np = strlen(prefix);
    int used = 0;
    if (strncmp(line, prefix, np) != 0 ||
        sscanf(line + np, "rows=%ld fnv1a64=%" SCNx64 "%n", rows, h, &used) != 2 ||
        line[np + (size_t)used] != '\0' || *rows < 0)
        return -1;
    return 0;
}

int cmd_write_table(const mech_table *t, const char *out, const char *command,
                    const char *input, mech_diag *d)
{
    if (!out || !output_is_h5_name(out))
        return mech_table_write_csv(t, out ? out : "-", d);
    uint64_t h = 0;
    char digest[24] = "-";
    if (input && manifest_hash_file(&h, input) == 0)
        snprintf(digest, sizeof digest, "%016llx", (unsigned long long)h);
    const char *keys[] = {"mech_version", "command", "input", "input_digest"};
    const char *values[] = {mech_version(), command, input ? input : "-", digest};
    return output_write_h5(t, out, keys, values, 4, d);
}
