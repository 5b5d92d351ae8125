/* peers.c - a small hash table of client addresses and their open connections. */
#include "peers.h"

#include <netinet/in.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Buckets of the table: a power of two; far more than the addresses a departmental
 * service sees at once, so chains stay short. */
#define BUCKETS 1024

struct peer_entry {
    unsigned char addr[16]; /* IPv4 mapped into IPv6, so that both compare alike */
    unsigned open;
    struct peer_entry *next;
};

struct gp_peers {
    pthread_mutex_t lock; /* guards every bucket */
    struct peer_entry *bucket[BUCKETS];
};

gp_peers *gp_peers_new(void)
{
    gp_peers *p = calloc(1, sizeof *p);
    if (p)
        pthread_mutex_init(&p->lock, NULL);
    return p;
}

void gp_peers_free(gp_peers *p)
{
    if (!p)
        return;
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

gp_peer_conn *gp_peers_opened(gp_peers *p, const struct sockaddr *addr, unsigned limit)
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
    if (--e->open == 0) { /* forget the address: the table holds open connections only */
        struct peer_entry **link = &p->bucket[bucket_of(e->addr)];
        while (*link != e)
            link = &(*link)->next;
        *link = e->next;
        free(e);
    }
    pthread_mutex_unlock(&p->lock);
    free(conn);
}
