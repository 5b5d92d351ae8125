/* test_distribution.c - radius laws: the sampler honours each law (chi-square tests at a
 * stated significance), draws only from the support, and reports the right bins. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/distribution.h"
#include "grainpack/stats.h"

/* A sampler is rejected when its chi-square statistic has an upper-tail probability below
 * this. With fixed seeds the tests are deterministic; the level says how unlucky a correct
 * sampler would have to be to fail. */
#define SIGNIFICANCE 0.001

/* The report's Table 1 histogram (docs/method.md §2). */
static const double table1_p[10] = {0.15, 0.2, 0.1, 0.05, 0.13, 0.09, 0.08, 0.07, 0.05, 0.08};

static gp_distribution table1(void)
{
    gp_distribution d = {.kind = GP_DIST_HISTOGRAM, .nbins = 10};
    d.bins = malloc(10 * sizeof *d.bins);
    for (int i = 0; i < 10; i++)
        d.bins[i] = (gp_bin){1.0 + 0.1 * i, 1.1 + 0.1 * i, table1_p[i]};
    gp_distribution_prepare(&d);
    return d;
}

/* Pearson's statistic of `n` draws of `dist` against its report bins; *p gets the tail
 * probability. Fails the test on any draw outside every bin. */
static double chi_square(const gp_distribution *dist, size_t n, uint64_t seed, double *p,
                         double *freq_out)
{
    gp_bin bins[64];
    size_t nb = gp_distribution_report_bins(dist, bins, 64);
    size_t counts[64] = {0}, outside = 0;
    gp_rng rng;
    gp_rng_seed(&rng, seed);
    for (size_t i = 0; i < n; i++) {
        double r = gp_distribution_sample(dist, &rng);
        size_t b = 0;
        while (b < nb && !(r >= bins[b].min && (r < bins[b].max || (b + 1 == nb && r <= bins[b].max))))
            b++;
        if (b == nb)
            outside++;
        else
            counts[b]++;
    }
    CHECK_MSG(outside == 0, "%zu draws outside the bins", outside);
    double chi2 = 0.0;
    int used = 0;
    for (size_t b = 0; b < nb; b++) {
        if (freq_out)
            freq_out[b] = (double)counts[b] / (double)n;
        if (bins[b].p <= 0.0) {
            CHECK_MSG(counts[b] == 0, "bin %zu has probability 0 but %zu draws", b, counts[b]);
            continue;
        }
        double e = bins[b].p * (double)n;
        chi2 += ((double)counts[b] - e) * ((double)counts[b] - e) / e;
        used++;
    }
    *p = gp_chi2_upper_tail(chi2, used - 1);
    return chi2;
}

static void test_table1_histogram_passes_chi_square_on_1e5_draws(void)
{
    gp_distribution d = table1();
    for (uint64_t seed = 1; seed <= 5; seed++) {
        double p, chi2 = chi_square(&d, 100000, seed, &p, NULL);
        CHECK_MSG(p >= SIGNIFICANCE, "seed %llu: chi2 = %.2f on 9 dof, p = %.2g",
                  (unsigned long long)seed, chi2, p);
    }
    gp_distribution_free(&d);
}

static void test_table1_with_1000_draws_is_as_close_as_the_report(void)
{
    /* the report's own check: 1000 draws, per-bin frequencies within a few 1e-2 */
    gp_distribution d = table1();
    double freq[10], p;
    chi_square(&d, 1000, 2026, &p, freq);
    for (int i = 0; i < 10; i++) {
        double se = sqrt(table1_p[i] * (1 - table1_p[i]) / 1000.0);
        CHECK_MSG(fabs(freq[i] - table1_p[i]) <= 4 * se, "bin %d: %.4f vs %.2f", i, freq[i], table1_p[i]);
    }
    CHECK(p >= SIGNIFICANCE);
    gp_distribution_free(&d);
}

static void test_biased_sampler_would_be_caught(void)
{
    /* the test has teeth: draws from a histogram whose first two probabilities are
     * swapped by 0.01 must fail against the true law at 1e5 draws */
    gp_distribution truth = table1(), skewed = table1();
    skewed.bins[0].p = 0.16;
    skewed.bins[1].p = 0.19;
    gp_distribution_prepare(&skewed);
    gp_bin bins[10];
    gp_distribution_report_bins(&truth, bins, 10);
    size_t counts[10] = {0};
    gp_rng rng;
    gp_rng_seed(&rng, 3);
    for (int i = 0; i < 100000; i++) {
        double r = gp_distribution_sample(&skewed, &rng);
        for (int b = 0; b < 10; b++)
            if (r >= bins[b].min && r < bins[b].max + (b == 9 ? 1e-12 : 0))
                counts[b]++;
    }
    double chi2 = 0.0;
    for (int b = 0; b < 10; b++) {
        double e = bins[b].p * 100000;
        chi2 += (counts[b] - e) * (counts[b] - e) / e;
    }
    CHECK_MSG(gp_chi2_upper_tail(chi2, 9) < SIGNIFICANCE, "chi2 = %.2f", chi2);
    gp_distribution_free(&truth);
    gp_distribution_free(&skewed);
}

static void test_radius_is_uniform_inside_its_bin(void)
{
    /* one bin: the position inside it comes from an independent uniform draw */
    gp_distribution d = {.kind = GP_DIST_HISTOGRAM, .nbins = 1};
    d.bins = malloc(sizeof *d.bins);
    d.bins[0] = (gp_bin){2.0, 3.0, 1.0};
    gp_distribution_prepare(&d);
    gp_rng rng;
    gp_rng_seed(&rng, 11);
    enum { N = 100000 };
    double sum = 0.0;
    for (int i = 0; i < N; i++)
        sum += gp_distribution_sample(&d, &rng);
    CHECK_NEAR(sum / N, 2.5, 5 * sqrt(1.0 / 12.0 / N));
    gp_distribution_free(&d);
}

