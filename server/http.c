/* http.c - the adapter between libmicrohttpd and the router: connections per address,
 * gathering the request into a gp_request (request.h), admission and the route call
 * (router.c), the gp_reply turned into a response with CORS, and the per-request log
 * line. */
#include "http.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "framing.h"
#include "log.h"
#include "peers.h"
#include "problem.h"
#include "router.h"

/* A body without Content-Length that passes the cap is read on (and dropped) up to this
 * many times the cap, so that the client still gets its 413; beyond, it is cut off. */
#define DISCARD_FACTOR 16
/* How long a browser may cache a CORS preflight answer. */
#define CORS_MAX_AGE "600"
/* libmicrohttpd answers by itself (431, in HTML) a request whose headers do not fit in a
 * connection's memory pool; the pool is made this many times --max-header-bytes, so that
 * headers a little over the limit still reach us and get our 431 problem instead. */
#define HEADER_POOL_FACTOR 4
#define MIN_POOL_BYTES ((size_t)32 * 1024)
/* libmicrohttpd's own per-address limit is set this far above --max-connections-per-ip:
 * connections in between are answered 429 by us, those beyond are dropped at accept. */
#define PER_IP_HARD_MARGIN 16
/* The body of a request must arrive within this many times --connection-timeout in all:
 * a client trickling a byte at a time is cut off even though it is never silent. */
#define BODY_DEADLINE_FACTOR 2
/* The listen queue: enough for a burst of a few hundred clients connecting at once. */
#define LISTEN_BACKLOG 1024
/* The buffer of a streamed response (a result download), filled by its producer each
 * time the socket has taken the last one: large enough that a callback's fixed cost
 * (a store connection, a window of the result) is spread over many bytes, small enough
 * that 20 downloads at once hold a few megabytes. */
#define STREAM_BLOCK ((size_t)128 * 1024)

/* Per-request state, from the first call of a request to its completion. */
typedef struct request_state {
    const gp_route_entry *route;
    char id[GP_ID_MAX + 1];
    gp_identity who; /* the key's identity, once checked */
    const gp_identity *who_ptr;
    const char *owner;
    char *body;
    size_t len, cap;
    int dropping;    /* the body is read and dropped: it passed the cap (413 answers) or
                        memory ran out (the out-of-memory 503 answers) */
    int no_memory;   /* why it is dropped: memory ran out (gather) */
    size_t discarded;
    int answered;    /* a response was queued */
    int suspended;   /* a long-poll is waiting */
    char method[16], path[200]; /* for the log line, sanitized */
    unsigned status;
    size_t bytes;
    double t0;
    int begun;               /* the first call came: the head is in */
    size_t query_parameters; /* more than GP_MAX_QUERY_PARAMETERS: the query was cut */
} request_state;

static const char *mhd_header(void *conn, const char *name)
{
    return MHD_lookup_connection_value(conn, MHD_HEADER_KIND, name);
}

static const char *mhd_query(void *conn, const char *name)
{
    return MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, name);
}

static const gp_request_ops mhd_request_ops = {mhd_header, mhd_query};

static void mhd_suspend(void *conn)
{
    MHD_suspend_connection(conn);
}

static void mhd_resume(void *conn)
{
    MHD_resume_connection(conn);
}

static int mhd_socket(void *conn)
{
    const union MHD_ConnectionInfo *info = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    return info ? info->connect_fd : -1;
}

const gp_suspender gp_http_suspender = {mhd_suspend, mhd_resume, mhd_socket};

/* The gp_request of a libmicrohttpd request as far as st has it (no body: the caller
 * adds it once it is in). */
static gp_request make_request(gp_service *svc, struct MHD_Connection *conn, const char *method,
                               const char *url, const request_state *st)
{
    return (gp_request){.svc = svc,
                        .ops = &mhd_request_ops,
                        .conn = conn,
                        .method = method,
                        .path = url,
                        .id = st->id,
                        .resumed = st->suspended,
                        .who = st->who_ptr,
                        .owner = st->owner};
}

