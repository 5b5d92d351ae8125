/* render.c - format negotiation and re-rendering a stored result. */
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "problem.h"

/* Lists the formats as "json, csv, svg" (or their media types). */
static void format_list(char *out, size_t size, int media)
{
    size_t n = 0;
    out[0] = '\0';
    for (size_t i = 0; i < gp_format_count() && n < size; i++) {
        gp_format f = (gp_format)i;
        n += (size_t)snprintf(out + n, size - n, "%s%s", i ? ", " : "",
                              media ? gp_format_media_type(f) : gp_format_name(f));
    }
}

/* Length of the bare media type (before any ';' parameter), trimmed. */
static size_t type_length(const char *t)
{
    size_t n = strcspn(t, ";,");
    while (n > 0 && t[n - 1] == ' ')
        n--;
    return n;
}

/* How specifically the range [r, r + n) matches media type mt: 3 exact, 2 "type/any",
 * 1 "any/any" (written with stars), 0 not at all. */
static int range_match(const char *r, size_t n, const char *mt)
{
    size_t mlen = type_length(mt);
    if (n == mlen && strncasecmp(r, mt, n) == 0)
        return 3;
    if (n == 3 && strncmp(r, "*/*", 3) == 0)
        return 1;
    const char *slash = memchr(mt, '/', mlen);
    if (slash && n >= 2 && r[n - 1] == '*' && r[n - 2] == '/' &&
        n - 1 == (size_t)(slash - mt) + 1 && strncasecmp(r, mt, n - 1) == 0)
        return 2;
    return 0;
}

double gp_accept_quality(const char *accept, const char *mt)
{
    int best_spec = 0;
    double q_best = 0.0;
    for (const char *p = accept; *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        if (!*p)
            break;
        const char *end = p + strcspn(p, ",");
        size_t n = type_length(p);
        double q = 1.0;
        const char *qp = p;
        while ((qp = strchr(qp, ';')) && qp < end) {
            qp++;
            while (*qp == ' ')
                qp++;
            if (qp[0] == 'q' && qp[1] == '=')
                q = strtod(qp + 2, NULL);
        }
        int spec = range_match(p, n, mt);
        if (spec > best_spec) {
            best_spec = spec;
            q_best = q;
        }
        p = end;
    }
    return q_best;
}

int gp_render_choose_format(const gp_request *req, gp_format *out, gp_reply *reply)
{
    char list[256];
    const char *f = gp_request_query(req, "f");
    if (f) {
        if (gp_format_parse(f, out) == 0)
            return 0;
        format_list(list, sizeof list, 0);
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "unknown format f=%.40s; expected one of %s", f, list);
        return -1;
    }
    const char *accept = gp_request_header(req, "Accept");
    *out = GP_FORMAT_JSON;
    if (!accept || !*accept)
        return 0;
    double best = 0.0;
    for (size_t i = 0; i < gp_format_count(); i++) {
        double q = gp_accept_quality(accept, gp_format_media_type((gp_format)i));
        if (q > best) { /* ties keep the earlier format: JSON first */
            best = q;
            *out = (gp_format)i;
        }
    }
    if (best > 0.0)
        return 0;
    char names[128];
    format_list(list, sizeof list, 1);
    format_list(names, sizeof names, 0);
    gp_problem(reply, 406, GP_PROBLEM_NOT_ACCEPTABLE, req->path,
               "no format matches Accept: %.100s; available: %s (or ?f= one of %s)", accept,
               list, names);
    return -1;
}

int gp_render_load(gp_db *db, const char *id, const char *owner, gp_spec *spec, gp_result *result)
{
    memset(spec, 0, sizeof *spec);
    memset(result, 0, sizeof *result);
    char *text;
    size_t len;
    int rc = gp_store_load_result(db, id, owner, &text, &len, &result->packing);
    if (rc)
        return rc;
    /* accepted once, so parsed without today's caps */
    gp_spec_limits unlimited = {(size_t)-1, (size_t)-1};
    gp_error err;
    rc = gp_spec_parse(text, len, &unlimited, spec, &err);
    free(text);
    if (rc == 0)
        rc = gp_pack_stats_compute(&spec->domain, &spec->dist, &result->packing, &result->stats);
    /* F and the Laguerre cells, rebuilt from the stored (balanced) disks */
    if (rc == 0)
        rc = gp_result_rederive(spec, result, &err);
    if (rc) {
        gp_spec_free(spec);
        gp_result_free(result);
    }
    return rc;
}

int gp_render_format(const gp_spec *spec, const gp_result *result, gp_format format,
                     char **body, size_t *len)
{
    *body = NULL;
    FILE *f = open_memstream(body, len);
    if (!f)
        return GP_ENOMEM;
    int rc = gp_write_result(f, format, spec, result);
    if (fclose(f) != 0 && rc == 0)
        rc = GP_ENOMEM;
    if (rc) {
        free(*body);
        *body = NULL;
    }
    return rc;
}
