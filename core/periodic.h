/* periodic.h - the ghost layer of a periodic domain (internal to core/, docs/method.md
 * §5.1): copies of the disks near the periodic sides, so that geometry written for the
 * plane (CGAL's regular triangulation, the cell builder) sees every neighbour a disk has
 * across a side. */
#ifndef GRAINPACK_CORE_PERIODIC_H
#define GRAINPACK_CORE_PERIODIC_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/disk.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/progress.h"
#include "grainpack/triangulation.h"

/* The disks followed by their images (shifted by a period along the periodic axes of
 * `domain`) whose centre lies in the domain grown by `margin` (0 < margin <= the period)
 * along those axes. *out (n + ghosts disks) and *origin (per ghost, the index of the disk
 * it copies: origin[k - n] for disk k >= n) are the caller's, to free. Returns 0 or
 * GP_ENOMEM. */
int periodic_images(const gp_domain *domain, const gp_disk *disks, size_t n, double margin,
                    gp_disk **out, int32_t **origin, size_t *n_out);

/* Appends `item` (`size` bytes) as element *count of *all (room for *cap) and its origin
 * as element *count - n of *from (room for *from_cap), growing both; the images of
 * periodic_images here and of the 3D cells (laguerre3d.c). Returns 0 or GP_ENOMEM (the
 * arrays then unchanged, still the caller's). */
int periodic_append(void **all, size_t *cap, size_t *count, size_t n, const void *item, size_t size,
                    int32_t **from, size_t *from_cap, int32_t origin);

/* The first ghost margin of the cells, F and balancing, in largest packing radii: a
 * dense packing's power cell reaches about one radius past its disk, so its vertices'
 * power circles stay within a few radii; a margin too small is found out cell by cell
 * (laguerre.c, quality.h) and doubled, up to a period. */
#define PERIODIC_MARGIN_RADII 6.0

/* The ghost layer of disks[0..n-1] within `margin` of the sides and the regular
 * triangulation of it: ghost g (n <= g < m) is all[origin[g - n]] shifted by
 * shift[2 (g - n)] periods along x and shift[2 (g - n) + 1] along y, and disk i's ghosts
 * are ghost_ids[ghost_start[i] .. ghost_start[i + 1] - 1]. Owns every array and rt. */
typedef struct periodic_layer {
    gp_disk *all;
    int32_t *origin;
    int8_t *shift;
    size_t *ghost_start;
    int32_t *ghost_ids;
    size_t n, m;
    double margin;
    gp_rt *rt;
} periodic_layer;

/* Builds the layer of disks[0..n-1] (read, not kept) with the given margin
 * (periodic_images) and triangulates it (gp_rt_build, with `progress`). Returns 0 or a
 * gp_rt_build / GP_ENOMEM error with err set; L is then empty. */
int periodic_layer_build(periodic_layer *L, const gp_domain *domain, const gp_disk *disks, size_t n,
                         double margin, const gp_progress *progress, gp_error *err);

/* Puts ghost g (L->n <= g < L->m) at its disk's image after the disk moved in L->all:
 * the same sum as periodic_images, so that the ghost is, to the bit, the image a new
 * layer would hold. */
void periodic_ghost_place(const periodic_layer *L, const gp_domain *domain, int32_t g);

/* The first margin of a layer (PERIODIC_MARGIN_RADII largest radii, at most the shorter
 * period) and the longest one worth trying (the shorter period). */
double periodic_first_margin(const gp_domain *domain, double R_max);
double periodic_last_margin(const gp_domain *domain);

void periodic_layer_free(periodic_layer *L);

/* Sets err to GP_EGEOM, a cell that even a layer one period wide cannot complete, and
 * returns GP_EGEOM. */
int periodic_too_small(gp_error *err);

#endif
