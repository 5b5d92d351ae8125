/* io_json.c - the statistics object, a compact JSON emitter with shortest doubles, and the
 * full JSON result. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json_values.h"
#include "writer.h"
#include "io_mesh_json.h"

/* json_object_set_new that remembers a failure instead of returning it at every call. */
static void put(json_t *obj, const char *key, json_t *value, int *failed)
{
    if (!value || json_object_set_new(obj, key, value))
        *failed = 1;
}

/* The achieved-versus-target table: one object per bin. */
json_t *gp_json_bins(const gp_bin_stat *table, size_t nbins, int *failed)
{
    json_t *bins = json_array();
    if (!bins)
        *failed = 1;
    for (size_t i = 0; bins && i < nbins; i++) {
        const gp_bin_stat *b = &table[i];
        json_t *bin = json_object();
        if (!bin) {
            *failed = 1;
            break;
        }
        put(bin, "min", json_real(b->min), failed);
        put(bin, "max", json_real(b->max), failed);
        put(bin, "target", json_real(b->target), failed);
        put(bin, "count", json_integer((json_int_t)b->count), failed);
        put(bin, "achieved", json_real(b->achieved), failed);
        put(bin, "se", json_real(b->se), failed);
        put(bin, "z", json_real(b->z), failed);
        if (json_array_append_new(bins, bin))
            *failed = 1;
    }
    return bins;
}

static json_t *distribution_json(const gp_pack_stats *st, int *failed)
{
    json_t *bins = gp_json_bins(st->bins, st->nbins, failed);
    json_t *d = json_object();
    if (!d) {
        json_decref(bins);
        *failed = 1;
        return NULL;
    }
    put(d, "bins", bins, failed);
    put(d, "chi2", json_real(st->chi2), failed);
    put(d, "dof", json_integer(st->dof), failed);
    put(d, "p_value", json_real(st->p_value), failed);
    put(d, "max_abs_z", json_real(st->max_abs_z), failed);
    return d;
}

json_t *gp_distribution_stats_json(const gp_pack_stats *st)
{
    int failed = 0;
    json_t *d = distribution_json(st, &failed);
    if (failed) {
        json_decref(d);
        return NULL;
    }
    return d;
}

json_t *gp_json_counts(const size_t *counts, size_t n, int *failed)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++)
        if (json_array_append_new(a, json_integer((json_int_t)counts[i])))
            *failed = 1;
    if (!a)
        *failed = 1;
    return a;
}

static json_t *quality_json(const gp_quality_stats *q, int *failed)
{
    json_t *o = json_object();
    if (!o) {
        *failed = 1;
        return NULL;
    }
    put(o, "interior", json_integer((json_int_t)q->interior), failed);
    put(o, "min", json_real(q->min), failed);
    put(o, "max", json_real(q->max), failed);
    put(o, "mean", json_real(q->mean), failed);
    put(o, "histogram", gp_json_counts(q->histogram, GP_QUALITY_BINS, failed), failed);
    return o;
}

json_t *gp_json_balance(const gp_balance_result *b, int *failed)
{
    json_t *o = json_object(), *t = json_object();
    if (!o || !t) {
        json_decref(o);
        json_decref(t);
        *failed = 1;
        return NULL;
    }
    put(o, "method", json_string(gp_balance_method_name(b->method)), failed);
    put(o, "max_step", json_real(b->max_step), failed);
    if (b->after_only) { /* rebuilt from the final disks: the run itself is not known */
        json_decref(t);
        put(o, "after", quality_json(&b->after, failed), failed);
        return o;
    }
    put(o, "sweeps", json_integer(b->sweeps), failed);
    put(o, "best_sweep", json_integer(b->best_sweep), failed);
    put(o, "stop", json_string(gp_balance_stop_name(b->stop)), failed);
    put(o, "moves", json_integer((json_int_t)b->moves), failed);
    put(o, "refused", json_integer((json_int_t)b->refused), failed);
    put(t, "moved_in_place", json_integer((json_int_t)b->triangulation.moved_in_place), failed);
    put(t, "flips", json_integer((json_int_t)b->triangulation.flips), failed);
    put(t, "reinserted", json_integer((json_int_t)b->triangulation.reinserted), failed);
    put(t, "rebuilds", json_integer((json_int_t)b->triangulation.rebuilds), failed);
    put(o, "triangulation", t, failed);
    put(o, "before", quality_json(&b->before, failed), failed);
    put(o, "after", quality_json(&b->after, failed), failed);
    return o;
}

