/* workers.c - worker threads: claim a job, run the pipeline, store what came of it; and
 * the watchdog that stops a job past --max-job-seconds. */
/* SCHED_IDLE (Linux) needs _GNU_SOURCE; the rest of the project keeps _DEFAULT_SOURCE. */
#define _GNU_SOURCE
#include "workers.h"

#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "log.h"

/* Seconds between two progress writes of one job: often enough for a person watching a
 * long job, rare enough that progress never competes with submissions for the write lock. */
#define PROGRESS_INTERVAL 0.25
/* An idle worker looks at the store this often even when nobody notified it (jobs queued
 * by a previous run of the daemon, or a notification that another worker consumed). */
#define IDLE_RECHECK_SECONDS 1

/* Niceness of the worker threads where SCHED_IDLE is refused (under SCHED_IDLE the kernel
 * ignores nice): packing still yields the processors to the HTTP threads, less promptly
 * (on Linux, nice is per thread). Workers take all the time the HTTP side leaves. */
#define WORKER_NICE 19

/* The watchdog looks at the running jobs at least this often (it also wakes when a job
 * starts); a job is stopped at most this late past its limit, plus the engine's own
 * cancel-check interval. */
#define WATCHDOG_SECONDS 0.1

/* When the outcome of a job cannot be stored (disk full, database not writable), the worker
 * keeps it and tries again after this many seconds, doubling up to the maximum: a
 * result is never dropped while the daemon runs, and a stop leaves the job running in
 * the store, to be queued again at the next start. */
#define STORE_RETRY_FIRST 0.25
#define STORE_RETRY_MAX 5.0

/* Values of a worker's cancel flag. */
enum { CANCEL_NONE = 0, CANCEL_DISMISSED = 1, CANCEL_SHUTDOWN = 2, CANCEL_TIMEOUT = 3 };

typedef struct worker {
    gp_pool *pool;
    pthread_t thread;
    gp_cancel_flag cancel;
    char job_id[GP_JOB_ID_SIZE]; /* the job it runs, "" when idle; guarded by pool->lock */
    double deadline;             /* monotonic seconds it must end by, 0: none; pool->lock */
    double started;              /* monotonic seconds it started, for the failure message */
    gp_db *db;                   /* its own connection, for the thread's lifetime */
    double last_write;           /* progress throttling */
    int last_percent;
} worker;

struct gp_pool {
    gp_service *svc;
    pthread_mutex_t lock;
    pthread_cond_t wake;  /* idle workers wait on it */
    pthread_cond_t watch; /* the watchdog waits on it */
    pthread_cond_t retry; /* a worker waiting to store an outcome again waits on it */
    int stopping;
    unsigned pending; /* notifications not yet taken by an idle worker */
    atomic_int busy;
    int n;
    worker *workers;
    pthread_t watchdog;
    int has_watchdog;
};

static void report_progress(void *ctx, const char *stage, double fraction)
{
    worker *w = ctx;
    int percent = (int)(fraction * 100.0);
    percent = percent < 0 ? 0 : (percent > 99 ? 99 : percent); /* 100 means stored */
    if (percent <= w->last_percent)
        return;
    double now = gp_monotonic_seconds();
    if (now - w->last_write < PROGRESS_INTERVAL)
        return;
    char message[64];
    snprintf(message, sizeof message, "running: %s %d%%", stage, percent);
    if (gp_store_progress(w->db, w->job_id, percent, message) == 0) {
        w->last_percent = percent;
        w->last_write = now;
    }
}

/* Publishes or clears the job a worker runs (under the pool lock, so that a cancel
 * either finds it or comes after it is done). */
static void set_current(worker *w, const char *id)
{
    gp_pool *pool = w->pool;
    double limit = pool->svc->cfg->max_job_seconds;
    pthread_mutex_lock(&pool->lock);
    atomic_store(&w->cancel, pool->stopping ? CANCEL_SHUTDOWN : CANCEL_NONE);
    snprintf(w->job_id, sizeof w->job_id, "%s", id);
    w->started = gp_monotonic_seconds();
    w->deadline = id[0] && limit > 0 ? w->started + limit : 0;
    pthread_cond_signal(&pool->watch);
    pthread_mutex_unlock(&pool->lock);
}

/* Converts a monotonic deadline into the realtime clock of condition variables. */
static struct timespec realtime_in(double seconds)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    if (seconds < 0.001)
        seconds = 0.001;
    long long ns = ts.tv_nsec + (long long)(seconds * 1e9);
    ts.tv_sec += (time_t)(ns / 1000000000);
    ts.tv_nsec = (long)(ns % 1000000000);
    return ts;
}

