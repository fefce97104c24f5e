/* src/base/util.c: checked allocation and string helpers. */
#define _DEFAULT_SOURCE 1 /* madvise, MADV_HUGEPAGE */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "base.h"

_Thread_local long xalloc_fail_countdown;

/* 1 when the test hook says this allocation fails. */
static int fail_now(void)
{
    return xalloc_fail_countdown > 0 && --xalloc_fail_countdown == 0;
}

void *xcalloc(size_t n, size_t size)
{
    if (fail_now())
        return NULL;
    if (n == 0 || size == 0)
        n = size = 1;
    return calloc(n, size);
}

/* A result table of 10^6 rows is some 300 MB, first touched row by row as
 * the sweep fills it: with 4 KiB pages that is 80 000 page faults (about
 * 0.7 s of system time, more than writing the CSV costs) and as many TLB
 * misses. Such a block is aligned to 2 MiB and offered to the kernel's
 * transparent huge pages (Linux; where it has no such advice, or declines
 * it, the block is an ordinary one). */
void *xcalloc_large(size_t n, size_t size)
{
    const size_t huge = (size_t)2 << 20;
    if (size && n > SIZE_MAX / size)
        return NULL;  /* as calloc, without a sanitizer's report of the overflow */
    if (n == 0 || size == 0 || n * size < 4 * huge)
        return xcalloc(n, size);
    if (fail_now() || n * size > SIZE_MAX - huge)
        return NULL;
    size_t bytes = (n * size + huge - 1) / huge * huge;
    void *p = NULL;
    if (posix_memalign(&p, huge, bytes) != 0)
        return NULL;
#ifdef MADV_HUGEPAGE
    (void)madvise(p, bytes, MADV_HUGEPAGE); /* advice only: a refusal changes nothing */
#endif
    memset(p, 0, bytes);
    return p;
}

void *xrealloc_array(void *p, size_t n, size_t size)
{
    if (fail_now() || (size && n > SIZE_MAX / size))
        return NULL;
    size_t bytes = n * size;
    return realloc(p, bytes ? bytes : 1);
}

int xcalloc_doubles(double **const *arrays, const size_t *sizes, size_t size, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!(*arrays[i] = xcalloc(sizes ? sizes[i] : size, sizeof(double))))
            return -1;
    return 0;
}

void free_all(void *const *blocks, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(blocks[i]);
}

char *xstrdup(const char *s)
{
    if (fail_now())
        return NULL;
    size_t n = strlen(s) + 1;
    char *c = malloc(n);
    if (c)
        memcpy(c, s, n);
    return c;
}

int edit_distance(const char *a, const char *b)
{
    enum { CAP = 64 };
    size_t la = strlen(a), lb = strlen(b);
    if (la >= CAP || lb >= CAP)
        return 99;
    int row[CAP + 1];
    for (size_t j = 0; j <= lb; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int up = row[j];
            int cost = a[i - 1] == b[j - 1] ? 0 : 1;
            int best = diag + cost;
            if (up + 1 < best)
                best = up + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb] > 99 ? 99 : row[lb];
}

const char *nearest_name(const char *word, const char *const *names, size_t n)
{
    const char *best = NULL;
    int best_d = 99;
    for (size_t i = 0; i < n; i++) {
        if (!names[i])  /* a name whose copy failed (out of memory, already reported) */
            continue;
        int dist = edit_distance(word, names[i]);
        if (dist < best_d) {
            best_d = dist;
            best = names[i];
        }
    }
    /* a typo: at most a third of the word wrong, and at least one letter right
     * (so a one-letter name is never "corrected" to another one-letter name) */
    size_t len = strlen(word);
    int allowed = len <= 3 ? 1 : (int)(len / 3) + 1;
    if (!best || best_d > allowed || (size_t)best_d >= len || (size_t)best_d >= strlen(best))
        return NULL;
    return best;
}

static size_t hash_string(const char *s)
{
    size_t h = 1469598103934665603u;  /* FNV-1a */
    while (*s)
        h = (h ^ (unsigned char)*s++) * 1099511628211u;
    return h;
}

int name_map_get(const name_map *nm, const char *key)
{
    if (nm->cap == 0)
        return -1;
    for (size_t i = hash_string(key) & (nm->cap - 1);; i = (i + 1) & (nm->cap - 1)) {
        if (!nm->keys[i])
            return -1;
        if (strcmp(nm->keys[i], key) == 0)
            return nm->values[i];
    }
}

static int name_map_grow(name_map *nm)
{
    name_map bigger = {0};
    bigger.cap = nm->cap ? 2 * nm->cap : 64;
    bigger.keys = xcalloc(bigger.cap, sizeof *bigger.keys);
    bigger.values = xcalloc(bigger.cap, sizeof *bigger.values);
    if (!bigger.keys || !bigger.values) {
        name_map_free(&bigger);
        return -1;
    }
    for (size_t i = 0; i < nm->cap; i++)
        if (nm->keys[i])
            name_map_put(&bigger, nm->keys[i], nm->values[i]);
    name_map_free(nm);
    *nm = bigger;
    return 0;
}

int name_map_put(name_map *nm, const char *key, int value)
{
    if (2 * (nm->count + 1) > nm->cap && name_map_grow(nm) < 0)
        return -1;
    size_t i = hash_string(key) & (nm->cap - 1);
    while (nm->keys[i] && strcmp(nm->keys[i], key) != 0)
        i = (i + 1) & (nm->cap - 1);
    if (!nm->keys[i])
        nm->count++;
    nm->keys[i] = key;
    nm->values[i] = value;
    return 0;
}

void name_map_free(name_map *nm)
{
    free(nm->keys);
    free(nm->values);
    memset(nm, 0, sizeof *nm);
}

int permutation_parity(const int *perm, int n, unsigned char *seen)
{
    int odd = 0;
    memset(seen, 0, (size_t)n);
    for (int i = 0; i < n; i++) {
        int len = 0;
        for (int k = i; !seen[k]; k = perm[k], len++)
            seen[k] = 1;
        if (len > 0)
            odd ^= (len - 1) & 1;  /* a cycle of length L is L - 1 swaps */
    }
    return odd;
}
