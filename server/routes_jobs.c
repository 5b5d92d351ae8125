/* routes_jobs.c - checking a spec, submitting a job, listing jobs, following one (with
 * the long-poll), dismissing or deleting it. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jobinfo.h"
#include "log.h"
#include "problem.h"
#include "processes.h"
#include "routes.h"
#include "workers.h"

#define JSON_TYPE "application/json"
/* Page size of GET /jobs when no limit is given, and the largest allowed. */
#define DEFAULT_LIMIT 10
#define MAX_LIMIT 1000

/* Parses an unsigned decimal query parameter in [lo, hi]. Returns 0 (value set, or
 * left alone when absent) or -1 with a 400 problem in reply. */
static int query_count(const gp_request *req, const char *name, long long lo, long long hi,
                       long long *value, gp_reply *reply)
{
    const char *text = gp_request_query(req, name);
    if (!text)
        return 0;
    char *end;
    errno = 0;
    long long v = strtoll(text, &end, 10);
    if (errno || end == text || *end || v < lo || v > hi) {
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "%s must be an integer from %lld to %lld, got '%.40s'", name, lo, hi, text);
        return -1;
    }
    *value = v;
    return 0;
}

/* The process of the path's {processId}; NULL with a 404 in reply when there is none. */
static const gp_process_def *find_process(const gp_request *req, gp_reply *reply)
{
    const gp_process_def *process = gp_process_find(req->id);
    if (!process)
        gp_problem_no_such_process(reply, req->path, req->id);
    return process;
}

int gp_route_validate(gp_request *req, gp_reply *reply)
{
    const gp_process_def *process = find_process(req, reply);
    void *spec;
    if (!process || gp_process_parse_request(process, req, &spec, reply))
        return GP_ROUTE_DONE;
    /* nothing is stored or queued: the answer is what a submission would be accepted as */
    json_t *body = process->validation(spec, req->svc->cfg);
    process->free_spec(spec);
    if (!body) {
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path, "out of memory");
        return GP_ROUTE_DONE;
    }
    gp_reply_json(reply, 200, JSON_TYPE, body);
    return GP_ROUTE_DONE;
}

int gp_route_execute(gp_request *req, gp_reply *reply)
{
    gp_service *svc = req->svc;
    const gp_process_def *process = find_process(req, reply);
    if (!process)
        return GP_ROUTE_DONE;
    if (!atomic_load(&svc->accepting)) {
        gp_problem(reply, 503, GP_PROBLEM_SHUTTING_DOWN, req->path,
                   "the service is shutting down and accepts no new jobs");
        reply->retry_after = GP_RETRY_AFTER_SECONDS;
        return GP_ROUTE_DONE;
    }
    void *spec;
    if (gp_process_parse_request(process, req, &spec, reply))
        return GP_ROUTE_DONE;
    gp_job_columns columns;
    process->columns(spec, &columns);
    /* reserve a queue place first, so that concurrent submissions cannot overshoot */
    long before = atomic_fetch_add(&svc->queued, 1);
    if (before >= (long)svc->cfg->max_queued) {
        atomic_fetch_sub(&svc->queued, 1);
        process->free_spec(spec);
        gp_problem(reply, 503, GP_PROBLEM_QUEUE_FULL, req->path,
                   "%ld jobs are waiting, the limit (--max-queued) is %zu; try again later",
                   before, svc->cfg->max_queued);
        reply->retry_after = GP_RETRY_AFTER_SECONDS;
        return GP_ROUTE_DONE;
    }
    /* the per-key limit only applies to keys: without them there is nobody to count */
    size_t max_active = req->who ? svc->cfg->max_jobs_per_key : 0;
    const char *owner = gp_request_submitter(req);
    gp_job job;
    long active = 0;
    gp_db *db = gp_store_acquire(svc->store, 1);
    int rc = db ? gp_store_insert_job_columns(db, owner, max_active, req->body, req->body_len,
                                              &columns, &job, &active)
                : GP_SRV_EDB;
    gp_store_release(svc->store, db);
    double expected = columns.expected;
    process->free_spec(spec);
    if (rc == GP_SRV_ELIMIT) {
        atomic_fetch_sub(&svc->queued, 1);
        gp_problem(reply, 429, GP_PROBLEM_TOO_MANY_JOBS, req->path,
                   "the key of '%s' has %ld jobs accepted or running, the limit is %zu "
                   "(--max-jobs-per-key); wait for some to finish, or dismiss some",
                   owner, active, max_active);
        reply->retry_after = GP_RETRY_AFTER_SECONDS;
        return GP_ROUTE_DONE;
    }
    if (rc) {
        atomic_fetch_sub(&svc->queued, 1);
        gp_problem_store_error(reply, req->path, rc, "the job was not stored");
        return GP_ROUTE_DONE;
    }
    gp_log("job %s accepted from %s: %s, about %.0f %s expected", job.id, owner[0] ? owner : "-",
           process->id, expected, process->noun);
    gp_pool_notify(svc->pool);
    snprintf(reply->location, sizeof reply->location, "/jobs/%s", job.id);
    gp_reply_json(reply, 201, JSON_TYPE, gp_job_status_info(&job));
    return GP_ROUTE_DONE;
}

