/* store_pg_watch.c - what a node hears from the others through PostgreSQL: LISTEN on
 * gp_queued (a job was queued: wake a worker) and gp_done (a job ended: wake its
 * long-polls), and on a steady tick the leases of the jobs this run holds renewed (a job
 * that is not this run's any more, dismissed on another node, is reported lost), the jobs
 * of dead nodes queued again, and the waiting jobs counted. One thread, one connection. */
#include "store_pg.h"

#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "log.h"

/* Seconds between two renewals: a dismissal on another node stops the job here within
 * this (the aim: a second), and a lease survives two missed renewals when it
 * lasts at least three times this. */
#define RENEW_SECONDS 1.0

/* The watching thread's connection, made (and LISTENing) when needed. */
static pg_db *listener(pg_store *store, pg_db *db)
{
    if (store->listen && PQstatus(store->listen) != CONNECTION_OK) {
        PQfinish(store->listen);
        store->listen = NULL;
    }
    if (!store->listen) {
        char why[512];
        const char *keys[] = {"dbname", "fallback_application_name", NULL};
        const char *values[] = {store->uri, "grainpackd", NULL};
        PGconn *conn = PQconnectdbParams(keys, values, 1);
        if (!conn || PQstatus(conn) != CONNECTION_OK) {
            snprintf(why, sizeof why, "%s", conn ? PQerrorMessage(conn) : "out of memory");
            gp_log("store: cannot connect to listen to the other nodes: %.*s",
                   (int)strcspn(why, "\n"), why);
            PQfinish(conn);
            return NULL;
        }
        store->listen = conn;
        db->conn = conn;
        if (gp_pg_run(db, "listen", "LISTEN gp_queued; LISTEN gp_done", NULL, NULL)) {
            PQfinish(conn);
            store->listen = NULL;
            return NULL;
        }
    }
    db->conn = store->listen;
    return db;
}

/* Renews this run's leases; the held jobs the renewal did not find are reported lost. */
static int renew(pg_store *store, pg_db *db, const gp_store_events *ev)
{
    /* the claims held before the query: one made after it is not in its answer */
    pthread_mutex_lock(&store->lock);
    size_t n = store->nheld;
    pg_held *before = n ? malloc(n * sizeof *before) : NULL;
    if (before)
        memcpy(before, store->held, n * sizeof *before);
    pthread_mutex_unlock(&store->lock);
    if (n && !before)
        return GP_ENOMEM;
    char lease[32];
    pg_params p = {0};
    gp_pg_text(&p, store->run);
    gp_pg_double(&p, lease, store->lease_seconds);
    /* SKIP LOCKED: a job whose row another transaction holds (this node storing its
     * result, another dismissing it) is not waited for; it ends running soon */
    int rc = gp_pg_run(db, "renew leases",
                       "WITH mine AS (SELECT id FROM jobs WHERE node = $1 AND status = 'running'"
                       " FOR UPDATE SKIP LOCKED) UPDATE jobs SET lease_until = now() +"
                       " make_interval(secs => $2::float8) FROM mine WHERE jobs.id = mine.id",
                       &p, NULL);
    /* what the store says this run holds, as last committed (a plain read waits for no
     * lock): a held job missing from it was dismissed, or taken after its lease expired */
    PGresult *res = rc ? NULL : gp_pg_query(db, "read this node's jobs",
                                            "SELECT id, claims FROM jobs WHERE node = $1"
                                            " AND status = 'running'",
                                            &(pg_params){.n = 1, .values = {store->run}}, 0, &rc);
    for (size_t i = 0; res && i < n; i++) {
        int found = 0;
        for (int row = 0; row < PQntuples(res) && !found; row++)
            found = strcmp(PQgetvalue(res, row, 0), before[i].id) == 0 &&
                    atoi(PQgetvalue(res, row, 1)) == before[i].claim;
        /* still held (not concluded meanwhile) yet not this run's in the store */
        if (!found && gp_pg_held(store, before[i].id) == before[i].claim) {
            gp_log("job %s: no longer this node's (dismissed on another node, or its lease "
                   "expired): stopping it", before[i].id);
            gp_pg_forget(store, before[i].id);
            if (ev && ev->lost)
                ev->lost(ev->ctx, before[i].id);
        }
    }
    PQclear(res);
    free(before);
    return rc;
}

/* The tick: leases, dead nodes' jobs, the count of waiting jobs. */
static int tick(pg_store *store, pg_db *db, const gp_store_events *ev)
{
    int requeued = 0, given_up = 0;
    int rc = renew(store, db, ev);
    if (rc == 0)
        rc = gp_pg_reap(db, store->max_attempts, &requeued, &given_up);
    if (requeued || given_up)
        gp_log("store: %d jobs of nodes that stopped queued again, %d failed after %d attempts",
               requeued, given_up, store->max_attempts);
    PGresult *res = rc ? NULL : gp_pg_query(db, "count waiting jobs",
                                            "SELECT count(*) FROM jobs WHERE status = 'accepted'",
                                            NULL, 0, &rc);
    if (res && ev && ev->waiting)
        ev->waiting(ev->ctx, atol(PQgetvalue(res, 0, 0)));
    PQclear(res);
    return rc;
}

/* Reports the notifications that arrived. */
static void drain(PGconn *conn, const gp_store_events *ev)
{
    PGnotify *note;
    PQconsumeInput(conn);
    while ((note = PQnotifies(conn))) {
        if (ev && strcmp(note->relname, "gp_queued") == 0 && ev->queued)
            ev->queued(ev->ctx);
        else if (ev && strcmp(note->relname, "gp_done") == 0 && ev->finished)
            ev->finished(ev->ctx, note->extra);
        PQfreemem(note);
    }
}

int gp_pg_watch(gp_store *s, const gp_store_events *ev, double seconds)
{
    pg_store *store = gp_pg_store(s);
    pg_db one = {.store = s};
    double now = gp_monotonic_seconds(), end = now + seconds;
    pg_db *db = listener(store, &one);
    if (!db) {
        struct timespec ts = {(time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9)};
        nanosleep(&ts, NULL); /* connect again at the next call */
        return GP_SRV_EDB;
    }
    double period = store->lease_seconds / 3 < RENEW_SECONDS ? store->lease_seconds / 3
                                                             : RENEW_SECONDS;
    int rc = 0;
    while (rc == 0 && (now = gp_monotonic_seconds()) < end) {
        if (now >= store->next_tick) {
            store->next_tick = now + period;
            rc = tick(store, db, ev);
            drain(store->listen, ev);
            continue;
        }
        double until = store->next_tick < end ? store->next_tick : end;
        struct pollfd pfd = {PQsocket(store->listen), POLLIN, 0};
        int ms = (int)((until - now) * 1000) + 1;
        if (poll(&pfd, 1, ms) > 0)
            drain(store->listen, ev);
        if (PQstatus(store->listen) != CONNECTION_OK)
            rc = GP_SRV_EDB;
    }
    return rc;
}
