/* request.h - what a route sees of a request, independent of the HTTP library: the
 * request line, body and caller, with headers and query parameters read through lookups
 * the HTTP side supplies (http.c: libmicrohttpd's; a unit test: a table of its own). The
 * router and the routes depend on this, never on http.h. */
#ifndef GRAINPACKD_REQUEST_H
#define GRAINPACKD_REQUEST_H

#include <stddef.h>

#include "auth.h"
#include "reply.h"
#include "service.h"

/* How a request's headers (names case-insensitive) and query parameters are read from
 * the connection it came on: the value, or NULL when absent; valid while the request is. */
typedef struct gp_request_ops {
    const char *(*header)(void *conn, const char *name);
    const char *(*query)(void *conn, const char *name);
} gp_request_ops;

/* What a route sees of a request. Valid for the duration of the route call. */
typedef struct gp_request {
    gp_service *svc;
    const gp_request_ops *ops;
    void *conn;         /* the HTTP side's connection: for ops, and for svc->waiters to
                           suspend and resume (long-poll) */
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

#endif
