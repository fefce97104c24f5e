/* src/study/sweep_random.c: the samples of `mech sweep --random N`. Variant i's
 * parameter k is nominal + tol * u with u uniform in [-1, 1] (docs/batch.md,
 * "Random variants within the tolerances"): u is made from a 64-bit hash of
 * (seed, i, k) with the SplitMix64 finaliser (Steele, Lea and Flood 2014),
 * its top 53 bits a double in [0, 1), mapped to the cell centres in
 * (-1, 1) so that the distribution is symmetric about 0. */
#include "study.h"

static uint64_t mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double sweep_random_unit(uint64_t seed, long index, int k)
{
    const uint64_t golden = 0x9e3779b97f4a7c15ULL;
    uint64_t z = mix(seed + golden);
    z = mix(z + golden * ((uint64_t)index + 1));
    z = mix(z + golden * ((uint64_t)k + 1));
    double u = ((double)(z >> 11) + 0.5) / 9007199254740992.0;  /* (0, 1), 2^-53 cells */
    return 2.0 * u - 1.0;
}
