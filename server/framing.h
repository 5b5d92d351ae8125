/* framing.h - the checks of RFC 9112 on how a request says where its body ends, and the
 * other head faults a proxy in front may read differently from libmicrohttpd, made once
 * the head is in and before any route runs. A request that fails them is refused (400, or
 * 501 for a transfer coding other than chunked) and its connection closed: the bytes
 * after its head are never read as a request. libmicrohttpd decides the framing from the
 * first Transfer-Encoding or Content-Length header it finds; these checks refuse every
 * request whose headers could be read another way.
 *
 * No libmicrohttpd type here: http.c hands in the version and each header. */
#ifndef GRAINPACKD_FRAMING_H
#define GRAINPACKD_FRAMING_H

#include <stddef.h>

#include "reply.h"

/* Headers counted and kept (the first value of each). */
typedef struct gp_framing {
    unsigned hosts, lengths, encodings;
    const char *host, *length, *encoding; /* borrowed: valid while the request is */
    char bad_name[64]; /* a header name that is not a token (sanitized), "" if none */
} gp_framing;

void gp_framing_init(gp_framing *f);

/* Records one header of the request, as libmicrohttpd parsed it. */
void gp_framing_add(gp_framing *f, const char *name, const char *value);

/* The verdict once every header is in: 0 when the request is framed one way only, else
 * 1 with reply filled (problem+json, `close` set). `version` is the request line's
 * ("HTTP/1.1"), `path` the instance of the problem. */
int gp_framing_check(const gp_framing *f, const char *version, const char *path, gp_reply *reply);

/* The most query parameters a request may have: more than any route reads. A longer
 * query is cut before libmicrohttpd parses it (each parameter takes a record from the
 * connection's memory pool: a thousand of them emptied it, and libmicrohttpd then never
 * answered) and the request is refused with 400. */
#define GP_MAX_QUERY_PARAMETERS 64

/* The number of parameters of the query in `uri` (the request target as sent): one more
 * than its '&', 0 without a query. */
size_t gp_query_parameters(const char *uri);

#endif
