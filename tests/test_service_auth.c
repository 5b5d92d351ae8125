/* test_service_auth.c - grainpackd's key file and Bearer check: the file format and its
 * refusals (with the line number), the identity a key gives, the header forms refused,
 * and a reload that swaps keys in, or keeps the old ones when the new file is bad. */
#include <nettle/sha2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "auth.h"
#include "check.h"
#include "grainpack/error.h"

static char path[] = "/tmp/grainpack-keys-XXXXXX";

/* The key file line of `key`, as the README's command makes it. */
static void key_line(char *out, size_t size, const char *key, const char *user, const char *role)
{
    unsigned char d[SHA256_DIGEST_SIZE];
    struct sha256_ctx ctx;
    sha256_init(&ctx);
    sha256_update(&ctx, strlen(key), (const uint8_t *)key);
    sha256_digest(&ctx, sizeof d, d);
    size_t n = (size_t)snprintf(out, size, "sha256:");
    for (size_t i = 0; i < sizeof d; i++)
        n += (size_t)snprintf(out + n, size - n, "%02x", d[i]);
    snprintf(out + n, size - n, " %s %s", user, role);
}

static void write_file(const char *text)
{
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
}

/* A file with alice (user) and root (admin), comments and blank lines. */
static void write_two_keys(void)
{
    char a[160], r[160], text[512];
    key_line(a, sizeof a, "alice-secret-key", "alice", "user");
    key_line(r, sizeof r, "root-secret-key", "root", "admin");
    snprintf(text, sizeof text, "# grainpackd keys\n\n%s\n   %s   # the administrator\n", a, r);
    write_file(text);
}

static void test_a_key_gives_its_user_and_role(void)
{
    write_two_keys();
    gp_keyring *k;
    char why[256];
    CHECK(gp_keyring_load(path, &k, why, sizeof why) == 0);
    CHECK(gp_keyring_count(k) == 2);
    gp_identity who;
    CHECK(gp_keyring_authenticate(k, "Bearer alice-secret-key", &who) == GP_AUTH_OK);
    CHECK_STR(who.user, "alice");
    CHECK(who.role == GP_ROLE_USER);
    CHECK(gp_keyring_authenticate(k, "bearer   root-secret-key  ", &who) == GP_AUTH_OK);
    CHECK_STR(who.user, "root");
    CHECK(who.role == GP_ROLE_ADMIN);
    gp_keyring_free(k);
}

static void test_headers_that_are_not_a_known_bearer_key_are_refused(void)
{
    write_two_keys();
    gp_keyring *k;
    char why[256], longkey[GP_KEY_MAX + 20];
    CHECK(gp_keyring_load(path, &k, why, sizeof why) == 0);
    memset(longkey, 'a', sizeof longkey);
    memcpy(longkey, "Bearer ", 7);
    longkey[sizeof longkey - 1] = '\0';
    gp_identity who;
    CHECK(gp_keyring_authenticate(k, NULL, &who) == GP_AUTH_MISSING);
    const char *malformed[] = {"", "Bearer", "Bearer ", "Basic YWxpY2U6cw==",
                               "Bearer alice secret", "Bearer alice-secret-key\x01",
                               "Bearer \xc3\xa9t\xc3\xa9", "Bearertoken", longkey};
    for (size_t i = 0; i < sizeof malformed / sizeof malformed[0]; i++)
        CHECK_MSG(gp_keyring_authenticate(k, malformed[i], &who) == GP_AUTH_MALFORMED,
                  "header %zu accepted as well-formed", i);
    CHECK(gp_keyring_authenticate(k, "Bearer alice-secret-keY", &who) == GP_AUTH_UNKNOWN);
    CHECK(gp_keyring_authenticate(k, "Bearer alice-secret-ke", &who) == GP_AUTH_UNKNOWN);
    /* the stored hash itself is not a key */
    char line[160], header[200];
    key_line(line, sizeof line, "alice-secret-key", "alice", "user");
    snprintf(header, sizeof header, "Bearer %.64s", line + 7);
    CHECK(gp_keyring_authenticate(k, header, &who) == GP_AUTH_UNKNOWN);
    gp_keyring_free(k);
}

