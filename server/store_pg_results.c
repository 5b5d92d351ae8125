/* store_pg_results.c - the PostgreSQL store's queries on results: a successful job's
 * sections (core/sections.h) as bytea chunks of GP_STORE_CHUNK bytes, its per-bin
 * statistics and stage timings, written with its final status in one transaction (only
 * by the run that still holds the job's claim); opened again and read chunk by chunk on
 * any node. */
#include "store_pg.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

/* Writes one section and its chunks, inside the finishing transaction. */
static int write_section(void *ctx, const char *id, const gp_section *sec)
{
    pg_db *db = ctx;
    char b[3][32];
    pg_params p = {0};
    gp_pg_text(&p, id);
    gp_pg_text(&p, sec->tag);
    gp_pg_int(&p, b[0], (long long)sec->version);
    gp_pg_int(&p, b[1], (long long)sec->size);
    gp_pg_text(&p, sec->summary ? "true" : "false");
    int rc;
    PGresult *res = gp_pg_query(db, "insert result section",
                                "INSERT INTO result_sections (job_id, tag, version, bytes, summary)"
                                " VALUES ($1, $2, $3, $4, $5) RETURNING id",
                                &p, 0, &rc);
    if (!res)
        return rc;
    char section[32];
    snprintf(section, sizeof section, "%s", PQgetvalue(res, 0, 0));
    PQclear(res);
    const unsigned char *bytes = sec->data;
    for (size_t off = 0, chunk = 0; rc == 0 && off < sec->size; off += GP_STORE_CHUNK, chunk++) {
        size_t len = sec->size - off < GP_STORE_CHUNK ? sec->size - off : GP_STORE_CHUNK;
        pg_params c = {0};
        gp_pg_text(&c, section);
        gp_pg_int(&c, b[2], (long long)chunk);
        gp_pg_bytes(&c, bytes + off, len);
        rc = gp_pg_run(db, "insert result chunk",
                       "INSERT INTO result_chunks (section, chunk, data) VALUES ($1, $2, $3)", &c,
                       NULL);
    }
    return rc;
}

/* The result rows of a successful job: its sections, bins and timings. */
static int write_result_rows(pg_db *db, const char *id, const gp_result *result)
{
    int rc = gp_store_write_sections(id, result, write_section, db);
    const gp_pack_stats *st = &result->stats;
    for (size_t i = 0; rc == 0 && i < st->nbins; i++) {
        const gp_bin_stat *bin = &st->bins[i];
        char b[7][32];
        pg_params p = {0};
        gp_pg_text(&p, id);
        gp_pg_int(&p, b[0], (long long)i);
        gp_pg_double(&p, b[1], bin->min);
        gp_pg_double(&p, b[2], bin->max);
        gp_pg_double(&p, b[3], bin->target);
        gp_pg_double(&p, b[4], bin->achieved);
        gp_pg_int(&p, b[5], (long long)bin->count);
        gp_pg_double(&p, b[6], bin->z);
        rc = gp_pg_run(db, "insert bin statistics",
                       "INSERT INTO bin_stats (job_id, bin, min, max, target, achieved, count, z)"
                       " VALUES ($1, $2, $3, $4, $5, $6, $7, $8)",
                       &p, NULL);
    }
    for (int i = 0; rc == 0 && i < result->ntimings; i++) {
        char b[2][32];
        pg_params p = {0};
        gp_pg_text(&p, id);
        gp_pg_int(&p, b[0], i);
        gp_pg_text(&p, result->timings[i].stage);
        gp_pg_double(&p, b[1], result->timings[i].seconds);
        rc = gp_pg_run(db, "insert stage timing",
                       "INSERT INTO stage_timings (job_id, position, stage, seconds)"
                       " VALUES ($1, $2, $3, coalesce($4::float8, 0))",
                       &p, NULL);
    }
    return rc;
}

