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

/* The lean over the seeds: a bin's z summed over n independent seeds, over sqrt(n), is
 * again a standard normal if the packing does not favour any radius; within MAX_Z it
 * bounds a systematic lean to MAX_Z / sqrt(n) standard errors per packing (0.28 at 200
 * seeds), far finer than one packing's |z| <= MAX_Z can see. */
#define LEAN_BINS 64

typedef struct config_summary {
    double min_density, max_density, mean_density, worst_overlap, max_abs_z, max_lean;
    size_t min_count, max_count;
} config_summary;

/* The packer's parameters for the spec with the default rule made explicit: the pilots
 * of gp_pack_default_rule run once, not once per seed (test_default_rule_is_the_pilots_
 * choice checks that this is what GP_FRONT_DEFAULT does). */
static gp_pack_params default_params(const gp_spec *spec)
{
    gp_pack_params params = gp_spec_pack_params(spec, 0);
    gp_error err;
    CHECK(gp_pack_default_rule(&spec->dist, &spec->joint, NULL, &params.wait_levels,
                               &params.alive_quantile, &err) == 0);
    params.rule = GP_FRONT_WAIT;
    return params;
}

/* The report's level rule with a level band. */
static gp_pack_params band_params(const gp_spec *spec, uint32_t band)
{
    gp_pack_params params = gp_spec_pack_params(spec, 0);
    params.rule = GP_FRONT_LEVEL_BAND;
    params.level_band = band;
    return params;
}

static const char *rule_name(const gp_pack_params *p, char *buf, size_t size)
{
    if (p->rule == GP_FRONT_LEVEL_BAND)
        snprintf(buf, size, "band %u", p->level_band);
    else
        snprintf(buf, size, "wait %u/q%.2g", p->wait_levels, p->alive_quantile);
    return buf;
}

/* Packs with `base` for seeds 1..seeds and checks every property; returns a summary for
 * the log. */
