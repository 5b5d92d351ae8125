/* router.c - the route table and the admission checks made before a body is read. */
#include "router.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "problem.h"
#include "processes.h"
#include "routes.h"

#define BEARER_REALM "Bearer realm=\"grainpack\""

static const gp_route_entry routes[] = {
    {"/", GP_ACCESS_PUBLIC, gp_route_landing, NULL, NULL},
    {"/conformance", GP_ACCESS_PUBLIC, gp_route_conformance, NULL, NULL},
    {"/processes", GP_ACCESS_PUBLIC, gp_route_processes, NULL, NULL},
    {"/processes/{}", GP_ACCESS_PUBLIC, gp_route_process, NULL, NULL},
    {"/processes/{}/execution", GP_ACCESS_KEY, NULL, gp_route_execute, NULL},
    {"/processes/{}/validation", GP_ACCESS_KEY, NULL, gp_route_validate, NULL},
    {"/jobs", GP_ACCESS_KEY, gp_route_jobs, NULL, NULL},
    {"/jobs/{}", GP_ACCESS_KEY, gp_route_job, NULL, gp_route_dismiss},
    {"/jobs/{}/results", GP_ACCESS_KEY, gp_route_results, NULL, NULL},
    {"/jobs/{}/statistics", GP_ACCESS_KEY, gp_route_statistics, NULL, NULL},
    {"/health", GP_ACCESS_PUBLIC, gp_route_health, NULL, NULL},
    {"/metrics", GP_ACCESS_ADMIN, gp_route_metrics, NULL, NULL},
    {"/openapi.yaml", GP_ACCESS_PUBLIC, gp_route_openapi, NULL, NULL},
    {"/ui/{}", GP_ACCESS_PUBLIC, gp_route_web_file, NULL, NULL},
};
#define NROUTES (sizeof routes / sizeof routes[0])

static int id_char(char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
           c == '-' || c == '_' || c == '.';
}

const gp_route_entry *gp_router_match(const char *url, char id[GP_ID_MAX + 1])
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
                    if (!id_char(c) || k == GP_ID_MAX)
                        ok = 0;
                    else
                        id[k++] = c;
                }
                id[k] = '\0';
                /* "." and ".." are never ids: a path that looks like a traversal is
                 * not found rather than passed on */
                ok = ok && k > 0 && strcmp(id, ".") != 0 && strcmp(id, "..") != 0;
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
    id[0] = '\0';
    return NULL;
}

