/* src/cmd_common.c: pieces several commands share: --help, loading a
 * checked file, usage errors, --shard, the default number of workers, and
 * running independent jobs on worker threads (mech batch, mech sweep). */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

int cmd_default_jobs(void)
{
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
    int started = 0;
    for (int t = 0; tid && t < nthreads; t++)
        started += pthread_create(&tid[t], NULL, worker, &p) == 0;
    if (started == 0)
        worker(&p);  /* no threads: do the work here */
    for (int t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
}
