/* test_sections.c - a result cut into tagged sections and read back: the summary decodes
 * to the same statistics, and every writer gives the very bytes of the result in memory
 * when it reads the per-grain arrays from the sections window by window (windows of a few
 * grains, so that every cell boundary falls on one), and when it is stopped and resumed
 * every few bytes. Corrupt or truncated sections are refused, not read past. A 3D
 * packing's sections read back the same way, and a balanced, tessellated 3D result's give
 * every 3D writer its bytes in memory, read window by window too. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "grainpack/io3d.h"
#include "grainpack/pipeline3d.h"
#include "json_values.h"
#include "sections.h"
#include "mesh_source.h"
#include "writer3d.h"
#include "packing_checks.h"
#include "render_checks.h"

/* The sections of a result copied into memory, as a store would hold them. */
typedef struct stored {
    gp_section sections[GP_SECTIONS_MAX];
    size_t n;
    unsigned char *copy[GP_SECTIONS_MAX];
    size_t reads; /* calls of read_stored */
} stored;

/* Where the pack section's layout puts the front's rule: after six u64 counts (disks,
 * initial front, attempts, closures, frozen, capped) and max_level (u32). */
#define RULE_OFFSET (6 * 8 + 4)

static void store(stored *st, const gp_result *r)
{
    memset(st, 0, sizeof *st);
    CHECK(gp_sections_from_result(r, st->sections, &st->n) == 0);
    for (size_t i = 0; i < st->n; i++) {
        st->copy[i] = malloc(st->sections[i].size + 1);
        memcpy(st->copy[i], st->sections[i].data, st->sections[i].size);
    }
}

static void unstore(stored *st)
{
    for (size_t i = 0; i < st->n; i++)
        free(st->copy[i]);
    gp_sections_free(st->sections, st->n);
}

/* Frees the copies only (the sections are the caller's). */
static void unstore_copies(stored *st)
{
    for (size_t i = 0; i < st->n; i++)
        free(st->copy[i]);
}

static int read_stored(void *ctx, const char *tag, uint64_t offset, void *dst, size_t len)
{
    stored *st = ctx;
    st->reads++;
    for (size_t i = 0; i < st->n; i++) {
        if (strcmp(st->sections[i].tag, tag) != 0)
            continue;
        if (offset + len > st->sections[i].size)
            return GP_EPARSE;
        memcpy(dst, st->copy[i] + offset, len);
        return 0;
    }
    return GP_EPARSE;
}

/* Decodes the summary sections into *summary; returns the first failure. */
static int decode(stored *st, gp_result *summary)
{
    memset(summary, 0, sizeof *summary);
    for (size_t i = 0; i < st->n; i++) {
        const gp_section *s = &st->sections[i];
        if (!s->summary)
            continue;
        int rc = gp_section_decode_summary(s->tag, s->version, st->copy[i], s->size, summary);
        if (rc)
            return rc;
    }
    return 0;
}

/* Writes through the sections, `step` bytes at a time (SIZE_MAX: at once); the mesh
 * formats read the mesh through windows of `window` records too. */
static char *render_stored(gp_format f, const gp_spec *spec, const gp_result *summary, stored *st,
                           size_t window, size_t step, size_t *len)
{
    gp_sections_source *src = gp_sections_source_new(summary, read_stored, st, window);
    gp_grain_source g = gp_sections_source_grains(src);
    gp_writer *w = gp_writer_new(f, spec, summary, &g);
    if (summary->has_mesh && (gp_format_needs_mesh(f) || f == GP_FORMAT_VTU)) {
        gp_mesh_source mesh;
        CHECK(gp_sections_mesh_source(summary, read_stored, st, window, 1, &mesh) == 0);
        gp_writer_set_mesh(w, &mesh);
    }
    gp_out out;
    CHECK(gp_out_init(&out, 0, NULL, NULL) == 0);
    int rc;
    size_t calls = 0;
    while ((rc = gp_writer_run(w, &out, step == SIZE_MAX ? SIZE_MAX : out.len + step)) == 1)
        calls++;
    CHECK(rc == 0);
    /* stopped every `step` bytes or so (a grain or an item past it): between two grains or items (the SVG's mesh edges
     * are one text step, which stops fewer times) */
    CHECK_MSG(step == SIZE_MAX || calls + 1 >= out.len / (2 * step) || (summary->has_mesh && f == GP_FORMAT_SVG),
              "%s: %zu stops in %zu bytes", gp_format_name(f), calls, out.len);
    gp_writer_free(w);
    gp_sections_source_free(src);
    gp_out_char(&out, '\0');
    *len = out.len - 1;
    return out.buf;
}

