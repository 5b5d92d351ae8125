/* workers.c - worker threads: claim a job, run the pipeline, store what came of it; the
 * watchdog that stops a job past --max-job-seconds and replaces a worker that does not
 * stop when told; the bounded stop. */
/* SCHED_IDLE (Linux) needs _GNU_SOURCE; the rest of the project keeps _DEFAULT_SOURCE. */
#define _GNU_SOURCE
#include "workers.h"

#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "log.h"
#include "processes.h"

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

/* A worker told to stop (dismissed, timed out) that still runs this many seconds later
 * is given up on: another thread takes its place, and it frees itself if it ever returns.
 * Every stage reads its flag within milliseconds (bench/CANCEL.md: under 0.1 s of CPU for
 * a million disks, freeing included), so only a stage that ignores it, or a store write
 * held up (sqlite waits up to 30 s for another process's write lock), comes this far.
 * The seconds exclude the time the worker waited for a processor (its run-queue wait,
 * from /proc's schedstat): a SCHED_IDLE worker on a loaded machine may get no processor
 * for seconds, and was then never given the chance to read its flag (test_service_limits
 * saw a job stopped by a 0.2 s limit given up on at a load of 20). */
#define ABANDON_SECONDS 2.0

/* ... and in any case this many seconds of wall-clock time after its flag: at a load of
 * 35 on 2 cores, a SCHED_IDLE worker spinning in the issue-18 histogram job took 58 s to
 * be given 2 s of its own (bench/CANCEL.md); past this bound its job fails and its slot
 * goes to another worker, whatever the load. */
#define ABANDON_WALL_SECONDS 20.0

/* At most this many workers given up on, per worker of the pool, still run: beyond, the
 * pool stops replacing them rather than start threads without end (each one that never
 * returns takes what processor time the others leave: they all run at the lowest
 * priority). Their jobs are failed all the same. */
#define ABANDONED_PER_WORKER 4

/* How long a failed start waits for the workers it started (idle: they return at once). */
#define STARTUP_STOP_SECONDS 10.0

/* A test-only fault (never set in production): the environment variable
 * GRAINPACKD_TEST_STALL_SECONDS makes the first job the daemon runs sleep that long at
 * its start without reading its cancel flag, as a stage that ignores the flag would. The
 * service tests use it to check that the pool replaces such a worker, that a stop stays
 * bounded, and what a restart does with the job. */
#define TEST_STALL_ENV "GRAINPACKD_TEST_STALL_SECONDS"

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
    double canceled_at;          /* monotonic seconds its flag was raised, 0: not; pool->lock */
    double queued_at_cancel;     /* its run-queue wait then (run_queue_seconds); pool->lock */
    pid_t tid;                   /* its thread's id, for /proc; pool->lock */
    int abandoned;               /* given up on and replaced (see ABANDON_SECONDS); pool->lock */
    int given_up;                /* given up on but kept in its slot, no replacement
                                    possible (its job recorded as for one replaced) */
    int storing;                 /* its pipeline returned, the outcome is being stored: no
                                    time limit, no giving up any more; pool->lock */
    gp_db *db;                   /* its own connection, for the thread's lifetime */
    double last_write;           /* progress throttling */
    int last_percent;
    const char *stages[GP_PROCESS_MAX_STAGES]; /* the stages of the job (its process's) */
    int nstages;
} worker;

struct gp_pool {
    gp_service *svc;
    pthread_mutex_t lock;
    pthread_cond_t wake;  /* idle workers wait on it */
    pthread_cond_t watch; /* the watchdog waits on it */
    pthread_cond_t retry; /* a worker waiting to store an outcome again waits on it */
    pthread_cond_t gone;  /* a worker thread returned */
    int stopping;
    unsigned pending; /* notifications not yet taken by an idle worker */
    atomic_int busy;
    int n;
    worker **workers;  /* the n slots; a slot's worker is replaced when given up on */
    int alive;         /* threads not yet returned: workers (given-up ones included) and
                          the watchdog; lock */
    atomic_int abandoned; /* given-up worker threads still running */
    double stall;      /* the test fault's seconds (TEST_STALL_ENV), 0: none */
    atomic_int stalled; /* the test fault struck already */
    pthread_t watchdog;
    int has_watchdog;
    gp_db *watchdog_db; /* the watchdog's connection, to fail a job given up on */
};

