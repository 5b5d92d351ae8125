/* service.h - the daemon's parts, wired together by main.c and handed to every route and
 * worker: nothing in the server lives in a global. */
#ifndef GRAINPACKD_SERVICE_H
#define GRAINPACKD_SERVICE_H

#include <stdatomic.h>

#include "auth.h"
#include "config.h"
#include "cursor.h"
#include "metrics.h"
#include "peers.h"
#include "store.h"
#include "waiters.h"

typedef struct gp_pool gp_pool;

typedef struct gp_service {
    const gp_config *cfg;
    gp_store *store;
    gp_metrics *metrics;
    gp_waiters *waiters;
    gp_pool *pool;
    gp_keyring *keys;     /* NULL: no key file, the service is open */
    gp_peers *peers;      /* connections per client address */
    atomic_long queued;   /* accepted jobs not yet claimed: admission control and metrics */
    atomic_int accepting; /* 0 once shutdown began: submissions get 503 */
    gp_peer_counts http;  /* open connections, slow heads: peers.c counts, /metrics reads */
    double started;       /* monotonic seconds at start, for /health's uptime */
    gp_cursor_keys cursor_keys; /* the keys of GET /jobs's page cursors (cursor.h) */
} gp_service;

#endif
