/* cell_stats.c - statistics of the Laguerre cells (docs/method.md §5): areas, neighbour counts, the
 * grain-boundary band and the equivalent radii against the target law. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grainpack/stats.h"
#include "cell_tally.h"

int gp_cell_stats_compute(const gp_domain *domain, const gp_distribution *dist,
                          const gp_disk *disks, const gp_cells *cells, gp_cell_stats *out)
{
    memset(out, 0, sizeof *out);
    size_t n = cells->count;
    out->count = n;
    out->vertices = cells->start[n];
    out->neighbour_links = cells->nstart[n];
    for (size_t i = 0; i < n; i++) {
        size_t k = cells->nstart[i + 1] - cells->nstart[i];
        out->max_neighbours = k > out->max_neighbours ? k : out->max_neighbours;
    }
    out->neighbour_histogram = calloc(out->max_neighbours + 1, sizeof *out->neighbour_histogram);
    if (!out->neighbour_histogram || gp_bin_table_init(dist, &out->req_bins, &out->nbins)) {
        gp_cell_stats_free(out);
        return GP_ENOMEM;
    }
    cell_tally t = {.bins = out->req_bins, .nbins = out->nbins};
    double neighbour_sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double a = cells->area[i];
        size_t k = cells->nstart[i + 1] - cells->nstart[i];
        out->neighbour_histogram[k]++;
        neighbour_sum += (double)k;
        cell_tally_add(&t, i, a, sqrt(a / M_PI), disks[i].r);
    }
    out->area_min = t.size_min;
    out->area_max = t.size_max;
    out->req_min = t.req_min;
    out->req_max = t.req_max;
    out->req_outside = t.outside;
    cell_tally_histogram(cells->area, n, out->area_min, out->area_max, out->area_histogram, GP_CELL_AREA_BINS);
    double A = gp_domain_area(domain);
    if (n) {
        out->area_mean = t.size_sum / (double)n;
        out->req_mean = t.req_sum / (double)n;
        out->req_ratio_mean = t.ratio_sum / (double)n;
        out->neighbours_mean = neighbour_sum / (double)n;
    }
    out->band_fraction = 1.0 - t.size_sum / A;
    out->tiling_error = (cells->power_area_sum - A) / A;
    gp_bin_table_finish(out->req_bins, out->nbins, n, &out->req_max_abs_z);
    return 0;
}

void gp_cell_stats_free(gp_cell_stats *stats)
{
    free(stats->neighbour_histogram);
    free(stats->req_bins);
    memset(stats, 0, sizeof *stats);
}
