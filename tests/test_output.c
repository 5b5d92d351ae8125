/* test_output.c - statistics on hand-made packings, the writers (CSV read back exactly,
 * JSON parsed, SVG counted), and determinism: same seed, same bytes; other seed, other
 * bytes; the mesh formats refuse a result without the mesh they read. */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "grainpack/io.h"
#include "grainpack/io_mesh.h"
#include "grainpack/pipeline.h"
#include "grainpack/stats.h"
#include "packing_checks.h"
#include "render_checks.h"

/* Renders a result in a format into a malloc'd, NUL-terminated buffer. */
static char *render(gp_format format, const gp_spec *spec, const gp_result *result, size_t *len)
{
    return render_text(format, spec, result, len);
}

/* Loads examples/<name>.json and runs the pipeline on it. */
static void run_example(const char *name, gp_spec *spec, gp_result *result)
{
    load_example(name, spec);
    gp_error err;
    CHECK_MSG(gp_pipeline_run(spec, 0, NULL, result, &err) == 0, "%s: %s", name, err.message);
}

static void test_statistics_of_a_hand_made_packing(void)
{
    gp_domain dom = {10, 10, 0};
    gp_bin bins[2] = {{1.0, 2.0, 0.5}, {2.0, 3.0, 0.5}};
    gp_distribution dist = {.kind = GP_DIST_HISTOGRAM, .nbins = 2, .bins = bins};
    gp_disk disks[4] = {{2, 2, 1.5, 2.0}, {7, 2, 1.0, 1.5}, {2, 7, 2.5, 2.5}, {7, 7, 3.0, 3.0}};
    gp_packing pk = {.disks = disks, .count = 4};
    gp_pack_stats st;
    CHECK(gp_pack_stats_compute(&dom, &dist, &pk, &st) == 0);
    CHECK(st.count == 4 && st.nbins == 2);
    CHECK_NEAR(st.packing_density, M_PI * (4 + 2.25 + 6.25 + 9) / 100.0, 1e-15);
    CHECK_NEAR(st.grain_fraction, M_PI * (2.25 + 1 + 6.25 + 9) / 100.0, 1e-15);
    /* r = 1.5, 1.0 in [1, 2); 2.5 in [2, 3); 3.0 is the closed end of the last bin */
    CHECK(st.bins[0].count == 2 && st.bins[1].count == 2);
    CHECK(st.bins[0].achieved == 0.5 && st.bins[0].z == 0.0);
    CHECK(st.chi2 == 0.0 && st.dof == 1 && st.p_value == 1.0);
    CHECK(st.r_min == 1.0 && st.r_max == 3.0 && st.r_mean == 2.0);
    gp_pack_stats_free(&st);

    /* three in the first bin: chi2 = (3-2)^2/2 + (1-2)^2/2 = 1, z = (0.75-0.5)/sqrt(.25/4) */
    disks[3].r = 1.2;
    CHECK(gp_pack_stats_compute(&dom, &dist, &pk, &st) == 0);
    CHECK(st.bins[0].count == 3);
    CHECK_NEAR(st.chi2, 1.0, 1e-15);
    CHECK_NEAR(st.bins[0].z, 1.0, 1e-12);
    /* the standard error of a frequency of 1/2 out of 4 draws: sqrt(0.5 * 0.5 / 4) */
    CHECK_NEAR(st.bins[0].se, 0.25, 1e-15);
    CHECK_NEAR(st.bins[1].se, 0.25, 1e-15);
    CHECK_NEAR(st.p_value, gp_chi2_upper_tail(1.0, 1), 1e-15);
    gp_pack_stats_free(&st);
}

static void test_same_seed_same_bytes_other_seed_other_bytes(void)
{
    gp_spec spec;
    load_example("iron", &spec);
    gp_result a, b, c;
    gp_error err;
    CHECK(gp_pipeline_run(&spec, 0, NULL, &a, &err) == 0);
    CHECK(gp_pipeline_run(&spec, 0, NULL, &b, &err) == 0);
    spec.seed = 2;
    CHECK(gp_pipeline_run(&spec, 0, NULL, &c, &err) == 0);
    spec.seed = 1;
    for (int f = GP_FORMAT_JSON; f <= GP_FORMAT_VTK; f++) {
        size_t la, lb, lc;
        char *ta = render((gp_format)f, &spec, &a, &la), *tb = render((gp_format)f, &spec, &b, &lb);
        spec.seed = 2;
        char *tc = render((gp_format)f, &spec, &c, &lc);
        spec.seed = 1;
        CHECK_MSG(la == lb && memcmp(ta, tb, la) == 0, "%s differs between two runs", gp_format_name((gp_format)f));
        CHECK_MSG(la != lc || memcmp(ta, tc, la) != 0, "%s is the same for seeds 1 and 2", gp_format_name((gp_format)f));
        free(ta);
        free(tb);
        free(tc);
    }
    gp_result_free(&a);
    gp_result_free(&b);
    gp_result_free(&c);
    gp_spec_free(&spec);
}

