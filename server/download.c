/* download.c - streaming a stored result: the engine's writer reads the sections through
 * a gp_result_reader (a store connection held for one fill only), its text goes to the
 * connection's buffer as it is, or through zlib's deflate in gzip framing. */
#include "download.h"

#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "sections.h"
#include "io_svg_mesh.h"
#include "mesh_source.h"
#include "log.h"
#include "render.h"

/* What the writer renders in one go: libmicrohttpd asks for as much as is free in its
 * buffer, often a few hundred bytes; rendering that little each time would cost a store
 * connection and a window of the result per grain. The rest waits in `text` for the next
 * calls. Also what deflate is given at once (it works best on large inputs). */
#define RENDER_BATCH ((size_t)64 * 1024)
/* zlib's window bits (the largest, 32 KB) plus 16: gzip framing instead of zlib's. */
#define GZIP_WINDOW_BITS (15 + 16)
/* zlib's default memory level: 128 KB of hash tables. */
#define GZIP_MEM_LEVEL 8

typedef struct gp_download {
    gp_body_stream stream; /* first: the reply's view of the download */
    gp_service *svc;
    gp_stored_result res;
    gp_spec spec;
    gp_format format;
    gp_result_reader *reader;
    gp_sections_source *source;
    int loaded;                /* load_mesh ran */
    gp_writer *writer;
    gp_download_renderer renderer; /* instead of writer, for another process's result */
    const char *name;              /* of the format, for the log */
    gp_out text;       /* rendered; bytes from `sent` on not handed on yet */
    size_t sent;
    gp_db *db;         /* held during one fill only */
    int rendered;      /* the writer is done */
    int gzip, z_open, z_done;
    z_stream z;
} gp_download;

static int read_section(void *ctx, const char *tag, uint64_t offset, void *dst, size_t len)
{
    gp_download *d = ctx;
    return d->db ? gp_result_reader_read(d->reader, d->db, tag, offset, dst, len) : GP_SRV_EDB;
}

/* Sets up what a format reads besides the per-grain windows. The mesh formats read the
 * mesh window by window (msh, inp, vtu), but for a vtu of a result stored before the
 * elements' qualities were (they need each element's nodes: the mesh is then read whole,
 * as it used to be), and the SVG picture draws the edges of a mesh under its cap (read
 * whole: some ten megabytes at most), nothing beyond. Returns 0 or the reader's error. */
static int load_mesh(gp_download *d)
{
    gp_result *r = &d->res.summary;
    int rc;
    if (r->has_mesh && (d->format == GP_FORMAT_MSH || d->format == GP_FORMAT_INP ||
                        (d->format == GP_FORMAT_VTU && d->res.mesh_quality))) {
        gp_mesh_source src;
        if ((rc = gp_sections_mesh_source(r, read_section, d, 0, d->res.mesh_quality, &src)))
            return rc;
        gp_writer_set_mesh(d->writer, &src);
        return 0;
    }
    if (r->has_mesh && d->format == GP_FORMAT_VTU) {
        gp_mesh_source src;
        if ((rc = gp_sections_read_mesh(r, read_section, d)) ||
            (rc = gp_mesh_source_memory(&r->mesh, &src)))
            return rc;
        gp_writer_set_mesh(d->writer, &src);
        return 0;
    }
    if (r->has_mesh && d->format == GP_FORMAT_SVG && gp_svg_mesh_drawable(&r->mesh))
        return gp_sections_read_mesh(r, read_section, d);
    return 0;
}

/* Renders on until `text` holds `want` bytes or the writer is done. Returns 0 or the
 * writer's error (logged). */
static int render(gp_download *d, size_t want)
{
    if (d->rendered || d->text.len >= want)
        return 0;
    if (!d->db && !(d->db = gp_store_acquire(d->svc->store, 1))) {
        gp_log("download: no store connection: the download is cut short");
        return GP_SRV_EDB;
    }
    int rc = 0;
    if (d->renderer.run) {
        rc = d->renderer.run(d->renderer.ctx, read_section, d, &d->text, want);
    } else {
        if (!d->loaded) {
            rc = load_mesh(d);
            d->loaded = rc == 0;
        }
        if (rc == 0)
            rc = gp_writer_run(d->writer, &d->text, want);
    }
    if (rc < 0) {
        gp_log("download: rendering %s of a stored result failed (%d): the download is cut short",
               d->name, rc);
        return rc;
    }
    d->rendered = rc == 0;
    return 0;
}

/* Gives back the store connection: none is held while the client reads. */
static void let_go(gp_download *d)
{
    gp_store_release(d->svc->store, d->db);
    d->db = NULL;
}

static long fill_plain(gp_download *d, char *buf, size_t max)
{
    if (d->sent == d->text.len) { /* all handed on: a new batch */
        d->text.len = d->sent = 0;
        int rc = render(d, max > RENDER_BATCH ? max : RENDER_BATCH);
        let_go(d);
        if (rc)
            return -1;
    }
    size_t n = d->text.len - d->sent < max ? d->text.len - d->sent : max;
    memcpy(buf, d->text.buf + d->sent, n);
    d->sent += n;
    return (long)n;
}