/* Parses ?status=a,b into a bit mask of gp_job_status. Returns 0 or -1 with a 400. */
static int status_filter(const gp_request *req, unsigned *mask, gp_reply *reply)
{
    const char *text = gp_request_query(req, "status");
    *mask = 0;
    if (!text)
        return 0;
    char name[32];
    for (const char *p = text;;) {
        size_t n = strcspn(p, ",");
        gp_job_status st;
        snprintf(name, sizeof name, "%.*s", (int)(n < sizeof name ? n : sizeof name - 1), p);
        if (n >= sizeof name || gp_job_status_parse(name, &st)) {
            gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                       "status must be a comma-separated list of accepted, running, successful, "
                       "failed, dismissed; got '%.60s'", text);
            return -1;
        }
        *mask |= 1u << st;
        if (!p[n])
            return 0;
        p += n + 1;
    }
}

/* Reads ?cursor= (a token of a `next` link, cursor.h) into the position the page starts
 * before; 0 when absent. Returns 0 or -1 with a 400. */
static int page_cursor(const gp_request *req, int64_t *seq, gp_reply *reply)
{
    const char *text = gp_request_query(req, "cursor");
    *seq = 0;
    if (!text || gp_cursor_decode(&req->svc->cursor_keys, req->owner, text, seq) == 0)
        return 0;
    gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
               "cursor must be taken from the next link of a page this daemon gave you (a "
               "cursor is valid for the key it was made for, until the daemon restarts); got "
               "'%.40s': start again from the first page",
               text);
    return -1;
}

int gp_route_jobs(gp_request *req, gp_reply *reply)
{
    gp_service *svc = req->svc;
    long long limit = DEFAULT_LIMIT;
    int64_t cursor = 0;
    unsigned mask;
    if (query_count(req, "limit", 1, MAX_LIMIT, &limit, reply) ||
        page_cursor(req, &cursor, reply) || status_filter(req, &mask, reply))
        return GP_ROUTE_DONE;
    gp_job *jobs = malloc((size_t)limit * sizeof *jobs);
    if (!jobs) {
        gp_problem_out_of_memory(reply);
        return GP_ROUTE_DONE;
    }
    size_t n = 0;
    int more = 0;
    gp_db *db = gp_store_acquire(svc->store, 1);
    int rc = db ? gp_store_list_jobs(db, req->owner, mask, cursor, (size_t)limit, jobs, &n, &more)
                : GP_SRV_EDB;
    gp_store_release(svc->store, db);
    if (rc) {
        free(jobs);
        gp_problem_store_unavailable(reply, req->path);
        return GP_ROUTE_DONE;
    }
    json_t *list = json_array();
    for (size_t i = 0; list && i < n; i++)
        json_array_append_new(list, gp_job_status_info(&jobs[i]));
    /* the links repeat the query so that the next page keeps the filter */
    const char *status = gp_request_query(req, "status");
    char self[160], next[160 + sizeof "&cursor=" + GP_CURSOR_CHARS];
    snprintf(self, sizeof self, "/jobs?limit=%lld%s%.60s", limit, status ? "&status=" : "",
             status ? status : "");
    json_t *links = json_pack("[{s:s, s:s, s:s}]", "href", self, "rel", "self", "type", JSON_TYPE);
    if (more && n > 0 && links) {
        char token[GP_CURSOR_SIZE];
        gp_cursor_encode(&svc->cursor_keys, req->owner, jobs[n - 1].seq, token);
        snprintf(next, sizeof next, "%s&cursor=%s", self, token);
        json_array_append_new(links,
                              json_pack("{s:s, s:s, s:s}", "href", next, "rel", "next", "type", JSON_TYPE));
    }
    free(jobs);
    gp_reply_json(reply, 200, JSON_TYPE, json_pack("{s:o, s:o}", "jobs", list, "links", links));
    return GP_ROUTE_DONE;
}

