/* rng.c - xoshiro256** (Blackman & Vigna), state filled by splitmix64 from the seed. */
#include "grainpack/rng.h"

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

void gp_rng_seed(gp_rng *rng, uint64_t seed)
{
    /* splitmix64 never yields four zero words in a row, so the state is never all zero */
    for (int i = 0; i < 4; i++)
        rng->state[i] = splitmix64(&seed);
}

uint64_t gp_rng_next(gp_rng *rng)
{
    uint64_t *s = rng->state;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double gp_rng_uniform(gp_rng *rng)
{
    /* the top 53 bits scaled by 2^-53: exactly representable, uniform on [0, 1) */
    return (double)(gp_rng_next(rng) >> 11) * 0x1.0p-53;
}
