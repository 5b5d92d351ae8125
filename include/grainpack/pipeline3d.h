/* pipeline3d.h - one 3D job from spec to result (docs/3d.md): pack the box, then (when
 * the spec asks) balance and build the Laguerre polyhedra on one regular triangulation,
 * then statistics. The command line and the service call this very function. */
#ifndef GRAINPACK_PIPELINE3D_H
#define GRAINPACK_PIPELINE3D_H

#include "grainpack/api.h"
#include "grainpack/balance.h"
#include "grainpack/error.h"
#include "grainpack/geometry3d.h"
#include "grainpack/pack3d.h"
#include "grainpack/pipeline.h"
#include "grainpack/progress.h"
#include "grainpack/spec3d.h"
#include "grainpack/stats.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a 3D packing achieved: densities, radii and fidelity to the law (as gp_pack_stats
 * in 2D, volumes for areas). */
typedef struct gp_pack3d_stats {
    size_t count;
    double box_volume;
    double packing_density;      /* sum 4/3 pi R^3 / volume */
    double grain_fraction;       /* sum 4/3 pi r^3 / volume */
    double r_min, r_max, r_mean; /* grain radii (0 without spheres) */
    double joint_min, joint_max; /* of R - r (0 without spheres) */
    size_t nbins;
    gp_bin_stat *bins;           /* owned: the radii against the law's report bins */
    double chi2;                 /* Pearson's statistic over bins with target > 0 */
    int dof;                     /* bins with target > 0, minus one */
    double p_value;              /* P(chi2_dof >= chi2); 1 when dof = 0 */
    double max_abs_z;
} gp_pack3d_stats;

/* Computes the statistics of `packing` against `dist` in `box`. Returns 0 or GP_ENOMEM;
 * `out` owns its bins (free with gp_pack3d_stats_free). */
GP_API int gp_pack3d_stats_compute(const gp_box *box, const gp_distribution *dist,
                                   const gp_packing3d *packing, gp_pack3d_stats *out);
GP_API void gp_pack3d_stats_free(gp_pack3d_stats *stats);

typedef struct gp_result3d {
    gp_packing3d packing;        /* owned; balanced in place when the balance stage ran */
    gp_pack3d_stats stats;       /* owned */
    int has_balance;             /* the balance stage ran: `balance` holds F and its stats */
    gp_balance_result balance;   /* owned */
    int has_cells;               /* the Laguerre stage ran: `cells` and `cell_stats` are set */
    gp_cells3d cells;            /* owned, shrunk as the spec asks */
    gp_cell3d_stats cell_stats;  /* owned */
    gp_stage_time timings[GP_MAX_STAGES];
    int ntimings;
} gp_result3d;

/* Runs every stage the spec asks for: the packing, then on one regular triangulation the
 * balancing ("balance", the spheres moved in place) and the polyhedra ("laguerre"). `max_spheres` caps the packing (0: none). On
 * success returns 0 and `result` owns everything in it (free with gp_result3d_free); on
 * failure returns the failing stage's code with err filled, and `result` is zeroed. A
 * periodic box with balancing or polyhedra is GP_EINVAL: not yet (docs/3d.md §11). */
GP_API int gp_pipeline3d_run(const gp_spec3d *spec, size_t max_spheres, const gp_progress *progress,
                             gp_result3d *result, gp_error *err);

/* The unshrunk power polyhedra of the result's spheres (what Neper's .tess describes):
 * built again from the spheres (a triangulation and the Laguerre stage without shrink).
 * Returns 0 and *out (free with gp_cells3d_free), or the geometry's error with err
 * filled. */
GP_API int gp_result3d_power_cells(const gp_spec3d *spec, const gp_result3d *result, gp_cells3d *out,
                                   gp_error *err);

GP_API void gp_result3d_free(gp_result3d *result);

/* Seconds spent in `stage`, or 0 if it did not run. */
GP_API double gp_result3d_stage_seconds(const gp_result3d *result, const char *stage);

#ifdef __cplusplus
}
#endif
#endif
