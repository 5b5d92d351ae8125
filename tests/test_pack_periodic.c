/* test_pack_periodic.c - the packer on periodic domains (docs/method.md §3.8): on the torus
 * and on strips periodic along one axis, over the reference laws and many seeds, no two
 * disks overlap under the minimum-image convention (checked on the 3 x 3 tiling, with no
 * minimum image at all), centres are inside the domain, radii are the law's with every
 * bin within 4 standard errors, and the front closes; the spec field and its errors. */
#include <stdlib.h>

#include <jansson.h>

#include "check.h"
#include "grainpack/pack.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "grainpack/stats.h"
#include "packing_checks.h"
#include "render_checks.h"

/* Bins must stay within this many standard errors of their target (as in
 * test_pack_properties: |z| > 4 has probability 6e-5 per bin). */
#define MAX_Z 4.0
#define LEAN_BINS 64

typedef struct summary {
    double mean_density, min_density, max_abs_z, max_lean;
    size_t min_count, max_count;
} summary;

/* Packs `spec` for seeds 1..seeds with the default rule's parameters and checks every
 * property; returns what the log shows. */
static summary check_seeds(const char *label, const gp_spec *spec, int seeds)
{
    summary sum = {0.0, 1.0, 0.0, 0.0, (size_t)-1, 0};
    double z_sum[LEAN_BINS] = {0};
    size_t nbins = 0;
    gp_pack_params base = gp_spec_pack_params(spec, 0);
    gp_error err;
    CHECK(gp_pack_default_rule(&spec->dist, &spec->joint, NULL, &base.wait_levels,
                               &base.alive_quantile, &err) == 0);
    base.rule = GP_FRONT_WAIT;
    for (int seed = 1; seed <= seeds; seed++) {
        gp_pack_params params = base;
        params.seed = (uint64_t)seed;
        gp_packing pk;
        int rc = gp_pack(&params, NULL, &pk, &err);
        CHECK_MSG(rc == 0, "%s seed %d: %s", label, seed, err.message);
        if (rc)
            continue;
        CHECK_MSG(pk.capped == 0, "%s seed %d: %llu capped closings", label, seed,
                  (unsigned long long)pk.capped);
        double fill = pk.fill_area / gp_domain_area(&spec->domain);
        CHECK_MSG(fill > 0.5, "%s seed %d: %zu disks fill only %.3f", label, seed, pk.count, fill);
        size_t nt;
        gp_disk *tiled = tile_packing(pk.disks, pk.count, &spec->domain, 3, &nt);
        double worst;
        size_t overlaps = count_overlaps(tiled, nt, &worst);
        free(tiled);
        CHECK_MSG(overlaps == 0, "%s seed %d: %zu overlapping pairs in the 3x3 tiling (worst %.3g)",
                  label, seed, overlaps, worst);
        size_t outside = count_outside(pk.disks, pk.count, &spec->domain);
        CHECK_MSG(outside == 0, "%s seed %d: %zu disks outside", label, seed, outside);
        size_t bad = 0;
        for (size_t i = 0; i < pk.count; i++)
            bad += !radius_in_support(&spec->dist, pk.disks[i].r) ||
                   pk.disks[i].R != gp_joint_packing_radius(&spec->joint, pk.disks[i].r);
        CHECK_MSG(bad == 0, "%s seed %d: %zu radii not the law's", label, seed, bad);
        gp_pack_stats st;
        CHECK(gp_pack_stats_compute(&spec->domain, &spec->dist, &pk, &st) == 0);
        for (size_t b = 0; b < st.nbins; b++)
            CHECK_MSG(fabs(st.bins[b].z) <= MAX_Z, "%s seed %d bin %zu: achieved %.4f vs %.4f, z = %.2f",
                      label, seed, b, st.bins[b].achieved, st.bins[b].target, st.bins[b].z);
        for (size_t b = 0; b < st.nbins && b < LEAN_BINS; b++)
            z_sum[b] += st.bins[b].z;
        nbins = st.nbins < LEAN_BINS ? st.nbins : LEAN_BINS;
        sum.mean_density += st.packing_density / seeds;
        if (st.packing_density < sum.min_density)
            sum.min_density = st.packing_density;
        if (st.max_abs_z > sum.max_abs_z)
            sum.max_abs_z = st.max_abs_z;
        if (pk.count < sum.min_count)
            sum.min_count = pk.count;
        if (pk.count > sum.max_count)
            sum.max_count = pk.count;
        gp_pack_stats_free(&st);
        gp_packing_free(&pk);
    }
    /* no systematic lean: a bin's z summed over the seeds, over sqrt(seeds) */
    for (size_t b = 0; b < nbins; b++) {
        double lean = z_sum[b] / sqrt((double)seeds);
        if (fabs(lean) > fabs(sum.max_lean))
            sum.max_lean = lean;
        CHECK_MSG(fabs(lean) <= MAX_Z, "%s bin %zu: lean %.2f over %d seeds", label, b, lean, seeds);
    }
    fprintf(stderr, "  %-24s %3d seeds: %zu..%zu disks, density %.4f mean, %.4f min, max |z| %.2f, lean %+.2f\n",
            label, seeds, sum.min_count, sum.max_count, sum.mean_density, sum.min_density,
            sum.max_abs_z, sum.max_lean);
    return sum;
}

