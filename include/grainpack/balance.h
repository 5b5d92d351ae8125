/* balance.h - balancing the free space around the grains (docs/method.md §4, report §IV): the
 * quality criterion F(p), constrained Laplacian smoothing (Algorithm 2) and the report's
 * relocation (Algorithm 3). */
#ifndef GRAINPACK_BALANCE_H
#define GRAINPACK_BALANCE_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/disk.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/progress.h"
#include "grainpack/triangulation.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_balance_method {
    GP_BALANCE_NONE = 0,   /* measure F only */
    GP_BALANCE_LAPLACIAN,  /* constrained Laplacian smoothing (docs/method.md §4.3), the baseline */
    GP_BALANCE_RELOCATION  /* the report's relocation (docs/method.md §4.4) */
} gp_balance_method;

/* "none", "laplacian" or "relocation". */
GP_API const char *gp_balance_method_name(gp_balance_method method);

/* The report shows F as a histogram of ten bins over [F_min, F_max]. */
#define GP_QUALITY_BINS 10

/* A sweep stops counting a centre as moving once its step would be shorter than this
 * fraction of its packing radius. Why this value: a move of d changes every gap h_i by at
 * most d, so F = (max h - min h) / R by at most 2d / R: 2e-4, below the third decimal
 * the report quotes F with (1.962, 1.87, 1.33). Smaller steps only polish digits nobody
 * reads, at the price of many more sweeps. */
#define GP_BALANCE_MIN_STEP_RTOL 1e-4

/* The default sweep cap of a balancing job. The report's cases stop well before it
 * (bench/); the cap bounds the work on any input. */
#define GP_BALANCE_DEFAULT_MAX_ITERATIONS 200

/* The report's relocation never stops by itself on some structures: a few centres end in
 * cycles (their targets jump as the triangulation flips back and forth), so "until no
 * centre moved" is never reached. A run also stops after this many sweeps in a row that
 * did not improve the best structure seen, and returns to that structure. Why this value:
 * on the report's cases the best structure is reached within a few tens of sweeps and the
 * cycles have periods of two or three sweeps (bench/). */
#define GP_BALANCE_STALL_SWEEPS 20

/* On a large structure the relocation's sweeps never stop moving centres (at 10^6 grains
 * one centre in twelve still moves at sweep 20), and the structure stops improving long
 * before the stall rule ends it: F_max is held from the first sweeps on by one void no
 * move closes, and the mean F, lowest after 2 to 4 sweeps, creeps back up (1e-4 a sweep
 * at 10^5 grains, 5e-5 at 10^6) while it swings by up to 3e-4 from one sweep to the next,
 * centres in cycles of two sweeps jumping back and forth (variable law, 2026-11-24).
 * A relocation of at least GP_BALANCE_STEADY_MIN_INTERIOR interior centres also stops,
 * "steady", after GP_BALANCE_STEADY_SWEEPS sweeps in a row that did not lower the lowest
 * F_max seen and lowered the lowest mean F seen by less than GP_BALANCE_STEADY_RTOL of it
 * (relative); it returns to the best structure seen, as the other stops do. (A first rule
 * asked the means of the last five structures to lie within 5e-4 of each other: the
 * swings and the creep kept it from firing on the densest packings.) Why these values: on
 * 39 relocations (3x10^4, 5x10^4 and 10^5 grains with both first steps, the Bagi case,
 * 10^6 grains) this rule returns the structure the stall rule returned but in one (5x10^4
 * grains: F_max 2.86 for 2.82, and a lower mean), after 7 to 28 sweeps instead of 10 to
 * 42; with 4 sweeps instead of 6 it lost two more (bench/GEOM_RESULTS.md). On a thousand
 * grains, and still on 10^4, the best structure comes by chance after long runs without
 * progress (variable, 10^4 grains: best at sweeps 25 and 31 in two of 12 runs, F_max 2.79
 * and 2.72 where this rule would stop at 3.38 and 2.92; the reference cases: up to 16
 * sweeps without progress before the best), so smaller structures keep the stall rule
 * alone. Laplacian smoothing does not take this rule: its moves die out and it ends
 * "converged". */
#define GP_BALANCE_STEADY_RTOL 5e-4
#define GP_BALANCE_STEADY_SWEEPS 6
#define GP_BALANCE_STEADY_MIN_INTERIOR 25000

/* Changes of F_max or mean F below this do not count as an improvement (the reason of
 * GP_BALANCE_MIN_STEP_RTOL: digits the report does not quote). */
#define GP_BALANCE_QUALITY_TOL 1e-4

/* The largest step toward the target, as a fraction w of the way; smaller ones follow
 * by 0.05 down to 0.05. The report (Algorithm 3, docs/method.md §4.4) starts at w = 0.30. Our
 * default starts at the whole way: on the report's fixed-radius case the report's 0.30
 * leaves F_max at 1.64 where the whole way reaches 1.32 (the report: 1.33), and F_max
 * ends lower on every reference case (variable 2.80 against 3.90, iron 1.89 against
 * 2.97); the mean F too, but for the fixed case (0.128 against 0.121)
 * (bench/GEOM_RESULTS.md, docs/method.md §4.6). */
#define GP_BALANCE_REPORT_MAX_STEP 0.30
#define GP_BALANCE_DEFAULT_MAX_STEP 1.0

/* F over the interior centres: how many there are, the extremes, the mean, and how many
 * fall in each tenth of [min, max] (the last bin closed). All zero when there are none. */
typedef struct gp_quality_stats {
    size_t interior;
    double min, max, mean;
    size_t histogram[GP_QUALITY_BINS];
} gp_quality_stats;

