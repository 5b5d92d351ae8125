/* reply.h - what a route answers, independent of the HTTP library: status, media type,
 * body and the few headers the API uses. http.c turns it into a libmicrohttpd response. */
#ifndef GRAINPACKD_REPLY_H
#define GRAINPACKD_REPLY_H

#include <jansson.h>
#include <stddef.h>

typedef struct gp_reply {
    unsigned status;
    const char *content_type; /* static string */
    char *body;               /* owned (malloc'd) unless `persistent`; NULL: empty body */
    size_t len;
    char location[160];       /* Location header, "" for none */
    char allow[64];           /* Allow header (405), "" for none */
    int retry_after;          /* Retry-After seconds (429, 503), 0 for none */
    char www_authenticate[96]; /* WWW-Authenticate header (401), "" for none */
    int close;                /* close the connection after this answer */
    int persistent;           /* body is a static text, never freed (the out-of-memory
                                 answer: gp_problem_out_of_memory) */
    const char *vary;         /* Vary header (static), NULL for none: the answer depends on it */
    const char *cache_control; /* Cache-Control header (static), NULL for none */
    const char *etag;         /* ETag header (static, quoted), NULL for none */
    const char *csp;          /* Content-Security-Policy (static) of a page, NULL for none;
                                 with it, the page's other security headers are sent too */
} gp_reply;

/* Serialises `value` (reference stolen) as the body with the given status and media type.
 * A NULL value is a JSON document whose building ran out of memory. Returns 0, or
 * GP_ENOMEM with the reply the static out-of-memory problem (gp_problem_out_of_memory). */
int gp_reply_json(gp_reply *reply, unsigned status, const char *content_type, json_t *value);

/* Takes ownership of a malloc'd body (the previous body is freed). */
void gp_reply_take(gp_reply *reply, unsigned status, const char *content_type, char *body,
                   size_t len);

/* Copies a static text into a new body. Returns 0, or GP_ENOMEM with the reply the
 * out-of-memory problem. */
int gp_reply_text(gp_reply *reply, unsigned status, const char *content_type, const char *text,
                  size_t len);

/* Frees the body (unless persistent) and clears the reply. */
void gp_reply_free(gp_reply *reply);

#endif
