/* routes_web.c - the web page: its files, compiled into the daemon (server/web/), served
 * at /ui/NAME, and its HTML at / for a browser (content negotiation against the JSON
 * landing page, which API clients keep getting). */
#include <string.h>

#include "embedded.h"
#include "problem.h"
#include "render.h"
#include "routes.h"

/* The page loads nothing from elsewhere and runs no inline script or style: everything
 * comes from this origin, and pictures of results are blob: URLs made from fetched SVG. */
#define PAGE_CSP                                                                            \
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' blob:; " \
    "connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"
/* Revalidated at every use (a 304 with the ETag costs a few bytes): a daemon upgraded in
 * place never serves a page that no longer matches its API from a browser's cache. */
#define WEB_CACHE_CONTROL "no-cache"
#define PAGE_NAME "index.html"

/* The media type of a served file, from its extension. */
static const char *media_type(const char *name)
{
    static const struct {
        const char *ext, *type;
    } types[] = {
        {".html", "text/html; charset=utf-8"},      {".css", "text/css; charset=utf-8"},
        {".js", "text/javascript; charset=utf-8"}, {".svg", "image/svg+xml"},
        {".json", "application/json"},             {".png", "image/png"},
    };
    const char *dot = strrchr(name, '.');
    for (size_t i = 0; dot && i < sizeof types / sizeof types[0]; i++)
        if (strcmp(dot, types[i].ext) == 0)
            return types[i].type;
    return "application/octet-stream";
}

static const gp_embedded_file *find_file(const char *name)
{
    for (size_t i = 0; i < gp_web_files_count; i++)
        if (strcmp(gp_web_files[i].name, name) == 0)
            return &gp_web_files[i];
    return NULL;
}

static int serve(gp_request *req, gp_reply *reply, const gp_embedded_file *f)
{
    reply->etag = f->etag;
    reply->cache_control = WEB_CACHE_CONTROL;
    reply->csp = PAGE_CSP;
    if (gp_render_not_modified(req, f->etag)) { /* the client's copy is current */
        reply->status = 304;
        return GP_ROUTE_DONE;
    }
    if (gp_reply_text(reply, 200, media_type(f->name), (const char *)f->bytes, f->len))
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path, "out of memory");
    return GP_ROUTE_DONE;
}

int gp_route_web_file(gp_request *req, gp_reply *reply)
{
    const gp_embedded_file *f = find_file(req->id);
    if (!f) {
        gp_problem(reply, 404, GP_PROBLEM_NOT_FOUND, req->path,
                   "the web page has no file %s; it starts at /", req->id);
        return GP_ROUTE_DONE;
    }
    return serve(req, reply, f);
}

int gp_route_web_wants_page(const gp_request *req, gp_reply *reply)
{
    const char *f = gp_request_query(req, "f");
    if (f) {
        if (strcmp(f, "html") == 0 || strcmp(f, "json") == 0)
            return strcmp(f, "html") == 0;
        gp_problem(reply, 400, GP_PROBLEM_BAD_PARAMETER, req->path,
                   "unknown format f=%.40s; expected html or json", f);
        return -1;
    }
    /* a browser asks for HTML first; curl's any/any or no Accept at all keeps JSON */
    const char *accept = gp_request_header(req, "Accept");
    if (!accept)
        return 0;
    return gp_accept_quality(accept, "text/html") > gp_accept_quality(accept, "application/json");
}

int gp_route_web_page(gp_request *req, gp_reply *reply)
{
    const gp_embedded_file *page = find_file(PAGE_NAME);
    if (!page) {
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path, "the web page was not built in");
        return GP_ROUTE_DONE;
    }
    return serve(req, reply, page);
}
