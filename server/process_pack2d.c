/* process_pack2d.c - the "pack2d" process (processes.h): disks in a rectangle, then the
 * stages the spec asks for (balance, Laguerre cells, mesh) through gp_pipeline_run; its
 * results rendered by the engine's writers from the stored sections. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "download.h"
#include "embedded.h"
#include "grainpack/pipeline.h"
#include "json_values.h"
#include "problem.h"
#include "processes.h"
#include "render.h"

static int parse(const char *text, size_t len, const gp_spec_limits *limits, void **out,
                 gp_error *err)
{
    gp_spec *spec = malloc(sizeof *spec);
    if (!spec)
        return gp_error_set(err, GP_ENOMEM, "", "out of memory");
    int rc = gp_spec_parse(text, len, limits, spec, err);
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
        gp_spec_free(spec);
    free(spec);
}

static void columns(const void *spec, gp_job_columns *out)
{
    gp_job_columns_of_spec(spec, out);
}

static json_t *validation(const void *s, const gp_config *cfg)
{
    const gp_spec *spec = s;
    json_t *body = json_pack("{s:b, s:I, s:o*, s:{s:I, s:I, s:I}}", "valid", 1, "expected_disks",
                             (json_int_t)llround(spec->expected_disks), "inputs", gp_spec_json(spec),
                             "limits", "max_disks", (json_int_t)cfg->max_disks, "max_bins",
                             (json_int_t)cfg->max_bins, "max_elements",
                             (json_int_t)cfg->max_elements);
    if (body && !json_object_get(body, "inputs")) {
        json_decref(body);
        return NULL;
    }
    return body;
}

static int stages(const void *s, const char **out, int cap)
{
    const gp_spec *spec = s;
    return gp_process_stages("pack", spec->balance_enabled, spec->laguerre_enabled, out, cap);
}

static void free_run(gp_process_run *run)
{
    gp_sections_free(run->sections, run->nsections);
    if (run->state)
        gp_result_free(run->state);
    free(run->state);
    memset(run, 0, sizeof *run);
}

static int run(void *s, const gp_config *cfg, const gp_progress *progress, gp_process_run *out,
               gp_error *err)
{
    gp_spec *spec = s;
    memset(out, 0, sizeof *out);
    gp_result *result = calloc(1, sizeof *result);
    if (!result)
        return gp_error_set(err, GP_ENOMEM, "", "out of memory");
    /* a mesh stops when it grows far beyond today's cap (the estimate it was accepted on
       may be off; gp_spec.max_elements) */
    spec->max_elements = cfg->max_elements;
    int rc = gp_pipeline_run(spec, cfg->max_disks, progress, result, err);
    if (rc) {
        free(result);
        return rc;
    }
    out->state = result;
    out->count = result->stats.count;
    out->density = result->stats.packing_density;
    if ((rc = gp_outcome_of_result(result, out->sections, &out->nsections, &out->outcome))) {
        free_run(out);
        return gp_error_set(err, rc, "", "the result cannot be cut into sections: %s",
                            gp_strerror(rc));
    }
    return 0;
}

/* The job's spec, as stored, parsed again without today's caps (it was accepted once).
 * Returns 0, or -1 with a problem in reply. */
static int stored_spec(gp_request *req, const gp_stored_result *res, gp_spec *spec, gp_reply *reply)
{
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
    gp_error err;
    int rc = gp_spec_parse(res->spec_text, res->spec_len, &unlimited, spec, &err);
    if (rc == GP_ENOMEM)
        gp_problem_out_of_memory(reply);
    else if (rc)
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path,
                   "the stored result of job %s could not be read: %s", req->id,
                   gp_srv_strerror(rc));
    return rc ? -1 : 0;
}

/* Reads ?color=radius|quality, what the picture is coloured by (the spec's choice when
 * absent). Returns 0 with *color set, or -1 with a 400 in reply. */
static int picture_color(const gp_request *req, int *color, gp_reply *reply)
{
    const char *text = gp_request_query(req, "color");
    *color = -1;
    if (!text)
        return 0;
    if (strcmp(text, "radius") == 0 || strcmp(text, "quality") == 0) {
        *color = strcmp(text, "radius") == 0 ? GP_PICTURE_COLOR_RADIUS : GP_PICTURE_COLOR_QUALITY;
        return 0;
    }
    gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
               "color must be radius or quality (F, for a job that balanced), got '%.40s'", text);
    return -1;
}

/* Why the stored result cannot be served as asked, as a 400 in reply; 0 when it can. */
static int refuse(gp_request *req, const gp_result *summary, gp_format format, int color,
                  gp_reply *reply)
{
    if (format == GP_FORMAT_TESS) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "f=tess is a 3D tessellation; job %s is a pack2d job: json, csv, svg, vtk or "
                   "vtu%s", req->id, summary->has_mesh ? ", msh or inp" : "");
        return -1;
    }
    if (color == GP_PICTURE_COLOR_QUALITY && !summary->has_balance) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "color=quality colours the grains by F, which only a job that balances has; "
                   "job %s has no balance stage (color=radius)", req->id);
        return -1;
    }
    if (gp_format_needs_mesh(format) && !summary->has_mesh) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "f=%s is the job's finite-element mesh; job %s has none (its spec has no "
                   "\"mesh\"): json, csv, svg, vtk or vtu", gp_format_name(format), req->id);
        return -1;
    }
    return 0;
}

static int serves(gp_format format, int has_mesh)
{
    return format != GP_FORMAT_TESS && (!gp_format_needs_mesh(format) || has_mesh);
}

static int results(gp_request *req, gp_stored_result *res, gp_format format, gp_reply *reply)
{
    int color;
    gp_spec spec;
    if (picture_color(req, &color, reply) || stored_spec(req, res, &spec, reply)) {
        gp_stored_result_free(res);
        return GP_ROUTE_DONE;
    }
    if (refuse(req, &res->summary, format, color, reply)) {
        gp_stored_result_free(res);
        gp_spec_free(&spec);
        return GP_ROUTE_DONE;
    }
    if (color >= 0)
        spec.picture_color = (gp_picture_color)color;
    int gzip = gp_format_is_text(format) && gp_render_accepts_gzip(req);
    char etag[GP_ETAG_SIZE];
    gp_render_etag(res, &spec, format, gzip, etag);
    if (gp_download_headers(req, etag, gp_format_name(format), gzip, reply)) {
        gp_stored_result_free(res);
        gp_spec_free(&spec);
        return GP_ROUTE_DONE;
    }
    gp_body_stream *stream;
    if (gp_download_new(req->svc, res, &spec, format, gzip, &stream) == 0)
        gp_download_reply(req, stream, gp_format_media_type(format), reply);
    else
        gp_problem_out_of_memory(reply); /* drops the headers above */
    return GP_ROUTE_DONE;
}

static json_t *statistics(const gp_stored_result *res)
{
    gp_spec spec;
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
    gp_error err;
    if (gp_spec_parse(res->spec_text, res->spec_len, &unlimited, &spec, &err))
        return NULL;
    json_t *stats = gp_statistics_json(&spec, &res->summary);
    gp_spec_free(&spec);
    return stats;
}

const gp_process_def gp_process_pack2d = {
    "pack2d",  "disks",  gp_process_pack2d_json, &gp_process_pack2d_json_len,
    parse,     free_spec, columns, validation, stages, run, free_run, serves, results, statistics,
};
