/* store_pg.c - the PostgreSQL job store, which nodes share: connections (a pool, one per
 * thread at a time), migrations under an advisory lock (nodes may start together), the
 * query helpers of store_pg.h and the claims this run holds. The queries are in
 * store_pg_jobs.c and store_pg_results.c, the nodes' news and leases in store_pg_watch.c. */
#include "store_pg.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "store_pg_schema.h"

/* The advisory lock key the migrations hold (any constant no other program uses: "gpak") */
#define MIGRATION_LOCK 0x6770616bLL

/* libpq's notices (NOTICE and below) are not news for the log */
static void ignore_notice(void *arg, const char *message)
{
    (void)arg;
    (void)message;
}

/* Connects; NULL with a reason (libpq's, which never holds the password) in why. */
static PGconn *connect_to(const char *uri, char *why, size_t why_size)
{
    const char *keys[] = {"dbname", "fallback_application_name", NULL};
    const char *values[] = {uri, "grainpackd", NULL};
    PGconn *conn = PQconnectdbParams(keys, values, 1);
    if (!conn || PQstatus(conn) != CONNECTION_OK) {
        snprintf(why, why_size, "cannot connect to PostgreSQL: %s",
                 conn ? PQerrorMessage(conn) : "out of memory");
        why[strcspn(why, "\n")] = '\0';
        PQfinish(conn);
        return NULL;
    }
    PQsetNoticeProcessor(conn, ignore_notice, NULL);
    return conn;
}

int gp_pg_text(pg_params *p, const char *value)
{
    p->values[p->n] = value;
    p->lengths[p->n] = 0;
    p->formats[p->n] = 0;
    return ++p->n;
}

int gp_pg_int(pg_params *p, char buf[32], long long value)
{
    snprintf(buf, 32, "%lld", value);
    return gp_pg_text(p, buf);
}

int gp_pg_double(pg_params *p, char buf[32], double value)
{
    if (!isfinite(value))
        return gp_pg_text(p, NULL);
    snprintf(buf, 32, "%.17g", value);
    return gp_pg_text(p, buf);
}

int gp_pg_bytes(pg_params *p, const void *data, size_t len)
{
    p->values[p->n] = data;
    p->lengths[p->n] = (int)len;
    p->formats[p->n] = 1;
    return ++p->n;
}

/* A failure's class from its SQLSTATE. */
static int classify(const PGresult *res)
{
    const char *state = res ? PQresultErrorField(res, PG_DIAG_SQLSTATE) : NULL;
    if (state && strcmp(state, "53100") == 0) /* disk_full */
        return GP_SRV_EFULL;
    if (state && (strcmp(state, "25006") == 0 || strncmp(state, "58", 2) == 0))
        return GP_SRV_EUNWRITABLE; /* read-only transaction, or a system (I/O) error */
    return GP_SRV_EDB;
}

PGresult *gp_pg_query(pg_db *db, const char *what, const char *sql, const pg_params *p,
                      int binary, int *rc)
{
    /* without parameters, the simple protocol: it runs several statements in one go */
    PGresult *res = !p && !binary ? PQexec(db->conn, sql)
                                  : PQexecParams(db->conn, sql, p ? p->n : 0, NULL,
                                                 p ? p->values : NULL, p ? p->lengths : NULL,
                                                 p ? p->formats : NULL, binary);
    ExecStatusType st = res ? PQresultStatus(res) : PGRES_FATAL_ERROR;
    if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) {
        if (rc)
            *rc = 0;
        atomic_store(&gp_pg_store(db->store)->write_state, 0);
        return res;
    }
    int cls = classify(res);
    const char *msg = res ? PQresultErrorMessage(res) : PQerrorMessage(db->conn);
    gp_log("store: %s: %.*s", what, (int)strcspn(msg, "\n"), msg);
    if (PQstatus(db->conn) != CONNECTION_OK)
        db->broken = 1;
    if (cls != GP_SRV_EDB)
        atomic_store(&gp_pg_store(db->store)->write_state, cls);
    PQclear(res);
    if (rc)
        *rc = cls;
    return NULL;
}

