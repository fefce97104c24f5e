/* src/cli/jit_cache.c: the compiled solvers of `mech solve --jit` kept
 * between runs (docs/codegen.md, "The cache of compiled solvers").
 *
 * An entry is two files named by the FNV-1a 64 of its key: HASH.so, the
 * shared object, and HASH.key, whose first line records the object's size
 * and digest ("mech-jit-cache 1 bytes=N fnv1a64=H") and whose rest is the
 * whole key: mech's version, the compiler's identity and command line, and
 * the generated source. A hit needs the key equal byte for byte (a
 * collision of the hash cannot serve another mechanism's code) and the
 * object's size and digest as recorded (a truncated or altered object is
 * not loaded). The directory is the user's own (mode 0700, not a symbolic
 * link, owned by the user); a file in it that is not a regular file owned
 * by the user, or that others may write, is not used. Entries are written
 * under temporary names and renamed, the key last, so a killed run leaves
 * no entry half made; when the directory holds more than its bound, the
 * entries used longest ago go. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"

#define CACHE_MAGIC "mech-jit-cache 1"
enum { CACHE_DEFAULT_MAX_MB = 256, CACHE_STALE_TMP_SECONDS = 3600 };

/* ---- the directory ------------------------------------------------------ */

/* mkdir -p of path, each new component 0700. */
static int make_dirs(char *path)
{
    for (char *p = path + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        int rc = mkdir(path, 0700);
        *p = '/';
        if (rc != 0 && errno != EEXIST)
            return -1;
    }
    return mkdir(path, 0700) != 0 && errno != EEXIST ? -1 : 0;
}

/* A file or directory we may trust: ours, not writable by others. */
static int owned_and_private(const struct stat *s)
{
    return s->st_uid == geteuid() && (s->st_mode & (S_IWGRP | S_IWOTH)) == 0;
}

