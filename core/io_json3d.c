/* io_json3d.c - the 3D result as JSON: the spec's inputs, the statistics (built with
 * jansson: small), then the spheres and polyhedra streamed window by window (writer3d.h)
 * with shortest doubles. */
#include <math.h>
#include <string.h>

#include "grainpack/io3d.h"
#include "json_values.h"
#include "writer3d.h"

static void put(json_t *obj, const char *key, json_t *value, int *failed)
{
    if (!obj || !value || json_object_set_new(obj, key, value)) {
        json_decref(value);
        *failed = 1;
    }
}

static json_t *statistics_json(const gp_spec3d *spec, const gp_result3d *result, int *failed)
{
    const gp_pack3d_stats *st = &result->stats;
    const gp_packing3d *pk = &result->packing;
    json_t *o = json_object();
    put(o, "count", json_integer((json_int_t)st->count), failed);
    put(o, "box_volume", json_real(st->box_volume), failed);
    put(o, "packing_density", json_real(st->packing_density), failed);
    put(o, "grain_fraction", json_real(st->grain_fraction), failed);
    put(o, "radius", json_pack("{s:f, s:f, s:f}", "min", st->r_min, "max", st->r_max, "mean", st->r_mean),
        failed);
    put(o, "joint", json_pack("{s:f, s:f}", "min", st->joint_min, "max", st->joint_max), failed);
    json_t *d = json_object();
    put(d, "bins", gp_json_bins(st->bins, st->nbins, failed), failed);
    put(d, "chi2", json_real(st->chi2), failed);
    put(d, "dof", json_integer(st->dof), failed);
    put(d, "p_value", json_real(st->p_value), failed);
    put(d, "max_abs_z", json_real(st->max_abs_z), failed);
    put(o, "distribution", d, failed);
    put(o, "front", json_pack("{s:I, s:I, s:I, s:I}", "wall_spheres", (json_int_t)pk->wall_spheres,
                              "triangles", (json_int_t)pk->triangles, "attempts", (json_int_t)pk->attempts,
                              "max_level", (json_int_t)pk->max_level), failed);
    put(o, "seed", json_integer((json_int_t)spec->seed), failed);
    return o;
}

json_t *gp_json_cells3d(const gp_cells3d *cells, const gp_cell3d_stats *c, int *failed)
{
    json_t *o = json_object();
    put(o, "count", json_integer((json_int_t)c->count), failed);
    put(o, "shrink", json_string(gp_shrink_name(cells->shrink)), failed);
    put(o, "faces", json_integer((json_int_t)c->faces), failed);
    put(o, "vertices", json_integer((json_int_t)c->vertices), failed);
    json_t *volume = json_pack("{s:f, s:f, s:f}", "min", c->volume_min, "max", c->volume_max, "mean",
                               c->volume_mean);
    put(volume, "histogram", gp_json_counts(c->volume_histogram, GP_CELL_VOLUME_BINS, failed), failed);
    put(o, "volume", volume, failed);
    json_t *faces = json_pack("{s:f, s:I}", "mean", c->faces_mean, "max", (json_int_t)c->max_faces);
    if (c->faces_histogram)
        put(faces, "histogram", gp_json_counts(c->faces_histogram, c->max_faces + 1, failed), failed);
    put(o, "faces_per_cell", faces, failed);
    put(o, "neighbours_mean", json_real(c->neighbours_mean), failed);
    put(o, "boundary_fraction", json_real(c->boundary_fraction), failed);
    put(o, "tiling_error", json_real(c->tiling_error), failed);
    json_t *req = json_pack("{s:f, s:f, s:f, s:f}", "min", c->req_min, "max", c->req_max, "mean",
                            c->req_mean, "mean_ratio", c->req_ratio_mean);
    put(req, "bins", gp_json_bins(c->req_bins, c->nbins, failed), failed);
    put(req, "outside", json_integer((json_int_t)c->req_outside), failed);
    put(req, "max_abs_z", json_real(c->req_max_abs_z), failed);
    put(o, "equivalent_radius", req, failed);
    return o;
}

/* ,"name":value (the name a literal with its quotes and colon). */
#define field(out, name, v) (GP_OUT_LITERAL(out, name), gp_out_double(out, v))

/* The head: the document's members before the arrays, one a line (built with jansson:
 * small), then the spheres' array opened. */
