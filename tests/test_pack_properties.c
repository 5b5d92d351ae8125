/* test_pack_properties.c - the packer's promises over many seeds, laws and joints:
 * no two packing disks overlap, every disk is inside the domain, every radius is one the
 * law can draw, the front always closes (with the safety cap never used), and the
 * achieved histogram stays within 4 standard errors of the target in every bin. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/pack.h"
#include "grainpack/spec.h"
#include "grainpack/stats.h"
#include "packing_checks.h"

/* Seeds per configuration; the issue asks for at least 200 on the reference cases. */
#define SEEDS 200
/* Fewer seeds for the extra laws and options, which are there for breadth. */
#define EXTRA_SEEDS 40
/* Bins must stay within this many standard errors sqrt(p (1 - p) / n) of their target.
 * The packer keeps each drawn radius until it is placed, so the achieved counts are those
 * of independent draws: |z| > 4 has probability 6e-5 per bin, so over the ~6000 bin
 * checks below a pass means no systematic lean. */
#define MAX_Z 4.0

typedef struct config_summary {
    double min_density, max_density, mean_density, worst_overlap, max_abs_z;
    size_t min_count, max_count;
} config_summary;

/* Packs `spec` for seeds 1..seeds with the given level band and checks every property;
 * returns a summary for the log. */
static config_summary check_config(const char *label, gp_spec *spec, int seeds, uint32_t band,
                                   int check_fidelity)
{
    config_summary sum = {1.0, 0.0, 0.0, -1.0, 0.0, (size_t)-1, 0};
    for (int seed = 1; seed <= seeds; seed++) {
        gp_pack_params params = {&spec->domain, &spec->dist, &spec->joint, (uint64_t)seed, 0, band};
        gp_packing pk;
        gp_error err;
        int rc = gp_pack(&params, NULL, &pk, &err);
        CHECK_MSG(rc == 0, "%s seed %d: %s", label, seed, err.message);
        if (rc)
            continue;
        /* the front closes: the loop ended by itself, never through the safety cap */
        CHECK_MSG(pk.capped == 0, "%s seed %d: %llu capped closings", label, seed,
                  (unsigned long long)pk.capped);
        /* the front does not give up early: a domain that holds a hundred disks or more
         * ends at least half filled (runs that stopped at the initial front, or left
         * most of a wall empty, once filled less than a quarter) */
        double fill = pk.fill_area / gp_domain_area(&spec->domain);
        if (spec->expected_disks > 100)
            CHECK_MSG(fill > 0.5, "%s seed %d: %zu disks fill only %.3f", label, seed, pk.count, fill);

        double worst;
        size_t overlaps = count_overlaps(pk.disks, pk.count, &worst);
        CHECK_MSG(overlaps == 0, "%s seed %d: %zu overlapping pairs (worst %.3g)", label, seed,
                  overlaps, worst);
        size_t outside = count_outside(pk.disks, pk.count, &spec->domain);
        CHECK_MSG(outside == 0, "%s seed %d: %zu disks outside the domain", label, seed, outside);
        size_t bad_radius = 0, bad_joint = 0;
        for (size_t i = 0; i < pk.count; i++) {
            bad_radius += !radius_in_support(&spec->dist, pk.disks[i].r);
            bad_joint += pk.disks[i].R != gp_joint_packing_radius(&spec->joint, pk.disks[i].r);
        }
        CHECK_MSG(bad_radius == 0, "%s seed %d: %zu radii outside the law", label, seed, bad_radius);
        CHECK_MSG(bad_joint == 0, "%s seed %d: %zu packing radii != r + j(r)", label, seed, bad_joint);

        gp_pack_stats st;
        CHECK(gp_pack_stats_compute(&spec->domain, &spec->dist, &pk, &st) == 0);
        if (check_fidelity)
            for (size_t b = 0; b < st.nbins; b++)
                CHECK_MSG(fabs(st.bins[b].z) <= MAX_Z, "%s seed %d bin %zu [%g,%g): achieved %.4f vs %.4f, z = %.2f",
                          label, seed, b, st.bins[b].min, st.bins[b].max, st.bins[b].achieved,
                          st.bins[b].target, st.bins[b].z);
        if (st.packing_density < sum.min_density)
            sum.min_density = st.packing_density;
        if (st.packing_density > sum.max_density)
            sum.max_density = st.packing_density;
        sum.mean_density += st.packing_density / seeds;
        if (worst > sum.worst_overlap)
            sum.worst_overlap = worst;
        if (st.max_abs_z > sum.max_abs_z)
            sum.max_abs_z = st.max_abs_z;
        if (st.count < sum.min_count)
            sum.min_count = st.count;
        if (st.count > sum.max_count)
            sum.max_count = st.count;
        gp_pack_stats_free(&st);
        gp_packing_free(&pk);
    }
    fprintf(stderr,
            "  %-28s band %u, %3d seeds: %zu..%zu disks, density %.4f..%.4f (mean %.4f), "
            "max |z| %.2f, closest pair %.2e of R1+R2 apart\n",
            label, band, seeds, sum.min_count, sum.max_count, sum.min_density, sum.max_density,
            sum.mean_density, sum.max_abs_z, -sum.worst_overlap);
    return sum;
}

