/* nodes.h - a node among others on a shared store (PostgreSQL): a thread that hears the
 * other nodes' news through gp_store_watch and passes it on to this node's parts: a job
 * queued wakes a worker, a job finished wakes its long-polls, a job lost (dismissed on
 * another node) is stopped, and the count of waiting jobs (for --max-queued and
 * /metrics) follows every node's submissions and claims. Nothing runs for sqlite. */
#ifndef GRAINPACKD_NODES_H
#define GRAINPACKD_NODES_H

#include "service.h"

typedef struct gp_nodes gp_nodes;

/* Starts the thread when svc->store is shared (*out NULL otherwise). svc, its pool and
 * waiters must outlive it. Returns 0 or GP_ENOMEM. */
int gp_nodes_start(gp_service *svc, gp_nodes **out);

/* Stops and joins the thread (within a second) and frees it; NULL is a no-op. */
void gp_nodes_stop(gp_nodes *nodes);

#endif