/* Raises CANCEL_TIMEOUT on every job past its deadline; sleeps until the next one. */
static void *watchdog_main(void *arg)
{
    gp_pool *pool = arg;
    pthread_mutex_lock(&pool->lock);
    while (!pool->stopping) {
        double now = gp_monotonic_seconds(), next = now + 1.0;
        for (int i = 0; i < pool->n; i++) {
            worker *w = &pool->workers[i];
            if (!w->job_id[0] || w->deadline <= 0)
                continue;
            if (now >= w->deadline) {
                int none = CANCEL_NONE; /* a dismissal or a stop that came first stays */
                atomic_compare_exchange_strong(&w->cancel, &none, CANCEL_TIMEOUT);
            } else if (w->deadline < next) {
                next = w->deadline;
            }
        }
        double wait = next - now;
        struct timespec ts = realtime_in(wait < WATCHDOG_SECONDS ? wait : WATCHDOG_SECONDS);
        pthread_cond_timedwait(&pool->watch, &pool->lock, &ts);
    }
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}

/* What a run of a job came to, for the store. */
typedef enum outcome_kind { OUTCOME_FINISH, OUTCOME_FAIL } outcome_kind;

static int store_outcome(worker *w, const char *id, outcome_kind kind, const gp_result *result,
                         const char *code, const char *message)
{
    if (kind == OUTCOME_FINISH)
        return gp_store_finish(w->db, id, result);
    return gp_store_fail(w->db, id, code, message);
}

/* Stores the outcome, trying again while the store cannot write it (see
 * STORE_RETRY_FIRST) until it can or the pool stops. Returns the last store result. */
static int persist(worker *w, const char *id, outcome_kind kind, const gp_result *result,
                   const char *code, const char *message)
{
    gp_pool *pool = w->pool;
    double delay = STORE_RETRY_FIRST;
    for (int attempt = 0;; attempt++) {
        if (!w->db)
            w->db = gp_store_acquire(pool->svc->store, 0);
        int rc = w->db ? store_outcome(w, id, kind, result, code, message) : GP_SRV_EDB;
        if (rc == 0 || rc == GP_SRV_ESTATE) {
            if (attempt > 0)
                gp_log("job %s: its outcome is stored after %d attempts", id, attempt + 1);
            return rc;
        }
        if (gp_store_broken(w->db)) { /* a fresh connection sees the file as it is now */
            gp_store_release(pool->svc->store, w->db);
            w->db = NULL;
        }
        pthread_mutex_lock(&pool->lock);
        int stopping = pool->stopping;
        if (!stopping) {
            if (attempt == 0)
                gp_log("job %s: cannot store its outcome (%s); the worker keeps it and tries "
                       "again until the database can be written",
                       id, rc == GP_SRV_EFULL       ? "the disk is full"
                           : rc == GP_SRV_EUNWRITABLE ? "the database cannot be written"
                                                    : "store error");
            struct timespec ts = realtime_in(delay);
            pthread_cond_timedwait(&pool->retry, &pool->lock, &ts);
            stopping = pool->stopping;
        }
        pthread_mutex_unlock(&pool->lock);
        if (stopping) {
            gp_log("job %s: outcome not stored, the daemon is stopping: the job is queued "
                   "again at the next start", id);
            return rc;
        }
        delay = delay * 2 < STORE_RETRY_MAX ? delay * 2 : STORE_RETRY_MAX;
    }
}

