/* process_pack3d.c - the "pack3d" process (processes.h, docs/3d.md §10): spheres in a
 * walled box by the 3D advancing front, balanced and cut into Laguerre polyhedra when the
 * spec asks (gp_pipeline3d_run), stored as sections (sections.h) with the .tess text the
 * worker renders, and served from them as CSV, JSON, VTU, tess or the section's SVG. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "download.h"
#include "embedded.h"
#include "grainpack/io3d.h"
#include "grainpack/pipeline3d.h"
#include "grainpack/spec3d.h"
#include "json_values.h"
#include "log.h"
#include "problem.h"
#include "processes.h"
#include "render.h"
#include "sections.h"
#include "writer3d.h"

static int parse(const char *text, size_t len, const gp_spec_limits *limits, void **out,
                 gp_error *err)
{
    gp_spec3d *spec = malloc(sizeof *spec);
    if (!spec)
        return gp_error_set(err, GP_ENOMEM, "", "out of memory");
    int rc = gp_spec3d_parse(text, len, limits, spec, err);
    if (rc) {
        free(spec);
        return rc;
    }
    *out = spec;
    return 0;
}

static void free_spec(void *spec)
{
    if (spec)
        gp_spec3d_free(spec);
    free(spec);
}

static void columns(const void *s, gp_job_columns *out)
{
    const gp_spec3d *spec = s;
    *out = (gp_job_columns){"pack3d",
                            spec->box.width,
                            spec->box.height,
                            gp_dist_kind_name(spec->dist.kind),
                            gp_joint_law_name(spec->joint.law),
                            0,
                            spec->seed,
                            spec->expected_spheres,
                            spec->laguerre_enabled};
}

static json_t *validation(const void *s, const gp_config *cfg)
{
    const gp_spec3d *spec = s;
    json_t *body = json_pack("{s:b, s:I, s:o*, s:{s:I, s:I}}", "valid", 1, "expected_spheres",
                             (json_int_t)llround(spec->expected_spheres), "inputs",
                             gp_spec3d_json(spec), "limits", "max_spheres",
                             (json_int_t)cfg->max_disks, "max_bins", (json_int_t)cfg->max_bins);
    if (body && !json_object_get(body, "inputs")) {
        json_decref(body);
        return NULL;
    }
    return body;
}

static int stages(const void *s, const char **out, int cap)
{
    const gp_spec3d *spec = s;
    /* "pack3d": the stage gp_pack3d reports its progress as */
    return gp_process_stages("pack3d", spec->balance_enabled, spec->laguerre_enabled, out, cap);
}

/* A run's own result: what the sections borrow from. */
typedef struct pack3d_state {
    gp_box box;
    gp_result3d result;
    gp_pack_stats stats; /* result's statistics as the store takes them (bins borrowed) */
    gp_out tess;         /* memory mode: the .tess text (with cells and when it welded) */
    int has_tess;
} pack3d_state;

