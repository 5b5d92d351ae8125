/* problem.c - RFC 9457 problem+json bodies. */
#include "problem.h"

#include <stdarg.h>
#include <stdio.h>

static const char *status_title(unsigned status)
{
    switch (status) {
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 406: return "Not Acceptable";
    case 413: return "Content Too Large";
    case 415: return "Unsupported Media Type";
    case 422: return "Unprocessable Content";
    case 503: return "Service Unavailable";
    default: return status >= 500 ? "Internal Server Error" : "Error";
    }
}

/* Builds the body; `pointer`/`expected` are added when not NULL. */
static void build(gp_reply *reply, unsigned status, const char *type, const char *instance,
                  const char *detail, const char *pointer, const char *expected)
{
    json_t *p = json_pack("{s:s, s:s, s:i, s:s}", "type", type, "title", status_title(status),
                          "status", (int)status, "detail", detail);
    if (p && instance)
        json_object_set_new(p, "instance", json_string(instance));
    if (p && pointer)
        json_object_set_new(p, "pointer", json_string(pointer));
    if (p && expected)
        json_object_set_new(p, "expected", json_string(expected));
    if (gp_reply_json(reply, status, GP_PROBLEM_MEDIA_TYPE, p))
        reply->status = status; /* out of memory: at least the status is right */
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
    gp_problem(reply, 404, GP_PROBLEM_NO_SUCH_PROCESS, instance,
               "there is no process '%s'; this service offers 'pack2d'", id);
}

void gp_problem_store_unavailable(gp_reply *reply, const char *instance)
{
    gp_problem(reply, 503, GP_PROBLEM_INTERNAL, instance,
               "the job store is not available right now; try again");
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
