/* store.c - the job store's calls (store.h), passed on to the backend the store was
 * opened with (store_ops.h), and what both backends share: status names, error texts,
 * job ids and result versions. */
#include "store_ops.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/random.h>

#include "log.h"

static const gp_store_ops *ops_of(gp_store *store)
{
    return ((const gp_store_head *)(const void *)store)->ops;
}

static const gp_store_ops *db_ops(const gp_db *db)
{
    return ops_of(((const gp_db_head *)(const void *)db)->store);
}

const char *gp_srv_strerror(int code)
{
    switch (code) {
    case GP_SRV_ENOTFOUND: return "no such job";
    case GP_SRV_ESTATE: return "the job is not in the state this needs";
    case GP_SRV_EDB: return "the database failed";
    case GP_SRV_EFULL: return "the database's disk is full";
    case GP_SRV_EUNWRITABLE: return "the database cannot be written";
    case GP_SRV_ELIMIT: return "too many active jobs";
    default: return gp_strerror(code);
    }
}

static const char *const status_names[GP_JOB_NSTATUS] = {"accepted", "running", "successful",
                                                          "failed", "dismissed"};

const char *gp_job_status_name(gp_job_status status)
{
    return status < GP_JOB_NSTATUS ? status_names[status] : "unknown";
}

int gp_job_status_parse(const char *name, gp_job_status *out)
{
    for (int i = 0; i < GP_JOB_NSTATUS; i++) {
        if (strcmp(name, status_names[i]) == 0) {
            *out = (gp_job_status)i;
            return 0;
        }
    }
    return GP_EINVAL;
}

void gp_store_random_bytes(void *buf, size_t len)
{
    size_t got = 0;
    while (got < len) {
        ssize_t n = getrandom((unsigned char *)buf + got, len - got, 0);
        if (n > 0)
            got += (size_t)n;
    }
}

void gp_store_new_job_id(char out[GP_JOB_ID_SIZE])
{
    unsigned char b[16];
    gp_store_random_bytes(b, sizeof b);
    b[6] = (unsigned char)((b[6] & 0x0f) | 0x40);
    b[8] = (unsigned char)((b[8] & 0x3f) | 0x80);
    snprintf(out, GP_JOB_ID_SIZE,
             "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", b[0], b[1],
             b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12], b[13], b[14],
             b[15]);
}

void gp_store_new_result_version(char out[33])
{
    unsigned char b[16];
    gp_store_random_bytes(b, sizeof b);
    for (size_t i = 0; i < sizeof b; i++)
        snprintf(out + 2 * i, 3, "%02x", b[i]);
}

int gp_store_conns_add(gp_store_conns *c, void *db)
{
    if (c->n == c->cap) {
        size_t cap = c->cap ? c->cap * 2 : 16;
        void **grown = realloc(c->items, cap * sizeof *grown);
        if (!grown)
            return GP_ENOMEM;
        c->items = grown;
        c->cap = cap;
    }
    c->items[c->n++] = db;
    return 0;
}

void gp_store_conns_remove(gp_store_conns *c, void *db)
{
    for (size_t i = 0; i < c->n; i++) {
        if (c->items[i] == db) {
            c->items[i] = c->items[--c->n];
            return;
        }
    }
}

void gp_store_new_job(gp_job *out, const gp_job_columns *columns)
{
    memset(out, 0, sizeof *out);
    gp_store_new_job_id(out->id);
    gp_timestamp_now(out->created);
    snprintf(out->updated, sizeof out->updated, "%s", out->created);
    snprintf(out->message, sizeof out->message, "queued");
    out->status = GP_JOB_ACCEPTED;
    out->has_mesh = columns->has_mesh;
    snprintf(out->process, sizeof out->process, "%s", columns->process);
}

int gp_store_write_sections(const char *id, const gp_result *result,
                            int (*write)(void *ctx, const char *id, const gp_section *sec),
                            void *ctx)
{
    gp_section sections[GP_SECTIONS_MAX];
    size_t n;
    int rc = gp_sections_from_result(result, sections, &n);
    if (rc)
        return rc;
    for (size_t i = 0; rc == 0 && i < n; i++)
        rc = write(ctx, id, &sections[i]);
    gp_sections_free(sections, n);
    return rc;
}

int gp_store_location_is_pg(const char *location)
{
    return strncasecmp(location, "postgresql://", 13) == 0 ||
           strncasecmp(location, "postgres://", 11) == 0;
}

void gp_store_redact(const char *location, char *out, size_t size)
{
    /* scheme://user:password@host...: the password is what lies between the first ':'
     * after the scheme and the '@' of the authority */
    const char *auth = strstr(location, "://");
    if (!gp_store_location_is_pg(location) || !auth) {
        snprintf(out, size, "%s", location);
        return;
    }
    auth += 3;
    size_t len = strcspn(auth, "/?");
    const char *at = memchr(auth, '@', len), *colon = memchr(auth, ':', len);
    if (!at || !colon || colon > at) {
        snprintf(out, size, "%s", location);
        return;
    }
    snprintf(out, size, "%.*s***%s", (int)(colon + 1 - location), location, at);
}

int gp_store_open(const char *location, gp_store **out, char *why, size_t why_size)
{
    if (gp_store_location_is_pg(location))
        return gp_store_pg_open(location, out, why, why_size);
    return gp_store_sqlite_open(location, out, why, why_size);
}