int gp_pg_finish(gp_db *d, const char *id, const gp_result *result)
{
    pg_db *db = gp_pg_db(d);
    pg_store *store = gp_pg_store(db->store);
    const gp_pack_stats *st = &result->stats;
    const gp_packing *pk = &result->packing;
    char now[GP_TIMESTAMP_SIZE], message[128], version[33], b[20][32];
    gp_timestamp_now(now);
    gp_store_new_result_version(version);
    snprintf(message, sizeof message, "%zu disks, packing density %.4f", st->count,
             st->packing_density);
    pg_params p = {0};
    gp_pg_text(&p, id);
    gp_pg_text(&p, store->run);
    gp_pg_int(&p, b[0], gp_pg_held(store, id));
    gp_pg_text(&p, message);
    gp_pg_text(&p, now);
    gp_pg_int(&p, b[1], (long long)st->count);
    gp_pg_double(&p, b[2], st->packing_density);
    gp_pg_double(&p, b[3], st->grain_fraction);
    gp_pg_double(&p, b[4], st->r_min);
    gp_pg_double(&p, b[5], st->r_max);
    gp_pg_double(&p, b[6], st->r_mean);
    gp_pg_double(&p, b[7], st->chi2);
    gp_pg_int(&p, b[8], st->dof);
    gp_pg_double(&p, b[9], st->p_value);
    gp_pg_double(&p, b[10], st->max_abs_z);
    gp_pg_int(&p, b[11], (long long)pk->initial_front);
    gp_pg_int(&p, b[12], (long long)pk->attempts);
    gp_pg_int(&p, b[13], (long long)pk->closures);
    gp_pg_int(&p, b[14], (long long)pk->frozen);
    gp_pg_int(&p, b[15], (long long)pk->capped);
    gp_pg_int(&p, b[16], (long long)pk->max_level);
    gp_pg_text(&p, version);
    long changed = 0;
    int rc = gp_pg_begin(db);
    if (!rc)
        rc = gp_pg_run(db, "finish job",
                       "UPDATE jobs SET status = 'successful', progress = 100, message = $4,"
                       " finished = $5, updated = $5, count = $6, packing_density = $7,"
                       " grain_fraction = $8, r_min = $9, r_max = $10, r_mean = $11, chi2 = $12,"
                       " dof = $13, p_value = $14, max_abs_z = $15, initial_disks = $16,"
                       " front_attempts = $17, front_closures = $18, front_frozen = $19,"
                       " front_capped = $20, max_level = $21, result_version = $22,"
                       " node = NULL, lease_until = NULL"
                       " WHERE id = $1 AND status = 'running' AND node = $2 AND claims = $3::int",
                       &p, &changed);
    if (!rc && changed == 0)
        rc = GP_SRV_ESTATE; /* dismissed while it ran, or taken by another node */
    if (!rc)
        rc = write_result_rows(db, id, result);
    if (!rc)
        rc = gp_pg_run(db, "notify", "SELECT pg_notify('gp_done', $1)",
                       &(pg_params){.n = 1, .values = {id}}, NULL);
    rc = gp_pg_end(db, rc); /* nothing kept unless all of it is */
    if (rc == 0 || rc == GP_SRV_ESTATE)
        gp_pg_forget(store, id);
    return rc;
}

/* Lists the summary sections of job id and decodes them into res->summary. */
static int open_summary(pg_db *db, const char *id, gp_stored_result *res)
{
    int rc;
    PGresult *r = gp_pg_query(db, "list result sections",
                              "SELECT tag, version, id, bytes FROM result_sections"
                              " WHERE job_id = $1 AND summary ORDER BY id",
                              &(pg_params){.n = 1, .values = {id}}, 0, &rc);
    if (!r)
        return rc;
    gp_section_ref found[GP_SECTIONS_MAX];
    size_t n = 0;
    for (int row = 0; row < PQntuples(r) && n < GP_SECTIONS_MAX; row++, n++) {
        snprintf(found[n].tag, sizeof found[n].tag, "%s", PQgetvalue(r, row, 0));
        found[n].version = (uint32_t)atol(PQgetvalue(r, row, 1));
        found[n].section = atoll(PQgetvalue(r, row, 2));
        found[n].bytes = (uint64_t)atoll(PQgetvalue(r, row, 3));
    }
    PQclear(r);
    return gp_store_decode_summary((gp_db *)(void *)db, id, found, n, res);
}

