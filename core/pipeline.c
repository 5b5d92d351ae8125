/* pipeline.c - spec -> packing -> statistics, timing each stage. */
#include "grainpack/pipeline.h"

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

int gp_pipeline_run(const gp_spec *spec, size_t max_disks, const gp_progress *progress,
                    gp_result *result, gp_error *err)
{
    memset(result, 0, sizeof *result);
    gp_pack_params params = {
        .domain = &spec->domain,
        .dist = &spec->dist,
        .joint = &spec->joint,
        .seed = spec->seed,
        .max_disks = max_disks,
        .level_band = spec->level_band,
    };
    double t0 = now_seconds();
    int rc = gp_pack(&params, progress, &result->packing, err);
    if (rc)
        goto fail;
    record(result, "pack", t0);

    t0 = now_seconds();
    rc = gp_pack_stats_compute(&spec->domain, &spec->dist, &result->packing, &result->stats);
    if (rc) {
        gp_error_set(err, rc, NULL, "out of memory computing statistics");
        goto fail;
    }
    record(result, "stats", t0);
    return 0;

fail:
    gp_result_free(result);
    return rc;
}

void gp_result_free(gp_result *result)
{
    gp_packing_free(&result->packing);
    gp_pack_stats_free(&result->stats);
    memset(result, 0, sizeof *result);
}

double gp_result_stage_seconds(const gp_result *result, const char *stage)
{
    for (int i = 0; i < result->ntimings; i++)
        if (strcmp(result->timings[i].stage, stage) == 0)
            return result->timings[i].seconds;
    return 0.0;
}
