/* pipeline3d.c - a 3D spec -> packing -> (balance, Laguerre polyhedra) -> statistics,
 * timing each stage. */
#include "grainpack/pipeline3d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void record(gp_result3d *result, const char *stage, double since)
{
    if (result->ntimings < GP_MAX_STAGES)
        result->timings[result->ntimings++] = (gp_stage_time){stage, now_seconds() - since};
}

int gp_pack3d_stats_compute(const gp_box *box, const gp_distribution *dist,
                            const gp_packing3d *packing, gp_pack3d_stats *out)
{
    memset(out, 0, sizeof *out);
    if (gp_bin_table_init(dist, &out->bins, &out->nbins))
        return GP_ENOMEM;
    size_t n = packing->count;
    double sum_R3 = 0.0, sum_r3 = 0.0, sum_r = 0.0;
    out->count = n;
    out->box_volume = box->width * box->height * box->depth;
    for (size_t i = 0; i < n; i++) {
        const gp_sphere *s = &packing->spheres[i];
        sum_R3 += s->R * s->R * s->R;
        sum_r3 += s->r * s->r * s->r;
        sum_r += s->r;
        double joint = s->R - s->r;
        if (i == 0 || s->r < out->r_min)
            out->r_min = s->r;
        if (i == 0 || s->r > out->r_max)
            out->r_max = s->r;
        if (i == 0 || joint < out->joint_min)
            out->joint_min = joint;
        if (i == 0 || joint > out->joint_max)
            out->joint_max = joint;
        long b = gp_bin_table_find(out->bins, out->nbins, s->r);
        if (b >= 0)
            out->bins[b].count++;
    }
    out->packing_density = 4.0 / 3.0 * M_PI * sum_R3 / out->box_volume;
    out->grain_fraction = 4.0 / 3.0 * M_PI * sum_r3 / out->box_volume;
    out->r_mean = n ? sum_r / (double)n : 0.0;
    gp_bin_table_finish(out->bins, out->nbins, n, &out->max_abs_z);
    gp_bin_table_chi2(out->bins, out->nbins, n, &out->chi2, &out->dof, &out->p_value);
    return 0;
}

void gp_pack3d_stats_free(gp_pack3d_stats *stats)
{
    free(stats->bins);
    memset(stats, 0, sizeof *stats);
}

/* The stages on the triangulation: balancing (the spheres moved in place, `rt` kept up to
 * date) then the polyhedra as `params` shrinks them. `timed` (NULL: no times) gets the
 * stages' times; `balance` (NULL: no balancing) gets the balancing's result. */
static int on_triangulation(const gp_spec3d *spec, gp_packing3d *packing, gp_balance_result *balance,
                            const gp_laguerre_params *params, const gp_progress *progress,
                            gp_cells3d *out, gp_result3d *timed, gp_error *err)
{
    gp_rt3 *rt = NULL;
    double t = now_seconds();
    int rc = gp_rt3_build(packing->spheres, packing->count, progress, &rt, err);
    if (rc)
        return rc;
    if (timed)
        record(timed, "triangulation", t);
    if (balance) {
        t = now_seconds();
        rc = gp_balance3d(&spec->box, packing->spheres, packing->count, rt, &spec->balance, progress,
                          balance, err);
        if (rc) {
            gp_rt3_free(rt);
            return rc;
        }
        if (timed)
            record(timed, "balance", t);
    }
    if (params) {
        t = now_seconds();
        rc = gp_laguerre3d(&spec->box, packing->spheres, packing->count, rt, params, progress, out, err);
        if (!rc && timed)
            record(timed, "laguerre", t);
    }
    gp_rt3_free(rt);
    if (rc && balance)
        gp_balance_result_free(balance);
    return rc;
}

int gp_pipeline3d_run(const gp_spec3d *spec, size_t max_spheres, const gp_progress *progress,
                      gp_result3d *result, gp_error *err)
{
    memset(result, 0, sizeof *result);
    if (spec->box.periodic && (spec->balance_enabled || spec->laguerre_enabled))
        return gp_error_set(err, GP_EINVAL, spec->balance_enabled ? "/balance" : "/laguerre",
                            "is not yet available on periodic boxes (docs/3d.md §11)");
    gp_pack3d_params params = gp_spec3d_pack_params(spec, max_spheres);
    double t = now_seconds();
    int rc = gp_pack3d(&params, progress, &result->packing, err);
    if (rc)
        return rc;
    record(result, "pack", t);
    if (spec->balance_enabled || spec->laguerre_enabled) {
        if (gp_canceled(gp_progress_cancel(progress)))
            rc = gp_error_set(err, GP_ECANCELED, NULL, "canceled after packing");
        else
            rc = on_triangulation(spec, &result->packing, spec->balance_enabled ? &result->balance : NULL,
                                  spec->laguerre_enabled ? &spec->laguerre : NULL, progress,
                                  &result->cells, result, err);
        if (rc) {
            gp_result3d_free(result);
            return rc;
        }
        result->has_balance = spec->balance_enabled;
        result->has_cells = spec->laguerre_enabled;
    }
    t = now_seconds();
    if (gp_pack3d_stats_compute(&spec->box, &spec->dist, &result->packing, &result->stats) ||
        (result->has_cells && gp_cell3d_stats_compute(&spec->box, &spec->dist, result->packing.spheres,
                                                       &result->cells, &result->cell_stats))) {
        gp_result3d_free(result);
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the statistics");
    }
    record(result, "stats", t);
    return 0;
}

int gp_result3d_power_cells(const gp_spec3d *spec, const gp_result3d *result, gp_cells3d *out,
                            gp_error *err)
{
    gp_laguerre_params none = {GP_SHRINK_NONE, 0};
    const gp_packing3d *p = &result->packing;
    gp_rt3 *rt = NULL;
    int rc = gp_rt3_build(p->spheres, p->count, NULL, &rt, err);
    if (rc)
        return rc;
    rc = gp_laguerre3d(&spec->box, p->spheres, p->count, rt, &none, NULL, out, err);
    gp_rt3_free(rt);
    return rc;
}

void gp_result3d_free(gp_result3d *result)
{
    gp_packing3d_free(&result->packing);
    gp_pack3d_stats_free(&result->stats);
    if (result->has_balance)
        gp_balance_result_free(&result->balance);
    if (result->has_cells) {
        gp_cells3d_free(&result->cells);
        gp_cell3d_stats_free(&result->cell_stats);
    }
    memset(result, 0, sizeof *result);
}

double gp_result3d_stage_seconds(const gp_result3d *result, const char *stage)
{
    for (int i = 0; i < result->ntimings; i++)
        if (strcmp(result->timings[i].stage, stage) == 0)
            return result->timings[i].seconds;
    return 0.0;
}
