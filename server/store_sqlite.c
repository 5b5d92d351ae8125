/* store_sqlite.c - the sqlite3 job store (one node): connections (a pool, one per thread at a time),
 * migrations, the statements every query uses (prepared once per connection), and the
 * transaction helpers of store_db.h. The queries are in store_jobs.c and store_results.c. */
#include "store_db.h"
#include "store_ops.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "store_schema.h"

/* How long a writer waits for another connection's transaction before giving up. Writes
 * are short (one job row, or one result), so this is only reached when the disk stalls. */
#define BUSY_TIMEOUT_MS 30000

/* Bytes the WAL file is cut back to after a checkpoint (see PRAGMA journal_size_limit). */
#define WAL_SIZE_LIMIT (64 << 20)

/* has_mesh: the spec asks for a mesh ("mesh" in the inputs, wrapped or bare: a bare spec
 * cannot hold "inputs"), or for polyhedra (a box's "laguerre"), so that a job lists the
 * mesh formats, or tess, only when it has them */
/* process: "pack3d" when the spec's domain has a depth (gp_process_of_spec, processes.h) */
#define JOB_COLUMNS "seq, id, status, created, started, finished, updated, progress, message," \
                    " coalesce(json_type(spec, '$.inputs.mesh'), json_type(spec, '$.mesh'), CASE WHEN" \
                    " coalesce(json_type(spec, '$.inputs.domain.depth'), json_type(spec, '$.domain.depth'))" \
                    " IS NOT NULL THEN coalesce(json_type(spec, '$.inputs.laguerre')," \
                    " json_type(spec, '$.laguerre')) END) IS NOT NULL," \
                    " CASE WHEN coalesce(json_type(spec, '$.inputs.domain.depth')," \
                    " json_type(spec, '$.domain.depth')) IS NULL THEN 'pack2d' ELSE 'pack3d' END"

static void sq_close(gp_store *store);
static void sq_release(gp_store *store, gp_db *db);
static int sq_broken(const gp_db *db);

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
    /* the claim's time is read before it waits for the write lock, which the job's own
     * insertion may hold: never before the job's creation */
    [ST_CLAIM] = "UPDATE jobs SET status = 'running', started = max(?1, created),"
                 " updated = max(?1, created), progress = 0,"
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
                  " front_capped = ?18, max_level = ?19, result_version = ?20"
                  " WHERE id = ?1 AND status = 'running'",
    [ST_SECTION] = "INSERT INTO result_sections (job_id, tag, version, bytes, summary)"
                   " VALUES (?1, ?2, ?3, ?4, ?5) RETURNING id",
    [ST_CHUNK] = "INSERT INTO result_chunks (section, chunk, data) VALUES (?1, ?2, ?3)",
    [ST_BIN] = "INSERT OR REPLACE INTO bin_stats (job_id, bin, min, max, target, achieved, count, z)"
               " VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
    [ST_TIMING] = "INSERT OR REPLACE INTO stage_timings (job_id, position, stage, seconds)"
                  " VALUES (?1, ?2, ?3, ?4)",
    [ST_FAIL] = "UPDATE jobs SET status = 'failed', error = ?2, message = ?3, finished = ?4,"
                " updated = ?4 WHERE id = ?1 AND status = 'running'",
    /* a stop that cancelled the job cleanly: its claim does not count (--max-job-attempts
     * counts the runs the daemon died in) */
    [ST_REQUEUE] = "UPDATE jobs SET status = 'accepted', started = NULL, progress = 0,"
                   " message = ?2, updated = ?3, claims = max(claims - 1, 0)"
                   " WHERE id = ?1 AND status = 'running'",
    [ST_STATUS] = "SELECT status FROM jobs WHERE id = ?1 AND (?2 IS NULL OR owner = ?2)",
    [ST_DISMISS] = "UPDATE jobs SET status = 'dismissed', message = ?2, finished = ?3, updated = ?3"
                   " WHERE id = ?1 AND status IN ('accepted', 'running')",
    [ST_DELETE] = "DELETE FROM jobs WHERE id = ?1",
    [ST_OPEN_RESULT] = "SELECT seq, spec, result_version FROM jobs"
                       " WHERE id = ?1 AND status = 'successful' AND (?2 IS NULL OR owner = ?2)",
    [ST_SUMMARY_SECTIONS] = "SELECT tag, version, id, bytes FROM result_sections"
                            " WHERE job_id = ?1 AND summary = 1 ORDER BY id",
    [ST_FIND_SECTION] = "SELECT s.id, s.bytes FROM result_sections s JOIN jobs j ON j.id = s.job_id"
                        " WHERE j.seq = ?1 AND s.tag = ?2",
    [ST_READ_CHUNK] = "SELECT data FROM result_chunks WHERE section = ?1 AND chunk = ?2",
    [ST_TIMINGS] = "SELECT stage, seconds FROM stage_timings WHERE job_id = ?1 ORDER BY position",
    [ST_COUNT] = "SELECT status, count(*) FROM jobs GROUP BY status",
    [ST_ACTIVE] = "SELECT count(*) FROM jobs WHERE owner = ?1 AND status IN ('accepted', 'running')",
};

