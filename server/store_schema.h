/* store_schema.h - the database schema as a list of migrations: migration i brings
 * PRAGMA user_version from i to i + 1, with its SQL and, where data must be rewritten, a
 * conversion in C. Append, never edit a released one. */
#ifndef GRAINPACKD_STORE_SCHEMA_H
#define GRAINPACKD_STORE_SCHEMA_H

#include <stddef.h>

typedef struct gp_db gp_db;

extern const char *const gp_store_migrations[];
extern const size_t gp_store_migration_count;

/* What migration i does besides its SQL, in the same transaction, or NULL. Returns 0 or
 * a negative code with a reason in why. */
extern int (*const gp_store_conversions[])(gp_db *db, char *why, size_t why_size);

/* Version 2 -> 3: every successful job's disks become sections (store_upgrade.c). */
int gp_store_upgrade_v3(gp_db *db, char *why, size_t why_size);

#endif
