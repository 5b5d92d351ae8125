/* store.h - the job store: jobs, their results and statistics. Two backends behind these
 * functions, which the HTTP side and the workers call without knowing which: sqlite3 (one
 * database file, readable with the sqlite3 shell; WAL mode, writes in BEGIN IMMEDIATE,
 * schema versioned by PRAGMA user_version; one node) and PostgreSQL through libpq (any
 * number of nodes share its queue, results and limits; see gp_store_watch). A connection
 * per thread (gp_db).
 *
 * Locking: each gp_db is used by one thread at a time (acquire/release); the store's own
 * mutex only guards its free list of connections. */
#ifndef GRAINPACKD_STORE_H
#define GRAINPACKD_STORE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "sections.h"

/* Service error codes, next to the engine's GP_E... codes (all negative). */
enum {
    GP_SRV_ENOTFOUND = -100, /* no such job (or no job to claim) */
    GP_SRV_ESTATE = -101,    /* the job is not in the state the operation needs */
    GP_SRV_EDB = -102,       /* sqlite failed; the log has its message */
    GP_SRV_EFULL = -103,     /* the disk (or the file size limit) is full: nothing was written */
    GP_SRV_EUNWRITABLE = -104, /* the database cannot be written (a read-only file or file
                                  system, or a write error): nothing was written */
    GP_SRV_ELIMIT = -105     /* the owner has as many active jobs as allowed */
};

/* A short constant English text for a service or engine code, for users and logs (never
 * the number): "the database failed", ..., gp_strerror's text for the engine's codes. */
const char *gp_srv_strerror(int code);

/* The schema version this build migrates to (PRAGMA user_version). */
#define GP_STORE_SCHEMA_VERSION 3

typedef enum gp_job_status {
    GP_JOB_ACCEPTED = 0,
    GP_JOB_RUNNING,
    GP_JOB_SUCCESSFUL,
    GP_JOB_FAILED,
    GP_JOB_DISMISSED,
    GP_JOB_NSTATUS
} gp_job_status;

const char *gp_job_status_name(gp_job_status status);
/* Maps a name to a status; returns 0 or GP_EINVAL. */
int gp_job_status_parse(const char *name, gp_job_status *out);
static inline int gp_job_status_final(gp_job_status s)
{
    return s == GP_JOB_SUCCESSFUL || s == GP_JOB_FAILED || s == GP_JOB_DISMISSED;
}

#define GP_JOB_ID_SIZE 37 /* a UUID and its NUL */

/* A job's status as the API shows it. Empty timestamps are not set yet. */
typedef struct gp_job {
    int64_t seq; /* submission order, the list cursor */
    char id[GP_JOB_ID_SIZE];
    gp_job_status status;
    char created[32], started[32], finished[32], updated[32];
    int progress; /* 0-100 */
    char message[256];
    int has_mesh; /* the spec asks for its process's extra geometry: pack2d a mesh (msh, inp),
                     pack3d polyhedra (tess); the status links list those formats */
    char process[16]; /* the process the spec is for: "pack3d" when its domain has a depth,
                         else "pack2d" (read from the stored spec, as processes.c tells it) */
} gp_job;

typedef struct gp_store gp_store;
typedef struct gp_db gp_db;

/* Opens (creating if needed) the database at `location` and migrates it to the current
 * schema: a PostgreSQL connection URI (postgresql://... or postgres://..., the password
 * from the environment's PGPASSWORD or a .pgpass file) or else a sqlite file's path.
 * On failure returns GP_SRV_EDB or GP_ENOMEM with a reason in why (never a password). The
 * caller owns *out (gp_store_close). */
int gp_store_open(const char *location, gp_store **out, char *why, size_t why_size);

/* Whether location names a PostgreSQL database rather than a sqlite file. */
int gp_store_location_is_pg(const char *location);

/* location for a log: a URI's password, if it holds one, replaced by "***". */
void gp_store_redact(const char *location, char *out, size_t size);

/* The backend's name, "sqlite" or "postgresql" (for /health and the log). */
const char *gp_store_kind(gp_store *store);

/* How a node takes part in a store shared by nodes (PostgreSQL; sqlite ignores them). */
typedef struct gp_store_options {
    const char *node;     /* the node's name for people (/health, the jobs' rows) */
    double lease_seconds; /* a claim lasts that long unless renewed (gp_store_watch) */
    int max_attempts;     /* a job whose node died that many times fails instead */
} gp_store_options;

