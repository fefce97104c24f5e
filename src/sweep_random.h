/* src/sweep_random.h: the samples of `mech sweep --random N` (sweep_random.c). */
#ifndef MECH_SWEEP_RANDOM_H
#define MECH_SWEEP_RANDOM_H

#include <stdint.h>

/* A number uniform in [-1, 1] for (seed, variant index, parameter k): a
 * function of the three alone (counter-based), so a variant's sample does
 * not depend on the order, the threads or the shard that draws it. */
double sweep_random_unit(uint64_t seed, long index, int k);

#endif
