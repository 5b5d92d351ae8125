/* waiters.c - suspended long-poll requests and the thread that expires them, and that
 * sees their clients hang up. */
#define _GNU_SOURCE /* POLLRDHUP */
#include "waiters.h"

#include <poll.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "grainpack/error.h"
#include "log.h"
#include "store.h"

/* The deadline thread wakes at least this often, so a stop is seen promptly. */
#define MAX_SLEEP_SECONDS 1.0

struct gp_waiter {
    void *conn;
    int fd;          /* the connection's socket, watched for the client's hang-up */
    uint64_t serial; /* tells this entry from a later one at the same address */
    char job_id[GP_JOB_ID_SIZE];
    double deadline;
    int suspended; /* the connection is suspended: whoever releases the entry resumes it */
    int woken;     /* woken before it was suspended: the handler answers at once */
    gp_waiter *next;
};

struct gp_waiters {
    pthread_mutex_t lock; /* guards head, stopping, closed; held around suspend/resume */
    gp_waiter *head;
    const gp_suspender *how;
    int stopping;
    int wake_fd;     /* an eventfd: written when the thread must look again (a new
                        suspension, a stop) */
    uint64_t serial; /* of the last entry */
    unsigned long hung_up; /* waits ended because the client closed its connection */
    pthread_t thread;
    struct pollfd *fds; /* the thread's: the wake_fd, then the sockets of the suspended */
    uint64_t *serials;  /* the entry of each socket in fds */
    size_t cap;
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

/* Wakes the deadline thread (a suspension, a stop). */
static void nudge(gp_waiters *w)
{
    uint64_t one = 1;
    if (write(w->wake_fd, &one, sizeof one) < 0) {
        /* the counter is full: the thread is due to wake anyway */
    }
}

/* The list of sockets to watch (lock held): the wake_fd first, then each suspended
 * connection's, for its hang-up only (POLLRDHUP; a client that sends more, a pipelined
 * request, is not a hang-up and must not wake the thread again and again). Returns how
 * many, 1 when out of memory (then only deadlines and nudges count). */
static size_t watch_list(gp_waiters *w)
{
    size_t n = 1;
    for (gp_waiter *e = w->head; e; e = e->next)
        n += e->suspended && e->fd >= 0;
    if (n > w->cap) {
        struct pollfd *fds = realloc(w->fds, n * sizeof *fds);
        if (fds)
            w->fds = fds;
        uint64_t *serials = realloc(w->serials, n * sizeof *serials);
        if (serials)
            w->serials = serials;
        if (!fds || !serials)
            return 1;
        w->cap = n;
    }
    n = 1;
    for (gp_waiter *e = w->head; e; e = e->next) {
        if (e->suspended && e->fd >= 0) {
            w->fds[n] = (struct pollfd){e->fd, POLLRDHUP, 0};
            w->serials[n++] = e->serial;
        }
    }
    return n;
}

/* Releases the entries whose client hung up (lock held): resumed, libmicrohttpd finds the
 * socket closed and frees the connection, and with it its place in the connection
 * limits, at once rather than at the end of the wait. */
static void release_hung_up(gp_waiters *w, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        if (!(w->fds[i].revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)))
            continue;
        for (gp_waiter *e = w->head; e; e = e->next) {
            if (e->serial == w->serials[i]) {
                if (e->suspended) {
                    w->hung_up++;
                    release(w, e);
                }
                break;
            }
        }
    }
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
        size_t n = watch_list(w);
        w->fds[0] = (struct pollfd){w->wake_fd, POLLIN, 0};
        pthread_mutex_unlock(&w->lock);
        int ms = (int)((next - now) * 1e3) + 1;
        if (poll(w->fds, n, ms < 1 ? 1 : ms) > 0 && (w->fds[0].revents & POLLIN)) {
            uint64_t count;
            if (read(w->wake_fd, &count, sizeof count) < 0) {
                /* nothing was pending after all */
            }
        }
        pthread_mutex_lock(&w->lock);
        release_hung_up(w, n);
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
    w->fds = malloc(sizeof *w->fds);
    w->serials = malloc(sizeof *w->serials);
    w->cap = 1;
    w->wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (!w->fds || !w->serials || w->wake_fd < 0 ||
        pthread_create(&w->thread, NULL, deadline_thread, w)) {
        if (w->wake_fd >= 0)
            close(w->wake_fd);
        free(w->fds);
        free(w->serials);
        pthread_mutex_destroy(&w->lock);
        free(w);
        return GP_ENOMEM;
    }
    *out = w;
    return 0;
}

unsigned long gp_waiters_hung_up(gp_waiters *w)
{
    pthread_mutex_lock(&w->lock);
    unsigned long n = w->hung_up;
    pthread_mutex_unlock(&w->lock);
    return n;
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
    nudge(w);
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
    close(w->wake_fd);
    free(w->fds);
    free(w->serials);
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
    e->fd = w->how->socket(conn);
    snprintf(e->job_id, sizeof e->job_id, "%s", job_id);
    pthread_mutex_lock(&w->lock);
    if (w->stopping) {
        pthread_mutex_unlock(&w->lock);
        free(e);
        return NULL;
    }
    e->serial = ++w->serial;
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
        nudge(w); /* the deadline thread watches its socket, and may need to wake sooner */
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