static void test_periodic_packings_hold_every_property(void)
{
    /* the four reference laws, in domains of a few thousand disks at most so that the
     * 3x3 tilings stay quick to check, periodic both ways and along each axis alone; the
     * walled packing of the same domain beside it, for the density */
    static const struct {
        const char *name;
        double width, height;
        int seeds;
    } cases[] = {{"fixed", 60, 60, 40}, {"variable", 30, 30, 60}, {"iron", 237, 300, 30},
                 {"bagi", 20, 20, 30}};
    static const unsigned modes[] = {GP_PERIODIC_X | GP_PERIODIC_Y, GP_PERIODIC_X, GP_PERIODIC_Y, 0};
    static const char *const mode_names[] = {"torus", "periodic x", "periodic y", "walled"};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        gp_spec spec;
        load_example(cases[i].name, &spec);
        spec.domain.width = cases[i].width;
        spec.domain.height = cases[i].height;
        double density[4];
        for (size_t m = 0; m < 4; m++) {
            spec.domain.periodic = modes[m];
            char label[64];
            snprintf(label, sizeof label, "%s %s", cases[i].name, mode_names[m]);
            density[m] = check_seeds(label, &spec, cases[i].seeds).mean_density;
        }
        /* no wall to lose density against: the torus packs at least as densely */
        CHECK_MSG(density[0] >= density[3] - 0.002, "%s: torus %.4f, walled %.4f", cases[i].name,
                  density[0], density[3]);
        gp_spec_free(&spec);
    }
}

static int parse_error(const char *json, gp_error *err)
{
    gp_spec spec;
    int rc = gp_spec_parse(json, strlen(json), NULL, &spec, err);
    if (rc == 0)
        gp_spec_free(&spec);
    return rc;
}

#define LAW "\"distribution\": {\"kind\": \"constant\", \"radius\": 0.9}, " \
            "\"joint\": {\"law\": \"constant\", \"value\": 0.1}"

