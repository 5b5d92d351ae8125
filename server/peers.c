/* peers.c - a small hash table of client addresses and their open connections, and the
 * watcher of request heads. */
#include "peers.h"

#include <netinet/in.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>

#include "grainpack/error.h"
#include "log.h"

/* How often the watcher looks at the heads: a slow head is closed at most this late. */
#define WATCH_SECONDS 0.25

/* Buckets of the table: a power of two; far more than the addresses a departmental
 * service sees at once, so chains stay short. */
#define BUCKETS 1024

struct peer_entry {
    unsigned char addr[16]; /* IPv4 mapped into IPv6, so that both compare alike */
    unsigned open;
    struct peer_entry *next;
};

struct gp_peers {
    pthread_mutex_t lock; /* guards every bucket, every record and the list */
    struct peer_entry *bucket[BUCKETS];
    gp_peer_conn *conns;  /* every open connection with a record */
    pthread_cond_t stop;  /* the watcher sleeps on it */
    pthread_t watcher;
    int watching, stopping;
    double head_seconds;
    char answer[512];     /* the 408 sent before a slow head's connection is shut */
    size_t answer_len;
    unsigned long timed_out;
    gp_peer_counts *counts; /* the caller's (gp_peers_new) */
};

gp_peers *gp_peers_new(gp_peer_counts *counts)
{
    gp_peers *p = calloc(1, sizeof *p);
    if (p) {
        p->counts = counts;
        pthread_mutex_init(&p->lock, NULL);
        pthread_cond_init(&p->stop, NULL);
    }
    return p;
}

void gp_peers_free(gp_peers *p)
{
    if (!p)
        return;
    if (p->watching) {
        pthread_mutex_lock(&p->lock);
        p->stopping = 1;
        pthread_cond_signal(&p->stop);
        pthread_mutex_unlock(&p->lock);
        pthread_join(p->watcher, NULL);
    }
    pthread_cond_destroy(&p->stop);
    for (size_t i = 0; i < BUCKETS; i++) {
        while (p->bucket[i]) {
            struct peer_entry *e = p->bucket[i];
            p->bucket[i] = e->next;
            free(e);
        }
    }
    pthread_mutex_destroy(&p->lock);
    free(p);
}

/* The 16-byte key of addr; 0, or -1 for another family. */
static int address_key(const struct sockaddr *addr, unsigned char key[16])
{
    memset(key, 0, 16);
    if (addr->sa_family == AF_INET) {
        const struct sockaddr_in *v4 = (const struct sockaddr_in *)(const void *)addr;
        key[10] = key[11] = 0xff;
        memcpy(key + 12, &v4->sin_addr, 4);
        return 0;
    }
    if (addr->sa_family == AF_INET6) {
        memcpy(key, &((const struct sockaddr_in6 *)(const void *)addr)->sin6_addr, 16);
        return 0;
    }
    return -1;
}

/* FNV-1a over the key. */
static size_t bucket_of(const unsigned char key[16])
{
    uint32_t h = 2166136261u;
    for (int i = 0; i < 16; i++)
        h = (h ^ key[i]) * 16777619u;
    return h & (BUCKETS - 1);
}

gp_peer_conn *gp_peers_opened(gp_peers *p, const struct sockaddr *addr, unsigned limit, int fd)
{
    unsigned char key[16];
    if (!addr || address_key(addr, key))
        return NULL;
    gp_peer_conn *conn = calloc(1, sizeof *conn);
    if (!conn)
        return NULL;
    size_t b = bucket_of(key);
    pthread_mutex_lock(&p->lock);
    struct peer_entry *e = p->bucket[b];
    while (e && memcmp(e->addr, key, 16) != 0)
        e = e->next;
    if (!e && (e = calloc(1, sizeof *e))) {
        memcpy(e->addr, key, 16);
        e->next = p->bucket[b];
        p->bucket[b] = e;
    }
    if (e) {
        conn->entry = e;
        conn->open = ++e->open;
        conn->over_limit = conn->open > limit;
        conn->fd = fd;
        conn->in_head = 1;
        conn->head_since = gp_monotonic_seconds();
        conn->next = p->conns;
        if (p->conns)
            p->conns->prev = conn;
        p->conns = conn;
        atomic_fetch_add(&p->counts->open, 1);
    }
    pthread_mutex_unlock(&p->lock);
    if (!e) {
        free(conn);
        return NULL;
    }
    return conn;
}

