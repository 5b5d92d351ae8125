/* quality.h - the criterion F of one centre and the statistics of F over a structure
 * (internal to core/): shared by gp_quality, which measures a whole structure, and the
 * balancing sweeps, which measure again only the centres a sweep changed. */
#ifndef GRAINPACK_CORE_QUALITY_H
#define GRAINPACK_CORE_QUALITY_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/balance.h"

/* Whether the power cell of disks[i], whose ring (degree >= 3, not on the hull) is
 * given, lies in the domain (docs/method.md §4.2). */
int quality_cell_inside(const gp_domain *domain, const gp_disk *disks, int32_t i,
                        const int32_t *ring, size_t degree);

/* F(p) of disks[i] with the given ring, or NAN when the centre is not interior (on the
 * hull, fewer than three neighbours, or its power cell not inside the domain). */
double quality_of_centre(const gp_domain *domain, const gp_disk *disks, int32_t i,
                         const int32_t *ring, size_t degree, int on_hull);

/* The statistics of F[0..n-1] over its non-NAN entries, summed in index order (so the
 * same values always give the same bits); the histogram only when `histogram` is set. */
void quality_summarise(const double *F, size_t n, int histogram, gp_quality_stats *stats);

#endif