static void test_bad_files_are_refused_naming_the_line(void)
{
    char good[160];
    key_line(good, sizeof good, "k1", "alice", "user");
    struct {
        const char *tail, *says;
    } cases[] = {
        {"k1 alice user", "sha256"},
        {"sha256:abcd alice user", "64 hex"},
        {"sha256:zz5e884898da28047151d0e56f8dc6292773603d0d6aabbdd62a11ef721d1542 alice user",
         "hex digit"},
        {"sha256:5e884898da28047151d0e56f8dc6292773603d0d6aabbdd62a11ef721d1542d8 alice", "three"},
        {"sha256:5e884898da28047151d0e56f8dc6292773603d0d6aabbdd62a11ef721d1542d8 al/ice user",
         "user name"},
        {"sha256:5e884898da28047151d0e56f8dc6292773603d0d6aabbdd62a11ef721d1542d8 bob root",
         "unknown role"},
        {"sha256:5e884898da28047151d0e56f8dc6292773603d0d6aabbdd62a11ef721d1542d8 alice admin",
         "user of line 1"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[400];
        snprintf(text, sizeof text, "%s\n# comment\n%s\n", good, cases[i].tail);
        write_file(text);
        gp_keyring *k = NULL;
        char why[256] = "";
        CHECK_MSG(gp_keyring_load(path, &k, why, sizeof why) == GP_EINVAL, "case %zu loaded", i);
        CHECK_MSG(k == NULL, "case %zu", i);
        CHECK_MSG(strstr(why, ":3: ") && strstr(why, cases[i].says), "case %zu: %s", i, why);
    }
    gp_keyring *k = NULL;
    char why[256];
    CHECK(gp_keyring_load("/nonexistent/keys", &k, why, sizeof why) == GP_EIO && !k);
    CHECK(strstr(why, "/nonexistent/keys") != NULL);
}

static void test_reload_swaps_keys_or_keeps_the_old_ones(void)
{
    write_two_keys();
    gp_keyring *k;
    char why[256];
    CHECK(gp_keyring_load(path, &k, why, sizeof why) == 0);
    char line[160];
    key_line(line, sizeof line, "bob-new-key", "bob", "user");
    write_file(line);
    CHECK(gp_keyring_reload(k, why, sizeof why) == 0);
    gp_identity who;
    CHECK(gp_keyring_authenticate(k, "Bearer bob-new-key", &who) == GP_AUTH_OK);
    CHECK(gp_keyring_authenticate(k, "Bearer alice-secret-key", &who) == GP_AUTH_UNKNOWN);
    write_file("this is not a key file\n");
    CHECK(gp_keyring_reload(k, why, sizeof why) == GP_EINVAL);
    CHECK(gp_keyring_authenticate(k, "Bearer bob-new-key", &who) == GP_AUTH_OK);
    CHECK(gp_keyring_count(k) == 1);
    write_file("# nobody\n");
    CHECK(gp_keyring_reload(k, why, sizeof why) == 0);
    CHECK(gp_keyring_count(k) == 0);
    CHECK(gp_keyring_authenticate(k, "Bearer bob-new-key", &who) == GP_AUTH_UNKNOWN);
    gp_keyring_free(k);
}

int main(void)
{
    int fd = mkstemp(path);
    if (fd < 0)
        return 1;
    close(fd);
    RUN(test_a_key_gives_its_user_and_role);
    RUN(test_headers_that_are_not_a_known_bearer_key_are_refused);
    RUN(test_bad_files_are_refused_naming_the_line);
    RUN(test_reload_swaps_keys_or_keeps_the_old_ones);
    unlink(path);
    return check_status();
}
