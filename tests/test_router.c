/* test_router.c - grainpackd's router and routes without HTTP: requests built by hand
 * (gp_request with a header and query table of the test's own) go through the same
 * admission and route call as http.c makes, against a real sqlite store in a temporary
 * directory. The program links no libmicrohttpd (checked below at run time). Out of
 * memory is injected through jansson's allocator: every answer is then either the
 * normal one or the static out-of-memory problem, never a body that is not
 * problem+json. */
#define _GNU_SOURCE
#include <dirent.h>
#include <jansson.h>
#include <link.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "check.h"
#include "log.h"
#include "problem.h"
#include "router.h"
#include "routes.h"
#include "service.h"
#include "store.h"

/* The HTTP side of a hand-built request: name/value pairs, NULL-terminated. */
typedef struct fake_conn {
    const char *const *headers;
    const char *const *query;
} fake_conn;

static const char *lookup(const char *const *pairs, const char *name, int ignore_case)
{
    for (size_t i = 0; pairs && pairs[i]; i += 2)
        if ((ignore_case ? strcasecmp(pairs[i], name) : strcmp(pairs[i], name)) == 0)
            return pairs[i + 1];
    return NULL;
}

static const char *fake_header(void *conn, const char *name)
{
    return lookup(((const fake_conn *)conn)->headers, name, 1);
}

static const char *fake_query(void *conn, const char *name)
{
    return lookup(((const fake_conn *)conn)->query, name, 0);
}

static const gp_request_ops fake_ops = {fake_header, fake_query};

static char dir[] = "/tmp/grainpack-router-XXXXXX";
static char db_path[300];
static gp_config cfg;
static gp_service svc;

/* What http.c does with a request: match, admit, then (with its body) call the route. */
static gp_reply call(const char *method, const char *path, const fake_conn *conn, const char *body)
{
    char id[GP_ID_MAX + 1];
    const gp_route_entry *rt = gp_router_match(path, id);
    gp_request req = {.svc = &svc, .ops = &fake_ops, .conn = (void *)conn, .method = method,
                      .path = path, .id = id};
    gp_identity who;
    gp_reply reply;
    memset(&reply, 0, sizeof reply);
    if (!gp_router_admit(&req, rt, strlen(path), 64, &who, &reply)) {
        req.body = body ? body : "";
        req.body_len = body ? strlen(body) : 0;
        CHECK(gp_router_call(rt, &req, &reply) == GP_ROUTE_DONE);
    }
    return reply;
}

static json_t *body_json(const gp_reply *reply)
{
    json_error_t err;
    return reply->body ? json_loadb(reply->body, reply->len, 0, &err) : NULL;
}

/* The string member `name` of obj, "" when absent. */
static const char *text_of(const json_t *obj, const char *name)
{
    const char *text = json_string_value(json_object_get(obj, name));
    return text ? text : "";
}

/* Checks that reply is a problem+json with this status and type. */
static void check_problem(const gp_reply *reply, unsigned status, const char *type)
{
    CHECK_MSG(reply->status == status, "status %u, expected %u", reply->status, status);
    CHECK(reply->content_type && strcmp(reply->content_type, GP_PROBLEM_MEDIA_TYPE) == 0);
    json_t *p = body_json(reply);
    CHECK_MSG(p != NULL, "not JSON: %.*s", (int)reply->len, reply->body ? reply->body : "");
    CHECK_STR(text_of(p, "type"), type);
    CHECK(json_integer_value(json_object_get(p, "status")) == (json_int_t)status);
    CHECK(json_is_string(json_object_get(p, "title")));
    json_decref(p);
}

/* The jobs in the store, by status. */
static long count_jobs(gp_job_status status)
{
    long counts[GP_JOB_NSTATUS];
    gp_db *db = gp_store_acquire(svc.store, 1);
    CHECK(db && gp_store_count(db, counts) == 0);
    gp_store_release(svc.store, db);
    return counts[status];
}

static const char *const json_post[] = {"Content-Type", "application/json", NULL};
static const fake_conn no_headers = {NULL, NULL};
static const fake_conn json_headers = {json_post, NULL};
static const char valid_spec[] = "{\"inputs\": {\"domain\": {\"width\": 10, \"height\": 10},"
                                 " \"distribution\": {\"kind\": \"constant\", \"radius\": 0.9}}}";

static void test_get_conformance_answers_200_with_the_core_class(void)
{
    gp_reply reply = call("GET", "/conformance", &no_headers, NULL);
    CHECK(reply.status == 200);
    CHECK(reply.content_type && strcmp(reply.content_type, "application/json") == 0);
    json_t *body = body_json(&reply);
    json_t *classes = json_object_get(body, "conformsTo");
    int core = 0;
    for (size_t i = 0; i < json_array_size(classes); i++) {
        const char *c = json_string_value(json_array_get(classes, i));
        core |= c && strstr(c, "/conf/core") != NULL;
    }
    CHECK(core);
    json_decref(body);
    gp_reply_free(&reply);
}

