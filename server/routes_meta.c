/* routes_meta.c - what the service is: landing page, conformance, the process and its
 * description, health, metrics and the OpenAPI document. */
#include <string.h>

#include "embedded.h"
#include "grainpack/version.h"
#include "log.h"
#include "problem.h"
#include "processes.h"
#include "routes.h"
#include "workers.h"

#define JSON_TYPE "application/json"
#define OGC_REL "http://www.opengis.net/def/rel/ogc/1.0/"
#define OGC_CONF "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/"

static json_t *make_link(const char *href, const char *rel, const char *type, const char *title)
{
    return json_pack("{s:s, s:s, s:s, s:s}", "href", href, "rel", rel, "type", type, "title",
                     title);
}

int gp_route_landing(gp_request *req, gp_reply *reply)
{
    reply->vary = "Accept"; /* the page for a browser, this document for the others */
    int page = gp_route_web_wants_page(req, reply);
    if (page)
        return page < 0 ? GP_ROUTE_DONE : gp_route_web_page(req, reply);
    json_t *body = json_pack(
        "{s:s, s:s, s:[o, o, o, o, o, o, o, o]}", "title", "grainpack",
        "description",
        "Packs a rectangle with disks (pack2d) or a box with spheres (pack3d) whose radii "
        "follow a distribution (advancing-front method of INRIA report RR-6414), as "
        "asynchronous jobs in the style of OGC API - Processes.",
        "links", make_link("/", "self", JSON_TYPE, "this document"),
        make_link("/?f=html", "alternate", "text/html", "the web page: design, run and look at jobs"),
        make_link("/openapi.yaml", "service-desc", "application/vnd.oai.openapi;version=3.1",
             "the API definition (OpenAPI 3.1)"),
        make_link("/conformance", OGC_REL "conformance", JSON_TYPE, "conformance classes"),
        make_link("/processes", OGC_REL "processes", JSON_TYPE, "the processes offered"),
        make_link("/jobs", OGC_REL "job-list", JSON_TYPE, "jobs, newest first"),
        make_link("/health", "status", JSON_TYPE, "health of the service"),
        make_link("/metrics", "metrics", "text/plain", "Prometheus metrics"));
    gp_reply_json(reply, 200, JSON_TYPE, body);
    return GP_ROUTE_DONE;
}

int gp_route_conformance(gp_request *req, gp_reply *reply)
{
    (void)req;
    json_t *body = json_pack("{s:[s, s, s, s, s]}", "conformsTo", OGC_CONF "core",
                             OGC_CONF "ogc-process-description", OGC_CONF "json",
                             OGC_CONF "job-list", OGC_CONF "dismiss");
    gp_reply_json(reply, 200, JSON_TYPE, body);
    return GP_ROUTE_DONE;
}

int gp_route_processes(gp_request *req, gp_reply *reply)
{
    (void)req;
    json_t *list = json_array();
    for (size_t i = 0; list && i < gp_process_count(); i++) {
        json_t *summary = gp_process_description(gp_process_at(i));
        if (!summary) {
            json_decref(list);
            list = NULL;
            break;
        }
        /* a summary is the description without inputs and outputs */
        json_object_del(summary, "inputs");
        json_object_del(summary, "outputs");
        json_array_append_new(list, summary);
    }
    json_t *body = json_pack("{s:o, s:[o]}", "processes", list, "links",
                             make_link("/processes", "self", JSON_TYPE, "this document"));
    gp_reply_json(reply, 200, JSON_TYPE, body);
    return GP_ROUTE_DONE;
}

int gp_route_process(gp_request *req, gp_reply *reply)
{
    const gp_process_def *process = gp_process_find(req->id);
    if (!process) {
        gp_problem_no_such_process(reply, req->path, req->id);
        return GP_ROUTE_DONE;
    }
    gp_reply_json(reply, 200, JSON_TYPE, gp_process_description(process));
    return GP_ROUTE_DONE;
}

int gp_route_health(gp_request *req, gp_reply *reply)
{
    gp_service *svc = req->svc;
    gp_db *db = gp_store_acquire(svc->store, 1);
    int db_ok = db && gp_store_healthy(db);
    gp_store_release(svc->store, db);
    /* readable but the last write failed: the service answers, new jobs are refused */
    int writes = gp_store_write_state(svc->store);
    const char *database = !db_ok                       ? "unavailable"
                           : writes == GP_SRV_EFULL     ? "full"
                           : writes == GP_SRV_EUNWRITABLE ? "unwritable"
                                                        : "ok";
    const char *status = !db_ok ? "unavailable" : writes ? "degraded" : "ok";
    int accepting = atomic_load(&svc->accepting);
    json_t *body = json_pack("{s:s, s:s, s:b, s:s, s:i, s:i, s:I, s:f, s:s, s:s, s:s}", "status",
                             status, "database", database, "accepting", accepting, "access",
                             svc->keys ? "keys" : "open", "workers", svc->cfg->workers,
                             "workers_busy", gp_pool_busy(svc->pool), "queue_depth",
                             (json_int_t)atomic_load(&svc->queued), "uptime_seconds",
                             gp_monotonic_seconds() - svc->started, "version", GP_VERSION,
                             "store", gp_store_kind(svc->store), "node", svc->cfg->node);
    gp_reply_json(reply, db_ok ? 200 : 503, JSON_TYPE, body);
    if (!db_ok)
        reply->retry_after = GP_RETRY_AFTER_SECONDS;
    return GP_ROUTE_DONE;
}

int gp_route_metrics(gp_request *req, gp_reply *reply)
{
    gp_service *svc = req->svc;
    gp_metrics_gauges g;
    memset(&g, 0, sizeof g);
    gp_db *db = gp_store_acquire(svc->store, 1);
    int rc = db ? gp_store_count(db, g.jobs) : GP_SRV_EDB;
    gp_store_release(svc->store, db);
    if (rc) {
        gp_problem_store_unavailable(reply, req->path);
        return GP_ROUTE_DONE;
    }
    g.queue_depth = atomic_load(&svc->queued);
    g.workers = svc->cfg->workers;
    g.workers_busy = gp_pool_busy(svc->pool);
    g.workers_abandoned = gp_pool_abandoned(svc->pool);
    g.slow_heads = atomic_load(&svc->http.slow_heads);
    g.connections = atomic_load(&svc->http.open);
    g.polls_hung_up = gp_waiters_hung_up(svc->waiters);
    g.node = svc->cfg->node;
    g.store = gp_store_kind(svc->store);
    size_t len;
    char *text = gp_metrics_render(svc->metrics, &g, &len);
    if (!text) {
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path, "out of memory");
        return GP_ROUTE_DONE;
    }
    gp_reply_take(reply, 200, "text/plain; version=0.0.4; charset=utf-8", text, len);
    return GP_ROUTE_DONE;
}

int gp_route_openapi(gp_request *req, gp_reply *reply)
{
    (void)req;
    if (gp_reply_text(reply, 200, "application/yaml", (const char *)gp_openapi_yaml,
                      gp_openapi_yaml_len))
        gp_problem(reply, 500, GP_PROBLEM_INTERNAL, req->path, "out of memory");
    return GP_ROUTE_DONE;
}
