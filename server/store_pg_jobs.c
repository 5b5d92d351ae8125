/* store_pg_jobs.c - the PostgreSQL store's queries on jobs: submit (the per-owner limit
 * counted across nodes), read, list, claim (FOR UPDATE SKIP LOCKED, with a lease), progress,
 * fail, requeue, dismiss or delete, count, and the requeue of jobs whose node died. Every
 * change another node must hear of is NOTIFYed in its transaction (store_pg_watch.c). */
#include "store_pg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

/* process: "pack3d" when the spec's domain has a depth (gp_process_of_spec, processes.h) */
#define JOB_COLUMNS "seq, id, status, created, started, finished, updated, progress, message," \
                    " has_mesh, CASE WHEN coalesce(spec::jsonb #> '{inputs,domain,depth}'," \
                    " spec::jsonb #> '{domain,depth}') IS NULL THEN 'pack2d' ELSE 'pack3d' END"

/* The owner advisory lock's class (pg_advisory_xact_lock(int, int)): "gp" */
#define OWNER_LOCK_CLASS 0x6770

/* Copies column col of row into dst (empty when NULL), truncated to size. */
static void copy_text(char *dst, size_t size, const PGresult *res, int row, int col)
{
    snprintf(dst, size, "%s", PQgetisnull(res, row, col) ? "" : PQgetvalue(res, row, col));
}

/* Reads a row of JOB_COLUMNS. */
static void read_job(const PGresult *res, int row, gp_job *job)
{
    memset(job, 0, sizeof *job);
    job->seq = atoll(PQgetvalue(res, row, 0));
    copy_text(job->id, sizeof job->id, res, row, 1);
    gp_job_status st = GP_JOB_FAILED;
    gp_job_status_parse(PQgetvalue(res, row, 2), &st);
    job->status = st;
    copy_text(job->created, sizeof job->created, res, row, 3);
    copy_text(job->started, sizeof job->started, res, row, 4);
    copy_text(job->finished, sizeof job->finished, res, row, 5);
    copy_text(job->updated, sizeof job->updated, res, row, 6);
    job->progress = atoi(PQgetvalue(res, row, 7));
    copy_text(job->message, sizeof job->message, res, row, 8);
    job->has_mesh = PQgetvalue(res, row, 9)[0] == 't';
    copy_text(job->process, sizeof job->process, res, row, 10);
}

int gp_pg_insert_job(gp_db *d, const char *owner, size_t max_active, const char *spec_text,
                     size_t spec_len, const gp_job_columns *columns, gp_job *out, long *active)
{
    pg_db *db = gp_pg_db(d);
    if (active)
        *active = 0;
    gp_store_new_job(out, columns);
    char *text = strndup(spec_text, spec_len);
    if (!text)
        return GP_ENOMEM;
    int rc = gp_pg_begin(db);
    if (!rc && max_active > 0) {
        /* the owner's jobs counted on every node: two submissions of one key, on two
         * nodes, take this lock in turn, so neither sees room that the other took */
        char cls[32];
        pg_params p = {0};
        gp_pg_int(&p, cls, OWNER_LOCK_CLASS);
        gp_pg_text(&p, owner);
        rc = gp_pg_run(db, "lock the owner's count",
                       "SELECT pg_advisory_xact_lock($1::int, hashtext($2::text))", &p, NULL);
        PGresult *res = rc ? NULL : gp_pg_query(db, "count active jobs",
                                                "SELECT count(*) FROM jobs WHERE owner = $1::text"
                                                " AND status IN ('accepted', 'running')",
                                                &(pg_params){.n = 1, .values = {owner}}, 0, &rc);
        long n = res ? atol(PQgetvalue(res, 0, 0)) : 0;
        PQclear(res);
        if (active)
            *active = n;
        if (!rc && n >= (long)max_active)
            rc = GP_SRV_ELIMIT;
    }
    if (!rc) {
        char b[6][32];
        pg_params p = {0};
        gp_pg_text(&p, out->id);
        gp_pg_text(&p, out->created);
        gp_pg_text(&p, text);
        gp_pg_double(&p, b[0], columns->width);
        gp_pg_double(&p, b[1], columns->height);
        gp_pg_text(&p, columns->distribution);
        gp_pg_text(&p, columns->joint);
        gp_pg_int(&p, b[2], (long long)columns->level_band);
        gp_pg_int(&p, b[3], (long long)columns->seed);
        gp_pg_double(&p, b[4], columns->expected);
        gp_pg_text(&p, owner);
        gp_pg_text(&p, columns->has_mesh ? "true" : "false");
        PGresult *res = gp_pg_query(
            db, "insert job",
            "INSERT INTO jobs (id, status, created, updated, message, spec, domain_width,"
            " domain_height, distribution, joint, level_band, seed, expected_disks, owner, has_mesh)"
            " VALUES ($1, 'accepted', $2, $2, 'queued', $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)"
            " RETURNING seq, pg_notify('gp_queued', '')",
            &p, 0, &rc);
        if (res)
            out->seq = atoll(PQgetvalue(res, 0, 0));
        PQclear(res);
    }
    free(text);
    return gp_pg_end(db, rc);
}

