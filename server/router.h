/* router.h - the route table and the checks a request passes once its headers are in,
 * before any body is read: sizes, path, method, API key and role, media type and length.
 * http.c calls these; they see the request only through gp_request (request.h), so that
 * they do not depend on how it arrived and are tested without an HTTP library. */
#ifndef GRAINPACKD_ROUTER_H
#define GRAINPACKD_ROUTER_H

#include <stddef.h>

#include "request.h"

/* The longest id segment accepted; job ids are 36 characters. */
#define GP_ID_MAX 64

/* Who may call a route when the daemon has a key file (without one, anyone may). */
typedef enum gp_access {
    GP_ACCESS_PUBLIC, /* what the service is: landing page, processes, health, OpenAPI */
    GP_ACCESS_KEY,    /* jobs: any key; a `user` key sees its own jobs only */
    GP_ACCESS_ADMIN   /* the metrics (they count everyone's jobs) */
} gp_access;

/* A path pattern whose "{}" segment is an id, and a function per method (NULL: not
 * allowed). HEAD is served by GET. */
typedef struct gp_route_entry {
    const char *pattern;
    gp_access access;
    gp_route_fn get, post, del;
} gp_route_entry;

/* Matches a path against the table; the "{}" segment goes to id. NULL when nothing
 * matches (an id longer than GP_ID_MAX, or with characters other than letters, digits,
 * '-', '_' and '.', matches nothing). */
const gp_route_entry *gp_router_match(const char *path, char id[GP_ID_MAX + 1]);

/* "GET, HEAD, POST, DELETE, OPTIONS" as the route allows. */
void gp_router_allow(const gp_route_entry *rt, char *out, size_t size);

/* The checks before the body: request line and headers within --max-header-bytes (414,
 * 431), a route (404), OPTIONS (204), the method (405), the key and role (401, 403),
 * and for a POST the process (404), the media type (415) and Content-Length (413).
 * `header_bytes` and `uri_bytes` are the sizes of the headers and of the path with its
 * query. Returns 1 with reply filled when the request is answered already, 0 when it
 * goes on (then req->who and req->owner are set). `who` is storage for the identity. */
int gp_router_admit(gp_request *req, const gp_route_entry *rt, size_t uri_bytes,
                    size_t header_bytes, gp_identity *who, gp_reply *reply);

/* Calls the route's function for req->method (HEAD is GET's) once the request passed
 * gp_router_admit and its body is in. Returns what the route did: GP_ROUTE_DONE with
 * reply filled, or GP_ROUTE_SUSPENDED. */
int gp_router_call(const gp_route_entry *rt, gp_request *req, gp_reply *reply);

#endif