static void test_reference_cases_hold_every_property_over_200_seeds(void)
{
    /* Floors on the packing density of every seed, about 0.01 under the lowest measured
     * over these 200 seeds (fixed 0.8762, variable 0.773, iron 0.770, Bagi 0.791): a run
     * that leaves a wall unfilled or lets the front give up drops far below them. */
    static const struct {
        const char *name;
        double floor;
    } cases[] = {{"fixed", 0.876}, {"variable", 0.76}, {"iron", 0.76}, {"bagi", 0.78}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gp_spec spec;
        load_example(cases[i].name, &spec);
        config_summary s = check_config(cases[i].name, &spec, SEEDS, spec.level_band, 1);
        CHECK_MSG(s.min_density >= cases[i].floor, "%s: a seed reached only %.4f", cases[i].name,
                  s.min_density);
        gp_spec_free(&spec);
    }
}

static void test_fixed_case_reproduces_the_report_count(void)
{
    /* the report's fixed-radius structure: 2789 disks, density 0.8762 */
    gp_spec spec;
    load_example("fixed", &spec);
    config_summary s = check_config("fixed (report count)", &spec, 5, 0, 0);
    CHECK_MSG(s.min_count == 2789 && s.max_count == 2789, "%zu..%zu disks", s.min_count, s.max_count);
    CHECK_NEAR(s.mean_density, 0.8762, 5e-5);
    gp_spec_free(&spec);
}

static void test_level_bands_keep_every_property(void)
{
    static const char *const cases[] = {"variable", "iron", "bagi"};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        for (uint32_t band = 1; band <= 4; band += 3) {
            gp_spec spec;
            load_example(cases[i], &spec);
            check_config(cases[i], &spec, EXTRA_SEEDS, band, 1);
            gp_spec_free(&spec);
        }
    }
}

/* Parses an inline spec, aborting on error (these are the test's own). */
static void parse(const char *json, gp_spec *spec)
{
    gp_error err;
    if (gp_spec_parse(json, strlen(json), NULL, spec, &err)) {
        fprintf(stderr, "bad test spec: %s %s\n", err.pointer, err.message);
        exit(2);
    }
}

