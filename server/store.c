/* store.c - the sqlite3 job store: connections, migrations, and every query the service
 * makes. Each query is a statement prepared once per connection. */
#include "store.h"

#include <errno.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include "log.h"
#include "store_schema.h"

/* How long a writer waits for another connection's transaction before giving up. Writes
 * are short (one job row, or one result), so this is only reached when the disk stalls. */
#define BUSY_TIMEOUT_MS 30000

/* Bytes the WAL file is cut back to after a checkpoint (see PRAGMA journal_size_limit). */
#define WAL_SIZE_LIMIT (64 << 20)

/* Bytes per disk in the results blob: x, y, r, R as float64. */
#define DISK_RECORD 32

enum stmt_id {
    ST_INSERT,
    ST_GET,
    ST_LIST,
    ST_CLAIM,
    ST_PROGRESS,
    ST_FINISH,
    ST_RESULT,
    ST_BIN,
    ST_TIMING,
    ST_FAIL,
    ST_REQUEUE,
    ST_STATUS,
    ST_DISMISS,
    ST_DELETE,
    ST_LOAD,
    ST_TIMINGS,
    ST_COUNT,
    ST_ACTIVE,
    ST_COUNT_OF
};

#define JOB_COLUMNS "seq, id, status, created, started, finished, updated, progress, message"

static const char *const stmt_sql[ST_COUNT_OF] = {
    [ST_INSERT] = "INSERT INTO jobs (id, status, created, updated, message, spec, domain_width,"
                  " domain_height, distribution, joint, level_band, seed, expected_disks, owner)"
                  " VALUES (?1, 'accepted', ?2, ?2, 'queued', ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)"
                  " RETURNING seq",
    /* an owner of NULL sees every job */
    [ST_GET] = "SELECT " JOB_COLUMNS " FROM jobs WHERE id = ?1 AND (?2 IS NULL OR owner = ?2)",
    /* status_mask bit i selects status i, in gp_job_status order */
    [ST_LIST] = "SELECT " JOB_COLUMNS " FROM jobs WHERE seq < ?1 AND (?2 = 0 OR"
                " (?2 >> (CASE status WHEN 'accepted' THEN 0 WHEN 'running' THEN 1"
                " WHEN 'successful' THEN 2 WHEN 'failed' THEN 3 ELSE 4 END)) & 1)"
                " AND (?4 IS NULL OR owner = ?4)"
                " ORDER BY seq DESC LIMIT ?3",
    [ST_CLAIM] = "UPDATE jobs SET status = 'running', started = ?1, updated = ?1, progress = 0,"
                 " message = 'running', claims = claims + 1"
                 " WHERE seq = (SELECT seq FROM jobs WHERE status = 'accepted' ORDER BY seq LIMIT 1)"
                 " RETURNING id, spec",
    [ST_PROGRESS] = "UPDATE jobs SET progress = ?2, message = ?3, updated = ?4"
                    " WHERE id = ?1 AND status = 'running'",
    [ST_FINISH] = "UPDATE jobs SET status = 'successful', progress = 100, message = ?2,"
                  " finished = ?3, updated = ?3, count = ?4, packing_density = ?5,"
                  " grain_fraction = ?6, r_min = ?7, r_max = ?8, r_mean = ?9, chi2 = ?10,"
                  " dof = ?11, p_value = ?12, max_abs_z = ?13, initial_disks = ?14,"
                  " front_attempts = ?15, front_closures = ?16, front_frozen = ?17,"
                  " front_capped = ?18, max_level = ?19"
                  " WHERE id = ?1 AND status = 'running'",
    [ST_RESULT] = "INSERT OR REPLACE INTO results (job_id, count, disks) VALUES (?1, ?2, ?3)",
    [ST_BIN] = "INSERT OR REPLACE INTO bin_stats (job_id, bin, min, max, target, achieved, count, z)"
               " VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
    [ST_TIMING] = "INSERT OR REPLACE INTO stage_timings (job_id, position, stage, seconds)"
                  " VALUES (?1, ?2, ?3, ?4)",
    [ST_FAIL] = "UPDATE jobs SET status = 'failed', error = ?2, message = ?3, finished = ?4,"
                " updated = ?4 WHERE id = ?1 AND status = 'running'",
    [ST_REQUEUE] = "UPDATE jobs SET status = 'accepted', started = NULL, progress = 0,"
                   " message = ?2, updated = ?3 WHERE id = ?1 AND status = 'running'",
    [ST_STATUS] = "SELECT status FROM jobs WHERE id = ?1 AND (?2 IS NULL OR owner = ?2)",
    [ST_DISMISS] = "UPDATE jobs SET status = 'dismissed', message = ?2, finished = ?3, updated = ?3"
                   " WHERE id = ?1 AND status IN ('accepted', 'running')",
    [ST_DELETE] = "DELETE FROM jobs WHERE id = ?1",
    [ST_LOAD] = "SELECT j.spec, r.count, r.disks, j.initial_disks, j.front_attempts,"
                " j.front_closures, j.front_frozen, j.front_capped, j.max_level"
                " FROM jobs j JOIN results r ON r.job_id = j.id"
                " WHERE j.id = ?1 AND j.status = 'successful' AND (?2 IS NULL OR j.owner = ?2)",
    [ST_TIMINGS] = "SELECT stage, seconds FROM stage_timings WHERE job_id = ?1 ORDER BY position",
    [ST_COUNT] = "SELECT status, count(*) FROM jobs GROUP BY status",
    [ST_ACTIVE] = "SELECT count(*) FROM jobs WHERE owner = ?1 AND status IN ('accepted', 'running')",
};