/* Sets the options before the first claim. Returns 0 or GP_ENOMEM. */
int gp_store_configure(gp_store *store, const gp_store_options *options);

/* The node's identity in the store: its name and what tells this run of it from others
 * (the name alone for sqlite). Owned by the store. */
const char *gp_store_node(gp_store *store);

/* What gp_store_watch tells its caller; any callback may be NULL. Called on the watching
 * thread. */
typedef struct gp_store_events {
    void *ctx;
    void (*queued)(void *ctx);                   /* a job was queued, on some node */
    void (*finished)(void *ctx, const char *id); /* a job reached a final status */
    void (*lost)(void *ctx, const char *id);     /* a job this node runs is no longer its
                                                    (dismissed on another node): stop it */
    void (*waiting)(void *ctx, long accepted);   /* the jobs waiting, all nodes counted */
} gp_store_events;

/* The secret `name` of len bytes every node of a shared store uses (made by the first node
 * that asks, from the kernel's random source). Returns 0 with out filled, GP_SRV_ENOTFOUND
 * for a store that is not shared (the caller draws its own), or GP_SRV_EDB. */
int gp_store_secret(gp_store *store, const char *name, void *out, size_t len);

/* Whether several nodes may share the store: then one thread calls gp_store_watch again
 * and again while the daemon runs. */
int gp_store_shared(gp_store *store);

/* For a shared store: waits up to `seconds` for the other nodes' news (jobs queued or
 * finished) and reports it; renews the leases of the jobs this node runs (reporting
 * those that are not its any more), and queues again the jobs of nodes whose leases
 * expired, when those are due. Returns 0 or GP_SRV_EDB (the next call connects again).
 * 0 at once for a store that is not shared. */
int gp_store_watch(gp_store *store, const gp_store_events *events, double seconds);

/* At start, the jobs a previous run left running (it died: a crash, a kill, a stop that
 * gave up on a worker): those started max_attempts times or more (their claims; a clean
 * stop gives its claim back) fail with a message that says why (*given_up counts them),
 * the others are queued again (*requeued). Returns 0 or a write failure. */
int gp_store_recover(gp_db *db, int max_attempts, int *requeued, int *given_up);

/* Closes every connection. All gp_db must have been released. */
void gp_store_close(gp_store *store);

/* A connection for the calling thread, opened on first need; NULL when sqlite cannot
 * open one. `durable` connections commit with synchronous=FULL (the HTTP side: a 201 is
 * only sent for a job on disk); others with NORMAL (workers: a completion lost on power
 * failure only makes the job run again). Give it back with gp_store_release. */
gp_db *gp_store_acquire(gp_store *store, int durable);
void gp_store_release(gp_store *store, gp_db *db);

/* Write failures: every function that writes returns GP_SRV_EFULL when sqlite could not
 * write for lack of space, GP_SRV_EUNWRITABLE when the files refused the write (read-only,
 * or an I/O error on writing), GP_SRV_EDB for any other failure; the transaction is then
 * rolled back, so nothing half-written stays.
 *
 * Owners: functions taking `owner` see only that owner's jobs ("" is the owner of jobs
 * submitted without a key); NULL sees every job (an admin, or a daemon without keys).
 * A job of another owner is GP_SRV_ENOTFOUND, as if it did not exist. */

/* Inserts an accepted job of `owner` (never NULL) with a new id; the spec text is kept
 * as submitted and its summary (domain, law, seed...) in columns. When max_active > 0
 * and the owner already has that many accepted or running jobs, nothing is inserted and
 * GP_SRV_ELIMIT is returned (the count is in *active, which may be NULL); the count and
 * the insert are one transaction, so concurrent submissions cannot overshoot. Returns 0
 * with *out filled, GP_SRV_ELIMIT, or a write failure. */
int gp_store_insert_job(gp_db *db, const char *owner, size_t max_active, const char *spec_text,
                        size_t spec_len, const gp_spec *spec, gp_job *out, long *active);

/* What a job's row keeps of its spec, in columns (for people querying the database): its
 * process fills it (server/processes.h). The strings are static names. */
