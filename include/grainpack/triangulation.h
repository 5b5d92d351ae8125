/* triangulation.h - the regular (weighted Delaunay) triangulation of the disk centres with
 * weights R^2 (docs/method.md §4.1, §5), behind a C API. The one C++ file core/triangulation.cpp
 * holds it in a CGAL Regular_triangulation_2 with exact predicates; nothing here shows a
 * C++ type, and no C++ exception crosses this API. */
#ifndef GRAINPACK_TRIANGULATION_H
#define GRAINPACK_TRIANGULATION_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/disk.h"
#include "grainpack/error.h"
#include "grainpack/progress.h"

#ifdef __cplusplus
extern "C" {
/* The entry points that cannot fail are noexcept on the C++ side: should CGAL ever throw
 * in one (a failed internal check), the program stops there rather than unwind into C. */
#define GP_RT_NOEXCEPT noexcept
#else
#define GP_RT_NOEXCEPT
#endif

/* Opaque: owns the CGAL triangulation and a table from disk id (the index in the disks
 * array it was built from) to vertex. Not safe to use from two threads at once; two
 * triangulations on two threads are independent. */
typedef struct gp_rt gp_rt;

/* Builds the regular triangulation of the centres of disks[0..n-1] with weights R^2
 * (power distance |x - c|^2 - R^2). The disks are read, not kept. On success returns 0
 * and *out owns the triangulation (free with gp_rt_free). Fails with GP_ENOMEM,
 * GP_ETOOBIG (n does not fit an int32_t id), GP_EGEOM when some disk has no vertex (a
 * hidden vertex: its disk lies inside the power cells of others, which non-overlapping
 * packing disks never do; also two disks with the same centre), GP_ECANCELED when
 * progress->cancel was raised, or GP_EINTERNAL when CGAL reports a failure; err says
 * which disk or what CGAL said, and *out is NULL. The points are spatially sorted (one
 * pass CGAL cannot interrupt: 0.1 s a million points) and inserted in batches of
 * GP_RT_INSERT_BATCH; between two batches the cancel flag is read and progress reported
 * as stage "triangulation". `progress` may be NULL.
 * (A gp_progress rather than its flag: C and C++ see the flag as two different types.) */
GP_API int gp_rt_build(const gp_disk *disks, size_t n, const gp_progress *progress,
                       gp_rt **out, gp_error *err);

/* Points inserted between two reads of the cancel flag: a few milliseconds of work. */
#define GP_RT_INSERT_BATCH 4096

/* Frees the triangulation (no-op on NULL). */
GP_API void gp_rt_free(gp_rt *rt) GP_RT_NOEXCEPT;

/* The number of vertices (= disks). */
GP_API size_t gp_rt_count(const gp_rt *rt) GP_RT_NOEXCEPT;

/* The dimension of the triangulation: -1 empty, 0 one vertex, 1 all centres collinear,
 * 2 otherwise. Only dimension 2 has interior vertices and balls. */
GP_API int gp_rt_dimension(const gp_rt *rt) GP_RT_NOEXCEPT;

/* The neighbours of vertex `id` (its ring), counter-clockwise around it. Writes the
 * first `cap` of them to `out` and returns how many there are (call again with a larger
 * buffer when that exceeds cap). *on_hull is set to 1 when the vertex is on the convex
 * hull of the centres (always, in dimension < 2), else 0.
 *
 * In dimension 2 the ring is the dual of the vertex's power cell: neighbour k shares
 * the cell edge on the radical line of the two disks. For an interior vertex p, the
 * triangles around it (its ball) are (p, out[k], out[k+1 mod degree]), and the boundary
 * edges of the ball (its link) are (out[k], out[k+1 mod degree]), each with p on its left.
 * For a hull vertex the ring starts just after the convex hull's outside and ends just
 * before it: the triangles and link edges are those with k + 1 < degree, and
 * (p, out[0]) and (out[degree-1], p) are hull edges. An interior vertex's ring starts at
 * its smallest id: the same triangulation always gives the same ring, however it was
 * built or updated. */
GP_API size_t gp_rt_ring(const gp_rt *rt, int32_t id, int32_t *out, size_t cap,
                         int *on_hull) GP_RT_NOEXCEPT;

/* Every ring at once, each as gp_rt_ring gives it: vertex id's ring is
 * (*ids)[start[id]] .. (*ids)[start[id + 1] - 1] and hull[id] is its on_hull. The
 * triangulation is walked once, in its own memory order, where a vertex and its faces lie
 * together; asking gp_rt_ring for each id in turn jumps across the whole structure for
 * every ring (at 10^6 grains that walk was half of the Laguerre cells' time). `start`
 * (gp_rt_count + 1 entries) and `hull` (gp_rt_count, or NULL when not wanted) are the
 * caller's; *ids is allocated here and the caller frees it. Returns 0, GP_ENOMEM or
 * GP_ECANCELED (progress->cancel is read every GP_RT_RINGS_PER_CHECK vertices of the walk
 * and once after it; no progress is reported; `progress` may be NULL); *ids is then NULL. */
GP_API int gp_rt_rings(const gp_rt *rt, size_t *start, uint8_t *hull, int32_t **ids,
                       const gp_progress *progress) GP_RT_NOEXCEPT;

/* Rings walked between two reads of the cancel flag: as many as the centres gp_quality
 * measures between two (a ring costs less than a centre's F): well under a millisecond. */
#define GP_RT_RINGS_PER_CHECK 16384

/* How to bring the triangulation up to date after centres moved. */
typedef enum gp_rt_update {
    /* Each moved vertex is moved in place and the regular property restored by edge
     * flips around it (report Algorithm 3: "basculer les arêtes"); a vertex on the hull,
     * or whose move would fold a triangle, is removed and inserted again. Should a flip
     * ever be impossible (a non-convex quadrilateral) the whole triangulation is built
     * again. */
    GP_RT_UPDATE_FLIPS = 0,
    /* The whole triangulation is built again from all the disks. */
    GP_RT_UPDATE_REBUILD
} gp_rt_update;

/* What an update did, added to the counters of *stats. */
typedef struct gp_rt_update_stats {
    uint64_t moved_in_place; /* vertices moved where they were, then flipped around */
    uint64_t flips;          /* edge flips done */
    uint64_t reinserted;     /* vertices removed and inserted again */
    uint64_t rebuilds;       /* full builds */
} gp_rt_update_stats;

/* Brings the triangulation up to date after the centres of disks[ids[k]] (k < nids)
 * moved; `disks` is the array it was built from, with the new positions (the radii must
 * not have changed). Returns 0 or, as gp_rt_build, GP_ENOMEM, GP_EGEOM, GP_ECANCELED
 * (progress->cancel is read every GP_RT_INSERT_BATCH moves, and as gp_rt_build reads it;
 * no progress is reported) or GP_EINTERNAL; on failure the triangulation must only be
 * freed. `stats` and `progress` may be NULL. */
GP_API int gp_rt_update_moved(gp_rt *rt, const gp_disk *disks, size_t ndisks,
                              const int32_t *ids, size_t nids, gp_rt_update mode,
                              gp_rt_update_stats *stats, const gp_progress *progress,
                              gp_error *err);

/* Has every later update of rt set marks[id] = 1 for each vertex whose ring (its
 * neighbours, their order, whether it is on the hull) it may have changed: the four
 * vertices of each flipped edge's quadrilateral, the old and new neighbours of a
 * vertex removed and inserted again, every vertex on a full rebuild. A vertex left
 * unmarked has the ring it had before the update. Marks are only ever set, never
 * cleared: the caller clears them. `marks` holds one byte per disk and is borrowed
 * until the next call; NULL stops the marking. */
GP_API void gp_rt_mark_changes(gp_rt *rt, uint8_t *marks) GP_RT_NOEXCEPT;

/* Whether the triangulation is a valid regular triangulation of its current points
 * (CGAL's own check: every triangle counter-clockwise, every edge locally regular, no
 * hidden vertex). Costly; for the tests. */
GP_API int gp_rt_is_regular(const gp_rt *rt) GP_RT_NOEXCEPT;

#ifdef __cplusplus
}
#endif
#endif
