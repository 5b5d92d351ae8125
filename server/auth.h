/* auth.h - API keys: the key file (one key a line, stored as its SHA-256 with a user name
 * and a role), read at start-up and again on SIGHUP, and the check of an
 * `Authorization: Bearer KEY` header against it.
 *
 * Key file lines:  sha256:<64 hex digits> <user> <role>    ('#' starts a comment)
 * The user name (letters, digits, '.', '_', '-'; at most 63) is unique in the file and is
 * who owns the jobs the key submits: replacing a user's line with a new hash (and SIGHUP)
 * rotates the key and keeps the jobs. Roles: `user` (its own jobs) and `admin` (every
 * job, and /metrics). Keys are random secrets (README: a command makes one), so one
 * SHA-256 is enough: there is no password to guess from the hash.
 *
 * Locking: a read-write lock guards the table; a reload parses the file first and swaps
 * the table in only if the whole file is valid, so a bad edit keeps the old keys. */
#ifndef GRAINPACKD_AUTH_H
#define GRAINPACKD_AUTH_H

#include <stddef.h>

#define GP_USER_SIZE 64
/* The longest key accepted in a header: generated keys have 43 characters. */
#define GP_KEY_MAX 512

typedef enum gp_role { GP_ROLE_USER = 0, GP_ROLE_ADMIN = 1 } gp_role;

typedef struct gp_identity {
    char user[GP_USER_SIZE];
    gp_role role;
} gp_identity;

/* Outcome of checking an Authorization header. */
typedef enum gp_auth_result {
    GP_AUTH_OK = 0,
    GP_AUTH_MISSING,   /* no Authorization header */
    GP_AUTH_MALFORMED, /* not "Bearer KEY" with a key of token characters */
    GP_AUTH_UNKNOWN    /* a well-formed key that is not in the file (or was revoked) */
} gp_auth_result;

typedef struct gp_keyring gp_keyring;

/* Reads the key file at path. Returns 0 with *out (caller frees with gp_keyring_free),
 * or GP_EIO (cannot read), GP_EINVAL (a bad line: why names its number and the fault) or
 * GP_ENOMEM, with a reason in why. A file without any key is valid (nobody gets in). */
int gp_keyring_load(const char *path, gp_keyring **out, char *why, size_t why_size);

/* Reads the same file again. On success the new keys replace the old at once (requests
 * in flight finish with the identity they had) and 0 is returned; on failure the old
 * keys stay and the error is returned as by gp_keyring_load. */
int gp_keyring_reload(gp_keyring *k, char *why, size_t why_size);

/* Number of keys. */
size_t gp_keyring_count(gp_keyring *k);

/* Checks an Authorization header value (NULL when absent). GP_AUTH_OK fills *who. The
 * key's hash is compared with every stored hash in constant time. */
gp_auth_result gp_keyring_authenticate(gp_keyring *k, const char *authorization, gp_identity *who);

const char *gp_role_name(gp_role role);

void gp_keyring_free(gp_keyring *k);

#endif
