/* store_results.c - the job store's queries on results: a successful job's result as
 * tagged sections (core/sections.h) cut in chunks of GP_STORE_CHUNK bytes, its
 * per-bin statistics and stage timings, written with its final status in one
 * transaction; opened again for rendering (the summary sections), and the chunks read
 * one by one for store_reader.c, each its own short read transaction. */
#include "store_db.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sections.h"
#include "log.h"

/* Writes one section and its chunks. */
static int write_section(void *ctx, const char *id, const gp_section *sec)
{
    gp_db *db = ctx;
    sqlite3_stmt *s = gp_db_stmt(db, ST_SECTION);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    sqlite3_bind_text(s, 2, sec->tag, -1, SQLITE_STATIC);
    sqlite3_bind_int64(s, 3, sec->version);
    sqlite3_bind_int64(s, 4, (sqlite3_int64)sec->size);
    sqlite3_bind_int(s, 5, sec->summary);
    if (sqlite3_step(s) != SQLITE_ROW) {
        sqlite3_reset(s);
        return gp_db_fail(db, "insert result section");
    }
    sqlite3_int64 section = sqlite3_column_int64(s, 0);
    if (sqlite3_step(s) != SQLITE_DONE) { /* RETURNING rows drained before the next write */
        sqlite3_reset(s);
        return gp_db_fail(db, "insert result section");
    }
    sqlite3_reset(s);
    const unsigned char *bytes = sec->data;
    for (size_t off = 0, chunk = 0; off < sec->size; off += GP_STORE_CHUNK, chunk++) {
        size_t len = sec->size - off < GP_STORE_CHUNK ? sec->size - off : GP_STORE_CHUNK;
        if (!(s = gp_db_stmt(db, ST_CHUNK)))
            return GP_SRV_EDB;
        sqlite3_bind_int64(s, 1, section);
        sqlite3_bind_int64(s, 2, (sqlite3_int64)chunk);
        sqlite3_bind_blob64(s, 3, bytes + off, len, SQLITE_STATIC);
        int rc = gp_db_run(db, s, "insert result chunk");
        if (rc)
            return rc;
    }
    return 0;
}

int gp_db_write_sections(gp_db *db, const char *id, const gp_result *result)
{
    return gp_store_write_sections(id, result, write_section, db);
}

/* The result rows of a successful job; called inside the finishing transaction. */
static int write_result_rows(gp_db *db, const char *id, const gp_result *result)
{
    const gp_pack_stats *st = &result->stats;
    sqlite3_stmt *s;
    int rc = gp_db_write_sections(db, id, result);
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

int sq_finish(gp_db *db, const char *id, const gp_result *result)
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
    char version[33];
    gp_store_new_result_version(version);
    sqlite3_bind_text(s, 20, version, -1, SQLITE_STATIC);
    rc = gp_db_run_one(db, s, "finish job"); /* GP_SRV_ESTATE: dismissed while it ran */
    if (rc == 0)
        rc = write_result_rows(db, id, result);
    return gp_db_end(db, rc); /* nothing kept unless all of it is */
}

/* Lists the summary sections of job `id` and decodes them into res->summary. */
static int open_summary(gp_db *db, const char *id, gp_stored_result *res)
{
    sqlite3_stmt *s = gp_db_stmt(db, ST_SUMMARY_SECTIONS);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    gp_section_ref found[GP_SECTIONS_MAX];
    size_t n = 0;
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW && n < GP_SECTIONS_MAX) {
        gp_db_copy_text(found[n].tag, sizeof found[n].tag, s, 0);
        found[n].version = (uint32_t)sqlite3_column_int64(s, 1);
        found[n].section = sqlite3_column_int64(s, 2);
        found[n].bytes = (uint64_t)sqlite3_column_int64(s, 3);
        n++;
    }
    sqlite3_reset(s);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE)
        return gp_db_fail(db, "list result sections");
    return gp_store_decode_summary(db, id, found, n, res);
}

int sq_open_result(gp_db *db, const char *id, const char *owner, gp_stored_result *out)
{
    memset(out, 0, sizeof *out);
    sqlite3_stmt *s = gp_db_stmt(db, ST_OPEN_RESULT);
    if (!s)
        return GP_SRV_EDB;
    /* one read transaction: the job row and its sections as of one moment */
    if (sqlite3_exec(db->conn, "BEGIN DEFERRED", NULL, NULL, NULL) != SQLITE_OK)
        return gp_db_fail(db, "begin a read");
    sqlite3_bind_text(s, 1, id, -1, SQLITE_STATIC);
    gp_db_bind_owner(s, 2, owner);
    int rc = sqlite3_step(s), result = 0;
    if (rc == SQLITE_ROW) {
        out->key = sqlite3_column_int64(s, 0);
        size_t len = (size_t)sqlite3_column_bytes(s, 1);
        if ((out->spec_text = malloc(len + 1))) {
            memcpy(out->spec_text, sqlite3_column_blob(s, 1), len);
            out->spec_text[len] = '\0';
            out->spec_len = len;
        } else {
            result = GP_ENOMEM;
        }
        gp_db_copy_text(out->version, sizeof out->version, s, 2);
    } else {
        result = rc == SQLITE_DONE ? GP_SRV_ENOTFOUND : gp_db_fail(db, "open result");
    }
    sqlite3_reset(s);
    if (result == 0)
        result = open_summary(db, id, out);
    sqlite3_exec(db->conn, "COMMIT", NULL, NULL, NULL);
    if (result)
        gp_stored_result_free(out);
    return result;
}

int sq_find_section(gp_db *db, int64_t key, const char *tag, int64_t *section, uint64_t *bytes)
{
    sqlite3_stmt *s = gp_db_stmt(db, ST_FIND_SECTION);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_int64(s, 1, key);
    sqlite3_bind_text(s, 2, tag, -1, SQLITE_STATIC);
    int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW) {
        *section = sqlite3_column_int64(s, 0);
        *bytes = (uint64_t)sqlite3_column_int64(s, 1);
    }
    sqlite3_reset(s);
    if (rc == SQLITE_DONE)
        return GP_SRV_ENOTFOUND;
    return rc == SQLITE_ROW ? 0 : gp_db_fail(db, "find result section");
}

int sq_read_chunk(gp_db *db, int64_t section, int64_t chunk, void *dst, size_t *len)
{
    sqlite3_stmt *s = gp_db_stmt(db, ST_READ_CHUNK);
    if (!s)
        return GP_SRV_EDB;
    sqlite3_bind_int64(s, 1, section);
    sqlite3_bind_int64(s, 2, chunk);
    int rc = sqlite3_step(s), result = 0;
    if (rc == SQLITE_ROW) {
        size_t n = (size_t)sqlite3_column_bytes(s, 0);
        if (n > GP_STORE_CHUNK) {
            result = GP_SRV_EDB;
        } else {
            if (n)
                memcpy(dst, sqlite3_column_blob(s, 0), n);
            *len = n;
        }
    } else {
        result = rc == SQLITE_DONE ? GP_SRV_ENOTFOUND : gp_db_fail(db, "read result chunk");
    }
    sqlite3_reset(s);
    return result;
}

int sq_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap)
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