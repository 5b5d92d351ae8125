/* routes_results.c - a finished job's result in the format asked for, and its
 * statistics with the stage timings. Both are rebuilt from the store on request. */
#include <stdlib.h>
#include <string.h>

#include "grainpack/io.h"
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

/* Loads the job's result; 1 with a problem in reply when there is none. */
static int load(gp_request *req, gp_db *db, gp_spec *spec, gp_result *result, gp_reply *reply)
{
    if (!db) {
        gp_problem_store_unavailable(reply, req->path);
        return 1;
    }
    if (without_result(req, db, reply))
        return 1;
    int rc = gp_render_load(db, req->id, req->owner, spec, result);
    if (rc == GP_SRV_ENOTFOUND) /* deleted between the two reads */
        return without_result(req, db, reply);
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
    gp_spec spec;
    gp_result result;
    gp_db *db = gp_store_acquire(req->svc->store, 1);
    int missing = load(req, db, &spec, &result, reply);
    gp_store_release(req->svc->store, db);
    if (missing)
        return GP_ROUTE_DONE;
    if (color == GP_PICTURE_COLOR_QUALITY && !result.has_balance) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "color=quality colours the grains by F, which only a job that balances has; "
                   "job %s has no balance stage (color=radius)", req->id);
        gp_result_free(&result);
        gp_spec_free(&spec);
        return GP_ROUTE_DONE;
    }
    if (color >= 0)
        spec.picture_color = (gp_picture_color)color;
    char *body;
    size_t len;
    int rc = gp_render_format(&spec, &result, format, &body, &len);
    if (rc == 0)
        gp_reply_take(reply, 200, gp_format_media_type(format), body, len);
    else if (rc == GP_ENOMEM)
        gp_problem_out_of_memory(reply);
    else
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path, "rendering %s failed: %s",
                   gp_format_name(format), gp_strerror(rc));
    gp_result_free(&result);
    gp_spec_free(&spec);
    return GP_ROUTE_DONE;
}

int gp_route_statistics(gp_request *req, gp_reply *reply)
{
    gp_spec spec;
    gp_result result;
    char names[GP_MAX_STAGES][32];
    double seconds[GP_MAX_STAGES];
    int ntimings = 0;
    gp_db *db = gp_store_acquire(req->svc->store, 1);
    int missing = load(req, db, &spec, &result, reply);
    if (!missing)
        ntimings = gp_store_load_timings(db, req->id, names, seconds, GP_MAX_STAGES);
    gp_store_release(req->svc->store, db);
    if (missing)
        return GP_ROUTE_DONE;
    json_t *stats = gp_statistics_json(&spec, &result);
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
    gp_result_free(&result);
    gp_spec_free(&spec);
    return GP_ROUTE_DONE;
}
