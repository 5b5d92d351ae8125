/* geometry3d.h - the 3D stages after packing (issue 17, docs/3d.md): the regular
 * triangulation of the sphere centres with weights R^2 (CGAL Regular_triangulation_3
 * behind a C API, as triangulation.h is for 2D), F and its balancing, and the Laguerre
 * (power) polyhedra clipped to the box and shrunk. This header is the contract between
 * the geometry (core/ files named *3d*) and its users (pipeline, writers, service). */
#ifndef GRAINPACK_GEOMETRY3D_H
#define GRAINPACK_GEOMETRY3D_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/balance.h"
#include "grainpack/error.h"
#include "grainpack/laguerre.h"
#include "grainpack/pack3d.h"
#include "grainpack/progress.h"
#include "grainpack/stats.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Opaque: the regular triangulation of spheres[0..n-1] (centres, weights R^2) and a table
 * from sphere id to vertex. Not safe from two threads at once. */
typedef struct gp_rt3 gp_rt3;

/* Builds it. The spheres are read, not kept. Returns 0 and *out (free with gp_rt3_free), or
 * GP_ENOMEM, GP_ETOOBIG, GP_EGEOM (a hidden vertex: overlapping spheres, or two with one
 * centre), GP_ECANCELED, GP_EINTERNAL; err says which; *out is NULL. Progress as stage
 * "triangulation"; `progress` may be NULL. */
GP_API int gp_rt3_build(const gp_sphere *spheres, size_t n, const gp_progress *progress,
                        gp_rt3 **out, gp_error *err);
GP_API void gp_rt3_free(gp_rt3 *rt);

/* F in 3D (docs/3d.md): for an interior centre p with triangulation neighbours p_i,
 * h_i = |p - p_i| - R_p - R_i and F(p) = (max h_i - min h_i) / R_p; NAN elsewhere. A centre
 * is interior when its power cell is bounded and inside the box. F may be NULL. */
GP_API int gp_quality3d(const gp_box *box, const gp_rt3 *rt, const gp_sphere *spheres, size_t n,
                        double *F, gp_quality_stats *stats, const gp_cancel_flag *cancel,
                        gp_error *err);

/* Balances spheres[0..n-1] in place as gp_balance does in 2D (same methods, stopping
 * rules, step ladder, the best structure returned, no overlap and inside the box at every
 * step); `rt` is borrowed and left up to date. Progress as stage "balance". Returns as
 * gp_balance; `out` as gp_balance's (free with gp_balance_result_free). */
GP_API int gp_balance3d(const gp_box *box, gp_sphere *spheres, size_t n, gp_rt3 *rt,
                        const gp_balance_params *params, const gp_progress *progress,
                        gp_balance_result *out, gp_error *err);

/* Box walls as face neighbours: a face on a wall has neighbour GP_WALL3D(k), k = 0 x = 0,
 * 1 x = width, 2 y = 0, 3 y = height, 4 z = 0, 5 z = depth. */
#define GP_WALL3D(k) (-1 - (int32_t)(k))
#define GP_IS_WALL3D(id) ((id) < 0)
#define GP_WALL3D_INDEX(id) (-1 - (id))

/* The Laguerre polyhedra of a structure, one per sphere, in the spheres' order. A cell's
 * vertices are its own (a vertex shared by several cells appears in each). Every array is
 * owned. */
typedef struct gp_cells3d {
    size_t count;
    gp_shrink shrink;
    size_t *vstart;       /* count + 1 offsets: cell i has vertices vstart[i] .. vstart[i+1]-1 */
    double *xyz;          /* vertices, x y z interleaved (absolute coordinates) */
    size_t *fstart;       /* count + 1 offsets: cell i has faces fstart[i] .. fstart[i+1]-1 */
    size_t *fvstart;      /* faces + 1 offsets into fverts */
    uint32_t *fverts;     /* a face's vertices as indices into its cell's own vertices (0 is
                             xyz[3 vstart[i]]), counter-clockwise seen from outside the cell,
                             the face convex and planar */
    int32_t *fneighbour;  /* per face: the grain on the other side of the (unshrunk) power
                             face, or GP_WALL3D(k); a pair of grains shares at most one face
                             and the relation is symmetric (offset cells: a small face the
                             offset erodes away in one cell may stay in the other, whose
                             joint is thinner; every face listed is a power face) */
    double *volume;       /* of each (shrunk) cell */
    double power_volume_sum; /* sum of the unshrunk power cells' volumes: the box's */
} gp_cells3d;

/* Builds the cells of spheres[0..n-1] in `box` from `rt` (borrowed; built on the same
 * spheres): each power cell is the box cut by the radical planes of the centre's
 * triangulation neighbours, faces whose area is below GP_LAGUERRE_EDGE_RTOL^2 R^2 dropped,
 * then shrunk as params asks (offset: every face moved inward by j(r) = R - r, walls
 * included unless flush_boundary; homothetic: about the centre by r / R). Progress as
 * stage "laguerre". Returns 0 and `out` (free with gp_cells3d_free), or GP_ENOMEM,
 * GP_ECANCELED, GP_EGEOM (a centre outside its own cell); `out` zeroed on failure. On a
 * periodic box (docs/3d.md §11) `rt` is not used (NULL is fine): the cells come from a
 * triangulation of the spheres and their images near the periodic sides, and a cell
 * across a side is one polyhedron around its sphere sticking out of the box, its faces'
 * neighbours grain ids; the power cells then tile the periodic box (power_volume_sum is
 * its volume). */
GP_API int gp_laguerre3d(const gp_box *box, const gp_sphere *spheres, size_t n, const gp_rt3 *rt,
                         const gp_laguerre_params *params, const gp_progress *progress,
                         gp_cells3d *out, gp_error *err);
GP_API void gp_cells3d_free(gp_cells3d *cells);

/* Bins of the cell-volume histogram, over [min, max] of the volumes. */
#define GP_CELL_VOLUME_BINS 10

/* What the 3D Laguerre stage made: volumes, faces per cell, equivalent radii
 * (3 V / 4 pi)^(1/3) against the law, the grain-boundary phase. */
typedef struct gp_cell3d_stats {
    size_t count;
    size_t faces, vertices;          /* over all cells */
    double volume_min, volume_max, volume_mean;
    size_t volume_histogram[GP_CELL_VOLUME_BINS];
    double faces_mean;               /* faces per cell, walls included */
    size_t max_faces;
    size_t *faces_histogram;         /* owned; max_faces + 1 entries */
    double neighbours_mean;          /* grain neighbours per cell (faces not on walls) */
    double boundary_fraction;        /* 1 - sum of cell volumes / box volume */
    double tiling_error;             /* (sum of unshrunk volumes - box volume) / box volume */
    double req_min, req_max, req_mean, req_ratio_mean; /* r_eq and mean r_eq / r */
    size_t nbins;
    gp_bin_stat *req_bins;           /* owned: r_eq against the law's bins */
    size_t req_outside;
    double req_max_abs_z;
} gp_cell3d_stats;

GP_API int gp_cell3d_stats_compute(const gp_box *box, const gp_distribution *dist,
                                   const gp_sphere *spheres, const gp_cells3d *cells,
                                   gp_cell3d_stats *out);
GP_API void gp_cell3d_stats_free(gp_cell3d_stats *stats);

#ifdef __cplusplus
}
#endif
#endif