struct gp_db {
    gp_store *store;
    sqlite3 *conn;
    sqlite3_stmt *stmt[ST_COUNT_OF];
    sqlite3_stmt *begin, *commit, *rollback;
    int durable;
    int broken;     /* an I/O or permission error: closed when released, not reused */
    int generation; /* the store's generation when it was opened */
    gp_db *next_free;
};

struct gp_store {
    char *path;
    pthread_mutex_t lock; /* guards free_list and all only */
    gp_db *free_list[2];  /* idle connections, by durability */
    gp_db **all;          /* every connection open, closed by gp_store_close */
    size_t nall, capall;
    atomic_int write_state; /* 0, GP_SRV_EFULL or GP_SRV_EUNWRITABLE: the last write's fate */
    /* Moves on when writes start failing and when they work again. A connection opened in
     * another generation is not reused: one opened while the files could not be written
     * may stay read-only for good (sqlite opens the WAL read-only and says nothing), and
     * one opened before may hold what the failure left behind. */
    atomic_int generation;
};

/* Records how a write went: a change from working to failing or back starts a new
 * generation of connections. */
static void set_write_state(gp_store *store, int state)
{
    if (!store)
        return;
    int before = atomic_exchange(&store->write_state, state);
    if ((before == 0) != (state == 0))
        atomic_fetch_add(&store->generation, 1);
}

static const char *const status_names[GP_JOB_NSTATUS] = {"accepted", "running", "successful",
                                                          "failed", "dismissed"};

const char *gp_job_status_name(gp_job_status status)
{
    return status < GP_JOB_NSTATUS ? status_names[status] : "unknown";
}

int gp_job_status_parse(const char *name, gp_job_status *out)
{
    for (int i = 0; i < GP_JOB_NSTATUS; i++) {
        if (strcmp(name, status_names[i]) == 0) {
            *out = (gp_job_status)i;
            return 0;
        }
    }
    return GP_EINVAL;
}

/* What the last failure of db's connection means for the caller: no space (sqlite maps
 * ENOSPC to SQLITE_FULL; a quota or the file size limit come as write errors with their
 * errno, when sqlite still has it), files that refuse writes (read-only, immutable, or
 * failing: sqlite's errno is not reliable enough to tell these apart), or anything else. */
static int classify(gp_db *db)
{
    int ext = sqlite3_extended_errcode(db->conn), primary = ext & 0xff;
    int sys = sqlite3_system_errno(db->conn);
    if (primary == SQLITE_FULL || (primary == SQLITE_IOERR && (sys == ENOSPC || sys == EDQUOT ||
                                                                sys == EFBIG)))
        return GP_SRV_EFULL;
    if (primary == SQLITE_READONLY || ext == SQLITE_IOERR_WRITE || ext == SQLITE_IOERR_FSYNC ||
        ext == SQLITE_IOERR_DIR_FSYNC || ext == SQLITE_IOERR_TRUNCATE ||
        ext == SQLITE_IOERR_SHMSIZE || ext == SQLITE_IOERR_SHMOPEN)
        return GP_SRV_EUNWRITABLE;
    return GP_SRV_EDB;
}

/* Logs a failure and returns its class (see classify). A connection that met an I/O or
 * permission error is not trusted again: it is closed when released. */
static int db_fail(gp_db *db, const char *what)
{
    int primary = sqlite3_extended_errcode(db->conn) & 0xff;
    int sys = sqlite3_system_errno(db->conn);
    int rc = classify(db);
    gp_log("store: %s: %s%s%s", what, sqlite3_errmsg(db->conn), sys ? ": " : "",
           sys ? strerror(sys) : "");
    if (primary == SQLITE_IOERR || primary == SQLITE_READONLY || primary == SQLITE_CORRUPT ||
        primary == SQLITE_CANTOPEN)
        db->broken = 1;
    if (rc != GP_SRV_EDB)
        set_write_state(db->store, rc);
    return rc;
}