int gp_pg_get_job(gp_db *d, const char *id, const char *owner, gp_job *out)
{
    pg_params p = {.n = 2, .values = {id, owner}};
    int rc;
    PGresult *res = gp_pg_query(gp_pg_db(d), "get job",
                                "SELECT " JOB_COLUMNS " FROM jobs WHERE id = $1::text"
                                " AND ($2::text IS NULL OR owner = $2::text)",
                                &p, 0, &rc);
    if (res && PQntuples(res) == 1)
        read_job(res, 0, out);
    else if (res)
        rc = GP_SRV_ENOTFOUND;
    PQclear(res);
    return rc;
}

int gp_pg_list_jobs(gp_db *d, const char *owner, unsigned status_mask, int64_t before,
                    size_t limit, gp_job *out, size_t *n, int *more)
{
    *n = 0;
    *more = 0;
    char b[3][32];
    pg_params p = {0};
    gp_pg_int(&p, b[0], before > 0 ? before : INT64_MAX);
    gp_pg_int(&p, b[1], (long long)status_mask);
    gp_pg_int(&p, b[2], (long long)limit + 1); /* one more tells whether there is more */
    gp_pg_text(&p, owner);
    int rc;
    /* status_mask bit i selects status i, in gp_job_status order */
    PGresult *res = gp_pg_query(
        gp_pg_db(d), "list jobs",
        "SELECT " JOB_COLUMNS " FROM jobs WHERE seq < $1::bigint AND ($2::int = 0 OR"
        " (($2::int >> (CASE status WHEN 'accepted' THEN 0 WHEN 'running' THEN 1"
        " WHEN 'successful' THEN 2 WHEN 'failed' THEN 3 ELSE 4 END)) & 1) = 1)"
        " AND ($4::text IS NULL OR owner = $4::text) ORDER BY seq DESC LIMIT $3::bigint",
        &p, 0, &rc);
    for (int row = 0; res && row < PQntuples(res); row++) {
        if (*n == limit) {
            *more = 1;
            break;
        }
        read_job(res, row, &out[(*n)++]);
    }
    PQclear(res);
    return rc;
}

int gp_pg_claim(gp_db *d, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
                size_t *spec_len)
{
    pg_db *db = gp_pg_db(d);
    pg_store *store = gp_pg_store(db->store);
    *spec_text = NULL;
    *spec_len = 0;
    char now[GP_TIMESTAMP_SIZE], lease[32];
    gp_timestamp_now(now);
    pg_params p = {0};
    gp_pg_text(&p, now);
    gp_pg_text(&p, store->run);
    gp_pg_double(&p, lease, store->lease_seconds);
    int rc;
    /* SKIP LOCKED: nodes claiming at once take different jobs instead of queueing on one */
    PGresult *res = gp_pg_query(
        db, "claim",
        /* the time is this node's, read before the statement; the job's creation may be
         * later (committed meanwhile, or another node's clock): never before it */
        "UPDATE jobs SET status = 'running', started = GREATEST($1, created),"
        " updated = GREATEST($1, created), progress = 0,"
        " message = 'running', claims = claims + 1, node = $2,"
        " lease_until = now() + make_interval(secs => $3::float8)"
        " WHERE seq = (SELECT seq FROM jobs WHERE status = 'accepted' ORDER BY seq LIMIT 1"
        " FOR UPDATE SKIP LOCKED) RETURNING id, spec, claims",
        &p, 0, &rc);
    if (res && PQntuples(res) == 0)
        rc = GP_SRV_ENOTFOUND;
    if (res && PQntuples(res) == 1) {
        copy_text(id, GP_JOB_ID_SIZE, res, 0, 0);
        size_t len = (size_t)PQgetlength(res, 0, 1);
        if ((*spec_text = malloc(len + 1))) {
            memcpy(*spec_text, PQgetvalue(res, 0, 1), len + 1);
            *spec_len = len;
        }
        /* without memory to hold the claim, the job is not renewed: it runs again on a
         * node after its lease, as after a crash */
        if (!*spec_text || gp_pg_hold(store, id, atoi(PQgetvalue(res, 0, 2)))) {
            free(*spec_text);
            *spec_text = NULL;
            rc = GP_ENOMEM;
        } else if (queued) {
            atomic_fetch_sub(queued, 1);
        }
    }
    PQclear(res);
    return rc;
}

