/* test_service_store.c - grainpackd's job store on a real sqlite file: a database of
 * schema version 1 migrates to version 2 keeping its jobs (owner ''); jobs are seen only
 * by their owner (NULL sees all); the per-owner limit counts accepted and running jobs in
 * the inserting transaction. */
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "grainpack/spec.h"
#include "store.h"
#include "store_schema.h"

static char dir[] = "/tmp/grainpack-store-XXXXXX";
static char db_path[256];

static void remove_database(void)
{
    const char *suffix[] = {"", "-wal", "-shm"};
    for (size_t i = 0; i < 3; i++) {
        char p[300];
        snprintf(p, sizeof p, "%s%s", db_path, suffix[i]);
        unlink(p);
    }
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

/* A store on a new database file, and a connection to it. */
static gp_db *open_fresh(gp_store **store)
{
    remove_database();
    char why[256];
    if (gp_store_open(db_path, store, why, sizeof why) != 0) {
        fprintf(stderr, "%s\n", why);
        abort();
    }
    return gp_store_acquire(*store, 1);
}

static void test_a_version_1_database_migrates_and_keeps_its_jobs(void)
{
    remove_database();
    sqlite3 *conn;
    CHECK(sqlite3_open(db_path, &conn) == SQLITE_OK);
    CHECK(sqlite3_exec(conn, gp_store_migrations[0], NULL, NULL, NULL) == SQLITE_OK);
    CHECK(sqlite3_exec(conn,
                       "PRAGMA user_version = 1;"
                       "INSERT INTO jobs (id, status, created, updated, spec, domain_width,"
                       " domain_height, distribution, joint, level_band, seed, expected_disks)"
                       " VALUES ('old-job', 'accepted', 't', 't', '{}', 1, 1, 'constant', 'none',"
                       " 0, 1, 1)",
                       NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(conn);

    gp_store *store;
    char why[256];
    CHECK(gp_store_open(db_path, &store, why, sizeof why) == 0);
    gp_db *db = gp_store_acquire(store, 1);
    gp_job job;
    CHECK(gp_store_get_job(db, "old-job", NULL, &job) == 0);
    CHECK(job.status == GP_JOB_ACCEPTED);
    CHECK(gp_store_get_job(db, "old-job", "", &job) == 0);
    CHECK(gp_store_get_job(db, "old-job", "alice", &job) == GP_SRV_ENOTFOUND);
    gp_store_release(store, db);
    gp_store_close(store);

    CHECK(sqlite3_open(db_path, &conn) == SQLITE_OK);
    sqlite3_stmt *s;
    CHECK(sqlite3_prepare_v2(conn, "PRAGMA user_version", -1, &s, NULL) == SQLITE_OK);
    CHECK(sqlite3_step(s) == SQLITE_ROW && sqlite3_column_int(s, 0) == GP_STORE_SCHEMA_VERSION);
    sqlite3_finalize(s);
    CHECK(sqlite3_prepare_v2(conn, "SELECT owner FROM jobs WHERE id = 'old-job'", -1, &s, NULL) ==
          SQLITE_OK);
    CHECK(sqlite3_step(s) == SQLITE_ROW && strcmp((const char *)sqlite3_column_text(s, 0), "") == 0);
    sqlite3_finalize(s);
    sqlite3_close(conn);
}

static void test_jobs_are_seen_by_their_owner_only(void)
{
    gp_store *store;
    gp_db *db = open_fresh(&store);
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
    CHECK(gp_store_list_jobs(db, NULL, 0, 0, 8, list, &n, &more) == 0 && n == 2);
    gp_job_status before;
    int deleted;
    CHECK(gp_store_dismiss(db, a.id, "bob", &before, &deleted, &got) == GP_SRV_ENOTFOUND);
    CHECK(gp_store_get_job(db, a.id, "alice", &got) == 0 && got.status == GP_JOB_ACCEPTED);
    CHECK(gp_store_dismiss(db, a.id, "alice", &before, &deleted, &got) == 0 && !deleted);
    CHECK(gp_store_dismiss(db, b.id, NULL, &before, &deleted, &got) == 0 && !deleted);
    gp_spec_free(&spec);
    gp_store_release(store, db);
    gp_store_close(store);
}

static void test_the_owner_limit_counts_accepted_and_running_jobs(void)
{
    gp_store *store;
    gp_db *db = open_fresh(&store);
    gp_spec spec = small_spec();
    gp_job j1, j2, j3, other;
    long active = -1;
    CHECK(gp_store_insert_job(db, "alice", 2, "{}", 2, &spec, &j1, &active) == 0 && active == 0);
    char id[GP_JOB_ID_SIZE], *text;
    size_t len;
    atomic_long queued;
    atomic_init(&queued, 1); /* the claim takes the job out of the caller's count */
    CHECK(gp_store_claim(db, &queued, id, &text, &len) == 0 && strcmp(id, j1.id) == 0); /* running */
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

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    snprintf(db_path, sizeof db_path, "%s/grainpack.db", dir);
    RUN(test_a_version_1_database_migrates_and_keeps_its_jobs);
    RUN(test_jobs_are_seen_by_their_owner_only);
    RUN(test_the_owner_limit_counts_accepted_and_running_jobs);
    remove_database();
    rmdir(dir);
    return check_status();
}
