/* store_upgrade.c - the conversion of a version 2 database to version 3, inside the
 * migration's transaction: each successful job's disks (v2's `results` table) become the
 * sections a v3 result is made of. What the stages after packing produced was not stored
 * in v2: F (after balancing) and the Laguerre cells are derived again from the stored
 * disks, once, here (at start-up, before the daemon answers any request: the conversion
 * of a 10^6-grain job with cells takes a few seconds); F before balancing and the sweeps
 * are lost for good (the result says so: after_only). */
#include "store_db.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "store_schema.h"

/* Bytes per disk in version 2's results blob: x, y, r, R as float64. */
#define V2_DISK_RECORD 32

/* The successful jobs that have a version 2 result, in submission order. */
static int list_jobs(gp_db *db, char (**ids)[GP_JOB_ID_SIZE], size_t *n)
{
    *ids = NULL;
    *n = 0;
    sqlite3_stmt *s;
    if (sqlite3_prepare_v2(db->conn,
                           "SELECT j.id FROM jobs j JOIN results r ON r.job_id = j.id"
                           " WHERE j.status = 'successful' ORDER BY j.seq",
                           -1, &s, NULL) != SQLITE_OK)
        return GP_SRV_EDB;
    size_t cap = 0;
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            void *grown = realloc(*ids, cap * sizeof **ids);
            if (!grown) {
                sqlite3_finalize(s);
                return GP_ENOMEM;
            }
            *ids = grown;
        }
        gp_db_copy_text((*ids)[(*n)++], GP_JOB_ID_SIZE, s, 0);
    }
    sqlite3_finalize(s);
    return rc == SQLITE_DONE ? 0 : GP_SRV_EDB;
}

/* Reads job id's spec and v2 result into spec and result (the packing with its
 * diagnostics). */
static int load_v2(gp_db *db, const char *id, gp_spec *spec, gp_result *result, char *why,
                   size_t why_size)
{
    sqlite3_stmt *s;
    if (sqlite3_prepare_v2(db->conn,
                           "SELECT j.spec, r.count, r.disks, j.initial_disks, j.front_attempts,"
                           " j.front_closures, j.front_frozen, j.front_capped, j.max_level"
                           " FROM jobs j JOIN results r ON r.job_id = j.id WHERE j.id = ?1",
                           -1, &s, NULL) != SQLITE_OK)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    int rc = sqlite3_step(s) == SQLITE_ROW ? 0 : GP_SRV_EDB;
    gp_packing *p = &result->packing;
    if (rc == 0) {
        gp_spec_limits unlimited = {(size_t)-1, (size_t)-1, (size_t)-1};
        gp_error err;
        size_t count = (size_t)sqlite3_column_int64(s, 1);
        size_t bytes = (size_t)sqlite3_column_bytes(s, 2);
        const unsigned char *blob = sqlite3_column_blob(s, 2);
        if (gp_spec_parse(sqlite3_column_blob(s, 0), (size_t)sqlite3_column_bytes(s, 0),
                          &unlimited, spec, &err)) {
            snprintf(why, why_size, "job %s: its stored spec does not parse: %s", id, err.message);
            rc = GP_SRV_EDB;
        } else if (bytes != count * V2_DISK_RECORD) {
            snprintf(why, why_size, "job %s: result blob of %zu bytes for %zu disks", id, bytes,
                     count);
            rc = GP_SRV_EDB;
        } else if (!(p->disks = malloc((count ? count : 1) * sizeof *p->disks))) {
            rc = GP_ENOMEM;
        } else {
            memcpy(p->disks, blob, bytes); /* the same layout: four little-endian doubles */
            p->count = count;
            for (size_t i = 0; i < count; i++)
                p->fill_area += M_PI * p->disks[i].R * p->disks[i].R;
            p->initial_front = (size_t)sqlite3_column_int64(s, 3);
            p->attempts = (uint64_t)sqlite3_column_int64(s, 4);
            p->closures = (uint64_t)sqlite3_column_int64(s, 5);
            p->frozen = (uint64_t)sqlite3_column_int64(s, 6);
            p->capped = (uint64_t)sqlite3_column_int64(s, 7);
            p->max_level = (uint32_t)sqlite3_column_int64(s, 8);
        }
    }
    sqlite3_finalize(s);
    return rc;
}

/* Converts one job: its statistics, F and cells derived again, every section written. */
static int convert(gp_db *db, const char *id, char *why, size_t why_size)
{
    gp_spec spec;
    gp_result result;
    memset(&spec, 0, sizeof spec);
    memset(&result, 0, sizeof result);
    int rc = load_v2(db, id, &spec, &result, why, why_size);
    if (rc == 0 && gp_pack_stats_compute(&spec.domain, &spec.dist, &result.packing, &result.stats))
        rc = GP_ENOMEM;
    if (rc == 0) {
        gp_error err;
        gp_error_clear(&err);
        int derived = gp_result_rederive(&spec, &result, &err);
        if (derived == GP_ENOMEM)
            rc = GP_ENOMEM;
        else if (derived) /* keep what the store had: the disks and their statistics */
            gp_log("store: upgrade: job %s: F and cells cannot be derived again (%s): its result "
                   "keeps the disks only", id, err.message);
    }
    if (rc == 0)
        rc = gp_db_write_sections(db, id, &result);
    if (rc == 0) {
        char version[33];
        gp_store_new_result_version(version);
        sqlite3_stmt *s;
        if (sqlite3_prepare_v2(db->conn, "UPDATE jobs SET result_version = ?2 WHERE id = ?1", -1,
                               &s, NULL) != SQLITE_OK)
            return GP_SRV_EDB;
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_text(s, 2, version, -1, SQLITE_STATIC);
        rc = sqlite3_step(s) == SQLITE_DONE ? 0 : GP_SRV_EDB;
        sqlite3_finalize(s);
    }
    if (rc == 0)
        gp_log("store: upgrade: job %s: %zu disks%s%s stored as sections", id, result.packing.count,
               result.has_balance ? ", F" : "", result.has_cells ? ", cells" : "");
    else if (!why[0])
        snprintf(why, why_size, "job %s: cannot convert its result (%d)", id, rc);
    gp_result_free(&result);
    gp_spec_free(&spec);
    return rc;
}

int gp_store_upgrade_v3(gp_db *db, char *why, size_t why_size)
{
    why[0] = '\0';
    char(*ids)[GP_JOB_ID_SIZE];
    size_t n;
    int rc = list_jobs(db, &ids, &n);
    for (size_t i = 0; rc == 0 && i < n; i++)
        rc = convert(db, ids[i], why, why_size);
    free(ids);
    if (rc == 0 && sqlite3_exec(db->conn, "DROP TABLE results", NULL, NULL, NULL) != SQLITE_OK)
        rc = GP_SRV_EDB;
    if (rc && !why[0])
        snprintf(why, why_size, "upgrade to version 3: %s", sqlite3_errmsg(db->conn));
    if (rc == 0 && n > 0)
        gp_log("store: upgrade to version 3: %zu results converted", n);
    return rc;
}