static void db_close(gp_db *db)
{
    if (!db)
        return;
    for (int i = 0; i < ST_COUNT_OF; i++)
        sqlite3_finalize(db->stmt[i]);
    sqlite3_finalize(db->begin);
    sqlite3_finalize(db->commit);
    sqlite3_finalize(db->rollback);
    sqlite3_close(db->conn);
    free(db);
}

/* Opens a connection with the pragmas every connection needs. */
static gp_db *db_open(const char *path, int durable, char *why, size_t why_size)
{
    gp_db *db = calloc(1, sizeof *db);
    if (!db) {
        snprintf(why, why_size, "out of memory");
        return NULL;
    }
    db->durable = durable;
    int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX;
    if (sqlite3_open_v2(path, &db->conn, flags, NULL) != SQLITE_OK) {
        snprintf(why, why_size, "cannot open %s: %s", path,
                 db->conn ? sqlite3_errmsg(db->conn) : "out of memory");
        db_close(db);
        return NULL;
    }
    sqlite3_busy_timeout(db->conn, BUSY_TIMEOUT_MS);
    /* journal_size_limit: a large result (tens of MB) grows the WAL; once checkpointed,
     * the file is cut back instead of staying that large */
    char pragmas[200];
    snprintf(pragmas, sizeof pragmas,
             "PRAGMA journal_mode = WAL; PRAGMA synchronous = %s; PRAGMA foreign_keys = ON;"
             " PRAGMA journal_size_limit = %d;",
             durable ? "FULL" : "NORMAL", WAL_SIZE_LIMIT);
    char *msg = NULL;
    if (sqlite3_exec(db->conn, pragmas, NULL, NULL, &msg) != SQLITE_OK ||
        sqlite3_prepare_v3(db->conn, "BEGIN IMMEDIATE", -1, SQLITE_PREPARE_PERSISTENT, &db->begin,
                           NULL) != SQLITE_OK ||
        sqlite3_prepare_v3(db->conn, "COMMIT", -1, SQLITE_PREPARE_PERSISTENT, &db->commit, NULL) !=
            SQLITE_OK ||
        sqlite3_prepare_v3(db->conn, "ROLLBACK", -1, SQLITE_PREPARE_PERSISTENT, &db->rollback,
                           NULL) != SQLITE_OK) {
        snprintf(why, why_size, "cannot set up %s: %s", path, msg ? msg : sqlite3_errmsg(db->conn));
        sqlite3_free(msg);
        db_close(db);
        return NULL;
    }
    return db;
}

/* The statement `id`, prepared on first use and reset for a new run. */
static sqlite3_stmt *stmt(gp_db *db, enum stmt_id id)
{
    if (!db->stmt[id] && sqlite3_prepare_v3(db->conn, stmt_sql[id], -1, SQLITE_PREPARE_PERSISTENT,
                                            &db->stmt[id], NULL) != SQLITE_OK) {
        db_fail(db, "prepare");
        return NULL;
    }
    sqlite3_reset(db->stmt[id]);
    sqlite3_clear_bindings(db->stmt[id]);
    return db->stmt[id];
}

static int step_simple(sqlite3_stmt *s)
{
    int rc = sqlite3_step(s);
    sqlite3_reset(s);
    return rc == SQLITE_DONE || rc == SQLITE_ROW ? 0 : GP_SRV_EDB;
}

static int begin(gp_db *db)
{
    return step_simple(db->begin) ? db_fail(db, "begin immediate") : 0;
}

static int commit(gp_db *db)
{
    if (step_simple(db->commit) == 0) {
        set_write_state(db->store, 0);
        return 0;
    }
    int rc = db_fail(db, "commit");
    step_simple(db->rollback);
    return rc;
}

static void rollback(gp_db *db)
{
    if (!sqlite3_get_autocommit(db->conn))
        step_simple(db->rollback);
}

static int exec_sql(sqlite3 *conn, const char *sql, char *why, size_t why_size)
{
    char *msg = NULL;
    if (sqlite3_exec(conn, sql, NULL, NULL, &msg) == SQLITE_OK)
        return 0;
    snprintf(why, why_size, "%s", msg ? msg : sqlite3_errmsg(conn));
    sqlite3_free(msg);
    return GP_SRV_EDB;
}

