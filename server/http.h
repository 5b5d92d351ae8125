/* http.h - the HTTP side of the daemon on libmicrohttpd: one internal polling thread per
 * HTTP thread (epoll), request bodies gathered under a cap, routing to the route
 * functions, CORS, one log line and one metrics count per request. No route runs
 * geometry: jobs go to the workers through the store. */
#ifndef GRAINPACKD_HTTP_H
#define GRAINPACKD_HTTP_H

#include <microhttpd.h>
#include <stddef.h>

#include "auth.h"
#include "reply.h"
#include "service.h"
#include "waiters.h"

/* What a route sees of a request. Valid for the duration of the route call. */
typedef struct gp_request {
    gp_service *svc;
    struct MHD_Connection *conn;
    const char *method; /* "GET", "HEAD", "POST", "DELETE" */
    const char *path;   /* without the query string */
    const char *id;     /* the {jobId} or {processId} segment of the path, "" if none */
    const char *body;   /* POST: the body (not NUL-terminated), else NULL */
    size_t body_len;
    int resumed;        /* called again after a long-poll suspension */
    const gp_identity *who; /* the key's user and role; NULL when the daemon has no keys */
    const char *owner;  /* whose jobs the request sees: a user's name, or NULL for every
                           job (an admin key, or no keys at all) */
} gp_request;

/* What a route did: answered (reply filled) or suspended the connection (long-poll). */
enum { GP_ROUTE_DONE = 0, GP_ROUTE_SUSPENDED = 1 };

typedef int (*gp_route_fn)(gp_request *req, gp_reply *reply);

/* A query parameter or header of the request, NULL when absent. */
const char *gp_request_query(const gp_request *req, const char *name);
const char *gp_request_header(const gp_request *req, const char *name);

/* The owner a job submitted by req gets: the key's user, or "" without keys. */
const char *gp_request_submitter(const gp_request *req);

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