static void test_csv_reads_back_to_the_exact_disks(void)
{
    gp_spec spec;
    gp_result r;
    run_example("variable", &spec, &r);
    size_t len;
    char *text = render(GP_FORMAT_CSV, &spec, &r, &len);
    CHECK(strncmp(text, "x,y,r,R\n", 8) == 0);
    char *line = text + 8;
    size_t rows = 0, exact = 0;
    while (*line) {
        double x, y, rr, R;
        if (sscanf(line, "%lf,%lf,%lf,%lf", &x, &y, &rr, &R) == 4 && rows < r.packing.count) {
            const gp_disk *d = &r.packing.disks[rows];
            exact += x == d->x && y == d->y && rr == d->r && R == d->R;
        }
        rows++;
        line = strchr(line, '\n') + 1;
    }
    CHECK(rows == r.packing.count && exact == rows);
    free(text);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

static void test_json_has_the_disks_and_every_statistic(void)
{
    gp_spec spec;
    gp_result r;
    run_example("iron", &spec, &r);
    size_t len;
    char *text = render(GP_FORMAT_JSON, &spec, &r, &len);
    json_error_t jerr;
    json_t *root = json_loadb(text, len, 0, &jerr);
    CHECK_MSG(root != NULL, "%s", jerr.text);
    json_t *st = json_object_get(root, "statistics");
    CHECK(json_integer_value(json_object_get(st, "count")) == (json_int_t)r.packing.count);
    CHECK(json_array_size(json_object_get(root, "disks")) == r.packing.count);
    CHECK(json_real_value(json_object_get(st, "packing_density")) == r.stats.packing_density);
    json_t *bins = json_object_get(json_object_get(st, "distribution"), "bins");
    CHECK(json_array_size(bins) == 12);
    json_int_t total = 0;
    for (size_t i = 0; i < json_array_size(bins); i++) {
        json_t *bin = json_array_get(bins, i);
        total += json_integer_value(json_object_get(bin, "count"));
        /* the error bar of each bin is its standard error, the unit of its z */
        double t = json_real_value(json_object_get(bin, "target"));
        double se = json_real_value(json_object_get(bin, "se"));
        CHECK_NEAR(se, sqrt(t * (1.0 - t) / (double)r.packing.count), 1e-15);
        CHECK_NEAR(json_real_value(json_object_get(bin, "z")) * se,
                   json_real_value(json_object_get(bin, "achieved")) - t, 1e-12);
    }
    CHECK(total == (json_int_t)r.packing.count);
    CHECK(json_object_get(st, "front") != NULL && json_object_get(json_object_get(st, "distribution"), "chi2") != NULL);
    json_t *first = json_array_get(json_object_get(root, "disks"), 0);
    CHECK(json_real_value(json_object_get(first, "x")) == r.packing.disks[0].x);
    json_decref(root);
    free(text);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

static void test_svg_draws_one_circle_per_grain_with_legend(void)
{
    gp_spec spec;
    gp_result r;
    run_example("iron", &spec, &r);
    size_t len;
    char *text = render(GP_FORMAT_SVG, &spec, &r, &len);
    size_t circles = 0;
    for (char *p = text; (p = strstr(p, "<circle")); p++)
        circles++;
    CHECK(circles == r.packing.count);
    CHECK(strstr(text, "<svg xmlns=\"http://www.w3.org/2000/svg\"") != NULL);
    CHECK(strstr(text, "grain radius") != NULL && strstr(text, "</svg>") != NULL);
    CHECK(strstr(text, "stroke=\"") != NULL); /* the joint ring */
    /* compact: well under 100 bytes per grain */
    CHECK_MSG(len < 100 * r.packing.count + 10000, "%zu bytes for %zu grains", len, r.packing.count);
    free(text);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

/* Runs the iron case balanced and with Laguerre cells. */
static void run_iron_with_stages(gp_spec *spec, gp_result *r, gp_shrink shrink)
{
    load_example("iron", spec);
    spec->balance_enabled = 1;
    spec->balance = (gp_balance_params){GP_BALANCE_RELOCATION, 0, 0.0, GP_RT_UPDATE_FLIPS};
    spec->picture_color = GP_PICTURE_COLOR_QUALITY;
    spec->laguerre_enabled = shrink != (gp_shrink)-1;
    spec->laguerre = (gp_laguerre_params){shrink, 0};
    gp_error err;
    CHECK_MSG(gp_pipeline_run(spec, 0, NULL, r, &err) == 0, "%s", err.message);
}

static size_t count(const char *text, const char *what)
{
    size_t n = 0;
    for (const char *p = text; (p = strstr(p, what)); p++)
        n++;
    return n;
}

static void test_svg_colours_by_F_with_its_legend(void)
{
    gp_spec spec;
    gp_result r;
    run_iron_with_stages(&spec, &r, (gp_shrink)-1);
    size_t len;
    char *text = render(GP_FORMAT_SVG, &spec, &r, &len);
    CHECK(count(text, "<circle") == r.packing.count);
    CHECK(strstr(text, "balance criterion F") != NULL && strstr(text, "F_max") != NULL);
    /* the grey group holds exactly the grains without F */
    size_t undefined = 0;
    for (size_t i = 0; i < r.packing.count; i++)
        undefined += isnan(r.balance.F[i]);
    char *grey = strstr(text, "<g fill=\"#c8c8c8\"");
    CHECK(grey != NULL && undefined > 0);
    if (grey) {
        char *end = strstr(grey, "</g>");
        size_t in_grey = 0;
        for (char *p = grey; (p = strstr(p, "<circle")) && p < end; p++)
            in_grey++;
        CHECK_MSG(in_grey == undefined, "%zu grey circles, %zu grains without F", in_grey, undefined);
    }
    free(text);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

static void test_svg_draws_cells_on_the_band(void)
{
    gp_spec spec;
    gp_result r;
    run_iron_with_stages(&spec, &r, GP_SHRINK_OFFSET);
    size_t len;
    char *text = render(GP_FORMAT_SVG, &spec, &r, &len);
    CHECK(count(text, "<polygon") == r.packing.count && count(text, "<circle") == 0);
    CHECK(strstr(text, "fill=\"#3b3b3b\"/>") != NULL); /* the band under the cells */
    CHECK(strstr(text, "Laguerre cells (offset shrink)") != NULL);
    free(text);
    spec.picture_disks = 1;
    text = render(GP_FORMAT_SVG, &spec, &r, &len);
    CHECK(count(text, "<circle") == r.packing.count);
    free(text);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

static void test_stages_are_deterministic_too(void)
{
    gp_spec spec;
    gp_result a, b;
    run_iron_with_stages(&spec, &a, GP_SHRINK_HOMOTHETIC);
    gp_spec_free(&spec);
    run_iron_with_stages(&spec, &b, GP_SHRINK_HOMOTHETIC);
    for (int f = GP_FORMAT_JSON; f <= GP_FORMAT_VTK; f++) {
        size_t la, lb;
        char *ta = render((gp_format)f, &spec, &a, &la), *tb = render((gp_format)f, &spec, &b, &lb);
        CHECK_MSG(la == lb && memcmp(ta, tb, la) == 0, "%s differs between two runs", gp_format_name((gp_format)f));
        free(ta);
        free(tb);
    }
    /* the timings name every stage that ran */
    CHECK(gp_result_stage_seconds(&a, "triangulation") > 0.0 && gp_result_stage_seconds(&a, "balance") > 0.0 &&
          gp_result_stage_seconds(&a, "laguerre") > 0.0);
    gp_result_free(&a);
    gp_result_free(&b);
    gp_spec_free(&spec);
}

static void test_format_names(void)
{
    gp_format f;
    CHECK(gp_format_parse("csv", &f) == 0 && f == GP_FORMAT_CSV);
    CHECK(gp_format_parse("svg", &f) == 0 && f == GP_FORMAT_SVG);
    CHECK(gp_format_parse("vtk", &f) == 0 && f == GP_FORMAT_VTK);
    CHECK(gp_format_parse("xml", &f) == GP_EINVAL);
    CHECK_STR(gp_format_media_type(GP_FORMAT_SVG), "image/svg+xml");
    CHECK_STR(gp_format_name(GP_FORMAT_VTK), "vtk");
}

/* Runs a writer of `format` on `result` (its grains from the result itself) to the end:
 * its return code, and its own error in *err. */
static int write_through(gp_format format, const gp_spec *spec, const gp_result *result, gp_error *err)
{
    gp_out out;
    CHECK(gp_out_init(&out, 4096, NULL, NULL) == 0);
    gp_grain_source source = gp_grain_source_memory(result);
    gp_writer *w = gp_writer_new(format, spec, result, &source);
    CHECK(w != NULL);
    int rc = w ? gp_writer_run(w, &out, SIZE_MAX) : GP_ENOMEM;
    if (w)
        *err = *gp_writer_error(w);
    gp_writer_free(w);
    gp_out_free(&out);
    return rc;
}

/* msh, inp and vtu of a result without the mesh (or without the arrays) they read fail
 * with GP_EINVAL and a message, through the writer and the direct calls alike; the
 * arrays are never read through NULL (which ASan would report). */
static void test_mesh_formats_refuse_a_result_without_its_mesh(void)
{
    const char *plain = "{\"domain\": {\"width\": 12, \"height\": 12}, \"distribution\": "
                        "{\"kind\": \"constant\", \"radius\": 1}, \"seed\": 3";
    char json[512];
    gp_spec spec, meshed_spec;
    gp_result bare, meshed;
    gp_error err;
    snprintf(json, sizeof json, "%s}", plain);
    CHECK(gp_spec_parse(json, strlen(json), NULL, &spec, &err) == 0);
    CHECK(gp_pipeline_run(&spec, 0, NULL, &bare, &err) == 0);
    snprintf(json, sizeof json, "%s, \"mesh\": {}}", plain);
    CHECK(gp_spec_parse(json, strlen(json), NULL, &meshed_spec, &err) == 0);
    CHECK(gp_pipeline_run(&meshed_spec, 0, NULL, &meshed, &err) == 0);
    CHECK(!bare.has_mesh && meshed.has_mesh && meshed.mesh.ntri > 0);

    /* no mesh stage: msh and inp refused, vtu writes the grains */
    for (gp_format f = GP_FORMAT_MSH; f <= GP_FORMAT_INP; f++) {
        CHECK(write_through(f, &spec, &bare, &err) == GP_EINVAL);
        CHECK(err.code == GP_EINVAL && strstr(err.message, "needs a mesh") != NULL);
    }
    CHECK(write_through(GP_FORMAT_VTU, &spec, &bare, &err) == 0 && err.code == 0);
    /* the meshed result whole: every format written, no error */
    for (gp_format f = GP_FORMAT_MSH; f <= GP_FORMAT_VTU; f++)
        CHECK(write_through(f, &meshed_spec, &meshed, &err) == 0 && err.code == 0);

    /* a summary: the counts without the arrays (a shallow copy, never freed) */
    gp_result summary = meshed;
    summary.mesh.xy = NULL;
    summary.mesh.tri = NULL;
    for (gp_format f = GP_FORMAT_MSH; f <= GP_FORMAT_VTU; f++) {
        CHECK(write_through(f, &meshed_spec, &summary, &err) == GP_EINVAL);
        CHECK_MSG(err.code == GP_EINVAL && strstr(err.message, "arrays") != NULL, "%s: %s",
                  gp_format_name(f), err.message);
    }
    gp_out out;
    CHECK(gp_out_init(&out, 4096, NULL, NULL) == 0);
    CHECK(gp_write_msh(&out, &meshed_spec, &summary) == GP_EINVAL);
    CHECK(gp_write_inp(&out, &meshed_spec, &summary) == GP_EINVAL);
    CHECK(gp_write_vtu(&out, &meshed_spec, &summary) == GP_EINVAL);
    CHECK(gp_write_msh(&out, &spec, &bare) == GP_EINVAL);
    /* vtu of grains whose arrays are not in the result */
    summary = bare;
    summary.packing.disks = NULL;
    CHECK(write_through(GP_FORMAT_VTU, &spec, &summary, &err) == GP_EINVAL && err.code == GP_EINVAL);
    CHECK(gp_write_vtu(&out, &spec, &summary) == GP_EINVAL);
    gp_out_free(&out);

    gp_result_free(&bare);
    gp_result_free(&meshed);
    gp_spec_free(&spec);
    gp_spec_free(&meshed_spec);
}

int main(void)
{
    RUN(test_statistics_of_a_hand_made_packing);
    RUN(test_same_seed_same_bytes_other_seed_other_bytes);
    RUN(test_csv_reads_back_to_the_exact_disks);
    RUN(test_json_has_the_disks_and_every_statistic);
    RUN(test_svg_draws_one_circle_per_grain_with_legend);
    RUN(test_format_names);
    RUN(test_svg_colours_by_F_with_its_legend);
    RUN(test_svg_draws_cells_on_the_band);
    RUN(test_stages_are_deterministic_too);
    RUN(test_mesh_formats_refuse_a_result_without_its_mesh);
    return check_status();
}
