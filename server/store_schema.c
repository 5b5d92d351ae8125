/* store_schema.c - the SQL of each schema migration (see store_schema.h). The tables are
 * meant to be queried by hand: `sqlite3 grainpack.db "select ..."`. */
#include "store_schema.h"

static const char migration_1[] =
    /* One row per job. Summary figures are columns so that past jobs can be compared
     * with plain SQL; they are NULL until the job succeeds. */
    "CREATE TABLE jobs ("
    "  seq INTEGER PRIMARY KEY AUTOINCREMENT," /* submission order; never reused */
    "  id TEXT NOT NULL UNIQUE,"               /* the jobID (UUID) */
    "  status TEXT NOT NULL CHECK (status IN"
    "    ('accepted','running','successful','failed','dismissed')),"
    "  created TEXT NOT NULL, started TEXT, finished TEXT, updated TEXT NOT NULL," /* RFC 3339 UTC */
    "  progress INTEGER NOT NULL DEFAULT 0,"
    "  message TEXT NOT NULL DEFAULT '',"
    "  claims INTEGER NOT NULL DEFAULT 0," /* times a worker took it: > 1 after a requeue */
    "  error TEXT,"                        /* failed jobs: the engine's error name */
    "  spec TEXT NOT NULL,"                /* the request body as submitted */
    "  domain_width REAL NOT NULL, domain_height REAL NOT NULL,"
    "  distribution TEXT NOT NULL, joint TEXT NOT NULL, level_band INTEGER NOT NULL,"
    "  seed INTEGER NOT NULL, expected_disks REAL NOT NULL,"
    "  count INTEGER, packing_density REAL, grain_fraction REAL,"
    "  r_min REAL, r_max REAL, r_mean REAL,"
    "  chi2 REAL, dof INTEGER, p_value REAL, max_abs_z REAL,"
    "  initial_disks INTEGER, front_attempts INTEGER, front_closures INTEGER,"
    "  front_frozen INTEGER, front_capped INTEGER, max_level INTEGER);"
    "CREATE INDEX jobs_by_status ON jobs (status, seq);"
    /* The disks of a successful job, from which every format is rendered on request:
     * `count` records of four little-endian float64 (x, y, r, R), 32 bytes per disk. */
    "CREATE TABLE results ("
    "  job_id TEXT PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,"
    "  count INTEGER NOT NULL,"
    "  disks BLOB NOT NULL);"
    /* Achieved versus target distribution, one row per bin. */
    "CREATE TABLE bin_stats ("
    "  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    "  bin INTEGER NOT NULL,"
    "  min REAL NOT NULL, max REAL NOT NULL, target REAL NOT NULL, achieved REAL NOT NULL,"
    "  count INTEGER NOT NULL, z REAL NOT NULL,"
    "  PRIMARY KEY (job_id, bin)) WITHOUT ROWID;"
    /* Wall-clock seconds per pipeline stage, in the order they ran. */
    "CREATE TABLE stage_timings ("
    "  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    "  position INTEGER NOT NULL,"
    "  stage TEXT NOT NULL,"
    "  seconds REAL NOT NULL,"
    "  PRIMARY KEY (job_id, position)) WITHOUT ROWID;";

/* Version 2: every job belongs to the API key (its user name) that submitted it. Jobs of
 * version 1, and every job of a daemon running without a key file, have the owner ''
 * (only an admin key sees them once keys are in use). The index serves the per-key
 * limit (accepted and running jobs of one owner) and the owner's job list. */
static const char migration_2[] =
    "ALTER TABLE jobs ADD COLUMN owner TEXT NOT NULL DEFAULT '';"
    "CREATE INDEX jobs_by_owner ON jobs (owner, status, seq);";

/* Version 3: a result is what every stage produced, as tagged binary sections
 * (grainpack/sections.h: the packing's statistics, the disks, the balancing run and F, the
 * cells and their statistics; a mesh stage adds its own tags), each cut in chunks of
 * GP_STORE_CHUNK bytes so that a download reads it piece by piece, one short query per
 * chunk. A download renders these; nothing is derived again. `summary` marks the small
 * sections a result's statistics are decoded from. result_version changes whenever a
 * job's stored result is written (the root of its downloads' ETags). Version 2's
 * `results` (the disks alone) is converted by store_upgrade.c, then dropped. */
static const char migration_3[] =
    "CREATE TABLE result_sections ("
    "  id INTEGER PRIMARY KEY AUTOINCREMENT," /* never reused: a reader's handle stays true */
    "  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    "  tag TEXT NOT NULL,"                     /* 'disks', 'F', 'cell_xy', ... */
    "  version INTEGER NOT NULL,"              /* of the section's layout */
    "  bytes INTEGER NOT NULL,"
    "  summary INTEGER NOT NULL,"
    "  UNIQUE (job_id, tag));"
    "CREATE TABLE result_chunks ("
    "  section INTEGER NOT NULL REFERENCES result_sections (id) ON DELETE CASCADE,"
    "  chunk INTEGER NOT NULL,"                /* bytes chunk * GP_STORE_CHUNK onwards */
    "  data BLOB NOT NULL,"
    "  PRIMARY KEY (section, chunk));"
    "ALTER TABLE jobs ADD COLUMN result_version TEXT;";

const char *const gp_store_migrations[] = {migration_1, migration_2, migration_3};
int (*const gp_store_conversions[])(gp_db *db, char *why, size_t why_size) = {NULL, NULL,
                                                                             gp_store_upgrade_v3};
const size_t gp_store_migration_count = sizeof gp_store_migrations / sizeof gp_store_migrations[0];
