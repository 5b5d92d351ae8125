/* store_results.c - the job store's queries on results: a successful job's disks, per-bin
 * statistics and stage timings, written with its final status in one transaction and
 * read back for rendering. */
#include "store_db.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

/* Bytes per disk in the results blob: x, y, r, R as float64. */
#define DISK_RECORD 32

/* The result rows of a successful job; called inside the finishing transaction. */
static int write_result_rows(gp_db *db, const char *id, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    const gp_pack_stats *st = &result->stats;
    size_t bytes = p->count * DISK_RECORD;
    unsigned char *blob = malloc(bytes ? bytes : 1);
    if (!blob)
        return GP_ENOMEM;
    for (size_t i = 0; i < p->count; i++) {
        double rec[4] = {p->disks[i].x, p->disks[i].y, p->disks[i].r, p->disks[i].R};
        memcpy(blob + i * DISK_RECORD, rec, DISK_RECORD); /* little-endian on our targets */
    }
    sqlite3_stmt *s = gp_db_stmt(db, ST_RESULT);
    int rc = s ? 0 : GP_SRV_EDB;
    if (s) {
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_int64(s, 2, (sqlite3_int64)p->count);
        sqlite3_bind_blob64(s, 3, blob, bytes, SQLITE_STATIC);
        rc = gp_db_run(db, s, "insert result");
    }
    free(blob);
    for (size_t i = 0; rc == 0 && i < st->nbins; i++) {
        const gp_bin_stat *b = &st->bins[i];
        if (!(s = gp_db_stmt(db, ST_BIN)))
            return GP_SRV_EDB;
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_int64(s, 2, (sqlite3_int64)i);
        sqlite3_bind_double(s, 3, b->min);
        sqlite3_bind_double(s, 4, b->max);
        sqlite3_bind_double(s, 5, b->target);
        sqlite3_bind_double(s, 6, b->achieved);
        sqlite3_bind_int64(s, 7, (sqlite3_int64)b->count);
        sqlite3_bind_double(s, 8, b->z);
        rc = gp_db_run(db, s, "insert bin statistics");
    }
    for (int i = 0; rc == 0 && i < result->ntimings; i++) {
        if (!(s = gp_db_stmt(db, ST_TIMING)))
            return GP_SRV_EDB;
        sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
        sqlite3_bind_int(s, 2, i);
        sqlite3_bind_text(s, 3, result->timings[i].stage, -1, SQLITE_STATIC);
        sqlite3_bind_double(s, 4, result->timings[i].seconds);
        rc = gp_db_run(db, s, "insert stage timing");
    }
    return rc;
}

int gp_store_finish(gp_db *db, const char *id, const gp_result *result)
{
    const gp_pack_stats *st = &result->stats;
    const gp_packing *p = &result->packing;
    char now[GP_TIMESTAMP_SIZE], message[128];
    gp_timestamp_now(now);
    snprintf(message, sizeof message, "%zu disks, packing density %.4f", st->count,
             st->packing_density);
    int rc;
    sqlite3_stmt *s = gp_db_write(db, ST_FINISH, &rc);
    if (!s)
        return rc;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 2, message, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 3, now, -1, SQLITE_STATIC);
    sqlite3_bind_int64(s, 4, (sqlite3_int64)st->count);
    sqlite3_bind_double(s, 5, st->packing_density);
    sqlite3_bind_double(s, 6, st->grain_fraction);
    sqlite3_bind_double(s, 7, st->r_min);
    sqlite3_bind_double(s, 8, st->r_max);
    sqlite3_bind_double(s, 9, st->r_mean);
    sqlite3_bind_double(s, 10, st->chi2);
    sqlite3_bind_int(s, 11, st->dof);
    sqlite3_bind_double(s, 12, st->p_value);
    sqlite3_bind_double(s, 13, st->max_abs_z);
    sqlite3_bind_int64(s, 14, (sqlite3_int64)p->initial_front);
    sqlite3_bind_int64(s, 15, (sqlite3_int64)p->attempts);
    sqlite3_bind_int64(s, 16, (sqlite3_int64)p->closures);
    sqlite3_bind_int64(s, 17, (sqlite3_int64)p->frozen);
    sqlite3_bind_int64(s, 18, (sqlite3_int64)p->capped);
    sqlite3_bind_int64(s, 19, (sqlite3_int64)p->max_level);
    rc = gp_db_run_one(db, s, "finish job"); /* GP_SRV_ESTATE: dismissed while it ran */
    if (rc == 0)
        rc = write_result_rows(db, id, result);
    return gp_db_end(db, rc); /* nothing kept unless all of it is */
}

int gp_store_load_result(gp_db *db, const char *id, const char *owner, char **spec_text,
                         size_t *spec_len, gp_packing *packing)
{
    *spec_text = NULL;
    memset(packing, 0, sizeof *packing);
    sqlite3_stmt *s = gp_db_stmt(db, ST_LOAD);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    gp_db_bind_owner(s, 2, owner);
    int rc = sqlite3_step(s);
    if (rc != SQLITE_ROW) {
        sqlite3_reset(s);
        return rc == SQLITE_DONE ? GP_SRV_ENOTFOUND : gp_db_fail(db, "load result");
    }
    int result = 0;
    size_t len = (size_t)sqlite3_column_bytes(s, 0);
    const void *text = sqlite3_column_blob(s, 0);
    size_t count = (size_t)sqlite3_column_int64(s, 1);
    size_t bytes = (size_t)sqlite3_column_bytes(s, 2);
    const unsigned char *blob = sqlite3_column_blob(s, 2);
    if (bytes != count * DISK_RECORD) {
        gp_log("store: job %s: result blob of %zu bytes for %zu disks", id, bytes, count);
        result = GP_SRV_EDB;
    } else if (!(*spec_text = malloc(len + 1)) ||
               !(packing->disks = malloc((count ? count : 1) * sizeof *packing->disks))) {
        result = GP_ENOMEM;
    } else {
        memcpy(*spec_text, text, len);
        (*spec_text)[len] = '\0';
        *spec_len = len;
        for (size_t i = 0; i < count; i++) {
            double rec[4];
            memcpy(rec, blob + i * DISK_RECORD, DISK_RECORD);
            packing->disks[i] = (gp_disk){rec[0], rec[1], rec[2], rec[3]};
            packing->fill_area += 3.14159265358979323846 * rec[3] * rec[3];
        }
        packing->count = count;
        packing->initial_front = (size_t)sqlite3_column_int64(s, 3);
        packing->attempts = (uint64_t)sqlite3_column_int64(s, 4);
        packing->closures = (uint64_t)sqlite3_column_int64(s, 5);
        packing->frozen = (uint64_t)sqlite3_column_int64(s, 6);
        packing->capped = (uint64_t)sqlite3_column_int64(s, 7);
        packing->max_level = (uint32_t)sqlite3_column_int64(s, 8);
    }
    sqlite3_reset(s);
    if (result) {
        free(*spec_text);
        *spec_text = NULL;
        gp_packing_free(packing);
    }
    return result;
}

int gp_store_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap)
{
    sqlite3_stmt *s = gp_db_stmt(db, ST_TIMINGS);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    int n = 0, rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW && n < cap) {
        gp_db_copy_text(names[n], 32, s, 0);
        seconds[n++] = sqlite3_column_double(s, 1);
    }
    sqlite3_reset(s);
    return rc == SQLITE_ROW || rc == SQLITE_DONE ? n : gp_db_fail(db, "load timings");
}