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

#endif