static config_summary check_config(const char *label, const gp_spec *spec, int seeds,
                                   gp_pack_params base, int check_fidelity)
{
    config_summary sum = {1.0, 0.0, 0.0, -1.0, 0.0, 0.0, (size_t)-1, 0};
    double z_sum[LEAN_BINS] = {0};
    size_t nbins = 0;
    for (int seed = 1; seed <= seeds; seed++) {
        gp_pack_params params = base;
        params.seed = (uint64_t)seed;
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
        for (size_t b = 0; b < st.nbins && b < LEAN_BINS; b++)
            z_sum[b] += st.bins[b].z;
        nbins = st.nbins < LEAN_BINS ? st.nbins : LEAN_BINS;
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
    for (size_t b = 0; b < nbins; b++) {
        double lean = z_sum[b] / sqrt((double)seeds);
        if (fabs(lean) > fabs(sum.max_lean))
            sum.max_lean = lean;
        if (check_fidelity)
            CHECK_MSG(fabs(lean) <= MAX_Z, "%s bin %zu: z summed over %d seeds / sqrt(seeds) = %.2f",
                      label, b, seeds, lean);
    }
    char rule[48];
    fprintf(stderr,
            "  %-28s %-12s %3d seeds: %zu..%zu disks, density %.4f..%.4f (mean %.4f), "
            "max |z| %.2f, lean %+.2f, closest pair %.2e of R1+R2 apart\n",
            label, rule_name(&base, rule, sizeof rule), seeds, sum.min_count, sum.max_count,
            sum.min_density, sum.max_density, sum.mean_density, sum.max_abs_z, sum.max_lean, -sum.worst_overlap);
    return sum;
}

static void test_reference_cases_hold_every_property_over_200_seeds(void)
{
    /* The default rule on the report's cases, 200 seeds each: no overlap, every bin
     * within 4 standard errors, and floors on the density of every seed, about 0.01
     * under the lowest measured over these 200 seeds (fixed 0.8762, variable 0.810, iron
     * 0.775, Bagi 0.866), and on the mean, 0.003 under what was measured (variable 0.822,
     * iron 0.788, Bagi 0.867): a run that leaves a wall unfilled or lets the front give up
     * drops far below the first, a rule that packs looser than this one below the second. */
    static const struct {
        const char *name;
        double floor, mean_floor;
    } cases[] = {{"fixed", 0.876, 0.876}, {"variable", 0.80, 0.819}, {"iron", 0.765, 0.785},
                 {"bagi", 0.856, 0.864}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gp_spec spec;
        load_example(cases[i].name, &spec);
        config_summary s = check_config(cases[i].name, &spec, SEEDS, default_params(&spec), 1);
        CHECK_MSG(s.min_density >= cases[i].floor, "%s: a seed reached only %.4f", cases[i].name,
                  s.min_density);
        CHECK_MSG(s.mean_density >= cases[i].mean_floor, "%s: mean density %.4f", cases[i].name,
                  s.mean_density);
        gp_spec_free(&spec);
    }
}

static void test_default_specs_reach_the_aimed_densities(void)
{
    /* The example files as a user runs them (seed 1, no "front"): the densities issue 12
     * aimed at, the fixed case still the report's 2789 disks / 0.8762 */
    static const struct {
        const char *name;
        double floor;
    } cases[] = {{"fixed", 0.8762}, {"variable", 0.82}, {"iron", 0.79}, {"bagi", 0.86}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gp_spec spec;
        load_example(cases[i].name, &spec);
        CHECK(!spec.level_band_set);
        gp_pack_params params = gp_spec_pack_params(&spec, 0);
        gp_packing pk;
        gp_error err;
        CHECK(gp_pack(&params, NULL, &pk, &err) == 0);
        double density = pk.fill_area / gp_domain_area(&spec.domain);
        CHECK_MSG(density >= cases[i].floor - 5e-5, "%s: %zu disks, density %.4f", cases[i].name,
                  pk.count, density);
        if (i == 0)
            CHECK_MSG(pk.count == 2789, "fixed: %zu disks", pk.count);
        fprintf(stderr, "  %-9s default: %zu disks, density %.4f (wait %u, quantile %g)\n",
                cases[i].name, pk.count, density, pk.wait_levels, pk.alive_quantile);
        gp_packing_free(&pk);
        gp_spec_free(&spec);
    }
}

static void test_default_rule_is_the_pilots_choice(void)
{
    /* GP_FRONT_DEFAULT is the waiting rule with gp_pack_default_rule's parameters: the
     * same disks, and the parameters reported */
    static const char *const cases[] = {"variable", "iron"};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gp_spec spec;
        load_example(cases[i], &spec);
        gp_pack_params def = gp_spec_pack_params(&spec, 0), explicit_rule = default_params(&spec);
        CHECK(def.rule == GP_FRONT_DEFAULT);
        for (uint64_t seed = 1; seed <= 3; seed++) {
            def.seed = explicit_rule.seed = seed;
            gp_packing a, b;
            gp_error err;
            CHECK(gp_pack(&def, NULL, &a, &err) == 0 && gp_pack(&explicit_rule, NULL, &b, &err) == 0);
            CHECK(a.rule == GP_FRONT_WAIT && a.wait_levels == explicit_rule.wait_levels &&
                  a.alive_quantile == explicit_rule.alive_quantile);
            CHECK(a.count == b.count && memcmp(a.disks, b.disks, a.count * sizeof *a.disks) == 0);
            gp_packing_free(&a);
            gp_packing_free(&b);
        }
        gp_spec_free(&spec);
    }
    /* a law of one radius has nothing to choose: no pilot, the first candidate */
    gp_distribution one = {.kind = GP_DIST_CONSTANT, .radius = 0.5};
    uint32_t wait = 0;
    double q = -1.0;
    gp_error err;
    CHECK(gp_pack_default_rule(&one, NULL, NULL, &wait, &q, &err) == 0);
    CHECK(wait == 4 && q == 0.0);
}

static void test_fixed_case_reproduces_the_report_count(void)
{
    /* the report's fixed-radius structure: 2789 disks, density 0.8762, whatever the rule */
    gp_spec spec;
    load_example("fixed", &spec);
    for (uint32_t band = 0; band <= 2; band++) {
        config_summary s = check_config("fixed (report count)", &spec, 5, band_params(&spec, band), 0);
        CHECK_MSG(s.min_count == 2789 && s.max_count == 2789, "%zu..%zu disks", s.min_count, s.max_count);
        CHECK_NEAR(s.mean_density, 0.8762, 5e-5);
    }
    config_summary s = check_config("fixed (report count)", &spec, 5, default_params(&spec), 0);
    CHECK_MSG(s.min_count == 2789 && s.max_count == 2789, "%zu..%zu disks", s.min_count, s.max_count);
    gp_spec_free(&spec);
}