int gp_pg_run(pg_db *db, const char *what, const char *sql, const pg_params *p, long *changed)
{
    int rc;
    PGresult *res = gp_pg_query(db, what, sql, p, 0, &rc);
    if (res && changed)
        *changed = atol(PQcmdTuples(res));
    PQclear(res);
    return rc;
}

int gp_pg_begin(pg_db *db)
{
    return gp_pg_run(db, "begin", "BEGIN", NULL, NULL);
}

int gp_pg_end(pg_db *db, int rc)
{
    if (rc) {
        if (PQtransactionStatus(db->conn) != PQTRANS_IDLE)
            PQclear(PQexec(db->conn, "ROLLBACK"));
        return rc;
    }
    rc = gp_pg_run(db, "commit", "COMMIT", NULL, NULL);
    if (rc && PQtransactionStatus(db->conn) != PQTRANS_IDLE)
        PQclear(PQexec(db->conn, "ROLLBACK"));
    return rc;
}

/* The schema version of the database (0: none yet), inside the migration's transaction. */
static int read_version(pg_db *db, int *version)
{
    int rc = gp_pg_run(db, "create the schema's version table",
                       "CREATE TABLE IF NOT EXISTS grainpack_schema (version integer NOT NULL)",
                       NULL, NULL);
    PGresult *res = rc ? NULL : gp_pg_query(db, "read the schema version",
                                            "SELECT version FROM grainpack_schema", NULL, 0, &rc);
    *version = res && PQntuples(res) > 0 ? atoi(PQgetvalue(res, 0, 0)) : 0;
    PQclear(res);
    return rc;
}

/* Brings the schema to GP_STORE_SCHEMA_VERSION in one transaction, under an advisory lock
 * so that nodes starting together migrate once. */
static int migrate(pg_db *db, char *why, size_t why_size)
{
    char lock[32];
    pg_params p = {0};
    gp_pg_int(&p, lock, MIGRATION_LOCK);
    int version = 0, from;
    int rc = gp_pg_begin(db);
    if (!rc)
        rc = gp_pg_run(db, "lock the schema", "SELECT pg_advisory_xact_lock($1::bigint)", &p, NULL);
    if (!rc)
        rc = read_version(db, &version);
    from = version;
    if (!rc && (version < 0 || (size_t)version > gp_pg_migration_count)) {
        snprintf(why, why_size, "schema version %d is not one this build knows (0..%zu)",
                 version, gp_pg_migration_count);
        return gp_pg_end(db, GP_SRV_EDB);
    }
    if (!rc && version == 0)
        version = gp_pg_first_version - 1; /* the versions before this store began */
    while (!rc && (size_t)version < gp_pg_migration_count) {
        char set[96];
        rc = gp_pg_run(db, "migrate", gp_pg_migrations[version], NULL, NULL);
        version++;
        snprintf(set, sizeof set, "DELETE FROM grainpack_schema; INSERT INTO grainpack_schema"
                                  " VALUES (%d)", version);
        if (!rc)
            rc = gp_pg_run(db, "set the schema version", set, NULL, NULL);
    }
    rc = gp_pg_end(db, rc);
    if (rc)
        snprintf(why, why_size, "cannot migrate the PostgreSQL schema (the log says why)");
    else if (from != version)
        gp_log("store: schema migrated from version %d to %d", from, version);
    return rc;
}

static void db_close(pg_db *db)
{
    if (db) {
        PQfinish(db->conn);
        free(db);
    }
}

/* A new connection to the store's database; NULL (with why) when it cannot connect. */
static pg_db *db_open(pg_store *store, char *why, size_t why_size)
{
    pg_db *db = calloc(1, sizeof *db);
    if (!db) {
        snprintf(why, why_size, "out of memory");
        return NULL;
    }
    db->store = (gp_store *)(void *)store;
    if (!(db->conn = connect_to(store->uri, why, why_size))) {
        free(db);
        return NULL;
    }
    return db;
}

static void pg_close(gp_store *s)
{
    pg_store *store = gp_pg_store(s);
    for (size_t i = 0; i < store->all.n; i++)
        db_close(store->all.items[i]);
    PQfinish(store->listen);
    free(store->all.items);
    free(store->held);
    free(store->uri);
    pthread_mutex_destroy(&store->lock);
    free(store);
}