const char *gp_store_kind(gp_store *store)
{
    return ops_of(store)->name;
}

int gp_store_configure(gp_store *store, const gp_store_options *options)
{
    return ops_of(store)->configure ? ops_of(store)->configure(store, options) : 0;
}

const char *gp_store_node(gp_store *store)
{
    return ops_of(store)->node ? ops_of(store)->node(store) : "";
}

int gp_store_secret(gp_store *store, const char *name, void *out, size_t len)
{
    if (!ops_of(store)->secret)
        return GP_SRV_ENOTFOUND;
    return ops_of(store)->secret(store, name, out, len);
}

int gp_store_shared(gp_store *store)
{
    return ops_of(store)->watch != NULL;
}

int gp_store_watch(gp_store *store, const gp_store_events *events, double seconds)
{
    return ops_of(store)->watch ? ops_of(store)->watch(store, events, seconds) : 0;
}

void gp_store_close(gp_store *store)
{
    if (store)
        ops_of(store)->close(store);
}

gp_db *gp_store_acquire(gp_store *store, int durable)
{
    return ops_of(store)->acquire(store, durable);
}

void gp_store_release(gp_store *store, gp_db *db)
{
    if (db)
        ops_of(store)->release(store, db);
}

int gp_store_recover(gp_db *db, int max_attempts, int *requeued, int *given_up)
{
    return db_ops(db)->recover(db, max_attempts, requeued, given_up);
}

void gp_job_columns_of_spec(const gp_spec *spec, gp_job_columns *out)
{
    *out = (gp_job_columns){"pack2d", spec->domain.width, spec->domain.height,
                            gp_dist_kind_name(spec->dist.kind), gp_joint_law_name(spec->joint.law),
                            (int)spec->level_band, spec->seed, spec->expected_disks,
                            spec->mesh_enabled};
}

int gp_store_insert_job_columns(gp_db *db, const char *owner, size_t max_active,
                                const char *spec_text, size_t spec_len,
                                const gp_job_columns *columns, gp_job *out, long *active)
{
    return db_ops(db)->insert_job(db, owner, max_active, spec_text, spec_len, columns, out, active);
}

int gp_store_insert_job(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                        size_t spec_len, const gp_spec *spec, gp_job *out, long *active)
{
    gp_job_columns columns;
    gp_job_columns_of_spec(spec, &columns);
    return gp_store_insert_job_columns(db, owner, max_active, spec_text, spec_len, &columns, out,
                                       active);
}

int gp_store_get_job(gp_db *db, const char *id, const char *owner, gp_job *out)
{
    return db_ops(db)->get_job(db, id, owner, out);
}

int gp_store_list_jobs(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                       size_t limit, gp_job *out, size_t *n, int *more)
{
    return db_ops(db)->list_jobs(db, owner, status_mask, before, limit, out, n, more);
}

int gp_store_claim(gp_db *db, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
                   size_t *spec_len)
{
    return db_ops(db)->claim(db, queued, id, spec_text, spec_len);
}

int gp_store_progress(gp_db *db, const char *id, int percent, const char *message)
{
    return db_ops(db)->progress(db, id, percent, message);
}

int gp_outcome_of_result(const gp_result *result, gp_section *sections, size_t *n,
                         gp_outcome *out)
{
    const gp_packing *p = &result->packing;
    int rc = gp_sections_from_result(result, sections, n);
    *out = (gp_outcome){sections, rc ? 0 : *n, &result->stats, p->initial_front, p->attempts,
                        p->closures, p->frozen, p->capped, p->max_level, "disks",
                        result->timings, result->ntimings};
    return rc;
}

int gp_store_finish_outcome(gp_db *db, const char *id, const gp_outcome *outcome)
{
    return db_ops(db)->finish(db, id, outcome);
}

int gp_store_finish(gp_db *db, const char *id, const gp_result *result)
{
    gp_section sections[GP_SECTIONS_MAX];
    size_t n = 0;
    gp_outcome outcome;
    int rc = gp_outcome_of_result(result, sections, &n, &outcome);
    if (rc)
        return rc;
    rc = gp_store_finish_outcome(db, id, &outcome);
    gp_sections_free(sections, n);
    return rc;
}

int gp_store_fail(gp_db *db, const char *id, const char *code_name, const char *message)
{
    return db_ops(db)->fail(db, id, code_name, message);
}

int gp_store_requeue(gp_db *db, const char *id)
{
    return db_ops(db)->requeue(db, id);
}

int gp_store_dismiss(gp_db *db, const char *id, const char *owner, gp_job_status *before,
                     int *deleted, gp_job *after)
{
    return db_ops(db)->dismiss(db, id, owner, before, deleted, after);
}

int gp_store_open_result(gp_db *db, const char *id, const char *owner, gp_stored_result *out)
{
    return db_ops(db)->open_result(db, id, owner, out);
}

int gp_store_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap)
{
    return db_ops(db)->load_timings(db, id, names, seconds, cap);
}

int gp_store_count(gp_db *db, long counts[GP_JOB_NSTATUS])
{
    return db_ops(db)->count(db, counts);
}

int gp_store_healthy(gp_db *db)
{
    return db_ops(db)->healthy(db);
}

int gp_store_write_state(gp_store *store)
{
    return ops_of(store)->write_state(store);
}

int gp_store_broken(const gp_db *db)
{
    return db && db_ops(db)->broken(db);
}
