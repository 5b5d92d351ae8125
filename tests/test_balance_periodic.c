/* test_balance_periodic.c - both balancing methods on periodic domains (docs/method.md
 * §4.7): on the torus and on strips periodic along one axis, over the reference laws and
 * several seeds, no overlap in the 3 x 3 tiling (no minimum image), centres inside, radii
 * untouched, F_max never higher, F defined for every grain of a torus and equal to the F
 * of the tiling measured as a walled structure, the cells still tiling the torus; and a
 * periodic spec with balancing runs through the pipeline. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/balance.h"
#include "grainpack/laguerre.h"
#include "grainpack/pack.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "packing_checks.h"

#define SEEDS 3

/* F from the tiling against F from the ghost layer: the same gaps, from coordinates a
 * period or two apart, so equal to the rounding of differences of coordinates of a few
 * hundred units (1e-13) over a radius. */
#define F_AGREEMENT 1e-10

/* The sum of the cells' areas against W H (relative), as test_laguerre asks. */
#define AREA_RTOL 1e-12

/* The middle copy's index of disk a in tile_packing(..., 3, ...): copy (1, 1) along the
 * periodic axes, 0 along a walled one. */
static size_t middle_of(const gp_domain *dom, size_t n, size_t a)
{
    int px = (dom->periodic & GP_PERIODIC_X) != 0, py = (dom->periodic & GP_PERIODIC_Y) != 0;
    size_t ky = py ? 3 : 1, i = px ? 1 : 0, j = py ? 1 : 0;
    return (i * ky + j) * n + a;
}

/* The largest difference between F[a] and the F of the middle copy of disk a in the
 * 3 x 3 tiling, measured by gp_quality as a walled structure of 3 W x 3 H (along the
 * periodic axes); counts in *mismatched the disks where one is NAN and not the other. */
static double tiled_F_difference(const gp_domain *dom, const gp_disk *disks, size_t n, const double *F,
                                 size_t *mismatched)
{
    size_t nt;
    gp_disk *tiled = tile_packing(disks, n, dom, 3, &nt);
    gp_domain big = {dom->width * ((dom->periodic & GP_PERIODIC_X) ? 3 : 1),
                     dom->height * ((dom->periodic & GP_PERIODIC_Y) ? 3 : 1), 0};
    double *Ft = malloc(nt * sizeof *Ft);
    gp_rt *rt;
    gp_error err;
    gp_quality_stats q;
    CHECK(gp_rt_build(tiled, nt, NULL, &rt, &err) == 0);
    CHECK(gp_quality(&big, rt, tiled, nt, Ft, &q, NULL, &err) == 0);
    double worst = 0.0;
    *mismatched = 0;
    for (size_t a = 0; a < n; a++) {
        double t = Ft[middle_of(dom, n, a)];
        if (isnan(t) || isnan(F[a])) {
            *mismatched += isnan(t) != isnan(F[a]);
            continue;
        }
        worst = fabs(t - F[a]) > worst ? fabs(t - F[a]) : worst;
    }
    gp_rt_free(rt);
    free(Ft);
    free(tiled);
    return worst;
}

typedef struct tally {
    double before_max, after_max, before_mean, after_mean, worst_F, worst_area;
    size_t runs;
} tally;

