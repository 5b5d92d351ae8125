/* routes_results.c - a finished job's result in the format asked for (streamed from the
 * stored sections, gzip when asked, with a strong ETag), and its statistics with the stage
 * timings (from the stored summary). Nothing is computed again. */
#include <stdlib.h>
#include <string.h>

#include "grainpack/io.h"
#include "problem.h"
#include "processes.h"
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

/* Opens the job's stored result; 1 with a problem in reply when there is none. On 0 the
 * caller frees res. */
static int open_result(gp_request *req, gp_stored_result *res, gp_reply *reply)
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

int gp_route_results(gp_request *req, gp_reply *reply)
{
    gp_format format;
    if (gp_render_choose_format(req, &format, reply))
        return GP_ROUTE_DONE;
    gp_stored_result res;
    if (open_result(req, &res, reply))
        return GP_ROUTE_DONE;
    /* the job's process serves it (and takes res over) */
    return gp_process_of_spec(res.spec_text, res.spec_len)->results(req, &res, format, reply);
}

int gp_route_statistics(gp_request *req, gp_reply *reply)
{
    gp_stored_result res;
    if (open_result(req, &res, reply))
        return GP_ROUTE_DONE;
    char names[GP_MAX_STAGES][32];
    double seconds[GP_MAX_STAGES];
    int ntimings = 0;
    gp_db *db = gp_store_acquire(req->svc->store, 1);
    if (db)
        ntimings = gp_store_load_timings(db, req->id, names, seconds, GP_MAX_STAGES);
    gp_store_release(req->svc->store, db);
    json_t *stats = gp_process_of_spec(res.spec_text, res.spec_len)->statistics(&res);
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
    return GP_ROUTE_DONE;
}
