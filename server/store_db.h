/* store_db.h - inside the job store (store*.c only): a connection with its prepared
 * statements, and the helpers every query uses. Not for the rest of the service. */
#ifndef GRAINPACKD_STORE_DB_H
#define GRAINPACKD_STORE_DB_H

#include <sqlite3.h>

#include "store_ops.h"

enum stmt_id {
    ST_INSERT,
    ST_GET,
    ST_LIST,
    ST_CLAIM,
    ST_PROGRESS,
    ST_FINISH,
    ST_SECTION,
    ST_CHUNK,
    ST_BIN,
    ST_TIMING,
    ST_FAIL,
    ST_REQUEUE,
    ST_STATUS,
    ST_DISMISS,
    ST_DELETE,
    ST_OPEN_RESULT,
    ST_SUMMARY_SECTIONS,
    ST_FIND_SECTION,
    ST_READ_CHUNK,
    ST_TIMINGS,
    ST_COUNT,
    ST_ACTIVE,
    ST_COUNT_OF
};

struct gp_db {
    gp_store *store; /* first: store.c reads it (gp_db_head) */
    sqlite3 *conn;
    sqlite3_stmt *stmt[ST_COUNT_OF];
    sqlite3_stmt *begin, *commit, *rollback;
    int durable;
    int broken;     /* an I/O or permission error: closed when released, not reused */
    int generation; /* the store's generation when it was opened */
    gp_db *next_free;
};

/* The statement `id` of db, prepared on first use, reset and unbound; NULL (logged, as
 * gp_db_fail) when sqlite cannot prepare it. Owned by db. */
sqlite3_stmt *gp_db_stmt(gp_db *db, enum stmt_id id);

/* Logs db's last failure with `what` and returns its class: GP_SRV_EFULL,
 * GP_SRV_EUNWRITABLE or GP_SRV_EDB. A connection that met an I/O or permission error is
 * marked broken (closed when released), and the store's write state follows. */
int gp_db_fail(gp_db *db, const char *what);

/* Every write is one transaction made with these three:
 *
 *     int rc;
 *     sqlite3_stmt *s = gp_db_write(db, ST_X, &rc);
 *     if (!s)
 *         return rc;
 *     ...bind s...
 *     return gp_db_end(db, gp_db_run(db, s, "what it does"));
 *
 * gp_db_write: statement `id` ready to bind (as gp_db_stmt) with a BEGIN IMMEDIATE
 * transaction open; NULL with *rc a class of gp_db_fail, and no transaction open, when
 * either fails. Other statements may run in the transaction (gp_db_stmt, gp_db_run). */
sqlite3_stmt *gp_db_write(gp_db *db, enum stmt_id id, int *rc);

/* Steps s once and resets it: 0 (a row or done), or a class of gp_db_fail logged with
 * `what`. gp_db_run_one is for an UPDATE of one row: GP_SRV_ESTATE when it changed none
 * (the row is not in the state the WHERE asks for). */
int gp_db_run(gp_db *db, sqlite3_stmt *s, const char *what);
int gp_db_run_one(gp_db *db, sqlite3_stmt *s, const char *what);

/* Ends the transaction of gp_db_write: rc 0 commits (0, or the commit's failure class,
 * rolled back), any other rc rolls back. Returns the outcome. */
int gp_db_end(gp_db *db, int rc);

/* Writes the sections of a successful job's result (sections.h), chunk by chunk, inside
 * the caller's transaction. Returns 0, GP_ENOMEM or a class of gp_db_fail. */
int gp_db_write_sections(gp_db *db, const char *id, const gp_result *result);

/* Copies the text of column col (empty when NULL) into dst, truncated to size. */
void gp_db_copy_text(char *dst, size_t size, sqlite3_stmt *s, int col);

/* Binds owner to parameter i: the name, or NULL (the statement then matches any owner). */
void gp_db_bind_owner(sqlite3_stmt *s, int i, const char *owner);

/* The sqlite backend's functions behind gp_store_sqlite_ops (store_sqlite.c), each with
 * the contract of its gp_store_ namesake in store.h or of its entry in store_ops.h. */
int sq_recover(gp_db *db, int max_attempts, int *requeued, int *given_up);
int sq_insert_job(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                  size_t spec_len, const gp_job_columns *columns, gp_job *out, long *active);
int sq_get_job(gp_db *db, const char *id, const char *owner, gp_job *out);
int sq_list_jobs(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                 size_t limit, gp_job *out, size_t *n, int *more);
int sq_claim(gp_db *db, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
             size_t *spec_len);
int sq_progress(gp_db *db, const char *id, int percent, const char *message);
int sq_finish(gp_db *db, const char *id, const gp_outcome *outcome);
int sq_fail(gp_db *db, const char *id, const char *code_name, const char *message);
int sq_requeue(gp_db *db, const char *id);
int sq_dismiss(gp_db *db, const char *id, const char *owner, gp_job_status *before,
               int *deleted, gp_job *after);
int sq_open_result(gp_db *db, const char *id, const char *owner, gp_stored_result *out);
int sq_find_section(gp_db *db, int64_t key, const char *tag, int64_t *section, uint64_t *bytes);
int sq_read_chunk(gp_db *db, int64_t section, int64_t chunk, void *dst, size_t *len);
int sq_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap);
int sq_count(gp_db *db, long counts[GP_JOB_NSTATUS]);

#endif