void jit_cache_open(jit_cache *c)
{
    memset(c, 0, sizeof *c);
    c->fd = -1;
    const char *off = getenv("MECH_JIT_CACHE");
    if (off && strcmp(off, "off") == 0) {
        snprintf(c->why, sizeof c->why, "MECH_JIT_CACHE=off");
        return;
    }
    const char *dir = getenv("MECH_CACHE_DIR"), *xdg = getenv("XDG_CACHE_HOME"),
               *home = getenv("HOME");
    int n = dir && *dir   ? snprintf(c->dir, sizeof c->dir, "%s/jit", dir)
            : xdg && *xdg ? snprintf(c->dir, sizeof c->dir, "%s/mech/jit", xdg)
            : home && *home ? snprintf(c->dir, sizeof c->dir, "%s/.cache/mech/jit", home)
                            : -1;
    if (n < 0 || (size_t)n >= sizeof c->dir - 40 || c->dir[0] != '/') {
        snprintf(c->why, sizeof c->why, "no cache directory (set HOME or MECH_CACHE_DIR to an "
                 "absolute path)");
        return;
    }
    struct stat s;
    char buf[128];
    if (make_dirs(c->dir) != 0 || lstat(c->dir, &s) != 0) {
        snprintf(c->why, sizeof c->why, "cannot make %s: %s", c->dir,
                 diag_strerror(errno, buf, sizeof buf));
        return;
    }
    if (!S_ISDIR(s.st_mode) || s.st_uid != geteuid() || (s.st_mode & 077) != 0) {
        snprintf(c->why, sizeof c->why, "%s is not a directory of this user's alone (mode 0700)",
                 c->dir);
        return;
    }
    c->fd = open(c->dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (c->fd < 0) {
        snprintf(c->why, sizeof c->why, "cannot open %s: %s", c->dir,
                 diag_strerror(errno, buf, sizeof buf));
        return;
    }
    const char *max = getenv("MECH_JIT_CACHE_MB");
    char *end = NULL;
    double mb = max && *max ? strtod(max, &end) : CACHE_DEFAULT_MAX_MB;
    if (max && *max && (*end || !(mb >= 0.0 && mb <= 1e6)))
        mb = CACHE_DEFAULT_MAX_MB;  /* not a size: the default */
    c->max_bytes = (long long)(mb * 1048576.0);
    c->usable = 1;
}

void jit_cache_close(jit_cache *c)
{
    if (c->fd >= 0)
        close(c->fd);
    c->fd = -1;
    c->usable = 0;
}

/* The cache directory opened for listing (its own descriptor, so its
 * offset is not c->fd's), or NULL. */
static DIR *open_listing(const jit_cache *c)
{
    int fd = openat(c->fd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    DIR *dir = fd >= 0 ? fdopendir(fd) : NULL;
    if (!dir && fd >= 0)
        close(fd);
    return dir;
}

/* 1 with *h when name is an entry's key file, HASH.key (16 hex digits). */
static int key_file(const char *name, uint64_t *h)
{
    unsigned long long v;
    char tail[8];
    if (strlen(name) != 20 || sscanf(name, "%16llx.%3s", &v, tail) != 2 ||
        strcmp(tail, "key") != 0)
        return 0;
    *h = (uint64_t)v;
    return 1;
}

int jit_cache_empty(const jit_cache *c)
{
    DIR *dir = c->usable ? open_listing(c) : NULL;
    if (!dir)
        return 1;
    int empty = 1;
    uint64_t h;
    for (struct dirent *e; empty && (e = readdir(dir));)
        empty = !key_file(e->d_name, &h);
    closedir(dir);
    return empty;
}

/* ---- entries ------------------------------------------------------------ */

static void entry_name(char *buf, size_t size, uint64_t h, const char *ext)
{
    snprintf(buf, size, "%016llx.%s", (unsigned long long)h, ext);
}

/* The whole of a regular file of ours in the cache, or NULL. */
static char *read_entry(const jit_cache *c, const char *name, size_t *n)
{
    int fd = openat(c->fd, name, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    struct stat s;
    char *data = NULL;
    if (fd < 0)
        return NULL;
    if (fstat(fd, &s) == 0 && S_ISREG(s.st_mode) && owned_and_private(&s) &&
            s.st_size < (1LL << 31) && (data = malloc((size_t)s.st_size + 1)) != NULL) {
        size_t got = 0;
        ssize_t r = 1;
        while (got < (size_t)s.st_size && (r = read(fd, data + got, (size_t)s.st_size - got)) > 0)
            got += (size_t)r;
        if (got != (size_t)s.st_size) {
            free(data);
            data = NULL;
        } else {
            data[got] = '\0';
            *n = got;
        }
    }
    close(fd);
    return data;
}

int jit_cache_find(const jit_cache *c, const char *key, size_t klen, char *so_path, size_t size)
{
    if (!c->usable)
        return 0;
    uint64_t h = manifest_hash(MANIFEST_HASH0, key, klen);
    char kname[40], sname[40];
    entry_name(kname, sizeof kname, h, "key");
    entry_name(sname, sizeof sname, h, "so");
    size_t n = 0, sn = 0;
    char *k = read_entry(c, kname, &n);
    const char *nl = k ? memchr(k, '\n', n) : NULL;
    unsigned long long bytes = 0, digest = 0;
    int hit = nl && sscanf(k, CACHE_MAGIC " bytes=%llu fnv1a64=%llx", &bytes, &digest) == 2 &&
              n - (size_t)(nl + 1 - k) == klen && memcmp(nl + 1, key, klen) == 0;
    free(k);
    char *so = hit ? read_entry(c, sname, &sn) : NULL;
    hit = so && sn == bytes && manifest_hash(MANIFEST_HASH0, so, sn) == digest;
    free(so);
    if (hit) {
        futimens(c->fd, NULL);
        utimensat(c->fd, kname, NULL, AT_SYMLINK_NOFOLLOW);  /* its last use, for trimming */
        hit = snprintf(so_path, size, "%s/%s", c->dir, sname) < (int)size;
    }
    return hit;
}

/* data written to a new temporary file of the cache renamed to name. */
static int write_entry(const jit_cache *c, const char *name, const char *head, size_t hn,
                       const char *data, size_t n)
{
    char tmp[64];
    snprintf(tmp, sizeof tmp, ".tmp-%ld-%s", (long)getpid(), name);
    int fd = openat(c->fd, tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0)
        return -1;
    int ok = 1;
    for (int part = 0; part < 2 && ok; part++) {
        const char *p = part ? data : head;
        size_t left = part ? n : hn;
        while (left > 0 && ok) {
            ssize_t w = write(fd, p, left);
            ok = w > 0;
            p += ok ? w : 0;
            left -= ok ? (size_t)w : 0;
        }
    }
    ok = ok && fsync(fd) == 0;
    ok = close(fd) == 0 && ok;
    ok = ok && renameat(c->fd, tmp, c->fd, name) == 0;
    if (!ok)
        unlinkat(c->fd, tmp, 0);
    return ok ? 0 : -1;
}

typedef struct cache_entry {
    uint64_t hash;
    long long bytes;
    struct timespec used;
} cache_entry;

static int older_first(const void *a, const void *b)
{
    const struct timespec *x = &((const cache_entry *)a)->used, *y = &((const cache_entry *)b)->used;
    return x->tv_sec != y->tv_sec ? (x->tv_sec < y->tv_sec ? -1 : 1)
           : x->tv_nsec != y->tv_nsec ? (x->tv_nsec < y->tv_nsec ? -1 : 1) : 0;
}

static void remove_entry(const jit_cache *c, uint64_t h)
{
    char name[40];
    entry_name(name, sizeof name, h, "key");  /* the key first: no entry without its object */
    unlinkat(c->fd, name, 0);
    entry_name(name, sizeof name, h, "so");
    unlinkat(c->fd, name, 0);
}

/* The entries used longest ago removed until the cache holds at most its
 * bound (the newest entry stays), and temporary files of killed runs. */
static void trim(const jit_cache *c, uint64_t keep)
{
    DIR *dir = open_listing(c);
    if (!dir)
        return;
    cache_entry *e = NULL;
    size_t n = 0, cap = 0;
    long long total = 0;
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    for (struct dirent *d; (d = readdir(dir)) != NULL;) {
        struct stat s, so;
        uint64_t h;
        char sname[40];
        if (fstatat(c->fd, d->d_name, &s, AT_SYMLINK_NOFOLLOW) != 0)
            continue;
        if (strncmp(d->d_name, ".tmp-", 5) == 0) {
            if (now.tv_sec - s.st_mtim.tv_sec > CACHE_STALE_TMP_SECONDS)
                unlinkat(c->fd, d->d_name, 0);
            continue;
        }
        if (!key_file(d->d_name, &h))
            continue;
        entry_name(sname, sizeof sname, h, "so");
        long long bytes = s.st_size + (fstatat(c->fd, sname, &so, AT_SYMLINK_NOFOLLOW) == 0
                                       ? so.st_size : 0);
        if (n == cap) {
            cap = cap ? 2 * cap : 64;
            cache_entry *m = realloc(e, cap * sizeof *e);
            if (!m)
                break;
            e = m;
        }
        e[n++] = (cache_entry){h, bytes, s.st_mtim};
        total += bytes;
    }
    closedir(dir);
    if (e)
        qsort(e, n, sizeof *e, older_first);
    for (size_t i = 0; i < n && total > c->max_bytes; i++)
        if (e[i].hash != keep) {
            remove_entry(c, e[i].hash);
            total -= e[i].bytes;
        }
    free(e);
}

int jit_cache_put(const jit_cache *c, const char *key, size_t klen, const char *so_path)
{
    if (!c->usable || c->max_bytes == 0)
        return -1;
    FILE *f = fopen(so_path, "rb");
    char *so = NULL;
    size_t sn = 0, cap = 0;
    for (size_t r = 1; f && r > 0;) {
        if (sn == cap) {
            char *m = realloc(so, cap = cap ? 2 * cap : 1 << 16);
            if (!m)
                break;
            so = m;
        }
        r = fread(so + sn, 1, cap - sn, f);
        sn += r;
    }
    int ok = f && !ferror(f) && sn > 0;
    if (f)
        fclose(f);
    uint64_t h = manifest_hash(MANIFEST_HASH0, key, klen);
    char head[96], kname[40], sname[40];
    int hn = snprintf(head, sizeof head, CACHE_MAGIC " bytes=%zu fnv1a64=%016llx\n", sn,
                      (unsigned long long)manifest_hash(MANIFEST_HASH0, so ? so : "", sn));
    entry_name(kname, sizeof kname, h, "key");
    entry_name(sname, sizeof sname, h, "so");
    ok = ok && write_entry(c, sname, NULL, 0, so, sn) == 0 &&
         write_entry(c, kname, head, (size_t)hn, key, klen) == 0;
    free(so);
    if (ok)
        trim(c, h);
    return ok ? 0 : -1;
}