/* Brings the schema to GP_STORE_SCHEMA_VERSION, one migration per transaction. */
static int migrate(gp_db *db, char *why, size_t why_size)
{
    for (;;) {
        if (exec_sql(db->conn, "BEGIN IMMEDIATE", why, why_size))
            return GP_SRV_EDB;
        sqlite3_stmt *s;
        int version = -1;
        if (sqlite3_prepare_v2(db->conn, "PRAGMA user_version", -1, &s, NULL) == SQLITE_OK) {
            if (sqlite3_step(s) == SQLITE_ROW)
                version = sqlite3_column_int(s, 0);
            sqlite3_finalize(s);
        }
        if (version < 0 || (size_t)version > gp_store_migration_count) {
            snprintf(why, why_size, "schema version %d is not one this build knows (0..%zu)",
                     version, gp_store_migration_count);
            char ignored[8];
            exec_sql(db->conn, "ROLLBACK", ignored, sizeof ignored);
            return GP_SRV_EDB;
        }
        if ((size_t)version == gp_store_migration_count)
            return exec_sql(db->conn, "COMMIT", why, why_size);
        char set_version[48];
        snprintf(set_version, sizeof set_version, "PRAGMA user_version = %d", version + 1);
        if (exec_sql(db->conn, gp_store_migrations[version], why, why_size) ||
            exec_sql(db->conn, set_version, why, why_size) ||
            exec_sql(db->conn, "COMMIT", why, why_size)) {
            char ignored[8];
            exec_sql(db->conn, "ROLLBACK", ignored, sizeof ignored);
            return GP_SRV_EDB;
        }
        gp_log("store: schema migrated to version %d", version + 1);
    }
}

static int requeue_running(gp_db *db, int *requeued, char *why, size_t why_size)
{
    char now[GP_TIMESTAMP_SIZE], sql[320];
    gp_timestamp_now(now);
    snprintf(sql, sizeof sql,
             "UPDATE jobs SET status = 'accepted', started = NULL, progress = 0,"
             " message = 'queued again: the daemon stopped while it ran', updated = '%s'"
             " WHERE status = 'running'",
             now);
    if (exec_sql(db->conn, "BEGIN IMMEDIATE", why, why_size) ||
        exec_sql(db->conn, sql, why, why_size))
        return GP_SRV_EDB;
    int n = sqlite3_changes(db->conn);
    if (exec_sql(db->conn, "COMMIT", why, why_size))
        return GP_SRV_EDB;
    if (requeued)
        *requeued = n;
    return 0;
}

/* Adds db to the list of connections closed with the store. */
static int remember(gp_store *store, gp_db *db)
{
    if (store->nall == store->capall) {
        size_t cap = store->capall ? store->capall * 2 : 16;
        gp_db **grown = realloc(store->all, cap * sizeof *grown);
        if (!grown)
            return GP_ENOMEM;
        store->all = grown;
        store->capall = cap;
    }
    store->all[store->nall++] = db;
    return 0;
}

int gp_store_open(const char *path, gp_store **out, int *requeued, char *why, size_t why_size)
{
    *out = NULL;
    gp_store *store = calloc(1, sizeof *store);
    if (!store || !(store->path = strdup(path))) {
        free(store);
        snprintf(why, why_size, "out of memory");
        return GP_ENOMEM;
    }
    pthread_mutex_init(&store->lock, NULL);
    gp_db *db = db_open(path, 1, why, why_size);
    if (db)
        db->store = store;
    int rc = db ? migrate(db, why, why_size) : GP_SRV_EDB;
    if (rc == 0)
        rc = requeue_running(db, requeued, why, why_size);
    if (rc == 0)
        rc = remember(store, db);
    if (rc) {
        db_close(db);
        gp_store_close(store);
        return rc;
    }
    db->next_free = NULL;
    store->free_list[1] = db;
    *out = store;
    return 0;
}

void gp_store_close(gp_store *store)
{
    if (!store)
        return;
    for (size_t i = 0; i < store->nall; i++)
        db_close(store->all[i]);
    free(store->all);
    pthread_mutex_destroy(&store->lock);
    free(store->path);
    free(store);
}

gp_db *gp_store_acquire(gp_store *store, int durable)
{
    durable = durable ? 1 : 0;
    pthread_mutex_lock(&store->lock);
    gp_db *db = store->free_list[durable];
    if (db)
        store->free_list[durable] = db->next_free;
    pthread_mutex_unlock(&store->lock);
    if (db && gp_store_broken(db)) { /* from another generation: a fresh one instead */
        db->broken = 1;
        gp_store_release(store, db);
        db = NULL;
    }
    if (db)
        return db;
    char why[256];
    db = db_open(store->path, durable, why, sizeof why);
    if (!db) {
        gp_log("store: %s", why);
        return NULL;
    }
    db->store = store;
    db->generation = atomic_load(&store->generation);
    pthread_mutex_lock(&store->lock);
    int rc = remember(store, db);
    pthread_mutex_unlock(&store->lock);
    if (rc) {
        db_close(db);
        return NULL;
    }
    return db;
}

void gp_store_release(gp_store *store, gp_db *db)
{
    if (!db)
        return;
    rollback(db); /* a caller that bailed out mid-transaction must not hold the write lock */
    if (gp_store_broken(db)) {
        pthread_mutex_lock(&store->lock);
        for (size_t i = 0; i < store->nall; i++) {
            if (store->all[i] == db) {
                store->all[i] = store->all[--store->nall];
                break;
            }
        }
        pthread_mutex_unlock(&store->lock);
        db_close(db);
        return;
    }
    pthread_mutex_lock(&store->lock);
    db->next_free = store->free_list[db->durable];
    store->free_list[db->durable] = db;
    pthread_mutex_unlock(&store->lock);
}

