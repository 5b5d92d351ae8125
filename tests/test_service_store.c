/* test_service_store.c - grainpackd's job store on a real sqlite file: a database of
 * schema version 1 migrates keeping its jobs (owner ''); a version 2 database, made from
 * version 2's own DDL with the disks-only results of that time, is upgraded in place: its
 * jobs are readable, its results serve every format (F and the cells derived once, at the
 * upgrade), new results are stored whole; a result is read piece by piece and a reader
 * stops cleanly when the job is deleted under it. What every backend must do is in
 * test_store_contract.c. */
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "grainpack/io.h"
#include "sections.h"
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

/* A job balanced and with Laguerre cells, small enough for a unit test. */
static const char staged_spec[] =
    "{\"inputs\": {\"domain\": {\"width\": 24, \"height\": 16},"
    " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.4, \"max\": 0.9},"
    " \"joint\": {\"law\": \"constant\", \"value\": 0.05},"
    " \"balance\": {\"method\": \"relocation\", \"max_iterations\": 3},"
    " \"laguerre\": {\"shrink\": \"offset\"}, \"picture\": {\"color\": \"quality\"}}}";

/* Runs the pipeline on a spec text; report_rule packs with the report's level rule whatever
 * the text says (as version 2 packed every job: it knew no other rule). */
static void run_spec(const char *text, int report_rule, gp_spec *spec, gp_result *r)
{
    gp_error err;
    CHECK(gp_spec_parse(text, strlen(text), NULL, spec, &err) == 0);
    spec->level_band_set |= report_rule;
    CHECK_MSG(gp_pipeline_run(spec, 0, NULL, r, &err) == 0, "%s", err.message);
    CHECK(r->packing.rule == (spec->level_band_set ? GP_FRONT_LEVEL_BAND : GP_FRONT_WAIT));
}

/* What a download reads: a stored result's sections through a reader. */
typedef struct stored_read {
    gp_result_reader *reader;
    gp_db *db;
} stored_read;

static int read_stored(void *ctx, const char *tag, uint64_t offset, void *dst, size_t len)
{
    stored_read *sr = ctx;
    return gp_result_reader_read(sr->reader, sr->db, tag, offset, dst, len);
}

/* Renders an opened result from the store, as the service does (a window of 5 grains:
 * many reads, across chunk boundaries). The caller frees the text. */
static char *render_stored(gp_db *db, gp_stored_result *res, const gp_spec *spec, gp_format f,
                           size_t *len)
{
    stored_read sr = {gp_result_reader_new(res->key), db};
    gp_sections_source *src = gp_sections_source_new(&res->summary, read_stored, &sr, 5);
    gp_grain_source grains = gp_sections_source_grains(src);
    gp_writer *w = gp_writer_new(f, spec, &res->summary, &grains);
    gp_out out;
    CHECK(gp_out_init(&out, 0, NULL, NULL) == 0);
    CHECK(gp_writer_run(w, &out, SIZE_MAX) == 0);
    gp_writer_free(w);
    gp_sections_source_free(src);
    gp_result_reader_free(sr.reader);
    *len = out.len;
    return out.buf;
}

static char *render_memory(const gp_spec *spec, const gp_result *r, gp_format f, size_t *len)
{
    gp_out out;
    CHECK(gp_out_init(&out, 0, NULL, NULL) == 0);
    CHECK(gp_write_result(&out, f, spec, r) == 0);
    *len = out.len;
    return out.buf;
}

/* Every format of the stored result equals the one of `expected` in memory. */
static void check_formats(gp_db *db, const char *id, const gp_spec *spec, const gp_result *expected)
{
    gp_stored_result res;
    CHECK(gp_store_open_result(db, id, NULL, &res) == 0);
    CHECK(res.summary.packing.count == expected->packing.count);
    CHECK(res.summary.has_balance == expected->has_balance && res.summary.has_cells == expected->has_cells);
    for (size_t f = 0; f < gp_format_count(); f++) {
        /* msh and inp exist only with a mesh (these jobs have none); vtu reads the grains
         * whole, which only the service's download lends it (test_service_downloads
         * compares its bytes over HTTP); tess is 3D only */
        if ((gp_format_needs_mesh((gp_format)f) && !expected->has_mesh) || f == GP_FORMAT_VTU ||
            f == GP_FORMAT_TESS)
            continue;
        size_t a, b;
        char *want = render_memory(spec, expected, (gp_format)f, &a);
        char *got = render_stored(db, &res, spec, (gp_format)f, &b);
        CHECK_MSG(a == b && memcmp(want, got, a) == 0, "job %s, %s: %zu bytes stored, %zu in memory",
                  id, gp_format_name((gp_format)f), b, a);
        free(want);
        free(got);
    }
    gp_stored_result_free(&res);
}

