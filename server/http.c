/* http.c - libmicrohttpd callbacks: gathering the request, routing, CORS, the response,
 * and the per-request log line. */
#include "http.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "log.h"
#include "problem.h"
#include "routes.h"

/* Connections kept open at most: enough for 100 benchmark clients and 50 long-polls each
 * way, far below the file descriptor limit. */
#define CONNECTION_LIMIT 2048
/* Seconds an idle connection is kept; longer than the longest long-poll. */
#define IDLE_TIMEOUT_MARGIN 60
/* A body without Content-Length that passes the cap is read on (and dropped) up to this
 * many times the cap, so that the client still gets its 413; beyond, it is cut off. */
#define DISCARD_FACTOR 16
/* How long a browser may cache a CORS preflight answer. */
#define CORS_MAX_AGE "600"

/* A route table entry: a path pattern whose "{}" segment is an id, and a function per
 * method (NULL: not allowed). HEAD is served by GET. */
typedef struct route {
    const char *pattern;
    gp_route_fn get, post, del;
} route;

static const route routes[] = {
    {"/", gp_route_landing, NULL, NULL},
    {"/conformance", gp_route_conformance, NULL, NULL},
    {"/processes", gp_route_processes, NULL, NULL},
    {"/processes/{}", gp_route_process, NULL, NULL},
    {"/processes/{}/execution", NULL, gp_route_execute, NULL},
    {"/jobs", gp_route_jobs, NULL, NULL},
    {"/jobs/{}", gp_route_job, NULL, gp_route_dismiss},
    {"/jobs/{}/results", gp_route_results, NULL, NULL},
    {"/jobs/{}/statistics", gp_route_statistics, NULL, NULL},
    {"/health", gp_route_health, NULL, NULL},
    {"/metrics", gp_route_metrics, NULL, NULL},
    {"/openapi.yaml", gp_route_openapi, NULL, NULL},
};
#define NROUTES (sizeof routes / sizeof routes[0])

/* The longest id segment accepted; job ids are 36 characters. */
#define ID_MAX 64

/* Per-connection state, from the first call of a request to its completion. */
typedef struct request_state {
    const route *route;
    char id[ID_MAX + 1];
    char *body;
    size_t len, cap;
    int too_large;   /* the body passed the cap: it is dropped, 413 answers */
    size_t discarded;
    int answered;    /* a response was queued */
    int suspended;   /* a long-poll is waiting */
    char method[8], path[200]; /* for the log line */
    unsigned status;
    size_t bytes;
    double t0;
} request_state;

const char *gp_request_query(const gp_request *req, const char *name)
{
    return MHD_lookup_connection_value(req->conn, MHD_GET_ARGUMENT_KIND, name);
}

const char *gp_request_header(const gp_request *req, const char *name)
{
    return MHD_lookup_connection_value(req->conn, MHD_HEADER_KIND, name);
}

/* Matches url against the table; the "{}" segment goes to id. NULL when nothing matches
 * (an id segment longer than ID_MAX, or with odd characters, matches nothing either). */
static const route *match(const char *url, char id[ID_MAX + 1])
{
    size_t n = strlen(url);
    if (n > 1 && url[n - 1] == '/')
        n--; /* "/jobs/" is "/jobs" */
    for (size_t r = 0; r < NROUTES; r++) {
        const char *p = routes[r].pattern, *u = url, *end = url + n;
        id[0] = '\0';
        int ok = 1;
        while (ok && *p) {
            if (p[0] == '{' && p[1] == '}') {
                size_t k = 0;
                while (u < end && *u != '/') {
                    char c = *u++;
                    int fine = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') ||
                               (c >= 'A' && c <= 'Z') || c == '-' || c == '_' || c == '.';
                    if (!fine || k == ID_MAX)
                        ok = 0;
                    else
                        id[k++] = c;
                }
                id[k] = '\0';
                ok = ok && k > 0;
                p += 2;
            } else if (u < end && *u == *p) {
                u++;
                p++;
            } else {
                ok = 0;
            }
        }
        if (ok && u == end)
            return &routes[r];
    }
    return NULL;
}

