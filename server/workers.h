/* workers.h - the pool of worker threads: each claims the oldest accepted job from the
 * store, runs the engine's pipeline on it, publishes progress (throttled) and stores the
 * result, honouring cancellation (DELETE), the time limit and shutdown (the job is queued
 * again). A worker that does not stop within seconds of being told to is replaced.
 *
 * Locking: the pool mutex guards the wake-up condition and each worker's current job id;
 * it is never held while a job runs or while the store is used. */
#ifndef GRAINPACKD_WORKERS_H
#define GRAINPACKD_WORKERS_H

#include "service.h"

/* Starts svc->cfg->workers threads. Returns 0 or GP_ENOMEM; the caller owns *out. */
int gp_pool_start(gp_service *svc, gp_pool **out);

/* A job was queued: wake an idle worker. */
void gp_pool_notify(gp_pool *pool);

/* Raises the cancel flag of the worker running job_id, if any; returns 1 if one was. */
int gp_pool_cancel(gp_pool *pool, const char *job_id);

/* Workers running a job right now. */
int gp_pool_busy(gp_pool *pool);

/* Worker threads given up on (they did not stop within seconds of being told to) that
 * still run: another thread took each one's place. */
int gp_pool_abandoned(gp_pool *pool);

/* Stops the pool: no new claims, running jobs are canceled and queued again, threads
 * joined; waits at most `seconds` for them. Returns 0 when every thread returned: the
 * pool stays valid (cancel, busy, notify are no-ops) until gp_pool_free. Otherwise
 * returns how many still run (a stage that ignores its flag, a store write held up):
 * their jobs stay running in the store (queued again at the next start, see
 * --max-job-attempts), and neither the pool nor the store they use may be freed: the
 * caller ends the process. */
int gp_pool_stop(gp_pool *pool, double seconds);
void gp_pool_free(gp_pool *pool);

#endif
