/* stats.c - densities and distribution fidelity of a packing. */
#include "grainpack/stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"

/* How near a point bin (min = max: a constant law) a radius counts as in it: the drawn
 * radii are the constant itself; a cell's equivalent radius 40 % larger is not. */
#define POINT_BIN_RTOL 1e-12

long gp_bin_table_find(const gp_bin_stat *bins, size_t n, double r)
{
    size_t lo = 0, hi = n;
    while (lo < hi) { /* first bin with min > r */
        size_t mid = lo + (hi - lo) / 2;
        if (bins[mid].min <= r)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo == 0)
        return -1;
    size_t i = lo - 1;
    int last = i + 1 == n;
    if (bins[i].min == bins[i].max) /* a constant law's point: r itself, not what lies above */
        return fabs(r - bins[i].min) <= POINT_BIN_RTOL * fabs(bins[i].min) ? (long)i : -1;
    if (r < bins[i].max || (last && r <= bins[i].max))
        return (long)i;
    return -1;
}

int gp_bin_table_init(const gp_distribution *dist, gp_bin_stat **out, size_t *nbins)
{
    size_t n = gp_distribution_report_bins(dist, NULL, 0);
    gp_bin *bins = malloc((n ? n : 1) * sizeof *bins);
    *out = calloc(n ? n : 1, sizeof **out);
    *nbins = 0;
    if (!bins || !*out) {
        free(bins);
        free(*out);
        *out = NULL;
        return GP_ENOMEM;
    }
    gp_distribution_report_bins(dist, bins, n);
    for (size_t i = 0; i < n; i++) {
        (*out)[i].min = bins[i].min;
        (*out)[i].max = bins[i].max;
        (*out)[i].target = bins[i].p;
    }
    free(bins);
    *nbins = n;
    return 0;
}

void gp_bin_table_finish(gp_bin_stat *bins, size_t nbins, size_t n, double *max_abs_z)
{
    *max_abs_z = 0.0;
    for (size_t i = 0; i < nbins; i++) {
        gp_bin_stat *b = &bins[i];
        b->achieved = n ? (double)b->count / (double)n : 0.0;
        b->se = n ? sqrt(b->target * (1.0 - b->target) / (double)n) : 0.0;
        b->z = b->se > 0.0 ? (b->achieved - b->target) / b->se : 0.0;
        if (fabs(b->z) > *max_abs_z)
            *max_abs_z = fabs(b->z);
    }
}

int gp_pack_stats_compute(const gp_domain *domain, const gp_distribution *dist,
                          const gp_packing *packing, gp_pack_stats *out)
{
    memset(out, 0, sizeof *out);
    if (gp_bin_table_init(dist, &out->bins, &out->nbins))
        return GP_ENOMEM;
    size_t nbins = out->nbins;

    size_t n = packing->count;
    double sum_R2 = 0.0, sum_r2 = 0.0, sum_r = 0.0;
    out->count = n;
    out->domain_area = gp_domain_area(domain);
    for (size_t i = 0; i < n; i++) {
        const gp_disk *d = &packing->disks[i];
        sum_R2 += d->R * d->R;
        sum_r2 += d->r * d->r;
        sum_r += d->r;
        if (i == 0 || d->r < out->r_min)
            out->r_min = d->r;
        if (i == 0 || d->r > out->r_max)
            out->r_max = d->r;
        double joint = d->R - d->r;
        if (i == 0 || joint < out->joint_min)
            out->joint_min = joint;
        if (i == 0 || joint > out->joint_max)
            out->joint_max = joint;
        long b = gp_bin_table_find(out->bins, nbins, d->r);
        if (b >= 0)
            out->bins[b].count++;
    }
    out->packing_density = M_PI * sum_R2 / out->domain_area;
    out->grain_fraction = M_PI * sum_r2 / out->domain_area;
    out->r_mean = n ? sum_r / (double)n : 0.0;

    gp_bin_table_finish(out->bins, nbins, n, &out->max_abs_z);
    gp_bin_table_chi2(out->bins, nbins, n, &out->chi2, &out->dof, &out->p_value);
    return 0;
}

void gp_bin_table_chi2(const gp_bin_stat *bins, size_t nbins, size_t n, double *chi2, int *dof,
                       double *p_value)
{
    int used = 0;
    *chi2 = 0.0;
    for (size_t i = 0; i < nbins; i++) {
        const gp_bin_stat *b = &bins[i];
        if (b->target > 0.0 && n) {
            double expected = b->target * (double)n;
            double diff = (double)b->count - expected;
            *chi2 += diff * diff / expected;
            used++;
        }
    }
    *dof = used > 0 ? used - 1 : 0;
    *p_value = *dof > 0 ? gp_chi2_upper_tail(*chi2, *dof) : 1.0;
}

void gp_pack_stats_free(gp_pack_stats *stats)
{
    free(stats->bins);
    memset(stats, 0, sizeof *stats);
}

/* Regularized upper incomplete gamma Q(a, x): the lower series when x < a + 1, where it
 * converges fast, else the continued fraction for Q evaluated by the modified Lentz
 * method. Both reach double precision within a few hundred terms for the a, x here. */
static double upper_incomplete_gamma(double a, double x)
{
    if (x <= 0.0)
        return 1.0;
    double log_prefactor = a * log(x) - x - lgamma(a);
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 1000 && fabs(term) > fabs(sum) * 1e-16; n++) {
            term *= x / (a + n);
            sum += term;
        }
        double lower = sum * exp(log_prefactor);
        return lower < 1.0 ? 1.0 - lower : 0.0;
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 1000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < tiny)
            d = tiny;
        c = b + an / c;
        if (fabs(c) < tiny)
            c = tiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (fabs(delta - 1.0) < 1e-16)
            break;
    }
    return exp(log_prefactor) * h;
}

double gp_chi2_upper_tail(double x, int dof)
{
    return upper_incomplete_gamma(0.5 * dof, 0.5 * x);
}