static void test_spec_field_and_its_errors(void)
{
    static const struct {
        const char *periodic;
        unsigned bits;
    } ok[] = {{"true", GP_PERIODIC_X | GP_PERIODIC_Y}, {"false", 0}, {"[]", 0},
              {"[\"x\"]", GP_PERIODIC_X}, {"[\"y\"]", GP_PERIODIC_Y},
              {"[\"y\", \"x\"]", GP_PERIODIC_X | GP_PERIODIC_Y}};
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        char json[512];
        snprintf(json, sizeof json,
                 "{\"domain\": {\"width\": 30, \"height\": 20, \"periodic\": %s}, " LAW "}",
                 ok[i].periodic);
        gp_spec spec;
        gp_error err;
        int rc = gp_spec_parse(json, strlen(json), NULL, &spec, &err);
        CHECK_MSG(rc == 0, "%s: %s %s", ok[i].periodic, err.pointer, err.message);
        if (rc == 0) {
            CHECK(spec.domain.periodic == ok[i].bits);
            gp_spec_free(&spec);
        }
    }
    static const struct {
        const char *domain, *pointer;
    } bad[] = {
        {"{\"width\": 30, \"height\": 20, \"periodic\": 1}", "/domain/periodic"},
        {"{\"width\": 30, \"height\": 20, \"periodic\": \"x\"}", "/domain/periodic"},
        {"{\"width\": 30, \"height\": 20, \"periodic\": [\"z\"]}", "/domain/periodic/0"},
        {"{\"width\": 30, \"height\": 20, \"periodic\": [\"x\", 2]}", "/domain/periodic/1"},
        {"{\"width\": 30, \"height\": 20, \"periodic\": [\"x\", \"x\"]}", "/domain/periodic/1"},
        /* 12 largest radii (R_max = 1) per period at the least: 11.9 is too short */
        {"{\"width\": 30, \"height\": 11.9, \"periodic\": true}", "/domain/periodic"},
        {"{\"width\": 11.9, \"height\": 30, \"periodic\": [\"x\"]}", "/domain/periodic"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char json[512];
        snprintf(json, sizeof json, "{\"domain\": %s, " LAW "}", bad[i].domain);
        gp_error err;
        CHECK_MSG(parse_error(json, &err) == GP_EINVAL, "%s", bad[i].domain);
        CHECK_STR(err.pointer, bad[i].pointer);
    }
    /* balancing and the mesh take a periodic domain; the mesh's band layers, which do
     * not, say so at their own field */
    static const struct {
        const char *stage, *pointer;
        int rc;
    } stages[] = {{"\"balance\": {\"method\": \"relocation\"}", "", 0},
                  {"\"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"element_size\": 1}", "", 0},
                  /* the band's strips would be cut by the periodic sides */
                  {"\"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_layers\": 2}",
                   "/mesh/band_layers", GP_EINVAL}};
    for (size_t i = 0; i < sizeof stages / sizeof stages[0]; i++) {
        char json[512];
        snprintf(json, sizeof json,
                 "{\"domain\": {\"width\": 30, \"height\": 30, \"periodic\": true}, " LAW ", %s}",
                 stages[i].stage);
        gp_error err;
        CHECK_MSG(parse_error(json, &err) == stages[i].rc, "%s", stages[i].stage);
        if (stages[i].rc)
            CHECK_STR(err.pointer, stages[i].pointer);
    }
    /* a tiled picture needs a periodic domain, and at most GP_PICTURE_MAX_TILE copies */
    static const struct {
        const char *domain, *tile;
    } tiles[] = {{"{\"width\": 30, \"height\": 30}", "2"},
                 {"{\"width\": 30, \"height\": 30, \"periodic\": true}", "5"},
                 {"{\"width\": 30, \"height\": 30, \"periodic\": true}", "1.5"}};
    for (size_t i = 0; i < sizeof tiles / sizeof tiles[0]; i++) {
        char json[512];
        snprintf(json, sizeof json, "{\"domain\": %s, " LAW ", \"picture\": {\"tile\": %s}}",
                 tiles[i].domain, tiles[i].tile);
        gp_error err;
        CHECK_MSG(parse_error(json, &err) == GP_EINVAL, "%s", json);
        CHECK_STR(err.pointer, "/picture/tile");
    }
    /* the cells and the mesh do take it (test_laguerre and test_mesh check them) */
    gp_error err;
    CHECK(parse_error("{\"domain\": {\"width\": 30, \"height\": 30, \"periodic\": true}, " LAW
                      ", \"laguerre\": {\"shrink\": \"offset\"}}", &err) == 0);
    CHECK(parse_error("{\"domain\": {\"width\": 30, \"height\": 30, \"periodic\": [\"x\"]}, " LAW
                      ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {}}", &err) == 0);
    /* along a walled axis the short side is the walled rule's: one disk must fit */
    CHECK(parse_error("{\"domain\": {\"width\": 30, \"height\": 2.5, \"periodic\": [\"x\"]}, " LAW "}",
                      &err) == 0);
}

static void test_narrow_periodic_strip_fills(void)
{
    /* a strip periodic along x and barely two disks high: the two wall chains meet each
     * other at once, and the front still fills it without overlap */
    gp_spec spec;
    const char *json = "{\"domain\": {\"width\": 40, \"height\": 2.5, \"periodic\": [\"x\"]}, " LAW "}";
    gp_error err;
    CHECK(gp_spec_parse(json, strlen(json), NULL, &spec, &err) == 0);
    check_seeds("strip 40 x 2.5", &spec, 20);
    gp_spec_free(&spec);
}

static void test_outputs_say_periodic_and_keep_centres_inside(void)
{
    /* the JSON gives the domain as the spec did and its statistics say periodic; the CSV's
     * centres are all inside the domain (disks across a side are written once) */
    static const char *const domains[] = {"true", "[\"y\"]"};
    static const char *const axes[] = {"[\"x\",\"y\"]", "[\"y\"]"}; /* compact */
    for (size_t k = 0; k < 2; k++) {
        char json[512];
        snprintf(json, sizeof json,
                 "{\"domain\": {\"width\": 24, \"height\": 30, \"periodic\": %s}, " LAW
                 ", \"laguerre\": {\"shrink\": \"offset\"}}",
                 domains[k]);
        gp_spec spec;
        gp_error err;
        CHECK(gp_spec_parse(json, strlen(json), NULL, &spec, &err) == 0);
        gp_result result;
        CHECK(gp_pipeline_run(&spec, 0, NULL, &result, &err) == 0);
        char *text = render_text(GP_FORMAT_JSON, &spec, &result, NULL);
        json_error_t jerr;
        json_t *root = json_loads(text, 0, &jerr);
        CHECK(root != NULL);
        char *domain = json_dumps(json_object_get(json_object_get(root, "domain"), "periodic"), JSON_COMPACT);
        char *stats = json_dumps(json_object_get(json_object_get(root, "statistics"), "periodic"), JSON_COMPACT);
        const char *want = axes[k];
        CHECK_MSG(domain && strcmp(domain, want) == 0, "domain.periodic %s, want %s", domain, want);
        CHECK_MSG(stats && strcmp(stats, want) == 0, "statistics.periodic %s, want %s", stats, want);
        free(domain);
        free(stats);
        json_decref(root);
        free(text);
        text = render_text(GP_FORMAT_CSV, &spec, &result, NULL);
        size_t rows = 0, outside = 0;
        for (char *line = strchr(text, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
            double x, y;
            if (sscanf(line + 1, "%lf,%lf", &x, &y) != 2)
                continue;
            rows++;
            outside += !(x >= 0.0 && x < spec.domain.width && y >= 0.0 && y < spec.domain.height);
        }
        CHECK(rows == result.packing.count);
        CHECK_MSG(outside == 0, "%zu CSV centres outside", outside);
        free(text);
        /* the SVG draws the grains once and uses them at every copy that reaches the
         * picture: (1 + 2) x (1 + 2) on the torus, 1 x 3 on the strip periodic along y */
        text = render_text(GP_FORMAT_SVG, &spec, &result, NULL);
        size_t uses = 0;
        for (const char *p = strstr(text, "<use "); p; p = strstr(p + 1, "<use "))
            uses++;
        CHECK_MSG(uses == (k == 0 ? 9u : 3u), "%zu copies drawn", uses);
        CHECK(strstr(text, "<clipPath id=\"gp-domain\"><rect x=\"0\" y=\"0\" width=\"24\" height=\"30\"/>") != NULL);
        free(text);
        /* a 2x2 tiling: the picture twice as wide and high, (2 + 2) x (2 + 2) copies */
        spec.picture_tile = 2;
        text = render_text(GP_FORMAT_SVG, &spec, &result, NULL);
        uses = 0;
        for (const char *p = strstr(text, "<use "); p; p = strstr(p + 1, "<use "))
            uses++;
        CHECK_MSG(uses == (k == 0 ? 16u : 4u), "%zu copies drawn for tile 2", uses);
        CHECK(strstr(text, k == 0 ? "width=\"48\" height=\"60\"/>" : "width=\"24\" height=\"60\"/>") != NULL);
        free(text);
        gp_result_free(&result);
        gp_spec_free(&spec);
    }
}

int main(void)
{
    RUN(test_outputs_say_periodic_and_keep_centres_inside);
    RUN(test_spec_field_and_its_errors);
    RUN(test_narrow_periodic_strip_fills);
    RUN(test_periodic_packings_hold_every_property);
    return check_status();
}