static void test_an_unknown_route_is_a_404_problem(void)
{
    gp_reply reply = call("GET", "/no/such/thing", &no_headers, NULL);
    check_problem(&reply, 404, GP_PROBLEM_NOT_FOUND);
    gp_reply_free(&reply);
    reply = call("GET", "/jobs/..", &no_headers, NULL); /* not an id: no route */
    check_problem(&reply, 404, GP_PROBLEM_NOT_FOUND);
    gp_reply_free(&reply);
}

static void test_a_method_the_route_lacks_is_a_405_with_allow(void)
{
    gp_reply reply = call("DELETE", "/conformance", &no_headers, NULL);
    check_problem(&reply, 405, GP_PROBLEM_METHOD_NOT_ALLOWED);
    CHECK_STR(reply.allow, "GET, HEAD, OPTIONS");
    gp_reply_free(&reply);
}

static void test_a_post_that_is_not_json_is_refused_before_its_body(void)
{
    static const char *const text[] = {"content-type", "text/plain", NULL};
    const fake_conn conn = {text, NULL};
    gp_reply reply = call("POST", "/processes/pack2d/execution", &conn, valid_spec);
    check_problem(&reply, 415, GP_PROBLEM_UNSUPPORTED_MEDIA_TYPE);
    gp_reply_free(&reply);
    CHECK(count_jobs(GP_JOB_ACCEPTED) == 0);
}

static void test_a_post_with_a_bad_body_is_a_400_and_stores_nothing(void)
{
    gp_reply reply = call("POST", "/processes/pack2d/execution", &json_headers, "{\"inputs\": ");
    check_problem(&reply, 400, GP_PROBLEM_MALFORMED_JSON);
    gp_reply_free(&reply);
    CHECK(count_jobs(GP_JOB_ACCEPTED) == 0);
}

static void test_an_invalid_spec_is_a_422_with_the_pointer(void)
{
    const char *spec = "{\"inputs\": {\"domain\": {\"width\": -1, \"height\": 10},"
                       " \"distribution\": {\"kind\": \"constant\", \"radius\": 0.9}}}";
    gp_reply reply = call("POST", "/processes/pack2d/execution", &json_headers, spec);
    check_problem(&reply, 422, GP_PROBLEM_INVALID_SPEC);
    json_t *p = body_json(&reply);
    CHECK_STR(text_of(p, "pointer"), "/inputs/domain/width");
    json_decref(p);
    gp_reply_free(&reply);
    CHECK(count_jobs(GP_JOB_ACCEPTED) == 0);
}

/* A submitted job is in the sqlite file, and GET /jobs/{id} (id from Location) finds it. */
static void test_a_valid_post_stores_the_job_and_get_finds_it(void)
{
    gp_reply reply = call("POST", "/processes/pack2d/execution", &json_headers, valid_spec);
    CHECK(reply.status == 201);
    CHECK(strncmp(reply.location, "/jobs/", 6) == 0);
    char location[sizeof reply.location];
    snprintf(location, sizeof location, "%s", reply.location);
    gp_reply_free(&reply);
    CHECK(count_jobs(GP_JOB_ACCEPTED) == 1);

    reply = call("GET", location, &no_headers, NULL);
    CHECK(reply.status == 200);
    json_t *info = body_json(&reply);
    CHECK_STR(text_of(info, "status"), "accepted");
    CHECK_STR(text_of(info, "jobID"), location + 6);
    json_decref(info);
    gp_reply_free(&reply);

    static const char *const bad_wait[] = {"wait", "soon", NULL};
    const fake_conn conn = {NULL, bad_wait};
    reply = call("GET", location, &conn, NULL);
    check_problem(&reply, 400, GP_PROBLEM_BAD_PARAMETER);
    gp_reply_free(&reply);
}

/* jansson allocations fail from the n-th on (n < 0: never), as memory running out would. */
static long allocations_left = -1;
static long allocations_refused;

static void *failing_malloc(size_t size)
{
    if (allocations_left == 0) {
        allocations_refused++;
        return NULL;
    }
    if (allocations_left > 0)
        allocations_left--;
    return malloc(size);
}

/* Calls the route with the n-th jansson allocation failing, for every n until one call
 * meets no failure: each answer must be the normal one (expect_status) or the static
 * out-of-memory problem (503, Retry-After). Returns how many answers were that problem. */
