/* src/cmd_common.c: pieces several commands share: --help, loading a
 * checked file, usage errors, --shard, the default number of workers (the
 * CPU affinity mask), and
 * running independent jobs on worker threads (mech batch, mech sweep). */
#define _GNU_SOURCE  /* sched_getaffinity, CPU_COUNT */
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "commands.h"

int cmd_wants_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

int cmd_load_checked(const char *path, mech_model **m)
{
    return cmd_load_checked_with(path, NULL, 0, m);
}

int cmd_load_checked_with(const char *path, const mech_override *ov, int nov, mech_model **m)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_summary s;
    int rc = mech_load_file_with(path, ov, nov, m, &d);
    if (rc == MECH_OK)
        rc = mech_check(*m, &s, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK)
        return MECH_EXIT_OK;
    mech_model_free(m);
    return rc == MECH_EIO ? MECH_EXIT_IO : MECH_EXIT_INPUT;
}

int cmd_usage_error(const char *command, const char *fmt, const char *arg)
{
    fprintf(stderr, "mech %s: ", command);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (see 'mech %s --help')\n", command);
    return MECH_EXIT_INPUT;
}

int cmd_parse_int(const char *text, int lo, int hi, int *v)
{
    char *end;
    double x = strtod(text, &end);
    /* !(lo <= x <= hi) also refuses NaN: converting it (or anything out of
       int's range) to int is undefined */
    if (end == text || *end != '\0' || !(x >= lo && x <= hi) || x != (double)(int)x)
        return 0;
    *v = (int)x;
    return 1;
}

int cmd_refuse_input(const char *command, const char *out, const char *const *inputs, int n)
{
    struct stat so, si;
    if (!out || strcmp(out, "-") == 0 || stat(out, &so) != 0 || !S_ISREG(so.st_mode))
        return -1;  /* new, or not a file an input can be */
    for (int i = 0; i < n; i++)
        if (inputs[i] && stat(inputs[i], &si) == 0 && si.st_dev == so.st_dev &&
            si.st_ino == so.st_ino) {
            fprintf(stderr, "mech %s: the output %s is the input file %s; not overwriting it\n",
                    command, out, inputs[i]);
            return MECH_EXIT_INPUT;
        }
    return -1;
}

int cmd_make_dir(const char *dir)
{
    char *p = malloc(strlen(dir) + 1);
    if (!p)
        return -1;
    strcpy(p, dir);
    for (char *s = p + 1;; s++) {
        if (*s == '/' || *s == '\0') {
            char c = *s;
            *s = '\0';
            if (mkdir(p, 0777) != 0 && errno != EEXIST) {
                int e = errno;
                free(p);
                errno = e;
                return -1;
            }
            *s = c;
            if (c == '\0')
                break;
        }
    }
    free(p);
    struct stat st;
    if (stat(dir, &st) != 0)
        return -1;
    if (!S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    return 0;
}

int cmd_parse_shard(const char *s, int *k, int *mod)
{
    char *end;
    long a = strtol(s, &end, 10);
    if (end == s || *end != '/')
        return -1;
    const char *p = end + 1;
    long b = strtol(p, &end, 10);
    if (end == p || *end != '\0' || b < 1 || a < 0 || a >= b || b > 1000000)
        return -1;
    *k = (int)a;
    *mod = (int)b;
    return 0;
}

/* The CPUs this process may run on (its affinity mask: taskset, a Slurm
 * allocation, a container's cpuset), not all those online: more workers
 * than that only take turns. */
int cmd_default_jobs(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set) < 1024 ? CPU_COUNT(&set) : 1024;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 && n < 1024 ? (int)n : 1;
}

typedef struct pool {
    int njobs;
    atomic_int next;
    void (*job)(void *ctx, int i);
    void *ctx;
} pool;

static void *worker(void *arg)
{
    pool *p = arg;
    for (int i; (i = atomic_fetch_add(&p->next, 1)) < p->njobs;)
        p->job(p->ctx, i);
    return NULL;
}

void cmd_run_parallel(int njobs, int nthreads, void (*job)(void *ctx, int i), void *ctx)
{
    pool p = {njobs, 0, job, ctx};
    if (nthreads > njobs)
        nthreads = njobs > 0 ? njobs : 1;
    pthread_t *tid = calloc((size_t)nthreads, sizeof *tid);
    int started = 0;  /* tid[0 .. started-1] are the threads created */
    for (int t = 0; tid && t < nthreads; t++)
        if (pthread_create(&tid[started], NULL, worker, &p) == 0)
            started++;
    if (started == 0)
        worker(&p);  /* no threads: do the work here */
    for (int t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
}

/* ---- progress ------------------------------------------------------------- */

static pthread_mutex_t progress_lock = PTHREAD_MUTEX_INITIALIZER;

static double monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cmd_progress_init(cmd_progress *p, const char *command, const char *unit, int quiet)
{
    memset(p, 0, sizeof *p);
    p->command = command;
    p->unit = unit;
    p->quiet = quiet;
    p->tty = isatty(STDERR_FILENO);
    p->interval = p->tty ? 0.1 : 5.0;
    const char *env = getenv("MECH_PROGRESS_SECONDS");
    if (env && *env && !p->tty)
        p->interval = atof(env);
    p->start = p->last = monotonic_seconds();
}

void cmd_progress_update(cmd_progress *p, int done, int total)
{
    if (p->quiet)
        return;
    pthread_mutex_lock(&progress_lock);
    double now = monotonic_seconds();
    if (now - p->last >= p->interval && done < total) {
        p->last = now;
        int pct = total > 0 ? (int)(100.0 * done / total) : 100;
        if (p->tty) {
            int width = 30, fill = total > 0 ? (int)((double)done * width / total) : width;
            fprintf(stderr, "\rmech %s: [%.*s%*s] %3d%% (%d of %d %s)", p->command, fill,
                    "##############################", width - fill, "", pct, done, total, p->unit);
            p->drawn = 1;
        } else {
            fprintf(stderr, "mech %s: %d of %d %s (%d%%), %.0f s\n", p->command, done, total,
                    p->unit, pct, now - p->start);
        }
        fflush(stderr);
    }
    pthread_mutex_unlock(&progress_lock);
}

void cmd_progress_done(cmd_progress *p)
{
    if (!p->quiet && p->drawn)
        fprintf(stderr, "\r\033[K");  /* the bar's line cleared for what follows */
    p->drawn = 0;
}

void cmd_progress_callback(void *ctx, int done, int total)
{
    cmd_progress_update(ctx, done, total);
}
