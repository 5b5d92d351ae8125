/* peers.h - the open connections: how many per client address, for
 * --max-connections-per-ip, and the deadline of each one's request head. A connection
 * over the limit is still accepted, so that its first request can be answered with a 429
 * problem saying why (then it is closed); libmicrohttpd's own per-address limit, set a
 * margin above, drops a flood before it costs more than a socket.
 *
 * libmicrohttpd's --connection-timeout only closes a connection that stays silent: one
 * that trickles a byte now and then keeps it for ever. So a watcher thread closes every
 * connection whose request head is not complete within the head deadline of its start
 * (the connection's opening, or the end of its previous response): with a 408 first when
 * its request line has come (a connection that sent nothing more since its last response
 * is closed without one: its client could take a 408 for the answer to the request it
 * sends next).
 *
 * Locking: one mutex guards the table and every record; HTTP threads open and close
 * connections at will. libmicrohttpd tells of a closed connection (gp_peers_closed)
 * before it closes the socket, so the watcher, under the mutex, only ever touches a
 * socket that is still the connection's. */
#ifndef GRAINPACKD_PEERS_H
#define GRAINPACKD_PEERS_H

#include <stdatomic.h>
#include <sys/socket.h>

typedef struct gp_peers gp_peers;

/* One open connection, owned by the table from gp_peers_opened to gp_peers_closed. */
typedef struct gp_peer_conn {
    struct peer_entry *entry;
    unsigned open;  /* connections from the address when this one opened, itself included */
    int over_limit; /* open > the limit: answer 429 and close */
    /* the rest is the table's (under its mutex) */
    int fd;            /* the socket */
    int in_head;       /* waiting for a request head (not yet complete) */
    int line_in;       /* ... of which the request line has come */
    int timed_out;     /* the watcher closed it */
    double head_since; /* monotonic seconds the head began */
    struct gp_peer_conn *prev, *next;
} gp_peer_conn;

/* What the table counts for /metrics, kept by its caller (gp_service) so that the routes
 * read them without linking this file. */
typedef struct gp_peer_counts {
    atomic_long open;        /* connections open (with a record) */
    atomic_ulong slow_heads; /* connections the watcher closed for a late head */
} gp_peer_counts;

/* A new empty table counting into *counts (not owned: it must outlive the table), or
 * NULL when out of memory. */
gp_peers *gp_peers_new(gp_peer_counts *counts);
void gp_peers_free(gp_peers *p);

/* A connection from addr opened on socket fd; `limit` is the most connections allowed
 * from one address. Its head deadline runs from now. Returns its record, or NULL when out
 * of memory (the connection is then not counted) or addr is not IPv4/IPv6. */
gp_peer_conn *gp_peers_opened(gp_peers *p, const struct sockaddr *addr, unsigned limit, int fd);

/* The connection's request line has come, its request head is complete (its deadline
 * stops), or a new one begins (its previous response was sent). NULL is a no-op. */
void gp_peers_line_in(gp_peers *p, gp_peer_conn *conn);
void gp_peers_head_done(gp_peers *p, gp_peer_conn *conn);
void gp_peers_head_begins(gp_peers *p, gp_peer_conn *conn);

/* Starts the watcher: a head not complete `seconds` after it began gets a 408 problem
 * and its connection is shut down. Returns 0 or GP_ENOMEM. gp_peers_free stops it. */
int gp_peers_watch(gp_peers *p, double seconds);

/* The connection closed: its record is freed. NULL is a no-op. */
void gp_peers_closed(gp_peers *p, gp_peer_conn *conn);

#endif
