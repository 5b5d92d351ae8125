/* waiters.c - suspended long-poll requests and the thread that expires them. */
#include "waiters.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "grainpack/error.h"
#include "log.h"
#include "store.h"

/* The deadline thread wakes at least this often, so a stop is seen promptly. */
#define MAX_SLEEP_SECONDS 1.0

struct gp_waiter {
    void *conn;
    char job_id[GP_JOB_ID_SIZE];
    double deadline;
    int suspended; /* the connection is suspended: whoever releases the entry resumes it */
    int woken;     /* woken before it was suspended: the handler answers at once */
    gp_waiter *next;
};

struct gp_waiters {
    pthread_mutex_t lock; /* guards head, stopping; held around suspend/resume */
    pthread_cond_t changed;
    gp_waiter *head;
    const gp_suspender *how;
    int stopping;
    pthread_t thread;
};

/* Unlinks e (lock held), resumes it if suspended, frees it. An entry that is not
 * suspended belongs to its handler until gp_waiters_suspend or gp_waiters_cancel: only
 * those free it, so the handler's pointer never dangles. */
static void release(gp_waiters *w, gp_waiter *e)
{
    for (gp_waiter **p = &w->head; *p; p = &(*p)->next) {
        if (*p == e) {
            *p = e->next;
            break;
        }
    }
    if (e->suspended)
        w->how->resume(e->conn);
    free(e);
}

static void *deadline_thread(void *arg)
{
    gp_waiters *w = arg;
    pthread_mutex_lock(&w->lock);
    while (!w->stopping) {
        double now = gp_monotonic_seconds(), next = now + MAX_SLEEP_SECONDS;
        for (gp_waiter *e = w->head, *after; e; e = after) {
            after = e->next;
            if (e->suspended && e->deadline <= now)
                release(w, e);
            else if (e->deadline < next)
                next = e->deadline;
        }
        /* condition variables wait on the realtime clock: convert the interval */
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        double wait = next - now;
        if (wait < 0.001)
            wait = 0.001;
        long long ns = ts.tv_nsec + (long long)(wait * 1e9);
        ts.tv_sec += (time_t)(ns / 1000000000);
        ts.tv_nsec = (long)(ns % 1000000000);
        pthread_cond_timedwait(&w->changed, &w->lock, &ts);
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

int gp_waiters_start(gp_waiters **out, const gp_suspender *how)
{
    gp_waiters *w = calloc(1, sizeof *w);
    if (!w)
        return GP_ENOMEM;
    w->how = how;
    pthread_mutex_init(&w->lock, NULL);
    pthread_cond_init(&w->changed, NULL);
    if (pthread_create(&w->thread, NULL, deadline_thread, w)) {
        pthread_cond_destroy(&w->changed);
        pthread_mutex_destroy(&w->lock);
        free(w);
        return GP_ENOMEM;
    }
    *out = w;
    return 0;
}

/* Wakes e (lock held): resumed now if suspended, else marked for its handler. */
static void wake(gp_waiters *w, gp_waiter *e)
{
    if (e->suspended)
        release(w, e);
    else
        e->woken = 1;
}

void gp_waiters_stop(gp_waiters *w)
{
    if (!w)
        return;
    pthread_mutex_lock(&w->lock);
    w->stopping = 1;
    for (gp_waiter *e = w->head, *after; e; e = after) {
        after = e->next;
        wake(w, e);
    }
    pthread_cond_signal(&w->changed);
    pthread_mutex_unlock(&w->lock);
    pthread_join(w->thread, NULL);
}

void gp_waiters_free(gp_waiters *w)
{
    if (!w)
        return;
    while (w->head) { /* only entries whose handler never came back: none in practice */
        gp_waiter *e = w->head;
        w->head = e->next;
        free(e);
    }
    pthread_cond_destroy(&w->changed);
    pthread_mutex_destroy(&w->lock);
    free(w);
}

gp_waiter *gp_waiters_add(gp_waiters *w, void *conn, const char *job_id, double deadline)
{
    gp_waiter *e = calloc(1, sizeof *e);
    if (!e)
        return NULL;
    e->conn = conn;
    e->deadline = deadline;
    snprintf(e->job_id, sizeof e->job_id, "%s", job_id);
    pthread_mutex_lock(&w->lock);
    if (w->stopping) {
        pthread_mutex_unlock(&w->lock);
        free(e);
        return NULL;
    }
    e->next = w->head;
    w->head = e;
    pthread_mutex_unlock(&w->lock);
    return e;
}

int gp_waiters_suspend(gp_waiters *w, gp_waiter *entry)
{
    pthread_mutex_lock(&w->lock);
    int suspend = !entry->woken && !w->stopping;
    if (suspend) {
        w->how->suspend(entry->conn);
        entry->suspended = 1;
        pthread_cond_signal(&w->changed); /* the deadline thread may need to wake sooner */
    } else {
        release(w, entry);
    }
    pthread_mutex_unlock(&w->lock);
    return suspend;
}

void gp_waiters_cancel(gp_waiters *w, gp_waiter *entry)
{
    pthread_mutex_lock(&w->lock);
    release(w, entry);
    pthread_mutex_unlock(&w->lock);
}

void gp_waiters_wake(gp_waiters *w, const char *job_id)
{
    pthread_mutex_lock(&w->lock);
    for (gp_waiter *e = w->head, *after; e; e = after) {
        after = e->next;
        if (strcmp(e->job_id, job_id) == 0)
            wake(w, e);
    }
    pthread_mutex_unlock(&w->lock);
}
