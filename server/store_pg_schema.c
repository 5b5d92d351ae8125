/* store_pg_schema.c - the PostgreSQL store's schema, versioned with the same numbers as
 * sqlite's (store_schema.c; the version in the one-row table grainpack_schema). The
 * PostgreSQL store came with version 3: a new database is created at 3 at once, as
 * sqlite's migrations 1 to 3 would leave it, plus what nodes sharing a queue need. A
 * later version appends a migration to both lists. */
#include "store_pg_schema.h"

static const char schema_v3[] =
    "CREATE TABLE jobs ("
    "  seq bigserial PRIMARY KEY," /* submission order; never reused */
    "  id text NOT NULL UNIQUE,"   /* the jobID (UUID) */
    "  status text NOT NULL CHECK (status IN"
    "    ('accepted','running','successful','failed','dismissed')),"
    "  created text NOT NULL, started text, finished text, updated text NOT NULL," /* RFC 3339 */
    "  progress integer NOT NULL DEFAULT 0,"
    "  message text NOT NULL DEFAULT '',"
    "  claims integer NOT NULL DEFAULT 0," /* times a node took it: > 1 after a requeue */
    "  error text,"
    "  spec text NOT NULL,"
    "  has_mesh boolean NOT NULL DEFAULT false," /* the spec asks for a 2D mesh or 3D polyhedra */
    "  domain_width double precision NOT NULL, domain_height double precision NOT NULL,"
    "  distribution text NOT NULL, joint text NOT NULL, level_band integer NOT NULL,"
    "  seed bigint NOT NULL, expected_disks double precision NOT NULL,"
    "  count bigint, packing_density double precision, grain_fraction double precision,"
    "  r_min double precision, r_max double precision, r_mean double precision,"
    "  chi2 double precision, dof integer, p_value double precision,"
    "  max_abs_z double precision,"
    "  initial_disks bigint, front_attempts bigint, front_closures bigint,"
    "  front_frozen bigint, front_capped bigint, max_level bigint,"
    "  owner text NOT NULL DEFAULT '',"
    "  result_version text,"
    /* the run of a node that holds a running job, and until when unless it renews */
    "  node text, lease_until timestamptz);"
    "CREATE INDEX jobs_by_status ON jobs (status, seq);"
    "CREATE INDEX jobs_by_owner ON jobs (owner, status, seq);"
    "CREATE INDEX jobs_by_node ON jobs (node) WHERE node IS NOT NULL;"
    "CREATE TABLE bin_stats ("
    "  job_id text NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    "  bin integer NOT NULL,"
    "  min double precision NOT NULL, max double precision NOT NULL,"
    "  target double precision NOT NULL, achieved double precision NOT NULL,"
    "  count bigint NOT NULL, z double precision,"
    "  PRIMARY KEY (job_id, bin));"
    "CREATE TABLE stage_timings ("
    "  job_id text NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    "  position integer NOT NULL, stage text NOT NULL, seconds double precision NOT NULL,"
    "  PRIMARY KEY (job_id, position));"
    "CREATE TABLE result_sections ("
    "  id bigserial PRIMARY KEY,"
    "  job_id text NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,"
    "  tag text NOT NULL, version integer NOT NULL, bytes bigint NOT NULL,"
    "  summary boolean NOT NULL,"
    "  UNIQUE (job_id, tag));"
    /* chunks of GP_STORE_CHUNK bytes: stored as they are (no TOAST compression, which the
     * float64 records would not repay) */
    "CREATE TABLE result_chunks ("
    "  section bigint NOT NULL REFERENCES result_sections (id) ON DELETE CASCADE,"
    "  chunk bigint NOT NULL, data bytea NOT NULL,"
    "  PRIMARY KEY (section, chunk));"
    "ALTER TABLE result_chunks ALTER COLUMN data SET STORAGE EXTERNAL;"
    /* secrets every node must share: the keys of GET /jobs's page cursors (cursor.h), so
     * that a listing's next page can be asked of any node */
    "CREATE TABLE grainpack_secrets (name text PRIMARY KEY, value bytea NOT NULL);";

/* version i's SQL at index i - 1; NULL: a version this store begins after */
const char *const gp_pg_migrations[] = {NULL, NULL, schema_v3};
const int gp_pg_first_version = 3;
const size_t gp_pg_migration_count = sizeof gp_pg_migrations / sizeof gp_pg_migrations[0];