struct gp_store {
    gp_store_head head; /* first: store.c reads it */
    char *path;
    pthread_mutex_t lock; /* guards free_list and all only */
    gp_db *free_list[2];  /* idle connections, by durability */
    gp_store_conns all;   /* every connection open, closed by sq_close */
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
int gp_db_fail(gp_db *db, const char *what)
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

sqlite3_stmt *gp_db_stmt(gp_db *db, enum stmt_id id)
{
    if (!db->stmt[id] && sqlite3_prepare_v3(db->conn, stmt_sql[id], -1, SQLITE_PREPARE_PERSISTENT,
                                            &db->stmt[id], NULL) != SQLITE_OK) {
        gp_db_fail(db, "prepare");
        return NULL;
    }
    sqlite3_reset(db->stmt[id]);
    sqlite3_clear_bindings(db->stmt[id]);
    return db->stmt[id];
}

/* Steps s once and resets it: 0 (a row or done) or GP_SRV_EDB. */
static int step(sqlite3_stmt *s)
{
    int rc = sqlite3_step(s);
    sqlite3_reset(s);
    return rc == SQLITE_DONE || rc == SQLITE_ROW ? 0 : GP_SRV_EDB;
}

int gp_db_run(gp_db *db, sqlite3_stmt *s, const char *what)
{
    return step(s) ? gp_db_fail(db, what) : 0;
}

int gp_db_run_one(gp_db *db, sqlite3_stmt *s, const char *what)
{
    int rc = gp_db_run(db, s, what);
    return rc == 0 && sqlite3_changes(db->conn) == 0 ? GP_SRV_ESTATE : rc;
}

/* ROLLBACK when a transaction is open. */
static void rollback(gp_db *db)
{
    if (!sqlite3_get_autocommit(db->conn))
        step(db->rollback);
}

sqlite3_stmt *gp_db_write(gp_db *db, enum stmt_id id, int *rc)
{
    sqlite3_stmt *s = gp_db_stmt(db, id);
    if (!s) {
        *rc = GP_SRV_EDB;
        return NULL;
    }
    *rc = gp_db_run(db, db->begin, "begin immediate");
    return *rc ? NULL : s;
}

int gp_db_end(gp_db *db, int rc)
{
    if (rc) {
        rollback(db);
        return rc;
    }
    if (step(db->commit) == 0) {
        set_write_state(db->store, 0);
        return 0;
    }
    rc = gp_db_fail(db, "commit");
    step(db->rollback);
    return rc;
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
            (gp_store_conversions[version] && gp_store_conversions[version](db, why, why_size)) ||
            exec_sql(db->conn, set_version, why, why_size) ||
            exec_sql(db->conn, "COMMIT", why, why_size)) {
            char ignored[8];
            exec_sql(db->conn, "ROLLBACK", ignored, sizeof ignored);
            return GP_SRV_EDB;
        }
        gp_log("store: schema migrated to version %d", version + 1);
    }
}

int sq_recover(gp_db *db, int max_attempts, int *requeued, int *given_up)
{
    /* a job still running in the store was running when the daemon died: its claims
     * count the starts it did not survive (a clean stop gives its claim back) */
    char now[GP_TIMESTAMP_SIZE], fail[512], requeue[320];
    gp_timestamp_now(now);
    snprintf(fail, sizeof fail,
             "UPDATE jobs SET status = 'failed', error = 'gave up', finished = '%s',"
             " updated = '%s', message = 'failed: the daemon stopped ' || claims ||"
             " ' times while this job ran (a crash, a kill, or a stop it did not answer"
             " in time); it is not run again (--max-job-attempts %d)'"
             " WHERE status = 'running' AND claims >= %d",
             now, now, max_attempts, max_attempts);
    snprintf(requeue, sizeof requeue,
             "UPDATE jobs SET status = 'accepted', started = NULL, progress = 0,"
             " message = '" GP_REQUEUE_MESSAGE "', updated = '%s'"
             " WHERE status = 'running'",
             now);
    int rc = gp_db_run(db, db->begin, "begin immediate");
    if (rc)
        return rc;
    char *msg = NULL;
    if (sqlite3_exec(db->conn, fail, NULL, NULL, &msg) != SQLITE_OK)
        goto failed;
    *given_up = sqlite3_changes(db->conn);
    if (sqlite3_exec(db->conn, requeue, NULL, NULL, &msg) != SQLITE_OK)
        goto failed;
    *requeued = sqlite3_changes(db->conn);
    return gp_db_end(db, 0);
failed:
    sqlite3_free(msg);
    return gp_db_end(db, gp_db_fail(db, "recover running jobs"));
}

