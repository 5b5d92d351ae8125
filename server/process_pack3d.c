/* process_pack3d.c - the "pack3d" process (processes.h, docs/3d.md §10): spheres in a
 * walled box by the 3D advancing front, balanced and cut into Laguerre polyhedra when the
 * spec asks (gp_pipeline3d_run), stored as sections (sections.h) with the .tess text the
 * worker renders, and served from them as CSV, JSON, VTU, tess or the section's SVG. */
#include <jansson.h>
#include <malloc.h>
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

/* Spheres read from the store at once when a download renders them: 40 KB a window, the
 * order of the text it makes (some 60 bytes a sphere) and of a store chunk. */
#define WINDOW_SPHERES 1024

/* A whole-rendered download at least this large gives its pages back to the system when
 * it ends (malloc_trim, a few ms): below, what glibc keeps mapped is not worth the call. */
#define WHOLE_TRIM_BYTES ((size_t)16 << 20)

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
static json_t *summary_json(const gp_result3d *r, uint64_t seed, int stages)
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
    if (o && stages && r->has_balance &&
        json_object_set_new(o, "balance", gp_json_balance(&r->balance, &failed)))
        failed = 1;
    if (o && stages && r->has_cells &&
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

/* The statistics of a stored result (with its stages' when `stages`), and its inputs
 * when `inputs` is not NULL. */
static json_t *stored_statistics(const gp_stored_result *res, int stages, json_t **inputs)
{
    gp_spec3d spec;
    stored3d sum;
    if (stored_spec(res, &spec))
        return NULL;
    json_t *stats = NULL;
    if (stored_summary(res, &sum) == 0) {
        stats = summary_json(&sum.result, spec.seed, stages);
        gp_result3d_free(&sum.result);
    }
    if (stats && inputs && !(*inputs = gp_spec3d_json(&spec))) {
        json_decref(stats);
        stats = NULL;
    }
    gp_spec3d_free(&spec);
    return stats;
}

static json_t *statistics(const gp_stored_result *res)
{
    return stored_statistics(res, 1, NULL);
}

/* A download of the spheres: CSV rows, or the JSON document's "spheres" array after its
 * head (the inputs and statistics). */
typedef struct spheres_text {
    gp_format format;
    size_t count, next; /* spheres in all, and the next to write */
    json_t *inputs, *stats; /* JSON: written first, then dropped */
    int started, done;
    gp_sphere window[WINDOW_SPHERES];
} spheres_text;

static void spheres_text_free(void *ctx)
{
    spheres_text *t = ctx;
    json_decref(t->inputs);
    json_decref(t->stats);
    free(t);
}

static void write_head(spheres_text *t, gp_out *text)
{
    if (t->format == GP_FORMAT_CSV) {
        gp_out_puts(text, "x,y,z,r,R\n");
        return;
    }
    /* as gp_write_json3d: the head's members one a line, then the spheres */
    GP_OUT_LITERAL(text, "{\n\"process\": \"pack3d\",\n\"inputs\": ");
    gp_out_json(text, t->inputs);
    GP_OUT_LITERAL(text, ",\n\"statistics\": ");
    gp_out_json(text, t->stats);
    GP_OUT_LITERAL(text, ",\n\"spheres\": [");
}

/* One sphere: "x,y,z,r,R\n" in CSV (as gp_write_spheres_csv), {"id", "x", "y", "z", "r",
 * "R"} in JSON (as gp_write_json3d); the shortest decimals that read back exactly. */
static void write_sphere(const spheres_text *t, gp_out *text, size_t i, const gp_sphere *s)
{
    const double v[5] = {s->x, s->y, s->z, s->r, s->R};
    static const char *const json_names[5] = {",\"x\":", ",\"y\":", ",\"z\":", ",\"r\":",
                                              ",\"R\":"};
    int json = t->format == GP_FORMAT_JSON;
    if (json) {
        gp_out_puts(text, i ? ",\n{\"id\":" : "\n{\"id\":");
        gp_out_uint(text, i);
    }
    for (int k = 0; k < 5; k++) {
        if (json)
            gp_out_puts(text, json_names[k]);
        else if (k)
            gp_out_char(text, ',');
        gp_out_double(text, v[k]);
    }
    gp_out_char(text, json ? '}' : '\n');
}

static int spheres_run(void *ctx, gp_section_read_fn read, void *read_ctx, gp_out *text,
                       size_t want)
{
    spheres_text *t = ctx;
    if (!t->started) {
        write_head(t, text);
        t->started = 1;
    }
    while (t->next < t->count && text->len < want) {
        size_t n = t->count - t->next < WINDOW_SPHERES ? t->count - t->next : WINDOW_SPHERES;
        int rc = read(read_ctx, GP_SECTION_SPHERES, (uint64_t)t->next * sizeof(gp_sphere),
                      t->window, n * sizeof(gp_sphere));
        if (rc)
            return rc;
        for (size_t i = 0; i < n; i++)
            write_sphere(t, text, t->next + i, &t->window[i]);
        t->next += n;
    }
    if (t->next == t->count && !t->done) {
        if (t->format == GP_FORMAT_JSON)
            GP_OUT_LITERAL(text, "\n]\n}\n");
        t->done = 1;
    }
    return t->done ? 0 : 1;
}

/* The renderer of res's spheres in format (CSV, or JSON of a job that only packed). Returns 0, GP_ENOMEM or the decoder's code. */
static int spheres_renderer(const gp_stored_result *res, gp_format format,
                            gp_download_renderer *out)
{
    spheres_text *t = calloc(1, sizeof *t);
    if (!t)
        return GP_ENOMEM;
    t->format = format;
    stored3d sum;
    int rc = stored_summary(res, &sum);
    if (rc) {
        free(t);
        return rc;
    }
    t->count = sum.result.packing.count;
    gp_result3d_free(&sum.result);
    if (format == GP_FORMAT_JSON && !(t->stats = stored_statistics(res, 0, &t->inputs))) {
        spheres_text_free(t);
        return GP_ENOMEM;
    }
    *out = (gp_download_renderer){t, spheres_run, spheres_text_free};
    return 0;
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

/* A download rendered whole by the command line's writer (gp_write_result3d) from the
 * arrays read whole: the polyhedra's formats, whose vertices a writer reaches from every
 * part of its output (vtu's connectivity then faces, the picture's cut of every cell),
 * and a balanced or tessellated job's JSON. Holds the result, then its text, at once
 * (docs/3d.md §10 measures it). */
typedef struct whole_text {
    gp_spec3d spec;
    gp_result3d result; /* the summary, then the arrays: dropped once rendered */
    gp_format3d format;
    gp_out out;         /* memory mode: the whole text */
    size_t pos;         /* bytes of it handed on */
    int rendered;
} whole_text;

static void whole_text_free(void *ctx)
{
    whole_text *t = ctx;
    int large = t->out.cap >= WHOLE_TRIM_BYTES;
    gp_spec3d_free(&t->spec);
    gp_result3d_free(&t->result);
    gp_out_free(&t->out);
    free(t);
    /* the arrays and the text went back to malloc's arenas, which glibc keeps mapped (an
       80 000-sphere VTU left the daemon 135 MB larger, docs/3d.md §10): give them back */
    if (large)
        malloc_trim(0);
}

static int whole_run(void *ctx, gp_section_read_fn read, void *read_ctx, gp_out *text, size_t want)
{
    whole_text *t = ctx;
    if (!t->rendered) {
        int rc = gp_sections_read_result3d(&t->result, read, read_ctx);
        if (rc)
            return rc;
        if (gp_out_init(&t->out, 0, NULL, NULL))
            return GP_ENOMEM;
        gp_error err = {0};
        rc = gp_write_result3d(&t->out, t->format, &t->spec, &t->result, &err);
        gp_result3d_free(&t->result);
        if (rc)
            return rc;
        t->rendered = 1;
    }
    size_t room = want > text->len ? want - text->len : 0, left = t->out.len - t->pos;
    size_t n = left < room ? left : room;
    gp_out_write(text, t->out.buf + t->pos, n);
    t->pos += n;
    return t->pos < t->out.len;
}

/* The renderer of res in `format` (its summary decoded in `sum`, taken over). Returns 0,
 * GP_ENOMEM or the decoder's code. */
static int renderer_of(const gp_stored_result *res, stored3d *sum, gp_format format,
                       gp_download_renderer *out)
{
    const gp_result3d *r = &sum->result;
    if (format == GP_FORMAT_CSV ||
        (format == GP_FORMAT_JSON && !r->has_balance && !r->has_cells)) {
        gp_result3d_free(&sum->result);
        return spheres_renderer(res, format, out);
    }
    if (format == GP_FORMAT_TESS) {
        tess_text *t = calloc(1, sizeof *t);
        gp_result3d_free(&sum->result);
        if (!t)
            return GP_ENOMEM;
        t->len = sum->tess_len;
        *out = (gp_download_renderer){t, tess_run, free};
        return 0;
    }
    whole_text *t = calloc(1, sizeof *t);
    if (!t) {
        gp_result3d_free(&sum->result);
        return GP_ENOMEM;
    }
    t->result = sum->result;
    memset(&sum->result, 0, sizeof sum->result);
    t->format = format == GP_FORMAT_JSON  ? GP_FORMAT3D_JSON
                : format == GP_FORMAT_VTU ? GP_FORMAT3D_VTU
                                          : GP_FORMAT3D_SVG;
    int rc = stored_spec(res, &t->spec);
    if (rc) {
        gp_result3d_free(&t->result);
        free(t);
        return rc;
    }
    *out = (gp_download_renderer){t, whole_run, whole_text_free};
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