static void test_other_laws_and_joints_hold_every_property(void)
{
    static const struct {
        const char *label, *json;
    } configs[] = {
        {"uniform, power joint",
         "{\"domain\":{\"width\":30,\"height\":20},\"distribution\":{\"kind\":\"uniform\",\"min\":0.2,"
         "\"max\":1.0},\"joint\":{\"law\":\"power\",\"k\":0.1,\"exponent\":-0.5}}"},
        {"wide uniform, no joint",
         "{\"domain\":{\"width\":25,\"height\":25},\"distribution\":{\"kind\":\"uniform\",\"min\":0.05,"
         "\"max\":1.5}}"},
        {"constant, inverse joint",
         "{\"domain\":{\"width\":20,\"height\":40},\"distribution\":{\"kind\":\"constant\",\"radius\":0.5},"
         "\"joint\":{\"law\":\"inverse\",\"k\":0.05}}"},
        {"two far bins, constant joint",
         "{\"domain\":{\"width\":40,\"height\":30},\"distribution\":{\"kind\":\"histogram\",\"bins\":["
         "{\"min\":0.1,\"max\":0.15,\"p\":0.7},{\"min\":0.5,\"max\":0.6,\"p\":0.0},{\"min\":1.0,\"max\":1.2,"
         "\"p\":0.3}]},\"joint\":{\"law\":\"constant\",\"value\":0.02}}"},
        {"thin strip",
         "{\"domain\":{\"width\":60,\"height\":2.5},\"distribution\":{\"kind\":\"uniform\",\"min\":0.1,"
         "\"max\":0.6}}"},
        {"domain just fits the largest",
         "{\"domain\":{\"width\":2.0,\"height\":2.0},\"distribution\":{\"kind\":\"uniform\",\"min\":0.3,"
         "\"max\":1.0}}"},
    };
    for (size_t i = 0; i < sizeof configs / sizeof configs[0]; i++) {
        gp_spec spec;
        parse(configs[i].json, &spec);
        /* fidelity needs many disks per bin; the tiny domains are checked for geometry */
        check_config(configs[i].label, &spec, EXTRA_SEEDS, 0, spec.expected_disks > 500);
        check_config(configs[i].label, &spec, EXTRA_SEEDS / 4, 2, spec.expected_disks > 500);
        gp_spec_free(&spec);
    }
}

static void test_cap_stops_the_packing_with_a_clear_error(void)
{
    gp_spec spec;
    load_example("bagi", &spec);
    gp_pack_params params = {&spec.domain, &spec.dist, &spec.joint, 1, 1000, 0};
    gp_packing pk;
    gp_error err;
    CHECK(gp_pack(&params, NULL, &pk, &err) == GP_ETOOBIG);
    CHECK(pk.disks == NULL && pk.count == 0);
    CHECK(strstr(err.message, "1000") != NULL);
    gp_spec_free(&spec);
}

static void count_reports(void *ctx, const char *stage, double fraction)
{
    double *last = ctx;
    CHECK_STR(stage, "pack");
    CHECK(fraction >= *last && fraction <= 1.0);
    *last = fraction;
}

static void test_progress_rises_to_one_and_cancel_stops_the_loop(void)
{
    gp_spec spec;
    load_example("bagi", &spec);
    gp_pack_params params = {&spec.domain, &spec.dist, &spec.joint, 1, 0, 0};
    double last = 0.0;
    gp_progress progress = {count_reports, &last, NULL};
    gp_packing pk;
    gp_error err;
    CHECK(gp_pack(&params, &progress, &pk, &err) == 0);
    CHECK(last == 1.0);
    gp_packing_free(&pk);

    gp_cancel_flag cancel;
    atomic_init(&cancel, 1);
    gp_progress cancelled = {NULL, NULL, &cancel};
    CHECK(gp_pack(&params, &cancelled, &pk, &err) == GP_ECANCELED);
    CHECK(pk.disks == NULL && pk.count == 0);
    gp_spec_free(&spec);
}

int main(void)
{
    RUN(test_fixed_case_reproduces_the_report_count);
    RUN(test_reference_cases_hold_every_property_over_200_seeds);
    RUN(test_level_bands_keep_every_property);
    RUN(test_other_laws_and_joints_hold_every_property);
    RUN(test_cap_stops_the_packing_with_a_clear_error);
    RUN(test_progress_rises_to_one_and_cancel_stops_the_loop);
    return check_status();
}
