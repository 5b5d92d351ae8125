/* io_json.c - the statistics object and the full JSON result. */
#include <math.h>

#include "grainpack/io.h"

/* json_object_set_new that remembers a failure instead of returning it at every call. */
static void put(json_t *obj, const char *key, json_t *value, int *failed)
{
    if (!value || json_object_set_new(obj, key, value))
        *failed = 1;
}

/* The achieved-versus-target table: one object per bin. */
static json_t *bins_json(const gp_bin_stat *table, size_t nbins, int *failed)
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
    json_t *bins = bins_json(st->bins, st->nbins, failed);
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

static json_t *count_array(const size_t *counts, size_t n, int *failed)
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
    put(o, "histogram", count_array(q->histogram, GP_QUALITY_BINS, failed), failed);
    return o;
}

static json_t *balance_json(const gp_balance_result *b, int *failed)
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
    put(area, "histogram", count_array(c->area_histogram, GP_CELL_AREA_BINS, failed), failed);
    put(o, "area", area, failed);
    put(nb, "mean", json_real(c->neighbours_mean), failed);
    put(nb, "histogram", count_array(c->neighbour_histogram, c->max_neighbours + 1, failed), failed);
    put(o, "neighbours", nb, failed);
    put(o, "band_fraction", json_real(c->band_fraction), failed);
    put(o, "tiling_error", json_real(c->tiling_error), failed);
    put(req, "min", json_real(c->req_min), failed);
    put(req, "max", json_real(c->req_max), failed);
    put(req, "mean", json_real(c->req_mean), failed);
    put(req, "mean_ratio", json_real(c->req_ratio_mean), failed);
    put(req, "bins", bins_json(c->req_bins, c->nbins, failed), failed);
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
    put(front, "level_band", json_integer((json_int_t)spec->level_band), &failed);
    put(front, "max_level", json_integer((json_int_t)pk->max_level), &failed);
    put(root, "front", front, &failed);
    put(root, "seed", json_integer((json_int_t)spec->seed), &failed);
    if (result->has_balance)
        put(root, "balance", balance_json(&result->balance, &failed), &failed);
    if (result->has_cells)
        put(root, "cells", cells_json(spec, &result->cell_stats, &failed), &failed);
    if (failed) {
        json_decref(root);
        return NULL;
    }
    return root;
}

/* "cells": one object per grain: its id (the index of its disk), centre, radius, polygon
 * (counter-clockwise) and the ids of its neighbours. */
static void write_cells(FILE *out, const gp_result *result)
{
    const gp_cells *c = &result->cells;
    const gp_disk *d = result->packing.disks;
    fputs(",\n\"cells\": [", out);
    for (size_t i = 0; i < c->count; i++) {
        fprintf(out, "%s\n{\"id\":%zu,\"x\":%.17g,\"y\":%.17g,\"r\":%.17g,\"area\":%.17g,\"polygon\":[",
                i ? "," : "", i, d[i].x, d[i].y, d[i].r, c->area[i]);
        for (size_t k = c->start[i]; k < c->start[i + 1]; k++)
            fprintf(out, "%s[%.17g,%.17g]", k > c->start[i] ? "," : "", c->xy[2 * k], c->xy[2 * k + 1]);
        fputs("],\"neighbours\":[", out);
        for (size_t k = c->nstart[i]; k < c->nstart[i + 1]; k++)
            fprintf(out, "%s%d", k > c->nstart[i] ? "," : "", c->neighbours[k]);
        fputs("]}", out);
    }
    fputs("\n]", out);
}

int gp_write_json(FILE *out, const gp_spec *spec, const gp_result *result)
{
    json_t *stats = gp_statistics_json(spec, result);
    if (!stats)
        return GP_ENOMEM;
    fprintf(out, "{\n\"domain\": {\"width\": %.17g, \"height\": %.17g},\n\"statistics\": ",
            spec->domain.width, spec->domain.height);
    int rc = json_dumpf(stats, out, JSON_COMPACT | JSON_REAL_PRECISION(17)) ? GP_EIO : 0;
    json_decref(stats);
    fputs(",\n\"disks\": [", out);
    const gp_packing *p = &result->packing;
    for (size_t i = 0; i < p->count; i++) {
        fprintf(out, "%s\n{\"x\":%.17g,\"y\":%.17g,\"r\":%.17g,\"R\":%.17g", i ? "," : "",
                p->disks[i].x, p->disks[i].y, p->disks[i].r, p->disks[i].R);
        if (result->has_balance) {
            /* F is defined for interior centres only (balance.h) */
            double F = result->balance.F[i];
            if (isnan(F))
                fputs(",\"F\":null", out);
            else
                fprintf(out, ",\"F\":%.17g", F);
        }
        fputc('}', out);
    }
    fputs("\n]", out);
    if (result->has_cells)
        write_cells(out, result);
    fputs("\n}\n", out);
    return rc ? rc : (ferror(out) ? GP_EIO : 0);
}