static int answers_under_failing_memory(const char *method, const char *path,
                                        const fake_conn *conn, unsigned expect_status)
{
    int out_of_memory = 0;
    for (long n = 0;; n++) {
        allocations_left = n;
        allocations_refused = 0;
        gp_reply reply = call(method, path, conn, NULL);
        allocations_left = -1;
        if (reply.status == 503) {
            check_problem(&reply, 503, GP_PROBLEM_INTERNAL);
            CHECK(reply.retry_after > 0);
            out_of_memory++;
        } else {
            CHECK_MSG(reply.status == expect_status, "%s %s, failing from allocation %ld: %u",
                      method, path, n, reply.status);
            json_t *body = body_json(&reply);
            CHECK_MSG(body != NULL, "%s %s: the body is not JSON", method, path);
            json_decref(body);
        }
        gp_reply_free(&reply);
        if (allocations_refused == 0)
            return out_of_memory;
    }
}

static void test_out_of_memory_answers_are_still_problem_json(void)
{
    json_set_alloc_funcs(failing_malloc, free);
    CHECK(answers_under_failing_memory("GET", "/conformance", &no_headers, 200) > 0);
    CHECK(answers_under_failing_memory("GET", "/no/such/thing", &no_headers, 404) > 0);
    CHECK(answers_under_failing_memory("GET", "/jobs", &no_headers, 200) > 0);
    CHECK(answers_under_failing_memory("GET", "/processes/pack2d", &no_headers, 200) > 0);
    json_set_alloc_funcs(malloc, free);
}

/* The static out-of-memory answer is never freed, whatever happens to the reply next. */
static void test_the_out_of_memory_body_survives_being_replaced_and_freed(void)
{
    gp_reply reply;
    memset(&reply, 0, sizeof reply);
    gp_problem_out_of_memory(&reply);
    const char *first = reply.body;
    CHECK(reply.persistent);
    CHECK(gp_reply_text(&reply, 200, "text/plain", "ok", 2) == 0); /* replaces, frees nothing */
    CHECK(!reply.persistent && reply.len == 2);
    gp_reply_free(&reply);
    gp_problem_out_of_memory(&reply);
    CHECK(reply.body == first);
    check_problem(&reply, 503, GP_PROBLEM_INTERNAL);
    gp_reply_free(&reply);
}

/* No error detail shows a raw code: the service's codes have sentences. */
static void test_service_codes_have_names(void)
{
    int codes[] = {GP_SRV_ENOTFOUND, GP_SRV_ESTATE, GP_SRV_EDB, GP_SRV_EFULL,
                   GP_SRV_EUNWRITABLE, GP_SRV_ELIMIT, GP_ENOMEM, GP_EINVAL};
    for (size_t i = 0; i < sizeof codes / sizeof codes[0]; i++) {
        const char *text = gp_srv_strerror(codes[i]);
        CHECK_MSG(strcmp(text, "unknown error") != 0 && !strpbrk(text, "0123456789"),
                  "code %d: '%s'", codes[i], text);
    }
}

static int find_microhttpd(struct dl_phdr_info *info, size_t size, void *found)
{
    (void)size;
    if (info->dlpi_name && strstr(info->dlpi_name, "libmicrohttpd"))
        *(int *)found = 1;
    return 0;
}

static void test_no_libmicrohttpd_is_loaded(void)
{
    int found = 0;
    dl_iterate_phdr(find_microhttpd, &found);
    CHECK(!found);
}

/* Removes the temporary directory with whatever sqlite left in it (WAL, shm). */
static void remove_dir(void)
{
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        char p[320];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (e->d_name[0] != '.')
            unlink(p);
    }
    if (d)
        closedir(d);
    rmdir(dir);
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    snprintf(db_path, sizeof db_path, "%s/grainpack.db", dir);
    char *argv[] = {"test_router", "--db", db_path, NULL};
    char why[256];
    gp_log_silence(1);
    if (gp_config_load(&cfg, 3, argv, stdout, stderr) != 0 ||
        gp_store_open(db_path, &svc.store, why, sizeof why) != 0 ||
        !(svc.metrics = gp_metrics_new())) {
        fprintf(stderr, "test_router: cannot set up the service\n");
        return 1;
    }
    svc.cfg = &cfg;
    atomic_init(&svc.queued, 0);
    atomic_init(&svc.accepting, 1);

    RUN(test_no_libmicrohttpd_is_loaded);
    RUN(test_get_conformance_answers_200_with_the_core_class);
    RUN(test_an_unknown_route_is_a_404_problem);
    RUN(test_a_method_the_route_lacks_is_a_405_with_allow);
    RUN(test_a_post_that_is_not_json_is_refused_before_its_body);
    RUN(test_a_post_with_a_bad_body_is_a_400_and_stores_nothing);
    RUN(test_an_invalid_spec_is_a_422_with_the_pointer);
    RUN(test_a_valid_post_stores_the_job_and_get_finds_it);
    RUN(test_out_of_memory_answers_are_still_problem_json);
    RUN(test_the_out_of_memory_body_survives_being_replaced_and_freed);
    RUN(test_service_codes_have_names);

    gp_metrics_free(svc.metrics);
    gp_store_close(svc.store);
    remove_dir();
    return check_status();
}