/* Adds the CORS headers when the request comes from an allowed origin. */
static void add_cors(gp_service *svc, struct MHD_Connection *conn, struct MHD_Response *resp,
                     const gp_route_entry *rt, int preflight)
{
    const char *origin = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Origin");
    if (!gp_config_origin_allowed(svc->cfg, origin))
        return;
    int any = strcmp(svc->cfg->cors_origins, "*") == 0;
    MHD_add_response_header(resp, "Access-Control-Allow-Origin", any ? "*" : origin);
    if (!any)
        MHD_add_response_header(resp, "Vary", "Origin");
    MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                            "Location, Retry-After, Content-Type, WWW-Authenticate, ETag, "
                            "Content-Disposition");
    if (preflight && rt) {
        char allow[64];
        gp_router_allow(rt, allow, sizeof allow);
        MHD_add_response_header(resp, "Access-Control-Allow-Methods", allow);
        MHD_add_response_header(resp, "Access-Control-Allow-Headers",
                                "Content-Type, Accept, Authorization");
        MHD_add_response_header(resp, "Access-Control-Max-Age", CORS_MAX_AGE);
    }
}

/* libmicrohttpd's reader of a streamed body: gp_body_stream's fill, in its terms. */
static ssize_t stream_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    gp_body_stream *s = cls;
    long n = s->fill(s, buf, max);
    return n > 0 ? (ssize_t)n : n == 0 ? MHD_CONTENT_READER_END_OF_STREAM
                                       : MHD_CONTENT_READER_END_WITH_ERROR;
}

static void stream_release(void *cls)
{
    gp_body_stream *s = cls;
    s->release(s);
}

/* A response taking reply's body or stream (the response's once this returns non-NULL);
 * NULL when out of memory. */
static struct MHD_Response *create_response(gp_reply *reply)
{
    struct MHD_Response *resp;
    if (reply->stream) {
        resp = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, STREAM_BLOCK, stream_read,
                                                 reply->stream, stream_release);
        if (resp)
            reply->stream = NULL;
        return resp;
    }
    int owned = reply->body && !reply->persistent;
    resp = MHD_create_response_from_buffer(reply->len, reply->body ? reply->body : (void *)"",
                                           owned ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
    if (resp && owned)
        reply->body = NULL;
    return resp;
}