/* A random (version 4) UUID: job ids must not be guessable from one another. */
static void new_job_id(char out[GP_JOB_ID_SIZE])
{
    unsigned char b[16];
    size_t got = 0;
    while (got < sizeof b) {
        ssize_t n = getrandom(b + got, sizeof b - got, 0);
        if (n > 0)
            got += (size_t)n;
    }
    b[6] = (unsigned char)((b[6] & 0x0f) | 0x40);
    b[8] = (unsigned char)((b[8] & 0x3f) | 0x80);
    snprintf(out, GP_JOB_ID_SIZE,
             "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", b[0], b[1],
             b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12], b[13], b[14],
             b[15]);
}

static void copy_text(char *dst, size_t size, sqlite3_stmt *s, int col)
{
    const unsigned char *t = sqlite3_column_text(s, col);
    snprintf(dst, size, "%s", t ? (const char *)t : "");
}

/* Reads a row of JOB_COLUMNS. */
static void read_job(sqlite3_stmt *s, gp_job *job)
{
    memset(job, 0, sizeof *job);
    job->seq = sqlite3_column_int64(s, 0);
    copy_text(job->id, sizeof job->id, s, 1);
    const unsigned char *status = sqlite3_column_text(s, 2);
    gp_job_status st = GP_JOB_FAILED;
    if (status)
        gp_job_status_parse((const char *)status, &st);
    job->status = st;
    copy_text(job->created, sizeof job->created, s, 3);
    copy_text(job->started, sizeof job->started, s, 4);
    copy_text(job->finished, sizeof job->finished, s, 5);
    copy_text(job->updated, sizeof job->updated, s, 6);
    job->progress = sqlite3_column_int(s, 7);
    copy_text(job->message, sizeof job->message, s, 8);
}

/* The owner's accepted and running jobs; inside the inserting transaction. */
static int count_active(gp_db *db, const char *owner, long *active)
{
    sqlite3_stmt *s = stmt(db, ST_ACTIVE);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, owner, -1, SQLITE_STATIC);
    int rc = sqlite3_step(s);
    *active = rc == SQLITE_ROW ? (long)sqlite3_column_int64(s, 0) : 0;
    sqlite3_reset(s);
    return rc == SQLITE_ROW ? 0 : db_fail(db, "count active jobs");
}

int gp_store_insert_job(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                        size_t spec_len, const gp_spec *spec, gp_job *out, long *active)
{
    long n_active = 0;
    if (active)
        *active = 0;
    memset(out, 0, sizeof *out);
    new_job_id(out->id);
    gp_timestamp_now(out->created);
    snprintf(out->updated, sizeof out->updated, "%s", out->created);
    snprintf(out->message, sizeof out->message, "queued");
    out->status = GP_JOB_ACCEPTED;
    int rc = begin(db);
    if (rc)
        return rc;
    /* the count and the insert in one transaction: two submissions of one key cannot
     * both see room for one more */
    if (max_active > 0) {
        if ((rc = count_active(db, owner, &n_active)) == 0 && n_active >= (long)max_active)
            rc = GP_SRV_ELIMIT;
        if (active)
            *active = n_active;
        if (rc) {
            rollback(db);
            return rc;
        }
    }
    sqlite3_stmt *s = stmt(db, ST_INSERT);
    if (!s) {
        rollback(db);
        return GP_SRV_EDB;
    }
    sqlite3_bind_text(s, 1, out->id, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 2, out->created, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 3, spec_text, (int)spec_len, SQLITE_STATIC);
    sqlite3_bind_double(s, 4, spec->domain.width);
    sqlite3_bind_double(s, 5, spec->domain.height);
    sqlite3_bind_text(s, 6, gp_dist_kind_name(spec->dist.kind), -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 7, gp_joint_law_name(spec->joint.law), -1, SQLITE_STATIC);
    sqlite3_bind_int(s, 8, (int)spec->level_band);
    sqlite3_bind_int64(s, 9, (sqlite3_int64)spec->seed);
    sqlite3_bind_double(s, 10, spec->expected_disks);
    sqlite3_bind_text(s, 11, owner, -1, SQLITE_STATIC);
    if (sqlite3_step(s) != SQLITE_ROW) {
        rc = db_fail(db, "insert job");
        sqlite3_reset(s);
        rollback(db);
        return rc;
    }
    out->seq = sqlite3_column_int64(s, 0);
    sqlite3_reset(s);
    return commit(db);
}

