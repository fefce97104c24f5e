/* src/base/parallel.c: independent jobs on worker threads (mech sweep's variants
 * through mech_sweep_run, mech batch's files), the default number of
 * workers (the CPUs of this process's affinity mask), and the one clock the
 * library and the command line time things with. */
#define _GNU_SOURCE  /* sched_getaffinity, CPU_COUNT */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "base.h"

double clock_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The CPUs this process may run on (its affinity mask: taskset, a Slurm
 * allocation, a container's cpuset), not all those online: more workers
 * than that only take turns. */
int parallel_default_jobs(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set) < 1024 ? CPU_COUNT(&set) : 1024;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 && n < 1024 ? (int)n : 1;
}

typedef struct pool {
    long njobs;
    atomic_long next;
    void (*job)(void *ctx, long i);
    void *ctx;
} pool;

static void *worker(void *arg)
{
    pool *p = arg;
    for (long i; (i = atomic_fetch_add(&p->next, 1)) < p->njobs;)
        p->job(p->ctx, i);
    return NULL;
}

void parallel_run(long njobs, int nthreads, void (*job)(void *ctx, long i), void *ctx)
{
    pool p = {njobs, 0, job, ctx};
    if (nthreads > njobs)
        nthreads = njobs > 0 ? (int)njobs : 1;
    if (nthreads < 1)
        nthreads = 1;
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