static void report_progress(void *ctx, const char *stage, double fraction)
{
    worker *w = ctx;
    /* the job's progress: each stage the spec runs has an equal share, in order, so that
     * it only rises; the message names the stage and how far it got */
    int k = 0;
    while (k < w->nstages - 1 && strcmp(w->stages[k], stage) != 0)
        k++;
    double overall = ((double)k + (fraction < 0 ? 0 : fraction > 1 ? 1 : fraction)) / w->nstages;
    int percent = (int)(overall * 100.0), local = (int)(fraction * 100.0);
    percent = percent < 0 ? 0 : (percent > 99 ? 99 : percent); /* 100 means stored */
    if (percent <= w->last_percent)
        return;
    double now = gp_monotonic_seconds();
    if (now - w->last_write < PROGRESS_INTERVAL)
        return;
    char message[64];
    snprintf(message, sizeof message, "running: %s %d%%", stage, local < 0 ? 0 : local > 99 ? 99 : local);
    if (gp_store_progress(w->db, w->job_id, percent, message) == 0) {
        w->last_percent = percent;
        w->last_write = now;
    }
}

/* The test fault (TEST_STALL_ENV): the first job the daemon runs sleeps at its start,
 * before the pipeline could read its flag, so that a flag raised at once (a DELETE right
 * after the job is seen running, a short time limit on a loaded machine) cannot let it
 * end and leave the fault to the next job. */
static void test_stall(worker *w, const char *id)
{
    gp_pool *pool = w->pool;
    if (pool->stall <= 0 || atomic_exchange(&pool->stalled, 1) != 0)
        return;
    gp_log("job %s: test fault, its worker sleeps %g s without reading its flag", id, pool->stall);
    struct timespec ts = {(time_t)pool->stall, (long)((pool->stall - (double)(time_t)pool->stall) * 1e9)};
    while (nanosleep(&ts, &ts) != 0)
        ;
}

/* Seconds the thread tid has waited for a processor since it started (the second field
 * of /proc/self/task/TID/schedstat), or -1 when the kernel does not say. */
static double run_queue_seconds(pid_t tid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/self/task/%ld/schedstat", (long)tid);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    unsigned long long ran, waited;
    int got = fscanf(f, "%llu %llu", &ran, &waited);
    fclose(f);
    return got == 2 ? (double)waited * 1e-9 : -1;
}

/* Seconds the worker has had to stop since its flag was raised (pool->lock held): the
 * time since then, less what it spent waiting for a processor. */
static double time_to_stop(const worker *w, double now)
{
    double queued = w->queued_at_cancel >= 0 ? run_queue_seconds(w->tid) : -1;
    return now - w->canceled_at - (queued >= 0 ? queued - w->queued_at_cancel : 0);
}

