/* cell3d_stats.c - statistics of the Laguerre polyhedra (geometry3d.h): volumes, faces per
 * cell, the grain-boundary phase and the equivalent radii against the target law, as
 * cell_stats.c does for the 2D cells. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grainpack/geometry3d.h"
#include "cell_tally.h"

int gp_cell3d_stats_compute(const gp_box *box, const gp_distribution *dist,
                            const gp_sphere *spheres, const gp_cells3d *cells,
                            gp_cell3d_stats *out)
{
    memset(out, 0, sizeof *out);
    size_t n = cells->count;
    out->count = n;
    out->faces = cells->fstart[n];
    out->vertices = cells->vstart[n];
    for (size_t i = 0; i < n; i++) {
        size_t k = cells->fstart[i + 1] - cells->fstart[i];
        out->max_faces = k > out->max_faces ? k : out->max_faces;
    }
    out->faces_histogram = calloc(out->max_faces + 1, sizeof *out->faces_histogram);
    if (!out->faces_histogram || gp_bin_table_init(dist, &out->req_bins, &out->nbins)) {
        gp_cell3d_stats_free(out);
        return GP_ENOMEM;
    }
    cell_tally t = {.bins = out->req_bins, .nbins = out->nbins};
    double face_sum = 0.0, neighbour_sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double v = cells->volume[i];
        size_t k = cells->fstart[i + 1] - cells->fstart[i];
        out->faces_histogram[k]++;
        face_sum += (double)k;
        for (size_t f = cells->fstart[i]; f < cells->fstart[i + 1]; f++)
            neighbour_sum += !GP_IS_WALL3D(cells->fneighbour[f]);
        cell_tally_add(&t, i, v, cbrt(3.0 * v / (4.0 * M_PI)), spheres[i].r);
    }
    out->volume_min = t.size_min;
    out->volume_max = t.size_max;
    out->req_min = t.req_min;
    out->req_max = t.req_max;
    out->req_outside = t.outside;
    cell_tally_histogram(cells->volume, n, out->volume_min, out->volume_max, out->volume_histogram,
                         GP_CELL_VOLUME_BINS);
    double V = box->width * box->height * box->depth;
    if (n) {
        out->volume_mean = t.size_sum / (double)n;
        out->req_mean = t.req_sum / (double)n;
        out->req_ratio_mean = t.ratio_sum / (double)n;
        out->faces_mean = face_sum / (double)n;
        out->neighbours_mean = neighbour_sum / (double)n;
    }
    out->boundary_fraction = 1.0 - t.size_sum / V;
    out->tiling_error = (cells->power_volume_sum - V) / V;
    gp_bin_table_finish(out->req_bins, out->nbins, n, &out->req_max_abs_z);
    return 0;
}

void gp_cell3d_stats_free(gp_cell3d_stats *stats)
{
    free(stats->faces_histogram);
    free(stats->req_bins);
    memset(stats, 0, sizeof *stats);
}