static void allow_list(const route *rt, char *out, size_t size)
{
    snprintf(out, size, "%s%s%sOPTIONS", rt->get ? "GET, HEAD, " : "", rt->post ? "POST, " : "",
             rt->del ? "DELETE, " : "");
}

/* Adds the CORS headers when the request comes from an allowed origin. */
static void add_cors(gp_service *svc, struct MHD_Connection *conn, struct MHD_Response *resp,
                     const route *rt, int preflight)
{
    const char *origin = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Origin");
    if (!gp_config_origin_allowed(svc->cfg, origin))
        return;
    int any = strcmp(svc->cfg->cors_origins, "*") == 0;
    MHD_add_response_header(resp, "Access-Control-Allow-Origin", any ? "*" : origin);
    if (!any)
        MHD_add_response_header(resp, "Vary", "Origin");
    MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                            "Location, Retry-After, Content-Type");
    if (preflight && rt) {
        char allow[64];
        allow_list(rt, allow, sizeof allow);
        MHD_add_response_header(resp, "Access-Control-Allow-Methods", allow);
        MHD_add_response_header(resp, "Access-Control-Allow-Headers", "Content-Type, Accept");
        MHD_add_response_header(resp, "Access-Control-Max-Age", CORS_MAX_AGE);
    }
}

/* Queues reply as the response (taking its body), logs and counts the request. */
static enum MHD_Result respond(gp_service *svc, struct MHD_Connection *conn, request_state *st,
                               gp_reply *reply, int preflight)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(reply->len, reply->body ? reply->body : (void *)"",
                                        reply->body ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
    if (!resp) {
        gp_reply_free(reply);
        return MHD_NO;
    }
    reply->body = NULL; /* now the response's */
    if (reply->content_type)
        MHD_add_response_header(resp, "Content-Type", reply->content_type);
    if (reply->location[0])
        MHD_add_response_header(resp, "Location", reply->location);
    if (reply->allow[0])
        MHD_add_response_header(resp, "Allow", reply->allow);
    if (reply->retry_after > 0) {
        char seconds[16];
        snprintf(seconds, sizeof seconds, "%d", reply->retry_after);
        MHD_add_response_header(resp, "Retry-After", seconds);
    }
    add_cors(svc, conn, resp, st->route, preflight);
    enum MHD_Result rc = MHD_queue_response(conn, reply->status, resp);
    MHD_destroy_response(resp);
    st->answered = 1;
    st->status = reply->status;
    st->bytes = reply->len;
    gp_metrics_request(svc->metrics, reply->status);
    gp_reply_free(reply);
    return rc;
}

/* Whether a Content-Type is JSON: application/json, parameters (charset) allowed. */
static int is_json_type(const char *type)
{
    if (!type)
        return 0;
    while (*type == ' ')
        type++;
    size_t n = strlen("application/json");
    return strncasecmp(type, "application/json", n) == 0 &&
           (type[n] == '\0' || type[n] == ';' || type[n] == ' ');
}

/* Checks done before the body is read: path, method, media type, declared length.
 * Returns 1 with reply filled when the request is answered already. */
