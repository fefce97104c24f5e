/* tests/pool/affinity.c: the default number of workers of mech batch and
 * mech sweep (parallel_default_jobs, src/base/parallel.c) is the number of CPUs in
 * the process's affinity mask, as taskset and Slurm set it: checked by
 * restricting this process to one CPU, then to two when the machine has
 * them. Run: build/affinity (exit 0 and "affinity: ok"). */
#define _GNU_SOURCE
#include <sched.h>
#include <stdio.h>

#include "base.h"

static int failures;

static void expect(const char *what, int got, int want)
{
    if (got != want) {
        printf("affinity: %s: parallel_default_jobs() = %d, expected %d\n", what, got, want);
        failures++;
    }
}

int main(void)
{
    cpu_set_t all, one;
    if (sched_getaffinity(0, sizeof all, &all) != 0)
        return printf("affinity: sched_getaffinity failed\n"), 1;
    expect("the mask we started with", parallel_default_jobs(), CPU_COUNT(&all));
    int first = -1, second = -1;
    for (int c = 0; c < CPU_SETSIZE && second < 0; c++)
        if (CPU_ISSET(c, &all)) {
            if (first < 0)
                first = c;
            else
                second = c;
        }
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    if (sched_setaffinity(0, sizeof one, &one) != 0)
        return printf("affinity: sched_setaffinity failed\n"), 1;
    expect("one CPU (taskset -c N)", parallel_default_jobs(), 1);
    if (second >= 0) {
        CPU_SET(second, &one);
        if (sched_setaffinity(0, sizeof one, &one) != 0)
            return printf("affinity: sched_setaffinity failed\n"), 1;
        expect("two CPUs", parallel_default_jobs(), 2);
    }
    if (!failures)
        printf("affinity: ok\n");
    return failures != 0;
}
