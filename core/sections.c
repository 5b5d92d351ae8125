/* sections.c - a result cut into tagged binary sections and read back: the summary
 * decoded whole, the per-grain arrays window by window (sections.h has the layouts). */
#include "grainpack/sections.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The layouts are little-endian, the byte order of every machine grainpack targets; the
 * big arrays are then stored as they lie in memory. */
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "sections.c stores little-endian layouts as they lie in memory: a big-endian port must swap"
#endif
_Static_assert(sizeof(gp_disk) == 32, "a disk is stored as four doubles");

/* The version of every section's layout this build writes (and the only one it reads). */
#define LAYOUT_V1 1

/* --- encoding --- */

typedef struct enc {
    unsigned char *buf;
    size_t len, cap;
    int failed;
} enc;

static void put(enc *e, const void *p, size_t n)
{
    if (e->failed)
        return;
    if (e->cap - e->len < n) {
        size_t cap = e->cap ? e->cap : 256;
        while (cap - e->len < n)
            cap *= 2;
        unsigned char *grown = realloc(e->buf, cap);
        if (!grown) {
            e->failed = 1;
            return;
        }
        e->buf = grown;
        e->cap = cap;
    }
    memcpy(e->buf + e->len, p, n);
    e->len += n;
}

static void put_u32(enc *e, uint32_t v) { put(e, &v, sizeof v); }
static void put_u64(enc *e, uint64_t v) { put(e, &v, sizeof v); }
static void put_f64(enc *e, double v) { put(e, &v, sizeof v); }

static void put_bins(enc *e, const gp_bin_stat *bins, size_t n)
{
    put_u64(e, n);
    for (size_t i = 0; i < n; i++) {
        put_f64(e, bins[i].min);
        put_f64(e, bins[i].max);
        put_f64(e, bins[i].target);
        put_u64(e, bins[i].count);
        put_f64(e, bins[i].achieved);
        put_f64(e, bins[i].se);
        put_f64(e, bins[i].z);
    }
}

static void put_counts(enc *e, const size_t *counts, size_t n)
{
    for (size_t i = 0; i < n; i++)
        put_u64(e, counts[i]);
}

static void put_quality(enc *e, const gp_quality_stats *q)
{
    put_u64(e, q->interior);
    put_f64(e, q->min);
    put_f64(e, q->max);
    put_f64(e, q->mean);
    put_counts(e, q->histogram, GP_QUALITY_BINS);
}

static void encode_pack(enc *e, const gp_result *r)
{
    const gp_packing *p = &r->packing;
    const gp_pack_stats *s = &r->stats;
    put_u64(e, p->count);
    put_u64(e, p->initial_front);
    put_u64(e, p->attempts);
    put_u64(e, p->closures);
    put_u64(e, p->frozen);
    put_u64(e, p->capped);
    put_u32(e, p->max_level);
    put_f64(e, p->fill_area);
    put_f64(e, s->domain_area);
    put_f64(e, s->packing_density);
    put_f64(e, s->grain_fraction);
    put_f64(e, s->r_min);
    put_f64(e, s->r_max);
    put_f64(e, s->r_mean);
    put_f64(e, s->joint_min);
    put_f64(e, s->joint_max);
    put_f64(e, s->chi2);
    put_u32(e, (uint32_t)s->dof);
    put_f64(e, s->p_value);
    put_f64(e, s->max_abs_z);
    put_bins(e, s->bins, s->nbins);
}

static void encode_balance(enc *e, const gp_balance_result *b)
{
    put_u32(e, (uint32_t)b->method);
    put_f64(e, b->max_step);
    put_quality(e, &b->before);
    put_quality(e, &b->after);
    put_u64(e, b->count);
    put_u32(e, b->sweeps);
    put_u32(e, b->best_sweep);
    put_u32(e, (uint32_t)b->stop);
    put_u64(e, b->moves);
    put_u64(e, b->refused);
    put_u64(e, b->triangulation.moved_in_place);
    put_u64(e, b->triangulation.flips);
    put_u64(e, b->triangulation.reinserted);
    put_u64(e, b->triangulation.rebuilds);
    put_u32(e, (uint32_t)b->after_only);
}