static int precheck(gp_service *svc, struct MHD_Connection *conn, const char *url,
                    const char *method, request_state *st, gp_reply *reply)
{
    if (!st->route) {
        gp_problem(reply, 404, GP_PROBLEM_NOT_FOUND, url,
                   "no resource at %s; GET / lists the API's links and GET /openapi.yaml "
                   "describes it", url);
        return 1;
    }
    const route *rt = st->route;
    int is_get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    int is_post = strcmp(method, "POST") == 0, is_del = strcmp(method, "DELETE") == 0;
    if (strcmp(method, "OPTIONS") == 0) {
        reply->status = 204;
        allow_list(rt, reply->allow, sizeof reply->allow);
        return 1;
    }
    if (!((is_get && rt->get) || (is_post && rt->post) || (is_del && rt->del))) {
        allow_list(rt, reply->allow, sizeof reply->allow);
        gp_problem(reply, 405, GP_PROBLEM_METHOD_NOT_ALLOWED, url,
                   "%s is not allowed on %s; allowed: %s", method, url, reply->allow);
        return 1;
    }
    if (!is_post)
        return 0;
    if (strcmp(st->id, GP_PROCESS_ID) != 0) { /* before the body: it would not be used */
        gp_problem_no_such_process(reply, url, st->id);
        return 1;
    }
    const char *type = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Content-Type");
    if (!is_json_type(type)) {
        gp_problem(reply, 415, GP_PROBLEM_UNSUPPORTED_MEDIA_TYPE, url,
                   "the body must be sent as application/json (got %s%s%s); with curl: "
                   "-H 'Content-Type: application/json'",
                   type ? "'" : "no Content-Type", type ? type : "", type ? "'" : "");
        return 1;
    }
    const char *length = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Content-Length");
    if (length && strtoull(length, NULL, 10) > svc->cfg->max_body) {
        gp_problem(reply, 413, GP_PROBLEM_BODY_TOO_LARGE, url,
                   "the body has %s bytes, more than the limit of %zu (--max-body)", length,
                   svc->cfg->max_body);
        return 1;
    }
    return 0;
}

/* Appends upload data under the cap. Returns 0, or 1 when the cap was passed. */
static int gather(gp_service *svc, request_state *st, const char *data, size_t size)
{
    if (st->len + size > svc->cfg->max_body)
        return 1;
    if (st->len + size > st->cap) {
        size_t cap = st->cap ? st->cap : 4096;
        while (cap < st->len + size)
            cap *= 2;
        char *grown = realloc(st->body, cap);
        if (!grown)
            return 1;
        st->body = grown;
        st->cap = cap;
    }
    memcpy(st->body + st->len, data, size);
    st->len += size;
    return 0;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version,
                                  const char *upload_data, size_t *upload_size, void **con_cls)
{
    (void)version;
    gp_service *svc = cls;
    request_state *st = *con_cls;
    gp_reply reply;
    memset(&reply, 0, sizeof reply);
    if (!st) {
        if (!(st = calloc(1, sizeof *st)))
            return MHD_NO;
        *con_cls = st;
        st->t0 = gp_monotonic_seconds();
        snprintf(st->method, sizeof st->method, "%s", method);
        snprintf(st->path, sizeof st->path, "%s", url);
        st->route = match(url, st->id);
        if (precheck(svc, conn, url, method, st, &reply))
            return respond(svc, conn, st, &reply, strcmp(method, "OPTIONS") == 0);
        return MHD_YES; /* the body (if any) comes in the next calls */
    }
    if (st->answered)
        return MHD_YES;
    if (*upload_size) {
        /* past the cap the rest is read and dropped, and 413 answered once it is all in:
         * libmicrohttpd cannot answer in the middle of a chunked upload. A client that
         * keeps sending far past the cap is cut off. */
        size_t size = *upload_size;
        *upload_size = 0;
        if (!st->too_large && gather(svc, st, upload_data, size))
            st->too_large = 1;
        if (st->too_large && (st->discarded += size) > DISCARD_FACTOR * svc->cfg->max_body)
            return MHD_NO;
        return MHD_YES;
    }
    if (st->too_large) {
        gp_problem(&reply, 413, GP_PROBLEM_BODY_TOO_LARGE, url,
                   "the body is larger than the limit of %zu bytes (--max-body)",
                   svc->cfg->max_body);
        return respond(svc, conn, st, &reply, 0);
    }
    const route *rt = st->route;
    int is_get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    gp_route_fn fn = is_get ? rt->get : strcmp(method, "POST") == 0 ? rt->post : rt->del;
    gp_request req = {svc,     conn,    method, url, st->id, st->body ? st->body : "",
                      st->len, st->suspended};
    st->suspended = 0;
    if (fn(&req, &reply) == GP_ROUTE_SUSPENDED) {
        st->suspended = 1;
        return MHD_YES;
    }
    return respond(svc, conn, st, &reply, 0);
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    (void)cls;
    request_state *st = *con_cls;
    if (!st)
        return;
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    char addr[INET6_ADDRSTRLEN] = "?";
    if (info && info->client_addr) {
        const struct sockaddr *sa = info->client_addr;
        if (sa->sa_family == AF_INET)
            inet_ntop(AF_INET, &((const struct sockaddr_in *)(const void *)sa)->sin_addr, addr,
                      sizeof addr);
        else if (sa->sa_family == AF_INET6)
            inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)(const void *)sa)->sin6_addr, addr,
                      sizeof addr);
    }
    if (st->answered)
        gp_log("http %s %s %s %u %zu bytes %.1f ms%s", addr, st->method, st->path, st->status,
               st->bytes,
               1e3 * (gp_monotonic_seconds() - st->t0),
               toe == MHD_REQUEST_TERMINATED_COMPLETED_OK ? "" : " (connection closed early)");
    free(st->body);
    free(st);
    *con_cls = NULL;
}