/* Records how a run ended, in the store, the metrics and the log. */
static void conclude(worker *w, const char *id, int rc, const gp_result *result,
                     const gp_error *err)
{
    gp_service *svc = w->pool->svc;
    int flag = atomic_load(&w->cancel);
    if (rc == 0) {
        for (int i = 0; i < result->ntimings; i++)
            gp_metrics_stage(svc->metrics, result->timings[i].stage, result->timings[i].seconds);
        int st = persist(w, id, OUTCOME_FINISH, result, NULL, NULL);
        if (st == 0) {
            gp_metrics_outcome(svc->metrics, "successful");
            gp_log("job %s successful: %zu disks, packing density %.4f, %.3f s", id,
                   result->stats.count, result->stats.packing_density,
                   gp_result_stage_seconds(result, "pack"));
        } else if (st == GP_SRV_ESTATE) {
            gp_metrics_outcome(svc->metrics, "discarded");
            gp_log("job %s finished after it was dismissed: result discarded", id);
        }
    } else if (rc == GP_ECANCELED && flag == CANCEL_TIMEOUT) {
        char message[200];
        double limit = svc->cfg->max_job_seconds;
        snprintf(message, sizeof message,
                 "stopped after %.1f s: a job may run at most %g s (--max-job-seconds); "
                 "submit a smaller job, or ask the administrator for a longer limit",
                 gp_monotonic_seconds() - w->started, limit);
        persist(w, id, OUTCOME_FAIL, NULL, "time limit", message);
        gp_metrics_outcome(svc->metrics, "timed_out");
        gp_log("job %s failed: %s", id, message);
    } else if (rc == GP_ECANCELED && flag == CANCEL_SHUTDOWN) {
        /* if this write fails the job stays running in the store: queued again at start */
        if (w->db && gp_store_requeue(w->db, id) == 0)
            atomic_fetch_add(&svc->queued, 1);
        gp_metrics_outcome(svc->metrics, "requeued");
        gp_log("job %s accepted: queued again, the daemon is stopping", id);
    } else if (rc == GP_ECANCELED) {
        gp_metrics_outcome(svc->metrics, "dismissed");
        gp_log("job %s dismissed: worker stopped", id);
    } else {
        int st = persist(w, id, OUTCOME_FAIL, NULL, gp_strerror(rc), err->message);
        gp_metrics_outcome(svc->metrics, "failed");
        gp_log("job %s failed: %s%s", id, err->message,
               st == GP_SRV_ESTATE ? " (it had been dismissed)" : "");
    }
    gp_waiters_wake(svc->waiters, id);
}

static void run_job(worker *w, const char *id, const char *spec_text, size_t spec_len)
{
    gp_service *svc = w->pool->svc;
    set_current(w, id);
    atomic_fetch_sub(&svc->queued, 1);
    atomic_fetch_add(&w->pool->busy, 1);
    gp_log("job %s running", id);
    w->last_percent = 0;
    w->last_write = gp_monotonic_seconds();

    /* the stored spec was valid when accepted; it is parsed again without the caps, which
     * may have been lowered since, so that an accepted job always runs */
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
    gp_spec spec;
    gp_result result;
    gp_error err;
    gp_error_clear(&err);
    memset(&result, 0, sizeof result);
    int rc = gp_spec_parse(spec_text, spec_len, &unlimited, &spec, &err);
    if (rc == 0) {
        /* a mesh stops when it grows far beyond today's cap (the estimate it was accepted
           on may be off; gp_spec.max_elements) */
        spec.max_elements = svc->cfg->max_elements;
        gp_progress progress = {report_progress, w, &w->cancel};
        gp_metrics_pipeline_run(svc->metrics);
        rc = gp_pipeline_run(&spec, svc->cfg->max_disks, &progress, &result, &err);
    }
    conclude(w, id, rc, &result, &err);
    gp_result_free(&result);
    gp_spec_free(&spec);
    atomic_fetch_sub(&w->pool->busy, 1);
    set_current(w, "");
}

/* Waits for a notification, a stop or the recheck interval. Returns 0 when stopping. */
static int wait_for_work(gp_pool *pool)
{
    pthread_mutex_lock(&pool->lock);
    if (!pool->stopping && pool->pending == 0) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_sec += IDLE_RECHECK_SECONDS;
        pthread_cond_timedwait(&pool->wake, &pool->lock, &ts);
    }
    if (pool->pending > 0)
        pool->pending--;
    int go_on = !pool->stopping;
    pthread_mutex_unlock(&pool->lock);
    return go_on;
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    gp_pool *pool = w->pool;
    /* SCHED_IDLE: a woken HTTP thread preempts a packing worker at once. Under SCHED_BATCH
     * and nice 19 the kernel's scheduler (EEVDF) lets the worker finish its slice first:
     * GET p99 8.7-11.5 ms while both workers packed, against 7.9-10.0 ms with SCHED_IDLE
     * (bench/service.sh, 2 cores). The price: under a request load that fills every core,
     * workers get less time (bench/load.sh: 2181-2244 jobs a minute, against 2509-2581). */
    struct sched_param idle = {0};
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0 &&
        setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), WORKER_NICE) != 0)
        gp_log("worker: cannot lower its priority; requests may wait behind packing");
    for (;;) {
        pthread_mutex_lock(&pool->lock);
        int stopping = pool->stopping;
        pthread_mutex_unlock(&pool->lock);
        if (stopping)
            break;
        if (!w->db && !(w->db = gp_store_acquire(pool->svc->store, 0))) {
            if (!wait_for_work(pool)) /* cannot open the database now: try again later */
                break;
            continue;
        }
        char id[GP_JOB_ID_SIZE], *spec_text;
        size_t spec_len;
        int rc = gp_store_claim(w->db, id, &spec_text, &spec_len);
        if (rc == 0) {
            run_job(w, id, spec_text, spec_len);
            free(spec_text);
            continue; /* more may be waiting */
        }
        if (gp_store_broken(w->db)) { /* the next claim on a fresh connection */
            gp_store_release(pool->svc->store, w->db);
            w->db = NULL;
        }
        if (rc == GP_ENOMEM)
            gp_log("worker: out of memory claiming a job");
        if (!wait_for_work(pool))
            break;
    }
    return NULL;
}