static json_t *cells_json(const gp_spec *spec, const gp_cell_stats *c, int *failed)
{
    json_t *o = json_object(), *area = json_object(), *nb = json_object(), *req = json_object();
    if (!o || !area || !nb || !req) {
        json_decref(o);
        json_decref(area);
        json_decref(nb);
        json_decref(req);
        *failed = 1;
        return NULL;
    }
    put(o, "count", json_integer((json_int_t)c->count), failed);
    put(o, "shrink", json_string(gp_shrink_name(spec->laguerre.shrink)), failed);
    put(o, "flush_boundary", json_boolean(spec->laguerre.flush_boundary), failed);
    put(area, "min", json_real(c->area_min), failed);
    put(area, "max", json_real(c->area_max), failed);
    put(area, "mean", json_real(c->area_mean), failed);
    put(area, "histogram", gp_json_counts(c->area_histogram, GP_CELL_AREA_BINS, failed), failed);
    put(o, "area", area, failed);
    put(nb, "mean", json_real(c->neighbours_mean), failed);
    put(nb, "histogram", gp_json_counts(c->neighbour_histogram, c->max_neighbours + 1, failed), failed);
    put(o, "neighbours", nb, failed);
    put(o, "band_fraction", json_real(c->band_fraction), failed);
    put(o, "tiling_error", json_real(c->tiling_error), failed);
    put(req, "min", json_real(c->req_min), failed);
    put(req, "max", json_real(c->req_max), failed);
    put(req, "mean", json_real(c->req_mean), failed);
    put(req, "mean_ratio", json_real(c->req_ratio_mean), failed);
    put(req, "bins", gp_json_bins(c->req_bins, c->nbins, failed), failed);
    put(req, "outside", json_integer((json_int_t)c->req_outside), failed);
    put(o, "equivalent_radius", req, failed);
    return o;
}

json_t *gp_statistics_json(const gp_spec *spec, const gp_result *result)
{
    const gp_pack_stats *st = &result->stats;
    const gp_packing *pk = &result->packing;
    int failed = 0;
    json_t *root = json_object();
    json_t *radius = json_object();
    json_t *front = json_object();
    if (!root || !radius || !front) {
        json_decref(root);
        json_decref(radius);
        json_decref(front);
        return NULL;
    }
    put(root, "count", json_integer((json_int_t)st->count), &failed);
    put(root, "domain_area", json_real(st->domain_area), &failed);
    put(root, "packing_density", json_real(st->packing_density), &failed);
    put(root, "grain_fraction", json_real(st->grain_fraction), &failed);
    put(radius, "min", json_real(st->r_min), &failed);
    put(radius, "max", json_real(st->r_max), &failed);
    put(radius, "mean", json_real(st->r_mean), &failed);
    put(root, "radius", radius, &failed);
    put(root, "distribution", distribution_json(st, &failed), &failed);
    put(front, "initial_disks", json_integer((json_int_t)pk->initial_front), &failed);
    put(front, "attempts", json_integer((json_int_t)pk->attempts), &failed);
    put(front, "closures", json_integer((json_int_t)pk->closures), &failed);
    put(front, "frozen", json_integer((json_int_t)pk->frozen), &failed);
    put(front, "rule", json_string(pk->rule == GP_FRONT_WAIT ? "wait" : "level_band"), &failed);
    put(front, "level_band", json_integer((json_int_t)spec->level_band), &failed);
    if (pk->rule == GP_FRONT_WAIT) {
        put(front, "wait_levels", json_integer((json_int_t)pk->wait_levels), &failed);
        put(front, "alive_quantile", json_real(pk->alive_quantile), &failed);
    }
    put(front, "max_level", json_integer((json_int_t)pk->max_level), &failed);
    put(root, "front", front, &failed);
    put(root, "seed", json_integer((json_int_t)spec->seed), &failed);
    if (spec->domain.periodic)
        put(root, "periodic", gp_json_periodic(spec->domain.periodic, 2, &failed), &failed);
    if (result->has_balance)
        put(root, "balance", gp_json_balance(&result->balance, &failed), &failed);
    if (result->has_cells)
        put(root, "cells", cells_json(spec, &result->cell_stats, &failed), &failed);
    if (result->has_mesh)
        put(root, "mesh", gp_mesh_statistics_json(spec, &result->mesh), &failed);
    if (failed) {
        json_decref(root);
        return NULL;
    }
    return root;
}

