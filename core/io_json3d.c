/* io_json3d.c - the 3D result as JSON: the spec's inputs, the statistics (built with
 * jansson: small), then the spheres and polyhedra streamed with shortest doubles. */
#include <math.h>
#include <string.h>

#include "grainpack/io3d.h"
#include "json_values.h"

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

static void spheres(gp_out *out, const gp_result3d *result)
{
    GP_OUT_LITERAL(out, ",\n\"spheres\": [");
    for (size_t i = 0; i < result->packing.count; i++) {
        const gp_sphere *s = &result->packing.spheres[i];
        if (i)
            gp_out_char(out, ',');
        GP_OUT_LITERAL(out, "\n{\"id\":");
        gp_out_uint(out, i);
        field(out, ",\"x\":", s->x);
        field(out, ",\"y\":", s->y);
        field(out, ",\"z\":", s->z);
        field(out, ",\"r\":", s->r);
        field(out, ",\"R\":", s->R);
        if (result->has_balance) {
            double F = result->balance.F[i]; /* defined for interior centres only */
            if (isnan(F))
                GP_OUT_LITERAL(out, ",\"F\":null");
            else
                field(out, ",\"F\":", F);
        }
        gp_out_char(out, '}');
    }
    GP_OUT_LITERAL(out, "\n]");
}

/* One object per grain: its volume, face count, the grains across its faces and the
 * walls it touches, in its faces' order. */
static void polyhedra(gp_out *out, const gp_cells3d *c)
{
    GP_OUT_LITERAL(out, ",\n\"polyhedra\": [");
    for (size_t i = 0; i < c->count; i++) {
        if (i)
            gp_out_char(out, ',');
        GP_OUT_LITERAL(out, "\n{\"id\":");
        gp_out_uint(out, i);
        field(out, ",\"volume\":", c->volume[i]);
        GP_OUT_LITERAL(out, ",\"faces\":");
        gp_out_uint(out, c->fstart[i + 1] - c->fstart[i]);
        for (int walls = 0; walls < 2; walls++) {
            gp_out_puts(out, walls ? "],\"walls\":[" : ",\"neighbours\":[");
            int first = 1;
            for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
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
    GP_OUT_LITERAL(out, "\n]");
}

int gp_write_json3d(gp_out *out, const gp_spec3d *spec, const gp_result3d *result)
{
    int failed = 0;
    json_t *head = json_object();
    put(head, "process", json_string("pack3d"), &failed);
    /* the same inputs as the service's validation: every stage the spec asked for */
    put(head, "inputs", gp_spec3d_json(spec), &failed);
    put(head, "statistics", statistics_json(spec, result, &failed), &failed);
    if (result->has_balance)
        put(head, "balance", gp_json_balance(&result->balance, &failed), &failed);
    if (result->has_cells)
        put(head, "cells", gp_json_cells3d(&result->cells, &result->cell_stats, &failed), &failed);
    if (failed) {
        json_decref(head);
        return GP_ENOMEM;
    }
    /* the head's members, then the streamed arrays, in one object */
    GP_OUT_LITERAL(out, "{");
    const char *key;
    json_t *value;
    int first = 1;
    json_object_foreach(head, key, value) {
        if (!first)
            gp_out_char(out, ',');
        first = 0;
        gp_out_puts(out, "\n\"");
        gp_out_puts(out, key); /* our own keys: nothing to escape */
        GP_OUT_LITERAL(out, "\": ");
        gp_out_json(out, value);
    }
    json_decref(head);
    spheres(out, result);
    if (result->has_cells)
        polyhedra(out, &result->cells);
    GP_OUT_LITERAL(out, "\n}\n");
    return gp_out_flush(out);
}
