/* auth.c - the key file and the Bearer check (see auth.h). SHA-256 and the constant-time
 * comparison come from Debian's nettle. */
#include "auth.h"

#include <errno.h>
#include <nettle/memops.h>
#include <nettle/sha2.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "grainpack/error.h"

#define HASH_PREFIX "sha256:"
/* The longest line read; a valid one has about 140 characters. */
#define LINE_MAX_CHARS 1024

typedef struct key_entry {
    unsigned char digest[SHA256_DIGEST_SIZE];
    gp_identity who;
} key_entry;

struct gp_keyring {
    char *path;
    pthread_rwlock_t lock; /* guards keys and n */
    key_entry *keys;
    size_t n;
};

const char *gp_role_name(gp_role role)
{
    return role == GP_ROLE_ADMIN ? "admin" : "user";
}

static int hex_value(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

static int user_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           c == '.' || c == '_' || c == '-';
}

/* Splits the next whitespace-separated word off *p; NULL at the end of the line. */
static char *next_word(char **p)
{
    char *s = *p;
    while (*s == ' ' || *s == '\t')
        s++;
    if (!*s)
        return NULL;
    char *end = s;
    while (*end && *end != ' ' && *end != '\t')
        end++;
    if (*end)
        *end++ = '\0';
    *p = end;
    return s;
}

/* Parses one non-blank, non-comment line into e. Returns 0 or -1 with the fault in why. */
static int parse_line(char *line, key_entry *e, char *why, size_t why_size)
{
    char *p = line, *hash = next_word(&p), *user = next_word(&p), *role = next_word(&p);
    if (!hash || !user || !role || next_word(&p)) {
        snprintf(why, why_size, "expected 'sha256:HEX USER ROLE' (three words)");
        return -1;
    }
    size_t plen = strlen(HASH_PREFIX);
    if (strncmp(hash, HASH_PREFIX, plen) != 0 || strlen(hash + plen) != 2 * SHA256_DIGEST_SIZE) {
        snprintf(why, why_size, "the hash must be 'sha256:' and 64 hex digits (the SHA-256 of "
                                "the key, not the key itself)");
        return -1;
    }
    for (size_t i = 0; i < SHA256_DIGEST_SIZE; i++) {
        int hi = hex_value(hash[plen + 2 * i]), lo = hex_value(hash[plen + 2 * i + 1]);
        if (hi < 0 || lo < 0) {
            snprintf(why, why_size, "the hash has a character that is not a hex digit");
            return -1;
        }
        e->digest[i] = (unsigned char)(hi * 16 + lo);
    }
    size_t ulen = strlen(user);
    for (size_t i = 0; i < ulen; i++) {
        if (!user_char(user[i])) {
            snprintf(why, why_size, "the user name may hold letters, digits, '.', '_' and '-' only");
            return -1;
        }
    }
    if (ulen >= GP_USER_SIZE) {
        snprintf(why, why_size, "the user name is longer than %d characters", GP_USER_SIZE - 1);
        return -1;
    }
    memcpy(e->who.user, user, ulen + 1);
    if (strcmp(role, "user") == 0) {
        e->who.role = GP_ROLE_USER;
    } else if (strcmp(role, "admin") == 0) {
        e->who.role = GP_ROLE_ADMIN;
    } else {
        snprintf(why, why_size, "unknown role '%.32s' (user or admin)", role);
        return -1;
    }
    return 0;
}

