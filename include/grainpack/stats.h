/* stats.h - what a packing achieved: densities, radii, and fidelity to the distribution. */
#ifndef GRAINPACK_STATS_H
#define GRAINPACK_STATS_H

#include <stddef.h>

#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/pack.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One bin of the achieved-versus-target histogram. */
typedef struct gp_bin_stat {
    double min, max;  /* [min, max), the last bin closed */
    double target;    /* probability asked for */
    size_t count;     /* disks whose grain radius falls in the bin */
    double achieved;  /* count / number of disks */
    double z;         /* (achieved - target) / sqrt(target (1 - target) / n); 0 if undefined */
} gp_bin_stat;

typedef struct gp_pack_stats {
    size_t count;
    double domain_area;
    double packing_density;  /* sum pi R^2 / area */
    double grain_fraction;   /* sum pi r^2 / area */
    double r_min, r_max, r_mean; /* achieved grain radii (0 without disks) */
    size_t nbins;
    gp_bin_stat *bins;       /* owned */
    double chi2;             /* Pearson's statistic over bins with target > 0 */
    int dof;                 /* bins with target > 0, minus one */
    double p_value;          /* P(chi2_dof >= chi2); 1 when dof = 0 */
    double max_abs_z;        /* the largest |z| over the bins */
} gp_pack_stats;

/* Computes the statistics of `packing` against `dist` in `domain`. Returns 0 or
 * GP_ENOMEM; on success `out` owns its bins (free with gp_pack_stats_free). */
int gp_pack_stats_compute(const gp_domain *domain, const gp_distribution *dist,
                          const gp_packing *packing, gp_pack_stats *out);

void gp_pack_stats_free(gp_pack_stats *stats);

/* The upper tail P(X >= x) of a chi-square law with dof degrees of freedom (dof >= 1). */
double gp_chi2_upper_tail(double x, int dof);

#ifdef __cplusplus
}
#endif
#endif
