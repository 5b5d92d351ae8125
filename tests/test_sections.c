/* test_sections.c - a result cut into tagged sections and read back: the summary decodes
 * to the same statistics, and every writer gives the very bytes of the result in memory
 * when it reads the per-grain arrays from the sections window by window (windows of a few
 * grains, so that every cell boundary falls on one), and when it is stopped and resumed
 * every few bytes. Corrupt or truncated sections are refused, not read past. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/sections.h"
#include "packing_checks.h"
#include "render_checks.h"

/* The sections of a result copied into memory, as a store would hold them. */
typedef struct stored {
    gp_section sections[GP_SECTIONS_MAX];
    size_t n;
    unsigned char *copy[GP_SECTIONS_MAX];
    size_t reads; /* calls of read_stored */
} stored;

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

/* Writes through the sections, `step` bytes at a time (SIZE_MAX: at once). */
static char *render_stored(gp_format f, const gp_spec *spec, const gp_result *summary, stored *st,
                           size_t window, size_t step, size_t *len)
{
    gp_sections_source *src = gp_sections_source_new(summary, read_stored, st, window);
    gp_grain_source g = gp_sections_source_grains(src);
    gp_writer *w = gp_writer_new(f, spec, summary, &g);
    gp_out out;
    CHECK(gp_out_init(&out, 0, NULL, NULL) == 0);
    int rc;
    size_t calls = 0;
    while ((rc = gp_writer_run(w, &out, step == SIZE_MAX ? SIZE_MAX : out.len + step)) == 1)
        calls++;
    CHECK(rc == 0);
    CHECK(step == SIZE_MAX || calls > 10);
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
    /* windows of 7 grains: cells straddle every kind of boundary; 1024: the default */
    const size_t windows[] = {7, 0};
    for (int f = 0; f < (int)gp_format_count(); f++) {
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
    CHECK(gp_section_decode_summary("mesh", 7, "x", 1, &summary) == 0);
    unstore(&st);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

int main(void)
{
    RUN(test_every_format_reads_the_same_from_sections);
    RUN(test_corrupt_sections_are_refused);
    return check_status();
}