/* Binds owner to parameter i: NULL (every owner) or the name. */
static void bind_owner(sqlite3_stmt *s, int i, const char *owner)
{
    if (owner)
        sqlite3_bind_text(s, i, owner, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(s, i);
}

int gp_store_get_job(gp_db *db, const char *id, const char *owner, gp_job *out)
{
    sqlite3_stmt *s = stmt(db, ST_GET);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    bind_owner(s, 2, owner);
    int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW)
        read_job(s, out);
    sqlite3_reset(s);
    if (rc == SQLITE_ROW)
        return 0;
    return rc == SQLITE_DONE ? GP_SRV_ENOTFOUND : db_fail(db, "get job");
}

int gp_store_list_jobs(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                       size_t limit, gp_job *out, size_t *n, int *more)
{
    *n = 0;
    *more = 0;
    sqlite3_stmt *s = stmt(db, ST_LIST);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_int64(s, 1, before > 0 ? before : INT64_MAX);
    sqlite3_bind_int(s, 2, (int)status_mask);
    sqlite3_bind_int64(s, 3, (sqlite3_int64)limit + 1); /* one more tells whether there is more */
    bind_owner(s, 4, owner);
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
        if (*n == limit) {
            *more = 1;
            break;
        }
        read_job(s, &out[(*n)++]);
    }
    sqlite3_reset(s);
    return rc == SQLITE_ROW || rc == SQLITE_DONE ? 0 : db_fail(db, "list jobs");
}

int gp_store_claim(gp_db *db, char id[GP_JOB_ID_SIZE], char **spec_text, size_t *spec_len)
{
    *spec_text = NULL;
    *spec_len = 0;
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    sqlite3_stmt *s = stmt(db, ST_CLAIM);
    if (!s)
        return GP_SRV_EDB;
    int began = begin(db);
    if (began)
        return began;
    sqlite3_bind_text(s, 1, now, -1, SQLITE_STATIC);
    int rc = sqlite3_step(s), result = 0;
    if (rc == SQLITE_ROW) {
        copy_text(id, GP_JOB_ID_SIZE, s, 0);
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
        result = db_fail(db, "claim");
    sqlite3_reset(s);
    if (result == 0) {
        result = commit(db);
    } else {
        rollback(db);
    }
    if (result && result != GP_SRV_ENOTFOUND) {
        free(*spec_text);
        *spec_text = NULL;
    }
    return result;
}

int gp_store_progress(gp_db *db, const char *id, int percent, const char *message)
{
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    sqlite3_stmt *s = stmt(db, ST_PROGRESS);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_int(s, 2, percent);
    sqlite3_bind_text(s, 3, message, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 4, now, -1, SQLITE_STATIC);
    int rc = begin(db);
    if (rc)
        return rc;
    if (step_simple(s)) {
        rc = db_fail(db, "progress");
        rollback(db);
        return rc;
    }
    return commit(db);
}

/* The result rows of a successful job; called inside the finishing transaction. */
static int write_result_rows(gp_db *db, const char *id, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    const gp_pack_stats *st = &result->stats;
    size_t bytes = p->count * DISK_RECORD;
    unsigned char *blob = malloc(bytes ? bytes : 1);
    if (!blob)
        return GP_ENOMEM;
    for (size_t i = 0; i < p->count; i++) {
        double rec[4] = {p->disks[i].x, p->disks[i].y, p->disks[i].r, p->disks[i].R};
        memcpy(blob + i * DISK_RECORD, rec, DISK_RECORD); /* little-endian on our targets */
    }
    sqlite3_stmt *s = stmt(db, ST_RESULT);
    int rc = s ? 0 : GP_SRV_EDB;
    if (s) {
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_int64(s, 2, (sqlite3_int64)p->count);
        sqlite3_bind_blob64(s, 3, blob, bytes, SQLITE_STATIC);
        if (step_simple(s))
            rc = db_fail(db, "insert result");
    }
    free(blob);
    for (size_t i = 0; rc == 0 && i < st->nbins; i++) {
        const gp_bin_stat *b = &st->bins[i];
        if (!(s = stmt(db, ST_BIN)))
            return GP_SRV_EDB;
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_int64(s, 2, (sqlite3_int64)i);
        sqlite3_bind_double(s, 3, b->min);
        sqlite3_bind_double(s, 4, b->max);
        sqlite3_bind_double(s, 5, b->target);
        sqlite3_bind_double(s, 6, b->achieved);
        sqlite3_bind_int64(s, 7, (sqlite3_int64)b->count);
        sqlite3_bind_double(s, 8, b->z);
        if (step_simple(s))
            rc = db_fail(db, "insert bin statistics");
    }
    for (int i = 0; rc == 0 && i < result->ntimings; i++) {
        if (!(s = stmt(db, ST_TIMING)))
            return GP_SRV_EDB;
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_int(s, 2, i);
        sqlite3_bind_text(s, 3, result->timings[i].stage, -1, SQLITE_STATIC);
        sqlite3_bind_double(s, 4, result->timings[i].seconds);
        if (step_simple(s))
            rc = db_fail(db, "insert stage timing");
    }
    return rc;
}

int gp_store_finish(gp_db *db, const char *id, const gp_result *result)
{
    const gp_pack_stats *st = &result->stats;
    const gp_packing *p = &result->packing;
    char now[GP_TIMESTAMP_SIZE], message[128];
    gp_timestamp_now(now);
    snprintf(message, sizeof message, "%zu disks, packing density %.4f", st->count,
             st->packing_density);
    sqlite3_stmt *s = stmt(db, ST_FINISH);
    if (!s)
        return GP_SRV_EDB;
    int began = begin(db);
    if (began)
        return began;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 2, message, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 3, now, -1, SQLITE_STATIC);
    sqlite3_bind_int64(s, 4, (sqlite3_int64)st->count);
    sqlite3_bind_double(s, 5, st->packing_density);
    sqlite3_bind_double(s, 6, st->grain_fraction);
    sqlite3_bind_double(s, 7, st->r_min);
    sqlite3_bind_double(s, 8, st->r_max);
    sqlite3_bind_double(s, 9, st->r_mean);
    sqlite3_bind_double(s, 10, st->chi2);
    sqlite3_bind_int(s, 11, st->dof);
    sqlite3_bind_double(s, 12, st->p_value);
    sqlite3_bind_double(s, 13, st->max_abs_z);
    sqlite3_bind_int64(s, 14, (sqlite3_int64)p->initial_front);
    sqlite3_bind_int64(s, 15, (sqlite3_int64)p->attempts);
    sqlite3_bind_int64(s, 16, (sqlite3_int64)p->closures);
    sqlite3_bind_int64(s, 17, (sqlite3_int64)p->frozen);
    sqlite3_bind_int64(s, 18, (sqlite3_int64)p->capped);
    sqlite3_bind_int64(s, 19, (sqlite3_int64)p->max_level);
    int rc = step_simple(s) ? db_fail(db, "finish job") : 0;
    if (rc == 0 && sqlite3_changes(db->conn) == 0)
        rc = GP_SRV_ESTATE; /* dismissed while it ran: keep nothing */
    if (rc == 0)
        rc = write_result_rows(db, id, result);
    if (rc) {
        rollback(db);
        return rc;
    }
    return commit(db);
}

