/* stats.h - what a packing achieved: densities, radii, and fidelity to the distribution. */
#ifndef GRAINPACK_STATS_H
#define GRAINPACK_STATS_H

#include <stddef.h>

#include "grainpack/api.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/laguerre.h"
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
    double se;        /* standard error of `achieved` when the law holds: sqrt(target (1 - target) / n),
                         0 without disks (the error bar of a plot) */
    double z;         /* (achieved - target) / se; 0 if undefined */
} gp_bin_stat;

typedef struct gp_pack_stats {
    size_t count;
    double domain_area;
    double packing_density;  /* sum pi R^2 / area */
    double grain_fraction;   /* sum pi r^2 / area */
    double r_min, r_max, r_mean; /* achieved grain radii (0 without disks) */
    double joint_min, joint_max; /* of the joint thickness R - r (0 without disks) */
    size_t nbins;
    gp_bin_stat *bins;       /* owned */
    double chi2;             /* Pearson's statistic over bins with target > 0 */
    int dof;                 /* bins with target > 0, minus one */
    double p_value;          /* P(chi2_dof >= chi2); 1 when dof = 0 */
    double max_abs_z;        /* the largest |z| over the bins */
} gp_pack_stats;

/* Computes the statistics of `packing` against `dist` in `domain`. Returns 0 or
 * GP_ENOMEM; on success `out` owns its bins (free with gp_pack_stats_free). */
GP_API int gp_pack_stats_compute(const gp_domain *domain, const gp_distribution *dist,
                                 const gp_packing *packing, gp_pack_stats *out);

GP_API void gp_pack_stats_free(gp_pack_stats *stats);

/* Bins of the cell-area histogram, over [min, max] of the areas. */
#define GP_CELL_AREA_BINS 10

/* What the Laguerre stage made (docs/method.md §5): the cells, their sizes and neighbours, the
 * grain-boundary band, and how the cells' equivalent radii compare with the target law. */
typedef struct gp_cell_stats {
    size_t count;
    size_t vertices;         /* over all cells */
    size_t neighbour_links;  /* entries of all neighbour lists (twice the pairs) */
    double area_min, area_max, area_mean;  /* of the (shrunk) cells */
    size_t area_histogram[GP_CELL_AREA_BINS];
    double neighbours_mean;
    size_t max_neighbours;
    size_t *neighbour_histogram; /* owned; max_neighbours + 1 entries: cells with k neighbours */
    double band_fraction;    /* 1 - sum of cell areas / domain area: the grain-boundary band */
    double tiling_error;     /* (sum of unshrunk cell areas - domain area) / domain area */
    double req_min, req_max, req_mean; /* equivalent radius sqrt(area / pi) of the cells */
    double req_ratio_mean;   /* mean of r_eq / r over the grains */
    size_t nbins;
    gp_bin_stat *req_bins;   /* owned: the equivalent radii against the target law's bins */
    size_t req_outside;      /* equivalent radii in none of the bins */
    double req_max_abs_z;
} gp_cell_stats;

/* Computes the statistics of `cells` (one per disk of `disks`) in `domain` against
 * `dist`. Returns 0 or GP_ENOMEM; on success `out` owns its arrays (free with
 * gp_cell_stats_free). */
GP_API int gp_cell_stats_compute(const gp_domain *domain, const gp_distribution *dist,
                                 const gp_disk *disks, const gp_cells *cells, gp_cell_stats *out);

GP_API void gp_cell_stats_free(gp_cell_stats *stats);

/* The achieved-versus-target table of `dist`: its report bins (gp_distribution_report_bins)
 * with zero counts. Returns 0 or GP_ENOMEM; *bins is the caller's to free. */
GP_API int gp_bin_table_init(const gp_distribution *dist, gp_bin_stat **bins, size_t *nbins);

/* The bin holding r among bins sorted by min, or -1 when r lies in none of them. A point
 * bin (min = max, a constant law) holds r only within a relative 1e-12 of its value. */
GP_API long gp_bin_table_find(const gp_bin_stat *bins, size_t nbins, double r);

/* Fills `achieved`, `se` and `z` of every bin from its count out of n values, and *max_abs_z. */
GP_API void gp_bin_table_finish(gp_bin_stat *bins, size_t nbins, size_t n, double *max_abs_z);

/* Pearson's chi-square of the counts of n values against the targets, over the bins with
 * a target > 0, its degrees of freedom (those bins less one) and p-value (1 when dof is 0). */
GP_API void gp_bin_table_chi2(const gp_bin_stat *bins, size_t nbins, size_t n, double *chi2, int *dof,
                              double *p_value);

/* The upper tail P(X >= x) of a chi-square law with dof degrees of freedom (dof >= 1). */
GP_API double gp_chi2_upper_tail(double x, int dof);

#ifdef __cplusplus
}
#endif
#endif
