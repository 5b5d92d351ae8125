/* render.h - a finished job's result as the client asked for it: the format chosen by
 * ?f= or Accept among the engine's writers (gp_format), and the result rebuilt from the
 * store (spec + disks; the statistics, F and the Laguerre cells are computed again from
 * them, deterministically). Every
 * format the engine's gp_write_result knows is served without a change here. */
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

/* Rebuilds the spec and result of a successful job of `owner` (NULL: any owner; see
 * store.h). On success returns 0 and the caller frees both (gp_spec_free,
 * gp_result_free); else GP_SRV_ENOTFOUND, GP_SRV_EDB, GP_ENOMEM or the engine's code,
 * with spec and result zeroed. Timings are not loaded. */
int gp_render_load(gp_db *db, const char *id, const char *owner, gp_spec *spec, gp_result *result);

/* Writes the result in `format` to a new malloc'd buffer (*body, *len). Returns 0 or a
 * negative code. */
int gp_render_format(const gp_spec *spec, const gp_result *result, gp_format format,
                     char **body, size_t *len);

#endif
