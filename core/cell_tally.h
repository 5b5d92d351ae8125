/* cell_tally.h - what the 2D and 3D cell statistics (cell_stats.c, cell3d_stats.c) count
 * alike (internal to core/): each cell's size (area or volume) and equivalent radius, their
 * extremes and sums, the equivalent radii against the law's bins, and the size histogram. */
#ifndef GRAINPACK_CORE_CELL_TALLY_H
#define GRAINPACK_CORE_CELL_TALLY_H

#include <stddef.h>

#include "grainpack/stats.h"

typedef struct cell_tally {
    double size_min, size_max, size_sum;
    double req_min, req_max, req_sum, ratio_sum;
    gp_bin_stat *bins; /* borrowed: the counts are added to */
    size_t nbins, outside;
} cell_tally;

/* Counts cell number i (0 first) of size `size`, equivalent radius req, grain radius r. */
static inline void cell_tally_add(cell_tally *t, size_t i, double size, double req, double r)
{
    t->size_sum += size;
    t->req_sum += req;
    t->ratio_sum += req / r;
    if (i == 0 || size < t->size_min)
        t->size_min = size;
    if (i == 0 || size > t->size_max)
        t->size_max = size;
    if (i == 0 || req < t->req_min)
        t->req_min = req;
    if (i == 0 || req > t->req_max)
        t->req_max = req;
    long b = gp_bin_table_find(t->bins, t->nbins, req);
    if (b >= 0)
        t->bins[b].count++;
    else
        t->outside++;
}

/* Adds sizes[0..n-1] to hist, `bins` bins over [min, max] (the last one closed). */
static inline void cell_tally_histogram(const double *sizes, size_t n, double min, double max,
                                        size_t *hist, int bins)
{
    double span = max - min;
    for (size_t i = 0; i < n; i++) {
        int bin = span > 0.0 ? (int)((sizes[i] - min) / span * bins) : 0;
        hist[bin < bins ? bin : bins - 1]++;
    }
}

#endif