int gp_pool_start(gp_service *svc, gp_pool **out)
{
    gp_pool *pool = calloc(1, sizeof *pool);
    int n = svc->cfg->workers;
    if (!pool || !(pool->workers = calloc((size_t)n, sizeof *pool->workers))) {
        free(pool);
        return GP_ENOMEM;
    }
    pool->svc = svc;
    pthread_mutex_init(&pool->lock, NULL);
    pthread_cond_init(&pool->wake, NULL);
    pthread_cond_init(&pool->watch, NULL);
    pthread_cond_init(&pool->retry, NULL);
    for (int i = 0; i < n; i++) {
        worker *w = &pool->workers[i];
        w->pool = pool;
        atomic_init(&w->cancel, CANCEL_NONE);
        if (pthread_create(&w->thread, NULL, worker_main, w)) {
            pool->n = i;
            gp_pool_stop(pool);
            gp_pool_free(pool);
            return GP_ENOMEM;
        }
        pool->n = i + 1;
    }
    if (pthread_create(&pool->watchdog, NULL, watchdog_main, pool)) {
        gp_pool_stop(pool);
        gp_pool_free(pool);
        return GP_ENOMEM;
    }
    pool->has_watchdog = 1;
    *out = pool;
    return 0;
}

void gp_pool_notify(gp_pool *pool)
{
    if (!pool)
        return;
    pthread_mutex_lock(&pool->lock);
    pool->pending++;
    pthread_cond_signal(&pool->wake);
    pthread_mutex_unlock(&pool->lock);
}

int gp_pool_cancel(gp_pool *pool, const char *job_id)
{
    int found = 0;
    if (!pool)
        return 0;
    pthread_mutex_lock(&pool->lock);
    for (int i = 0; i < pool->n; i++) {
        worker *w = &pool->workers[i];
        if (strcmp(w->job_id, job_id) == 0) {
            atomic_store(&w->cancel, CANCEL_DISMISSED);
            found = 1;
        }
    }
    pthread_mutex_unlock(&pool->lock);
    return found;
}

int gp_pool_busy(gp_pool *pool)
{
    return pool ? atomic_load(&pool->busy) : 0;
}

void gp_pool_stop(gp_pool *pool)
{
    if (!pool)
        return;
    pthread_mutex_lock(&pool->lock);
    pool->stopping = 1;
    for (int i = 0; i < pool->n; i++)
        if (pool->workers[i].job_id[0])
            atomic_store(&pool->workers[i].cancel, CANCEL_SHUTDOWN);
    pthread_cond_broadcast(&pool->wake);
    pthread_cond_signal(&pool->watch);
    pthread_cond_broadcast(&pool->retry);
    pthread_mutex_unlock(&pool->lock);
    if (pool->has_watchdog) {
        pthread_join(pool->watchdog, NULL);
        pool->has_watchdog = 0;
    }
    for (int i = 0; i < pool->n; i++) {
        pthread_join(pool->workers[i].thread, NULL);
        gp_store_release(pool->svc->store, pool->workers[i].db);
        pool->workers[i].db = NULL;
    }
    pthread_mutex_lock(&pool->lock);
    pool->n = 0;
    pthread_mutex_unlock(&pool->lock);
}

void gp_pool_free(gp_pool *pool)
{
    if (!pool)
        return;
    pthread_cond_destroy(&pool->wake);
    pthread_cond_destroy(&pool->watch);
    pthread_cond_destroy(&pool->retry);
    pthread_mutex_destroy(&pool->lock);
    free(pool->workers);
    free(pool);
}