/* Inserts, as version 2 stored them, a successful job and its disks-only result. */
static void insert_v2_job(sqlite3 *conn, const char *id, const char *spec_text, const gp_result *r)
{
    sqlite3_stmt *s;
    CHECK(sqlite3_prepare_v2(conn,
                             "INSERT INTO jobs (id, status, created, updated, finished, spec,"
                             " domain_width, domain_height, distribution, joint, level_band, seed,"
                             " expected_disks, count, initial_disks, front_attempts, front_closures,"
                             " front_frozen, front_capped, max_level, progress)"
                             " VALUES (?1, 'successful', 't', 't', 't', ?2, 24, 16, 'uniform',"
                             " 'constant', 0, 1, 500, ?3, ?4, ?5, ?6, ?7, 0, ?8, 100)",
                             -1, &s, NULL) == SQLITE_OK);
    const gp_packing *p = &r->packing;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 2, spec_text, -1, SQLITE_STATIC);
    sqlite3_bind_int64(s, 3, (sqlite3_int64)p->count);
    sqlite3_bind_int64(s, 4, (sqlite3_int64)p->initial_front);
    sqlite3_bind_int64(s, 5, (sqlite3_int64)p->attempts);
    sqlite3_bind_int64(s, 6, (sqlite3_int64)p->closures);
    sqlite3_bind_int64(s, 7, (sqlite3_int64)p->frozen);
    sqlite3_bind_int64(s, 8, (sqlite3_int64)p->max_level);
    CHECK(sqlite3_step(s) == SQLITE_DONE);
    sqlite3_finalize(s);
    CHECK(sqlite3_prepare_v2(conn, "INSERT INTO results (job_id, count, disks) VALUES (?1, ?2, ?3)",
                             -1, &s, NULL) == SQLITE_OK);
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_int64(s, 2, (sqlite3_int64)p->count);
    sqlite3_bind_blob(s, 3, p->disks, (int)(p->count * sizeof *p->disks), SQLITE_STATIC);
    CHECK(sqlite3_step(s) == SQLITE_DONE);
    sqlite3_finalize(s);
}

static void test_a_version_2_database_is_upgraded_with_its_results(void)
{
    const char *plain_spec = "{\"inputs\": {\"domain\": {\"width\": 30, \"height\": 20},"
                             " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.3, \"max\": 0.8}}}";
    gp_spec staged, plain, fresh_spec;
    gp_result ran_staged, ran_plain, ran_fresh;
    run_spec(staged_spec, 1, &staged, &ran_staged);
    run_spec(plain_spec, 1, &plain, &ran_plain);

    /* version 2 exactly as it was: its two migrations' DDL, its results table */
    remove_database();
    sqlite3 *conn;
    CHECK(sqlite3_open(db_path, &conn) == SQLITE_OK);
    CHECK(sqlite3_exec(conn, gp_store_migrations[0], NULL, NULL, NULL) == SQLITE_OK);
    CHECK(sqlite3_exec(conn, gp_store_migrations[1], NULL, NULL, NULL) == SQLITE_OK);
    CHECK(sqlite3_exec(conn,
                       "PRAGMA user_version = 2;"
                       "INSERT INTO jobs (id, status, created, updated, spec, domain_width,"
                       " domain_height, distribution, joint, level_band, seed, expected_disks, owner)"
                       " VALUES ('v2-queued', 'accepted', 't', 't', '{}', 1, 1, 'constant', 'none',"
                       " 0, 1, 1, 'alice')",
                       NULL, NULL, NULL) == SQLITE_OK);
    insert_v2_job(conn, "v2-staged", staged_spec, &ran_staged);
    insert_v2_job(conn, "v2-plain", plain_spec, &ran_plain);
    sqlite3_close(conn);

    gp_store *store;
    char why[256];
    CHECK_MSG(gp_store_open(db_path, &store, why, sizeof why) == 0, "%s", why);
    gp_db *db = gp_store_acquire(store, 1);
    gp_job job;
    CHECK(gp_store_get_job(db, "v2-queued", "alice", &job) == 0 && job.status == GP_JOB_ACCEPTED);
    CHECK(gp_store_get_job(db, "v2-staged", NULL, &job) == 0 && job.status == GP_JOB_SUCCESSFUL);

    /* what version 2 kept were the final disks: F and the cells are derived from them once,
     * at the upgrade, and every format of the result is what those disks give */
    gp_result expected;
    memset(&expected, 0, sizeof expected);
    expected.packing = ran_staged.packing;
    expected.packing.disks = malloc(ran_staged.packing.count * sizeof(gp_disk));
    memcpy(expected.packing.disks, ran_staged.packing.disks, ran_staged.packing.count * sizeof(gp_disk));
    CHECK(gp_pack_stats_compute(&staged.domain, &staged.dist, &expected.packing, &expected.stats) == 0);
    gp_error err;
    CHECK(gp_result_rederive(&staged, &expected, &err) == 0);
    CHECK(expected.balance.after_only && expected.has_cells);
    check_formats(db, "v2-staged", &staged, &expected);
    gp_result_free(&expected);
    check_formats(db, "v2-plain", &plain, &ran_plain); /* nothing was lost: the same bytes */

    /* the queued job of version 2 can still be dismissed; a new job gets a version 3
     * result: what every stage produced, F before balancing too, and the front's rule (the
     * densest default's waiting rule, with the parameters it chose) */
    gp_job_status before;
    int deleted;
    CHECK(gp_store_dismiss(db, "v2-queued", "alice", &before, &deleted, &job) == 0 && !deleted);
    run_spec(staged_spec, 0, &fresh_spec, &ran_fresh);
    gp_job fresh;
    CHECK(gp_store_insert_job(db, "", 0, staged_spec, strlen(staged_spec), &fresh_spec, &fresh,
                              NULL) == 0);
    char id[GP_JOB_ID_SIZE], *text;
    size_t len;
    CHECK(gp_store_claim(db, NULL, id, &text, &len) == 0 && strcmp(id, fresh.id) == 0);
    free(text);
    CHECK(gp_store_finish(db, fresh.id, &ran_fresh) == 0);
    check_formats(db, fresh.id, &fresh_spec, &ran_fresh);

    gp_store_release(store, db);
    gp_store_close(store);
    CHECK(sqlite3_open(db_path, &conn) == SQLITE_OK);
    sqlite3_stmt *s;
    CHECK(sqlite3_prepare_v2(conn, "PRAGMA user_version", -1, &s, NULL) == SQLITE_OK);
    CHECK(sqlite3_step(s) == SQLITE_ROW && sqlite3_column_int(s, 0) == 3);
    sqlite3_finalize(s);
    CHECK(sqlite3_prepare_v2(conn, "SELECT count(*) FROM sqlite_schema WHERE name = 'results'", -1,
                             &s, NULL) == SQLITE_OK);
    CHECK(sqlite3_step(s) == SQLITE_ROW && sqlite3_column_int(s, 0) == 0);
    sqlite3_finalize(s);
    sqlite3_close(conn);
    gp_result_free(&ran_staged);
    gp_result_free(&ran_plain);
    gp_result_free(&ran_fresh);
    gp_spec_free(&staged);
    gp_spec_free(&plain);
    gp_spec_free(&fresh_spec);
}