/* Packs `spec` with `seed`, balances it with `method` and checks every promise. */
static void check_balance(const char *label, const gp_spec *spec, uint64_t seed, gp_balance_method method,
                          tally *t)
{
    const gp_domain *dom = &spec->domain;
    gp_packing pk;
    gp_error err;
    pack_seed(spec, seed, &pk);
    gp_disk *before = malloc(pk.count * sizeof *before);
    memcpy(before, pk.disks, pk.count * sizeof *before);
    gp_balance_params bp = {method, 0, 0.0, GP_RT_UPDATE_FLIPS};
    gp_balance_result br;
    int rc = gp_balance(dom, pk.disks, pk.count, NULL, &bp, NULL, &br, &err);
    CHECK_MSG(rc == 0, "%s seed %llu: %s", label, (unsigned long long)seed, err.message);
    if (rc) {
        free(before);
        gp_packing_free(&pk);
        return;
    }
    size_t nt;
    gp_disk *tiled = tile_packing(pk.disks, pk.count, dom, 3, &nt);
    double worst;
    size_t overlaps = count_overlaps(tiled, nt, &worst);
    free(tiled);
    CHECK_MSG(overlaps == 0, "%s seed %llu: %zu overlapping pairs in the 3x3 tiling (worst %.3g)", label,
              (unsigned long long)seed, overlaps, worst);
    CHECK_MSG(count_outside(pk.disks, pk.count, dom) == 0, "%s seed %llu: disks outside", label,
              (unsigned long long)seed);
    size_t radius_changed = 0;
    for (size_t i = 0; i < pk.count; i++)
        radius_changed += pk.disks[i].r != before[i].r || pk.disks[i].R != before[i].R;
    CHECK(radius_changed == 0);
    CHECK(br.moves > 0);
    CHECK_MSG(br.after.max <= br.before.max, "%s seed %llu: F_max %.4f -> %.4f", label,
              (unsigned long long)seed, br.before.max, br.after.max);
    /* on the torus every grain is interior, before and after */
    if (dom->periodic == (GP_PERIODIC_X | GP_PERIODIC_Y))
        CHECK_MSG(br.before.interior == pk.count && br.after.interior == pk.count,
                  "%s seed %llu: F on %zu then %zu of %zu grains", label, (unsigned long long)seed,
                  br.before.interior, br.after.interior, pk.count);
    /* F handed back is, to the bit, gp_quality's on the returned disks, and to rounding
     * the F of the 3 x 3 tiling's middle copy measured with no periodic code at all */
    gp_quality_stats fresh;
    double *F = malloc(pk.count * sizeof *F);
    CHECK(gp_quality(dom, NULL, pk.disks, pk.count, F, &fresh, NULL, &err) == 0);
    CHECK_MSG(memcmp(&fresh, &br.after, sizeof fresh) == 0 && memcmp(F, br.F, pk.count * sizeof *F) == 0,
              "%s seed %llu: gp_quality %.6f/%.6f vs %.6f/%.6f", label, (unsigned long long)seed, fresh.max,
              fresh.mean, br.after.max, br.after.mean);
    size_t mismatched;
    double dF = tiled_F_difference(dom, pk.disks, pk.count, br.F, &mismatched);
    CHECK_MSG(mismatched == 0 && dF <= F_AGREEMENT, "%s seed %llu: F of the tiling off by %.3g, %zu NAN mismatches",
              label, (unsigned long long)seed, dF, mismatched);
    /* the cells of the balanced disks still tile the periodic domain */
    gp_laguerre_params lp = {GP_SHRINK_NONE, 0};
    gp_cells cells;
    CHECK(gp_laguerre(dom, pk.disks, pk.count, NULL, &lp, NULL, &cells, &err) == 0);
    double area = 0.0, WH = dom->width * dom->height;
    for (size_t i = 0; i < cells.count; i++)
        area += cells.area[i];
    CHECK_MSG(fabs(area - WH) <= AREA_RTOL * WH, "%s seed %llu: cells' areas sum to %.15g, not %.15g", label,
              (unsigned long long)seed, area, WH);
    gp_cells_free(&cells);
    t->before_max += br.before.max;
    t->after_max += br.after.max;
    t->before_mean += br.before.mean;
    t->after_mean += br.after.mean;
    t->worst_F = dF > t->worst_F ? dF : t->worst_F;
    t->worst_area = fabs(area - WH) / WH > t->worst_area ? fabs(area - WH) / WH : t->worst_area;
    t->runs++;
    free(F);
    gp_balance_result_free(&br);
    free(before);
    gp_packing_free(&pk);
}

