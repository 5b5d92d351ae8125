/* download.h - a stored result streamed to a client in one format, gzip-compressed when
 * asked: rendered piece by piece from the stored sections into the connection's buffer
 * each time the socket has taken the last piece, so the daemon's memory grows neither
 * with the size of the result nor with the number of downloads (a download holds about a
 * megabyte: a window of the result, a chunk per section, the compressor's state). No
 * geometry: the writers only read what the worker stored. */
#ifndef GRAINPACKD_DOWNLOAD_H
#define GRAINPACKD_DOWNLOAD_H

#include "grainpack/io.h"
#include "reply.h"
#include "request.h"
#include "sections.h"
#include "service.h"
#include "store.h"

/* The compression level of gzip answers. Why this value: see bench/SERVICE.md; level 1
 * compresses the text formats to about 45% at some 60 MB/s of one core, where the
 * default 6 gains a few per cent for three times the time. */
#define GP_DOWNLOAD_GZIP_LEVEL 1

/* A body stream (reply.h) writing the result `res` in `format`, gzip-compressed when
 * `gzip`. Takes `res` and `spec` over (they are zeroed here, and freed with the stream).
 * Returns 0 with *out set, or GP_ENOMEM (then res and spec are freed). */
int gp_download_new(gp_service *svc, gp_stored_result *res, gp_spec *spec, gp_format format,
                    int gzip, gp_body_stream **out);

/* What renders a stored result of another process than the engine's writers know: run
 * appends to `text` until text->len reaches `want` or the result is all out, reading the
 * stored sections through read(read_ctx, ...) (sections.h), and returns 1 when more is to
 * come, 0 when done, or a negative code; free frees ctx (may be NULL). */
typedef struct gp_download_renderer {
    void *ctx;
    int (*run)(void *ctx, gp_section_read_fn read, void *read_ctx, gp_out *text, size_t want);
    void (*free)(void *ctx);
} gp_download_renderer;

/* gp_download_new with `renderer` (taken over) instead of the writer of a format;
 * `name` (static) names the format in the log. Takes `res` over. Returns 0 with *out set,
 * or GP_ENOMEM (then res and the renderer are freed). */
int gp_download_new_renderer(gp_service *svc, gp_stored_result *res, gp_download_renderer renderer,
                             const char *name, int gzip, gp_body_stream **out);

/* The headers of a download of job req->id: its ETag, Vary, Cache-Control, and either a
 * 304 (If-None-Match lists the tag: returns 1, reply done) or its Content-Disposition
 * (job-ID.EXT) and Content-Encoding (returns 0: the caller streams the body). */
int gp_download_headers(gp_request *req, const char *etag, const char *ext, int gzip,
                        gp_reply *reply);

/* Answers 200 with `stream` (a gp_download_new's) of media type `type`. */
void gp_download_reply(gp_request *req, gp_body_stream *stream, const char *type, gp_reply *reply);

#endif