static void check_every_format(const char *label, const gp_spec *spec, const gp_result *r)
{
    stored st;
    store(&st, r);
    gp_result summary;
    CHECK(decode(&st, &summary) == 0);
    CHECK(summary.packing.count == r->packing.count && summary.packing.disks == NULL);
    CHECK(summary.has_balance == r->has_balance && summary.has_cells == r->has_cells);
    CHECK(summary.stats.nbins == r->stats.nbins && summary.stats.chi2 == r->stats.chi2);
    CHECK(summary.stats.joint_max == r->stats.joint_max);
    if (r->has_balance)
        CHECK(memcmp(&summary.balance.before, &r->balance.before, sizeof r->balance.before) == 0 &&
              summary.balance.sweeps == r->balance.sweeps && summary.balance.F == NULL);
    if (r->has_cells)
        CHECK(summary.cell_stats.vertices == r->cells.start[r->cells.count] &&
              summary.cell_stats.max_neighbours == r->cell_stats.max_neighbours &&
              summary.cell_stats.band_fraction == r->cell_stats.band_fraction);
    if (r->has_mesh)
        CHECK(summary.has_mesh && summary.mesh.stats.triangles == r->mesh.stats.triangles &&
              summary.mesh.xy == NULL);
    /* windows of 7 grains or mesh records: cells and regions straddle every kind of
     * boundary; 0: the defaults */
    const size_t windows[] = {7, 0};
    for (int f = 0; f < (int)gp_format_count(); f++) {
        /* msh and inp exist only with a mesh, tess in 3D only; the mesh's SVG draws it
         * read whole */
        if ((gp_format_needs_mesh((gp_format)f) && !r->has_mesh) || f == GP_FORMAT_TESS)
            continue;
        if (f == GP_FORMAT_SVG && r->has_mesh && !summary.mesh.xy) {
            CHECK(gp_sections_read_mesh(&summary, read_stored, &st) == 0);
            CHECK(summary.mesh.nnodes == r->mesh.nnodes &&
                  memcmp(summary.mesh.xy, r->mesh.xy, 2 * r->mesh.nnodes * sizeof(double)) == 0);
        }
        size_t len;
        char *want = render_text((gp_format)f, spec, r, &len);
        for (size_t k = 0; k < 2; k++) {
            size_t got_len;
            char *got = render_stored((gp_format)f, spec, &summary, &st, windows[k],
                                      k ? 4096 : SIZE_MAX, &got_len);
            CHECK_MSG(got_len == len && memcmp(got, want, len) == 0,
                      "%s %s, window %zu: %zu bytes, %zu from memory", label,
                      gp_format_name((gp_format)f), windows[k], got_len, len);
            free(got);
        }
        free(want);
    }
    gp_result_free(&summary);
    unstore(&st);
}

static void run(const char *name, gp_spec *spec, gp_result *r, int balance, int cells)
{
    load_example(name, spec);
    spec->balance_enabled = balance;
    spec->balance = (gp_balance_params){GP_BALANCE_RELOCATION, 3, 0.0, GP_RT_UPDATE_FLIPS};
    spec->laguerre_enabled = cells;
    spec->laguerre = (gp_laguerre_params){GP_SHRINK_OFFSET, 0};
    spec->picture_color = balance ? GP_PICTURE_COLOR_QUALITY : GP_PICTURE_COLOR_RADIUS;
    spec->picture_disks = cells;
    gp_error err;
    CHECK_MSG(gp_pipeline_run(spec, 0, NULL, r, &err) == 0, "%s", err.message);
}

