/* store_pg_schema.h - the PostgreSQL store's migrations (store_pg_schema.c): the SQL that
 * brings version i - 1 to i is gp_pg_migrations[i - 1]; a new database starts at
 * gp_pg_first_version. Append, never edit a released one. */
#ifndef GRAINPACKD_STORE_PG_SCHEMA_H
#define GRAINPACKD_STORE_PG_SCHEMA_H

#include <stddef.h>

extern const char *const gp_pg_migrations[];
extern const int gp_pg_first_version;
extern const size_t gp_pg_migration_count;

#endif