/* Runs a one-row UPDATE `id` with (id, text, now) bindings in its own transaction;
 * GP_SRV_ESTATE when no row matched. */
static int update_running(gp_db *db, enum stmt_id which, const char *id, const char *a,
                          const char *b, const char *what)
{
    char now[GP_TIMESTAMP_SIZE];
    gp_timestamp_now(now);
    sqlite3_stmt *s = stmt(db, which);
    if (!s)
        return GP_SRV_EDB;
    int began = begin(db);
    if (began)
        return began;
    int n = 1;
    sqlite3_bind_text(s, n++, id, -1, SQLITE_STATIC);
    if (a)
        sqlite3_bind_text(s, n++, a, -1, SQLITE_STATIC);
    if (b)
        sqlite3_bind_text(s, n++, b, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, n, now, -1, SQLITE_STATIC);
    int rc = step_simple(s) ? db_fail(db, what) : 0;
    if (rc == 0 && sqlite3_changes(db->conn) == 0)
        rc = GP_SRV_ESTATE;
    if (rc) {
        rollback(db);
        return rc;
    }
    return commit(db);
}

int gp_store_fail(gp_db *db, const char *id, const char *code_name, const char *message)
{
    return update_running(db, ST_FAIL, id, code_name, message, "fail job");
}

int gp_store_requeue(gp_db *db, const char *id)
{
    return update_running(db, ST_REQUEUE, id, "queued again: the daemon stopped while it ran",
                          NULL, "requeue job");
}

int gp_store_dismiss(gp_db *db, const char *id, const char *owner, gp_job_status *before,
                     int *deleted, gp_job *after)
{
    *deleted = 0;
    sqlite3_stmt *s = stmt(db, ST_STATUS);
    if (!s)
        return GP_SRV_EDB;
    int began = begin(db);
    if (began)
        return began;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    bind_owner(s, 2, owner);
    int rc = sqlite3_step(s), result = 0;
    gp_job_status st = GP_JOB_FAILED;
    if (rc == SQLITE_ROW)
        gp_job_status_parse((const char *)sqlite3_column_text(s, 0), &st);
    sqlite3_reset(s);
    if (rc == SQLITE_DONE)
        result = GP_SRV_ENOTFOUND;
    else if (rc != SQLITE_ROW)
        result = db_fail(db, "dismiss: read status");
    if (result == 0)
        gp_store_get_job(db, id, NULL, after);
    if (result == 0 && !gp_job_status_final(st)) {
        char now[GP_TIMESTAMP_SIZE];
        gp_timestamp_now(now);
        if (!(s = stmt(db, ST_DISMISS))) {
            result = GP_SRV_EDB;
        } else {
            sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
            sqlite3_bind_text(s, 2, "dismissed by request", -1, SQLITE_STATIC);
            sqlite3_bind_text(s, 3, now, -1, SQLITE_STATIC);
            if (step_simple(s))
                result = db_fail(db, "dismiss");
        }
        if (result == 0)
            gp_store_get_job(db, id, NULL, after);
    } else if (result == 0) {
        if (!(s = stmt(db, ST_DELETE))) {
            result = GP_SRV_EDB;
        } else {
            sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
            if (step_simple(s))
                result = db_fail(db, "delete");
        }
        *deleted = 1;
    }
    if (result) {
        rollback(db);
        return result;
    }
    *before = st;
    return commit(db);
}

