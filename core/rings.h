/* rings.h - the rings of every vertex of a triangulation in one array (internal to core/),
 * kept from one balancing sweep to the next and re-read from the triangulation only for
 * the vertices an update changed (gp_rt_mark_changes): a sweep and the F that follows it
 * then never walk CGAL's faces, which at 10^6 grains cost a third of a sweep. */
#ifndef GRAINPACK_CORE_RINGS_H
#define GRAINPACK_CORE_RINGS_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/progress.h"
#include "grainpack/triangulation.h"

/* Vertex i has the ring ids[start[i]] .. ids[start[i + 1] - 1], as gp_rt_ring gives it,
 * and hull[i] says whether it is on the convex hull. The next version is built in the
 * spare arrays, then the two swap. Owns every array. */
typedef struct rings {
    size_t n;
    size_t *start;
    int32_t *ids;
    size_t cap;
    uint8_t *hull;
    size_t *spare_start;
    int32_t *spare_ids;
    size_t spare_cap;
} rings;

/* Reads the rings of the n vertices of rt (ids 0 .. n-1) into r (gp_rt_rings, which reads
 * the cancel flag of `progress`, may be NULL). Returns 0, GP_ENOMEM or GP_ECANCELED (r is
 * then empty and only rings_free may follow). */
int rings_init(rings *r, const gp_rt *rt, size_t n, const gp_progress *progress);

/* Re-reads from rt the rings of the vertices with changed[i] set and keeps the others;
 * *cancel (may be NULL) is read every GP_RT_RINGS_PER_CHECK vertices (after a rebuild
 * every ring is read again). Returns 0, GP_ENOMEM or GP_ECANCELED (only rings_free may
 * then follow). */
int rings_refresh(rings *r, const gp_rt *rt, const uint8_t *changed, const gp_cancel_flag *cancel);

void rings_free(rings *r);

static inline const int32_t *rings_of(const rings *r, int32_t i, size_t *degree)
{
    *degree = r->start[i + 1] - r->start[i];
    return r->ids + r->start[i];
}

#endif
