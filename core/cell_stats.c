/* cell_stats.c - statistics of the Laguerre cells (docs/method.md §5): areas, neighbour counts, the
 * grain-boundary band and the equivalent radii against the target law. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grainpack/stats.h"

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
    double area_sum = 0.0, req_sum = 0.0, ratio_sum = 0.0, neighbour_sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double a = cells->area[i], req = sqrt(a / M_PI);
        size_t k = cells->nstart[i + 1] - cells->nstart[i];
        out->neighbour_histogram[k]++;
        neighbour_sum += (double)k;
        area_sum += a;
        req_sum += req;
        ratio_sum += req / disks[i].r;
        if (i == 0 || a < out->area_min)
            out->area_min = a;
        if (i == 0 || a > out->area_max)
            out->area_max = a;
        if (i == 0 || req < out->req_min)
            out->req_min = req;
        if (i == 0 || req > out->req_max)
            out->req_max = req;
        long b = gp_bin_table_find(out->req_bins, out->nbins, req);
        if (b >= 0)
            out->req_bins[b].count++;
        else
            out->req_outside++;
    }
    double span = out->area_max - out->area_min;
    for (size_t i = 0; i < n; i++) {
        int bin = span > 0.0 ? (int)((cells->area[i] - out->area_min) / span * GP_CELL_AREA_BINS) : 0;
        out->area_histogram[bin < GP_CELL_AREA_BINS ? bin : GP_CELL_AREA_BINS - 1]++;
    }
    double A = gp_domain_area(domain);
    if (n) {
        out->area_mean = area_sum / (double)n;
        out->req_mean = req_sum / (double)n;
        out->req_ratio_mean = ratio_sum / (double)n;
        out->neighbours_mean = neighbour_sum / (double)n;
    }
    out->band_fraction = 1.0 - area_sum / A;
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
