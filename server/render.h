/* render.h - how a finished job's result is served: the format chosen by ?f= or Accept
 * among the engine's writers (gp_format), gzip when Accept-Encoding allows it, and the
 * strong ETag of each (result, format, encoding). Every format the engine's writers know
 * is served without a change here. The result itself is streamed from the store by
 * download.c: nothing is computed again. */
#ifndef GRAINPACKD_RENDER_H
#define GRAINPACKD_RENDER_H

#include "grainpack/io.h"
#include "request.h"
#include "store.h"

/* Picks the format: ?f=NAME wins, else the best match of the Accept header (q-values,
 * type/any and any/any honoured), else JSON. Returns 0, or -1 with reply filled (400 for an
 * unknown f, 406 when Accept allows none). */
int gp_render_choose_format(const gp_request *req, gp_format *out, gp_reply *reply);

/* The q that an Accept header gives media type mt: that of its most specific matching
 * range (exact, type/any, any/any), 0 when none matches. */
double gp_accept_quality(const char *accept, const char *mt);

/* Whether the request's Accept-Encoding allows gzip: "gzip" (or "x-gzip") with a q above
 * 0, or "*" with a q above 0 when gzip is not named. */
int gp_render_accepts_gzip(const gp_request *req);

/* The revision of the writers' output: bump it whenever a writer's bytes change for the
 * same result (a new field, another rounding), so that no cache keeps the old bytes
 * under an ETag that still matches. */
#define GP_RENDER_REVISION 2 /* 2: the statistics' bins have their standard error */

/* The strong entity tag (with its quotes) of result `res` in `format`, gzip or not, as
 * `spec` (the job's, with the request's overrides such as ?color=) renders it: the stored
 * result's version, the format, the picture's colouring for the SVG, the encoding, and
 * the build's version and writer revision, so that different bytes never share a tag.
 * `spec` is NULL for a process whose pictures have no colouring choice.
 * `out` has room for GP_ETAG_SIZE bytes. */
#define GP_ETAG_SIZE 112
void gp_render_etag(const gp_stored_result *res, const gp_spec *spec, gp_format format, int gzip,
                    char *out);

/* Whether the request's If-None-Match lists `etag` (weak comparison, as RFC 9110 asks for
 * If-None-Match) or is "*". */
int gp_render_not_modified(const gp_request *req, const char *etag);

#endif