static void encode_cells(enc *e, const gp_cells *c, const gp_cell_stats *s)
{
    put_u64(e, c->count);
    put_u32(e, (uint32_t)c->shrink);
    put_f64(e, c->power_area_sum);
    put_u64(e, s->count);
    put_u64(e, s->vertices);
    put_u64(e, s->neighbour_links);
    put_f64(e, s->area_min);
    put_f64(e, s->area_max);
    put_f64(e, s->area_mean);
    put_counts(e, s->area_histogram, GP_CELL_AREA_BINS);
    put_f64(e, s->neighbours_mean);
    put_u64(e, s->max_neighbours);
    put_counts(e, s->neighbour_histogram, s->max_neighbours + 1);
    put_f64(e, s->band_fraction);
    put_f64(e, s->tiling_error);
    put_f64(e, s->req_min);
    put_f64(e, s->req_max);
    put_f64(e, s->req_mean);
    put_f64(e, s->req_ratio_mean);
    put_bins(e, s->req_bins, s->nbins);
    put_u64(e, s->req_outside);
    put_f64(e, s->req_max_abs_z);
}

/* Per cell, its vertex and neighbour counts (u32 each). */
static int encode_cell_sizes(enc *e, const gp_cells *c)
{
    for (size_t i = 0; i < c->count; i++) {
        size_t v = c->start[i + 1] - c->start[i], q = c->nstart[i + 1] - c->nstart[i];
        if (v > UINT32_MAX || q > UINT32_MAX)
            return GP_ETOOBIG;
        put_u32(e, (uint32_t)v);
        put_u32(e, (uint32_t)q);
    }
    return 0;
}

/* Adds a section: borrowed bytes (e == NULL), or the encoder's (taken over). */
static void add(gp_section *s, size_t *n, const char *tag, int summary, const void *data,
                size_t size, enc *e)
{
    gp_section *x = &s[(*n)++];
    memset(x, 0, sizeof *x);
    snprintf(x->tag, sizeof x->tag, "%s", tag);
    x->version = LAYOUT_V1;
    x->summary = summary;
    if (e) {
        x->owned = e->buf;
        x->data = e->buf;
        x->size = e->len;
    } else {
        x->data = data;
        x->size = size;
    }
}

int gp_sections_from_result(const gp_result *r, gp_section *s, size_t *n)
{
    *n = 0;
    size_t count = r->packing.count;
    enc e = {0};
    encode_pack(&e, r);
    if (e.failed)
        goto fail;
    add(s, n, GP_SECTION_PACK, 1, NULL, 0, &e);
    add(s, n, GP_SECTION_DISKS, 0, r->packing.disks, count * sizeof(gp_disk), NULL);
    if (r->has_balance) {
        e = (enc){0};
        encode_balance(&e, &r->balance);
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_BALANCE, 1, NULL, 0, &e);
        add(s, n, GP_SECTION_F, 0, r->balance.F, count * sizeof(double), NULL);
    }
    if (r->has_cells) {
        const gp_cells *c = &r->cells;
        e = (enc){0};
        encode_cells(&e, c, &r->cell_stats);
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_CELLS, 1, NULL, 0, &e);
        e = (enc){0};
        int rc = encode_cell_sizes(&e, c);
        if (rc) {
            free(e.buf);
            gp_sections_free(s, *n);
            return rc;
        }
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_CELL_SIZES, 0, NULL, 0, &e);
        add(s, n, GP_SECTION_CELL_XY, 0, c->xy, 2 * c->start[c->count] * sizeof(double), NULL);
        add(s, n, GP_SECTION_CELL_AREA, 0, c->area, c->count * sizeof(double), NULL);
        add(s, n, GP_SECTION_CELL_NEIGHBOURS, 0, c->neighbours,
            c->nstart[c->count] * sizeof(int32_t), NULL);
    }
    return 0;
fail:
    free(e.buf);
    gp_sections_free(s, *n);
    *n = 0;
    return GP_ENOMEM;
}

void gp_sections_free(gp_section *sections, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        free(sections[i].owned);
        sections[i].owned = NULL;
    }
}

/* --- decoding --- */

typedef struct dec {
    const unsigned char *p;
    size_t left;
    int failed;
} dec;

static void get(dec *d, void *dst, size_t n)
{
    if (d->failed || d->left < n) {
        d->failed = 1;
        memset(dst, 0, n);
        return;
    }
    memcpy(dst, d->p, n);
    d->p += n;
    d->left -= n;
}

static uint32_t get_u32(dec *d) { uint32_t v; get(d, &v, sizeof v); return v; }
static uint64_t get_u64(dec *d) { uint64_t v; get(d, &v, sizeof v); return v; }
static double get_f64(dec *d) { double v; get(d, &v, sizeof v); return v; }
static size_t get_size(dec *d) { return (size_t)get_u64(d); }

