/* render.c - format and encoding negotiation, entity tags. */
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "grainpack/version.h"
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

/* The q of a coding in Accept-Encoding, -1 when it is not named. */
static double coding_quality(const char *header, const char *coding)
{
    size_t n = strlen(coding);
    for (const char *p = header; *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        const char *end = p + strcspn(p, ",");
        size_t len = strcspn(p, ";, ");
        if (len == n && strncasecmp(p, coding, n) == 0) {
            const char *q = memchr(p, ';', (size_t)(end - p));
            while (q && q < end) {
                q++;
                while (*q == ' ')
                    q++;
                if ((q[0] == 'q' || q[0] == 'Q') && q[1] == '=')
                    return strtod(q + 2, NULL);
                q = memchr(q, ';', (size_t)(end - q));
            }
            return 1.0;
        }
        p = end;
    }
    return -1.0;
}

int gp_render_accepts_gzip(const gp_request *req)
{
    const char *header = gp_request_header(req, "Accept-Encoding");
    if (!header)
        return 0;
    double gzip = coding_quality(header, "gzip"), xgzip = coding_quality(header, "x-gzip");
    if (gzip < 0.0)
        gzip = xgzip;
    if (gzip < 0.0)
        gzip = coding_quality(header, "*");
    return gzip > 0.0;
}

void gp_render_etag(const gp_stored_result *res, const gp_spec *spec, gp_format format, int gzip,
                    char *out)
{
    /* only the picture shows the colouring (?color= or the spec's) */
    const char *color = format != GP_FORMAT_SVG || !spec ? ""
                        : spec->picture_color == GP_PICTURE_COLOR_QUALITY ? "-quality"
                                                                         : "-radius";
    snprintf(out, GP_ETAG_SIZE, "\"%s-%s%s%s-%s.%d\"", res->version, gp_format_name(format),
             color, gzip ? "-gzip" : "", GP_VERSION, GP_RENDER_REVISION);
}

int gp_render_not_modified(const gp_request *req, const char *etag)
{
    const char *header = gp_request_header(req, "If-None-Match");
    if (!header)
        return 0;
    size_t n = strlen(etag);
    for (const char *p = header; *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        if (*p == '*')
            return 1;
        if (strncmp(p, "W/", 2) == 0)
            p += 2;
        if (*p != '"')
            break; /* not an entity tag: nothing further can be read as one */
        const char *close = strchr(p + 1, '"');
        if (!close)
            break;
        if ((size_t)(close + 1 - p) == n && strncmp(p, etag, n) == 0)
            return 1;
        p = close + 1;
    }
    return 0;
}
