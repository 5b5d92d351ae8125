/* process_pack3d.c - the "pack3d" process (processes.h, docs/3d.md): spheres in a walled
 * box by the 3D advancing front, stored as the "pack3d" and "spheres" sections and served
 * from them as CSV (x,y,z,r,R) or JSON (inputs, statistics, spheres). The stages after
 * packing (balancing, Laguerre polyhedra) and their formats slot in here as they come. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "download.h"
#include "embedded.h"
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
    /* The service stores a 3D job's spheres and their statistics only: a balanced or
     * tessellated result would be run and then served without what was asked for. */
    const char *stage = spec->balance_enabled ? "balance" : spec->laguerre_enabled ? "laguerre" : NULL;
    if (stage) {
        json_t *doc = json_loadb(text, len, 0, NULL);
        int wrapped = json_is_object(json_object_get(doc, "inputs"));
        json_decref(doc);
        char pointer[32];
        snprintf(pointer, sizeof pointer, "%s/%s", wrapped ? "/inputs" : "", stage);
        gp_spec3d_free(spec);
        free(spec);
        return gp_error_set(err, GP_EINVAL, pointer,
                            "the service's pack3d packs only for now: '%s' runs from the command "
                            "line (grainpack run)", stage);
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
                            0};
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

static int stages(const void *spec, const char **out, int cap)
{
    (void)spec;
    if (cap < 1)
        return 0;
    out[0] = "pack3d"; /* the stage gp_pack3d reports its progress as */
    return 1;
}

/* A run's own result: what the sections borrow from. */
typedef struct pack3d_state {
    gp_box box;
    gp_result3d result;
    gp_pack_stats stats; /* result's statistics as the store takes them (bins borrowed) */
} pack3d_state;

static void free_run(gp_process_run *run)
{
    pack3d_state *st = run->state;
    gp_sections_free(run->sections, run->nsections);
    if (st) {
        gp_result3d_free(&st->result);
        free(st);
    }
    memset(run, 0, sizeof *run);
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
    if (rc == 0 && gp_sections_from_packing3d(&st->box, &st->result.packing, &st->result.stats,
                                              out->sections, &out->nsections))
        rc = gp_error_set(err, GP_ENOMEM, "", "out of memory");
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

static int serves(gp_format format, int has_mesh)
{
    (void)has_mesh;
    return format == GP_FORMAT_JSON || format == GP_FORMAT_CSV;
}

/* The stored summary of a 3D result (decoded from its "pack3d" section). Returns 0 or
 * the decoder's code. */
static int stored_summary(const gp_stored_result *res, gp_summary3d *out)
{
    for (size_t i = 0; i < res->nraw; i++)
        if (strcmp(res->raw[i].tag, GP_SECTION_PACK3D) == 0)
            return gp_section_decode_summary3d(res->raw[i].tag, res->raw[i].version,
                                               res->raw[i].data, res->raw[i].size, out);
    memset(out, 0, sizeof *out);
    return GP_EPARSE;
}

/* The statistics document of a 3D result, as gp_write_json3d writes it (io_json3d.c):
 * the spheres' densities (volume fractions), radii and joints, the law's bins and how the
 * front went. NULL when out of memory. */
static json_t *summary_json(const gp_summary3d *sum, uint64_t seed)
{
    const gp_pack3d_stats *st = &sum->stats;
    const gp_packing3d *pk = &sum->packing;
    gp_pack_stats view = gp_pack3d_stats_view(st);
    return json_pack("{s:I, s:f, s:f, s:f, s:{s:f, s:f, s:f}, s:{s:f, s:f}, s:o*, "
                     "s:{s:I, s:I, s:I, s:I}, s:I}",
                     "count", (json_int_t)st->count, "box_volume", st->box_volume,
                     "packing_density", st->packing_density, "grain_fraction", st->grain_fraction,
                     "radius", "min", st->r_min, "max", st->r_max, "mean", st->r_mean, "joint",
                     "min", st->joint_min, "max", st->joint_max, "distribution",
                     gp_distribution_stats_json(&view), "front", "wall_spheres",
                     (json_int_t)pk->wall_spheres, "triangles", (json_int_t)pk->triangles,
                     "attempts", (json_int_t)pk->attempts, "max_level", (json_int_t)pk->max_level,
                     "seed", (json_int_t)seed);
}

/* The job's spec as stored, parsed again without today's caps (it was accepted once). */
static int stored_spec(const gp_stored_result *res, gp_spec3d *spec)
{
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
    gp_error err;
    return gp_spec3d_parse(res->spec_text, res->spec_len, &unlimited, spec, &err);
}

/* The statistics of a stored result, and its inputs when `inputs` is not NULL. */
static json_t *stored_statistics(const gp_stored_result *res, json_t **inputs)
{
    gp_spec3d spec;
    gp_summary3d sum;
    if (stored_spec(res, &spec))
        return NULL;
    json_t *stats = NULL;
    if (stored_summary(res, &sum) == 0) {
        stats = summary_json(&sum, spec.seed);
        gp_summary3d_free(&sum);
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
    return stored_statistics(res, NULL);
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

/* The renderer of res in format (CSV or JSON). Returns 0, GP_ENOMEM or the decoder's code. */
static int spheres_renderer(const gp_stored_result *res, gp_format format,
                            gp_download_renderer *out)
{
    spheres_text *t = calloc(1, sizeof *t);
    if (!t)
        return GP_ENOMEM;
    t->format = format;
    gp_summary3d sum;
    int rc = stored_summary(res, &sum);
    if (rc) {
        free(t);
        return rc;
    }
    t->count = sum.packing.count;
    gp_summary3d_free(&sum);
    if (format == GP_FORMAT_JSON && !(t->stats = stored_statistics(res, &t->inputs))) {
        spheres_text_free(t);
        return GP_ENOMEM;
    }
    *out = (gp_download_renderer){t, spheres_run, spheres_text_free};
    return 0;
}

static int results(gp_request *req, gp_stored_result *res, gp_format format, gp_reply *reply)
{
    if (!serves(format, 0)) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "f=%s is not offered for a pack3d job yet: json or csv", gp_format_name(format));
        gp_stored_result_free(res);
        return GP_ROUTE_DONE;
    }
    int gzip = gp_format_is_text(format) && gp_render_accepts_gzip(req);
    char etag[GP_ETAG_SIZE];
    gp_render_etag(res, NULL, format, gzip, etag);
    if (gp_download_headers(req, etag, gp_format_name(format), gzip, reply)) {
        gp_stored_result_free(res);
        return GP_ROUTE_DONE;
    }
    gp_download_renderer renderer;
    int rc = spheres_renderer(res, format, &renderer);
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
