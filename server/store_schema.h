/* store_schema.h - the database schema as a list of migrations: migration i brings
 * PRAGMA user_version from i to i + 1. Append, never edit a released one. */
#ifndef GRAINPACKD_STORE_SCHEMA_H
#define GRAINPACKD_STORE_SCHEMA_H

#include <stddef.h>

extern const char *const gp_store_migrations[];
extern const size_t gp_store_migration_count;

#endif