/* A count of records of `record` bytes each that the rest of the bytes can hold: a
 * corrupt count must not make a huge allocation. */
static size_t get_count(dec *d, size_t record)
{
    size_t n = get_size(d);
    if (n > d->left / record)
        d->failed = 1;
    return d->failed ? 0 : n;
}

static void get_counts(dec *d, size_t *counts, size_t n)
{
    for (size_t i = 0; i < n; i++)
        counts[i] = get_size(d);
}

/* Reads a bin table into a new array (*bins, *n). Returns 0 or GP_ENOMEM. */
static int get_bins(dec *d, gp_bin_stat **bins, size_t *n)
{
    enum { BIN_BYTES = 56 };
    *n = get_count(d, BIN_BYTES);
    *bins = calloc(*n ? *n : 1, sizeof **bins);
    if (!*bins)
        return GP_ENOMEM;
    for (size_t i = 0; i < *n; i++) {
        gp_bin_stat *b = &(*bins)[i];
        b->min = get_f64(d);
        b->max = get_f64(d);
        b->target = get_f64(d);
        b->count = get_size(d);
        b->achieved = get_f64(d);
        b->se = get_f64(d);
        b->z = get_f64(d);
    }
    return 0;
}

static void get_quality(dec *d, gp_quality_stats *q)
{
    q->interior = get_size(d);
    q->min = get_f64(d);
    q->max = get_f64(d);
    q->mean = get_f64(d);
    get_counts(d, q->histogram, GP_QUALITY_BINS);
}

static int decode_pack(dec *d, gp_result *r)
{
    gp_packing *p = &r->packing;
    gp_pack_stats *s = &r->stats;
    gp_pack_stats_free(s);
    p->count = s->count = get_size(d);
    p->initial_front = get_size(d);
    p->attempts = get_u64(d);
    p->closures = get_u64(d);
    p->frozen = get_u64(d);
    p->capped = get_u64(d);
    p->max_level = get_u32(d);
    p->fill_area = get_f64(d);
    s->domain_area = get_f64(d);
    s->packing_density = get_f64(d);
    s->grain_fraction = get_f64(d);
    s->r_min = get_f64(d);
    s->r_max = get_f64(d);
    s->r_mean = get_f64(d);
    s->joint_min = get_f64(d);
    s->joint_max = get_f64(d);
    s->chi2 = get_f64(d);
    s->dof = (int)get_u32(d);
    s->p_value = get_f64(d);
    s->max_abs_z = get_f64(d);
    return get_bins(d, &s->bins, &s->nbins);
}

static int decode_balance(dec *d, gp_result *r)
{
    gp_balance_result *b = &r->balance;
    gp_balance_result_free(b);
    b->method = (gp_balance_method)get_u32(d);
    b->max_step = get_f64(d);
    get_quality(d, &b->before);
    get_quality(d, &b->after);
    b->count = get_size(d);
    b->sweeps = get_u32(d);
    b->best_sweep = get_u32(d);
    b->stop = (gp_balance_stop)get_u32(d);
    b->moves = get_u64(d);
    b->refused = get_u64(d);
    b->triangulation.moved_in_place = get_u64(d);
    b->triangulation.flips = get_u64(d);
    b->triangulation.reinserted = get_u64(d);
    b->triangulation.rebuilds = get_u64(d);
    b->after_only = (int)get_u32(d);
    r->has_balance = !d->failed;
    return 0;
}

static int decode_cells(dec *d, gp_result *r)
{
    gp_cells *c = &r->cells;
    gp_cell_stats *s = &r->cell_stats;
    gp_cell_stats_free(s);
    c->count = get_size(d);
    c->shrink = (gp_shrink)get_u32(d);
    c->power_area_sum = get_f64(d);
    s->count = get_size(d);
    s->vertices = get_size(d);
    s->neighbour_links = get_size(d);
    s->area_min = get_f64(d);
    s->area_max = get_f64(d);
    s->area_mean = get_f64(d);
    get_counts(d, s->area_histogram, GP_CELL_AREA_BINS);
    s->neighbours_mean = get_f64(d);
    s->max_neighbours = get_size(d);
    if (d->failed || s->max_neighbours >= d->left / sizeof(uint64_t)) {
        d->failed = 1;
        return 0;
    }
    s->neighbour_histogram = calloc(s->max_neighbours + 1, sizeof *s->neighbour_histogram);
    if (!s->neighbour_histogram)
        return GP_ENOMEM;
    get_counts(d, s->neighbour_histogram, s->max_neighbours + 1);
    s->band_fraction = get_f64(d);
    s->tiling_error = get_f64(d);
    s->req_min = get_f64(d);
    s->req_max = get_f64(d);
    s->req_mean = get_f64(d);
    s->req_ratio_mean = get_f64(d);
    int rc = get_bins(d, &s->req_bins, &s->nbins);
    s->req_outside = get_size(d);
    s->req_max_abs_z = get_f64(d);
    r->has_cells = !d->failed && rc == 0;
    return rc;
}

