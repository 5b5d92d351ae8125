/* test_store_contract.c - the job store's contract, the same test code run against each
 * backend: `test_store_contract sqlite` (a real file in a temporary directory) or
 * `test_store_contract postgresql STATE` (the real server of tests/pg/pg_server.sh, a new
 * database per test). Jobs are claimed oldest first and once only, also by threads
 * claiming at once; a result is stored whole and read back byte for byte, piece by
 * piece; a job dismissed while it runs keeps no result; jobs are seen by their owner only;
 * the per-owner limit counts accepted and running jobs. On a store shared by nodes (two
 * stores on one database): a dismissal on one node is reported to the node running the
 * job, a node's jobs go back to the queue once its lease expires (and fail after the
 * attempts allowed), the other node hears of jobs queued and finished. */
#include <libpq-fe.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "grainpack/spec.h"
#include "grainpack/pipeline3d.h"
#include "log.h"
#include "sections.h"
#include "store.h"

static const char *backend;
static char location[1024]; /* of the current test's database */
static char admin_uri[1024]; /* PostgreSQL: the server's maintenance database */
static char dir[] = "/tmp/grainpack-contract-XXXXXX";
static int databases; /* made so far, for their names */

/* Runs one SQL command on a PostgreSQL database. */
static void pg_exec(const char *uri, const char *sql)
{
    PGconn *conn = PQconnectdb(uri);
    PGresult *res = PQexec(conn, sql);
    CHECK_MSG(PQresultStatus(res) == PGRES_COMMAND_OK, "%s: %s", sql, PQerrorMessage(conn));
    PQclear(res);
    PQfinish(conn);
}

/* Runs one SQL command on the PostgreSQL server's maintenance database. */
static void pg_admin(const char *sql)
{
    pg_exec(admin_uri, sql);
}

/* A new empty database for one test: its location in `location`. */
static void new_database(void)
{
    databases++;
    if (strcmp(backend, "sqlite") == 0) {
        snprintf(location, sizeof location, "%s/t%d.db", dir, databases);
        return;
    }
    char sql[128], name[64];
    snprintf(name, sizeof name, "contract_%ld_%d", (long)getpid(), databases);
    snprintf(sql, sizeof sql, "CREATE DATABASE %s", name);
    pg_admin(sql);
    /* the maintenance URI names the database "postgres": the test's instead */
    const char *db = strstr(admin_uri, "/postgres");
    snprintf(location, sizeof location, "%.*s/%s%s", (int)(db - admin_uri), admin_uri, name,
             db + strlen("/postgres"));
}

static gp_store *open_store(void)
{
    gp_store *store = NULL;
    char why[512];
    int rc = gp_store_open(location, &store, why, sizeof why);
    CHECK_MSG(rc == 0, "%s", why);
    if (rc)
        exit(check_status());
    return store;
}

static gp_spec small_spec(void)
{
    const char *text = "{\"inputs\": {\"domain\": {\"width\": 10, \"height\": 10},"
                       " \"distribution\": {\"kind\": \"constant\", \"radius\": 0.9}}}";
    gp_spec spec;
    gp_error err;
    if (gp_spec_parse(text, strlen(text), NULL, &spec, &err) != 0)
        abort();
    return spec;
}

/* A job with every stage but the mesh, small enough for a unit test. */
static const char staged_spec[] =
    "{\"inputs\": {\"domain\": {\"width\": 24, \"height\": 16},"
    " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.4, \"max\": 0.9},"
    " \"joint\": {\"law\": \"constant\", \"value\": 0.05},"
    " \"balance\": {\"method\": \"relocation\", \"max_iterations\": 3},"
    " \"laguerre\": {\"shrink\": \"offset\"}}}";

static void claim_one(gp_db *db, char id[GP_JOB_ID_SIZE])
{
    char *text = NULL;
    size_t len;
    CHECK(gp_store_claim(db, NULL, id, &text, &len) == 0);
    free(text);
}