static void test_every_format_reads_the_same_from_sections(void)
{
    const int stages[][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (size_t i = 0; i < 4; i++) {
        gp_spec spec;
        gp_result r;
        run("iron", &spec, &r, stages[i][0], stages[i][1]);
        char label[32];
        snprintf(label, sizeof label, "iron balance %d cells %d", stages[i][0], stages[i][1]);
        check_every_format(label, &spec, &r);
        gp_result_free(&r);
        gp_spec_free(&spec);
    }
}

/* Runs the pipeline on spec text `json` (0, or its failure reported). */
static int run_json(const char *json, gp_spec *spec, gp_result *r)
{
    gp_error err;
    int rc = gp_spec_parse(json, strlen(json), NULL, spec, &err);
    CHECK_MSG(rc == 0, "%s", err.message);
    if (rc)
        return rc;
    rc = gp_pipeline_run(spec, 0, NULL, r, &err);
    CHECK_MSG(rc == 0, "%s", err.message);
    if (rc)
        gp_spec_free(spec);
    return rc;
}

/* Runs writer `f` of the stored `st` to its end, the mesh read through `window` records
 * with or without the stored qualities: its return code. */
static int run_mesh_writer(gp_format f, const gp_spec *spec, const gp_result *summary, stored *st,
                           size_t window, int quality)
{
    gp_sections_source *src = gp_sections_source_new(summary, read_stored, st, window);
    gp_grain_source g = gp_sections_source_grains(src);
    gp_writer *w = gp_writer_new(f, spec, summary, &g);
    gp_mesh_source mesh;
    CHECK(gp_sections_mesh_source(summary, read_stored, st, window, quality, &mesh) == 0);
    gp_writer_set_mesh(w, &mesh);
    gp_out out;
    gp_out_init(&out, 0, NULL, NULL);
    int rc = gp_writer_run(w, &out, SIZE_MAX);
    gp_out_free(&out);
    gp_writer_free(w);
    gp_sections_source_free(src);
    return rc;
}

/* Meshes through their sections (grains and band with quadrilateral layers at order 2,
 * triangles only, shrink none, disks in a matrix, a periodic one): the summary, and every
 * format read window by window from them gives the bytes of the mesh in memory. */
static void test_mesh_from_sections(void)
{
    const char *base = "{\"domain\": {\"width\": 20, \"height\": 20}, \"distribution\": {\"kind\": "
                       "\"uniform\", \"min\": 0.5, \"max\": 1.5}, \"joint\": {\"law\": \"constant\", "
                       "\"value\": 0.1}";
    const struct {
        const char *label, *rest;
    } cases[] = {
        {"layers order 2", ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_layers\": 2, \"order\": 2}}"},
        {"triangles", ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {}}"},
        {"shrink none", ", \"laguerre\": {\"shrink\": \"none\"}, \"mesh\": {\"order\": 2}}"},
        {"matrix", ", \"mesh\": {}}"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        char json[1024];
        snprintf(json, sizeof json, "%s%s", base, cases[c].rest);
        gp_spec spec;
        gp_result r;
        if (run_json(json, &spec, &r))
            continue;
        CHECK(r.has_mesh && (c > 0 || r.mesh.nquad > 0));
        check_every_format(cases[c].label, &spec, &r);
        gp_result_free(&r);
        gp_spec_free(&spec);
    }
    /* a periodic domain: the $Periodic section and the paired node sets from the windows */
    const char *periodic = "{\"domain\": {\"width\": 16, \"height\": 16, \"periodic\": true}, "
                           "\"distribution\": {\"kind\": \"uniform\", \"min\": 0.5, \"max\": 1.0}, "
                           "\"joint\": {\"law\": \"constant\", \"value\": 0.1}, \"laguerre\": "
                           "{\"shrink\": \"offset\"}, \"mesh\": {}}";
    gp_spec spec;
    gp_result r;
    if (run_json(periodic, &spec, &r) == 0) {
        CHECK(r.mesh.stats.periodic_pairs[0] > 2);
        check_every_format("periodic", &spec, &r);
        gp_result_free(&r);
        gp_spec_free(&spec);
    }
}

/* A stored mesh that is corrupt (a node index beyond the nodes, a side that is none) is
 * refused, not handed to a writer; a result stored without the qualities writes msh and
 * inp from its windows but not vtu (the download reads that mesh whole). */
static void test_mesh_sections_refused(void)
{
    const char *json = "{\"domain\": {\"width\": 20, \"height\": 20}, \"distribution\": {\"kind\": "
                       "\"uniform\", \"min\": 0.5, \"max\": 1.5}, \"joint\": {\"law\": \"constant\", "
                       "\"value\": 0.1}, \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {}}";
    gp_spec spec;
    gp_result r;
    if (run_json(json, &spec, &r))
        return;
    const char *tags[] = {GP_SECTION_MESH_TRI, GP_SECTION_MESH_BEDGE_SIDE, GP_SECTION_MESH_TRI_REGION};
    for (size_t t = 0; t < 3; t++) {
        stored st;
        store(&st, &r);
        for (size_t i = 0; i < st.n; i++)
            if (strcmp(st.sections[i].tag, tags[t]) == 0)
                memset(st.copy[i] + st.sections[i].size - 4, 0x7f, 4);
        gp_result summary;
        CHECK(decode(&st, &summary) == 0);
        CHECK(gp_sections_read_mesh(&summary, read_stored, &st) == GP_EPARSE && summary.mesh.xy == NULL);
        /* (vtu has no use for the sides) */
        for (gp_format f = GP_FORMAT_MSH; f <= (t == 1 ? GP_FORMAT_INP : GP_FORMAT_VTU); f++)
            CHECK_MSG(run_mesh_writer(f, &spec, &summary, &st, 5, 1) == GP_EPARSE, "%s with a corrupt %s",
                      gp_format_name(f), tags[t]);
        gp_result_free(&summary);
        unstore(&st);
    }
    stored st;
    store(&st, &r);
    gp_result summary;
    CHECK(decode(&st, &summary) == 0);
    CHECK(run_mesh_writer(GP_FORMAT_MSH, &spec, &summary, &st, 0, 0) == 0);
    CHECK(run_mesh_writer(GP_FORMAT_INP, &spec, &summary, &st, 0, 0) == 0);
    CHECK(run_mesh_writer(GP_FORMAT_VTU, &spec, &summary, &st, 0, 0) == GP_EINVAL);
    gp_result_free(&summary);
    /* the mesh summary of a result stored before the qualities (version 1) reads the same */
    for (size_t i = 0; i < st.n; i++)
        if (strcmp(st.sections[i].tag, GP_SECTION_MESH) == 0) {
            CHECK(st.sections[i].version == GP_SECTION_MESH_VERSION);
            memset(&summary, 0, sizeof summary);
            CHECK(gp_section_decode_summary(GP_SECTION_MESH, 1, st.copy[i], st.sections[i].size, &summary) == 0);
            CHECK(summary.has_mesh && summary.mesh.ntri == r.mesh.ntri && summary.mesh.nnodes == r.mesh.nnodes);
            gp_result_free(&summary);
            CHECK(gp_section_decode_summary(GP_SECTION_MESH, GP_SECTION_MESH_VERSION + 1, st.copy[i],
                                            st.sections[i].size, &summary) == GP_EINVAL);
            gp_result_free(&summary);
        }
    unstore(&st);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

static void test_corrupt_sections_are_refused(void)
{
    gp_spec spec;
    gp_result r;
    run("iron", &spec, &r, 1, 1);
    stored st;
    store(&st, &r);
    for (size_t i = 0; i < st.n; i++) {
        gp_section *s = &st.sections[i];
        if (!s->summary)
            continue;
        gp_result summary;
        memset(&summary, 0, sizeof summary);
        /* every truncation of a summary section fails, none reads past the end */
        size_t refused = 0;
        for (size_t cut = 0; cut < s->size; cut += 1 + s->size / 97) {
            unsigned char *part = malloc(cut ? cut : 1);
            memcpy(part, st.copy[i], cut);
            refused += gp_section_decode_summary(s->tag, s->version, part, cut, &summary) == GP_EPARSE;
            free(part);
        }
        CHECK_MSG(refused == 1 + (s->size - 1) / (1 + s->size / 97), "%s: %zu truncations refused", s->tag, refused);
        CHECK(gp_section_decode_summary(s->tag, s->version + 1, st.copy[i], s->size, &summary) == GP_EINVAL);
        gp_result_free(&summary);
    }
    /* a cell-size section that disagrees with the totals stops the writer */
    gp_result summary;
    CHECK(decode(&st, &summary) == 0);
    for (size_t i = 0; i < st.n; i++)
        if (strcmp(st.sections[i].tag, GP_SECTION_CELL_SIZES) == 0)
            memset(st.copy[i], 0xff, 8);
    gp_sections_source *src = gp_sections_source_new(&summary, read_stored, &st, 0);
    gp_grain_source g = gp_sections_source_grains(src);
    gp_writer *w = gp_writer_new(GP_FORMAT_VTK, &spec, &summary, &g);
    gp_out out;
    gp_out_init(&out, 0, NULL, NULL);
    CHECK(gp_writer_run(w, &out, SIZE_MAX) == GP_EPARSE);
    gp_out_free(&out);
    gp_writer_free(w);
    gp_sections_source_free(src);
    gp_result_free(&summary);
    /* an unknown tag is skipped: a later stage's section does not break an older reader */
    memset(&summary, 0, sizeof summary);
    CHECK(gp_section_decode_summary("a_later_stage", 7, "x", 1, &summary) == 0);
    unstore(&st);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

/* The pack section keeps the front's rule the packing ran under, with the waiting rule's
 * parameters: the statistics' front from the sections is the one in memory, for the report's
 * rule, for the densest default (the waiting rule it chose: iron's quantile is 0), and for
 * waiting parameters set by hand to values with every bit of the double significant. */
static void test_pack_section_keeps_the_front_rule(void)
{
    for (int k = 0; k < 3; k++) {
        int level_band = k == 0;
        gp_spec spec;
        gp_result r;
        load_example("iron", &spec);
        spec.level_band_set = level_band;
        gp_error err;
        CHECK_MSG(gp_pipeline_run(&spec, 0, NULL, &r, &err) == 0, "%s", err.message);
        gp_packing *p = &r.packing;
        CHECK(p->rule == (level_band ? GP_FRONT_LEVEL_BAND : GP_FRONT_WAIT));
        CHECK(level_band ||
              (p->wait_levels >= 1 && p->alive_quantile >= 0.0 && p->alive_quantile < 1.0));
        if (k == 2) {
            p->wait_levels = GP_PACK_MAX_WAIT_LEVELS;
            p->alive_quantile = 1.0 / 3.0;
        }
        stored st;
        store(&st, &r);
        gp_result summary;
        CHECK(decode(&st, &summary) == 0);
        CHECK(summary.packing.rule == p->rule && summary.packing.wait_levels == p->wait_levels &&
              memcmp(&summary.packing.alive_quantile, &p->alive_quantile, sizeof(double)) == 0);
        json_t *want = gp_statistics_json(&spec, &r), *got = gp_statistics_json(&spec, &summary);
        char *a = json_dumps(want, JSON_SORT_KEYS), *b = json_dumps(got, JSON_SORT_KEYS);
        CHECK_MSG(a && b && strcmp(a, b) == 0, "rule %d: statistics from the sections differ",
                  (int)p->rule);
        free(a);
        free(b);
        json_decref(want);
        json_decref(got);
        gp_result_free(&summary);
        /* a rule no packing runs under (the default is resolved before packing) is refused */
        for (size_t i = 0; i < st.n; i++) {
            if (strcmp(st.sections[i].tag, GP_SECTION_PACK) != 0)
                continue;
            uint32_t rule = GP_FRONT_DEFAULT;
            memcpy(st.copy[i] + RULE_OFFSET, &rule, sizeof rule);
            memset(&summary, 0, sizeof summary);
            CHECK(gp_section_decode_summary(GP_SECTION_PACK, st.sections[i].version, st.copy[i],
                                            st.sections[i].size, &summary) == GP_EPARSE);
            gp_result_free(&summary);
        }
        unstore(&st);
        gp_result_free(&r);
        gp_spec_free(&spec);
    }
}

/* A 3D packing's sections: the summary decodes to the box, the front's counters and the
 * statistics bit for bit, the spheres section is the spheres as placed, every truncation
 * of the summary is refused, another version is not read, and a 2D reader skips both. */
static void test_pack3d_sections(void)
{
    gp_spec3d spec;
    gp_error err;
    const char *text = "{\"inputs\": {\"domain\": {\"width\": 9, \"height\": 7, \"depth\": 6},"
                       " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.4, \"max\": 0.9},"
                       " \"joint\": {\"law\": \"constant\", \"value\": 0.05}, \"seed\": 4}}";
    CHECK_MSG(gp_spec3d_parse(text, strlen(text), NULL, &spec, &err) == 0, "%s", err.message);
    gp_pack3d_params params = gp_spec3d_pack_params(&spec, 0);
    gp_packing3d p;
    CHECK_MSG(gp_pack3d(&params, NULL, &p, &err) == 0, "%s", err.message);
    gp_pack3d_stats st;
    CHECK(gp_pack3d_stats_compute(&spec.box, &spec.dist, &p, &st) == 0);
    double volume = spec.box.width * spec.box.height * spec.box.depth;
    CHECK(st.count == p.count && p.count > 50 && st.box_volume == volume);
    CHECK_MSG(fabs(st.packing_density - p.fill_volume / volume) < 1e-12 * st.packing_density,
              "density %.17g, fill %.17g", st.packing_density, p.fill_volume / volume);
    size_t binned = 0;
    for (size_t i = 0; i < st.nbins; i++)
        binned += st.bins[i].count;
    CHECK(binned == p.count && st.dof == (int)st.nbins - 1 && st.p_value > 0 && st.p_value <= 1);

    gp_section sec[GP_SECTIONS_MAX];
    size_t n;
    CHECK(gp_sections_from_packing3d(&spec.box, &p, &st, sec, &n) == 0 && n == 2);
    CHECK(strcmp(sec[0].tag, GP_SECTION_PACK3D) == 0 && sec[0].summary);
    CHECK(strcmp(sec[1].tag, GP_SECTION_SPHERES) == 0 && !sec[1].summary &&
          sec[1].size == p.count * 40 && memcmp(sec[1].data, p.spheres, sec[1].size) == 0);
    gp_summary3d sum;
    CHECK(gp_section_decode_summary3d(sec[0].tag, sec[0].version, sec[0].data, sec[0].size, &sum) == 0);
    CHECK(memcmp(&sum.box, &spec.box, sizeof sum.box) == 0 && sum.packing.count == p.count &&
          sum.packing.wall_spheres == p.wall_spheres && sum.packing.triangles == p.triangles &&
          sum.packing.attempts == p.attempts && sum.packing.max_level == p.max_level &&
          sum.packing.fill_volume == p.fill_volume && !sum.packing.spheres);
    CHECK(sum.stats.nbins == st.nbins && memcmp(sum.stats.bins, st.bins, st.nbins * sizeof *st.bins) == 0);
    CHECK(sum.stats.packing_density == st.packing_density && sum.stats.chi2 == st.chi2 &&
          sum.stats.r_min == st.r_min && sum.stats.joint_max == st.joint_max);
    gp_summary3d_free(&sum);
    size_t refused = 0, cuts = 0;
    for (size_t cut = 0; cut < sec[0].size; cut++, cuts++)
        refused += gp_section_decode_summary3d(sec[0].tag, sec[0].version, sec[0].data, cut, &sum) == GP_EPARSE;
    CHECK_MSG(refused == cuts, "%zu of %zu truncations refused", refused, cuts);
    CHECK(gp_section_decode_summary3d(sec[0].tag, sec[0].version + 1, sec[0].data, sec[0].size, &sum) == GP_EINVAL);
    gp_result summary;
    memset(&summary, 0, sizeof summary);
    for (size_t i = 0; i < n; i++)
        CHECK(gp_section_decode_summary(sec[i].tag, sec[i].version, sec[i].data, sec[i].size, &summary) == 0);
    CHECK(summary.packing.count == 0);
    gp_sections_free(sec, n);
    gp_pack3d_stats_free(&st);
    gp_packing3d_free(&p);
    gp_spec3d_free(&spec);
}

/* The sections of `n` copied into `st`, as a store would hold them. */
static void store_sections(stored *st, const gp_section *sec, size_t n)
{
    memset(st, 0, sizeof *st);
    st->n = n;
    for (size_t i = 0; i < n; i++) {
        st->sections[i] = sec[i];
        st->sections[i].owned = NULL; /* the caller's to free */
        st->copy[i] = malloc(sec[i].size + 1);
        memcpy(st->copy[i], sec[i].data, sec[i].size);
    }
}

/* The text of `result` in `format`, written in memory; *len its length. */
static char *render3d(gp_format3d format, const gp_spec3d *spec, const gp_result3d *result, size_t *len)
{
    gp_out o;
    gp_error err;
    CHECK(gp_out_init(&o, 0, NULL, NULL) == 0);
    CHECK_MSG(gp_write_result3d(&o, format, spec, result, &err) == 0, "%s: %s",
              gp_format3d_name(format), err.message);
    *len = o.len;
    return o.buf; /* the caller frees it */
}

/* The text of the stored result (`summary` decoded, the arrays in `st`) in `format`,
 * read `window` cells at a time, each gp_writer_run asked for `step` more bytes (1: it
 * stops after every grain, at least once a grain); *len its length, *rc the writer's
 * last code. */
static char *render_stored3d(gp_format3d format, const gp_spec3d *spec, const gp_result3d *summary,
                           stored *st, size_t window, size_t step, size_t *len, int *rc)
{
    gp_source3d source;
    CHECK(gp_sections_source3d(summary, read_stored, st, window, &source) == 0);
    gp_writer *w = gp_writer3d_new(format, spec, summary, &source);
    CHECK(w != NULL);
    gp_out o;
    CHECK(gp_out_init(&o, 0, NULL, NULL) == 0);
    size_t calls = 0;
    while ((*rc = gp_writer_run(w, &o, step > SIZE_MAX - o.len ? SIZE_MAX : o.len + step)) == 1)
        calls++;
    /* (the svg writes nothing for a grain the section misses) */
    CHECK_MSG(step != 1 || *rc || format == GP_FORMAT3D_SVG || calls >= summary->packing.count,
              "%s: %zu stops for %zu grains",
              gp_format3d_name(format), calls, summary->packing.count);
    gp_writer_free(w);
    gp_source3d_free(&source);
    *len = o.len;
    return o.buf; /* the caller frees it */
}

/* A balanced, tessellated 3D result cut into sections, the summary decoded and the
 * arrays read window by window: every format writes the same bytes from them as from the
 * result in memory, whatever the window (one cell, a few, the default) and however little
 * each call may write; the stored .tess is the text it was given; a summary without its
 * arrays is refused by the writers; a face vertex or neighbour out of range, sizes that
 * overrun the totals, a face larger than its cell or a truncated summary are refused. */
static void test_result3d_sections(void)
{
    gp_spec3d spec;
    gp_error err;
    const char *text = "{\"inputs\": {\"domain\": {\"width\": 6, \"height\": 5, \"depth\": 4},"
                       " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.4, \"max\": 0.8},"
                       " \"joint\": {\"law\": \"constant\", \"value\": 0.05}, \"seed\": 5,"
                       " \"balance\": {\"method\": \"relocation\"}, \"laguerre\": {\"shrink\": \"offset\"},"
                       " \"picture\": {\"section\": {\"axis\": \"x\", \"at\": 0.3}}}}";
    CHECK_MSG(gp_spec3d_parse(text, strlen(text), NULL, &spec, &err) == 0, "%s", err.message);
    gp_result3d r;
    CHECK_MSG(gp_pipeline3d_run(&spec, 0, NULL, &r, &err) == 0, "%s", err.message);
    CHECK(r.has_balance && r.has_cells && r.packing.count > 20);
    size_t tess_len;
    char *tess = render3d(GP_FORMAT3D_TESS, &spec, &r, &tess_len);
    gp_section sec[GP_SECTIONS_MAX];
    size_t n;
    CHECK(gp_sections_from_result3d(&spec.box, &r, tess, tess_len, sec, &n) == 0 && n == 12);
    stored st;
    store_sections(&st, sec, n);
    gp_section raw[GP_SECTIONS_MAX];
    size_t nraw = 0;
    for (size_t i = 0; i < n; i++)
        if (sec[i].summary)
            raw[nraw++] = sec[i];
    CHECK(nraw == 3);
    gp_box box;
    gp_result3d back;
    size_t stored_tess;
    CHECK(gp_section_decode_result3d(raw, nraw, &box, &back, &stored_tess) == 0);
    CHECK(back.has_balance && back.has_cells && stored_tess == tess_len && !back.packing.spheres &&
          !back.cells.vstart && back.cell_stats.faces == r.cell_stats.faces &&
          back.balance.after.max == r.balance.after.max && back.balance.sweeps == r.balance.sweeps);
    CHECK(memcmp(&box, &spec.box, sizeof box) == 0);
    const gp_format3d formats[] = {GP_FORMAT3D_CSV, GP_FORMAT3D_JSON, GP_FORMAT3D_VTU, GP_FORMAT3D_SVG};
    for (size_t k = 0; k < sizeof formats / sizeof formats[0]; k++) {
        size_t a;
        char *want = render3d(formats[k], &spec, &r, &a);
        /* the summary alone: refused, not read through NULL */
        gp_out o;
        CHECK(gp_out_init(&o, 0, NULL, NULL) == 0);
        CHECK_MSG(gp_write_result3d(&o, formats[k], &spec, &back, &err) == GP_EINVAL, "%s of a summary",
                  gp_format3d_name(formats[k]));
        gp_out_free(&o);
        const size_t windows[] = {1, 3, 0}, steps[] = {1, 700, SIZE_MAX};
        for (size_t v = 0; v < 3; v++) {
            size_t b;
            int rc;
            char *got = render_stored3d(formats[k], &spec, &back, &st, windows[v], steps[v], &b, &rc);
            CHECK_MSG(rc == 0 && a == b && memcmp(want, got, a) == 0,
                      "%s: %zu bytes from the sections (window %zu), %zu in memory",
                      gp_format3d_name(formats[k]), b, windows[v], a);
            free(got);
        }
        free(want);
    }
    char *tess_back = malloc(tess_len);
    CHECK(read_stored(&st, GP_SECTION_TESS, 0, tess_back, tess_len) == 0 &&
          memcmp(tess_back, tess, tess_len) == 0);
    free(tess_back);

    /* corrupt arrays: each window is refused, not indexed past (the face vertices by the
     * formats that read them, vtu and svg; the neighbours by json; the sizes by all) */
    const struct {
        const char *tag;
        size_t at;
        uint32_t value;
        gp_format3d format;
    } corruptions[] = {
        {GP_SECTION_CELL3D_FACE_VERTICES, 0, 1000000, GP_FORMAT3D_VTU},
        {GP_SECTION_CELL3D_FACE_VERTICES, 0, 1000000, GP_FORMAT3D_SVG},
        {GP_SECTION_CELL3D_FACE_NEIGHBOURS, 0, (uint32_t)r.packing.count, GP_FORMAT3D_JSON},
        {GP_SECTION_CELL3D_SIZES, 0, 1000000, GP_FORMAT3D_VTU},  /* cell 0's vertices */
        {GP_SECTION_CELL3D_SIZES, 1, 1000000, GP_FORMAT3D_JSON}, /* cell 0's faces */
        {GP_SECTION_CELL3D_FACE_SIZES, 0, 1000, GP_FORMAT3D_SVG},
    };
    for (size_t k = 0; k < sizeof corruptions / sizeof corruptions[0]; k++)
        for (size_t v = 0; v < 2; v++) {
            stored bad;
            store_sections(&bad, sec, n);
            for (size_t i = 0; i < n; i++)
                if (strcmp(sec[i].tag, corruptions[k].tag) == 0)
                    ((uint32_t *)bad.copy[i])[corruptions[k].at] = corruptions[k].value;
            size_t b;
            int rc;
            free(render_stored3d(corruptions[k].format, &spec, &back, &bad, v ? 3 : 0, SIZE_MAX, &b, &rc));
            CHECK_MSG(rc == GP_EPARSE, "corruption %zu of %s (window %d): %d", k, corruptions[k].tag,
                      v ? 3 : 0, rc);
            unstore_copies(&bad);
        }
    gp_result3d_free(&back);
    /* every truncation of the summaries is refused */
    size_t refused = 0, cuts = 0;
    for (size_t i = 0; i < nraw; i++) {
        gp_section cut = raw[i];
        for (cut.size = 0; cut.size < raw[i].size; cut.size++, cuts++) {
            gp_section trial[3];
            memcpy(trial, raw, sizeof trial);
            trial[i] = cut;
            refused += gp_section_decode_result3d(trial, nraw, &box, &back, &stored_tess) == GP_EPARSE;
        }
    }
    CHECK_MSG(refused == cuts, "%zu of %zu truncations refused", refused, cuts);
    unstore_copies(&st);
    gp_sections_free(sec, n);
    free(tess);
    gp_result3d_free(&r);
    gp_spec3d_free(&spec);
}

int main(void)
{
    RUN(test_pack3d_sections);
    RUN(test_result3d_sections);
    RUN(test_every_format_reads_the_same_from_sections);
    RUN(test_mesh_from_sections);
    RUN(test_mesh_sections_refused);
    RUN(test_corrupt_sections_are_refused);
    RUN(test_pack_section_keeps_the_front_rule);
    return check_status();
}