/* Starts the clock of ABANDON_SECONDS (pool->lock held). */
static void start_stop_clock(worker *w, double now)
{
    w->canceled_at = now;
    w->queued_at_cancel = w->tid ? run_queue_seconds(w->tid) : -1;
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
    w->canceled_at = 0;
    if (pool->stopping)
        start_stop_clock(w, w->started);
    w->storing = 0;
    w->given_up = 0;
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

#define TIMEOUT_MESSAGE_SIZE 256

/* The message of a job stopped by --max-job-seconds after `ran` seconds. */
static void timeout_message(char out[TIMEOUT_MESSAGE_SIZE], double ran, double limit)
{
    snprintf(out, TIMEOUT_MESSAGE_SIZE,
             "stopped after %.1f s: a job may run at most %g s (--max-job-seconds); "
             "submit a smaller job, or ask the administrator for a longer limit",
             ran, limit);
}

/* Raises w's cancel flag (pool->lock held). A timeout does not replace a dismissal or a
 * stop that came first; the first raise starts the ABANDON_SECONDS clock. */
static void raise_cancel(worker *w, int why, double now)
{
    if (why == CANCEL_TIMEOUT) {
        int none = CANCEL_NONE;
        atomic_compare_exchange_strong(&w->cancel, &none, CANCEL_TIMEOUT);
    } else {
        atomic_store(&w->cancel, why);
    }
    if (w->canceled_at <= 0)
        start_stop_clock(w, now);
}

static void *worker_main(void *arg);

/* Starts a worker thread in slot i (pool->lock held). Returns 0 or GP_ENOMEM. */
static int start_worker(gp_pool *pool, int i)
{
    worker *w = calloc(1, sizeof *w);
    if (!w)
        return GP_ENOMEM;
    w->pool = pool;
    atomic_init(&w->cancel, CANCEL_NONE);
    if (pthread_create(&w->thread, NULL, worker_main, w)) {
        free(w);
        return GP_ENOMEM;
    }
    pool->workers[i] = w;
    pool->alive++;
    return 0;
}

/* A job whose worker was given up on. */
typedef struct given_up {
    char id[GP_JOB_ID_SIZE];
    int why;
    double ran;
    int replaced; /* another worker took its place */
} given_up;

/* Gives up on the worker in slot i, told to stop ABANDON_SECONDS ago and still running
 * (pool->lock held): another thread takes its place when one can be started (under the
 * ABANDONED_PER_WORKER cap), else it stays in its slot. Either way its job goes to *job,
 * to be recorded. Returns 1 when replaced, 0 when not. */
static int abandon(gp_pool *pool, int i, double now, given_up *job)
{
    worker *w = pool->workers[i];
    snprintf(job->id, sizeof job->id, "%s", w->job_id);
    job->why = atomic_load(&w->cancel);
    job->ran = now - w->started;
    job->replaced = atomic_load(&pool->abandoned) < ABANDONED_PER_WORKER * pool->n &&
                    start_worker(pool, i) == 0;
    if (!job->replaced) {
        pool->workers[i] = w;
        w->given_up = 1;
        return 0;
    }
    w->abandoned = 1;
    pthread_detach(w->thread);
    atomic_fetch_add(&pool->abandoned, 1);
    atomic_fetch_sub(&pool->busy, 1);
    return 1;
}

/* Records that a job's worker was given up on: a timed-out job fails (a dismissed one
 * already is), its waiters are woken. Called without pool->lock. */
static void record_given_up(gp_pool *pool, const given_up *job)
{
    gp_service *svc = pool->svc;
    gp_log("job %s: its worker did not stop within %.0f s of being told to (%s); %s",
           job->id, ABANDON_SECONDS,
           job->why == CANCEL_TIMEOUT ? "time limit" : job->why == CANCEL_DISMISSED ? "dismissed" : "stop",
           job->replaced ? "another worker takes its place, and the job's result is dropped if it "
                           "ever comes"
                         : "too many workers were given up on already: it keeps its place "
                           "(restart the daemon to get it back)");
    gp_metrics_outcome(svc->metrics, "abandoned");
    if (job->why == CANCEL_TIMEOUT) {
        char message[TIMEOUT_MESSAGE_SIZE];
        timeout_message(message, job->ran, svc->cfg->max_job_seconds);
        if (!pool->watchdog_db)
            pool->watchdog_db = gp_store_acquire(svc->store, 0);
        if (!pool->watchdog_db || gp_store_fail(pool->watchdog_db, job->id, "time limit", message) < 0)
            gp_log("job %s: cannot record its failure now; it is queued again at the next start",
                   job->id);
        if (gp_store_broken(pool->watchdog_db)) {
            gp_store_release(svc->store, pool->watchdog_db);
            pool->watchdog_db = NULL;
        }
    }
    gp_waiters_wake(svc->waiters, job->id);
}

/* Raises CANCEL_TIMEOUT on every job past its deadline, gives up on workers that do not
 * stop; sleeps until the next deadline. */
static void *watchdog_main(void *arg)
{
    gp_pool *pool = arg;
    pthread_mutex_lock(&pool->lock);
    while (!pool->stopping) {
        double now = gp_monotonic_seconds(), next = now + 1.0;
        for (int i = 0; i < pool->n; i++) {
            worker *w = pool->workers[i];
            if (!w->job_id[0] || w->storing || w->given_up)
                continue;
            if (w->deadline > 0 && now >= w->deadline)
                raise_cancel(w, CANCEL_TIMEOUT, now);
            else if (w->deadline > 0 && w->deadline < next)
                next = w->deadline;
            given_up job;
            if (w->canceled_at > 0 && (time_to_stop(w, now) >= ABANDON_SECONDS ||
                                       now - w->canceled_at >= ABANDON_WALL_SECONDS)) {
                abandon(pool, i, now, &job);
                pthread_mutex_unlock(&pool->lock);
                record_given_up(pool, &job);
                pthread_mutex_lock(&pool->lock);
                if (pool->stopping)
                    break;
            }
        }
        double wait = next - now;
        struct timespec ts = realtime_in(wait < WATCHDOG_SECONDS ? wait : WATCHDOG_SECONDS);
        pthread_cond_timedwait(&pool->watch, &pool->lock, &ts);
    }
    pthread_mutex_unlock(&pool->lock);
    gp_store_release(pool->svc->store, pool->watchdog_db);
    pool->watchdog_db = NULL;
    pthread_mutex_lock(&pool->lock);
    pool->alive--;
    pthread_cond_broadcast(&pool->gone);
    pthread_mutex_unlock(&pool->lock);
    return NULL;
}

/* What a run of a job came to, for the store. */
typedef enum outcome_kind { OUTCOME_FINISH, OUTCOME_FAIL } outcome_kind;

static int store_outcome(worker *w, const char *id, outcome_kind kind, const gp_outcome *result,
                         const char *code, const char *message)
{
    if (kind == OUTCOME_FINISH)
        return gp_store_finish_outcome(w->db, id, result);
    return gp_store_fail(w->db, id, code, message);
}

/* Stores the outcome, trying again while the store cannot write it (see
 * STORE_RETRY_FIRST) until it can or the pool stops. Returns the last store result. */
static int persist(worker *w, const char *id, outcome_kind kind, const gp_outcome *result,
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
static void conclude(worker *w, const char *id, int rc, const gp_process_run *run,
                     const gp_error *err)
{
    gp_service *svc = w->pool->svc;
    int flag = atomic_load(&w->cancel);
    if (rc == 0) {
        const gp_outcome *result = &run->outcome;
        double pack = 0.0;
        for (int i = 0; i < result->ntimings; i++) {
            gp_metrics_stage(svc->metrics, result->timings[i].stage, result->timings[i].seconds);
            if (strcmp(result->timings[i].stage, "pack") == 0)
                pack = result->timings[i].seconds;
        }
        int st = persist(w, id, OUTCOME_FINISH, result, NULL, NULL);
        if (st == 0) {
            gp_metrics_outcome(svc->metrics, "successful");
            gp_log("job %s successful: %zu %s, packing density %.4f, %.3f s", id, run->count,
                   result->noun, run->density, pack);
        } else if (st == GP_SRV_ESTATE) {
            gp_metrics_outcome(svc->metrics, "discarded");
            gp_log("job %s finished after it was dismissed: result discarded", id);
        }
    } else if (rc == GP_ECANCELED && flag == CANCEL_TIMEOUT) {
        char message[TIMEOUT_MESSAGE_SIZE];
        timeout_message(message, gp_monotonic_seconds() - w->started, svc->cfg->max_job_seconds);
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
}

static void run_job(worker *w, const char *id, const char *spec_text, size_t spec_len)
{
    gp_service *svc = w->pool->svc;
    set_current(w, id);
    atomic_fetch_add(&w->pool->busy, 1);
    gp_log("job %s running", id);
    w->last_percent = 0;
    w->last_write = gp_monotonic_seconds();

    /* the stored spec was valid when accepted; it is parsed again without the caps, which
     * may have been lowered since, so that an accepted job always runs; its process is
     * the one the text is for */
    const gp_process_def *process = gp_process_of_spec(spec_text, spec_len);
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
    void *spec = NULL;
    gp_process_run result;
    gp_error err;
    gp_error_clear(&err);
    memset(&result, 0, sizeof result);
    int rc = process->parse(spec_text, spec_len, &unlimited, &spec, &err);
    if (rc == 0) {
        test_stall(w, id);
        w->nstages = process->stages(spec, w->stages, GP_PROCESS_MAX_STAGES);
        gp_progress progress = {report_progress, w, &w->cancel};
        gp_metrics_pipeline_run(svc->metrics);
        rc = process->run(spec, svc->cfg, &progress, &result, &err);
    }
    pthread_mutex_lock(&w->pool->lock);
    /* a worker given up on had its job recorded then (failed, or dismissed already): what
     * it brings back now is dropped, whether it was replaced or kept its slot */
    int abandoned = w->abandoned, kept = w->given_up;
    w->storing = 1;
    pthread_mutex_unlock(&w->pool->lock);
    if (abandoned || kept)
        gp_log("job %s: the worker given up on returned after %.1f s; its outcome is dropped", id,
               gp_monotonic_seconds() - w->started);
    else
        conclude(w, id, rc, &result, &err);
    if (rc == 0)
        process->free_run(&result);
    if (spec)
        process->free_spec(spec);
    if (!abandoned) {
        int was_last = atomic_fetch_sub(&w->pool->busy, 1) == 1;
        set_current(w, "");
        /* after the worker is idle: whoever sees the job final sees the worker free */
        gp_waiters_wake(svc->waiters, id);
        /* the pipeline's large blocks went back to malloc's arenas, which glibc keeps
         * mapped: a daemon idle after one 10^6-grain job held 263 MB. When no job runs, the
         * free pages go back to the system (a few ms, once per job at most) */
        if (was_last)
            malloc_trim(0);
    }
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

/* A worker thread's end: its connection back, the pool told; a worker given up on
 * frees itself (its slot has another). */
static void *worker_exit(worker *w)
{
    gp_pool *pool = w->pool;
    gp_store_release(pool->svc->store, w->db);
    w->db = NULL;
    pthread_mutex_lock(&pool->lock);
    int abandoned = w->abandoned;
    if (abandoned)
        atomic_fetch_sub(&pool->abandoned, 1);
    pool->alive--;
    pthread_cond_broadcast(&pool->gone);
    pthread_mutex_unlock(&pool->lock);
    if (abandoned)
        free(w);
    return NULL;
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
    pthread_mutex_lock(&pool->lock);
    w->tid = (pid_t)syscall(SYS_gettid);
    pthread_mutex_unlock(&pool->lock);
    struct sched_param idle = {0};
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0 &&
        setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), WORKER_NICE) != 0)
        gp_log("worker: cannot lower its priority; requests may wait behind packing");
    for (;;) {
        pthread_mutex_lock(&pool->lock);
        int stopping = pool->stopping || w->abandoned;
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
        int rc = gp_store_claim(w->db, &pool->svc->queued, id, &spec_text, &spec_len);
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
    return worker_exit(w);
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
    const char *stall = getenv(TEST_STALL_ENV);
    pool->stall = stall ? atof(stall) : 0.0;
    pthread_mutex_init(&pool->lock, NULL);
    pthread_cond_init(&pool->wake, NULL);
    pthread_cond_init(&pool->watch, NULL);
    pthread_cond_init(&pool->retry, NULL);
    pthread_cond_init(&pool->gone, NULL);
    atomic_init(&pool->abandoned, 0);
    atomic_init(&pool->stalled, 0);
    pthread_mutex_lock(&pool->lock);
    int rc = 0;
    for (int i = 0; i < n && rc == 0; i++)
        if ((rc = start_worker(pool, i)) == 0)
            pool->n = i + 1;
    if (rc == 0 && pthread_create(&pool->watchdog, NULL, watchdog_main, pool))
        rc = GP_ENOMEM;
    pool->has_watchdog = rc == 0;
    pool->alive += pool->has_watchdog;
    pthread_mutex_unlock(&pool->lock);
    if (rc) {
        /* the workers started are idle: they return at once */
        if (gp_pool_stop(pool, STARTUP_STOP_SECONDS) == 0)
            gp_pool_free(pool);
        return rc;
    }
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
    double now = gp_monotonic_seconds();
    for (int i = 0; i < pool->n; i++) {
        worker *w = pool->workers[i];
        if (strcmp(w->job_id, job_id) == 0) {
            raise_cancel(w, CANCEL_DISMISSED, now);
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

int gp_pool_abandoned(gp_pool *pool)
{
    return pool ? atomic_load(&pool->abandoned) : 0;
}

int gp_pool_stop(gp_pool *pool, double seconds)
{
    if (!pool)
        return 0;
    pthread_mutex_lock(&pool->lock);
    pool->stopping = 1;
    double now = gp_monotonic_seconds();
    for (int i = 0; i < pool->n; i++)
        if (pool->workers[i]->job_id[0])
            raise_cancel(pool->workers[i], CANCEL_SHUTDOWN, now);
    pthread_cond_broadcast(&pool->wake);
    pthread_cond_signal(&pool->watch);
    pthread_cond_broadcast(&pool->retry);
    /* every thread returns within milliseconds of its flag, unless a stage ignores it or
     * a store write is held up (the watchdog's too): then the stop gives up after
     * `seconds` */
    double deadline = now + seconds;
    while (pool->alive > atomic_load(&pool->abandoned) && gp_monotonic_seconds() < deadline) {
        struct timespec ts = realtime_in(deadline - gp_monotonic_seconds());
        pthread_cond_timedwait(&pool->gone, &pool->lock, &ts);
    }
    int running = pool->alive; /* those given up on are not waited for: their jobs are done */
    pthread_mutex_unlock(&pool->lock);
    if (running)
        return running;
    if (pool->has_watchdog) {
        pthread_join(pool->watchdog, NULL);
        pool->has_watchdog = 0;
    }
    for (int i = 0; i < pool->n; i++) {
        pthread_join(pool->workers[i]->thread, NULL);
        free(pool->workers[i]);
        pool->workers[i] = NULL;
    }
    pthread_mutex_lock(&pool->lock);
    pool->n = 0;
    pthread_mutex_unlock(&pool->lock);
    return 0;
}

void gp_pool_free(gp_pool *pool)
{
    if (!pool)
        return;
    pthread_cond_destroy(&pool->wake);
    pthread_cond_destroy(&pool->watch);
    pthread_cond_destroy(&pool->retry);
    pthread_cond_destroy(&pool->gone);
    pthread_mutex_destroy(&pool->lock);
    free(pool->workers);
    free(pool);
}