static void test_jobs_are_claimed_oldest_first_and_results_read_back_whole(void)
{
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec spec;
    gp_error err;
    CHECK(gp_spec_parse(staged_spec, strlen(staged_spec), NULL, &spec, &err) == 0);
    gp_result r;
    CHECK_MSG(gp_pipeline_run(&spec, 0, NULL, &r, &err) == 0, "%s", err.message);
    gp_job first, second, got;
    CHECK(gp_store_insert_job(db, "", 0, staged_spec, strlen(staged_spec), &spec, &first, NULL) == 0);
    CHECK(gp_store_insert_job(db, "", 0, "{}", 2, &spec, &second, NULL) == 0);
    CHECK(second.seq > first.seq);
    char id[GP_JOB_ID_SIZE], *text = NULL;
    size_t len;
    CHECK(gp_store_claim(db, NULL, id, &text, &len) == 0 && strcmp(id, first.id) == 0);
    CHECK(text && len == strlen(staged_spec) && memcmp(text, staged_spec, len) == 0);
    free(text);
    CHECK(gp_store_progress(db, id, 40, "running: pack 80%") == 0);
    CHECK(gp_store_get_job(db, id, NULL, &got) == 0 && got.status == GP_JOB_RUNNING &&
          got.progress == 40 && strcmp(got.message, "running: pack 80%") == 0 && got.started[0]);
    CHECK(gp_store_finish(db, id, &r) == 0);
    CHECK(gp_store_get_job(db, id, NULL, &got) == 0 && got.status == GP_JOB_SUCCESSFUL &&
          got.progress == 100 && got.finished[0]);
    /* the result: its summary decoded, every disk and cell vertex byte for byte, read in
     * windows that cross the chunks' boundaries */
    gp_stored_result res;
    CHECK(gp_store_open_result(db, id, NULL, &res) == 0);
    CHECK(res.summary.stats.count == r.stats.count);
    CHECK(res.summary.stats.packing_density == r.stats.packing_density);
    CHECK(res.spec_len == strlen(staged_spec) && strcmp(res.spec_text, staged_spec) == 0);
    CHECK(strlen(res.version) == 32);
    gp_result_reader *reader = gp_result_reader_new(res.key);
    size_t bytes = r.packing.count * sizeof(gp_disk), window = 5000;
    unsigned char *back = malloc(bytes);
    for (size_t off = 0; off < bytes; off += window) {
        size_t n = bytes - off < window ? bytes - off : window;
        CHECK(gp_result_reader_read(reader, db, GP_SECTION_DISKS, off, back + off, n) == 0);
    }
    CHECK(memcmp(back, r.packing.disks, bytes) == 0);
    free(back);
    gp_result_reader_free(reader);
    gp_stored_result_free(&res);
    char names[8][32];
    double seconds[8];
    int n = gp_store_load_timings(db, id, names, seconds, 8);
    CHECK(n == r.ntimings && n > 0 && strcmp(names[0], r.timings[0].stage) == 0);
    /* the second job is next; then none waits */
    CHECK(gp_store_claim(db, NULL, id, &text, &len) == 0 && strcmp(id, second.id) == 0);
    free(text);
    CHECK(gp_store_claim(db, NULL, id, &text, &len) == GP_SRV_ENOTFOUND);
    CHECK(gp_store_open_result(db, second.id, NULL, &res) == GP_SRV_ENOTFOUND); /* running */
    long counts[GP_JOB_NSTATUS];
    CHECK(gp_store_count(db, counts) == 0 && counts[GP_JOB_SUCCESSFUL] == 1 &&
          counts[GP_JOB_RUNNING] == 1 && counts[GP_JOB_ACCEPTED] == 0);
    CHECK(gp_store_healthy(db));
    gp_result_free(&r);
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

/* Any process's outcome: a pack3d run (sections "pack3d" and "spheres", its statistics)
 * is stored as given, its job reads back as pack3d (the process the stored spec is for),
 * its message counts spheres, its summary section comes back as stored and its spheres
 * byte for byte, its bins and timings are rows like 2D's. */
static void test_a_pack3d_outcome_is_stored_and_read_back(void)
{
    static const char text[] = "{\"inputs\": {\"domain\": {\"width\": 6, \"height\": 6,"
                               " \"depth\": 6}, \"distribution\": {\"kind\": \"constant\","
                               " \"radius\": 0.5}, \"seed\": 2}}";
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec3d spec;
    gp_error err;
    CHECK(gp_spec3d_parse(text, strlen(text), NULL, &spec, &err) == 0);
    gp_pack3d_params params = gp_spec3d_pack_params(&spec, 0);
    gp_packing3d p;
    gp_pack3d_stats st;
    CHECK(gp_pack3d(&params, NULL, &p, &err) == 0 && p.count > 20);
    CHECK(gp_pack3d_stats_compute(&spec.box, &spec.dist, &p, &st) == 0);
    gp_job_columns columns = {"pack3d", 6, 6, "constant", "none", 0, 2, spec.expected_spheres, 0};
    gp_job job, got;
    CHECK(gp_store_insert_job_columns(db, "", 0, text, strlen(text), &columns, &job, NULL) == 0);
    CHECK(strcmp(job.process, "pack3d") == 0);
    char id[GP_JOB_ID_SIZE];
    claim_one(db, id);
    gp_section sec[GP_SECTIONS_MAX];
    size_t n;
    CHECK(gp_sections_from_packing3d(&spec.box, &p, &st, sec, &n) == 0);
    gp_stage_time timings[1] = {{"pack3d", 0.25}};
    gp_pack_stats view = gp_pack3d_stats_view(&st);
    gp_outcome outcome = {sec, n, &view, 0, p.attempts, 0, 0, 0, p.max_level, "spheres", timings, 1};
    CHECK(gp_store_finish_outcome(db, id, &outcome) == 0);
    CHECK(gp_store_get_job(db, id, NULL, &got) == 0 && got.status == GP_JOB_SUCCESSFUL &&
          strcmp(got.process, "pack3d") == 0 && strstr(got.message, " spheres, packing density "));
    gp_job list[2];
    size_t listed;
    int more;
    CHECK(gp_store_list_jobs(db, NULL, 0, 0, 2, list, &listed, &more) == 0 && listed == 1 &&
          strcmp(list[0].process, "pack3d") == 0);
    gp_stored_result res;
    CHECK(gp_store_open_result(db, id, NULL, &res) == 0 && res.nraw == 1 && res.summary.stats.count == 0);
    CHECK(strcmp(res.raw[0].tag, GP_SECTION_PACK3D) == 0 && res.raw[0].size == sec[0].size &&
          memcmp(res.raw[0].data, sec[0].data, sec[0].size) == 0);
    gp_result_reader *reader = gp_result_reader_new(res.key);
    size_t bytes = p.count * sizeof(gp_sphere);
    unsigned char *back = malloc(bytes);
    CHECK(gp_result_reader_read(reader, db, GP_SECTION_SPHERES, 0, back, bytes) == 0);
    CHECK(memcmp(back, p.spheres, bytes) == 0);
    free(back);
    gp_result_reader_free(reader);
    gp_stored_result_free(&res);
    char names[2][32];
    double seconds[2];
    CHECK(gp_store_load_timings(db, id, names, seconds, 2) == 1 && strcmp(names[0], "pack3d") == 0);
    gp_sections_free(sec, n);
    gp_pack3d_stats_free(&st);
    gp_packing3d_free(&p);
    gp_spec3d_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

/* Runs one SQL command on the current test's database, beside the store. */
static void raw_sql(const char *sql)
{
    if (strcmp(backend, "sqlite") == 0) {
        sqlite3 *conn = NULL;
        char *why = NULL;
        CHECK(sqlite3_open(location, &conn) == SQLITE_OK);
        CHECK_MSG(sqlite3_exec(conn, sql, NULL, NULL, &why) == SQLITE_OK, "%s: %s", sql, why);
        sqlite3_free(why);
        sqlite3_close(conn);
        return;
    }
    pg_exec(location, sql);
}

/* A worker reads the clock before its claim waits for the database (the job's own
 * insertion may hold it, or the job came from a node whose clock is ahead): a job created
 * after that reading is still never started before it was created. */
static void test_a_job_is_never_started_before_it_was_created(void)
{
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec spec = small_spec();
    gp_job job, got;
    CHECK(gp_store_insert_job(db, "", 0, "{}", 2, &spec, &job, NULL) == 0);
    static const char later[] = "2999-01-01T00:00:00.000Z";
    char sql[256];
    snprintf(sql, sizeof sql, "UPDATE jobs SET created = '%s' WHERE id = '%s'", later, job.id);
    raw_sql(sql);
    char id[GP_JOB_ID_SIZE];
    claim_one(db, id);
    CHECK(strcmp(id, job.id) == 0);
    CHECK(gp_store_get_job(db, id, NULL, &got) == 0 && got.status == GP_JOB_RUNNING);
    CHECK_MSG(strcmp(got.started, got.created) >= 0, "started %s, created %s", got.started,
              got.created);
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

static void test_a_job_dismissed_while_it_runs_keeps_no_result(void)
{
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec spec = small_spec();
    gp_result r;
    gp_error err;
    CHECK(gp_pipeline_run(&spec, 0, NULL, &r, &err) == 0);
    gp_job job, after;
    CHECK(gp_store_insert_job(db, "", 0, "{}", 2, &spec, &job, NULL) == 0);
    char id[GP_JOB_ID_SIZE];
    claim_one(db, id);
    gp_job_status before;
    int deleted;
    CHECK(gp_store_dismiss(db, id, NULL, &before, &deleted, &after) == 0 && !deleted &&
          before == GP_JOB_RUNNING && after.status == GP_JOB_DISMISSED);
    CHECK(gp_store_finish(db, id, &r) == GP_SRV_ESTATE);
    CHECK(gp_store_fail(db, id, "x", "y") == GP_SRV_ESTATE);
    gp_stored_result res;
    CHECK(gp_store_open_result(db, id, NULL, &res) == GP_SRV_ENOTFOUND);
    /* a second DELETE removes it */
    CHECK(gp_store_dismiss(db, id, NULL, &before, &deleted, &after) == 0 && deleted &&
          before == GP_JOB_DISMISSED);
    CHECK(gp_store_get_job(db, id, NULL, &after) == GP_SRV_ENOTFOUND);
    /* a job queued again by a stop gives its claim back and is claimed again */
    CHECK(gp_store_insert_job(db, "", 0, "{}", 2, &spec, &job, NULL) == 0);
    claim_one(db, id);
    CHECK(gp_store_requeue(db, id) == 0);
    CHECK(gp_store_get_job(db, id, NULL, &after) == 0 && after.status == GP_JOB_ACCEPTED);
    claim_one(db, id);
    CHECK(strcmp(id, job.id) == 0);
    CHECK(gp_store_fail(db, id, "some error", "it failed") == 0);
    CHECK(gp_store_get_job(db, id, NULL, &after) == 0 && after.status == GP_JOB_FAILED &&
          strcmp(after.message, "it failed") == 0);
    gp_result_free(&r);
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

static void test_jobs_are_seen_by_their_owner_only(void)
{
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec spec = small_spec();
    gp_job a, b, got, list[8];
    CHECK(gp_store_insert_job(db, "alice", 0, "{}", 2, &spec, &a, NULL) == 0);
    CHECK(gp_store_insert_job(db, "bob", 0, "{}", 2, &spec, &b, NULL) == 0);
    CHECK(gp_store_get_job(db, a.id, "alice", &got) == 0);
    CHECK(gp_store_get_job(db, a.id, "bob", &got) == GP_SRV_ENOTFOUND);
    CHECK(gp_store_get_job(db, a.id, NULL, &got) == 0);
    size_t n;
    int more;
    CHECK(gp_store_list_jobs(db, "bob", 0, 0, 8, list, &n, &more) == 0);
    CHECK(n == 1 && strcmp(list[0].id, b.id) == 0);
    CHECK(gp_store_list_jobs(db, NULL, 0, 0, 8, list, &n, &more) == 0 && n == 2 &&
          strcmp(list[0].id, b.id) == 0); /* newest first */
    CHECK(gp_store_list_jobs(db, NULL, 0, 0, 1, list, &n, &more) == 0 && n == 1 && more);
    CHECK(gp_store_list_jobs(db, NULL, 0, b.seq, 8, list, &n, &more) == 0 && n == 1 &&
          strcmp(list[0].id, a.id) == 0 && !more);
    CHECK(gp_store_list_jobs(db, NULL, 1u << GP_JOB_RUNNING, 0, 8, list, &n, &more) == 0 && n == 0);
    gp_job_status before;
    int deleted;
    CHECK(gp_store_dismiss(db, a.id, "bob", &before, &deleted, &got) == GP_SRV_ENOTFOUND);
    CHECK(gp_store_get_job(db, a.id, "alice", &got) == 0 && got.status == GP_JOB_ACCEPTED);
    CHECK(gp_store_dismiss(db, a.id, "alice", &before, &deleted, &got) == 0 && !deleted);
    CHECK(gp_store_list_jobs(db, NULL, 1u << GP_JOB_DISMISSED, 0, 8, list, &n, &more) == 0 &&
          n == 1 && strcmp(list[0].id, a.id) == 0);
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

static void test_the_owner_limit_counts_accepted_and_running_jobs(void)
{
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec spec = small_spec();
    gp_job j1, j2, j3, other;
    long active = -1;
    CHECK(gp_store_insert_job(db, "alice", 2, "{}", 2, &spec, &j1, &active) == 0 && active == 0);
    char id[GP_JOB_ID_SIZE], *text;
    size_t len;
    atomic_long queued;
    atomic_init(&queued, 1); /* the claim takes the job out of the caller's count */
    CHECK(gp_store_claim(db, &queued, id, &text, &len) == 0 && strcmp(id, j1.id) == 0);
    CHECK(atomic_load(&queued) == 0);
    free(text);
    CHECK(gp_store_insert_job(db, "alice", 2, "{}", 2, &spec, &j2, &active) == 0 && active == 1);
    CHECK(gp_store_insert_job(db, "alice", 2, "{}", 2, &spec, &j3, &active) == GP_SRV_ELIMIT);
    CHECK(active == 2);
    CHECK(gp_store_insert_job(db, "bob", 2, "{}", 2, &spec, &other, &active) == 0 && active == 0);
    CHECK(gp_store_insert_job(db, "alice", 0, "{}", 2, &spec, &j3, NULL) == 0); /* 0: no limit */
    gp_job_status before;
    int deleted;
    gp_job after;
    CHECK(gp_store_fail(db, j1.id, "test", "done") == 0);
    CHECK(gp_store_dismiss(db, j3.id, NULL, &before, &deleted, &after) == 0);
    CHECK(gp_store_insert_job(db, "alice", 2, "{}", 2, &spec, &j3, &active) == 0 && active == 1);
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

/* Threads claiming from one store at once, each on its own connection. */
#define CLAIMERS 4
#define CLAIMED_JOBS 60

typedef struct claimer {
    gp_store *store;
    char ids[CLAIMED_JOBS][GP_JOB_ID_SIZE];
    int n;
} claimer;

static void *claim_all(void *arg)
{
    claimer *c = arg;
    gp_db *db = gp_store_acquire(c->store, 0);
    for (;;) {
        char id[GP_JOB_ID_SIZE], *text = NULL;
        size_t len;
        int rc = gp_store_claim(db, NULL, id, &text, &len);
        free(text);
        if (rc == GP_SRV_ENOTFOUND)
            break;
        if (rc != 0 || c->n == CLAIMED_JOBS) {
            c->n = -1;
            break;
        }
        snprintf(c->ids[c->n++], GP_JOB_ID_SIZE, "%s", id);
    }
    gp_store_release(c->store, db);
    return NULL;
}

static void test_threads_claiming_at_once_take_each_job_once(void)
{
    new_database();
    gp_store *store = open_store();
    gp_db *db = gp_store_acquire(store, 1);
    gp_spec spec = small_spec();
    gp_job jobs[CLAIMED_JOBS];
    for (int i = 0; i < CLAIMED_JOBS; i++)
        CHECK(gp_store_insert_job(db, "", 0, "{}", 2, &spec, &jobs[i], NULL) == 0);
    static claimer c[CLAIMERS];
    pthread_t t[CLAIMERS];
    for (int i = 0; i < CLAIMERS; i++) {
        memset(&c[i], 0, sizeof c[i]);
        c[i].store = store;
        pthread_create(&t[i], NULL, claim_all, &c[i]);
    }
    int total = 0;
    for (int i = 0; i < CLAIMERS; i++) {
        pthread_join(t[i], NULL);
        CHECK(c[i].n >= 0);
        total += c[i].n > 0 ? c[i].n : 0;
    }
    CHECK_MSG(total == CLAIMED_JOBS, "%d claims of %d jobs", total, CLAIMED_JOBS);
    for (int j = 0; j < CLAIMED_JOBS; j++) {
        int seen = 0;
        for (int i = 0; i < CLAIMERS; i++)
            for (int k = 0; k < c[i].n; k++)
                seen += strcmp(c[i].ids[k], jobs[j].id) == 0;
        CHECK_MSG(seen == 1, "job %d claimed %d times", j, seen);
    }
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

/* What gp_store_watch reported to a node. */
typedef struct heard {
    int queued, finished, lost;
    char lost_id[GP_JOB_ID_SIZE], finished_id[GP_JOB_ID_SIZE];
    long waiting;
} heard;

static void on_queued(void *ctx) { ((heard *)ctx)->queued++; }
static void on_finished(void *ctx, const char *id)
{
    heard *h = ctx;
    h->finished++;
    snprintf(h->finished_id, sizeof h->finished_id, "%s", id);
}
static void on_lost(void *ctx, const char *id)
{
    heard *h = ctx;
    h->lost++;
    snprintf(h->lost_id, sizeof h->lost_id, "%s", id);
}
static void on_waiting(void *ctx, long n) { ((heard *)ctx)->waiting = n; }

/* Watches for up to `seconds` or until *count reaches `want`; the seconds it took. */
static double watch_until(gp_store *store, heard *h, const int *count, int want, double seconds)
{
    gp_store_events ev = {h, on_queued, on_finished, on_lost, on_waiting};
    double start = gp_monotonic_seconds();
    while (*count < want && gp_monotonic_seconds() - start < seconds)
        CHECK(gp_store_watch(store, &ev, 0.05) == 0);
    return gp_monotonic_seconds() - start;
}

/* Two nodes, A and B, on one database (a shared store only). */
static void test_nodes_hear_of_each_other_and_take_over_a_dead_nodes_jobs(void)
{
    new_database();
    gp_store *a = open_store(), *b = open_store();
    CHECK(gp_store_shared(a) && gp_store_shared(b));
    /* leases of a second: a node that stops renewing loses its jobs soon */
    gp_store_options oa = {"node-a", 1.0, 2}, ob = {"node-b", 1.0, 2};
    CHECK(gp_store_configure(a, &oa) == 0 && gp_store_configure(b, &ob) == 0);
    CHECK(strncmp(gp_store_node(a), "node-a/", 7) == 0);
    gp_db *da = gp_store_acquire(a, 1), *db = gp_store_acquire(b, 1);
    gp_spec spec = small_spec();
    heard ha = {0}, hb = {0};
    watch_until(b, &hb, &hb.queued, 1, 0.3); /* B listens from now on */
    hb = (heard){0};
    /* B hears of A's submission; A claims it; B dismisses it: A hears it lost */
    gp_job job, after;
    CHECK(gp_store_insert_job(da, "", 0, "{}", 2, &spec, &job, NULL) == 0);
    watch_until(b, &hb, &hb.queued, 1, 5);
    CHECK(hb.queued == 1);
    char id[GP_JOB_ID_SIZE];
    claim_one(da, id);
    gp_job_status before;
    int deleted;
    CHECK(gp_store_dismiss(db, id, NULL, &before, &deleted, &after) == 0 && before == GP_JOB_RUNNING);
    double took = watch_until(a, &ha, &ha.lost, 1, 5);
    CHECK_MSG(ha.lost == 1 && strcmp(ha.lost_id, id) == 0 && took < 1.5, "lost %d after %.2f s",
              ha.lost, took);
    watch_until(b, &hb, &hb.finished, 1, 5); /* the dismissal is news too */
    CHECK(hb.finished == 1 && strcmp(hb.finished_id, id) == 0);
    /* A claims a job and dies (stops renewing): B queues it again after the lease, with
     * its claim counted; A's late outcome is refused */
    CHECK(gp_store_insert_job(da, "", 0, "{}", 2, &spec, &job, NULL) == 0);
    claim_one(da, id);
    hb = (heard){0};
    took = watch_until(b, &hb, &hb.queued, 2, 10); /* the submission, then the requeue */
    CHECK_MSG(hb.queued == 2 && took < 2 * oa.lease_seconds + 1, "queued %d after %.2f s",
              hb.queued, took);
    CHECK(gp_store_get_job(db, id, NULL, &after) == 0 && after.status == GP_JOB_ACCEPTED);
    char again[GP_JOB_ID_SIZE];
    claim_one(db, again);
    CHECK(strcmp(again, id) == 0);
    CHECK(gp_store_fail(da, id, "late", "from the dead node") == GP_SRV_ESTATE);
    CHECK(gp_store_progress(db, id, 10, "running") == 0);
    /* B dies too: this was the second claim of two allowed, so it fails for good */
    ha = (heard){0};
    watch_until(a, &ha, &ha.finished, 1, 10);
    CHECK(gp_store_get_job(da, id, NULL, &after) == 0 && after.status == GP_JOB_FAILED &&
          strstr(after.message, "2 times"));
    CHECK(ha.finished == 1 && ha.waiting == 0);
    gp_spec_free(&spec);
    gp_store_release(a, da);
    gp_store_release(b, db);
    gp_store_close(a);
    gp_store_close(b);
}

static void test_a_location_is_logged_without_its_password(void)
{
    char out[256];
    gp_store_redact("postgresql://alice:s3cret@db.example:5432/jobs?sslmode=require", out,
                    sizeof out);
    CHECK_STR(out, "postgresql://alice:***@db.example:5432/jobs?sslmode=require");
    gp_store_redact("postgres://alice@db/jobs", out, sizeof out);
    CHECK_STR(out, "postgres://alice@db/jobs");
    gp_store_redact("/var/lib/grainpack/a:b@c.db", out, sizeof out); /* a file: as it is */
    CHECK_STR(out, "/var/lib/grainpack/a:b@c.db");
    CHECK(gp_store_location_is_pg("PostgreSQL://x") && !gp_store_location_is_pg("./pg.db"));
}

int main(int argc, char **argv)
{
    if (argc < 2 || (strcmp(argv[1], "sqlite") != 0 && (strcmp(argv[1], "postgresql") != 0 || argc < 3))) {
        fprintf(stderr, "usage: %s sqlite | postgresql STATE\n", argv[0]);
        return 2;
    }
    backend = argv[1];
    if (!mkdtemp(dir))
        return 1;
    if (strcmp(backend, "postgresql") == 0) {
        FILE *f = fopen(argv[2], "r");
        char line[1100];
        while (f && fgets(line, sizeof line, f))
            if (strncmp(line, "uri=", 4) == 0)
                snprintf(admin_uri, sizeof admin_uri, "%.*s", (int)strcspn(line + 4, "\n"), line + 4);
        if (f)
            fclose(f);
        if (!admin_uri[0] || !strstr(admin_uri, "/postgres")) {
            fprintf(stderr, "no server URI in %s (tests/pg/pg_server.sh start)\n", argv[2]);
            return 1;
        }
    }
    RUN(test_a_location_is_logged_without_its_password);
    RUN(test_jobs_are_claimed_oldest_first_and_results_read_back_whole);
    RUN(test_a_pack3d_outcome_is_stored_and_read_back);
    RUN(test_a_job_dismissed_while_it_runs_keeps_no_result);
    RUN(test_a_job_is_never_started_before_it_was_created);
    RUN(test_jobs_are_seen_by_their_owner_only);
    RUN(test_the_owner_limit_counts_accepted_and_running_jobs);
    RUN(test_threads_claiming_at_once_take_each_job_once);
    if (strcmp(backend, "postgresql") == 0) {
        RUN(test_nodes_hear_of_each_other_and_take_over_a_dead_nodes_jobs);
        for (int i = 1; i <= databases; i++) {
            char sql[96];
            snprintf(sql, sizeof sql, "DROP DATABASE contract_%ld_%d", (long)getpid(), i);
            pg_admin(sql);
        }
    } else {
        for (int i = 1; i <= databases; i++) {
            const char *suffix[] = {"", "-wal", "-shm"};
            for (int k = 0; k < 3; k++) {
                char p[1100];
                snprintf(p, sizeof p, "%s/t%d.db%s", dir, i, suffix[k]);
                unlink(p);
            }
        }
    }
    rmdir(dir);
    return check_status();
}
