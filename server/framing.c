/* framing.c - RFC 9112 framing checks of a request head (see framing.h). */
#include "framing.h"

#include <string.h>
#include <strings.h>

#include "problem.h"

void gp_framing_init(gp_framing *f)
{
    memset(f, 0, sizeof *f);
}

/* tchar of RFC 9110 §5.6.2: a header name is a token. */
static int is_tchar(unsigned char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
           (c && strchr("!#$%&'*+-.^_`|~", c));
}

static int is_token(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (!is_tchar((unsigned char)*s))
            return 0;
    return 1;
}

void gp_framing_add(gp_framing *f, const char *name, const char *value)
{
    value = value ? value : "";
    if (!is_token(name) && !f->bad_name[0])
        gp_text_sanitize(f->bad_name, sizeof f->bad_name, name);
    if (strcasecmp(name, "Host") == 0 && f->hosts++ == 0)
        f->host = value;
    else if (strcasecmp(name, "Content-Length") == 0 && f->lengths++ == 0)
        f->length = value;
    else if (strcasecmp(name, "Transfer-Encoding") == 0 && f->encodings++ == 0)
        f->encoding = value;
}

/* Whether a Host value is host[:port] (RFC 3986 reg-name, IPv4 or an IP literal in
 * brackets): no space, no control character, nothing that ends an authority. Empty is
 * allowed (RFC 9112 §3.2: a target without authority). */
static int valid_host(const char *host)
{
    for (const unsigned char *p = (const unsigned char *)host; *p; p++)
        if (!((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
              strchr("-._~!$&'()*+,;=:%[]", *p)))
            return 0;
    return 1;
}

/* The element of a comma-separated list ending at `end` (exclusive), without optional
 * whitespace: [*start, *stop). */
static void trim(const char *begin, const char *end, const char **start, const char **stop)
{
    while (begin < end && (*begin == ' ' || *begin == '\t'))
        begin++;
    while (end > begin && (end[-1] == ' ' || end[-1] == '\t'))
        end--;
    *start = begin;
    *stop = end;
}

static int is_chunked(const char *start, const char *stop)
{
    return stop - start == 7 && strncasecmp(start, "chunked", 7) == 0;
}

/* A Transfer-Encoding other than exactly "chunked": 501 when it is a list that ends in
 * chunked after codings of other names (they are not implemented), else 400 (chunked not
 * last: the body's end cannot be known, RFC 9112 §6.3; chunked twice; empty elements). */
static unsigned classify_coding(const char *value)
{
    const char *comma = strrchr(value, ',');
    const char *start, *stop;
    if (!comma)
        return 400;
    trim(comma + 1, value + strlen(value), &start, &stop);
    if (!is_chunked(start, stop))
        return 400;
    for (const char *p = value;;) { /* the elements before the last, empty ones included */
        const char *next = memchr(p, ',', (size_t)(comma - p));
        next = next ? next : comma;
        trim(p, next, &start, &stop);
        if (start == stop || is_chunked(start, stop))
            return 400;
        if (next == comma)
            return 501;
        p = next + 1;
    }
}

int gp_framing_check(const gp_framing *f, const char *version, const char *path, gp_reply *reply)
{
    int http11 = strcmp(version, "HTTP/1.1") == 0;
    unsigned status = 400;
    const char *type = GP_PROBLEM_BAD_FRAMING, *detail = NULL, *echo = NULL;
    if (f->bad_name[0]) {
        detail = "a header name must be a token (RFC 9110 §5.1): no space before the colon";
        echo = f->bad_name;
    } else if (f->hosts > 1) {
        detail = "more than one Host header (RFC 9112 §3.2)";
    } else if (http11 && f->hosts == 0) {
        detail = "an HTTP/1.1 request must have a Host header (RFC 9112 §3.2)";
    } else if (f->hosts == 1 && !valid_host(f->host)) {
        detail = "the Host header is not host[:port] (RFC 9112 §3.2)";
        echo = f->host;
    } else if (f->encodings && f->lengths) {
        detail = "both Transfer-Encoding and Content-Length: where the body ends would be "
                 "ambiguous (RFC 9112 §6.3)";
    } else if (f->lengths > 1) {
        detail = "more than one Content-Length header (RFC 9112 §6.3)";
    } else if (f->encodings && !http11) {
        detail = "Transfer-Encoding in an HTTP/1.0 request (RFC 9112 §6.1)";
    } else if (f->encodings > 1) {
        detail = "more than one Transfer-Encoding header: send one, chunked";
    } else if (f->encodings && strcasecmp(f->encoding, "chunked") != 0) {
        status = classify_coding(f->encoding);
        type = status == 501 ? GP_PROBLEM_UNSUPPORTED_CODING : GP_PROBLEM_BAD_FRAMING;
        detail = status == 501 ? "a transfer coding other than chunked: only chunked is implemented"
                               : "Transfer-Encoding must be chunked alone: chunked last and once "
                                 "(RFC 9112 §6.3), no other coding";
        echo = f->encoding;
    }
    if (!detail)
        return 0;
    if (echo)
        gp_problem(reply, status, type, path, "%s; got '%.60s'", detail, echo);
    else
        gp_problem(reply, status, type, path, "%s", detail);
    reply->close = 1;
    return 1;
}

size_t gp_query_parameters(const char *uri)
{
    const char *q = uri ? strchr(uri, '?') : NULL;
    if (!q)
        return 0;
    size_t n = 1;
    for (const char *p = q + 1; *p; p++)
        n += *p == '&';
    return n;
}