void gp_peers_closed(gp_peers *p, gp_peer_conn *conn)
{
    if (!conn)
        return;
    struct peer_entry *e = conn->entry;
    pthread_mutex_lock(&p->lock);
    if (conn->prev)
        conn->prev->next = conn->next;
    else
        p->conns = conn->next;
    if (conn->next)
        conn->next->prev = conn->prev;
    if (--e->open == 0) { /* forget the address: the table holds open connections only */
        struct peer_entry **link = &p->bucket[bucket_of(e->addr)];
        while (*link != e)
            link = &(*link)->next;
        *link = e->next;
        free(e);
    }
    atomic_fetch_sub(&p->counts->open, 1);
    pthread_mutex_unlock(&p->lock);
    free(conn);
}

void gp_peers_line_in(gp_peers *p, gp_peer_conn *conn)
{
    if (!conn)
        return;
    pthread_mutex_lock(&p->lock);
    conn->line_in = 1;
    pthread_mutex_unlock(&p->lock);
}

void gp_peers_head_done(gp_peers *p, gp_peer_conn *conn)
{
    if (!conn)
        return;
    pthread_mutex_lock(&p->lock);
    conn->in_head = 0;
    pthread_mutex_unlock(&p->lock);
}

void gp_peers_head_begins(gp_peers *p, gp_peer_conn *conn)
{
    if (!conn)
        return;
    pthread_mutex_lock(&p->lock);
    conn->in_head = 1;
    conn->line_in = 0;
    conn->head_since = gp_monotonic_seconds();
    pthread_mutex_unlock(&p->lock);
}

/* Closes every connection whose head is late (lock held): the 408 (when its request line
 * came), then a shutdown, which libmicrohttpd sees as the client's end and closes the
 * connection itself. */
static void close_late_heads(gp_peers *p, double now)
{
    for (gp_peer_conn *c = p->conns; c; c = c->next) {
        if (!c->in_head || c->timed_out || now - c->head_since < p->head_seconds)
            continue;
        /* bytes the daemon has not read yet: the delay is its own (each HTTP thread busy,
         * say with a big download), not the client's; such a head is looked at again once
         * they are read (bench/hostile.py downloads: without this, requests queued behind
         * four big downloads were closed unanswered) */
        int unread = 0;
        if (ioctl(c->fd, FIONREAD, &unread) == 0 && unread > 0)
            continue;
        c->timed_out = 1;
        p->timed_out++;
        atomic_fetch_add(&p->counts->slow_heads, 1);
        /* best effort, never blocking: a client that does not read it is closed anyway */
        if (c->line_in && send(c->fd, p->answer, p->answer_len, MSG_DONTWAIT | MSG_NOSIGNAL) < 0) {
            /* nothing to do: the shutdown below closes it */
        }
        shutdown(c->fd, SHUT_RDWR);
    }
}

static void *watch_main(void *arg)
{
    gp_peers *p = arg;
    pthread_mutex_lock(&p->lock);
    while (!p->stopping) {
        unsigned long before = p->timed_out;
        close_late_heads(p, gp_monotonic_seconds());
        if (p->timed_out != before)
            gp_log("http: %lu connections did not send a whole request head within %g s: "
                   "closed (with a 408 when the request line had come)", p->timed_out - before,
                   p->head_seconds);
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        long long ns = ts.tv_nsec + (long long)(WATCH_SECONDS * 1e9);
        ts.tv_sec += (time_t)(ns / 1000000000);
        ts.tv_nsec = (long)(ns % 1000000000);
        pthread_cond_timedwait(&p->stop, &p->lock, &ts);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

int gp_peers_watch(gp_peers *p, double seconds)
{
    p->head_seconds = seconds;
    char body[256];
    int blen = snprintf(body, sizeof body,
                        "{\"type\":\"urn:grainpack:problem:request-timeout\",\"title\":"
                        "\"Request Timeout\",\"status\":408,\"detail\":\"the request head "
                        "(request line and headers) did not arrive within %g s "
                        "(--connection-timeout)\"}",
                        seconds);
    int n = snprintf(p->answer, sizeof p->answer,
                     "HTTP/1.1 408 Request Timeout\r\nConnection: close\r\n"
                     "Content-Type: application/problem+json\r\nContent-Length: %d\r\n\r\n%s",
                     blen, body);
    p->answer_len = (size_t)n;
    if (pthread_create(&p->watcher, NULL, watch_main, p))
        return GP_ENOMEM;
    p->watching = 1;
    return 0;
}