static long fill_gzip(gp_download *d, char *buf, size_t max)
{
    z_stream *z = &d->z;
    z->next_out = (Bytef *)buf;
    z->avail_out = (uInt)max;
    while (z->avail_out > 0 && !d->z_done) {
        if (z->avail_in == 0) {
            d->text.len = 0; /* deflate took it all */
            if (render(d, RENDER_BATCH)) {
                let_go(d);
                return -1;
            }
            z->next_in = (Bytef *)d->text.buf;
            z->avail_in = (uInt)d->text.len;
        }
        /* once the writer is done, what zlib holds is the last of the input */
        int rc = deflate(z, d->rendered ? Z_FINISH : Z_NO_FLUSH);
        if (rc == Z_STREAM_END) {
            d->z_done = 1;
        } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
            gp_log("download: deflate failed (%d): the download is cut short", rc);
            let_go(d);
            return -1;
        }
    }
    let_go(d);
    return (long)(max - z->avail_out);
}

static long fill(gp_body_stream *s, char *buf, size_t max)
{
    gp_download *d = (gp_download *)s;
    return d->gzip ? fill_gzip(d, buf, max) : fill_plain(d, buf, max);
}

static void release(gp_body_stream *s)
{
    gp_download *d = (gp_download *)s;
    let_go(d);
    if (d->z_open)
        deflateEnd(&d->z);
    gp_writer_free(d->writer);
    if (d->renderer.free)
        d->renderer.free(d->renderer.ctx);
    gp_sections_source_free(d->source);
    gp_result_reader_free(d->reader);
    gp_out_free(&d->text);
    gp_stored_result_free(&d->res);
    gp_spec_free(&d->spec);
    gp_metrics_download(d->svc->metrics, -1);
    free(d);
}

/* A download of res (taken over) without its renderer yet: NULL when out of memory (res
 * is then freed). */
static gp_download *download_new(gp_service *svc, gp_stored_result *res, int gzip)
{
    gp_download *d = calloc(1, sizeof *d);
    if (!d) {
        gp_stored_result_free(res);
        return NULL;
    }
    d->stream = (gp_body_stream){fill, release};
    d->svc = svc;
    d->res = *res;
    memset(res, 0, sizeof *res);
    d->gzip = gzip;
    gp_metrics_download(svc->metrics, 1);
    if (gp_out_init(&d->text, 2 * RENDER_BATCH, NULL, NULL) ||
        !(d->reader = gp_result_reader_new(d->res.key))) {
        release(&d->stream);
        return NULL;
    }
    return d;
}

/* Opens the compressor when asked and hands the stream out. Returns 0 or GP_ENOMEM (then
 * everything is freed). */
static int download_start(gp_download *d, gp_body_stream **out)
{
    if (d->gzip && deflateInit2(&d->z, GP_DOWNLOAD_GZIP_LEVEL, Z_DEFLATED, GZIP_WINDOW_BITS,
                                GZIP_MEM_LEVEL, Z_DEFAULT_STRATEGY) != Z_OK) {
        release(&d->stream);
        return GP_ENOMEM;
    }
    d->z_open = d->gzip;
    *out = &d->stream;
    return 0;
}

int gp_download_new(gp_service *svc, gp_stored_result *res, gp_spec *spec, gp_format format,
                    int gzip, gp_body_stream **out)
{
    *out = NULL;
    gp_download *d = download_new(svc, res, gzip);
    if (!d) {
        gp_spec_free(spec);
        return GP_ENOMEM;
    }
    d->spec = *spec;
    memset(spec, 0, sizeof *spec);
    d->format = format;
    d->name = gp_format_name(format);
    gp_grain_source grains;
    if (!(d->source = gp_sections_source_new(&d->res.summary, read_section, d, 0)) ||
        (grains = gp_sections_source_grains(d->source),
         !(d->writer = gp_writer_new(format, &d->spec, &d->res.summary, &grains)))) {
        release(&d->stream);
        return GP_ENOMEM;
    }
    return download_start(d, out);
}

int gp_download_new_renderer(gp_service *svc, gp_stored_result *res, gp_download_renderer renderer,
                             const char *name, int gzip, gp_body_stream **out)
{
    *out = NULL;
    gp_download *d = download_new(svc, res, gzip);
    if (!d) {
        if (renderer.free)
            renderer.free(renderer.ctx);
        return GP_ENOMEM;
    }
    d->renderer = renderer;
    d->name = name;
    return download_start(d, out);
}

int gp_download_headers(gp_request *req, const char *etag, const char *ext, int gzip,
                        gp_reply *reply)
{
    gp_reply_header_add(reply, "ETag", "%s", etag);
    /* the bytes depend on Accept (the format, without ?f=) and Accept-Encoding */
    gp_reply_header_add(reply, "Vary", "Accept, Accept-Encoding");
    /* a result never changes but may be deleted, and is per key: ask again each time,
     * which a 304 makes cheap */
    gp_reply_header_add(reply, "Cache-Control", "private, no-cache");
    if (gp_render_not_modified(req, etag)) {
        gp_reply_take(reply, 304, NULL, NULL, 0);
        return 1;
    }
    gp_reply_header_add(reply, "Content-Disposition", "attachment; filename=\"job-%s.%s\"",
                        req->id, ext);
    if (gzip)
        gp_reply_header_add(reply, "Content-Encoding", "gzip");
    return 0;
}

void gp_download_reply(gp_request *req, gp_body_stream *stream, const char *type, gp_reply *reply)
{
    gp_reply_stream(reply, 200, type, stream);
    /* libmicrohttpd 0.9.75 ends the headers of a HEAD answer to a chunked response with
     * the last chunk ("0\r\n\r\n") although HEAD has no body: a client reusing the
     * connection would read it as the next status line, so the connection closes */
    reply->close = strcmp(req->method, "HEAD") == 0;
}
