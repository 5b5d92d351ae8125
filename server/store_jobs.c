/* store_jobs.c - the job store's queries on jobs: submit (with the per-owner limit), read,
 * list, claim, progress, fail, requeue, dismiss or delete, count by status. */
#include "store_db.h"
#include "store_ops.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

/* Reads a row of JOB_COLUMNS (store.c: the columns of ST_GET and ST_LIST). */
static void read_job(sqlite3_stmt *s, gp_job *job)
{
    memset(job, 0, sizeof *job);
    job->seq = sqlite3_column_int64(s, 0);
    gp_db_copy_text(job->id, sizeof job->id, s, 1);
    const unsigned char *status = sqlite3_column_text(s, 2);
    gp_job_status st = GP_JOB_FAILED;
    if (status)
        gp_job_status_parse((const char *)status, &st);
    job->status = st;
    gp_db_copy_text(job->created, sizeof job->created, s, 3);
    gp_db_copy_text(job->started, sizeof job->started, s, 4);
    gp_db_copy_text(job->finished, sizeof job->finished, s, 5);
    gp_db_copy_text(job->updated, sizeof job->updated, s, 6);
    job->progress = sqlite3_column_int(s, 7);
    gp_db_copy_text(job->message, sizeof job->message, s, 8);
    job->has_mesh = sqlite3_column_int(s, 9);
    gp_db_copy_text(job->process, sizeof job->process, s, 10);
}

/* The owner's accepted and running jobs; inside the inserting transaction. */
static int count_active(gp_db *db, const char *owner, long *active)
{
    sqlite3_stmt *s = gp_db_stmt(db, ST_ACTIVE);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, owner, -1, SQLITE_STATIC);
    int rc = sqlite3_step(s);
    *active = rc == SQLITE_ROW ? (long)sqlite3_column_int64(s, 0) : 0;
    sqlite3_reset(s);
    return rc == SQLITE_ROW ? 0 : gp_db_fail(db, "count active jobs");
}

int sq_insert_job(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                        size_t spec_len, const gp_job_columns *columns, gp_job *out, long *active)
{
    long n_active = 0;
    if (active)
        *active = 0;
    gp_store_new_job(out, columns);
    int rc;
    sqlite3_stmt *s = gp_db_write(db, ST_INSERT, &rc);
    if (!s)
        return rc;
    /* the count and the insert in one transaction: two submissions of one key cannot
     * both see room for one more */
    if (max_active > 0) {
        if ((rc = count_active(db, owner, &n_active)) == 0 && n_active >= (long)max_active)
            rc = GP_SRV_ELIMIT;
        if (active)
            *active = n_active;
        if (rc)
            return gp_db_end(db, rc);
    }
    sqlite3_bind_text(s, 1, out->id, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 2, out->created, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 3, spec_text, (int)spec_len, SQLITE_STATIC);
    sqlite3_bind_double(s, 4, columns->width);
    sqlite3_bind_double(s, 5, columns->height);
    sqlite3_bind_text(s, 6, columns->distribution, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 7, columns->joint, -1, SQLITE_STATIC);
    sqlite3_bind_int(s, 8, columns->level_band);
    sqlite3_bind_int64(s, 9, (sqlite3_int64)columns->seed);
    sqlite3_bind_double(s, 10, columns->expected);
    sqlite3_bind_text(s, 11, owner, -1, SQLITE_STATIC);
    if (sqlite3_step(s) == SQLITE_ROW)
        out->seq = sqlite3_column_int64(s, 0);
    else
        rc = gp_db_fail(db, "insert job");
    sqlite3_reset(s);
    return gp_db_end(db, rc);
}

int sq_get_job(gp_db *db, const char *id, const char *owner, gp_job *out)
{
    sqlite3_stmt *s = gp_db_stmt(db, ST_GET);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    gp_db_bind_owner(s, 2, owner);
    int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW)
        read_job(s, out);
    sqlite3_reset(s);
    if (rc == SQLITE_ROW)
        return 0;
    return rc == SQLITE_DONE ? GP_SRV_ENOTFOUND : gp_db_fail(db, "get job");
}

int sq_list_jobs(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                       size_t limit, gp_job *out, size_t *n, int *more)
{
    *n = 0;
    *more = 0;
    sqlite3_stmt *s = gp_db_stmt(db, ST_LIST);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_int64(s, 1, before > 0 ? before : INT64_MAX);
    sqlite3_bind_int(s, 2, (int)status_mask);
    sqlite3_bind_int64(s, 3, (sqlite3_int64)limit + 1); /* one more tells whether there is more */
    gp_db_bind_owner(s, 4, owner);
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
        if (*n == limit) {
            *more = 1;
            break;
        }
        read_job(s, &out[(*n)++]);
    }
    sqlite3_reset(s);
    return rc == SQLITE_ROW || rc == SQLITE_DONE ? 0 : gp_db_fail(db, "list jobs");
}

