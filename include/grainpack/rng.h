/* rng.h - seeded pseudo-random numbers (xoshiro256**, seeded through splitmix64).
 * A generator is a plain value: every job owns its own, so stages are reentrant and a
 * job's seed reproduces its output bit for bit. */
#ifndef GRAINPACK_RNG_H
#define GRAINPACK_RNG_H

#include <stdint.h>

#include "grainpack/api.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gp_rng {
    uint64_t state[4];
} gp_rng;

/* Initialises rng from a 64-bit seed; every seed (0 included) gives a valid state. */
GP_API void gp_rng_seed(gp_rng *rng, uint64_t seed);

/* The next 64 random bits. */
GP_API uint64_t gp_rng_next(gp_rng *rng);

/* A double uniform in [0, 1), with 53 random bits. */
GP_API double gp_rng_uniform(gp_rng *rng);

#ifdef __cplusplus
}
#endif
#endif