static void test_a_reader_stops_when_the_job_is_deleted_under_it(void)
{
    gp_store *store;
    gp_db *db = open_fresh(&store);
    gp_spec spec;
    gp_result r;
    run_spec(staged_spec, 0, &spec, &r);
    gp_job job;
    CHECK(gp_store_insert_job(db, "", 0, staged_spec, strlen(staged_spec), &spec, &job, NULL) == 0);
    char id[GP_JOB_ID_SIZE], *text;
    size_t len;
    CHECK(gp_store_claim(db, NULL, id, &text, &len) == 0);
    free(text);
    CHECK(gp_store_finish(db, job.id, &r) == 0);
    gp_stored_result res;
    CHECK(gp_store_open_result(db, job.id, NULL, &res) == 0);
    gp_result_reader *reader = gp_result_reader_new(res.key);
    gp_stored_result_free(&res); /* the reader needs the key only */
    gp_disk d[3];
    CHECK(gp_result_reader_read(reader, db, GP_SECTION_DISKS, 32, d, sizeof d) == 0);
    CHECK(memcmp(d, r.packing.disks + 1, sizeof d) == 0);
    /* past the end of a section, an unknown section */
    CHECK(gp_result_reader_read(reader, db, GP_SECTION_DISKS, 32 * r.packing.count - 16, d, 32) ==
          GP_SRV_ENOTFOUND);
    CHECK(gp_result_reader_read(reader, db, "no such section", 0, d, 8) == GP_SRV_ENOTFOUND);
    gp_job_status before;
    int deleted;
    gp_job after;
    CHECK(gp_store_dismiss(db, job.id, NULL, &before, &deleted, &after) == 0 && deleted);
    /* the cached chunk no longer counts: another chunk of the section is gone */
    double xy[2];
    CHECK(gp_result_reader_read(reader, db, GP_SECTION_CELL_XY, 0, xy, sizeof xy) == GP_SRV_ENOTFOUND);
    CHECK(gp_store_open_result(db, job.id, NULL, &res) == GP_SRV_ENOTFOUND);
    gp_result_reader_free(reader);
    gp_result_free(&r);
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
    RUN(test_a_version_2_database_is_upgraded_with_its_results);
    RUN(test_a_reader_stops_when_the_job_is_deleted_under_it);
    remove_database();
    rmdir(dir);
    return check_status();
}
