/* distribution.c - radius laws: sampling (docs/method.md §2), support, moments, report bins. */
#include "grainpack/distribution.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"

int gp_distribution_prepare(gp_distribution *dist)
{
    if (dist->kind != GP_DIST_HISTOGRAM)
        return 0;
    free(dist->cdf);
    dist->cdf = malloc((dist->nbins ? dist->nbins : 1) * sizeof *dist->cdf);
    if (!dist->cdf)
        return GP_ENOMEM;
    double sum = 0.0;
    for (size_t i = 0; i < dist->nbins; i++) {
        sum += dist->bins[i].p;
        dist->cdf[i] = sum;
    }
    return 0;
}

void gp_distribution_free(gp_distribution *dist)
{
    free(dist->bins);
    free(dist->cdf);
    memset(dist, 0, sizeof *dist);
}

/* The bin j with cdf[j-1] <= u < cdf[j]; bins of probability zero are never returned. */
static size_t histogram_bin(const gp_distribution *dist, double u)
{
    size_t lo = 0, hi = dist->nbins;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (dist->cdf[mid] <= u)
            lo = mid + 1;
        else
            hi = mid;
    }
    /* u can reach past the last cumulative sum when the probabilities add up to slightly
     * less than 1 (validation allows 1e-6): that mass belongs to the last non-empty bin */
    if (lo >= dist->nbins)
        lo = dist->nbins - 1;
    while (lo > 0 && dist->bins[lo].p <= 0.0)
        lo--;
    return lo;
}

double gp_distribution_sample(const gp_distribution *dist, gp_rng *rng)
{
    switch (dist->kind) {
    case GP_DIST_CONSTANT: return dist->radius;
    case GP_DIST_UNIFORM: return dist->min + gp_rng_uniform(rng) * (dist->max - dist->min);
    case GP_DIST_HISTOGRAM: {
        double u = gp_rng_uniform(rng);
        const gp_bin *bin = &dist->bins[histogram_bin(dist, u)];
        return bin->min + (dist->report_same_draw ? u : gp_rng_uniform(rng)) * (bin->max - bin->min);
    }
    }
    return dist->radius;
}

void gp_distribution_support(const gp_distribution *dist, double *r_min, double *r_max)
{
    switch (dist->kind) {
    case GP_DIST_CONSTANT: *r_min = *r_max = dist->radius; return;
    case GP_DIST_UNIFORM: *r_min = dist->min; *r_max = dist->max; return;
    case GP_DIST_HISTOGRAM: {
        int any = 0;
        for (size_t i = 0; i < dist->nbins; i++) {
            if (dist->bins[i].p <= 0.0)
                continue;
            if (!any || dist->bins[i].min < *r_min)
                *r_min = dist->bins[i].min;
            if (!any || dist->bins[i].max > *r_max)
                *r_max = dist->bins[i].max;
            any = 1;
        }
        if (!any)
            *r_min = *r_max = 0.0;
        return;
    }
    }
}

/* Mean of (r + j(r))^k for r uniform on [a, b], by composite Simpson's rule; the
 * integrand is smooth on the interval, and 64 panels are exact to ~1e-9 relative for
 * every law here, far more than the disk-count estimates need. */
static double mean_pow_on_interval(const gp_joint *joint, double a, double b, int k)
{
    if (!(b > a))
        return pow(gp_joint_packing_radius(joint, a), k);
    enum { PANELS = 64 };
    double h = (b - a) / PANELS, sum = 0.0;
    for (int i = 0; i <= PANELS; i++) {
        double R = gp_joint_packing_radius(joint, a + h * i);
        double w = (i == 0 || i == PANELS) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * pow(R, k);
    }
    return sum * h / 3.0 / (b - a);
}

double gp_distribution_quantile(const gp_distribution *dist, double q)
{
    q = q < 0.0 ? 0.0 : (q > 1.0 ? 1.0 : q);
    switch (dist->kind) {
    case GP_DIST_CONSTANT: return dist->radius;
    case GP_DIST_UNIFORM: return dist->min + q * (dist->max - dist->min);
    case GP_DIST_HISTOGRAM: {
        double below = 0.0, r = 0.0;
        for (size_t i = 0; i < dist->nbins; i++) {
            const gp_bin *b = &dist->bins[i];
            if (!(b->p > 0.0))
                continue;
            r = b->max;
            if (below + b->p >= q)
                return b->min + (q - below) / b->p * (b->max - b->min);
            below += b->p;
        }
        return r;
    }
    }
    return 0.0;
}

double gp_distribution_packing_moment(const gp_distribution *dist, const gp_joint *joint, int k)
{
    switch (dist->kind) {
    case GP_DIST_CONSTANT: return mean_pow_on_interval(joint, dist->radius, dist->radius, k);
    case GP_DIST_UNIFORM: return mean_pow_on_interval(joint, dist->min, dist->max, k);
    case GP_DIST_HISTOGRAM: {
        double sum = 0.0, mass = 0.0;
        for (size_t i = 0; i < dist->nbins; i++) {
            if (dist->bins[i].p <= 0.0)
                continue;
            sum += dist->bins[i].p * mean_pow_on_interval(joint, dist->bins[i].min, dist->bins[i].max, k);
            mass += dist->bins[i].p;
        }
        return mass > 0.0 ? sum / mass : 0.0;
    }
    }
    return 0.0;
}

double gp_distribution_mean_packing_r2(const gp_distribution *dist, const gp_joint *joint)
{
    return gp_distribution_packing_moment(dist, joint, 2);
}

size_t gp_distribution_report_bins(const gp_distribution *dist, gp_bin *out, size_t cap)
{
    switch (dist->kind) {
    case GP_DIST_CONSTANT:
        if (cap >= 1)
            out[0] = (gp_bin){dist->radius, dist->radius, 1.0};
        return 1;
    case GP_DIST_UNIFORM: {
        double width = (dist->max - dist->min) / GP_UNIFORM_REPORT_BINS;
        for (size_t i = 0; i < GP_UNIFORM_REPORT_BINS && i < cap; i++) {
            out[i].min = dist->min + width * (double)i;
            out[i].max = i + 1 == GP_UNIFORM_REPORT_BINS ? dist->max : dist->min + width * (double)(i + 1);
            out[i].p = 1.0 / GP_UNIFORM_REPORT_BINS;
        }
        return GP_UNIFORM_REPORT_BINS;
    }
    case GP_DIST_HISTOGRAM:
        for (size_t i = 0; i < dist->nbins && i < cap; i++)
            out[i] = dist->bins[i];
        return dist->nbins;
    }
    return 0;
}

const char *gp_dist_kind_name(gp_dist_kind kind)
{
    switch (kind) {
    case GP_DIST_CONSTANT: return "constant";
    case GP_DIST_UNIFORM: return "uniform";
    case GP_DIST_HISTOGRAM: return "histogram";
    }
    return "unknown";
}
