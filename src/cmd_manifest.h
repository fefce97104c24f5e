/* src/cmd_manifest.h: the manifest line of a sharded run's output (mech
 * sweep --shard CSVs, mech batch --shard summaries), which mech merge reads
 * to prove that the shards it joins are the pieces of one run
 * (docs/batch.md, section "Manifests and mech merge"). */
#ifndef MECH_CMD_MANIFEST_H
#define MECH_CMD_MANIFEST_H

#include <stdint.h>
#include <stdio.h>

/* The line, one per file, the first line:
 *   # mech-manifest version=V command=C shard=K/M rows=R total=T offset=O
 *     input=H grid=H args=A...
 * (on one line). rows: the data rows this shard must hold; total: the
 * indices of the run, offset .. offset+total-1; input, grid: FNV-1a 64-bit
 * hashes (16 hex digits) of the input files and of the grid; args: the
 * arguments that decide the results (not -o, -j, -q, --shard, ...),
 * escaped, to the end of the line. */
typedef struct manifest {
    char version[32];
    char command[16];
    int shard_k, shard_m;
    long rows, total, offset;
    uint64_t input, grid;
    char args[4096];
} manifest;

#define MANIFEST_PREFIX "# mech-manifest "

/* FNV-1a 64 of n bytes, continuing from h (start with MANIFEST_HASH0). */
#define MANIFEST_HASH0 UINT64_C(0xcbf29ce484222325)
uint64_t manifest_hash(uint64_t h, const void *data, size_t n);
/* The hash of a file's bytes continued from h; 0 with *h set, -1 (errno)
 * when it cannot be read. */
int manifest_hash_file(uint64_t *h, const char *path);
/* Appends arg to m->args (a space before all but the first), with a
 * backslash before a space or a backslash and \xNN for a control byte, so
 * the line stays one line and the arguments can be told apart. */
void manifest_add_arg(manifest *m, const char *arg);
/* Writes m as its line (with the newline). */
void manifest_write(const manifest *m, FILE *f);
/* Reads the line (without its newline) into m: 0, or -1 when it is not a
 * manifest line. */
int manifest_parse(const char *line, manifest *m);
/* 1 when a and b are shards of the same run (all but shard and rows agree). */
int manifest_same_run(const manifest *a, const manifest *b);
/* The rows shard K/M of a run of total indices holds (i % M == K). */
long manifest_shard_rows(long total, int k, int m);

#endif