/* A JSON string: quote, backslash and control characters escaped, the rest (UTF-8) as
 * it is. */
static void json_string_out(gp_out *out, const char *s, size_t len)
{
    static const char hex[] = "0123456789abcdef";
    gp_out_char(out, '"');
    size_t plain = 0;
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c >= 0x20 && c != '"' && c != '\\')
            continue;
        gp_out_write(out, s + plain, i - plain);
        plain = i + 1;
        char esc[6] = {'\\', (char)c, 0, 0, 0, 0};
        size_t n = 2;
        if (c == '\n')
            esc[1] = 'n';
        else if (c == '\t')
            esc[1] = 't';
        else if (c == '\r')
            esc[1] = 'r';
        else if (c < 0x20) {
            memcpy(esc + 1, "u00", 3);
            esc[4] = hex[c >> 4];
            esc[5] = hex[c & 15];
            n = 6;
        }
        gp_out_write(out, esc, n);
    }
    gp_out_write(out, s + plain, len - plain);
    gp_out_char(out, '"');
}

void gp_out_json_F(gp_out *out, double F)
{
    if (isnan(F)) {
        GP_OUT_LITERAL(out, ",\"F\":null");
    } else {
        GP_OUT_LITERAL(out, ",\"F\":");
        gp_out_double(out, F);
    }
}

void gp_out_json(gp_out *out, const json_t *value)
{
    switch (json_typeof(value)) {
    case JSON_OBJECT: {
        const char *key;
        json_t *item;
        int first = 1;
        gp_out_char(out, '{');
        json_object_foreach((json_t *)value, key, item) {
            if (!first)
                gp_out_char(out, ',');
            first = 0;
            json_string_out(out, key, strlen(key));
            gp_out_char(out, ':');
            gp_out_json(out, item);
        }
        gp_out_char(out, '}');
        break;
    }
    case JSON_ARRAY:
        gp_out_char(out, '[');
        for (size_t i = 0; i < json_array_size(value); i++) {
            if (i)
                gp_out_char(out, ',');
            gp_out_json(out, json_array_get(value, i));
        }
        gp_out_char(out, ']');
        break;
    case JSON_STRING:
        json_string_out(out, json_string_value(value), json_string_length(value));
        break;
    case JSON_INTEGER: gp_out_int(out, (int64_t)json_integer_value(value)); break;
    case JSON_REAL: gp_out_double(out, json_real_value(value)); break;
    case JSON_TRUE: GP_OUT_LITERAL(out, "true"); break;
    case JSON_FALSE: GP_OUT_LITERAL(out, "false"); break;
    case JSON_NULL: GP_OUT_LITERAL(out, "null"); break;
    }
}

/* What the JSON writer keeps between steps. */
typedef struct json_state {
    json_t *statistics; /* built by the plan, so that a failure shows before any byte */
} json_state;

static void drop_state(void *state)
{
    json_decref(((json_state *)state)->statistics);
}