static void test_level_bands_keep_every_property(void)
{
    static const char *const cases[] = {"variable", "iron", "bagi"};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        for (uint32_t band = 1; band <= 4; band += 3) {
            gp_spec spec;
            load_example(cases[i], &spec);
            check_config(cases[i], &spec, EXTRA_SEEDS, band_params(&spec, band), 1);
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
        check_config(configs[i].label, &spec, EXTRA_SEEDS, default_params(&spec), spec.expected_disks > 500);
        check_config(configs[i].label, &spec, EXTRA_SEEDS / 4, band_params(&spec, 0), spec.expected_disks > 500);
        check_config(configs[i].label, &spec, EXTRA_SEEDS / 4, band_params(&spec, 2), spec.expected_disks > 500);
        gp_spec_free(&spec);
    }
}

/* Whether packing b is packing a turned by 90 degrees counter-clockwise: a in W x H, b in
 * H x W, where (x, y) goes to (H - y, x); disk for disk, in the same order, within a
 * relative 1e-9 (the two are computed apart, in doubles). */
static int is_turned(const gp_packing *a, const gp_packing *b, double H)
{
    if (a->count != b->count)
        return 0;
    for (size_t i = 0; i < a->count; i++) {
        const gp_disk *p = &a->disks[i], *q = &b->disks[i];
        double tol = 1e-9 * (p->R > 1.0 ? p->R : 1.0) * (H > 1.0 ? H : 1.0);
        if (fabs(H - p->y - q->x) > tol || fabs(p->x - q->y) > tol || p->R != q->R)
            return 0;
    }
    return 1;
}

static void test_turned_and_transposed_domains_fill_alike(void)
{
    /* A rectangle turned by 90 degrees and the transposed one (mirrored across its
     * diagonal) are the same rectangle, H x W: the packer must fill it as it fills W x H.
     * Both turnings are checked: the counts over many seeds agree within noise, whatever
     * the law and however narrow the strip (a 1 x 10 strip of r = 0.3 once got 2 disks
     * and the 10 x 1 one 17); and as the walk starts from a longest wall, the packing of
     * H x W is the turned packing of W x H, disk for disk, in exact arithmetic: with one
     * radius on every seed, with several on the seeds where rounding never tips a test
     * (a limit falling near the edge of a failure class, say) the other way. */
    static const struct {
        const char *label, *law;
        double W, H;
    } configs[] = {
        {"constant r 0.3, 10 x 1", "{\"kind\":\"constant\",\"radius\":0.3}", 10, 1},
        {"constant r 0.3, 10 x 1.1", "{\"kind\":\"constant\",\"radius\":0.3}", 10, 1.1},
        {"uniform 0.1-0.3, 10 x 1", "{\"kind\":\"uniform\",\"min\":0.1,\"max\":0.3}", 10, 1},
        {"uniform 0.1-0.5, 40 x 5", "{\"kind\":\"uniform\",\"min\":0.1,\"max\":0.5}", 40, 5},
        {"Bagi law, 30 x 8", "{\"kind\":\"uniform\",\"min\":0.06,\"max\":0.42}", 30, 8},
        {"variable law, 50 x 12",
         "{\"kind\":\"histogram\",\"bins\":[{\"min\":0.2,\"max\":0.4,\"p\":0.3},{\"min\":0.4,"
         "\"max\":0.6,\"p\":0.2},{\"min\":0.6,\"max\":0.9,\"p\":0.5}]}", 50, 12},
    };
    enum { TURN_SEEDS = 60 };
    for (size_t i = 0; i < sizeof configs / sizeof configs[0]; i++) {
        char json[2][512];
        gp_spec spec[2];
        for (int t = 0; t < 2; t++) {
            snprintf(json[t], sizeof json[t], "{\"domain\":{\"width\":%g,\"height\":%g},\"distribution\":%s}",
                     t ? configs[i].H : configs[i].W, t ? configs[i].W : configs[i].H, configs[i].law);
            parse(json[t], &spec[t]);
        }
        double sum[2] = {0, 0}, sum2[2] = {0, 0};
        int turned = 0;
        gp_pack_params base[2] = {default_params(&spec[0]), default_params(&spec[1])};
        for (int seed = 1; seed <= TURN_SEEDS; seed++) {
            gp_packing pk[2];
            gp_error err;
            for (int t = 0; t < 2; t++) {
                gp_pack_params params = base[t];
                params.seed = (uint64_t)seed;
                CHECK_MSG(gp_pack(&params, NULL, &pk[t], &err) == 0, "%s: %s", configs[i].label, err.message);
                sum[t] += (double)pk[t].count;
                sum2[t] += (double)pk[t].count * (double)pk[t].count;
            }
            turned += is_turned(&pk[0], &pk[1], configs[i].H);
            gp_packing_free(&pk[0]);
            gp_packing_free(&pk[1]);
        }
        double mean[2], var[2];
        for (int t = 0; t < 2; t++) {
            mean[t] = sum[t] / TURN_SEEDS;
            var[t] = sum2[t] / TURN_SEEDS - mean[t] * mean[t];
        }
        /* within 4 standard errors of the difference; half a disk for laws without noise */
        double se = sqrt((var[0] + var[1]) / TURN_SEEDS);
        CHECK_MSG(fabs(mean[0] - mean[1]) <= 4.0 * se + 0.5, "%s: %.1f disks, turned %.1f (se %.2f)",
                  configs[i].label, mean[0], mean[1], se);
        /* one radius leaves nothing to rounding: the turned packing, disk for disk */
        if (spec[0].dist.kind == GP_DIST_CONSTANT)
            CHECK_MSG(turned == TURN_SEEDS, "%s: only %d of %d seeds give the turned packing",
                      configs[i].label, turned, TURN_SEEDS);
        fprintf(stderr, "  %-28s %.1f disks, turned %.1f; the turned packing on %d of %d seeds\n",
                configs[i].label, mean[0], mean[1], turned, TURN_SEEDS);
        gp_spec_free(&spec[0]);
        gp_spec_free(&spec[1]);
    }
}

