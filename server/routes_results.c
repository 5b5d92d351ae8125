/* routes_results.c - a finished job's result in the format asked for (streamed from the
 * stored sections, gzip when asked, with a strong ETag), and its statistics with the stage
 * timings (from the stored summary). Nothing is computed again. */
#include <stdlib.h>
#include <string.h>

#include "grainpack/io.h"
#include "download.h"
#include "problem.h"
#include "render.h"
#include "routes.h"

#define JSON_TYPE "application/json"

/* Answers for a job that has no result (not found, not finished, failed, dismissed).
 * Returns 1 with reply filled when the job has none, 0 when it is successful. */
static int without_result(gp_request *req, gp_db *db, gp_reply *reply)
{
    gp_job job;
    int rc = gp_store_get_job(db, req->id, req->owner, &job);
    if (rc == GP_SRV_ENOTFOUND) {
        gp_problem_no_such_job(reply, req->path, req->id);
    } else if (rc) {
        gp_problem_store_unavailable(reply, req->path);
    } else if (job.status == GP_JOB_ACCEPTED || job.status == GP_JOB_RUNNING) {
        gp_problem(reply, 404, GP_PROBLEM_RESULT_NOT_READY, req->path,
                   "job %s is %s (%d%%); the result is ready when its status is successful "
                   "(GET /jobs/%s?wait=30 waits for it)",
                   job.id, gp_job_status_name(job.status), job.progress, job.id);
    } else if (job.status != GP_JOB_SUCCESSFUL) {
        gp_problem(reply, 404,
                   job.status == GP_JOB_FAILED ? GP_PROBLEM_JOB_FAILED : GP_PROBLEM_JOB_DISMISSED,
                   req->path, "job %s is %s and has no result: %s", job.id,
                   gp_job_status_name(job.status), job.message);
    } else {
        return 0;
    }
    return 1;
}

/* Opens the job's stored result and parses its spec; 1 with a problem in reply when there
 * is none. On 0 the caller frees res and spec. */
static int open_result(gp_request *req, gp_stored_result *res, gp_spec *spec, gp_reply *reply)
{
    gp_db *db = gp_store_acquire(req->svc->store, 1);
    if (!db) {
        gp_problem_store_unavailable(reply, req->path);
        return 1;
    }
    int missing = without_result(req, db, reply), rc = 0;
    if (!missing) {
        rc = gp_store_open_result(db, req->id, req->owner, res);
        if (rc == GP_SRV_ENOTFOUND) /* deleted between the two reads */
            missing = without_result(req, db, reply);
    }
    gp_store_release(req->svc->store, db);
    if (missing)
        return 1;
    gp_error err;
    /* accepted once, so parsed without today's caps */
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1};
    if (rc == 0 && (rc = gp_spec_parse(res->spec_text, res->spec_len, &unlimited, spec, &err)))
        gp_stored_result_free(res);
    if (rc == GP_ENOMEM) {
        gp_problem_out_of_memory(reply);
        return 1;
    }
    if (rc) {
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path,
                   "the stored result of job %s could not be read: %s", req->id,
                   gp_srv_strerror(rc));
        return 1;
    }
    return 0;
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

int gp_route_results(gp_request *req, gp_reply *reply)
{
    gp_format format;
    int color;
    if (gp_render_choose_format(req, &format, reply) || picture_color(req, &color, reply))
        return GP_ROUTE_DONE;
    gp_stored_result res;
    gp_spec spec;
    if (open_result(req, &res, &spec, reply))
        return GP_ROUTE_DONE;
    if (color == GP_PICTURE_COLOR_QUALITY && !res.summary.has_balance) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "color=quality colours the grains by F, which only a job that balances has; "
                   "job %s has no balance stage (color=radius)", req->id);
        gp_stored_result_free(&res);
        gp_spec_free(&spec);
        return GP_ROUTE_DONE;
    }
    if (color >= 0)
        spec.picture_color = (gp_picture_color)color;
    int gzip = gp_format_is_text(format) && gp_render_accepts_gzip(req);
    char etag[GP_ETAG_SIZE];
    gp_render_etag(&res, &spec, format, gzip, etag);
    gp_reply_header_add(reply, "ETag", "%s", etag);
    /* the bytes depend on Accept (the format, without ?f=) and Accept-Encoding */
    gp_reply_header_add(reply, "Vary", "Accept, Accept-Encoding");
    /* a result never changes but may be deleted, and is per key: ask again each time,
     * which a 304 makes cheap */
    gp_reply_header_add(reply, "Cache-Control", "private, no-cache");
    if (gp_render_not_modified(req, etag)) {
        gp_stored_result_free(&res);
        gp_spec_free(&spec);
        gp_reply_take(reply, 304, NULL, NULL, 0);
        return GP_ROUTE_DONE;
    }
    gp_reply_header_add(reply, "Content-Disposition", "attachment; filename=\"job-%s.%s\"",
                        req->id, gp_format_name(format));
    if (gzip)
        gp_reply_header_add(reply, "Content-Encoding", "gzip");
    gp_body_stream *stream;
    if (gp_download_new(req->svc, &res, &spec, format, gzip, &stream) == 0) {
        gp_reply_stream(reply, 200, gp_format_media_type(format), stream);
        /* libmicrohttpd 0.9.75 ends the headers of a HEAD answer to a chunked response with
         * the last chunk ("0\r\n\r\n") although HEAD has no body: a client reusing the
         * connection would read it as the next status line, so the connection closes */
        reply->close = strcmp(req->method, "HEAD") == 0;
    } else {
        gp_problem_out_of_memory(reply); /* drops the headers above */
    }
    return GP_ROUTE_DONE;
}

int gp_route_statistics(gp_request *req, gp_reply *reply)
{
    gp_stored_result res;
    gp_spec spec;
    if (open_result(req, &res, &spec, reply))
        return GP_ROUTE_DONE;
    char names[GP_MAX_STAGES][32];
    double seconds[GP_MAX_STAGES];
    int ntimings = 0;
    gp_db *db = gp_store_acquire(req->svc->store, 1);
    if (db)
        ntimings = gp_store_load_timings(db, req->id, names, seconds, GP_MAX_STAGES);
    gp_store_release(req->svc->store, db);
    json_t *stats = gp_statistics_json(&spec, &res.summary);
    json_t *timings = json_array();
    double total = 0.0;
    for (int i = 0; timings && i < ntimings; i++) {
        json_array_append_new(timings, json_pack("{s:s, s:f}", "stage", names[i], "seconds",
                                                 seconds[i]));
        total += seconds[i];
    }
    if (stats) {
        json_object_set_new(stats, "jobID", json_string(req->id));
        json_object_set_new(stats, "timings", timings ? timings : json_null());
        json_object_set_new(stats, "total_seconds", json_real(total));
    } else {
        json_decref(timings);
    }
    gp_reply_json(reply, 200, JSON_TYPE, stats);
    gp_stored_result_free(&res);
    gp_spec_free(&spec);
    return GP_ROUTE_DONE;
}
