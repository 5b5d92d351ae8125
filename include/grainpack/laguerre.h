/* laguerre.h - polygonal grains (docs/method.md §5, report §V): the power (Laguerre) cells of the
 * packing disks (centre, radius R = r + j(r): power weight R^2, as in triangulation.h),
 * clipped to the domain so that they tile it, then shrunk to leave the grain-boundary band. */
#ifndef GRAINPACK_LAGUERRE_H
#define GRAINPACK_LAGUERRE_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/disk.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/progress.h"
#include "grainpack/triangulation.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_shrink {
    GP_SHRINK_NONE = 0,    /* the power cells themselves */
    GP_SHRINK_HOMOTHETIC,  /* report eq. 15: each vertex o goes to p + (r / R)(o - p) */
    GP_SHRINK_OFFSET       /* every edge moves inward by j(r) = R - r */
} gp_shrink;

/* "none", "homothetic" or "offset". */
GP_API const char *gp_shrink_name(gp_shrink shrink);

typedef struct gp_laguerre_params {
    gp_shrink shrink;
    int flush_boundary; /* offset only: edges on the domain boundary stay where they are */
} gp_laguerre_params;

/* An edge of a power cell shorter than this fraction of the mean packing radius of its
 * two grains does not make them neighbours. Why this value: cell vertices are computed to a
 * few ulps of the radius (coordinates are taken relative to the centre), about 1e-15 R;
 * an edge of 1e-9 R is far above that noise, and far below any real contact (four
 * centres on one power circle give an edge of exactly zero, which rounding turns into
 * 1e-15 R or so). */
#define GP_LAGUERRE_EDGE_RTOL 1e-9

/* The cells of a structure, one per disk, in the disks' order. Every array is owned. */
typedef struct gp_cells {
    size_t count;
    gp_shrink shrink;
    size_t *start;        /* count + 1 offsets: cell i has vertices start[i] .. start[i+1]-1 */
    double *xy;           /* vertices, x and y interleaved, counter-clockwise, convex */
    size_t *nstart;       /* count + 1 offsets into neighbours */
    int32_t *neighbours;  /* ids of the grains whose power cell shares an edge (longer than
                             GP_LAGUERRE_EDGE_RTOL (R_i + R_j) / 2) with this one, in
                             counter-clockwise order; the relation is symmetric */
    double *area;         /* area of each (shrunk) cell */
    double power_area_sum;/* sum of the areas of the unshrunk power cells: the domain's */
} gp_cells;

/* Builds the cells of disks[0..n-1] in `domain` from their regular triangulation `rt`
 * (borrowed; gp_rt_build on the same disks). Each power cell is the domain cut by the
 * radical half-planes of the centre's triangulation neighbours (the dual edges), so the
 * cells are clipped exactly to the domain and unbounded cells need no special case; then
 * the cell is shrunk as params asks. Reports progress as stage "laguerre", honours
 * progress->cancel.
 *
 * On a periodic domain (docs/method.md §5.1) `rt` is not used (it may be NULL): the cells
 * are those among all the periodic images, from a ghost layer of images near the sides
 * and its own triangulation; they are clipped only by the walled sides, a cell across a
 * periodic side is one polygon in unwrapped coordinates around its disk (it sticks out of
 * the domain), its neighbours are grain ids, and the cells' areas sum to W H.
 *
 * On success returns 0 and `out` owns its arrays (free with gp_cells_free). Fails with
 * GP_ENOMEM, GP_ECANCELED, or GP_EGEOM when a centre lies outside its own cell (a disk
 * outside the domain, or overlapping disks); err says which; `out` is zeroed. */
GP_API int gp_laguerre(const gp_domain *domain, const gp_disk *disks, size_t n, const gp_rt *rt,
                       const gp_laguerre_params *params, const gp_progress *progress,
                       gp_cells *out, gp_error *err);

GP_API void gp_cells_free(gp_cells *cells);

/* The area of a polygon given as n interleaved x, y vertices (positive when
 * counter-clockwise). */
GP_API double gp_polygon_area(const double *xy, size_t n);

#ifdef __cplusplus
}
#endif
#endif
