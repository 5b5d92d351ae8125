/* reply.h - what a route answers, independent of the HTTP library: status, media type,
 * body and the few headers the API uses. http.c turns it into a libmicrohttpd response. */
#ifndef GRAINPACKD_REPLY_H
#define GRAINPACKD_REPLY_H

#include <jansson.h>
#include <stddef.h>

/* A body produced piece by piece as the connection takes it (a result download): http.c
 * calls fill for up to `max` more bytes (it returns how many it wrote, 0 at the end, or
 * -1 on failure, which cuts the connection) and release once the response is done with it
 * (or never sent). Embedded first in the producer's own struct. */
typedef struct gp_body_stream gp_body_stream;
struct gp_body_stream {
    long (*fill)(gp_body_stream *s, char *buf, size_t max);
    void (*release)(gp_body_stream *s);
};

/* The most extra headers a reply carries (ETag, Vary, Content-Disposition,
 * Content-Encoding, Cache-Control). */
#define GP_REPLY_MAX_HEADERS 6

typedef struct gp_reply_header {
    const char *name; /* static string */
    char value[160];
} gp_reply_header;

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
    gp_body_stream *stream;   /* owned: the body comes from it instead of `body` */
    gp_reply_header headers[GP_REPLY_MAX_HEADERS];
    int nheaders;
} gp_reply;

/* Adds a header (printf-style value, cut at 159 bytes; ignored past
 * GP_REPLY_MAX_HEADERS). */
void gp_reply_header_add(gp_reply *reply, const char *name, const char *format, ...)
    __attribute__((format(printf, 3, 4)));

/* Takes a streamed body: the reply's answer is `status` with that body. */
void gp_reply_stream(gp_reply *reply, unsigned status, const char *content_type,
                     gp_body_stream *stream);

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