/* Queues reply as the response (taking its body), logs and counts the request. */
static enum MHD_Result respond(gp_service *svc, struct MHD_Connection *conn, request_state *st,
                               gp_reply *reply, int preflight)
{
    struct MHD_Response *resp = create_response(reply);
    if (!resp) { /* out of memory: the static problem needs no copy of its body */
        gp_problem_out_of_memory(reply);
        resp = create_response(reply);
    }
    if (!resp) {
        gp_reply_free(reply);
        return MHD_NO;
    }
    if (reply->content_type)
        MHD_add_response_header(resp, "Content-Type", reply->content_type);
    if (reply->location[0])
        MHD_add_response_header(resp, "Location", reply->location);
    if (reply->allow[0])
        MHD_add_response_header(resp, "Allow", reply->allow);
    if (reply->www_authenticate[0])
        MHD_add_response_header(resp, "WWW-Authenticate", reply->www_authenticate);
    if (reply->retry_after > 0) {
        char seconds[16];
        snprintf(seconds, sizeof seconds, "%d", reply->retry_after);
        MHD_add_response_header(resp, "Retry-After", seconds);
    }
    for (int i = 0; i < reply->nheaders; i++)
        MHD_add_response_header(resp, reply->headers[i].name, reply->headers[i].value);
    if (reply->close)
        MHD_add_response_header(resp, "Connection", "close");
    if (reply->vary)
        MHD_add_response_header(resp, "Vary", reply->vary);
    if (reply->cache_control)
        MHD_add_response_header(resp, "Cache-Control", reply->cache_control);
    if (reply->etag)
        MHD_add_response_header(resp, "ETag", reply->etag);
    if (reply->csp) { /* the web page's files: no sniffing, no framing, no referrer */
        MHD_add_response_header(resp, "Content-Security-Policy", reply->csp);
        MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
        MHD_add_response_header(resp, "Referrer-Policy", "no-referrer");
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

/* Appends upload data under the cap. Returns 0, or 1 when the cap was passed or memory
 * ran out (then st->no_memory is set). */
static int gather(gp_service *svc, request_state *st, const char *data, size_t size)
{
    if (st->len + size > svc->cfg->max_body)
        return 1;
    if (st->len + size > st->cap) {
        size_t cap = st->cap ? st->cap : 4096;
        while (cap < st->len + size)
            cap *= 2;
        char *grown = realloc(st->body, cap);
        if (!grown) {
            st->no_memory = 1;
            return 1;
        }
        st->body = grown;
        st->cap = cap;
    }
    memcpy(st->body + st->len, data, size);
    st->len += size;
    return 0;
}

/* Adds the size of one header or query argument to *cls (a size_t). */
static enum MHD_Result add_size(void *cls, enum MHD_ValueKind kind, const char *key,
                                const char *value)
{
    (void)kind;
    *(size_t *)cls += strlen(key) + (value ? strlen(value) : 0) + 4; /* ": " or "=&", CRLF */
    return MHD_YES;
}

/* Records a header for the framing checks (cls: a gp_framing). */
static enum MHD_Result add_framing(void *cls, enum MHD_ValueKind kind, const char *key,
                                   const char *value)
{
    (void)kind;
    gp_framing_add(cls, key, value);
    return MHD_YES;
}

/* The connection's record in the peer table, or NULL. */
static gp_peer_conn *peer_of(struct MHD_Connection *conn)
{
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    return info ? info->socket_context : NULL;
}

/* The first call of a request: the checks before its body. Returns the MHD result. */
static enum MHD_Result begin_request(gp_service *svc, struct MHD_Connection *conn,
                                     const char *url, const char *method, const char *version,
                                     request_state *st)
{
    gp_reply reply;
    memset(&reply, 0, sizeof reply);
    gp_peer_conn *peer = peer_of(conn);
    gp_peers_head_done(svc->peers, peer);
    /* how the body is framed, before anything else: a request that a proxy in front could
     * read another way is refused and its connection closed, whatever its route */
    gp_framing framing;
    gp_framing_init(&framing);
    MHD_get_connection_values(conn, MHD_HEADER_KIND, add_framing, &framing);
    if (gp_framing_check(&framing, version, url, &reply))
        return respond(svc, conn, st, &reply, 0);
    if (st->query_parameters) {
        gp_problem(&reply, 400, GP_PROBLEM_BAD_PARAMETER, url,
                   "the query has %zu parameters; a request takes at most %d", st->query_parameters,
                   GP_MAX_QUERY_PARAMETERS);
        return respond(svc, conn, st, &reply, 0);
    }
    if (peer && peer->over_limit) {
        gp_problem(&reply, 429, GP_PROBLEM_TOO_MANY_CONNECTIONS, url,
                   "%u connections are open from your address, the limit is %d "
                   "(--max-connections-per-ip); this one is closed: reuse a connection "
                   "(keep-alive) or wait for others to finish",
                   peer->open, svc->cfg->max_connections_per_ip);
        reply.retry_after = GP_RETRY_AFTER_SECONDS;
        reply.close = 1;
        return respond(svc, conn, st, &reply, 0);
    }
    size_t uri_bytes = strlen(url), header_bytes = strlen(method) + 12; /* " HTTP/1.1\r\n" */
    MHD_get_connection_values(conn, MHD_GET_ARGUMENT_KIND, add_size, &uri_bytes);
    MHD_get_connection_values(conn, MHD_HEADER_KIND, add_size, &header_bytes);
    st->route = gp_router_match(url, st->id);
    gp_request req = make_request(svc, conn, method, url, st);
    int answered = gp_router_admit(&req, st->route, uri_bytes, header_bytes, &st->who, &reply);
    st->who_ptr = req.who ? &st->who : NULL;
    if (answered)
        return respond(svc, conn, st, &reply, strcmp(method, "OPTIONS") == 0);
    st->owner = req.owner ? st->who.user : NULL;
    return MHD_YES; /* the body (if any) comes in the next calls */
}

/* A request line arrived (before its query is parsed): the request's state begins. A
 * query of more parameters than any route takes is cut here, before libmicrohttpd parses
 * it into its connection's memory (see GP_MAX_QUERY_PARAMETERS); the request is refused
 * at its first call. `uri` is libmicrohttpd's own buffer, the query then parsed from it:
 * a NUL right after the '?' leaves an empty query. */
static void *on_uri(void *cls, const char *uri, struct MHD_Connection *conn)
{
    gp_service *svc = cls;
    gp_peers_line_in(svc->peers, peer_of(conn));
    request_state *st = calloc(1, sizeof *st);
    if (!st)
        return NULL; /* on_request tries again */
    st->t0 = gp_monotonic_seconds();
    size_t n = gp_query_parameters(uri);
    if (n > GP_MAX_QUERY_PARAMETERS) {
        st->query_parameters = n;
        strchr(uri, '?')[1] = '\0';
    }
    return st;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version,
                                  const char *upload_data, size_t *upload_size, void **con_cls)
{
    gp_service *svc = cls;
    request_state *st = *con_cls;
    gp_reply reply;
    memset(&reply, 0, sizeof reply);
    if (!st) {
        if (!(st = calloc(1, sizeof *st)))
            return MHD_NO;
        *con_cls = st;
        st->t0 = gp_monotonic_seconds();
    }
    if (!st->begun) {
        st->begun = 1;
        gp_text_sanitize(st->method, sizeof st->method, method);
        gp_text_sanitize(st->path, sizeof st->path, url);
        return begin_request(svc, conn, url, method, version, st);
    }
    if (st->answered)
        return MHD_YES;
    if (*upload_size) {
        /* past the cap the rest is read and dropped, and 413 answered once it is all in:
         * libmicrohttpd cannot answer in the middle of an upload. A client that keeps
         * sending far past the cap, or too slowly, is cut off. */
        size_t size = *upload_size;
        *upload_size = 0;
        if (!st->dropping && gather(svc, st, upload_data, size))
            st->dropping = 1;
        if (st->dropping && (st->discarded += size) > DISCARD_FACTOR * svc->cfg->max_body)
            return MHD_NO;
        if (gp_monotonic_seconds() - st->t0 >
            (double)(BODY_DEADLINE_FACTOR * svc->cfg->connection_timeout)) {
            gp_log("http: %s %s: the body did not arrive within %d s: connection closed",
                   st->method, st->path, BODY_DEADLINE_FACTOR * svc->cfg->connection_timeout);
            return MHD_NO;
        }
        return MHD_YES;
    }
    if (st->no_memory) {
        gp_problem_out_of_memory(&reply);
        return respond(svc, conn, st, &reply, 0);
    }
    if (st->dropping) {
        gp_problem(&reply, 413, GP_PROBLEM_BODY_TOO_LARGE, url,
                   "the body is larger than the limit of %zu bytes (--max-body)",
                   svc->cfg->max_body);
        return respond(svc, conn, st, &reply, 0);
    }
    gp_request req = make_request(svc, conn, method, url, st);
    req.body = st->body ? st->body : "";
    req.body_len = st->len;
    st->suspended = 0;
    if (gp_router_call(st->route, &req, &reply) == GP_ROUTE_SUSPENDED) {
        st->suspended = 1;
        return MHD_YES;
    }
    return respond(svc, conn, st, &reply, 0);
}

/* The client's address as text ("?" when unknown). */
static void client_address(struct MHD_Connection *conn, char *addr, size_t size)
{
    const union MHD_ConnectionInfo *info =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    snprintf(addr, size, "?");
    if (info && info->client_addr) {
        const struct sockaddr *sa = info->client_addr;
        if (sa->sa_family == AF_INET)
            inet_ntop(AF_INET, &((const struct sockaddr_in *)(const void *)sa)->sin_addr, addr,
                      (socklen_t)size);
        else if (sa->sa_family == AF_INET6)
            inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)(const void *)sa)->sin6_addr, addr,
                      (socklen_t)size);
    }
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    gp_service *svc = cls;
    request_state *st = *con_cls;
    if (toe == MHD_REQUEST_TERMINATED_COMPLETED_OK) /* the next request's head begins */
        gp_peers_head_begins(svc->peers, peer_of(conn));
    if (!st)
        return;
    if (st->answered) {
        char addr[INET6_ADDRSTRLEN];
        client_address(conn, addr, sizeof addr);
        gp_log("http %s %s %s %s %u %zu bytes %.1f ms%s", addr, st->who_ptr ? st->who.user : "-",
               st->method, st->path, st->status, st->bytes, 1e3 * (gp_monotonic_seconds() - st->t0),
               toe == MHD_REQUEST_TERMINATED_COMPLETED_OK ? "" : " (connection closed early)");
    }
    free(st->body);
    free(st);
    *con_cls = NULL;
}