int sq_claim(gp_db *db, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
                   size_t *spec_len)
{
    *spec_text = NULL;
    *spec_len = 0;
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    int result;
    sqlite3_stmt *s = gp_db_write(db, ST_CLAIM, &result);
    if (!s)
        return result;
    sqlite3_bind_text(s, 1, now, -1, SQLITE_STATIC);
    int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW) {
        gp_db_copy_text(id, GP_JOB_ID_SIZE, s, 0);
        int len = sqlite3_column_bytes(s, 1);
        const void *text = sqlite3_column_blob(s, 1);
        *spec_text = malloc((size_t)len + 1);
        if (!*spec_text) {
            result = GP_ENOMEM;
        } else {
            memcpy(*spec_text, text, (size_t)len);
            (*spec_text)[len] = '\0';
            *spec_len = (size_t)len;
        }
        rc = sqlite3_step(s); /* RETURNING rows must be drained before the commit */
    } else if (rc == SQLITE_DONE) {
        result = GP_SRV_ENOTFOUND;
    }
    if (rc != SQLITE_DONE && rc != SQLITE_ROW)
        result = gp_db_fail(db, "claim");
    sqlite3_reset(s);
    int claimed = result == 0;
    if (claimed && queued)
        atomic_fetch_sub(queued, 1);
    result = gp_db_end(db, result);
    if (claimed && result && queued)
        atomic_fetch_add(queued, 1);
    if (result && result != GP_SRV_ENOTFOUND) {
        free(*spec_text);
        *spec_text = NULL;
    }
    return result;
}

int sq_progress(gp_db *db, const char *id, int percent, const char *message)
{
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    int rc;
    sqlite3_stmt *s = gp_db_write(db, ST_PROGRESS, &rc);
    if (!s)
        return rc;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_int(s, 2, percent);
    sqlite3_bind_text(s, 3, message, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 4, now, -1, SQLITE_STATIC);
    return gp_db_end(db, gp_db_run(db, s, "progress"));
}

/* Runs a one-row UPDATE `id` with (id, text, now) bindings in its own transaction;
 * GP_SRV_ESTATE when no row matched. */
static int update_running(gp_db *db, enum stmt_id which, const char *id, const char *a,
                          const char *b, const char *what)
{
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    int rc;
    sqlite3_stmt *s = gp_db_write(db, which, &rc);
    if (!s)
        return rc;
    int n = 1;
    sqlite3_bind_text(s, n++, id, -1, SQLITE_STATIC);
    if (a)
        sqlite3_bind_text(s, n++, a, -1, SQLITE_STATIC);
    if (b)
        sqlite3_bind_text(s, n++, b, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, n, now, -1, SQLITE_STATIC);
    return gp_db_end(db, gp_db_run_one(db, s, what));
}

int sq_fail(gp_db *db, const char *id, const char *code_name, const char *message)
{
    return update_running(db, ST_FAIL, id, code_name, message, "fail job");
}

int sq_requeue(gp_db *db, const char *id)
{
    return update_running(db, ST_REQUEUE, id, GP_REQUEUE_MESSAGE, NULL, "requeue job");
}

int sq_dismiss(gp_db *db, const char *id, const char *owner, gp_job_status *before,
                     int *deleted, gp_job *after)
{
    *deleted = 0;
    int result;
    sqlite3_stmt *s = gp_db_write(db, ST_STATUS, &result);
    if (!s)
        return result;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    gp_db_bind_owner(s, 2, owner);
    int rc = sqlite3_step(s);
    gp_job_status st = GP_JOB_FAILED;
    if (rc == SQLITE_ROW)
        gp_job_status_parse((const char *)sqlite3_column_text(s, 0), &st);
    sqlite3_reset(s);
    if (rc == SQLITE_DONE)
        result = GP_SRV_ENOTFOUND;
    else if (rc != SQLITE_ROW)
        result = gp_db_fail(db, "dismiss: read status");
    if (result == 0)
        sq_get_job(db, id, NULL, after);
    if (result == 0 && !gp_job_status_final(st)) {
        char now[GP_TIMESTAMP_SIZE];
        gp_timestamp_now(now);
        if (!(s = gp_db_stmt(db, ST_DISMISS))) {
            result = GP_SRV_EDB;
        } else {
            sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
            sqlite3_bind_text(s, 2, "dismissed by request", -1, SQLITE_STATIC);
            sqlite3_bind_text(s, 3, now, -1, SQLITE_STATIC);
            result = gp_db_run(db, s, "dismiss");
        }
        if (result == 0)
            sq_get_job(db, id, NULL, after);
    } else if (result == 0) {
        if (!(s = gp_db_stmt(db, ST_DELETE))) {
            result = GP_SRV_EDB;
        } else {
            sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
            result = gp_db_run(db, s, "delete");
        }
        *deleted = 1;
    }
    if (result == 0)
        *before = st;
    return gp_db_end(db, result);
}

int sq_count(gp_db *db, long counts[GP_JOB_NSTATUS])
{
    memset(counts, 0, GP_JOB_NSTATUS * sizeof *counts);
    sqlite3_stmt *s = gp_db_stmt(db, ST_COUNT);
    if (!s)
        return GP_SRV_EDB;
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
        gp_job_status st;
        if (gp_job_status_parse((const char *)sqlite3_column_text(s, 0), &st) == 0)
            counts[st] = (long)sqlite3_column_int64(s, 1);
    }
    sqlite3_reset(s);
    return rc == SQLITE_DONE ? 0 : gp_db_fail(db, "count jobs");
}