/* Reads path into a new table. Returns 0, GP_EIO, GP_EINVAL or GP_ENOMEM. */
static int read_keys(const char *path, key_entry **out, size_t *count, char *why, size_t why_size)
{
    *out = NULL;
    *count = 0;
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(why, why_size, "cannot read the key file %s: %s", path, strerror(errno));
        return GP_EIO;
    }
    key_entry *keys = NULL;
    size_t n = 0, cap = 0;
    char line[LINE_MAX_CHARS + 2], fault[160];
    int rc = 0, number = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        number++;
        size_t len = strlen(line);
        if (len > LINE_MAX_CHARS) {
            snprintf(why, why_size, "%s:%d: line longer than %d characters", path, number,
                     LINE_MAX_CHARS);
            rc = GP_EINVAL;
            break;
        }
        while (len && (line[len - 1] == '\n' || line[len - 1] == '\r'))
            line[--len] = '\0';
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        if (line[strspn(line, " \t")] == '\0')
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            key_entry *grown = realloc(keys, cap * sizeof *grown);
            if (!grown) {
                snprintf(why, why_size, "out of memory reading %s", path);
                rc = GP_ENOMEM;
                break;
            }
            keys = grown;
        }
        key_entry *e = &keys[n];
        memset(e, 0, sizeof *e);
        if (parse_line(line, e, fault, sizeof fault)) {
            snprintf(why, why_size, "%s:%d: %s", path, number, fault);
            rc = GP_EINVAL;
            break;
        }
        for (size_t i = 0; i < n && rc == 0; i++) {
            if (strcmp(keys[i].who.user, e->who.user) == 0 ||
                memcmp(keys[i].digest, e->digest, sizeof e->digest) == 0) {
                snprintf(why, why_size, "%s:%d: the %s of line %d again (each user has one key "
                         "line; replace it to change the key)", path, number,
                         strcmp(keys[i].who.user, e->who.user) == 0 ? "user" : "key", (int)i + 1);
                rc = GP_EINVAL;
            }
        }
        if (rc == 0)
            n++;
    }
    if (rc == 0 && ferror(f)) {
        snprintf(why, why_size, "cannot read the key file %s", path);
        rc = GP_EIO;
    }
    fclose(f);
    if (rc) {
        free(keys);
        return rc;
    }
    *out = keys;
    *count = n;
    return 0;
}

int gp_keyring_load(const char *path, gp_keyring **out, char *why, size_t why_size)
{
    *out = NULL;
    gp_keyring *k = calloc(1, sizeof *k);
    if (!k || !(k->path = strdup(path))) {
        free(k);
        snprintf(why, why_size, "out of memory");
        return GP_ENOMEM;
    }
    int rc = read_keys(path, &k->keys, &k->n, why, why_size);
    if (rc) {
        free(k->path);
        free(k);
        return rc;
    }
    pthread_rwlock_init(&k->lock, NULL);
    *out = k;
    return 0;
}

int gp_keyring_reload(gp_keyring *k, char *why, size_t why_size)
{
    key_entry *keys;
    size_t n;
    int rc = read_keys(k->path, &keys, &n, why, why_size);
    if (rc)
        return rc;
    pthread_rwlock_wrlock(&k->lock);
    key_entry *old = k->keys;
    k->keys = keys;
    k->n = n;
    pthread_rwlock_unlock(&k->lock);
    free(old);
    return 0;
}

size_t gp_keyring_count(gp_keyring *k)
{
    pthread_rwlock_rdlock(&k->lock);
    size_t n = k->n;
    pthread_rwlock_unlock(&k->lock);
    return n;
}

/* RFC 6750's b64token: the characters a Bearer token may have. */
static int token_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           c == '-' || c == '.' || c == '_' || c == '~' || c == '+' || c == '/';
}

gp_auth_result gp_keyring_authenticate(gp_keyring *k, const char *authorization, gp_identity *who)
{
    if (!authorization)
        return GP_AUTH_MISSING;
    const char *p = authorization;
    while (*p == ' ')
        p++;
    if (strncasecmp(p, "Bearer", 6) != 0 || p[6] != ' ')
        return GP_AUTH_MALFORMED;
    p += 6;
    while (*p == ' ')
        p++;
    size_t len = 0;
    while (token_char(p[len]))
        len++;
    size_t pad = 0;
    while (p[len + pad] == '=')
        pad++;
    const char *rest = p + len + pad;
    while (*rest == ' ')
        rest++;
    if (len == 0 || len + pad > GP_KEY_MAX || *rest)
        return GP_AUTH_MALFORMED;

    unsigned char digest[SHA256_DIGEST_SIZE];
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, len + pad, (const uint8_t *)p);
    sha256_digest(&ctx, sizeof digest, digest);

    /* every entry is compared, in constant time each, so that the time taken says
     * nothing about which stored hash came close */
    size_t match = (size_t)-1;
    pthread_rwlock_rdlock(&k->lock);
    for (size_t i = 0; i < k->n; i++)
        if (memeql_sec(digest, k->keys[i].digest, sizeof digest))
            match = i;
    if (match != (size_t)-1)
        *who = k->keys[match].who;
    pthread_rwlock_unlock(&k->lock);
    return match != (size_t)-1 ? GP_AUTH_OK : GP_AUTH_UNKNOWN;
}

void gp_keyring_free(gp_keyring *k)
{
    if (!k)
        return;
    pthread_rwlock_destroy(&k->lock);
    free(k->keys);
    free(k->path);
    free(k);
}
