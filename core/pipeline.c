/* pipeline.c - spec -> packing -> (balance, Laguerre cells, mesh) -> statistics, timing
 * each stage. */
#include "grainpack/pipeline.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void record(gp_result *result, const char *stage, double since)
{
    if (result->ntimings < GP_MAX_STAGES)
        result->timings[result->ntimings++] = (gp_stage_time){stage, now_seconds() - since};
}

/* The check between two stages: a flag raised at the very end of one stops the next
 * before it allocates anything. */
static int between_stages(const gp_progress *progress, const char *next, gp_error *err)
{
    if (gp_canceled(gp_progress_cancel(progress)))
        return gp_error_set(err, GP_ECANCELED, NULL, "canceled before the %s stage", next);
    return 0;
}

static int mesh(const gp_spec *spec, gp_result *result, const gp_rt *rt,
                const gp_progress *progress, gp_error *err)
{
    gp_mesh_input in = {
        .domain = &spec->domain,
        .disks = result->packing.disks,
        .ndisks = result->packing.count,
        .cells = result->has_cells ? &result->cells : NULL,
        .rt = rt,
        .max_elements = spec->max_elements > SIZE_MAX / GP_MESH_CAP_SLACK
                            ? SIZE_MAX : spec->max_elements * GP_MESH_CAP_SLACK,
    };
    int rc = gp_mesh_build(&in, &spec->mesh, progress, &result->mesh, err);
    result->has_mesh = rc == 0;
    return rc;
}

/* Whether a stage needs the regular triangulation of the disks: balancing and the cells
 * of a periodic domain build their own, with the ghost layer (docs/method.md §4.7, §5.1). */
static int needs_rt(const gp_spec *spec)
{
    return spec->mesh_enabled ||
           (!spec->domain.periodic && (spec->balance_enabled || spec->laguerre_enabled));
}

int gp_pipeline_run(const gp_spec *spec, size_t max_disks, const gp_progress *progress,
                    gp_result *result, gp_error *err)
{
    memset(result, 0, sizeof *result);
    gp_pack_params params = gp_spec_pack_params(spec, max_disks);
    gp_rt *rt = NULL;
    gp_packing *pk = &result->packing;
    double t0 = now_seconds();
    int rc = gp_pack(&params, progress, pk, err);
    if (rc)
        goto fail;
    record(result, "pack", t0);

    if (needs_rt(spec)) {
        /* one triangulation serves every stage: balancing keeps it up to date; the mesh of
           disks in a matrix finds their contacts in it */
        t0 = now_seconds();
        if ((rc = between_stages(progress, "triangulation", err)) ||
            (rc = gp_rt_build(pk->disks, pk->count, progress, &rt, err)))
            goto fail;
        record(result, "triangulation", t0);
    }
    if (spec->balance_enabled) {
        t0 = now_seconds();
        if ((rc = between_stages(progress, "balance", err)))
            goto fail;
        if ((rc = gp_balance(&spec->domain, pk->disks, pk->count, rt, &spec->balance, progress,
                             &result->balance, err)))
            goto fail;
        result->has_balance = 1;
        record(result, "balance", t0);
    }
    if (spec->laguerre_enabled) {
        t0 = now_seconds();
        if ((rc = between_stages(progress, "laguerre", err)) ||
            (rc = gp_laguerre(&spec->domain, pk->disks, pk->count, rt, &spec->laguerre, progress,
                              &result->cells, err)))
            goto fail;
        result->has_cells = 1;
        record(result, "laguerre", t0);
    }
    if (spec->mesh_enabled) {
        t0 = now_seconds();
        if ((rc = mesh(spec, result, rt, progress, err)))
            goto fail;
        record(result, "mesh", t0);
    }
    gp_rt_free(rt);
    rt = NULL;

    /* the statistics are a few passes over the disks and cells (milliseconds for a
     * million disks): not interrupted inside */
    t0 = now_seconds();
    if ((rc = between_stages(progress, "statistics", err)))
        goto fail;
    rc = gp_pack_stats_compute(&spec->domain, &spec->dist, pk, &result->stats);
    if (rc == 0 && result->has_cells)
        rc = gp_cell_stats_compute(&spec->domain, &spec->dist, pk->disks, &result->cells,
                                   &result->cell_stats);
    if (rc) {
        gp_error_set(err, rc, NULL, "out of memory computing statistics");
        goto fail;
    }
    record(result, "stats", t0);
    return 0;

fail:
    gp_rt_free(rt);
    gp_result_free(result);
    return rc;
}

int gp_result_rederive(const gp_spec *spec, gp_result *result, gp_error *err)
{
    gp_packing *pk = &result->packing;
    if (!spec->balance_enabled && !spec->laguerre_enabled && !spec->mesh_enabled)
        return 0;
    gp_rt *rt = NULL;
    int rc = needs_rt(spec) ? gp_rt_build(pk->disks, pk->count, NULL, &rt, err) : 0;
    if (rc)
        return rc;
    if (spec->balance_enabled) {
        gp_balance_result *b = &result->balance;
        memset(b, 0, sizeof *b);
        b->method = spec->balance.method;
        b->max_step = spec->balance.max_step;
        b->count = pk->count;
        b->after_only = 1;
        b->F = malloc((pk->count ? pk->count : 1) * sizeof *b->F);
        rc = b->F ? gp_quality(&spec->domain, rt, pk->disks, pk->count, b->F, &b->after, NULL, err)
                  : gp_error_set(err, GP_ENOMEM, NULL, "out of memory for F");
        if (rc)
            gp_balance_result_free(b);
        result->has_balance = rc == 0;
    }
    if (rc == 0 && spec->laguerre_enabled) {
        rc = gp_laguerre(&spec->domain, pk->disks, pk->count, rt, &spec->laguerre, NULL,
                         &result->cells, err);
        if (rc == 0 && (rc = gp_cell_stats_compute(&spec->domain, &spec->dist, pk->disks,
                                                   &result->cells, &result->cell_stats))) {
            gp_error_set(err, rc, NULL, "out of memory computing cell statistics");
            gp_cells_free(&result->cells);
        }
        result->has_cells = rc == 0;
    }
    if (rc == 0 && spec->mesh_enabled)
        rc = mesh(spec, result, rt, NULL, err);
    gp_rt_free(rt);
    return rc;
}

void gp_result_free(gp_result *result)
{
    gp_packing_free(&result->packing);
    gp_pack_stats_free(&result->stats);
    gp_balance_result_free(&result->balance);
    gp_cells_free(&result->cells);
    gp_cell_stats_free(&result->cell_stats);
    gp_mesh_free(&result->mesh);
    memset(result, 0, sizeof *result);
}

double gp_result_stage_seconds(const gp_result *result, const char *stage)
{
    for (int i = 0; i < result->ntimings; i++)
        if (strcmp(result->timings[i].stage, stage) == 0)
            return result->timings[i].seconds;
    return 0.0;
}