/* Reads a job as the request may see it, with a connection of its own. */
static int read_job(const gp_request *req, gp_job *job)
{
    gp_service *svc = req->svc;
    gp_db *db = gp_store_acquire(svc->store, 1);
    int rc = db ? gp_store_get_job(db, req->id, req->owner, job) : GP_SRV_EDB;
    gp_store_release(svc->store, db);
    return rc;
}

int gp_route_job(gp_request *req, gp_reply *reply)
{
    gp_service *svc = req->svc;
    long long wait = 0;
    if (query_count(req, "wait", 0, svc->cfg->max_wait, &wait, reply))
        return GP_ROUTE_DONE;
    gp_job job;
    int rc = read_job(req, &job);
    /* the long-poll: register, look again (the job may have finished in between), and
     * suspend only if it still runs; a worker's wake-up or the deadline resumes us */
    if (rc == 0 && wait > 0 && !req->resumed && !gp_job_status_final(job.status)) {
        gp_waiter *w = gp_waiters_add(svc->waiters, req->conn, req->id,
                                      gp_monotonic_seconds() + (double)wait);
        if (w) {
            rc = read_job(req, &job);
            if (rc == 0 && !gp_job_status_final(job.status)) {
                if (gp_waiters_suspend(svc->waiters, w))
                    return GP_ROUTE_SUSPENDED;
                rc = read_job(req, &job);
            } else {
                gp_waiters_cancel(svc->waiters, w);
            }
        }
    }
    if (rc == GP_SRV_ENOTFOUND)
        gp_problem_no_such_job(reply, req->path, req->id);
    else if (rc)
        gp_problem_store_unavailable(reply, req->path);
    else
        gp_reply_json(reply, 200, JSON_TYPE, gp_job_status_info(&job));
    return GP_ROUTE_DONE;
}

int gp_route_dismiss(gp_request *req, gp_reply *reply)
{
    gp_service *svc = req->svc;
    gp_job_status before = GP_JOB_ACCEPTED;
    gp_job job;
    int deleted = 0;
    memset(&job, 0, sizeof job);
    gp_db *db = gp_store_acquire(svc->store, 1);
    int rc = db ? gp_store_dismiss(db, req->id, req->owner, &before, &deleted, &job) : GP_SRV_EDB;
    gp_store_release(svc->store, db);
    if (rc == GP_SRV_ENOTFOUND) {
        gp_problem_no_such_job(reply, req->path, req->id);
        return GP_ROUTE_DONE;
    }
    if (rc) {
        gp_problem_store_error(reply, req->path, rc, "the job was neither dismissed nor deleted");
        return GP_ROUTE_DONE;
    }
    if (deleted) {
        gp_log("job %s deleted with its results (it was %s)", req->id, gp_job_status_name(before));
        job.status = GP_JOB_DISMISSED;
        snprintf(job.message, sizeof job.message, "deleted with its results");
    } else {
        if (before == GP_JOB_ACCEPTED)
            atomic_fetch_sub(&svc->queued, 1);
        else
            gp_pool_cancel(svc->pool, req->id);
        gp_log("job %s dismissed (it was %s)", req->id, gp_job_status_name(before));
        gp_waiters_wake(svc->waiters, req->id);
    }
    gp_reply_json(reply, 200, JSON_TYPE, gp_job_status_info(&job));
    return GP_ROUTE_DONE;
}
