/* test_rng.c - the seeded generator: reproducible, seed-sensitive, uniform on [0, 1). */
#include "check.h"
#include "grainpack/rng.h"

static void test_same_seed_gives_the_same_sequence(void)
{
    gp_rng a, b;
    gp_rng_seed(&a, 42);
    gp_rng_seed(&b, 42);
    int same = 1;
    for (int i = 0; i < 1000; i++)
        same &= gp_rng_next(&a) == gp_rng_next(&b);
    CHECK(same);
}

static void test_neighbouring_seeds_give_unrelated_sequences(void)
{
    gp_rng a, b;
    gp_rng_seed(&a, 0);
    gp_rng_seed(&b, 1);
    int equal = 0;
    for (int i = 0; i < 1000; i++)
        equal += gp_rng_next(&a) == gp_rng_next(&b);
    CHECK(equal == 0);
}

static void test_uniform_is_in_unit_interval_with_the_right_moments(void)
{
    gp_rng rng;
    gp_rng_seed(&rng, 7);
    enum { N = 1000000 };
    double sum = 0.0, sum2 = 0.0, lo = 1.0, hi = 0.0;
    for (int i = 0; i < N; i++) {
        double u = gp_rng_uniform(&rng);
        sum += u;
        sum2 += u * u;
        lo = u < lo ? u : lo;
        hi = u > hi ? u : hi;
    }
    CHECK(lo >= 0.0 && hi < 1.0);
    /* mean 1/2 with standard error sqrt(1/12 / N) = 2.9e-4; variance 1/12 */
    CHECK_NEAR(sum / N, 0.5, 5 * 2.9e-4);
    CHECK_NEAR(sum2 / N - (sum / N) * (sum / N), 1.0 / 12.0, 1e-3);
}

int main(void)
{
    RUN(test_same_seed_gives_the_same_sequence);
    RUN(test_neighbouring_seeds_give_unrelated_sequences);
    RUN(test_uniform_is_in_unit_interval_with_the_right_moments);
    return check_status();
}