static gp_db *pg_acquire(gp_store *s, int durable)
{
    (void)durable; /* every commit waits for PostgreSQL's WAL flush (synchronous_commit) */
    pg_store *store = gp_pg_store(s);
    pthread_mutex_lock(&store->lock);
    pg_db *db = store->free_list;
    if (db)
        store->free_list = db->next_free;
    pthread_mutex_unlock(&store->lock);
    if (db)
        return (gp_db *)(void *)db;
    char why[512];
    if (!(db = db_open(store, why, sizeof why))) {
        gp_log("store: %s", why);
        return NULL;
    }
    pthread_mutex_lock(&store->lock);
    int rc = gp_store_conns_add(&store->all, db);
    pthread_mutex_unlock(&store->lock);
    if (rc) {
        db_close(db);
        return NULL;
    }
    return (gp_db *)(void *)db;
}

static void pg_release(gp_store *s, gp_db *d)
{
    pg_store *store = gp_pg_store(s);
    pg_db *db = gp_pg_db(d);
    if (PQstatus(db->conn) != CONNECTION_OK)
        db->broken = 1;
    if (!db->broken && PQtransactionStatus(db->conn) != PQTRANS_IDLE)
        PQclear(PQexec(db->conn, "ROLLBACK")); /* a caller that bailed out mid-transaction */
    pthread_mutex_lock(&store->lock);
    if (db->broken) {
        gp_store_conns_remove(&store->all, db);
    } else {
        db->next_free = store->free_list;
        store->free_list = db;
    }
    pthread_mutex_unlock(&store->lock);
    if (db->broken)
        db_close(db);
}

int gp_store_pg_open(const char *uri, gp_store **out, char *why, size_t why_size)
{
    *out = NULL;
    pg_store *store = calloc(1, sizeof *store);
    if (!store || !(store->uri = strdup(uri))) {
        free(store);
        snprintf(why, why_size, "out of memory");
        return GP_ENOMEM;
    }
    store->head.ops = &gp_store_pg_ops;
    pthread_mutex_init(&store->lock, NULL);
    gp_store_options defaults = {"grainpackd", 10.0, 3};
    gp_store *s = (gp_store *)(void *)store;
    pg_db *db = db_open(store, why, why_size);
    int rc = db ? migrate(db, why, why_size) : GP_SRV_EDB;
    if (rc == 0)
        rc = gp_store_conns_add(&store->all, db);
    if (rc == 0)
        rc = gp_store_configure(s, &defaults);
    if (rc) {
        if (db && (store->all.n == 0 || store->all.items[store->all.n - 1] != db))
            db_close(db);
        pg_close(s);
        return rc;
    }
    store->free_list = db;
    *out = s;
    return 0;
}

static int pg_configure(gp_store *s, const gp_store_options *options)
{
    pg_store *store = gp_pg_store(s);
    unsigned char r[6];
    gp_store_random_bytes(r, sizeof r);
    snprintf(store->node, sizeof store->node, "%s", options->node);
    /* the run: a restarted node must not take the jobs of its previous run for its own */
    snprintf(store->run, sizeof store->run, "%s/%02x%02x%02x%02x%02x%02x", store->node, r[0],
             r[1], r[2], r[3], r[4], r[5]);
    store->lease_seconds = options->lease_seconds;
    store->max_attempts = options->max_attempts;
    return 0;
}

static const char *pg_node(gp_store *s)
{
    return gp_pg_store(s)->run;
}

int gp_pg_held(pg_store *store, const char *id)
{
    int claim = 0;
    pthread_mutex_lock(&store->lock);
    for (size_t i = 0; i < store->nheld && !claim; i++)
        if (strcmp(store->held[i].id, id) == 0)
            claim = store->held[i].claim;
    pthread_mutex_unlock(&store->lock);
    return claim;
}

void gp_pg_forget(pg_store *store, const char *id)
{
    pthread_mutex_lock(&store->lock);
    for (size_t i = 0; i < store->nheld; i++) {
        if (strcmp(store->held[i].id, id) == 0) {
            store->held[i] = store->held[--store->nheld];
            break;
        }
    }
    pthread_mutex_unlock(&store->lock);
}

