/* tests/pool/pool_fail.c: parallel_run (src/base/parallel.c) when a
 * pthread_create in the middle fails: it must join exactly the threads it
 * created, each once, and still run every job once.
 *
 * This program defines its own pthread_create and pthread_join, which the
 * linker prefers to the C library's: "creating" a thread runs it at once in
 * the caller and hands out an id; the second call fails with EAGAIN. The
 * joins are recorded and checked against the ids handed out.
 * Run: build/pool-fail (exit 0 and "pool-fail: ok", else the problems). */
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "base.h"

enum { MAXT = 64 };

static int ncalls;               /* pthread_create calls */
static unsigned long made[MAXT]; /* ids handed out */
static int nmade;
static int joined[MAXT];         /* times made[i] was joined */
static int bad_joins;            /* joins of ids never handed out */

int pthread_create(pthread_t *t, const pthread_attr_t *attr, void *(*fn)(void *), void *arg)
{
    (void)attr;
    if (++ncalls == 2)
        return EAGAIN;
    unsigned long id = 1000 + (unsigned long)nmade;
    made[nmade++] = id;
    memset(t, 0, sizeof *t);
    memcpy(t, &id, sizeof id < sizeof *t ? sizeof id : sizeof *t);
    fn(arg);
    return 0;
}

int pthread_join(pthread_t t, void **ret)
{
    unsigned long id = 0;
    memcpy(&id, &t, sizeof id < sizeof t ? sizeof id : sizeof t);
    if (ret)
        *ret = NULL;
    for (int i = 0; i < nmade; i++)
        if (made[i] == id) {
            joined[i]++;
            return 0;
        }
    bad_joins++;
    return ESRCH;
}

static int runs[100];

static void job(void *ctx, long i)
{
    (void)ctx;
    runs[i]++;
}

int main(void)
{
    int problems = 0;
    parallel_run(100, 4, job, NULL);
    if (nmade != 3) {
        printf("pool-fail: %d threads made of 4 asked (one failing), expected 3\n", nmade);
        problems++;
    }
    for (int i = 0; i < nmade; i++)
        if (joined[i] != 1) {
            printf("pool-fail: thread %d joined %d times, expected once\n", i, joined[i]);
            problems++;
        }
    if (bad_joins) {
        printf("pool-fail: %d joins of threads never created\n", bad_joins);
        problems++;
    }
    for (int i = 0; i < 100; i++)
        if (runs[i] != 1) {
            printf("pool-fail: job %d ran %d times\n", i, runs[i]);
            problems++;
        }
    printf("pool-fail: %s\n", problems ? "FAILED" : "ok");
    return problems != 0;
}
