/* nodes.c - the thread that keeps a node in step with the others on a shared store
 * (see nodes.h). */
#include "nodes.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

#include "log.h"
#include "workers.h"

/* Seconds one gp_store_watch call waits at most: how long a stop waits for the thread. */
#define WATCH_SLICE 0.25

struct gp_nodes {
    gp_service *svc;
    pthread_t thread;
    atomic_int stopping;
};

static void on_queued(void *ctx)
{
    gp_nodes *n = ctx;
    gp_pool_notify(n->svc->pool);
}

static void on_finished(void *ctx, const char *id)
{
    gp_nodes *n = ctx;
    gp_waiters_wake(n->svc->waiters, id);
}

static void on_lost(void *ctx, const char *id)
{
    gp_nodes *n = ctx;
    gp_pool_cancel(n->svc->pool, id);
}

static void on_waiting(void *ctx, long accepted)
{
    gp_nodes *n = ctx;
    atomic_store(&n->svc->queued, accepted);
}

static void *watch_main(void *arg)
{
    gp_nodes *n = arg;
    gp_store_events ev = {n, on_queued, on_finished, on_lost, on_waiting};
    int failing = 0;
    while (!atomic_load(&n->stopping)) {
        int rc = gp_store_watch(n->svc->store, &ev, WATCH_SLICE);
        if (rc && !failing)
            gp_log("store: cannot hear from the other nodes; trying again (the leases of this "
                   "node's jobs are not renewed meanwhile)");
        else if (!rc && failing)
            gp_log("store: hearing from the other nodes again");
        failing = rc != 0;
    }
    return NULL;
}

int gp_nodes_start(gp_service *svc, gp_nodes **out)
{
    *out = NULL;
    if (!gp_store_shared(svc->store))
        return 0;
    gp_nodes *n = calloc(1, sizeof *n);
    if (!n)
        return GP_ENOMEM;
    n->svc = svc;
    atomic_init(&n->stopping, 0);
    if (pthread_create(&n->thread, NULL, watch_main, n)) {
        free(n);
        return GP_ENOMEM;
    }
    *out = n;
    return 0;
}

void gp_nodes_stop(gp_nodes *n)
{
    if (!n)
        return;
    atomic_store(&n->stopping, 1);
    pthread_join(n->thread, NULL);
    free(n);
}
