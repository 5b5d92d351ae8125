/* triangulation3d.h - what core/ reads of the 3D regular triangulation (internal, not
 * installed): every vertex's neighbours at once, and a rebuild in place, for the Laguerre
 * polyhedra and the balancing of core/laguerre3d.c and core/balance3d.c. */
#ifndef GRAINPACK_CORE_TRIANGULATION3D_H
#define GRAINPACK_CORE_TRIANGULATION3D_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/geometry3d.h"

#ifdef __cplusplus
extern "C" {
#define GP_RT3_NOEXCEPT noexcept
#else
#define GP_RT3_NOEXCEPT
#endif

/* The number of vertices (= spheres). */
size_t gp_rt3_count(const gp_rt3 *rt) GP_RT3_NOEXCEPT;

/* The dimension of the triangulation: -1 empty, 0, 1, 2 (all centres coplanar) or 3. */
int gp_rt3_dimension(const gp_rt3 *rt) GP_RT3_NOEXCEPT;

/* Every vertex's finite neighbours (its "ring", in no particular order, the same for the
 * same triangulation): sphere id's are (*ids)[start[id]] .. (*ids)[start[id + 1] - 1],
 * and infinite[id] is 1 when the vertex is also adjacent to the infinite vertex (its
 * centre is on the convex hull of the centres). `start` (gp_rt3_count + 1 entries) and
 * `infinite` (gp_rt3_count, or NULL when not wanted) are the caller's; *ids is allocated
 * here and the caller frees it. Returns 0, GP_ENOMEM or GP_ECANCELED (the flag of
 * `progress`, which may be NULL, read every GP_RT3_RINGS_PER_CHECK vertices); *ids is then
 * NULL. */
int gp_rt3_rings(const gp_rt3 *rt, size_t *start, uint8_t *infinite, int32_t **ids,
                 const gp_progress *progress) GP_RT3_NOEXCEPT;

/* Vertices walked between two reads of the cancel flag: a few milliseconds of work. */
#define GP_RT3_RINGS_PER_CHECK 8192

/* The finite tetrahedra, four sphere ids each, into *tets (allocated here, the caller's
 * to free), *count of them. Returns 0 or GP_ENOMEM (*tets NULL). */
int gp_rt3_tetrahedra(const gp_rt3 *rt, int32_t **tets, size_t *count) GP_RT3_NOEXCEPT;

/* Builds rt again from spheres[0..n-1] (n must be the count it was built with; the centres
 * may have moved, the radii not). Returns as gp_rt3_build; on failure rt must only be
 * freed. No progress is reported; the cancel flag is read. */
int gp_rt3_rebuild(gp_rt3 *rt, const gp_sphere *spheres, size_t n, const gp_progress *progress,
                   gp_error *err);

/* Whether rt is a valid regular triangulation with no hidden vertex (CGAL's own check).
 * Costly; for the tests. */
int gp_rt3_is_valid(const gp_rt3 *rt) GP_RT3_NOEXCEPT;

#ifdef __cplusplus
}
#endif
#endif