static void test_both_methods_keep_every_promise_on_periodic_domains(void)
{
    /* the reference laws in domains of a few hundred grains (the 3x3 tilings are
     * triangulated and checked pair by pair), as test_laguerre's periodic cells */
    static const struct {
        const char *name;
        double width, height;
    } cases[] = {{"fixed", 30, 30}, {"variable", 20, 24}, {"iron", 160, 140}, {"bagi", 8, 9}};
    static const unsigned modes[] = {GP_PERIODIC_X | GP_PERIODIC_Y, GP_PERIODIC_X, GP_PERIODIC_Y};
    static const char *const mode_names[] = {"torus", "periodic x", "periodic y"};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        gp_spec spec;
        load_example(cases[c].name, &spec);
        spec.domain.width = cases[c].width;
        spec.domain.height = cases[c].height;
        for (size_t m = 0; m < 3; m++) {
            spec.domain.periodic = modes[m];
            for (int method = GP_BALANCE_LAPLACIAN; method <= GP_BALANCE_RELOCATION; method++) {
                char label[96];
                snprintf(label, sizeof label, "%s %s %s", cases[c].name, mode_names[m],
                         gp_balance_method_name((gp_balance_method)method));
                tally t = {0, 0, 0, 0, 0, 0, 0};
                /* the fixed law draws nothing: every seed packs the same structure */
                int seeds = c == 0 ? 1 : SEEDS;
                for (int seed = 1; seed <= seeds; seed++)
                    check_balance(label, &spec, (uint64_t)seed, (gp_balance_method)method, &t);
                if (!t.runs)
                    continue;
                double k = (double)t.runs;
                /* balancing balances: over the seeds, F_max and the mean F fall. One radius
                 * packs a triangular lattice but for the seams where the fronts met, whose
                 * worst centre (F 1.18 on the torus) no relocation lowers, and the mean
                 * F of a lattice (0.036 on a strip) has little to lose: there Laplacian
                 * smoothing lowers the mean, relocation keeps F_max from rising */
                if (c > 0 || method == GP_BALANCE_LAPLACIAN)
                    CHECK_MSG((c == 0 || t.after_max < t.before_max) && t.after_mean < t.before_mean,
                              "%s: mean F_max %.4f -> %.4f, mean F %.4f -> %.4f", label, t.before_max / k,
                              t.after_max / k, t.before_mean / k, t.after_mean / k);
                fprintf(stderr, "  %-32s F_max %.3f -> %.3f, mean F %.4f -> %.4f; F vs tiling %.1e, area %.1e\n",
                        label, t.before_max / k, t.after_max / k, t.before_mean / k, t.after_mean / k,
                        t.worst_F, t.worst_area);
            }
        }
        gp_spec_free(&spec);
    }
}

static void test_rebuilding_the_layer_every_sweep_gives_a_valid_structure(void)
{
    /* GP_RT_UPDATE_REBUILD makes the ghost layer again each sweep (centres wrapped) in
     * place of moving the ghosts along: the same promises */
    gp_spec spec;
    load_example("iron", &spec);
    spec.domain = (gp_domain){160, 140, GP_PERIODIC_X | GP_PERIODIC_Y};
    gp_packing pk;
    pack_seed(&spec, 1, &pk);
    gp_balance_params bp = {GP_BALANCE_RELOCATION, 0, 0.0, GP_RT_UPDATE_REBUILD};
    gp_balance_result br;
    gp_error err;
    CHECK(gp_balance(&spec.domain, pk.disks, pk.count, NULL, &bp, NULL, &br, &err) == 0);
    size_t nt;
    double worst;
    gp_disk *tiled = tile_packing(pk.disks, pk.count, &spec.domain, 3, &nt);
    CHECK(count_overlaps(tiled, nt, &worst) == 0);
    free(tiled);
    CHECK(count_outside(pk.disks, pk.count, &spec.domain) == 0);
    CHECK(br.after.max < br.before.max && br.after.interior == pk.count);
    CHECK_MSG(br.triangulation.rebuilds >= br.sweeps, "%llu layers for %u sweeps",
              (unsigned long long)br.triangulation.rebuilds, br.sweeps);
    gp_balance_result_free(&br);
    gp_packing_free(&pk);
    gp_spec_free(&spec);
}

static void test_a_periodic_spec_balances_through_the_pipeline(void)
{
    /* the spec that was refused with a 422 at /balance runs, and the result says so */
    static const char json[] =
        "{\"domain\": {\"width\": 30, \"height\": 30, \"periodic\": [\"x\"]}, "
        "\"distribution\": {\"kind\": \"constant\", \"radius\": 0.9}, "
        "\"joint\": {\"law\": \"constant\", \"value\": 0.1}, \"balance\": {\"method\": \"relocation\"}, "
        "\"laguerre\": {\"shrink\": \"offset\"}}";
    gp_spec spec;
    gp_error err;
    int rc = gp_spec_parse(json, strlen(json), NULL, &spec, &err);
    CHECK_MSG(rc == 0, "%s %s", err.pointer, err.message);
    if (rc)
        return;
    gp_result result;
    rc = gp_pipeline_run(&spec, 0, NULL, &result, &err);
    CHECK_MSG(rc == 0, "%s", err.message);
    if (rc == 0) {
        CHECK(result.has_balance && result.has_cells && result.balance.moves > 0);
        CHECK(result.balance.after.max <= result.balance.before.max);
        CHECK(count_outside(result.packing.disks, result.packing.count, &spec.domain) == 0);
        gp_result_free(&result);
    }
    gp_spec_free(&spec);
}

int main(void)
{
    RUN(test_both_methods_keep_every_promise_on_periodic_domains);
    RUN(test_rebuilding_the_layer_every_sweep_gives_a_valid_structure);
    RUN(test_a_periodic_spec_balances_through_the_pipeline);
    return check_status();
}