int gp_http_start(gp_service *svc, struct MHD_Daemon **out, unsigned *port)
{
    const gp_config *cfg = svc->cfg;
    struct sockaddr_in v4;
    struct sockaddr_in6 v6;
    struct sockaddr *addr;
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | MHD_ALLOW_SUSPEND_RESUME |
                     MHD_USE_TURBO;
    memset(&v4, 0, sizeof v4);
    memset(&v6, 0, sizeof v6);
    if (inet_pton(AF_INET, cfg->host, &v4.sin_addr) == 1) {
        v4.sin_family = AF_INET;
        v4.sin_port = htons((uint16_t)cfg->port);
        addr = (struct sockaddr *)&v4;
    } else if (inet_pton(AF_INET6, cfg->host, &v6.sin6_addr) == 1) {
        v6.sin6_family = AF_INET6;
        v6.sin6_port = htons((uint16_t)cfg->port);
        addr = (struct sockaddr *)&v6;
        flags |= MHD_USE_IPv6;
    } else {
        gp_log("http: --host must be an IPv4 or IPv6 address, got '%s'", cfg->host);
        return GP_EINVAL;
    }
    struct MHD_Daemon *d = MHD_start_daemon(
        flags, (uint16_t)cfg->port, NULL, NULL, on_request, svc, MHD_OPTION_SOCK_ADDR, addr,
        MHD_OPTION_THREAD_POOL_SIZE, (unsigned)cfg->http_threads, MHD_OPTION_NOTIFY_COMPLETED,
        on_completed, svc, MHD_OPTION_CONNECTION_LIMIT, (unsigned)CONNECTION_LIMIT,
        MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)(cfg->max_wait + IDLE_TIMEOUT_MARGIN),
        MHD_OPTION_LISTEN_BACKLOG_SIZE, (unsigned)1024, MHD_OPTION_END);
    if (!d) {
        gp_log("http: cannot listen on %s port %d (in use, or not an address of this machine)",
               cfg->host, cfg->port);
        return GP_EIO;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(d, MHD_DAEMON_INFO_BIND_PORT);
    *port = info ? info->port : (unsigned)cfg->port;
    *out = d;
    return 0;
}

void gp_http_quiesce(struct MHD_Daemon *daemon)
{
    MHD_socket s = MHD_quiesce_daemon(daemon);
    if (s != MHD_INVALID_SOCKET)
        close(s);
}

void gp_http_stop(struct MHD_Daemon *daemon)
{
    MHD_stop_daemon(daemon);
}
