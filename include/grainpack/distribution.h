/* distribution.h - grain radius laws (histogram, constant, uniform), their sampling and
 * the bins against which achieved radii are compared. */
#ifndef GRAINPACK_DISTRIBUTION_H
#define GRAINPACK_DISTRIBUTION_H

#include <stddef.h>

#include "grainpack/api.h"
#include "grainpack/joint.h"
#include "grainpack/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_dist_kind {
    GP_DIST_CONSTANT = 0,
    GP_DIST_UNIFORM,
    GP_DIST_HISTOGRAM
} gp_dist_kind;

/* One histogram bin [min, max) (the last bin closed) drawn with probability p. */
typedef struct gp_bin {
    double min, max, p;
} gp_bin;

/* Bins used to report achieved frequencies of laws that are not histograms. */
#define GP_UNIFORM_REPORT_BINS 10

typedef struct gp_distribution {
    gp_dist_kind kind;
    double radius;   /* GP_DIST_CONSTANT */
    double min, max; /* GP_DIST_UNIFORM */
    size_t nbins;    /* GP_DIST_HISTOGRAM: bins sorted by min, not overlapping */
    gp_bin *bins;    /* owned; freed by gp_distribution_free */
    double *cdf;     /* owned; cdf[i] = p_0 + .. + p_i, built by gp_distribution_prepare */
    int report_same_draw; /* GP_DIST_HISTOGRAM: 0 (docs/method.md §2) places the radius in its bin
                             with an independent draw; 1 reuses the bin-choosing draw, the
                             literal "r' = r" of the report, which honours the bin
                             frequencies but leans to the top of each bin. Only for
                             reproducing the report's figures (bench/). */
} gp_distribution;

/* Builds the sampling table of a histogram (no-op for other kinds). Call once after the
 * fields are set and validated; returns 0 or GP_ENOMEM. */
GP_API int gp_distribution_prepare(gp_distribution *dist);

/* Frees what the distribution owns and zeroes it. */
GP_API void gp_distribution_free(gp_distribution *dist);

/* Draws one radius (docs/method.md §2): a bin by inversion of the cumulative probabilities, then a
 * position in the bin from an independent second draw. */
GP_API double gp_distribution_sample(const gp_distribution *dist, gp_rng *rng);

/* The support [*r_min, *r_max]: the smallest and largest radius that can be drawn
 * (bins of probability zero are not part of it). */
GP_API void gp_distribution_support(const gp_distribution *dist, double *r_min, double *r_max);

/* The expected value of (r + j(r))^2: the mean packing-disk area divided by pi. */
GP_API double gp_distribution_mean_packing_r2(const gp_distribution *dist, const gp_joint *joint);

/* The radius r below which a draw falls with probability q (q in [0, 1]; uniform within
 * a bin, as the draws are). */
GP_API double gp_distribution_quantile(const gp_distribution *dist, double q);

/* The expected value of (r + j(r))^k, the k-th moment of the packing radius. */
GP_API double gp_distribution_packing_moment(const gp_distribution *dist, const gp_joint *joint, int k);

/* The bins achieved radii are reported against: the histogram's own, ten equal bins for
 * the uniform law, one degenerate bin for a constant radius. Writes at most `cap` bins to
 * `out` and returns how many there are. */
GP_API size_t gp_distribution_report_bins(const gp_distribution *dist, gp_bin *out, size_t cap);

/* "constant", "uniform" or "histogram". */
GP_API const char *gp_dist_kind_name(gp_dist_kind kind);

#ifdef __cplusplus
}
#endif
#endif
