/* pack.h - the advancing-front disk packer (docs/method.md §3, report §III). */
#ifndef GRAINPACK_PACK_H
#define GRAINPACK_PACK_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/disk.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What to pack. Everything is borrowed for the duration of gp_pack. */
typedef struct gp_pack_params {
    const gp_domain *domain;
    const gp_distribution *dist; /* prepared (gp_distribution_prepare) */
    const gp_joint *joint;       /* NULL: no joint */
    uint64_t seed;
    size_t max_disks;            /* fail with GP_ETOOBIG beyond this many disks; 0: no cap */
    uint32_t level_band;         /* segments up to this many levels above the front's level
                                    may take a radius before the front is closed (0: the
                                    report's rule, docs/method.md §3.3) */
} gp_pack_params;

/* A packing: the disks in the order they were placed, and how the front got there. */
typedef struct gp_packing {
    gp_disk *disks;          /* owned; count entries */
    size_t count;
    size_t initial_front;    /* disks laid along the boundary (level 0) */
    uint64_t attempts;       /* candidate placements tested for conflicts */
    uint64_t closures;       /* front closings (docs/method.md §3.5, last branch) */
    uint64_t frozen;         /* closings that found no disk to close on and froze the segment */
    uint64_t capped;         /* closings refused by the per-disk safety cap: 0 unless the
                                front tangled, which the tests check never happens */
    uint32_t max_level;      /* highest disk level reached */
    double fill_area;        /* sum of pi R^2 over the disks */
} gp_packing;

/* Packs the domain (docs/method.md §3.5) until the front is empty. On success returns 0 and `out`
 * owns its disks (free with gp_packing_free). On failure returns GP_EINVAL (the largest
 * packing disk does not fit in the domain), GP_ETOOBIG (max_disks reached, or the bucket
 * grid would be too large for the domain), GP_ENOMEM or GP_ECANCELED, sets err, and leaves
 * `out` zeroed. */
GP_API int gp_pack(const gp_pack_params *params, const gp_progress *progress, gp_packing *out,
                   gp_error *err);

/* Frees the disks of a packing and zeroes it. */
GP_API void gp_packing_free(gp_packing *packing);

#ifdef __cplusplus
}
#endif
#endif
