/* sections.c - a result cut into tagged binary sections and read back: the summary
 * decoded whole, the per-grain arrays window by window (sections.h has the layouts). */
#include "sections.h"
#include "mesh_source.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The layouts are little-endian, the byte order of every machine grainpack targets; the
 * big arrays are then stored as they lie in memory. */
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "sections.c stores little-endian layouts as they lie in memory: a big-endian port must swap"
#endif
_Static_assert(sizeof(gp_disk) == 32, "a disk is stored as four doubles");
_Static_assert(sizeof(gp_sphere) == 40, "a sphere is stored as five doubles");

/* The version of every section's layout this build writes (and the only one it reads),
 * but the mesh summary's (GP_SECTION_MESH_VERSION). */
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

static void put_stats(enc *e, const gp_pack_stats *s);

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
    put_u32(e, (uint32_t)p->rule);
    put_u32(e, p->wait_levels);
    put_f64(e, p->alive_quantile);
    put_f64(e, p->fill_area);
    put_stats(e, s);
}

/* The statistics of a packing (2D or 3D) against its law. */
static void put_stats(enc *e, const gp_pack_stats *s)
{
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

/* The equivalent radii of cells (2D or 3D): min, max, mean, mean ratio, bins, outside,
 * max |z|. */
static void put_req(enc *e, double min, double max, double mean, double ratio_mean,
                    const gp_bin_stat *bins, size_t nbins, size_t outside, double max_abs_z)
{
    put_f64(e, min);
    put_f64(e, max);
    put_f64(e, mean);
    put_f64(e, ratio_mean);
    put_bins(e, bins, nbins);
    put_u64(e, outside);
    put_f64(e, max_abs_z);
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
    put_req(e, s->req_min, s->req_max, s->req_mean, s->req_ratio_mean, s->req_bins, s->nbins,
            s->req_outside, s->req_max_abs_z);
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

/* The mesh's summary: kind, order, counts, each region's polygon area, its statistics. */
static void encode_mesh(enc *e, const gp_mesh *m)
{
    const gp_mesh_stats *s = &m->stats;
    put_u32(e, (uint32_t)m->kind);
    put_u32(e, (uint32_t)m->order);
    put_u64(e, m->ngrains);
    put_u64(e, m->nnodes);
    put_u64(e, m->ntri);
    put_u64(e, m->nquad);
    put_u64(e, m->nbedges);
    for (size_t i = 0; i <= m->ngrains; i++)
        put_f64(e, m->region_area[i]);
    put_u64(e, s->nodes);
    put_u64(e, s->triangles);
    put_u64(e, s->quads);
    put_u64(e, s->boundary_edges);
    put_f64(e, s->min_angle);
    put_f64(e, s->max_angle);
    put_u64(e, s->below_min_angle);
    put_f64(e, s->min_input_angle);
    put_f64(e, s->quality_min);
    put_f64(e, s->quality_mean);
    put_counts(e, s->quality_histogram, GP_MESH_QUALITY_BINS);
    put_f64(e, s->domain_area);
    put_f64(e, s->element_area);
    put_f64(e, s->grain_area);
    put_f64(e, s->grain_polygon_area);
    put_f64(e, s->phase_area);
    put_f64(e, s->phase_polygon_area);
    put_u64(e, s->band_strips);
    put_f64(e, s->band_thickness_min);
    put_f64(e, s->band_thickness_mean);
    put_u64(e, s->refused_refinements);
    /* added after the first stored meshes: read only when present */
    put_u64(e, s->periodic_pairs[0]);
    put_u64(e, s->periodic_pairs[1]);
    put_u32(e, (uint32_t)s->rounds);
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
    if (r->has_mesh) {
        const gp_mesh *m = &r->mesh;
        e = (enc){0};
        encode_mesh(&e, m);
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_MESH, 1, NULL, 0, &e);
        s[*n - 1].version = GP_SECTION_MESH_VERSION;
        add(s, n, GP_SECTION_MESH_XY, 0, m->xy, 2 * m->nnodes * sizeof(double), NULL);
        add(s, n, GP_SECTION_MESH_TRI, 0, m->tri,
            m->ntri * (size_t)gp_mesh_tri_nodes(m->order) * sizeof(int32_t), NULL);
        add(s, n, GP_SECTION_MESH_TRI_REGION, 0, m->tri_region, m->ntri * sizeof(int32_t), NULL);
        add(s, n, GP_SECTION_MESH_QUAD, 0, m->quad,
            m->nquad * (size_t)gp_mesh_quad_nodes(m->order) * sizeof(int32_t), NULL);
        add(s, n, GP_SECTION_MESH_QUAD_REGION, 0, m->quad_region, m->nquad * sizeof(int32_t), NULL);
        add(s, n, GP_SECTION_MESH_BEDGE, 0, m->bedge,
            m->nbedges * (size_t)(m->order + 1) * sizeof(int32_t), NULL);
        add(s, n, GP_SECTION_MESH_BEDGE_SIDE, 0, m->bedge_side, m->nbedges, NULL);
        /* the elements' qualities, which need their nodes: a download reads the nodes
           window by window, not the ones an element happens to use */
        e = (enc){0};
        for (size_t k = 0; k < m->ntri + m->nquad && !e.failed; k++)
            put_f64(&e, gp_mesh_quality_at(m, k));
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_MESH_QUALITY, 0, NULL, 0, &e);
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

static int get_stats(dec *d, gp_pack_stats *s);

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
    /* a packing ran under one of two rules (the default is the waiting rule it chose) */
    uint32_t rule = get_u32(d);
    if (rule != GP_FRONT_LEVEL_BAND && rule != GP_FRONT_WAIT)
        d->failed = 1;
    p->rule = (gp_front_rule)rule;
    p->wait_levels = get_u32(d);
    p->alive_quantile = get_f64(d);
    p->fill_area = get_f64(d);
    return get_stats(d, s);
}

/* The statistics of a packing (2D or 3D), as put_stats wrote them. */
static int get_stats(dec *d, gp_pack_stats *s)
{
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

/* A histogram of max + 1 counts after its max (a corrupt max must not make a huge
 * allocation: it fails the decoder instead). Returns 0 or GP_ENOMEM. */
static int get_histogram(dec *d, size_t *max, size_t **out)
{
    *max = get_size(d);
    if (d->failed || *max >= d->left / sizeof(uint64_t)) {
        d->failed = 1;
        return 0;
    }
    if (!(*out = calloc(*max + 1, sizeof **out)))
        return GP_ENOMEM;
    get_counts(d, *out, *max + 1);
    return 0;
}

/* The equivalent radii of cells (2D or 3D), as put_req wrote them. */
typedef struct req_fields {
    double *min, *max, *mean, *ratio_mean;
    gp_bin_stat **bins;
    size_t *nbins, *outside;
    double *max_abs_z;
} req_fields;

static int get_req(dec *d, req_fields f)
{
    *f.min = get_f64(d);
    *f.max = get_f64(d);
    *f.mean = get_f64(d);
    *f.ratio_mean = get_f64(d);
    int rc = get_bins(d, f.bins, f.nbins);
    *f.outside = get_size(d);
    *f.max_abs_z = get_f64(d);
    return rc;
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
    int rc = get_histogram(d, &s->max_neighbours, &s->neighbour_histogram);
    if (rc || d->failed)
        return rc;
    s->band_fraction = get_f64(d);
    s->tiling_error = get_f64(d);
    rc = get_req(d, (req_fields){&s->req_min, &s->req_max, &s->req_mean, &s->req_ratio_mean,
                                 &s->req_bins, &s->nbins, &s->req_outside, &s->req_max_abs_z});
    r->has_cells = !d->failed && rc == 0;
    return rc;
}

static int decode_mesh(dec *d, gp_result *r)
{
    gp_mesh *m = &r->mesh;
    gp_mesh_free(m);
    gp_mesh_stats *s = &m->stats;
    m->kind = (gp_mesh_kind)get_u32(d);
    m->order = (int)get_u32(d);
    m->ngrains = get_count(d, sizeof(double));
    m->nnodes = get_size(d);
    m->ntri = get_size(d);
    m->nquad = get_size(d);
    m->nbedges = get_size(d);
    if (m->order != 1 && m->order != 2)
        d->failed = 1;
    if (d->failed)
        return 0;
    m->region_area = calloc(m->ngrains + 1, sizeof *m->region_area);
    if (!m->region_area)
        return GP_ENOMEM;
    for (size_t i = 0; i <= m->ngrains; i++)
        m->region_area[i] = get_f64(d);
    s->nodes = get_size(d);
    s->triangles = get_size(d);
    s->quads = get_size(d);
    s->boundary_edges = get_size(d);
    s->min_angle = get_f64(d);
    s->max_angle = get_f64(d);
    s->below_min_angle = get_size(d);
    s->min_input_angle = get_f64(d);
    s->quality_min = get_f64(d);
    s->quality_mean = get_f64(d);
    get_counts(d, s->quality_histogram, GP_MESH_QUALITY_BINS);
    s->domain_area = get_f64(d);
    s->element_area = get_f64(d);
    s->grain_area = get_f64(d);
    s->grain_polygon_area = get_f64(d);
    s->phase_area = get_f64(d);
    s->phase_polygon_area = get_f64(d);
    s->band_strips = get_size(d);
    s->band_thickness_min = get_f64(d);
    s->band_thickness_mean = get_f64(d);
    s->refused_refinements = get_size(d);
    if (d->left > 0) { /* a mesh stored before the periodic pairs had none */
        s->periodic_pairs[0] = get_size(d);
        s->periodic_pairs[1] = get_size(d);
        s->rounds = (int)get_u32(d);
    }
    r->has_mesh = !d->failed;
    return 0;
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
    else if (strcmp(tag, GP_SECTION_MESH) == 0)
        decode = decode_mesh;
    if (!decode)
        return 0;
    /* the mesh summary's layout is the same in both its versions */
    if (version != LAYOUT_V1 && !(decode == decode_mesh && version == GP_SECTION_MESH_VERSION))
        return GP_EINVAL;
    dec d = {data, size, 0};
    int rc = decode(&d, summary);
    if (rc)
        return rc;
    if (d.failed || d.left != 0) {
        summary->has_balance &= strcmp(tag, GP_SECTION_BALANCE) != 0;
        summary->has_cells &= strcmp(tag, GP_SECTION_CELLS) != 0;
        summary->has_mesh &= strcmp(tag, GP_SECTION_MESH) != 0;
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

/* --- the mesh, whole --- */

/* Reads section `tag`, `count` records of `size` bytes, into a new array at *dst. */
static int read_array(gp_section_read_fn read, void *ctx, const char *tag, size_t count,
                      size_t size, void **dst)
{
    *dst = malloc(count ? count * size : 1);
    if (!*dst)
        return GP_ENOMEM;
    return count ? read(ctx, tag, 0, *dst, count * size) : 0;
}

int gp_sections_read_mesh(gp_result *summary, gp_section_read_fn read, void *ctx)
{
    gp_mesh *m = &summary->mesh;
    if (!summary->has_mesh)
        return GP_EINVAL;
    if (m->xy) /* read already */
        return 0;
    size_t tri = (size_t)gp_mesh_tri_nodes(m->order), quad = (size_t)gp_mesh_quad_nodes(m->order);
    void *p[7] = {0};
    int rc;
    if ((rc = read_array(read, ctx, GP_SECTION_MESH_XY, 2 * m->nnodes, sizeof(double), &p[0])) ||
        (rc = read_array(read, ctx, GP_SECTION_MESH_TRI, tri * m->ntri, sizeof(int32_t), &p[1])) ||
        (rc = read_array(read, ctx, GP_SECTION_MESH_TRI_REGION, m->ntri, sizeof(int32_t), &p[2])) ||
        (rc = read_array(read, ctx, GP_SECTION_MESH_QUAD, quad * m->nquad, sizeof(int32_t), &p[3])) ||
        (rc = read_array(read, ctx, GP_SECTION_MESH_QUAD_REGION, m->nquad, sizeof(int32_t), &p[4])) ||
        (rc = read_array(read, ctx, GP_SECTION_MESH_BEDGE, (size_t)(m->order + 1) * m->nbedges,
                         sizeof(int32_t), &p[5])) ||
        (rc = read_array(read, ctx, GP_SECTION_MESH_BEDGE_SIDE, m->nbedges, 1, &p[6])))
        goto fail;
    /* a stored node index beyond the nodes, or a region beyond the regions, would make a
     * writer read out of bounds */
    const int32_t *idx[5] = {p[1], p[3], p[5], p[2], p[4]};
    size_t len[5] = {tri * m->ntri, quad * m->nquad, (size_t)(m->order + 1) * m->nbedges, m->ntri,
                     m->nquad};
    for (int a = 0; a < 5 && rc == 0; a++)
        for (size_t i = 0; i < len[a]; i++)
            if (idx[a][i] < 0 || (size_t)idx[a][i] >= (a < 3 ? m->nnodes : m->ngrains + 1)) {
                rc = GP_EPARSE;
                break;
            }
    for (size_t i = 0; i < m->nbedges && rc == 0; i++)
        if (((const uint8_t *)p[6])[i] >= GP_SIDE_COUNT)
            rc = GP_EPARSE;
    if (rc) {
    fail:
        for (int i = 0; i < 7; i++)
            free(p[i]);
        return rc;
    }
    m->xy = p[0];
    m->tri = p[1];
    m->tri_region = p[2];
    m->quad = p[3];
    m->quad_region = p[4];
    m->bedge = p[5];
    m->bedge_side = p[6];
    return 0;
}

/* --- the 3D packing --- */

gp_pack_stats gp_pack3d_stats_view(const gp_pack3d_stats *st)
{
    return (gp_pack_stats){.count = st->count, .domain_area = st->box_volume,
                           .packing_density = st->packing_density,
                           .grain_fraction = st->grain_fraction, .r_min = st->r_min,
                           .r_max = st->r_max, .r_mean = st->r_mean, .joint_min = st->joint_min,
                           .joint_max = st->joint_max, .nbins = st->nbins, .bins = st->bins,
                           .chi2 = st->chi2, .dof = st->dof, .p_value = st->p_value,
                           .max_abs_z = st->max_abs_z};
}

int gp_sections_from_packing3d(const gp_box *box, const gp_packing3d *p,
                               const gp_pack3d_stats *stats3d, gp_section *s, size_t *n)
{
    gp_pack_stats view = gp_pack3d_stats_view(stats3d), *stats = &view;
    *n = 0;
    enc e = {0};
    put_f64(&e, box->width);
    put_f64(&e, box->height);
    put_f64(&e, box->depth);
    put_u64(&e, p->count);
    put_u64(&e, p->wall_spheres);
    put_u64(&e, p->triangles);
    put_u64(&e, p->attempts);
    put_u32(&e, p->max_level);
    put_f64(&e, p->fill_volume);
    put_stats(&e, stats);
    if (e.failed) {
        free(e.buf);
        return GP_ENOMEM;
    }
    add(s, n, GP_SECTION_PACK3D, 1, NULL, 0, &e);
    add(s, n, GP_SECTION_SPHERES, 0, p->spheres, p->count * sizeof(gp_sphere), NULL);
    return 0;
}

int gp_section_decode_summary3d(const char *tag, uint32_t version, const void *data, size_t size,
                                gp_summary3d *out)
{
    memset(out, 0, sizeof *out);
    if (strcmp(tag, GP_SECTION_PACK3D) != 0 || version != LAYOUT_V1)
        return GP_EINVAL;
    dec d = {data, size, 0};
    out->box.width = get_f64(&d);
    out->box.height = get_f64(&d);
    out->box.depth = get_f64(&d);
    gp_packing3d *p = &out->packing;
    p->count = out->stats.count = get_size(&d);
    p->wall_spheres = get_size(&d);
    p->triangles = get_u64(&d);
    p->attempts = get_u64(&d);
    p->max_level = get_u32(&d);
    p->fill_volume = get_f64(&d);
    gp_pack_stats st = {0};
    int rc = get_stats(&d, &st);
    out->stats = (gp_pack3d_stats){.count = p->count, .box_volume = st.domain_area,
                                   .packing_density = st.packing_density,
                                   .grain_fraction = st.grain_fraction, .r_min = st.r_min,
                                   .r_max = st.r_max, .r_mean = st.r_mean,
                                   .joint_min = st.joint_min, .joint_max = st.joint_max,
                                   .nbins = st.nbins, .bins = st.bins, .chi2 = st.chi2,
                                   .dof = st.dof, .p_value = st.p_value,
                                   .max_abs_z = st.max_abs_z};
    if (rc == 0 && (d.failed || d.left != 0))
        rc = GP_EPARSE;
    if (rc)
        gp_summary3d_free(out);
    return rc;
}

void gp_summary3d_free(gp_summary3d *summary)
{
    gp_pack3d_stats_free(&summary->stats);
    memset(summary, 0, sizeof *summary);
}

/* --- the 3D stages after packing --- */

/* The polyhedra's summary: count, shrink, their statistics (with the totals of vertices
 * and faces), the .tess text's length. */
static void encode_cells3d(enc *e, const gp_cells3d *c, const gp_cell3d_stats *s, size_t tess_len)
{
    put_u64(e, c->count);
    put_u32(e, (uint32_t)c->shrink);
    put_f64(e, c->power_volume_sum);
    put_u64(e, s->count);
    put_u64(e, s->faces);
    put_u64(e, s->vertices);
    put_f64(e, s->volume_min);
    put_f64(e, s->volume_max);
    put_f64(e, s->volume_mean);
    put_counts(e, s->volume_histogram, GP_CELL_VOLUME_BINS);
    put_f64(e, s->faces_mean);
    put_u64(e, s->max_faces);
    put_counts(e, s->faces_histogram, s->max_faces + 1);
    put_f64(e, s->neighbours_mean);
    put_f64(e, s->boundary_fraction);
    put_f64(e, s->tiling_error);
    put_req(e, s->req_min, s->req_max, s->req_mean, s->req_ratio_mean, s->req_bins, s->nbins,
            s->req_outside, s->req_max_abs_z);
    put_u64(e, tess_len);
}

/* Per cell its vertex and face counts, into `sizes`; per face its vertex count, into
 * `face_sizes`. Returns 0 or GP_ETOOBIG. */
static int encode_cell3d_sizes(enc *sizes, enc *face_sizes, const gp_cells3d *c)
{
    for (size_t i = 0; i < c->count; i++) {
        size_t v = c->vstart[i + 1] - c->vstart[i], f = c->fstart[i + 1] - c->fstart[i];
        if (v > UINT32_MAX || f > UINT32_MAX)
            return GP_ETOOBIG;
        put_u32(sizes, (uint32_t)v);
        put_u32(sizes, (uint32_t)f);
    }
    for (size_t f = 0; f < c->fstart[c->count]; f++) {
        size_t k = c->fvstart[f + 1] - c->fvstart[f];
        if (k > UINT32_MAX)
            return GP_ETOOBIG;
        put_u32(face_sizes, (uint32_t)k);
    }
    return 0;
}

int gp_sections_from_result3d(const gp_box *box, const gp_result3d *r, const char *tess,
                              size_t tess_len, gp_section *s, size_t *n)
{
    int rc = gp_sections_from_packing3d(box, &r->packing, &r->stats, s, n);
    if (rc)
        return rc;
    enc e = {0}, f = {0};
    if (r->has_balance) {
        encode_balance(&e, &r->balance);
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_BALANCE3D, 1, NULL, 0, &e);
        add(s, n, GP_SECTION_F, 0, r->balance.F, r->packing.count * sizeof(double), NULL);
    }
    if (r->has_cells) {
        const gp_cells3d *c = &r->cells;
        size_t faces = c->fstart[c->count];
        e = (enc){0};
        encode_cells3d(&e, c, &r->cell_stats, tess ? tess_len : 0);
        if (e.failed)
            goto fail;
        add(s, n, GP_SECTION_CELLS3D, 1, NULL, 0, &e);
        e = (enc){0};
        rc = encode_cell3d_sizes(&e, &f, c);
        if (rc || e.failed || f.failed)
            goto fail;
        add(s, n, GP_SECTION_CELL3D_SIZES, 0, NULL, 0, &e);
        add(s, n, GP_SECTION_CELL3D_FACE_SIZES, 0, NULL, 0, &f);
        e = f = (enc){0};
        add(s, n, GP_SECTION_CELL3D_FACE_NEIGHBOURS, 0, c->fneighbour, faces * sizeof(int32_t), NULL);
        add(s, n, GP_SECTION_CELL3D_FACE_VERTICES, 0, c->fverts, c->fvstart[faces] * sizeof(uint32_t),
            NULL);
        add(s, n, GP_SECTION_CELL3D_XYZ, 0, c->xyz, 3 * c->vstart[c->count] * sizeof(double), NULL);
        add(s, n, GP_SECTION_CELL3D_VOLUME, 0, c->volume, c->count * sizeof(double), NULL);
    }
    if (tess)
        add(s, n, GP_SECTION_TESS, 0, tess, tess_len, NULL);
    return 0;
fail:
    free(e.buf);
    free(f.buf);
    gp_sections_free(s, *n);
    *n = 0;
    return rc ? rc : GP_ENOMEM;
}

static int decode_cells3d(dec *d, gp_result3d *r, size_t *tess_len)
{
    gp_cells3d *c = &r->cells;
    gp_cell3d_stats *s = &r->cell_stats;
    c->count = get_size(d);
    c->shrink = (gp_shrink)get_u32(d);
    c->power_volume_sum = get_f64(d);
    if (c->shrink != GP_SHRINK_NONE && c->shrink != GP_SHRINK_OFFSET &&
        c->shrink != GP_SHRINK_HOMOTHETIC)
        d->failed = 1;
    s->count = get_size(d);
    s->faces = get_size(d);
    s->vertices = get_size(d);
    s->volume_min = get_f64(d);
    s->volume_max = get_f64(d);
    s->volume_mean = get_f64(d);
    get_counts(d, s->volume_histogram, GP_CELL_VOLUME_BINS);
    s->faces_mean = get_f64(d);
    int rc = get_histogram(d, &s->max_faces, &s->faces_histogram);
    if (rc || d->failed)
        return rc;
    s->neighbours_mean = get_f64(d);
    s->boundary_fraction = get_f64(d);
    s->tiling_error = get_f64(d);
    rc = get_req(d, (req_fields){&s->req_min, &s->req_max, &s->req_mean, &s->req_ratio_mean,
                                 &s->req_bins, &s->nbins, &s->req_outside, &s->req_max_abs_z});
    *tess_len = get_size(d);
    return rc;
}

int gp_section_decode_result3d(const gp_section *raw, size_t nraw, gp_box *box, gp_result3d *out,
                               size_t *tess_len)
{
    memset(out, 0, sizeof *out);
    memset(box, 0, sizeof *box);
    *tess_len = 0;
    int rc = GP_EINVAL;
    for (size_t i = 0; i < nraw; i++)
        if (strcmp(raw[i].tag, GP_SECTION_PACK3D) == 0) {
            gp_summary3d sum;
            rc = gp_section_decode_summary3d(raw[i].tag, raw[i].version, raw[i].data, raw[i].size,
                                             &sum);
            if (rc)
                return rc;
            *box = sum.box;
            out->packing = sum.packing;
            out->stats = sum.stats; /* its bins taken over */
        }
    for (size_t i = 0; i < nraw && rc == 0; i++) {
        int balance = strcmp(raw[i].tag, GP_SECTION_BALANCE3D) == 0;
        int cells = strcmp(raw[i].tag, GP_SECTION_CELLS3D) == 0;
        if (!balance && !cells)
            continue;
        if (raw[i].version != LAYOUT_V1) {
            rc = GP_EINVAL;
            break;
        }
        dec d = {raw[i].data, raw[i].size, 0};
        if (balance) {
            out->has_balance = 1;
            gp_result tmp = {0};
            rc = decode_balance(&d, &tmp);
            out->balance = tmp.balance;
        } else {
            out->has_cells = 1;
            rc = decode_cells3d(&d, out, tess_len);
            if (out->cell_stats.count != out->cells.count)
                d.failed = 1;
        }
        if (rc == 0 && (d.failed || d.left != 0))
            rc = GP_EPARSE;
    }
    if (rc)
        gp_result3d_free(out);
    return rc;
}

/* --- the mesh, window by window --- */

static const char *const mesh_tags[GP_MESH_ARRAYS] = {
    GP_SECTION_MESH_XY, GP_SECTION_MESH_TRI, GP_SECTION_MESH_TRI_REGION, GP_SECTION_MESH_QUAD,
    GP_SECTION_MESH_QUAD_REGION, GP_SECTION_MESH_BEDGE, GP_SECTION_MESH_BEDGE_SIDE,
    GP_SECTION_MESH_QUALITY,
};

typedef struct sections_mesh {
    const gp_mesh *m;            /* the summary's: counts and order */
    gp_section_read_fn read;
    void *ctx;
    size_t window;
    int quality;                 /* the qualities are stored */
    void *buf[GP_MESH_ARRAYS];   /* `window` records of each array */
} sections_mesh;

/* Whether n records of array `a` hold node indices, regions and sides in range: a
 * corrupt store must not make a writer read out of bounds. */
static int in_range(const gp_mesh *m, gp_mesh_array a, const void *data, size_t n)
{
    size_t values = n * gp_mesh_record_size(m, a), limit;
    switch (a) {
    case GP_MESH_TRI:
    case GP_MESH_QUAD:
    case GP_MESH_BEDGE: limit = m->nnodes; values /= sizeof(int32_t); break;
    case GP_MESH_TRI_REGION:
    case GP_MESH_QUAD_REGION: limit = m->ngrains + 1; values /= sizeof(int32_t); break;
    case GP_MESH_BEDGE_SIDE:
        for (size_t k = 0; k < n; k++)
            if (((const uint8_t *)data)[k] >= GP_SIDE_COUNT)
                return 0;
        return 1;
    default: return 1;
    }
    const int32_t *v = data;
    for (size_t k = 0; k < values; k++)
        if (v[k] < 0 || (size_t)v[k] >= limit)
            return 0;
    return 1;
}

static int load_mesh(void *ctx, gp_mesh_array a, size_t first, const void **data, size_t *count)
{
    sections_mesh *s = ctx;
    if (a == GP_MESH_QUALITY && !s->quality)
        return GP_EINVAL;
    size_t total = gp_mesh_record_count(s->m, a), size = gp_mesh_record_size(s->m, a);
    if (first >= total)
        return GP_EINVAL;
    size_t n = total - first < s->window ? total - first : s->window;
    int rc = s->read(s->ctx, mesh_tags[a], (uint64_t)first * size, s->buf[a], n * size);
    if (rc)
        return rc;
    if (!in_range(s->m, a, s->buf[a], n))
        return GP_EPARSE;
    *data = s->buf[a];
    *count = n;
    return 0;
}

static void drop_mesh(void *ctx)
{
    sections_mesh *s = ctx;
    for (int a = 0; a < GP_MESH_ARRAYS; a++)
        free(s->buf[a]);
    free(s);
}

int gp_sections_mesh_source(const gp_result *summary, gp_section_read_fn read, void *ctx,
                            size_t window, int quality, gp_mesh_source *out)
{
    if (!summary->has_mesh)
        return GP_EINVAL;
    sections_mesh *s = calloc(1, sizeof *s);
    if (!s)
        return GP_ENOMEM;
    *s = (sections_mesh){&summary->mesh, read, ctx, window ? window : GP_MESH_WINDOW_RECORDS, quality,
                         {NULL}};
    for (int a = 0; a < GP_MESH_ARRAYS; a++)
        if (!(s->buf[a] = malloc(s->window * gp_mesh_record_size(s->m, (gp_mesh_array)a)))) {
            drop_mesh(s);
            return GP_ENOMEM;
        }
    *out = (gp_mesh_source){load_mesh, s, drop_mesh};
    return 0;
}