typedef struct gp_job_columns {
    const char *process;      /* its id, "pack2d" or "pack3d" (not stored: the spec tells it) */
    double width, height;     /* the domain's first two sides (a 3D box's depth is in the spec) */
    const char *distribution; /* the law's kind */
    const char *joint;        /* the joint law */
    int level_band;
    uint64_t seed;
    double expected;          /* grains expected (disks or spheres) */
    int has_mesh;             /* as gp_job's: a 2D mesh, or 3D polyhedra, asked for */
} gp_job_columns;

/* The columns of a 2D spec. */
void gp_job_columns_of_spec(const gp_spec *spec, gp_job_columns *out);

/* gp_store_insert_job for any process: the summary columns given as they are. */
int gp_store_insert_job_columns(gp_db *db, const char *owner, size_t max_active,
                                const char *spec_text, size_t spec_len,
                                const gp_job_columns *columns, gp_job *out, long *active);

/* Reads a job's status. Returns 0, GP_SRV_ENOTFOUND or GP_SRV_EDB. */
int gp_store_get_job(gp_db *db, const char *id, const char *owner, gp_job *out);

/* Lists jobs newest first: those with seq < before (0: from the newest), of the statuses
 * whose bit (1 << status) is set in status_mask (0: all), at most `limit`. Writes the jobs
 * into out (room for limit) and their number into *n; *more is 1 when further jobs
 * match. Returns 0 or GP_SRV_EDB. */
int gp_store_list_jobs(gp_db *db, const char *owner, unsigned status_mask, int64_t before,
                       size_t limit, gp_job *out, size_t *n, int *more);

/* Claims the oldest accepted job atomically (UPDATE ... RETURNING): it becomes running.
 * *queued (the caller's count of accepted jobs; may be NULL) is decremented before the
 * claim commits and given back if the commit fails, so that whoever sees the job running
 * sees it out of the queue (the --max-queued admission reads that count). Returns 0
 * with the id and a malloc'd copy of its spec text (caller frees), or GP_SRV_ENOTFOUND
 * when none waits, or GP_SRV_EDB. */
int gp_store_claim(gp_db *db, atomic_long *queued, char id[GP_JOB_ID_SIZE], char **spec_text,
                   size_t *spec_len);

/* Records the progress of a running job (no-op when it is no longer running). */
int gp_store_progress(gp_db *db, const char *id, int percent, const char *message);

/* Stores a successful job's result (disks as a blob, summary figures as columns, one
 * statistics row per bin, stage timings) and marks it successful, in one transaction.
 * Returns 0, GP_SRV_ESTATE when the job is no longer running (dismissed meanwhile:
 * nothing is written) or GP_SRV_EDB. */
int gp_store_finish(gp_db *db, const char *id, const gp_result *result);

/* What any process's successful run leaves in the store, borrowed for the call: its
 * sections (core/sections.h), the statistics of its grains against the law (the columns
 * and the per-bin rows), the front's counters (columns; 0 where the process has none),
 * the noun of its grains for the job's message ("disks", "spheres") and its timings. */
typedef struct gp_outcome {
    const gp_section *sections;
    size_t nsections;
    const gp_pack_stats *stats;
    uint64_t initial_front, attempts, closures, frozen, capped;
    uint32_t max_level;
    const char *noun;
    const gp_stage_time *timings;
    int ntimings;
} gp_outcome;

/* gp_store_finish for any process: the outcome as given. */
int gp_store_finish_outcome(gp_db *db, const char *id, const gp_outcome *outcome);

/* The outcome of a 2D result: its sections cut into sections[GP_SECTIONS_MAX] (*n of them,
 * borrowing from `result`; free with gp_sections_free). Returns 0 or gp_sections_from_result's code. */
int gp_outcome_of_result(const gp_result *result, gp_section *sections, size_t *n,
                         gp_outcome *out);

/* Marks a running job failed with a reason. Returns 0, GP_SRV_ESTATE or GP_SRV_EDB. */
int gp_store_fail(gp_db *db, const char *id, const char *code_name, const char *message);

/* Puts a running job back in the queue (daemon shutting down). 0, GP_SRV_ESTATE, EDB. */
int gp_store_requeue(gp_db *db, const char *id);