int gp_pg_hold(pg_store *store, const char *id, int claim)
{
    int rc = 0;
    pthread_mutex_lock(&store->lock);
    if (store->nheld == store->capheld) {
        size_t cap = store->capheld ? store->capheld * 2 : 16;
        pg_held *grown = realloc(store->held, cap * sizeof *grown);
        if (grown) {
            store->held = grown;
            store->capheld = cap;
        }
    }
    if (store->nheld < store->capheld) {
        snprintf(store->held[store->nheld].id, GP_JOB_ID_SIZE, "%s", id);
        store->held[store->nheld++].claim = claim;
    } else {
        rc = GP_ENOMEM;
    }
    pthread_mutex_unlock(&store->lock);
    return rc;
}

static int pg_recover(gp_db *db, int max_attempts, int *requeued, int *given_up)
{
    /* the jobs of nodes that died (their leases expired); those of live nodes go on */
    *requeued = *given_up = 0;
    return gp_pg_reap(gp_pg_db(db), max_attempts, requeued, given_up);
}

static int pg_healthy(gp_db *db)
{
    PGresult *res = gp_pg_query(gp_pg_db(db), "health", "SELECT 1 FROM jobs LIMIT 1", NULL, 0, NULL);
    PQclear(res);
    return res != NULL;
}

static int pg_write_state(gp_store *s)
{
    return atomic_load(&gp_pg_store(s)->write_state);
}

static int pg_broken(const gp_db *db)
{
    const pg_db *p = (const pg_db *)(const void *)db;
    return p->broken || PQstatus(p->conn) != CONNECTION_OK;
}

static int pg_secret(gp_store *s, const char *name, void *out, size_t len)
{
    gp_db *d = pg_acquire(s, 1);
    if (!d)
        return GP_SRV_EDB;
    pg_db *db = gp_pg_db(d);
    unsigned char *fresh = malloc(len);
    if (!fresh) {
        pg_release(s, d);
        return GP_ENOMEM;
    }
    gp_store_random_bytes(fresh, len);
    pg_params p = {0};
    gp_pg_text(&p, name);
    gp_pg_bytes(&p, fresh, len);
    /* the first node's draw stays: the others read it */
    int rc = gp_pg_run(db, "store a secret",
                       "INSERT INTO grainpack_secrets (name, value) VALUES ($1, $2)"
                       " ON CONFLICT (name) DO NOTHING",
                       &p, NULL);
    free(fresh);
    PGresult *res = rc ? NULL : gp_pg_query(db, "read a secret",
                                            "SELECT value FROM grainpack_secrets WHERE name = $1",
                                            &(pg_params){.n = 1, .values = {name}}, 1, &rc);
    if (res && PQntuples(res) == 1 && (size_t)PQgetlength(res, 0, 0) == len)
        memcpy(out, PQgetvalue(res, 0, 0), len);
    else if (res)
        rc = GP_SRV_EDB; /* another size than asked: a secret of another build */
    PQclear(res);
    pg_release(s, d);
    return rc;
}

const gp_store_ops gp_store_pg_ops = {
    .name = "postgresql",
    .close = pg_close,
    .acquire = pg_acquire,
    .release = pg_release,
    .recover = pg_recover,
    .insert_job = gp_pg_insert_job,
    .get_job = gp_pg_get_job,
    .list_jobs = gp_pg_list_jobs,
    .claim = gp_pg_claim,
    .progress = gp_pg_progress,
    .finish = gp_pg_finish,
    .fail = gp_pg_fail,
    .requeue = gp_pg_requeue,
    .dismiss = gp_pg_dismiss,
    .open_result = gp_pg_open_result,
    .find_section = gp_pg_find_section,
    .read_chunk = gp_pg_read_chunk,
    .load_timings = gp_pg_load_timings,
    .count = gp_pg_count,
    .healthy = pg_healthy,
    .write_state = pg_write_state,
    .broken = pg_broken,
    .configure = pg_configure,
    .watch = gp_pg_watch,
    .node = pg_node,
    .secret = pg_secret,
};