/* Adds the claim this run holds on id (node and claims) to p; 0 when it holds none. */
static int held_params(pg_store *store, const char *id, pg_params *p, char buf[32])
{
    int claim = gp_pg_held(store, id);
    gp_pg_text(p, store->run);
    gp_pg_int(p, buf, claim);
    return claim;
}

int gp_pg_progress(gp_db *d, const char *id, int percent, const char *message)
{
    pg_db *db = gp_pg_db(d);
    char now[GP_TIMESTAMP_SIZE], b[2][32];
    gp_timestamp_now(now);
    pg_params p = {0};
    gp_pg_text(&p, id);
    gp_pg_int(&p, b[0], percent);
    gp_pg_text(&p, message);
    gp_pg_text(&p, now);
    held_params(gp_pg_store(db->store), id, &p, b[1]);
    return gp_pg_run(db, "progress",
                     "UPDATE jobs SET progress = $2::int, message = $3, updated = $4"
                     " WHERE id = $1 AND status = 'running' AND node = $5 AND claims = $6::int",
                     &p, NULL);
}

/* Runs a one-row UPDATE of a job this run holds, whose first parameters are (id, node,
 * claims, now) and then those of extra (which may be NULL); notifies `channel`; forgets
 * the claim when it is over (done or no longer this run's). GP_SRV_ESTATE when no row
 * matched: the job was dismissed, or its lease expired and another node took it. */
static int update_held(pg_db *db, const char *id, const char *sql, const char *what,
                       const char *a, const char *b)
{
    pg_store *store = gp_pg_store(db->store);
    char now[GP_TIMESTAMP_SIZE], claim[32];
    gp_timestamp_now(now);
    pg_params p = {0};
    gp_pg_text(&p, id);
    held_params(store, id, &p, claim);
    gp_pg_text(&p, now);
    if (a)
        gp_pg_text(&p, a);
    if (b)
        gp_pg_text(&p, b);
    long changed = 0;
    int rc = gp_pg_run(db, what, sql, &p, &changed);
    if (rc == 0 && changed == 0)
        rc = GP_SRV_ESTATE;
    if (rc == 0 || rc == GP_SRV_ESTATE)
        gp_pg_forget(store, id);
    return rc;
}

int gp_pg_fail(gp_db *d, const char *id, const char *code_name, const char *message)
{
    return update_held(gp_pg_db(d), id,
                       "WITH f AS (UPDATE jobs SET status = 'failed', error = $5, message = $6,"
                       " finished = $4, updated = $4, node = NULL, lease_until = NULL"
                       " WHERE id = $1 AND status = 'running' AND node = $2 AND claims = $3::int"
                       " RETURNING id) SELECT pg_notify('gp_done', id) FROM f",
                       "fail job", code_name, message);
}

int gp_pg_requeue(gp_db *d, const char *id)
{
    /* a stop that cancelled the job cleanly: its claim does not count */
    return update_held(gp_pg_db(d), id,
                       "WITH r AS (UPDATE jobs SET status = 'accepted', started = NULL,"
                       " progress = 0, message = '" GP_REQUEUE_MESSAGE "', updated = $4,"
                       " claims = greatest(claims - 1, 0), node = NULL, lease_until = NULL"
                       " WHERE id = $1 AND status = 'running' AND node = $2 AND claims = $3::int"
                       " RETURNING id) SELECT pg_notify('gp_queued', '') FROM r",
                       "requeue job", NULL, NULL);
}

