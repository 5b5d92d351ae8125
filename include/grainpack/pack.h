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

/* Where the front may put the radius it holds before it closes (docs/method.md §3.5). */
typedef enum gp_front_rule {
    /* the report's level rule: segments of the front's level, and up to level_band levels
     * above it, take the radius; then the front closes at its first segment */
    GP_FRONT_LEVEL_BAND = 0,
    /* the waiting rule: when the first segment would still take a radius of the law's
     * alive_quantile, it waits for one, and segments up to wait_levels above take the
     * radius before the front closes there */
    GP_FRONT_WAIT,
    /* the default: the waiting rule with the parameters that pack the law densest, as
     * gp_pack_default_rule measures them */
    GP_FRONT_DEFAULT
} gp_front_rule;

/* What to pack. Everything is borrowed for the duration of gp_pack. */
typedef struct gp_pack_params {
    const gp_domain *domain;
    const gp_distribution *dist; /* prepared (gp_distribution_prepare) */
    const gp_joint *joint;       /* NULL: no joint */
    uint64_t seed;
    size_t max_disks;            /* fail with GP_ETOOBIG beyond this many disks; 0: no cap */
    uint32_t level_band;         /* GP_FRONT_LEVEL_BAND: segments up to this many levels
                                    above the front's level may take a radius before the
                                    front is closed (0: the report's rule, docs/method.md
                                    §3.3) */
    gp_front_rule rule;          /* GP_FRONT_LEVEL_BAND (0) unless set */
    uint32_t wait_levels;        /* GP_FRONT_WAIT: 1 to GP_PACK_MAX_WAIT_LEVELS */
    double alive_quantile;       /* GP_FRONT_WAIT: in [0, 1) */
} gp_pack_params;

/* The widest wait a rule may give (the default's candidates go up to it). */
#define GP_PACK_MAX_WAIT_LEVELS 16

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
/* The shortest periodic side, in largest packing radii (docs/method.md §3.8): 12 radii
 * make at least three grid cells of 2 R_max per period (no image counted twice) and keep
 * every front segment (under 4 R_max) and every contact (2 R_max) under half a period,
 * so that the nearest image of a neighbour is the only one that can touch. */
#define GP_PACK_MIN_PERIOD_RADII 12.0

/* Why a law cannot be packed in a domain (gp_pack_check_law). */
typedef enum gp_pack_law_limit {
    GP_PACK_LAW_OK = 0,
    GP_PACK_LAW_RATIO,     /* R_max / R_min above GP_PACK_MAX_RADIUS_RATIO */
    GP_PACK_LAW_PRECISION, /* a domain side above GP_PACK_MAX_SIDE_RADII smallest radii */
    GP_PACK_LAW_PERIOD     /* a periodic side under GP_PACK_MIN_PERIOD_RADII largest radii */
} gp_pack_law_limit;

/* Checks the three bounds above for `dist` (with `joint`, which may be NULL) in `domain`.
 * Returns GP_PACK_LAW_OK, or the bound broken with err's message saying which and why
 * (err's pointer left empty for the caller to name the field). */
GP_API gp_pack_law_limit gp_pack_check_law(const gp_domain *domain, const gp_distribution *dist,
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
    gp_front_rule rule;      /* the rule used: GP_FRONT_LEVEL_BAND or GP_FRONT_WAIT */
    uint32_t wait_levels;    /* GP_FRONT_WAIT: its parameters (for the default, the ones */
    double alive_quantile;   /*   gp_pack_default_rule chose) */
    double fill_area;        /* sum of pi R^2 over the disks */
} gp_packing;

/* Packs the domain (docs/method.md §3.5) until the front is empty, with params->rule (the
 * default runs gp_pack_default_rule first). On success returns 0 and `out` owns its disks
 * (free with gp_packing_free). On failure returns GP_ENOMEM, GP_ECANCELED, GP_ETOOBIG
 * (max_disks reached), GP_EINVAL (a law gp_pack_check_law refuses, a disk larger than the
 * domain, or waiting-rule parameters out of range) or GP_EINTERNAL (the front failed to
 * close: a bug), sets err, and leaves `out` zeroed. */
GP_API int gp_pack(const gp_pack_params *params, const gp_progress *progress, gp_packing *out,
                   gp_error *err);

/* The parameters of the waiting rule that pack `dist` (with `joint`, NULL for none)
 * densest: a few candidates, each packed in two pilot squares of about
 * GP_PACK_PILOT_DISKS disks with fixed seeds, the densest kept (docs/method.md §3.5). The
 * choice depends on the law only, not on a domain or a seed. A law of one radius has
 * nothing to choose and takes the first candidate without a pilot. `progress` may be
 * NULL; only its cancel flag is read. Returns 0, GP_ECANCELED, GP_ENOMEM or GP_EINVAL (a
 * law gp_pack refuses), with err set. */
GP_API int gp_pack_default_rule(const gp_distribution *dist, const gp_joint *joint,
                                const gp_progress *progress, uint32_t *wait_levels,
                                double *alive_quantile, gp_error *err);

/* Disks in each pilot packing of gp_pack_default_rule: enough that the densities of the
 * candidates are told apart (their spread over seeds is ~0.003 at this size, the
 * differences that matter 0.005 and more), few enough to cost about 10 ms in all. */
#define GP_PACK_PILOT_DISKS 1500

/* Frees the disks of a packing and zeroes it. */
GP_API void gp_packing_free(gp_packing *packing);

#ifdef __cplusplus
}
#endif
#endif