int gp_store_load_result(gp_db *db, const char *id, const char *owner, char **spec_text,
                         size_t *spec_len, gp_packing *packing)
{
    *spec_text = NULL;
    memset(packing, 0, sizeof *packing);
    sqlite3_stmt *s = stmt(db, ST_LOAD);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    bind_owner(s, 2, owner);
    int rc = sqlite3_step(s);
    if (rc != SQLITE_ROW) {
        sqlite3_reset(s);
        return rc == SQLITE_DONE ? GP_SRV_ENOTFOUND : db_fail(db, "load result");
    }
    int result = 0;
    size_t len = (size_t)sqlite3_column_bytes(s, 0);
    const void *text = sqlite3_column_blob(s, 0);
    size_t count = (size_t)sqlite3_column_int64(s, 1);
    size_t bytes = (size_t)sqlite3_column_bytes(s, 2);
    const unsigned char *blob = sqlite3_column_blob(s, 2);
    if (bytes != count * DISK_RECORD) {
        gp_log("store: job %s: result blob of %zu bytes for %zu disks", id, bytes, count);
        result = GP_SRV_EDB;
    } else if (!(*spec_text = malloc(len + 1)) ||
               !(packing->disks = malloc((count ? count : 1) * sizeof *packing->disks))) {
        result = GP_ENOMEM;
    } else {
        memcpy(*spec_text, text, len);
        (*spec_text)[len] = '\0';
        *spec_len = len;
        for (size_t i = 0; i < count; i++) {
            double rec[4];
            memcpy(rec, blob + i * DISK_RECORD, DISK_RECORD);
            packing->disks[i] = (gp_disk){rec[0], rec[1], rec[2], rec[3]};
            packing->fill_area += 3.14159265358979323846 * rec[3] * rec[3];
        }
        packing->count = count;
        packing->initial_front = (size_t)sqlite3_column_int64(s, 3);
        packing->attempts = (uint64_t)sqlite3_column_int64(s, 4);
        packing->closures = (uint64_t)sqlite3_column_int64(s, 5);
        packing->frozen = (uint64_t)sqlite3_column_int64(s, 6);
        packing->capped = (uint64_t)sqlite3_column_int64(s, 7);
        packing->max_level = (uint32_t)sqlite3_column_int64(s, 8);
    }
    sqlite3_reset(s);
    if (result) {
        free(*spec_text);
        *spec_text = NULL;
        gp_packing_free(packing);
    }
    return result;
}

int gp_store_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap)
{
    sqlite3_stmt *s = stmt(db, ST_TIMINGS);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    int n = 0, rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW && n < cap) {
        copy_text(names[n], 32, s, 0);
        seconds[n++] = sqlite3_column_double(s, 1);
    }
    sqlite3_reset(s);
    return rc == SQLITE_ROW || rc == SQLITE_DONE ? n : db_fail(db, "load timings");
}

int gp_store_count(gp_db *db, long counts[GP_JOB_NSTATUS])
{
    memset(counts, 0, GP_JOB_NSTATUS * sizeof *counts);
    sqlite3_stmt *s = stmt(db, ST_COUNT);
    if (!s)
        return GP_SRV_EDB;
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
        gp_job_status st;
        if (gp_job_status_parse((const char *)sqlite3_column_text(s, 0), &st) == 0)
            counts[st] = (long)sqlite3_column_int64(s, 1);
    }
    sqlite3_reset(s);
    return rc == SQLITE_DONE ? 0 : db_fail(db, "count jobs");
}

int gp_store_write_state(gp_store *store)
{
    return atomic_load(&store->write_state);
}

int gp_store_broken(const gp_db *db)
{
    return db && (db->broken || db->generation != atomic_load(&db->store->generation));
}

int gp_store_healthy(gp_db *db)
{
    sqlite3_stmt *s;
    if (sqlite3_prepare_v2(db->conn, "SELECT count(*) FROM jobs", -1, &s, NULL) != SQLITE_OK)
        return 0;
    int ok = sqlite3_step(s) == SQLITE_ROW;
    sqlite3_finalize(s);
    return ok;
}
