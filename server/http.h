/* http.h - the HTTP side of the daemon on libmicrohttpd: one internal polling thread per
 * HTTP thread (epoll), request bodies gathered under a cap, each request turned into a
 * gp_request (request.h) for the router and its gp_reply into a response, CORS, one log
 * line and one metrics count per request. No route runs geometry: jobs go to the workers
 * through the store. */
#ifndef GRAINPACKD_HTTP_H
#define GRAINPACKD_HTTP_H

#include <microhttpd.h>
#include <stddef.h>

#include "service.h"
#include "waiters.h"

/* libmicrohttpd's suspend and resume, for the long-poll registry (gp_waiters_start). */
extern const gp_suspender gp_http_suspender;

/* Starts listening on cfg->host:cfg->port with cfg->http_threads threads. Returns 0 with
 * the daemon and the port actually bound (cfg->port may be 0), or, after logging why,
 * GP_EINVAL (--host is not an address) or GP_EIO (cannot listen). */
int gp_http_start(gp_service *svc, struct MHD_Daemon **out, unsigned *port);

/* The same request handling without a socket or a thread of its own, for the fuzzer:
 * connections are handed in with MHD_add_connection and served by MHD_run. Returns 0
 * or GP_EIO. */
int gp_http_start_embedded(gp_service *svc, struct MHD_Daemon **out);

/* Stops accepting new connections (in-flight requests go on). */
void gp_http_quiesce(struct MHD_Daemon *daemon);

/* Closes every connection and joins the HTTP threads. */
void gp_http_stop(struct MHD_Daemon *daemon);

#endif
