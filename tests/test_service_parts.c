/* test_service_parts.c - two small pure parts of grainpackd's HTTP side: the page
 * cursors (a token reads back to its position for its viewer only; altered, foreign or
 * made-up tokens are refused; the keys of another start refuse it) and the framing rules
 * of a request head (every verdict of RFC 9112 the daemon applies, decided from the
 * headers alone). */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "cursor.h"
#include "framing.h"

static void test_cursors_read_back_for_their_viewer_only(void)
{
    gp_cursor_keys keys, other;
    CHECK(gp_cursor_keys_init(&keys) == 0 && gp_cursor_keys_init(&other) == 0);
    const int64_t positions[] = {1, 2, 1000, (int64_t)1 << 40};
    for (size_t i = 0; i < sizeof positions / sizeof *positions; i++) {
        char token[GP_CURSOR_SIZE], alice[GP_CURSOR_SIZE];
        int64_t seq = 0;
        gp_cursor_encode(&keys, NULL, positions[i], token);
        gp_cursor_encode(&keys, "alice", positions[i], alice);
        CHECK(strlen(token) == GP_CURSOR_CHARS && strspn(token, "0123456789abcdef") == GP_CURSOR_CHARS);
        CHECK(gp_cursor_decode(&keys, NULL, token, &seq) == 0 && seq == positions[i]);
        CHECK(gp_cursor_decode(&keys, "alice", alice, &seq) == 0 && seq == positions[i]);
        CHECK(strcmp(token, alice) != 0);
        /* another viewer, a name that extends the first, other keys: refused */
        CHECK(gp_cursor_decode(&keys, "bob", alice, &seq) == -1);
        CHECK(gp_cursor_decode(&keys, "alice2", alice, &seq) == -1);
        CHECK(gp_cursor_decode(&keys, NULL, alice, &seq) == -1);
        CHECK(gp_cursor_decode(&keys, "alice", token, &seq) == -1);
        CHECK(gp_cursor_decode(&other, "alice", alice, &seq) == -1);
        /* every single altered character is refused */
        for (int k = 0; k < GP_CURSOR_CHARS; k++) {
            char altered[GP_CURSOR_SIZE];
            memcpy(altered, alice, sizeof altered);
            altered[k] = altered[k] == '0' ? '1' : '0';
            CHECK(gp_cursor_decode(&keys, "alice", altered, &seq) == -1);
        }
    }
    int64_t seq;
    const char *bad[] = {"", "7", "-1", "0123456789abcdef0123456789abcdeF",
                         "0123456789abcdef0123456789abcdef0", "zz23456789abcdef0123456789abcdef"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        CHECK_MSG(gp_cursor_decode(&keys, "alice", bad[i], &seq) == -1, "'%s'", bad[i]);
}

/* The verdict on a head of version `version` and headers name, value, ... NULL. */
static unsigned verdict(const char *version, ...)
{
    gp_framing f;
    gp_framing_init(&f);
    va_list ap;
    va_start(ap, version);
    for (const char *name; (name = va_arg(ap, const char *));)
        gp_framing_add(&f, name, va_arg(ap, const char *));
    va_end(ap);
    gp_reply reply;
    memset(&reply, 0, sizeof reply);
    if (!gp_framing_check(&f, version, "/x", &reply))
        return 0;
    CHECK(reply.close && strcmp(reply.content_type, "application/problem+json") == 0);
    unsigned status = reply.status;
    gp_reply_free(&reply);
    return status;
}

static void test_framing_verdicts(void)
{
    const char *H = "Host", *CL = "Content-Length", *TE = "Transfer-Encoding";
    /* well framed */
    CHECK(verdict("HTTP/1.1", H, "a", NULL) == 0);
    CHECK(verdict("HTTP/1.1", H, "", NULL) == 0);
    CHECK(verdict("HTTP/1.1", H, "[::1]:8080", CL, "12", NULL) == 0);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "chunked", NULL) == 0);
    CHECK(verdict("HTTP/1.1", "host", "a", "transfer-encoding", "ChUnKeD", NULL) == 0);
    CHECK(verdict("HTTP/1.0", NULL) == 0);
    CHECK(verdict("HTTP/1.0", CL, "3", NULL) == 0);
    /* Host */
    CHECK(verdict("HTTP/1.1", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", H, "a", NULL) == 400);
    CHECK(verdict("HTTP/1.0", H, "a", H, "b", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a b", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a/b", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "user@a", NULL) == 400);
    /* lengths and codings */
    CHECK(verdict("HTTP/1.1", H, "a", CL, "3", TE, "chunked", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "chunked", CL, "3", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", CL, "3", CL, "3", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", CL, "3", CL, "4", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "chunked", TE, "chunked", NULL) == 400);
    CHECK(verdict("HTTP/1.0", TE, "chunked", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "gzip", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "chunked, gzip", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "chunked,chunked", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, ", chunked", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "gzip,, chunked", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "chunked ", NULL) == 400); /* not exactly chunked */
    CHECK(verdict("HTTP/1.1", H, "a", TE, "identity, chunked", NULL) == 501);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "gzip,chunked", NULL) == 501);
    CHECK(verdict("HTTP/1.1", H, "a", TE, "gzip , deflate ,\tCHUNKED", NULL) == 501);
    /* header names are tokens */
    CHECK(verdict("HTTP/1.1", H, "a", "Content-Length ", "3", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", "X(y)", "1", NULL) == 400);
    CHECK(verdict("HTTP/1.1", H, "a", "X-Fine_1.2~", "1", NULL) == 0);
}

static void test_query_parameters_are_counted_before_parsing(void)
{
    CHECK(gp_query_parameters("/jobs") == 0);
    CHECK(gp_query_parameters("/jobs?") == 1);
    CHECK(gp_query_parameters("/jobs?a=1") == 1);
    CHECK(gp_query_parameters("/jobs?a=1&b&&c=") == 4);
    CHECK(gp_query_parameters(NULL) == 0);
}

int main(void)
{
    RUN(test_cursors_read_back_for_their_viewer_only);
    RUN(test_framing_verdicts);
    RUN(test_query_parameters_are_counted_before_parsing);
    return check_status();
}
