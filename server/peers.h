/* peers.h - connections open per client address, for --max-connections-per-ip. A
 * connection over the limit is still accepted, so that its first request can be answered
 * with a 429 problem saying why (then it is closed); libmicrohttpd's own per-address limit,
 * set a margin above, drops a flood before it costs more than a socket.
 *
 * Locking: one mutex guards the table; HTTP threads open and close connections at will. */
#ifndef GRAINPACKD_PEERS_H
#define GRAINPACKD_PEERS_H

#include <sys/socket.h>

typedef struct gp_peers gp_peers;

/* One open connection, owned by the table from gp_peers_opened to gp_peers_closed. */
typedef struct gp_peer_conn {
    struct peer_entry *entry;
    unsigned open;  /* connections from the address when this one opened, itself included */
    int over_limit; /* open > the limit: answer 429 and close */
} gp_peer_conn;

/* A new empty table, or NULL when out of memory. */
gp_peers *gp_peers_new(void);
void gp_peers_free(gp_peers *p);

/* A connection from addr opened; `limit` is the most connections allowed from one
 * address. Returns its record, or NULL when out of memory (the connection is then not
 * counted) or addr is not IPv4/IPv6. */
gp_peer_conn *gp_peers_opened(gp_peers *p, const struct sockaddr *addr, unsigned limit);

/* The connection closed: its record is freed. NULL is a no-op. */
void gp_peers_closed(gp_peers *p, gp_peer_conn *conn);

#endif
