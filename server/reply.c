/* reply.c - building route replies. */
#include "reply.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grainpack/io.h"
#include "problem.h"

int gp_reply_json(gp_reply *reply, unsigned status, const char *content_type, json_t *value)
{
    /* compact, doubles in their shortest round-trip form (0.6, not 0.59999999999999998) */
    gp_out out;
    int rc = value ? gp_out_init(&out, 1024, NULL, NULL) : GP_ENOMEM;
    if (rc == 0) {
        gp_out_json(&out, value);
        if ((rc = out.err))
            gp_out_free(&out);
    }
    json_decref(value);
    if (rc) {
        gp_problem_out_of_memory(reply);
        return GP_ENOMEM;
    }
    gp_reply_take(reply, status, content_type, out.buf, out.len);
    return 0;
}

void gp_reply_take(gp_reply *reply, unsigned status, const char *content_type, char *body,
                   size_t len)
{
    if (!reply->persistent)
        free(reply->body);
    reply->status = status;
    reply->content_type = content_type;
    reply->body = body;
    reply->len = len;
    reply->persistent = 0;
}

int gp_reply_text(gp_reply *reply, unsigned status, const char *content_type, const char *text,
                  size_t len)
{
    char *copy = malloc(len ? len : 1);
    if (!copy) {
        gp_problem_out_of_memory(reply);
        return GP_ENOMEM;
    }
    memcpy(copy, text, len);
    gp_reply_take(reply, status, content_type, copy, len);
    return 0;
}

void gp_reply_header_add(gp_reply *reply, const char *name, const char *format, ...)
{
    if (reply->nheaders == GP_REPLY_MAX_HEADERS)
        return;
    gp_reply_header *h = &reply->headers[reply->nheaders++];
    h->name = name;
    va_list ap;
    va_start(ap, format);
    vsnprintf(h->value, sizeof h->value, format, ap);
    va_end(ap);
}

void gp_reply_stream(gp_reply *reply, unsigned status, const char *content_type,
                     gp_body_stream *stream)
{
    gp_reply_take(reply, status, content_type, NULL, 0);
    if (reply->stream)
        reply->stream->release(reply->stream);
    reply->stream = stream;
}

void gp_reply_free(gp_reply *reply)
{
    if (reply->stream)
        reply->stream->release(reply->stream);
    if (!reply->persistent)
        free(reply->body);
    memset(reply, 0, sizeof *reply);
}