int gp_store_sqlite_open(const char *path, gp_store **out, char *why, size_t why_size)
{
    *out = NULL;
    gp_store *store = calloc(1, sizeof *store);
    if (!store || !(store->path = strdup(path))) {
        free(store);
        snprintf(why, why_size, "out of memory");
        return GP_ENOMEM;
    }
    store->head.ops = &gp_store_sqlite_ops;
    pthread_mutex_init(&store->lock, NULL);
    gp_db *db = db_open(path, 1, why, why_size);
    if (db)
        db->store = store;
    int rc = db ? migrate(db, why, why_size) : GP_SRV_EDB;
    if (rc == 0)
        rc = gp_store_conns_add(&store->all, db);
    if (rc) {
        db_close(db);
        sq_close(store);
        return rc;
    }
    db->next_free = NULL;
    store->free_list[1] = db;
    *out = store;
    return 0;
}

static void sq_close(gp_store *store)
{
    if (!store)
        return;
    for (size_t i = 0; i < store->all.n; i++)
        db_close(store->all.items[i]);
    free(store->all.items);
    pthread_mutex_destroy(&store->lock);
    free(store->path);
    free(store);
}

static gp_db *sq_acquire(gp_store *store, int durable)
{
    durable = durable ? 1 : 0;
    pthread_mutex_lock(&store->lock);
    gp_db *db = store->free_list[durable];
    if (db)
        store->free_list[durable] = db->next_free;
    pthread_mutex_unlock(&store->lock);
    if (db && sq_broken(db)) { /* from another generation: a fresh one instead */
        db->broken = 1;
        sq_release(store, db);
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
    int rc = gp_store_conns_add(&store->all, db);
    pthread_mutex_unlock(&store->lock);
    if (rc) {
        db_close(db);
        return NULL;
    }
    return db;
}

static void sq_release(gp_store *store, gp_db *db)
{
    if (!db)
        return;
    rollback(db); /* a caller that bailed out mid-transaction must not hold the write lock */
    if (sq_broken(db)) {
        pthread_mutex_lock(&store->lock);
        gp_store_conns_remove(&store->all, db);
        pthread_mutex_unlock(&store->lock);
        db_close(db);
        return;
    }
    pthread_mutex_lock(&store->lock);
    db->next_free = store->free_list[db->durable];
    store->free_list[db->durable] = db;
    pthread_mutex_unlock(&store->lock);
}

void gp_db_copy_text(char *dst, size_t size, sqlite3_stmt *s, int col)
{
    const unsigned char *t = sqlite3_column_text(s, col);
    snprintf(dst, size, "%s", t ? (const char *)t : "");
}

void gp_db_bind_owner(sqlite3_stmt *s, int i, const char *owner)
{
    if (owner)
        sqlite3_bind_text(s, i, owner, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(s, i);
}

static int sq_write_state(gp_store *store)
{
    return atomic_load(&store->write_state);
}

static int sq_broken(const gp_db *db)
{
    return db && (db->broken || db->generation != atomic_load(&db->store->generation));
}

static int sq_healthy(gp_db *db)
{
    sqlite3_stmt *s;
    if (sqlite3_prepare_v2(db->conn, "SELECT count(*) FROM jobs", -1, &s, NULL) != SQLITE_OK)
        return 0;
    int ok = sqlite3_step(s) == SQLITE_ROW;
    sqlite3_finalize(s);
    return ok;
}

const gp_store_ops gp_store_sqlite_ops = {
    .name = "sqlite",
    .close = sq_close,
    .acquire = sq_acquire,
    .release = sq_release,
    .recover = sq_recover,
    .insert_job = sq_insert_job,
    .get_job = sq_get_job,
    .list_jobs = sq_list_jobs,
    .claim = sq_claim,
    .progress = sq_progress,
    .finish = sq_finish,
    .fail = sq_fail,
    .requeue = sq_requeue,
    .dismiss = sq_dismiss,
    .open_result = sq_open_result,
    .find_section = sq_find_section,
    .read_chunk = sq_read_chunk,
    .load_timings = sq_load_timings,
    .count = sq_count,
    .healthy = sq_healthy,
    .write_state = sq_write_state,
    .broken = sq_broken,
};