static void test_report_same_draw_keeps_bins_but_leans_to_bin_tops(void)
{
    /* the report's literal r' = r: bin frequencies still right, radii near the tops of
     * the later bins (the draw that chose bin j lies in [cdf_j-1, cdf_j)) */
    gp_distribution d = table1();
    d.report_same_draw = 1;
    double p;
    chi_square(&d, 100000, 4, &p, NULL);
    CHECK(p >= SIGNIFICANCE);
    gp_rng rng;
    gp_rng_seed(&rng, 4);
    double sum_last = 0.0;
    int n_last = 0;
    for (int i = 0; i < 100000; i++) {
        double r = gp_distribution_sample(&d, &rng);
        if (r >= 1.9) {
            sum_last += r;
            n_last++;
        }
    }
    /* the last bin [1.9, 2.0) is chosen by u in [0.92, 1): r = 1.9 + 0.1 u, mean 1.996 */
    CHECK_NEAR(sum_last / n_last, 1.996, 1e-3);
    gp_distribution_free(&d);
}

static void test_uniform_law_passes_chi_square_on_ten_bins(void)
{
    gp_distribution d = {.kind = GP_DIST_UNIFORM, .min = 0.06, .max = 0.42};
    double p, chi2 = chi_square(&d, 100000, 9, &p, NULL);
    CHECK_MSG(p >= SIGNIFICANCE, "chi2 = %.2f, p = %.2g", chi2, p);
}

static void test_constant_law_always_gives_its_radius(void)
{
    gp_distribution d = {.kind = GP_DIST_CONSTANT, .radius = 0.9};
    gp_rng rng;
    gp_rng_seed(&rng, 1);
    int all = 1;
    for (int i = 0; i < 1000; i++)
        all &= gp_distribution_sample(&d, &rng) == 0.9;
    CHECK(all);
    double lo, hi;
    gp_distribution_support(&d, &lo, &hi);
    CHECK(lo == 0.9 && hi == 0.9);
}

static void test_support_skips_empty_bins_and_mass_below_one_goes_to_last_bin(void)
{
    gp_distribution d = {.kind = GP_DIST_HISTOGRAM, .nbins = 3};
    d.bins = malloc(3 * sizeof *d.bins);
    d.bins[0] = (gp_bin){0.5, 1.0, 0.0};
    d.bins[1] = (gp_bin){1.0, 2.0, 0.9999995}; /* sums to 1 within the allowed 1e-6 */
    d.bins[2] = (gp_bin){2.0, 3.0, 0.0};
    gp_distribution_prepare(&d);
    double lo, hi;
    gp_distribution_support(&d, &lo, &hi);
    CHECK(lo == 1.0 && hi == 2.0);
    gp_rng rng;
    gp_rng_seed(&rng, 5);
    int inside = 1;
    for (int i = 0; i < 100000; i++) {
        double r = gp_distribution_sample(&d, &rng);
        inside &= r >= 1.0 && r < 2.0;
    }
    CHECK(inside);
    gp_distribution_free(&d);
}

static void test_mean_packing_area_matches_closed_forms(void)
{
    gp_joint none = {GP_JOINT_NONE, 0, 0, 0}, c = {GP_JOINT_CONSTANT, 0.1, 0, 0};
    gp_distribution u = {.kind = GP_DIST_UNIFORM, .min = 0.06, .max = 0.42};
    /* E[r^2] for r uniform on [a, b] is (a^2 + ab + b^2) / 3 */
    CHECK_NEAR(gp_distribution_mean_packing_r2(&u, &none), (0.0036 + 0.0252 + 0.1764) / 3.0, 1e-12);
    gp_distribution k = {.kind = GP_DIST_CONSTANT, .radius = 0.9};
    CHECK_NEAR(gp_distribution_mean_packing_r2(&k, &c), 1.0, 1e-12);
}

static void test_chi_square_tail_matches_tables(void)
{
    CHECK_NEAR(gp_chi2_upper_tail(3.841459, 1), 0.05, 1e-6);
    CHECK_NEAR(gp_chi2_upper_tail(18.307038, 10), 0.05, 1e-6);
    CHECK_NEAR(gp_chi2_upper_tail(27.877165, 9), 0.001, 1e-7);
    CHECK_NEAR(gp_chi2_upper_tail(2.0, 2), exp(-1.0), 1e-12);
    CHECK(gp_chi2_upper_tail(0.0, 3) == 1.0);
}

int main(void)
{
    RUN(test_table1_histogram_passes_chi_square_on_1e5_draws);
    RUN(test_table1_with_1000_draws_is_as_close_as_the_report);
    RUN(test_biased_sampler_would_be_caught);
    RUN(test_radius_is_uniform_inside_its_bin);
    RUN(test_report_same_draw_keeps_bins_but_leans_to_bin_tops);
    RUN(test_uniform_law_passes_chi_square_on_ten_bins);
    RUN(test_constant_law_always_gives_its_radius);
    RUN(test_support_skips_empty_bins_and_mass_below_one_goes_to_last_bin);
    RUN(test_mean_packing_area_matches_closed_forms);
    RUN(test_chi_square_tail_matches_tables);
    return check_status();
}