static void test_narrow_strip_is_filled_along_its_length(void)
{
    /* 1 x 10 with r = 0.3: a row of 17 disks along a long wall (the report's rule leaves
     * no room for a second row), as in 10 x 1; once 2 disks, the corners only */
    for (int t = 0; t < 2; t++) {
        gp_spec spec;
        parse(t ? "{\"domain\":{\"width\":1,\"height\":10},\"distribution\":{\"kind\":\"constant\",\"radius\":0.3}}"
                : "{\"domain\":{\"width\":10,\"height\":1},\"distribution\":{\"kind\":\"constant\",\"radius\":0.3}}",
              &spec);
        gp_pack_params params = gp_spec_pack_params(&spec, 0);
        gp_packing pk;
        gp_error err;
        CHECK(gp_pack(&params, NULL, &pk, &err) == 0);
        CHECK_MSG(pk.count == 17, "%s: %zu disks", t ? "1 x 10" : "10 x 1", pk.count);
        double worst;
        CHECK(count_overlaps(pk.disks, pk.count, &worst) == 0);
        CHECK(count_outside(pk.disks, pk.count, &spec.domain) == 0);
        gp_packing_free(&pk);
        gp_spec_free(&spec);
    }
}

static void test_laws_beyond_the_limits_are_refused_not_packed(void)
{
    /* the job that never ended: radii 1e-6 and 1 in 100 x 100. gp_pack refuses it
     * itself (for callers that skip the spec), saying which limit and why */
    gp_bin bins[2] = {{1e-6, 2e-6, 0.5}, {1.0, 1.1, 0.5}};
    gp_distribution dist = {.kind = GP_DIST_HISTOGRAM, .nbins = 2, .bins = bins};
    CHECK(gp_distribution_prepare(&dist) == 0);
    gp_domain dom = {100, 100, 0};
    gp_pack_params params = {.domain = &dom, .dist = &dist, .seed = 1, .rule = GP_FRONT_DEFAULT};
    gp_packing pk;
    gp_error err;
    CHECK(gp_pack(&params, NULL, &pk, &err) == GP_EINVAL);
    CHECK(strstr(err.message, "more than the packer's limit of 100") != NULL);
    CHECK(pk.disks == NULL && pk.count == 0);
    /* within the ratio, but too small for the domain's precision */
    bins[0] = (gp_bin){0.02, 0.021, 0.5};
    bins[1] = (gp_bin){1.0, 1.1, 0.5};
    gp_domain strip = {30000, 2.5, 0};
    params.domain = &strip;
    CHECK(gp_pack(&params, NULL, &pk, &err) == GP_EINVAL);
    CHECK(strstr(err.message, "too small for a domain side of 30000") != NULL);
    CHECK(gp_pack_check_law(&dom, &dist, NULL, &err) == GP_PACK_LAW_OK);
    CHECK(gp_pack_check_law(&strip, &dist, NULL, &err) == GP_PACK_LAW_PRECISION);
    free(dist.cdf);
}