int gp_section_decode_summary(const char *tag, uint32_t version, const void *data, size_t size,
                              gp_result *summary)
{
    int (*decode)(dec *, gp_result *) = NULL;
    if (strcmp(tag, GP_SECTION_PACK) == 0)
        decode = decode_pack;
    else if (strcmp(tag, GP_SECTION_BALANCE) == 0)
        decode = decode_balance;
    else if (strcmp(tag, GP_SECTION_CELLS) == 0)
        decode = decode_cells;
    if (!decode)
        return 0;
    if (version != LAYOUT_V1)
        return GP_EINVAL;
    dec d = {data, size, 0};
    int rc = decode(&d, summary);
    if (rc)
        return rc;
    if (d.failed || d.left != 0) {
        summary->has_balance &= strcmp(tag, GP_SECTION_BALANCE) != 0;
        summary->has_cells &= strcmp(tag, GP_SECTION_CELLS) != 0;
        return GP_EPARSE;
    }
    return 0;
}

/* --- the per-grain arrays, window by window --- */

struct gp_sections_source {
    const gp_result *summary;
    gp_section_read_fn read;
    void *ctx;
    size_t window;
    gp_disk *disks;
    double *F, *area;
    uint32_t *sizes;       /* two per grain: vertices, neighbours */
    size_t *start, *nstart;
    double *xy;
    size_t xy_cap;         /* vertices xy has room for */
    int32_t *neighbours;
    size_t neighbours_cap;
    /* where grain `cursor` starts among the vertices and the neighbour entries: a pass
     * reads the grains in order, so the next window starts where the last one ended */
    size_t cursor, vertex_at, neighbour_at;
    /* the window loaded last, and the arrays it holds: a writer stopped in the middle of
     * a window (its output full) goes on from it without reading it again */
    gp_grain_window last;
    unsigned last_needs;
};

/* Makes room for n elements of `size` bytes in *buf (capacity *cap). */
static int reserve(void *bufp, size_t *cap, size_t n, size_t size)
{
    void **buf = bufp;
    if (n <= *cap)
        return 0;
    void *grown = realloc(*buf, (n ? n : 1) * size);
    if (!grown)
        return GP_ENOMEM;
    *buf = grown;
    *cap = n;
    return 0;
}

/* Where grain `first`'s cell starts among the vertices and neighbour entries: where the
 * last window ended, or a sum over the sizes from the start (never on the writers' own
 * order of reads). */
static int locate(gp_sections_source *s, size_t first)
{
    if (first == 0) {
        s->cursor = s->vertex_at = s->neighbour_at = 0;
        return 0;
    }
    if (first == s->cursor)
        return 0;
    s->cursor = s->vertex_at = s->neighbour_at = 0;
    while (s->cursor < first) {
        size_t n = first - s->cursor < s->window ? first - s->cursor : s->window;
        int rc = s->read(s->ctx, GP_SECTION_CELL_SIZES, 8 * (uint64_t)s->cursor, s->sizes, 8 * n);
        if (rc)
            return rc;
        for (size_t j = 0; j < n; j++) {
            s->vertex_at += s->sizes[2 * j];
            s->neighbour_at += s->sizes[2 * j + 1];
        }
        s->cursor += n;
    }
    return 0;
}