static void free_run(gp_process_run *run)
{
    pack3d_state *st = run->state;
    gp_sections_free(run->sections, run->nsections);
    if (st) {
        gp_result3d_free(&st->result);
        gp_out_free(&st->tess);
        free(st);
    }
    memset(run, 0, sizeof *run);
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Renders the .tess of the result's power cells into st->tess, here on the worker: a
 * shrunk result needs its power cells built again, geometry no HTTP thread does
 * (docs/3d.md §10). A tessellation that does not weld (GP_EGEOM, which the command line
 * reports as its error too) leaves the job's other formats: it is logged and no "tess"
 * is stored. Returns 0, GP_ENOMEM or GP_ECANCELED with err set. */
static int render_tess(const gp_spec3d *spec, const gp_progress *progress, pack3d_state *st,
                       gp_error *err)
{
    double t = now_seconds();
    if (gp_canceled(gp_progress_cancel(progress)))
        return gp_error_set(err, GP_ECANCELED, NULL, "canceled after the polyhedra");
    if (gp_out_init(&st->tess, 0, NULL, NULL))
        return gp_error_set(err, GP_ENOMEM, "", "out of memory");
    gp_error why = {0};
    int rc = gp_write_result3d(&st->tess, GP_FORMAT3D_TESS, spec, &st->result, &why);
    if (rc == GP_ENOMEM)
        return gp_error_set(err, GP_ENOMEM, "", "out of memory for the tessellation");
    st->has_tess = rc == 0;
    if (rc)
        gp_log("pack3d: no .tess stored (%s): %s", gp_strerror(rc), why.message);
    gp_result3d *r = &st->result;
    if (r->ntimings < GP_MAX_STAGES)
        r->timings[r->ntimings++] = (gp_stage_time){"tess", now_seconds() - t};
    return 0;
}

static int run(void *s, const gp_config *cfg, const gp_progress *progress, gp_process_run *out,
               gp_error *err)
{
    const gp_spec3d *spec = s;
    memset(out, 0, sizeof *out);
    pack3d_state *st = calloc(1, sizeof *st);
    if (!st)
        return gp_error_set(err, GP_ENOMEM, "", "out of memory");
    out->state = st;
    st->box = spec->box;
    /* the sphere cap is the daemon's --max-disks, as the spec's estimate was checked
     * against it: a packing that outgrows the estimate stops there */
    int rc = gp_pipeline3d_run(spec, cfg->max_disks, progress, &st->result, err);
    if (rc == 0 && st->result.has_cells)
        rc = render_tess(spec, progress, st, err);
    if (rc == 0 && (rc = gp_sections_from_result3d(&st->box, &st->result,
                                                   st->has_tess ? st->tess.buf : NULL,
                                                   st->tess.len, out->sections, &out->nsections)))
        rc = gp_error_set(err, rc, "", "the result cannot be cut into sections: %s",
                          gp_strerror(rc));
    if (rc) {
        free_run(out);
        return rc;
    }
    const gp_result3d *r = &st->result;
    st->stats = gp_pack3d_stats_view(&r->stats);
    out->count = r->packing.count;
    out->density = r->stats.packing_density;
    out->outcome = (gp_outcome){out->sections, out->nsections, &st->stats, 0, r->packing.attempts,
                                0, 0, 0, r->packing.max_level, "spheres", r->timings, r->ntimings};
    return 0;
}

/* The formats every pack3d job is served in: its spheres (csv, json), its polyhedra or its
 * spheres (vtu), the section picture (svg); and tess when its spec asked for polyhedra
 * (`has_polyhedra`, the job's has_mesh column). */
static int serves(gp_format format, int has_polyhedra)
{
    return format == GP_FORMAT_JSON || format == GP_FORMAT_CSV || format == GP_FORMAT_VTU ||
           format == GP_FORMAT_SVG || (format == GP_FORMAT_TESS && has_polyhedra);
}

/* The stored summary of a 3D result: counts and statistics, arrays NULL (sections.h). */
typedef struct stored3d {
    gp_box box;
    gp_result3d result; /* owned */
    size_t tess_len;    /* bytes of the stored .tess text (0: none) */
} stored3d;

static int stored_summary(const gp_stored_result *res, stored3d *out)
{
    return gp_section_decode_result3d(res->raw, res->nraw, &out->box, &out->result, &out->tess_len);
}

/* The statistics document of a 3D result, as gp_write_json3d writes its "statistics":
 * the spheres' densities (volume fractions), radii and joints, the law's bins and how the
 * front went; then (not in the JSON download's "statistics", which has them beside it)
 * "balance" and "cells" when they ran. NULL when out of memory. */
static json_t *summary_json(const gp_result3d *r, uint64_t seed)
{
    const gp_pack3d_stats *st = &r->stats;
    const gp_packing3d *pk = &r->packing;
    gp_pack_stats view = gp_pack3d_stats_view(st);
    json_t *o = json_pack("{s:I, s:f, s:f, s:f, s:{s:f, s:f, s:f}, s:{s:f, s:f}, s:o*, "
                          "s:{s:I, s:I, s:I, s:I}, s:I}",
                          "count", (json_int_t)st->count, "box_volume", st->box_volume,
                          "packing_density", st->packing_density, "grain_fraction",
                          st->grain_fraction, "radius", "min", st->r_min, "max", st->r_max, "mean",
                          st->r_mean, "joint", "min", st->joint_min, "max", st->joint_max,
                          "distribution", gp_distribution_stats_json(&view), "front",
                          "wall_spheres", (json_int_t)pk->wall_spheres, "triangles",
                          (json_int_t)pk->triangles, "attempts", (json_int_t)pk->attempts,
                          "max_level", (json_int_t)pk->max_level, "seed", (json_int_t)seed);
    int failed = !o;
    if (o && r->has_balance &&
        json_object_set_new(o, "balance", gp_json_balance(&r->balance, &failed)))
        failed = 1;
    if (o && r->has_cells &&
        json_object_set_new(o, "cells", gp_json_cells3d(&r->cells, &r->cell_stats, &failed)))
        failed = 1;
    if (failed) {
        json_decref(o);
        return NULL;
    }
    return o;
}

/* The job's spec as stored, parsed again without today's caps (it was accepted once). */
static int stored_spec(const gp_stored_result *res, gp_spec3d *spec)
{
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
    gp_error err;
    return gp_spec3d_parse(res->spec_text, res->spec_len, &unlimited, spec, &err);
}

/* The statistics of a stored result, with its stages' ("balance", "cells"). */
static json_t *statistics(const gp_stored_result *res)
{
    gp_spec3d spec;
    stored3d sum;
    if (stored_spec(res, &spec))
        return NULL;
    json_t *stats = NULL;
    if (stored_summary(res, &sum) == 0) {
        stats = summary_json(&sum.result, spec.seed);
        gp_result3d_free(&sum.result);
    }
    gp_spec3d_free(&spec);
    return stats;
}

/* A download of the stored .tess text, copied window by window. */
typedef struct tess_text {
    size_t len, next;
    char window[GP_STORE_CHUNK];
} tess_text;

static int tess_run(void *ctx, gp_section_read_fn read, void *read_ctx, gp_out *text, size_t want)
{
    tess_text *t = ctx;
    while (t->next < t->len && text->len < want) {
        size_t n = t->len - t->next < sizeof t->window ? t->len - t->next : sizeof t->window;
        int rc = read(read_ctx, GP_SECTION_TESS, (uint64_t)t->next, t->window, n);
        if (rc)
            return rc;
        gp_out_write(text, t->window, n);
        t->next += n;
    }
    return t->next < t->len;
}

/* A download in csv, json, vtu or svg: the command line's own 3D writer (writer3d.h,
 * the bytes of `grainpack run -f FORMAT`) reading the stored arrays window by window
 * (gp_sections_source3d): the download holds a window of cells and the text of a batch,
 * whatever the job's size (docs/3d.md §10). */
typedef struct windowed_text {
    gp_spec3d spec;
    gp_result3d summary; /* counts and statistics, arrays NULL */
    gp_format3d format;
    gp_source3d source;
    gp_writer *writer;   /* made at the first run, when the reader is known */
} windowed_text;

static void windowed_text_free(void *ctx)
{
    windowed_text *t = ctx;
    gp_writer_free(t->writer);
    gp_source3d_free(&t->source);
    gp_spec3d_free(&t->spec);
    gp_result3d_free(&t->summary);
    free(t);
}

static int windowed_run(void *ctx, gp_section_read_fn read, void *read_ctx, gp_out *text,
                        size_t want)
{
    windowed_text *t = ctx;
    if (!t->writer) {
        int rc = gp_sections_source3d(&t->summary, read, read_ctx, 0, &t->source);
        if (rc)
            return rc;
        if (!(t->writer = gp_writer3d_new(t->format, &t->spec, &t->summary, &t->source)))
            return GP_ENOMEM;
    }
    return gp_writer_run(t->writer, text, want);
}

/* The renderer of res in `format` (its summary decoded in `sum`, taken over). Returns 0,
 * GP_ENOMEM or the decoder's code. */
static int renderer_of(const gp_stored_result *res, stored3d *sum, gp_format format,
                       gp_download_renderer *out)
{
    if (format == GP_FORMAT_TESS) {
        tess_text *t = calloc(1, sizeof *t);
        gp_result3d_free(&sum->result);
        if (!t)
            return GP_ENOMEM;
        t->len = sum->tess_len;
        *out = (gp_download_renderer){t, tess_run, free};
        return 0;
    }
    windowed_text *t = calloc(1, sizeof *t);
    if (!t) {
        gp_result3d_free(&sum->result);
        return GP_ENOMEM;
    }
    t->summary = sum->result;
    memset(&sum->result, 0, sizeof sum->result);
    t->format = format == GP_FORMAT_JSON  ? GP_FORMAT3D_JSON
                : format == GP_FORMAT_CSV ? GP_FORMAT3D_CSV
                : format == GP_FORMAT_VTU ? GP_FORMAT3D_VTU
                                          : GP_FORMAT3D_SVG;
    int rc = stored_spec(res, &t->spec);
    if (rc) {
        gp_result3d_free(&t->summary);
        free(t);
        return rc;
    }
    *out = (gp_download_renderer){t, windowed_run, windowed_text_free};
    return 0;
}

/* Why the stored result cannot be served in `format`, as a 400 in reply; 0 when it can. */
static int refuse(gp_request *req, const stored3d *sum, gp_format format, gp_reply *reply)
{
    if (format == GP_FORMAT_TESS && !sum->result.has_cells) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "f=tess is the Laguerre tessellation; job %s made no polyhedra (its spec has "
                   "no \"laguerre\"): json, csv, vtu or svg", req->id);
        return -1;
    }
    if (format == GP_FORMAT_TESS && sum->tess_len == 0) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "job %s has no .tess: its power cells did not weld into a tessellation "
                   "(the daemon's log says why): json, csv, vtu or svg", req->id);
        return -1;
    }
    if (format != GP_FORMAT_TESS && !serves(format, 0)) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "f=%s is not offered for a pack3d job: json, csv, vtu, svg, or tess (with "
                   "polyhedra)", gp_format_name(format));
        return -1;
    }
    return 0;
}