/* F(p) (docs/method.md §4.2) for every disk of the triangulation `rt` of disks[0..n-1]: for an
 * interior centre p with neighbours p_i, h_i = |p - p_i| - R_p - R_i and
 * F(p) = (max h_i - min h_i) / R_p; NAN elsewhere. A centre is interior when its power
 * cell is bounded and inside the domain (so not on the convex hull): along a wall the
 * triangulation has long thin triangles across the empty outside, and a centre touching
 * one has "neighbours" far along the wall whose gaps say nothing of the free space around
 * it. These centres (the layer along the walls) are also the ones balancing leaves in
 * place. F may be NULL when only the statistics are wanted.
 * On a periodic domain (docs/method.md §4.7) `rt` is not used (it may be NULL): F is
 * measured among all the periodic images, from a ghost layer and its own triangulation,
 * and a centre is interior when its cell is inside the domain along the walled axes
 * (every centre of a torus). Returns 0, GP_ENOMEM or GP_ECANCELED (*cancel, which may be
 * NULL, is read every GP_QUALITY_CENTRES_PER_CHECK centres), or on a periodic domain a
 * gp_rt_build error or GP_EGEOM (a cell reaches beyond a whole period of images). */
GP_API int gp_quality(const gp_domain *domain, const gp_rt *rt, const gp_disk *disks, size_t n,
                      double *F, gp_quality_stats *stats, const gp_cancel_flag *cancel,
                      gp_error *err);

/* Centres measured between two reads of the cancel flag: a few milliseconds of work. */
#define GP_QUALITY_CENTRES_PER_CHECK 16384

typedef struct gp_balance_params {
    gp_balance_method method;
    uint32_t max_iterations; /* sweep cap; 0 takes GP_BALANCE_DEFAULT_MAX_ITERATIONS */
    double max_step;         /* first step tried, in (0, 1]; 0 takes GP_BALANCE_DEFAULT_MAX_STEP */
    gp_rt_update update;     /* how the triangulation follows the moves (see bench/) */
} gp_balance_params;

/* Why the sweeps stopped. */
typedef enum gp_balance_stop {
    GP_BALANCE_STOP_CONVERGED = 0, /* a sweep moved no centre */
    GP_BALANCE_STOP_STALLED,       /* GP_BALANCE_STALL_SWEEPS sweeps without improvement */
    GP_BALANCE_STOP_CAP,           /* max_iterations reached */
    GP_BALANCE_STOP_STEADY         /* GP_BALANCE_STEADY_SWEEPS sweeps without meaningful progress */
} gp_balance_stop;

/* "converged", "stalled", "max_iterations" or "steady". */
GP_API const char *gp_balance_stop_name(gp_balance_stop stop);

typedef struct gp_balance_result {
    gp_balance_method method;
    double max_step;
    gp_quality_stats before, after;
    double *F;              /* owned: F after balancing, one per disk, NAN on the hull */
    size_t count;           /* entries of F */
    uint32_t sweeps;        /* sweeps done */
    uint32_t best_sweep;    /* the sweep that left the structure returned (0: the input) */
    gp_balance_stop stop;
    uint64_t moves;         /* centre moves over all sweeps */
    uint64_t refused;       /* centres that had somewhere to go but no conflict-free step */
    gp_rt_update_stats triangulation; /* how the triangulation followed */
    int after_only;         /* rebuilt from the final disks (gp_result_rederive): only
                               `method`, `F` and `after` are known, not the run itself */
} gp_balance_result;

/* Balances disks[0..n-1] in `domain` in place: moves interior centres (radii never
 * change), sweep after sweep, until a sweep moves none, GP_BALANCE_STALL_SWEEPS sweeps
 * bring no progress, a relocation is steady (GP_BALANCE_STEADY_SWEEPS) or the cap is
 * reached, and leaves the best structure seen (lowest F_max, then lowest mean; the input
 * counts, so F_max never rises). A move is taken only
 * if the moved packing disk overlaps no other (GP_CONTACT_RTOL) and stays in the domain,
 * so the packing stays valid at every step. `rt` must be the triangulation
 * of the disks (gp_rt_build); it is borrowed and left up to date with the final
 * positions. F is measured before and after. Reports progress as stage "balance" and
 * honours progress->cancel.
 *
 * On a periodic domain (docs/method.md §4.7) `rt` is not used (it may be NULL): the sweeps
 * run on a ghost layer of the disks and its own triangulation, each ghost moved with its
 * disk; `params->update` GP_RT_UPDATE_FLIPS updates that triangulation by flips and makes
 * the layer again only when a disk has drifted far, GP_RT_UPDATE_REBUILD makes the layer
 * again every sweep (counted in triangulation.rebuilds either way). Overlaps are between
 * nearest images, and the disks come back with their centres wrapped into the domain.
 *
 * On success returns 0 and `out` owns its F array (free with gp_balance_result_free).
 * On failure returns GP_ENOMEM, GP_ECANCELED, GP_ETOOBIG (bucket grid too large) or a
 * triangulation error (GP_EGEOM, GP_EINTERNAL), fills err, zeroes `out`; the disks are
 * then valid but partly balanced, and rt must only be freed. */
GP_API int gp_balance(const gp_domain *domain, gp_disk *disks, size_t n, gp_rt *rt,
                      const gp_balance_params *params, const gp_progress *progress,
                      gp_balance_result *out, gp_error *err);

GP_API void gp_balance_result_free(gp_balance_result *result);

#ifdef __cplusplus
}
#endif
#endif