static void test_cap_stops_the_packing_with_a_clear_error(void)
{
    gp_spec spec;
    load_example("bagi", &spec);
    gp_pack_params params = gp_spec_pack_params(&spec, 1000);
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
    gp_pack_params params = gp_spec_pack_params(&spec, 0);
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

typedef struct cancel_on_report {
    gp_cancel_flag flag;
    int reports;
    double fraction; /* at the first report */
} cancel_on_report;

static void raise_cancel(void *ctx, const char *stage, double fraction)
{
    (void)stage;
    (void)fraction;
    cancel_on_report *c = ctx;
    if (c->reports++ == 0)
        c->fraction = fraction;
    atomic_store(&c->flag, 1);
}

static void test_cancel_stops_the_worst_law_at_the_next_check(void)
{
    /* The slowest law the packer accepts: radii at the ratio cap, nearly all of them the
     * smallest, so that every grid query tests thousands of disks. A cancel raised at the
     * first progress report must end gp_pack at the next check, before any further report
     * (reports come once per PACK_CHECKS_PER_REPORT checks), whatever the loop it is in:
     * the checks are counted in units of worst-case work, not in placements. The time this
     * takes is measured by bench/ (bench/RESULTS.md, the packer's limits). */
    gp_bin bins[2] = {{0.01, 0.0105, 0.99999}, {0.95, 1.0, 0.00001}};
    gp_distribution dist = {.kind = GP_DIST_HISTOGRAM, .nbins = 2, .bins = bins};
    CHECK(gp_distribution_prepare(&dist) == 0);
    for (int walls_only = 0; walls_only < 2; walls_only++) {
        /* a domain whose walls alone hold 300 000 disks, where the first report must come
         * from the walk along the walls (their first ~40 disks, not their end at 1% of the
         * fill), and one where it comes from the front */
        gp_domain dom = walls_only ? (gp_domain){3000, 3, 0} : (gp_domain){30, 30, 0};
        gp_pack_params params = {.domain = &dom, .dist = &dist, .seed = 1, .rule = GP_FRONT_WAIT,
                                 .wait_levels = 4};
        cancel_on_report c = {0, 0, 0.0};
        atomic_init(&c.flag, 0);
        gp_progress progress = {raise_cancel, &c, &c.flag};
        gp_packing pk;
        gp_error err;
        CHECK(gp_pack(&params, &progress, &pk, &err) == GP_ECANCELED);
        CHECK_MSG(c.reports == 1, "%d reports", c.reports);
        if (walls_only)
            CHECK_MSG(c.fraction < 1e-3, "first report at %g of the fill", c.fraction);
        CHECK(strstr(err.message, "canceled") != NULL);
    }
    free(dist.cdf);
}

int main(void)
{
    RUN(test_fixed_case_reproduces_the_report_count);
    RUN(test_default_specs_reach_the_aimed_densities);
    RUN(test_default_rule_is_the_pilots_choice);
    RUN(test_reference_cases_hold_every_property_over_200_seeds);
    RUN(test_level_bands_keep_every_property);
    RUN(test_other_laws_and_joints_hold_every_property);
    RUN(test_turned_and_transposed_domains_fill_alike);
    RUN(test_narrow_strip_is_filled_along_its_length);
    RUN(test_laws_beyond_the_limits_are_refused_not_packed);
    RUN(test_cap_stops_the_packing_with_a_clear_error);
    RUN(test_cancel_stops_the_worst_law_at_the_next_check);
    RUN(test_progress_rises_to_one_and_cancel_stops_the_loop);
    return check_status();
}