int gp_pg_open_result(gp_db *d, const char *id, const char *owner, gp_stored_result *out)
{
    pg_db *db = gp_pg_db(d);
    memset(out, 0, sizeof *out);
    /* one snapshot: the job row and its sections as of one moment */
    int rc = gp_pg_run(db, "begin a read", "BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY",
                       NULL, NULL);
    PGresult *res = rc ? NULL : gp_pg_query(db, "open result",
                                            "SELECT seq, spec, result_version FROM jobs"
                                            " WHERE id = $1::text AND status = 'successful'"
                                            " AND ($2::text IS NULL OR owner = $2::text)",
                                            &(pg_params){.n = 2, .values = {id, owner}}, 0, &rc);
    if (res && PQntuples(res) == 1) {
        out->key = atoll(PQgetvalue(res, 0, 0));
        size_t len = (size_t)PQgetlength(res, 0, 1);
        if ((out->spec_text = malloc(len + 1))) {
            memcpy(out->spec_text, PQgetvalue(res, 0, 1), len + 1);
            out->spec_len = len;
        } else {
            rc = GP_ENOMEM;
        }
        snprintf(out->version, sizeof out->version, "%s", PQgetvalue(res, 0, 2));
    } else if (res) {
        rc = GP_SRV_ENOTFOUND;
    }
    PQclear(res);
    if (rc == 0)
        rc = open_summary(db, id, out);
    gp_pg_end(db, GP_SRV_ESTATE); /* a read: rolled back */
    if (rc)
        gp_stored_result_free(out);
    return rc;
}

int gp_pg_find_section(gp_db *d, int64_t key, const char *tag, int64_t *section, uint64_t *bytes)
{
    char k[32];
    pg_params p = {0};
    gp_pg_int(&p, k, key);
    gp_pg_text(&p, tag);
    int rc;
    PGresult *res = gp_pg_query(gp_pg_db(d), "find result section",
                                "SELECT s.id, s.bytes FROM result_sections s JOIN jobs j"
                                " ON j.id = s.job_id WHERE j.seq = $1::bigint AND s.tag = $2",
                                &p, 0, &rc);
    if (res && PQntuples(res) == 1) {
        *section = atoll(PQgetvalue(res, 0, 0));
        *bytes = (uint64_t)atoll(PQgetvalue(res, 0, 1));
    } else if (res) {
        rc = GP_SRV_ENOTFOUND;
    }
    PQclear(res);
    return rc;
}

int gp_pg_read_chunk(gp_db *d, int64_t section, int64_t chunk, void *dst, size_t *len)
{
    char b[2][32];
    pg_params p = {0};
    gp_pg_int(&p, b[0], section);
    gp_pg_int(&p, b[1], chunk);
    int rc;
    /* the bytes in binary: no hex text to decode */
    PGresult *res = gp_pg_query(gp_pg_db(d), "read result chunk",
                                "SELECT data FROM result_chunks WHERE section = $1::bigint"
                                " AND chunk = $2::bigint",
                                &p, 1, &rc);
    if (res && PQntuples(res) == 1) {
        size_t n = (size_t)PQgetlength(res, 0, 0);
        if (n > GP_STORE_CHUNK) {
            rc = GP_SRV_EDB;
        } else {
            memcpy(dst, PQgetvalue(res, 0, 0), n);
            *len = n;
        }
    } else if (res) {
        rc = GP_SRV_ENOTFOUND;
    }
    PQclear(res);
    return rc;
}

int gp_pg_load_timings(gp_db *d, const char *id, char names[][32], double *seconds, int cap)
{
    int rc;
    PGresult *res = gp_pg_query(gp_pg_db(d), "load timings",
                                "SELECT stage, seconds FROM stage_timings WHERE job_id = $1"
                                " ORDER BY position",
                                &(pg_params){.n = 1, .values = {id}}, 0, &rc);
    int n = 0;
    for (int row = 0; res && row < PQntuples(res) && n < cap; row++) {
        snprintf(names[n], 32, "%s", PQgetvalue(res, row, 0));
        seconds[n++] = atof(PQgetvalue(res, row, 1));
    }
    PQclear(res);
    return res ? n : rc;
}