void gp_router_allow(const gp_route_entry *rt, char *out, size_t size)
{
    snprintf(out, size, "%s%s%sOPTIONS", rt->get ? "GET, HEAD, " : "", rt->post ? "POST, " : "",
             rt->del ? "DELETE, " : "");
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

/* The key check of a route that needs one. Returns 1 with a 401 or 403 in reply. */
static int authenticate(gp_request *req, const gp_route_entry *rt, gp_identity *who,
                        gp_reply *reply)
{
    gp_service *svc = req->svc;
    req->who = NULL;
    req->owner = NULL; /* no keys: everyone sees every job */
    if (!svc->keys || rt->access == GP_ACCESS_PUBLIC)
        return 0;
    gp_auth_result r = gp_keyring_authenticate(svc->keys, gp_request_header(req, "Authorization"),
                                               who);
    if (r != GP_AUTH_OK) {
        snprintf(reply->www_authenticate, sizeof reply->www_authenticate, "%s%s", BEARER_REALM,
                 r == GP_AUTH_MISSING ? ""
                 : r == GP_AUTH_MALFORMED ? ", error=\"invalid_request\""
                                          : ", error=\"invalid_token\"");
        if (r == GP_AUTH_MISSING)
            gp_problem(reply, 401, GP_PROBLEM_UNAUTHORIZED, req->path,
                       "%s needs an API key: send the header 'Authorization: Bearer KEY' "
                       "(the service's administrator issues keys)", req->path);
        else if (r == GP_AUTH_MALFORMED)
            gp_problem(reply, 401, GP_PROBLEM_UNAUTHORIZED, req->path,
                       "the Authorization header must be 'Bearer KEY', the key made of letters, "
                       "digits and -._~+/ (at most %d characters)", GP_KEY_MAX);
        else
            gp_problem(reply, 401, GP_PROBLEM_UNAUTHORIZED, req->path,
                       "the API key is not valid: unknown, or revoked by the administrator");
        return 1;
    }
    req->who = who; /* known from here on, for the log line even of a 403 */
    if (rt->access == GP_ACCESS_ADMIN && who->role != GP_ROLE_ADMIN) {
        gp_problem(reply, 403, GP_PROBLEM_FORBIDDEN, req->path,
                   "%s needs a key with the role admin; the key of '%s' has the role %s",
                   req->path, who->user, gp_role_name(who->role));
        return 1;
    }
    req->owner = who->role == GP_ROLE_ADMIN ? NULL : who->user;
    return 0;
}

int gp_router_admit(gp_request *req, const gp_route_entry *rt, size_t uri_bytes,
                    size_t header_bytes, gp_identity *who, gp_reply *reply)
{
    gp_service *svc = req->svc;
    const char *url = req->path, *method = req->method;
    size_t cap = svc->cfg->max_header_bytes;
    if (uri_bytes > cap) {
        gp_problem(reply, 414, GP_PROBLEM_URI_TOO_LONG, NULL,
                   "the path and query have %zu bytes, more than the limit of %zu "
                   "(--max-header-bytes)", uri_bytes, cap);
        reply->close = 1;
        return 1;
    }
    if (uri_bytes + header_bytes > cap) {
        gp_problem(reply, 431, GP_PROBLEM_HEADERS_TOO_LARGE, url,
                   "the request line and headers have %zu bytes, more than the limit of %zu "
                   "(--max-header-bytes)", uri_bytes + header_bytes, cap);
        reply->close = 1;
        return 1;
    }
    if (!rt) {
        gp_problem(reply, 404, GP_PROBLEM_NOT_FOUND, url,
                   "no resource at %s; GET / lists the API's links and GET /openapi.yaml "
                   "describes it", url);
        return 1;
    }
    int is_get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    int is_post = strcmp(method, "POST") == 0, is_del = strcmp(method, "DELETE") == 0;
    if (strcmp(method, "OPTIONS") == 0) { /* a CORS preflight carries no key */
        reply->status = 204;
        gp_router_allow(rt, reply->allow, sizeof reply->allow);
        return 1;
    }
    if (!((is_get && rt->get) || (is_post && rt->post) || (is_del && rt->del))) {
        gp_router_allow(rt, reply->allow, sizeof reply->allow);
        gp_problem(reply, 405, GP_PROBLEM_METHOD_NOT_ALLOWED, url,
                   "%.32s is not allowed on %s; allowed: %s", method, url, reply->allow);
        return 1;
    }
    if (authenticate(req, rt, who, reply))
        return 1;
    if (!is_post)
        return 0;
    if (!gp_process_find(req->id)) { /* before the body: it would not be used */
        gp_problem_no_such_process(reply, url, req->id);
        return 1;
    }
    const char *type = gp_request_header(req, "Content-Type");
    if (!is_json_type(type)) {
        gp_problem(reply, 415, GP_PROBLEM_UNSUPPORTED_MEDIA_TYPE, url,
                   "the body must be sent as application/json (got %s%.60s%s); with curl: "
                   "-H 'Content-Type: application/json'",
                   type ? "'" : "no Content-Type", type ? type : "", type ? "'" : "");
        return 1;
    }
    const char *length = gp_request_header(req, "Content-Length");
    if (length && strtoull(length, NULL, 10) > svc->cfg->max_body) {
        gp_problem(reply, 413, GP_PROBLEM_BODY_TOO_LARGE, url,
                   "the body has %.20s bytes, more than the limit of %zu (--max-body)", length,
                   svc->cfg->max_body);
        return 1;
    }
    return 0;
}

int gp_router_call(const gp_route_entry *rt, gp_request *req, gp_reply *reply)
{
    const char *method = req->method;
    int is_get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    gp_route_fn fn = is_get ? rt->get : strcmp(method, "POST") == 0 ? rt->post : rt->del;
    return fn(req, reply);
}
