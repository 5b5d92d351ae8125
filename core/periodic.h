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

/* The disks followed by their images (shifted by a period along the periodic axes of
 * `domain`) whose centre lies in the domain grown by `margin` (0 < margin <= the period)
 * along those axes. *out (n + ghosts disks) and *origin (per ghost, the index of the disk
 * it copies: origin[k - n] for disk k >= n) are the caller's, to free. Returns 0 or
 * GP_ENOMEM. */
int periodic_images(const gp_domain *domain, const gp_disk *disks, size_t n, double margin,
                    gp_disk **out, int32_t **origin, size_t *n_out);

#endif
