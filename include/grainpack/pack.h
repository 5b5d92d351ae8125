/* pack.h - the advancing-front disk packer (docs/method.md §3, report §III). */
#ifndef GRAINPACK_PACK_H
#define GRAINPACK_PACK_H

#include <stddef.h>
#include <stdint.h>

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

/* The widest span R_max / R_min of packing radii the packer takes (docs/method.md §3.7).
 * Its work per placed disk is bounded by a constant times the square of this ratio (the
 * disks a candidate position is tested against lie in cells sized by R_max, and as many as
 * 36 (R_max / R_min)^2 / pi small ones fit there); at 100, a law of nearly only its smallest
 * radius, the worst case, still packs a few thousand disks a second (bench/RESULTS.md). */
#define GP_PACK_MAX_RADIUS_RATIO 100.0
/* The longest domain side, in smallest packing radii (docs/method.md §3.7). Disks are placed
 * in doubles, whose rounding is relative to the coordinates: at 10^6 radii a tangent disk
 * is off by ~3e-11 of its radius (measured), 30 times inside GP_CONTACT_RTOL; at 10^8 the
 * rounding exceeds the tolerance, disks overlap and a wall can stall. */
#define GP_PACK_MAX_SIDE_RADII 1e6

/* Why a law cannot be packed in a domain (gp_pack_check_law). */
typedef enum gp_pack_law_limit {
    GP_PACK_LAW_OK = 0,
    GP_PACK_LAW_RATIO,     /* R_max / R_min above GP_PACK_MAX_RADIUS_RATIO */
    GP_PACK_LAW_PRECISION  /* a domain side above GP_PACK_MAX_SIDE_RADII smallest radii */
} gp_pack_law_limit;

/* Checks the two bounds above for `dist` (with `joint`, which may be NULL) in `domain`.
 * Returns GP_PACK_LAW_OK, or the bound broken with err's message saying which and why
 * (err's pointer left empty for the caller to name the field). */
gp_pack_law_limit gp_pack_check_law(const gp_domain *domain, const gp_distribution *dist,
                                    const gp_joint *joint, gp_error *err);

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
 * owns its disks (free with gp_packing_free). On failure returns GP_ENOMEM, GP_ECANCELED,
 * GP_ETOOBIG (max_disks reached), GP_EINVAL (a law gp_pack_check_law refuses, or a disk
 * larger than the domain) or GP_EINTERNAL (the front failed to close: a bug), sets
 * err, and leaves `out` zeroed. */
int gp_pack(const gp_pack_params *params, const gp_progress *progress, gp_packing *out,
            gp_error *err);

/* Frees the disks of a packing and zeroes it. */
void gp_packing_free(gp_packing *packing);

#ifdef __cplusplus
}
#endif
#endif