/* DELETE /jobs/{id}: an accepted or running job becomes dismissed (*deleted = 0); a
 * finished one (successful, failed, dismissed) is deleted with its results (*deleted =
 * 1). *before gets the status the job had. Returns 0, GP_SRV_ENOTFOUND or a write
 * failure. */
int gp_store_dismiss(gp_db *db, const char *id, const char *owner, gp_job_status *before,
                     int *deleted, gp_job *after);

/* A successful job's stored result, opened for rendering: its spec, its summary (the
 * statistics and every figure but the per-grain arrays, which gp_result_reader reads piece
 * by piece), and what identifies its stored bytes. */
typedef struct gp_stored_result {
    int64_t key;            /* the store's own handle of the result, for gp_result_reader */
    char *spec_text;        /* owned, NUL-terminated: the spec as submitted */
    size_t spec_len;
    gp_result summary;      /* owned (gp_result_free): per-grain arrays NULL; a 2D result's
                               summary, zero for another process's */
    gp_section raw[GP_SECTIONS_MAX]; /* the summary sections as stored (bytes owned), for
                                        a process that decodes its own (processes.h) */
    size_t nraw;
    char version[40];       /* changes whenever the stored bytes could (a strong ETag's root) */
    int mesh_quality;       /* the mesh's qualities are stored (sections.h: "mesh" version 2) */
} gp_stored_result;

/* Opens the result of a successful job of `owner`: reads the spec and the summary
 * sections. Returns 0 with *out filled (free with gp_stored_result_free), GP_SRV_ENOTFOUND
 * (no such job, not successful, or deleted meanwhile), GP_SRV_EDB (also for a result whose
 * sections cannot be decoded: logged) or GP_ENOMEM. */
int gp_store_open_result(gp_db *db, const char *id, const char *owner, gp_stored_result *out);
void gp_stored_result_free(gp_stored_result *r);

/* Reading the per-grain sections of one opened result, piece by piece, for one download.
 * Every read is its own short read transaction: a slow client holds none between two
 * pieces, so WAL checkpoints go on. The reader keeps the last chunk it read of each
 * section (GP_STORE_CHUNK bytes at most each), so the small reads of a writer's windows
 * cost one query per chunk. */
typedef struct gp_result_reader gp_result_reader;

/* The size of the pieces a result's sections are stored in. Why this value: large enough
 * that a 10^6-grain result is some 2500 rows (one query each when read in order), small
 * enough that a reader's cache of one chunk per section stays a few hundred kilobytes. */
#define GP_STORE_CHUNK ((size_t)64 * 1024)

/* A reader of the result `key` (gp_stored_result.key); NULL when out of memory. */
gp_result_reader *gp_result_reader_new(int64_t key);

/* Reads `len` bytes of section `tag` from `offset` into dst through db (a connection the
 * caller holds for the call). Returns 0, GP_SRV_ENOTFOUND (the result was deleted
 * meanwhile, or the section is shorter), GP_SRV_EDB or GP_ENOMEM. */
int gp_result_reader_read(gp_result_reader *r, gp_db *db, const char *tag, uint64_t offset,
                          void *dst, size_t len);
void gp_result_reader_free(gp_result_reader *r);

/* The stage timings of a job, in the order the stages ran (at most cap; stage names are
 * copied into names[i], 32 bytes each). Returns the count or a negative code. */
int gp_store_load_timings(gp_db *db, const char *id, char names[][32], double *seconds, int cap);

/* Counts jobs by status (counts has GP_JOB_NSTATUS entries). Returns 0 or GP_SRV_EDB. */
int gp_store_count(gp_db *db, long counts[GP_JOB_NSTATUS]);

/* Whether the database answers a query (for /health; cheap enough to poll). */
int gp_store_healthy(gp_db *db);

/* How the last write went: 0 (it succeeded, or none failed yet), GP_SRV_EFULL or
 * GP_SRV_EUNWRITABLE. Any successful write sets it back to 0. */
int gp_store_write_state(gp_store *store);

/* Whether the connection should not be used again: it hit an I/O or permission error,
 * or writes started failing or working again since it was opened. A worker holding a
 * connection for long then gives it back (gp_store_release closes it) and takes a fresh
 * one, which sees the files as they are now (writable again, say). */
int gp_store_broken(const gp_db *db);

#endif