/* Counts connections per address (the limit is applied to the first request). */
static void on_connection(void *cls, struct MHD_Connection *conn, void **socket_context,
                          enum MHD_ConnectionNotificationCode code)
{
    gp_service *svc = cls;
    if (code == MHD_CONNECTION_NOTIFY_STARTED) {
        const union MHD_ConnectionInfo *info =
            MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
        const union MHD_ConnectionInfo *fd =
            MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
        *socket_context = gp_peers_opened(svc->peers, info ? info->client_addr : NULL,
                                          (unsigned)svc->cfg->max_connections_per_ip,
                                          fd ? fd->connect_fd : -1);
    } else if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
        gp_peers_closed(svc->peers, *socket_context);
        *socket_context = NULL;
    }
}

static int hex_digit(char c)
{
    return c >= '0' && c <= '9' ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
}

/* Decodes %HH escapes in the path and query values, except %00: a NUL would cut the
 * text short and make "/jobs/%00x" the path "/jobs/". Left as it is, it matches no route
 * and no parameter value. */
static size_t unescape(void *cls, struct MHD_Connection *conn, char *s)
{
    (void)cls;
    (void)conn;
    char *w = s;
    for (const char *r = s; *r;) {
        int hi = r[0] == '%' ? hex_digit(r[1]) : -1, lo = hi >= 0 ? hex_digit(r[2]) : -1;
        if (lo >= 0 && (hi | lo) != 0) {
            *w++ = (char)(hi * 16 + lo);
            r += 3;
        } else {
            *w++ = *r++;
        }
    }
    *w = '\0';
    return (size_t)(w - s);
}