int gp_pg_dismiss(gp_db *d, const char *id, const char *owner, gp_job_status *before,
                  int *deleted, gp_job *after)
{
    pg_db *db = gp_pg_db(d);
    *deleted = 0;
    int rc = gp_pg_begin(db);
    pg_params p = {.n = 2, .values = {id, owner}};
    PGresult *res = rc ? NULL : gp_pg_query(db, "dismiss: read status",
                                            "SELECT status FROM jobs WHERE id = $1::text AND"
                                            " ($2::text IS NULL OR owner = $2::text) FOR UPDATE",
                                            &p, 0, &rc);
    gp_job_status st = GP_JOB_FAILED;
    if (res && PQntuples(res) == 1)
        gp_job_status_parse(PQgetvalue(res, 0, 0), &st);
    else if (res)
        rc = GP_SRV_ENOTFOUND;
    PQclear(res);
    if (rc == 0)
        rc = gp_pg_get_job(d, id, NULL, after);
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    pg_params q = {.n = 2, .values = {id, now}};
    if (rc == 0 && !gp_job_status_final(st)) {
        /* the node running it hears of it when it renews its lease (gp_store_watch) */
        rc = gp_pg_run(db, "dismiss",
                       "WITH u AS (UPDATE jobs SET status = 'dismissed',"
                       " message = 'dismissed by request', finished = $2, updated = $2,"
                       " node = NULL, lease_until = NULL WHERE id = $1 RETURNING id)"
                       " SELECT pg_notify('gp_done', id) FROM u",
                       &q, NULL);
        if (rc == 0)
            rc = gp_pg_get_job(d, id, NULL, after);
    } else if (rc == 0) {
        rc = gp_pg_run(db, "delete", "DELETE FROM jobs WHERE id = $1", &(pg_params){.n = 1, .values = {id}},
                       NULL);
        *deleted = 1;
    }
    if (rc == 0)
        *before = st;
    return gp_pg_end(db, rc);
}

int gp_pg_count(gp_db *d, long counts[GP_JOB_NSTATUS])
{
    memset(counts, 0, GP_JOB_NSTATUS * sizeof *counts);
    int rc;
    PGresult *res = gp_pg_query(gp_pg_db(d), "count jobs",
                                "SELECT status, count(*) FROM jobs GROUP BY status", NULL, 0, &rc);
    for (int row = 0; res && row < PQntuples(res); row++) {
        gp_job_status st;
        if (gp_job_status_parse(PQgetvalue(res, row, 0), &st) == 0)
            counts[st] = atol(PQgetvalue(res, row, 1));
    }
    PQclear(res);
    return rc;
}

int gp_pg_reap(pg_db *db, int max_attempts, int *requeued, int *given_up)
{
    char now[GP_TIMESTAMP_SIZE], max[32];
    gp_timestamp_now(now);
    pg_params p = {0};
    gp_pg_text(&p, now);
    gp_pg_int(&p, max, max_attempts);
    int rc = gp_pg_begin(db);
    /* two nodes reaping at once: the second's UPDATE sees the rows the first changed,
     * no longer running, and leaves them */
    PGresult *res = rc ? NULL : gp_pg_query(
        db, "give up jobs whose nodes died",
        "WITH f AS (UPDATE jobs SET status = 'failed', error = 'gave up', finished = $1,"
        " updated = $1, node = NULL, lease_until = NULL, message = 'failed: the node running"
        " it stopped ' || claims || ' times while this job ran (a crash, a kill, or a stop"
        " it did not answer in time); it is not run again (--max-job-attempts ' || $2::int || ')'"
        " WHERE status = 'running' AND lease_until < now() AND claims >= $2::int RETURNING id)"
        " SELECT pg_notify('gp_done', id) FROM f", &p, 0, &rc);
    if (res && given_up)
        *given_up += PQntuples(res);
    PQclear(res);
    res = rc ? NULL : gp_pg_query(
        db, "queue again jobs whose nodes died",
        "WITH r AS (UPDATE jobs SET status = 'accepted', started = NULL, progress = 0,"
        " message = '" GP_REQUEUE_MESSAGE "', updated = $1, node = NULL, lease_until = NULL"
        " WHERE status = 'running' AND lease_until < now() RETURNING id)"
        " SELECT pg_notify('gp_queued', '') FROM r", &(pg_params){.n = 1, .values = {now}}, 0, &rc);
    if (res && requeued)
        *requeued += PQntuples(res);
    PQclear(res);
    return gp_pg_end(db, rc);
}