static void head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    json_state *st = w->state;
    GP_OUT_LITERAL(out, "{\n\"domain\": {\"width\": ");
    gp_out_double(out, w->spec->domain.width);
    GP_OUT_LITERAL(out, ", \"height\": ");
    gp_out_double(out, w->spec->domain.height);
    unsigned periodic = w->spec->domain.periodic;
    if (periodic) /* as the spec gives it; walled domains write nothing more */
        gp_out_puts(out, periodic == GP_PERIODIC_X   ? ", \"periodic\": [\"x\"]"
                         : periodic == GP_PERIODIC_Y ? ", \"periodic\": [\"y\"]"
                                                     : ", \"periodic\": [\"x\", \"y\"]");
    GP_OUT_LITERAL(out, "},\n\"statistics\": ");
    gp_out_json(out, st->statistics);
    json_decref(st->statistics); /* written once: not needed any more */
    st->statistics = NULL;
    GP_OUT_LITERAL(out, ",\n\"disks\": [");
}

/* ,"name":value (the name a literal, with its quotes and colon). */
#define field(out, name, v) (GP_OUT_LITERAL(out, name), gp_out_double(out, v))

static void disk(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)param;
    const gp_disk *d = &win->disks[j];
    if (win->first + j)
        gp_out_char(out, ',');
    GP_OUT_LITERAL(out, "\n{\"x\":");
    gp_out_double(out, d->x);
    field(out, ",\"y\":", d->y);
    field(out, ",\"r\":", d->r);
    field(out, ",\"R\":", d->R);
    if (w->result->has_balance)
        gp_out_json_F(out, win->F[j]);
    gp_out_char(out, '}');
}

static void close_array(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, "\n]");
}

static void open_cells(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, ",\n\"cells\": [");
}

/* "cells": one object per grain: its id (the index of its disk), centre, radius, polygon
 * (counter-clockwise) and the ids of its neighbours. */
static void cell(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    (void)param;
    const gp_disk *d = &win->disks[j];
    size_t id = win->first + j;
    if (id)
        gp_out_char(out, ',');
    GP_OUT_LITERAL(out, "\n{\"id\":");
    gp_out_uint(out, id);
    field(out, ",\"x\":", d->x);
    field(out, ",\"y\":", d->y);
    field(out, ",\"r\":", d->r);
    field(out, ",\"area\":", win->area[j]);
    GP_OUT_LITERAL(out, ",\"polygon\":[");
    for (size_t k = win->start[j]; k < win->start[j + 1]; k++) {
        const double *v = &win->xy[2 * (k - win->vertex_base)];
        if (k > win->start[j])
            gp_out_char(out, ',');
        gp_out_char(out, '[');
        gp_out_double(out, v[0]);
        gp_out_char(out, ',');
        gp_out_double(out, v[1]);
        gp_out_char(out, ']');
    }
    GP_OUT_LITERAL(out, "],\"neighbours\":[");
    for (size_t k = win->nstart[j]; k < win->nstart[j + 1]; k++) {
        if (k > win->nstart[j])
            gp_out_char(out, ',');
        gp_out_int(out, win->neighbours[k - win->neighbour_base]);
    }
    GP_OUT_LITERAL(out, "]}");
}

static void tail(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, "\n}\n");
}

int gp_plan_json(gp_writer *w)
{
    json_state *st = calloc(1, sizeof *st);
    if (!st)
        return GP_ENOMEM;
    w->state = st;
    w->drop = drop_state;
    if (!(st->statistics = gp_statistics_json(w->spec, w->result)))
        return GP_ENOMEM;
    gp_writer_text(w, head, 0);
    gp_writer_grains(w, disk, GP_GRAINS_DISKS | (w->result->has_balance ? GP_GRAINS_F : 0), 0);
    gp_writer_text(w, close_array, 0);
    if (w->result->has_cells) {
        gp_writer_text(w, open_cells, 0);
        gp_writer_grains(w, cell,
                         GP_GRAINS_DISKS | GP_GRAINS_AREA | GP_GRAINS_POLYGONS | GP_GRAINS_NEIGHBOURS, 0);
        gp_writer_text(w, close_array, 0);
    }
    gp_writer_text(w, tail, 0);
    return 0;
}