/* Starts a daemon with the options both modes share. */
static struct MHD_Daemon *start(gp_service *svc, unsigned flags, uint16_t port,
                                const struct sockaddr *addr, unsigned threads)
{
    const gp_config *cfg = svc->cfg;
    size_t pool = HEADER_POOL_FACTOR * cfg->max_header_bytes;
    if (pool < MIN_POOL_BYTES)
        pool = MIN_POOL_BYTES;
    struct MHD_OptionItem options[] = {
        {MHD_OPTION_NOTIFY_COMPLETED, (intptr_t)on_completed, svc},
        {MHD_OPTION_NOTIFY_CONNECTION, (intptr_t)on_connection, svc},
        {MHD_OPTION_URI_LOG_CALLBACK, (intptr_t)on_uri, svc},
        {MHD_OPTION_UNESCAPE_CALLBACK, (intptr_t)unescape, NULL},
        {MHD_OPTION_CONNECTION_LIMIT, cfg->max_connections, NULL},
        {MHD_OPTION_PER_IP_CONNECTION_LIMIT, cfg->max_connections_per_ip + PER_IP_HARD_MARGIN, NULL},
        {MHD_OPTION_CONNECTION_TIMEOUT, cfg->connection_timeout, NULL},
        {MHD_OPTION_CONNECTION_MEMORY_LIMIT, (intptr_t)pool, NULL},
        {threads > 1 ? MHD_OPTION_THREAD_POOL_SIZE : MHD_OPTION_END, threads, NULL},
        {MHD_OPTION_END, 0, NULL},
    };
    if (addr)
        return MHD_start_daemon(flags, port, NULL, NULL, on_request, svc, MHD_OPTION_SOCK_ADDR,
                                addr, MHD_OPTION_LISTEN_BACKLOG_SIZE, (unsigned)LISTEN_BACKLOG,
                                MHD_OPTION_ARRAY, options, MHD_OPTION_END);
    return MHD_start_daemon(flags, 0, NULL, NULL, on_request, svc, MHD_OPTION_ARRAY, options,
                            MHD_OPTION_END);
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
    struct MHD_Daemon *d = start(svc, flags, (uint16_t)cfg->port, addr, (unsigned)cfg->http_threads);
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

int gp_http_start_embedded(gp_service *svc, struct MHD_Daemon **out)
{
    *out = start(svc, MHD_USE_NO_LISTEN_SOCKET | MHD_ALLOW_SUSPEND_RESUME, 0, NULL, 1);
    return *out ? 0 : GP_EIO;
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
