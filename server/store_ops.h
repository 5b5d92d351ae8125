/* store_ops.h - inside the job store: what each backend (sqlite: store_sqlite.c and its
 * query files; PostgreSQL: store_pg*.c) provides, as a table of functions that store.c
 * dispatches the calls of store.h to. Not for the rest of the service. */
#ifndef GRAINPACKD_STORE_OPS_H
#define GRAINPACKD_STORE_OPS_H

#include "sections.h"
#include "store.h"

/* Each backend's store struct starts with a gp_store_head, and each of its connections
 * with a gp_db_head: store.c reads them without knowing the rest. */
typedef struct gp_store_ops gp_store_ops;
typedef struct gp_store_head {
    const gp_store_ops *ops;
} gp_store_head;
typedef struct gp_db_head {
    gp_store *store;
} gp_db_head;

/* One of a result's sections as its store lists it: where its chunks are. */
typedef struct gp_section_ref {
    char tag[GP_SECTION_TAG_SIZE];
    uint32_t version;
    int64_t section; /* the store's id of the section, for read_chunk */
    uint64_t bytes;
} gp_section_ref;

/* Every function has the contract of its gp_store_ namesake in store.h; the others: */
struct gp_store_ops {
    const char *name; /* "sqlite" or "postgresql", for /health and the log */
    void (*close)(gp_store *store);
    gp_db *(*acquire)(gp_store *store, int durable);
    void (*release)(gp_store *store, gp_db *db);
    int (*recover)(gp_db *db, int max_attempts, int *requeued, int *given_up);
    int (*insert_job)(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                      size_t spec_len, const gp_job_columns *columns, gp_job *out, long *active);
    int (*get_job)(gp_db *db, const char *id, const char *owner, gp_job *out);
    int (*list_jobs)(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                     size_t limit, gp_job *out, size_t *n, int *more);
    int (*claim)(gp_db *db, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
                 size_t *spec_len);
    int (*progress)(gp_db *db, const char *id, int percent, const char *message);
    int (*finish)(gp_db *db, const char *id, const gp_outcome *outcome);
    int (*fail)(gp_db *db, const char *id, const char *code_name, const char *message);
    int (*requeue)(gp_db *db, const char *id);
    int (*dismiss)(gp_db *db, const char *id, const char *owner, gp_job_status *before,
                   int *deleted, gp_job *after);
    int (*open_result)(gp_db *db, const char *id, const char *owner, gp_stored_result *out);
    /* Where section `tag` of the result `key` is: 0, GP_SRV_ENOTFOUND or GP_SRV_EDB. */
    int (*find_section)(gp_db *db, int64_t key, const char *tag, int64_t *section,
                        uint64_t *bytes);
    /* Copies chunk `chunk` of a section into dst (room for GP_STORE_CHUNK bytes) and its
     * length into *len: 0, GP_SRV_ENOTFOUND (no such chunk: deleted meanwhile) or
     * GP_SRV_EDB (also for a chunk longer than GP_STORE_CHUNK). */
    int (*read_chunk)(gp_db *db, int64_t section, int64_t chunk, void *dst, size_t *len);
    int (*load_timings)(gp_db *db, const char *id, char names[][32], double *seconds, int cap);
    int (*count)(gp_db *db, long counts[GP_JOB_NSTATUS]);
    int (*healthy)(gp_db *db);
    int (*write_state)(gp_store *store);
    int (*broken)(const gp_db *db);
    /* A store shared by nodes (NULL for one that is not): gp_store_configure and
     * gp_store_watch. */
    int (*configure)(gp_store *store, const gp_store_options *options);
    int (*watch)(gp_store *store, const gp_store_events *events, double seconds);
    const char *(*node)(gp_store *store);
    int (*secret)(gp_store *store, const char *name, void *out, size_t len);
};

extern const gp_store_ops gp_store_sqlite_ops;
extern const gp_store_ops gp_store_pg_ops;

/* The backends' openers (gp_store_open picks one by the location's form). */
int gp_store_sqlite_open(const char *path, gp_store **out, char *why, size_t why_size);
int gp_store_pg_open(const char *uri, gp_store **out, char *why, size_t why_size);

/* Decodes the summary sections refs[0..n) of job `id` (read whole through read_chunk)
 * into res->summary (a 2D result's; other tags are skipped), keeps each as stored in
 * res->raw, and notes in res->mesh_quality whether the mesh's qualities are stored (its
 * "mesh" section's version says so: a result stored before has none). Returns 0,
 * GP_SRV_ENOTFOUND (a section is missing, or none: the job was deleted meanwhile),
 * GP_SRV_EDB (a section that cannot be decoded: logged) or
 * GP_ENOMEM. */
int gp_store_decode_summary(gp_db *db, const char *id, const gp_section_ref *refs, size_t n,
                            gp_stored_result *res);

/* The connections a store has open (each backend's own type, as void *): closed with it. */
typedef struct gp_store_conns {
    void **items;
    size_t n, cap;
} gp_store_conns;

/* Adds a connection (GP_ENOMEM when it cannot), removes one (no-op when absent). The
 * caller holds the store's lock. */
int gp_store_conns_add(gp_store_conns *c, void *db);
void gp_store_conns_remove(gp_store_conns *c, void *db);

/* A new accepted job's fields (id, times, message, status, has_mesh), before its insert. */
void gp_store_new_job(gp_job *out, const gp_job_columns *columns);

/* Cuts a successful job's result into sections (core/sections.h) and writes each with
 * write(ctx, id, section), stopping at the first failure. Returns 0, GP_ENOMEM or what
 * write returned. */
int gp_store_write_sections(const char *id, const gp_result *result,
                            int (*write)(void *ctx, const char *id, const gp_section *sec),
                            void *ctx);

/* Fills buf with len bytes from the kernel's random source. */
void gp_store_random_bytes(void *buf, size_t len);

/* A new random (version 4) UUID for a job: ids must not be guessable from one another. */
void gp_store_new_job_id(char out[GP_JOB_ID_SIZE]);

/* A new random version of a job's stored result: 32 hex digits and a NUL. */
void gp_store_new_result_version(char out[33]);

/* The message of a job that was running when the daemon stopped, queued again (at
 * shutdown, or at the next start after a crash). No quote in it: it is put in SQL. */
#define GP_REQUEUE_MESSAGE "queued again: the daemon stopped while it ran"

#endif
