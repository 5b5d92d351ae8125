/* reply.c - building route replies. */
#include "reply.h"

#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "problem.h"

int gp_reply_json(gp_reply *reply, unsigned status, const char *content_type, json_t *value)
{
    char *text = value ? json_dumps(value, JSON_COMPACT | JSON_REAL_PRECISION(17)) : NULL;
    json_decref(value);
    if (!text) {
        gp_problem_out_of_memory(reply);
        return GP_ENOMEM;
    }
    gp_reply_take(reply, status, content_type, text, strlen(text));
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

void gp_reply_free(gp_reply *reply)
{
    if (!reply->persistent)
        free(reply->body);
    memset(reply, 0, sizeof *reply);
}
