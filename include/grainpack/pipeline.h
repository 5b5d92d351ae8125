/* pipeline.h - one job from spec to result: pack, then (when the spec asks) balance and
 * Laguerre cells on one regular triangulation, then statistics. The service and the
 * command line call this very function. */
#ifndef GRAINPACK_PIPELINE_H
#define GRAINPACK_PIPELINE_H

#include "grainpack/api.h"
#include "grainpack/balance.h"
#include "grainpack/error.h"
#include "grainpack/laguerre.h"
#include "grainpack/mesh.h"
#include "grainpack/pack.h"
#include "grainpack/progress.h"
#include "grainpack/spec.h"
#include "grainpack/stats.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GP_MAX_STAGES 8

/* Wall-clock time spent in one stage. */
typedef struct gp_stage_time {
    const char *stage; /* static string: "pack", "triangulation", "balance", "laguerre", "mesh",
                          "stats" */
    double seconds;
} gp_stage_time;

typedef struct gp_result {
    gp_packing packing;   /* owned; balanced in place when the balance stage ran */
    gp_pack_stats stats;  /* owned */
    int has_balance;      /* the balance stage ran: `balance` holds F and its statistics */
    gp_balance_result balance; /* owned */
    int has_cells;        /* the Laguerre stage ran: `cells` and `cell_stats` are set */
    gp_cells cells;       /* owned */
    gp_cell_stats cell_stats; /* owned */
    int has_mesh;         /* the mesh stage ran: `mesh` is set */
    gp_mesh mesh;         /* owned */
    gp_stage_time timings[GP_MAX_STAGES];
    int ntimings;
} gp_result;

/* Runs every stage the spec asks for. `max_disks` caps the packing (0: none). On success
 * returns 0 and `result` owns everything in it (free with gp_result_free); on failure
 * returns the failing stage's code with err filled, and `result` is zeroed. */
GP_API int gp_pipeline_run(const gp_spec *spec, size_t max_disks, const gp_progress *progress,
                           gp_result *result, gp_error *err);

/* Rebuilds, from the final disks in result->packing (what a store keeps) and the spec,
 * what the stages after packing derived from them: F and its statistics when the spec
 * balances, the Laguerre cells and their statistics when it builds cells, the mesh when
 * it meshes. The same disks
 * give the same bytes as the run did. What only the run saw (F before balancing, the
 * sweeps) is not rebuilt: result->balance.after_only is set and the writers leave it
 * out. Returns 0 or the stage's error code with err filled (result then keeps only
 * what it had). */
GP_API int gp_result_rederive(const gp_spec *spec, gp_result *result, gp_error *err);

GP_API void gp_result_free(gp_result *result);

/* Seconds spent in `stage`, or 0 if it did not run. */
GP_API double gp_result_stage_seconds(const gp_result *result, const char *stage);

#ifdef __cplusplus
}
#endif
#endif