static int load_cells(gp_sections_source *s, unsigned needs, size_t first, size_t n,
                      gp_grain_window *win)
{
    int rc = locate(s, first);
    if (rc || (rc = s->read(s->ctx, GP_SECTION_CELL_SIZES, 8 * (uint64_t)first, s->sizes, 8 * n)))
        return rc;
    s->start[0] = s->vertex_at;
    s->nstart[0] = s->neighbour_at;
    for (size_t j = 0; j < n; j++) {
        s->start[j + 1] = s->start[j] + s->sizes[2 * j];
        s->nstart[j + 1] = s->nstart[j] + s->sizes[2 * j + 1];
    }
    const gp_cell_stats *cs = &s->summary->cell_stats;
    if (s->start[n] > cs->vertices || s->nstart[n] > cs->neighbour_links)
        return GP_EPARSE; /* sizes that disagree with the totals: a corrupt store */
    size_t nv = s->start[n] - s->start[0], nq = s->nstart[n] - s->nstart[0];
    win->start = s->start;
    win->nstart = s->nstart;
    win->vertex_base = s->start[0];
    win->neighbour_base = s->nstart[0];
    if (needs & GP_GRAINS_POLYGONS) {
        if ((rc = reserve(&s->xy, &s->xy_cap, 2 * nv, sizeof *s->xy)) ||
            (rc = s->read(s->ctx, GP_SECTION_CELL_XY, 16 * (uint64_t)s->start[0], s->xy, 16 * nv)))
            return rc;
        win->xy = s->xy;
    }
    if (needs & GP_GRAINS_NEIGHBOURS) {
        if ((rc = reserve(&s->neighbours, &s->neighbours_cap, nq, sizeof *s->neighbours)) ||
            (rc = s->read(s->ctx, GP_SECTION_CELL_NEIGHBOURS, 4 * (uint64_t)s->nstart[0],
                          s->neighbours, 4 * nq)))
            return rc;
        win->neighbours = s->neighbours;
    }
    s->cursor = first + n;
    s->vertex_at = s->start[n];
    s->neighbour_at = s->nstart[n];
    return 0;
}

static int load(void *ctx, unsigned needs, size_t first, gp_grain_window *win)
{
    gp_sections_source *s = ctx;
    if (s->last.count && first >= s->last.first && first - s->last.first < s->last.count &&
        (needs & ~s->last_needs) == 0) {
        *win = s->last;
        return 0;
    }
    size_t total = s->summary->packing.count;
    size_t n = total - first < s->window ? total - first : s->window;
    s->last.count = 0;
    memset(win, 0, sizeof *win);
    win->first = first;
    win->count = n;
    int rc = 0;
    if ((needs & GP_GRAINS_DISKS) &&
        !(rc = s->read(s->ctx, GP_SECTION_DISKS, 32 * (uint64_t)first, s->disks, 32 * n)))
        win->disks = s->disks;
    if (!rc && (needs & GP_GRAINS_F) &&
        !(rc = s->read(s->ctx, GP_SECTION_F, 8 * (uint64_t)first, s->F, 8 * n)))
        win->F = s->F;
    if (!rc && (needs & GP_GRAINS_AREA) &&
        !(rc = s->read(s->ctx, GP_SECTION_CELL_AREA, 8 * (uint64_t)first, s->area, 8 * n)))
        win->area = s->area;
    if (!rc && (needs & (GP_GRAINS_POLYGONS | GP_GRAINS_NEIGHBOURS)))
        rc = load_cells(s, needs, first, n, win);
    if (!rc) {
        s->last = *win;
        s->last_needs = needs;
    }
    return rc;
}

gp_sections_source *gp_sections_source_new(const gp_result *summary, gp_section_read_fn read,
                                           void *ctx, size_t window)
{
    gp_sections_source *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->summary = summary;
    s->read = read;
    s->ctx = ctx;
    s->window = window ? window : GP_SECTIONS_WINDOW_GRAINS;
    size_t w = s->window;
    s->disks = malloc(w * sizeof *s->disks);
    s->F = malloc(w * sizeof *s->F);
    s->area = malloc(w * sizeof *s->area);
    s->sizes = malloc(2 * w * sizeof *s->sizes);
    s->start = malloc((w + 1) * sizeof *s->start);
    s->nstart = malloc((w + 1) * sizeof *s->nstart);
    if (!s->disks || !s->F || !s->area || !s->sizes || !s->start || !s->nstart) {
        gp_sections_source_free(s);
        return NULL;
    }
    return s;
}

gp_grain_source gp_sections_source_grains(gp_sections_source *s)
{
    const gp_result *r = s->summary;
    gp_grain_source g = {load, s, 0, 0};
    if (r->has_cells) {
        g.vertex_count = r->cell_stats.vertices;
        g.neighbour_count = r->cell_stats.neighbour_links;
    }
    return g;
}

void gp_sections_source_free(gp_sections_source *s)
{
    if (!s)
        return;
    free(s->disks);
    free(s->F);
    free(s->area);
    free(s->sizes);
    free(s->start);
    free(s->nstart);
    free(s->xy);
    free(s->neighbours);
    free(s);
}