static int results(gp_request *req, gp_stored_result *res, gp_format format, gp_reply *reply)
{
    stored3d sum;
    int rc = stored_summary(res, &sum);
    if (rc == 0 && refuse(req, &sum, format, reply)) {
        gp_result3d_free(&sum.result);
        gp_stored_result_free(res);
        return GP_ROUTE_DONE;
    }
    int gzip = gp_format_is_text(format) && gp_render_accepts_gzip(req);
    char etag[GP_ETAG_SIZE];
    gp_render_etag(res, NULL, format, gzip, etag);
    if (rc == 0 && gp_download_headers(req, etag, gp_format_name(format), gzip, reply)) {
        gp_result3d_free(&sum.result);
        gp_stored_result_free(res);
        return GP_ROUTE_DONE;
    }
    gp_download_renderer renderer;
    if (rc == 0)
        rc = renderer_of(res, &sum, format, &renderer);
    if (rc) {
        gp_stored_result_free(res);
        if (rc == GP_ENOMEM)
            gp_problem_out_of_memory(reply);
        else
            gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path,
                       "the stored result of job %s could not be read: %s", req->id,
                       gp_strerror(rc));
        return GP_ROUTE_DONE;
    }
    gp_body_stream *stream;
    if (gp_download_new_renderer(req->svc, res, renderer, gp_format_name(format), gzip, &stream))
        gp_problem_out_of_memory(reply); /* drops the headers above */
    else
        gp_download_reply(req, stream, gp_format_media_type(format), reply);
    return GP_ROUTE_DONE;
}

const gp_process_def gp_process_pack3d = {
    "pack3d",  "spheres", gp_process_pack3d_json, &gp_process_pack3d_json_len,
    parse,     free_spec, columns, validation, stages, run, free_run, serves, results, statistics,
};
