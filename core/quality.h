/* quality.h - the criterion F of one centre and the statistics of F over a structure
 * (internal to core/): shared by gp_quality, which measures a whole structure, and the
 * balancing sweeps, which measure again only the centres a sweep changed. */
#ifndef GRAINPACK_CORE_QUALITY_H
#define GRAINPACK_CORE_QUALITY_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/balance.h"

/* Where F is measured: the domain and, on a periodic one, the ghost layer the rings come
 * from (periodic.h): `box` is how far past the periodic sides every image is present (the
 * layer's margin less how far any disk moved since the layer was made), `R_max` the
 * largest packing radius. Both 0 on a walled domain. */
typedef struct quality_frame {
    const gp_domain *domain;
    double box, R_max;
} quality_frame;

/* quality_cell_inside's answer when the cell may miss a neighbour beyond the ghosts. */
#define QUALITY_INCOMPLETE (-1)

/* Whether the power cell of disks[i], whose ring (degree >= 3, not on the hull) is
 * given, lies in the domain along its walled axes (docs/method.md §4.2): 1 or 0. On a
 * periodic domain QUALITY_INCOMPLETE when, though inside along the walls, the cell may
 * not be the one among all the periodic images: some vertex's power circle, grown by
 * R_max, reaches past the frame's box along a periodic axis (docs/method.md §5.1). */
int quality_cell_inside(const quality_frame *frame, const gp_disk *disks, int32_t i,
                        const int32_t *ring, size_t degree);

/* F(p) of disks[i] with the given ring, or NAN when the centre is not interior (on the
 * hull, fewer than three neighbours, or its power cell not inside the domain); sets
 * *incomplete when it is NAN because the cell is incomplete (quality_cell_inside). */
double quality_of_centre(const quality_frame *frame, const gp_disk *disks, int32_t i,
                         const int32_t *ring, size_t degree, int on_hull, int *incomplete);

/* The statistics of F[0..n-1] over its non-NAN entries, summed in index order (so the
 * same values always give the same bits); the histogram only when `histogram` is set. */
void quality_summarise(const double *F, size_t n, int histogram, gp_quality_stats *stats);

#endif
