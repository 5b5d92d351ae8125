/* problem.c - RFC 9457 problem+json bodies. */
#include "problem.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "processes.h"
#include "store.h"

static const char *status_title(unsigned status)
{
    switch (status) {
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 406: return "Not Acceptable";
    case 408: return "Request Timeout";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 422: return "Unprocessable Content";
    case 429: return "Too Many Requests";
    case 431: return "Request Header Fields Too Large";
    case 501: return "Not Implemented";
    case 503: return "Service Unavailable";
    default: return status >= 500 ? "Internal Server Error" : "Error";
    }
}

/* Length of the valid UTF-8 sequence (RFC 3629: no overlongs, no surrogates, at most
 * U+10FFFF) at s, or 0. */
static size_t utf8_length(const unsigned char *s)
{
    unsigned c = s[0];
    if (c < 0x80)
        return 1;
    size_t n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
    if (!n)
        return 0;
    for (size_t i = 1; i < n; i++)
        if ((s[i] & 0xc0) != 0x80)
            return 0;
    if ((c == 0xe0 && s[1] < 0xa0) || (c == 0xed && s[1] > 0x9f) || (c == 0xf0 && s[1] < 0x90) ||
        (c == 0xf4 && s[1] > 0x8f))
        return 0;
    return n;
}

void gp_text_sanitize(char *out, size_t size, const char *text)
{
    static const char replacement[] = "\xef\xbf\xbd"; /* U+FFFD */
    size_t o = 0;
    if (!size)
        return;
    for (const unsigned char *s = (const unsigned char *)text; *s;) {
        size_t n = utf8_length(s);
        const char *piece = (const char *)s;
        size_t len = n;
        if (n == 0 || (n == 1 && (*s < 0x20 || *s == 0x7f))) {
            piece = replacement;
            len = 3;
            n = 1;
        }
        if (o + len >= size)
            break;
        memcpy(out + o, piece, len);
        o += len;
        s += n;
    }
    out[o] = '\0';
}

/* Adds member name = text made valid (see gp_text_sanitize) to p, when text is not NULL. */
static void set_text(json_t *p, const char *name, const char *text)
{
    char clean[2400];
    if (!p || !text)
        return;
    gp_text_sanitize(clean, sizeof clean, text);
    json_object_set_new(p, name, json_string(clean));
}

/* Builds the body; `instance`, `pointer` and `expected` are added when not NULL. Every
 * text is sanitized: a message cut inside a character, or a path of raw bytes, must not
 * make the problem itself fail. */
static void build(gp_reply *reply, unsigned status, const char *type, const char *instance,
                  const char *detail, const char *pointer, const char *expected)
{
    json_t *p = json_pack("{s:s, s:s, s:i}", "type", type, "title", status_title(status),
                          "status", (int)status);
    set_text(p, "detail", detail);
    set_text(p, "instance", instance);
    set_text(p, "pointer", pointer);
    set_text(p, "expected", expected);
    gp_reply_json(reply, status, GP_PROBLEM_MEDIA_TYPE, p); /* or the out-of-memory 503 */
}

/* 503: running out of memory is passing (other requests free theirs), so the client is
 * told to try again rather than that the request is wrong. */
static const char out_of_memory_body[] =
    "{\"type\":\"" GP_PROBLEM_INTERNAL "\",\"title\":\"Service Unavailable\",\"status\":503,"
    "\"detail\":\"the service ran out of memory while answering this request; "
    "try again in a few seconds\"}";

void gp_problem_out_of_memory(gp_reply *reply)
{
    if (reply->stream) { /* a download that could not start: its body and headers go */
        reply->stream->release(reply->stream);
        reply->stream = NULL;
    }
    reply->nheaders = 0;
    gp_reply_take(reply, 503, GP_PROBLEM_MEDIA_TYPE, (char *)out_of_memory_body,
                  sizeof out_of_memory_body - 1);
    reply->persistent = 1;
    reply->retry_after = GP_RETRY_AFTER_SECONDS;
}

void gp_problem(gp_reply *reply, unsigned status, const char *type, const char *instance,
                const char *detail_fmt, ...)
{
    char detail[768];
    va_list ap;
    va_start(ap, detail_fmt);
    vsnprintf(detail, sizeof detail, detail_fmt, ap);
    va_end(ap);
    build(reply, status, type, instance, detail, NULL, NULL);
}

void gp_problem_no_such_job(gp_reply *reply, const char *instance, const char *id)
{
    gp_problem(reply, 404, GP_PROBLEM_NO_SUCH_JOB, instance,
               "there is no job '%s' (never submitted, or deleted)", id);
}

void gp_problem_no_such_process(gp_reply *reply, const char *instance, const char *id)
{
    char offered[128] = "";
    for (size_t i = 0, len = 0; i < gp_process_count() && len < sizeof offered; i++)
        len += (size_t)snprintf(offered + len, sizeof offered - len, "%s'%s'", i ? ", " : "",
                                gp_process_at(i)->id);
    gp_problem(reply, 404, GP_PROBLEM_NO_SUCH_PROCESS, instance,
               "there is no process '%.60s'; this service offers %s", id, offered);
}

void gp_problem_store_unavailable(gp_reply *reply, const char *instance)
{
    gp_problem(reply, 503, GP_PROBLEM_INTERNAL, instance,
               "the job store is not available right now; try again");
    reply->retry_after = GP_RETRY_AFTER_SECONDS;
}

void gp_problem_store_error(gp_reply *reply, const char *instance, int rc, const char *action)
{
    if (rc == GP_SRV_EFULL)
        gp_problem(reply, 503, GP_PROBLEM_STORAGE_FULL, instance,
                   "the database's disk is full: %s. Nothing was lost; try again once an "
                   "administrator has freed space", action);
    else if (rc == GP_SRV_EUNWRITABLE)
        gp_problem(reply, 503, GP_PROBLEM_STORAGE_UNWRITABLE, instance,
                   "the database cannot be written (a read-only file or file system, or a "
                   "write error): %s. "
                   "Nothing was lost; try again once an administrator has fixed it", action);
    else
        gp_problem(reply, 503, GP_PROBLEM_INTERNAL, instance,
                   "the job store is not available right now: %s; try again", action);
    reply->retry_after = GP_RETRY_AFTER_SECONDS;
}

void gp_problem_from_spec_error(gp_reply *reply, const char *instance, const gp_error *err)
{
    char detail[768];
    switch (err->code) {
    case GP_EPARSE:
        snprintf(detail, sizeof detail, "the body is not well-formed JSON: %s", err->message);
        build(reply, 400, GP_PROBLEM_MALFORMED_JSON, instance, detail, NULL, NULL);
        return;
    case GP_EINVAL:
    case GP_ETOOBIG: {
        /* the root has the empty pointer; name it so that the detail still reads well */
        const char *where = err->pointer[0] ? err->pointer : "(the document)";
        snprintf(detail, sizeof detail, "%s: %s", where, err->message);
        build(reply, 422, err->code == GP_ETOOBIG ? GP_PROBLEM_JOB_TOO_BIG : GP_PROBLEM_INVALID_SPEC,
              instance, detail, err->pointer, err->message);
        return;
    }
    default:
        snprintf(detail, sizeof detail, "the spec could not be read: %s (%s)", err->message,
                 gp_strerror(err->code));
        build(reply, 500, GP_PROBLEM_INTERNAL, instance, detail, NULL, NULL);
    }
}
