/* store_pg.h - inside the PostgreSQL job store (store_pg*.c only): the store shared by
 * nodes, a connection, and the helpers every query uses. Not for the rest of the service. */
#ifndef GRAINPACKD_STORE_PG_H
#define GRAINPACKD_STORE_PG_H

#include <libpq-fe.h>
#include <pthread.h>

#include "store_ops.h"

typedef struct pg_db pg_db;

/* A job this node claimed and runs: the claim (the job's claims count when this node took
 * it) is what a later write must still find, so that a node whose lease expired meanwhile
 * (and whose job another node took) changes nothing. */
typedef struct pg_held {
    char id[GP_JOB_ID_SIZE];
    int claim;
} pg_held;

typedef struct pg_store {
    gp_store_head head; /* first: store.c reads it */
    char *uri;
    char node[64];   /* the node's name (gp_store_options.node) */
    char run[128];   /* node/random: this run of the node, in the rows of the jobs it runs */
    double lease_seconds;
    int max_attempts;
    pthread_mutex_t lock; /* guards free_list, all and held */
    pg_db *free_list;
    gp_store_conns all; /* every connection open, closed by gp_store_close */
    pg_held *held; /* the jobs this run claimed and has not concluded */
    size_t nheld, capheld;
    atomic_int write_state;
    /* gp_store_watch's own (one thread): its connection, which LISTENs */
    PGconn *listen;
    double next_tick; /* monotonic seconds of the next renewal of leases */
} pg_store;

struct pg_db {
    gp_store *store; /* first: store.c reads it (gp_db_head) */
    PGconn *conn;
    int broken; /* the connection failed: closed when released, not reused */
    pg_db *next_free;
};

static inline pg_db *gp_pg_db(gp_db *db)
{
    return (pg_db *)(void *)db;
}

static inline pg_store *gp_pg_store(gp_store *store)
{
    return (pg_store *)(void *)store;
}

/* A query's parameters: text values (NULL is SQL NULL), and binary ones where lengths
 * (may be NULL) and formats say so (a bytea's bytes: format 1). */
typedef struct pg_params {
    int n;
    const char *values[24];
    int lengths[24];
    int formats[24];
} pg_params;

/* Adds a text parameter (NULL: SQL NULL), an integer, a double (NaN and infinities as
 * NULL, as sqlite stores them) or bytes; each returns its $ number. Numbers are written
 * into buf (room for 32 bytes per number), which must outlive the query. */
int gp_pg_text(pg_params *p, const char *value);
int gp_pg_int(pg_params *p, char buf[32], long long value);
int gp_pg_double(pg_params *p, char buf[32], double value);
int gp_pg_bytes(pg_params *p, const void *data, size_t len);

/* Runs sql with the parameters p (may be NULL); the result rows in binary when
 * `binary`. Returns the result (caller PQclear) or NULL after logging the failure with
 * `what` (*rc, which may be NULL, gets its class: GP_SRV_EFULL, GP_SRV_EUNWRITABLE or
 * GP_SRV_EDB); a connection that broke is marked so. */
PGresult *gp_pg_query(pg_db *db, const char *what, const char *sql, const pg_params *p,
                      int binary, int *rc);

/* gp_pg_query for a statement whose rows do not matter: 0 or the failure's class; with
 * `changed`, the number of rows it changed. */
int gp_pg_run(pg_db *db, const char *what, const char *sql, const pg_params *p, long *changed);

/* A transaction: gp_pg_begin opens it (0 or a failure class), gp_pg_end commits when rc is
 * 0 (returning the commit's outcome) or rolls back and returns rc. */
int gp_pg_begin(pg_db *db);
int gp_pg_end(pg_db *db, int rc);

/* The claim this run holds on job id (0: none), and forgetting it. */
int gp_pg_held(pg_store *store, const char *id);
void gp_pg_forget(pg_store *store, const char *id);
/* Remembers a claim; GP_ENOMEM when it cannot. */
int gp_pg_hold(pg_store *store, const char *id, int claim);

/* Jobs whose node's lease expired: failed after max_attempts claims, queued again before
 * (both counted into the pointers, which may be NULL). Returns 0 or a failure class. */
int gp_pg_reap(pg_db *db, int max_attempts, int *requeued, int *given_up);

/* The functions behind gp_store_pg_ops, each with the contract of its gp_store_
 * namesake in store.h or of its entry in store_ops.h. */
int gp_pg_insert_job(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                     size_t spec_len, const gp_job_columns *columns, gp_job *out, long *active);
int gp_pg_get_job(gp_db *db, const char *id, const char *owner, gp_job *out);
int gp_pg_list_jobs(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                    size_t limit, gp_job *out, size_t *n, int *more);
int gp_pg_claim(gp_db *db, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
                size_t *spec_len);
int gp_pg_progress(gp_db *db, const char *id, int percent, const char *message);
int gp_pg_fail(gp_db *db, const char *id, const char *code_name, const char *message);
int gp_pg_requeue(gp_db *db, const char *id);
int gp_pg_dismiss(gp_db *db, const char *id, const char *owner, gp_job_status *before,
                  int *deleted, gp_job *after);
int gp_pg_count(gp_db *db, long counts[GP_JOB_NSTATUS]);
int gp_pg_finish(gp_db *db, const char *id, const gp_outcome *outcome);
int gp_pg_open_result(gp_db *db, const char *id, const char *owner, gp_stored_result *out);
int gp_pg_find_section(gp_db *db, int64_t key, const char *tag, int64_t *section,
                       uint64_t *bytes);
int gp_pg_read_chunk(gp_db *db, int64_t section, int64_t chunk, void *dst, size_t *len);
int gp_pg_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap);
int gp_pg_watch(gp_store *store, const gp_store_events *events, double seconds);

#endif