static void head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    const gp_state3d *st = w->state;
    const gp_result3d *result = st->result;
    int failed = 0;
    json_t *h = json_object();
    put(h, "process", json_string("pack3d"), &failed);
    /* the same inputs as the service's validation: every stage the spec asked for */
    put(h, "inputs", gp_spec3d_json(st->spec), &failed);
    put(h, "statistics", statistics_json(st->spec, result, &failed), &failed);
    if (result->has_balance)
        put(h, "balance", gp_json_balance(&result->balance, &failed), &failed);
    if (result->has_cells)
        put(h, "cells", gp_json_cells3d(&result->cells, &result->cell_stats, &failed), &failed);
    if (failed) {
        json_decref(h);
        if (!out->err)
            out->err = GP_ENOMEM;
        return;
    }
    GP_OUT_LITERAL(out, "{");
    const char *key;
    json_t *value;
    int first = 1;
    json_object_foreach(h, key, value) {
        if (!first)
            gp_out_char(out, ',');
        first = 0;
        gp_out_puts(out, "\n\"");
        gp_out_puts(out, key); /* our own keys: nothing to escape */
        GP_OUT_LITERAL(out, "\": ");
        gp_out_json(out, value);
    }
    json_decref(h);
    GP_OUT_LITERAL(out, ",\n\"spheres\": [");
}

static void sphere(gp_writer *w, gp_out *out, size_t i, int param)
{
    (void)param;
    const gp_state3d *st = w->state;
    int balance = st->result->has_balance;
    const gp_window3d *win = gp_state3d_window(w, out, GP_W3_SPHERES | (balance ? GP_W3_F : 0), i);
    if (!win)
        return;
    const gp_sphere *s = &win->spheres[i - win->first];
    if (i)
        gp_out_char(out, ',');
    GP_OUT_LITERAL(out, "\n{\"id\":");
    gp_out_uint(out, i);
    field(out, ",\"x\":", s->x);
    field(out, ",\"y\":", s->y);
    field(out, ",\"z\":", s->z);
    field(out, ",\"r\":", s->r);
    field(out, ",\"R\":", s->R);
    if (balance)
        gp_out_json_F(out, win->F[i - win->first]);
    gp_out_char(out, '}');
}

/* Closes the spheres' array (`param`: and opens the polyhedra's). */
static void between(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    GP_OUT_LITERAL(out, "\n]");
    if (param)
        GP_OUT_LITERAL(out, ",\n\"polyhedra\": [");
}

/* One object per grain: its volume, face count, the grains across its faces and the
 * walls it touches, in its faces' order. */
static void polyhedron(gp_writer *w, gp_out *out, size_t i, int param)
{
    (void)param;
    const gp_window3d *win = gp_state3d_window(w, out, GP_W3_CELLS | GP_W3_NEIGHBOURS | GP_W3_VOLUME, i);
    if (!win)
        return;
    const gp_cells3d *c = win->cells;
    size_t j = i - win->first;
    if (i)
        gp_out_char(out, ',');
    GP_OUT_LITERAL(out, "\n{\"id\":");
    gp_out_uint(out, i);
    field(out, ",\"volume\":", c->volume[j]);
    GP_OUT_LITERAL(out, ",\"faces\":");
    gp_out_uint(out, c->fstart[j + 1] - c->fstart[j]);
    for (int walls = 0; walls < 2; walls++) {
        gp_out_puts(out, walls ? "],\"walls\":[" : ",\"neighbours\":[");
        int first = 1;
        for (size_t f = c->fstart[j]; f < c->fstart[j + 1]; f++) {
            int32_t nb = c->fneighbour[f];
            if (GP_IS_WALL3D(nb) != walls)
                continue;
            if (!first)
                gp_out_char(out, ',');
            first = 0;
            gp_out_int(out, walls ? GP_WALL3D_INDEX(nb) : nb);
        }
    }
    GP_OUT_LITERAL(out, "]}");
}

static void tail(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, "\n]\n}\n");
}

int gp_plan_json3d(gp_writer *w, const gp_plan3d_args *a)
{
    int rc = gp_plan3d_state(w, a, sizeof(gp_state3d));
    if (rc)
        return rc;
    size_t n = a->result->packing.count;
    gp_writer_text(w, head, 0);
    gp_writer_items(w, sphere, n, 0);
    if (a->result->has_cells) {
        gp_writer_text(w, between, 1);
        gp_writer_items(w, polyhedron, n, 0);
    }
    gp_writer_text(w, tail, 0);
    return 0;
}

int gp_write_json3d(gp_out *out, const gp_spec3d *spec, const gp_result3d *result)
{
    return gp_write3d_memory(out, GP_FORMAT3D_JSON, spec, result);
}
