/* fuzz_http.c - libFuzzer harness for grainpackd's request path: the input is what one
 * client sends on one connection (request lines, headers, query strings, bodies, several
 * pipelined requests), fed through a socket pair to the real daemon code (libmicrohttpd,
 * admission, API keys, routes, store on a sqlite file) running in this thread.
 *
 * Besides crashes, leaks and undefined behaviour, it traps on: a 500 (the daemon never
 * fails on input); an error of ours that is not a problem+json whose `status` is the
 * HTTP status and whose `detail` says something; an error answered by libmicrohttpd
 * itself (no Content-Type) with a status other than those it is documented to send.
 *
 * The service holds three keys (alice and bob: user; root: admin), a successful job of
 * alice (FIXED_DONE) and an accepted job of bob (FIXED_QUEUED), so that the corpus can
 * reach results, other owners' jobs and dismissals. No worker runs jobs. */
/* memmem, strncasecmp: GNU and POSIX extras on top of the project's _DEFAULT_SOURCE */
#define _GNU_SOURCE
#include <fcntl.h>
#include <jansson.h>
#include <microhttpd.h>
#include <nettle/sha2.h>
#include <netinet/in.h>
#include <sqlite3.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "config.h"
#include "grainpack/pipeline.h"
#include "http.h"
#include "log.h"
#include "peers.h"
#include "service.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The keys of the corpus (tests/fuzz/corpus/http uses them). */
static const char *const keys[][3] = {{"alice-fuzz-key", "alice", "user"},
                                      {"bob-fuzz-key", "bob", "user"},
                                      {"root-fuzz-key", "root", "admin"}};
#define FIXED_DONE "00000000-0000-4000-8000-00000000d0e1"
#define FIXED_QUEUED "00000000-0000-4000-8000-00000000b0b1"
/* Jobs the fuzzer submits pile up (nobody runs them): every so many inputs the store is
 * put back to the two fixtures. */
#define RESET_EVERY 64
/* Rounds of MHD_run per input at most: an exchange takes a handful. */
#define MAX_ROUNDS 200

static gp_config cfg;
static gp_service svc;
static struct MHD_Daemon *daemon_;
static char dir[64];
static unsigned long inputs;

static void remove_files(void)
{
    const char *names[] = {"keys", "grainpack.db", "grainpack.db-wal", "grainpack.db-shm"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char p[128];
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        unlink(p);
    }
    rmdir(dir);
}

static void teardown(void)
{
    if (daemon_)
        MHD_stop_daemon(daemon_);
    gp_waiters_stop(svc.waiters);
    gp_waiters_free(svc.waiters);
    gp_metrics_free(svc.metrics);
    gp_peers_free(svc.peers);
    gp_keyring_free(svc.keys);
    gp_store_close(svc.store);
    remove_files();
}

static void write_keys(const char *path)
{
    FILE *f = fopen(path, "w");
    for (size_t k = 0; f && k < sizeof keys / sizeof keys[0]; k++) {
        unsigned char d[SHA256_DIGEST_SIZE];
        struct sha256_ctx ctx;
        sha256_init(&ctx);
        sha256_update(&ctx, strlen(keys[k][0]), (const uint8_t *)keys[k][0]);
        sha256_digest(&ctx, sizeof d, d);
        fputs("sha256:", f);
        for (size_t i = 0; i < sizeof d; i++)
            fprintf(f, "%02x", d[i]);
        fprintf(f, " %s %s\n", keys[k][1], keys[k][2]);
    }
    if (f)
        fclose(f);
}

/* Runs SQL on the database with a connection of its own. */
static void exec_sql(const char *sql)
{
    sqlite3 *conn;
    if (sqlite3_open(cfg.db_path, &conn) == SQLITE_OK) {
        sqlite3_busy_timeout(conn, 10000);
        sqlite3_exec(conn, sql, NULL, NULL, NULL);
    }
    sqlite3_close(conn);
}

/* Inserts a job of owner under a fixed id; with `run`, runs it and stores its result. */
static void add_fixture(const char *id, const char *owner, int run)
{
    static const char spec_text[] = "{\"inputs\": {\"domain\": {\"width\": 12, \"height\": 9},"
                                    " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.5, "
                                    "\"max\": 1.0}, \"joint\": {\"law\": \"inverse\", \"k\": 0.1}}}";
    gp_spec spec;
    gp_error err;
    gp_job job;
    if (gp_spec_parse(spec_text, sizeof spec_text - 1, NULL, &spec, &err))
        abort();
    gp_db *db = gp_store_acquire(svc.store, 1);
    if (!db || gp_store_insert_job(db, owner, 0, spec_text, sizeof spec_text - 1, &spec, &job, NULL))
        abort();
    char sql[256];
    snprintf(sql, sizeof sql, "UPDATE jobs SET id = '%s'%s WHERE id = '%s'", id,
             run ? ", status = 'running'" : "", job.id);
    exec_sql(sql);
    if (run) {
        gp_result result;
        if (gp_pipeline_run(&spec, 0, NULL, &result, &err) || gp_store_finish(db, id, &result))
            abort();
        gp_result_free(&result);
    }
    gp_store_release(svc.store, db);
    gp_spec_free(&spec);
}

/* Puts the store back to the two fixtures. */
static void reset_store(void)
{
    exec_sql("DELETE FROM jobs WHERE id NOT IN ('" FIXED_DONE "', '" FIXED_QUEUED "')");
    gp_job job;
    gp_db *db = gp_store_acquire(svc.store, 1);
    int done = gp_store_get_job(db, FIXED_DONE, NULL, &job) == 0 && job.status == GP_JOB_SUCCESSFUL;
    int queued = gp_store_get_job(db, FIXED_QUEUED, NULL, &job) == 0 && job.status == GP_JOB_ACCEPTED;
    gp_store_release(svc.store, db);
    if (!done) {
        exec_sql("DELETE FROM jobs WHERE id = '" FIXED_DONE "'");
        add_fixture(FIXED_DONE, "alice", 1);
    }
    if (!queued) {
        exec_sql("DELETE FROM jobs WHERE id = '" FIXED_QUEUED "'");
        add_fixture(FIXED_QUEUED, "bob", 0);
    }
    atomic_store(&svc.queued, 1);
}

static void setup(void)
{
    struct stat st;
    snprintf(dir, sizeof dir, "%s/grainpack-fuzz-XXXXXX",
             stat("/dev/shm", &st) == 0 && access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp");
    if (!mkdtemp(dir))
        abort();
    char keyfile[96], db[96];
    snprintf(keyfile, sizeof keyfile, "%s/keys", dir);
    snprintf(db, sizeof db, "%s/grainpack.db", dir);
    write_keys(keyfile);
    char *argv[] = {"fuzz", "--db", db, "--key-file", keyfile, "--max-wait", "0",
                    "--max-body", "65536", "--max-queued", "40", "--max-header-bytes", "4096",
                    "--max-jobs-per-key", "20", "--max-disks", "100000", "--max-bins", "1000",
                    "--http-threads", "1", NULL};
    FILE *sink = fopen("/dev/null", "w");
    if (gp_config_load(&cfg, (int)(sizeof argv / sizeof argv[0]) - 1, argv, sink, stderr))
        abort();
    fclose(sink);
    gp_log_silence(1);
    svc.cfg = &cfg;
    atomic_init(&svc.queued, 0);
    atomic_init(&svc.accepting, 1);
    char why[256];
    if (gp_store_open(cfg.db_path, &svc.store, why, sizeof why) ||
        gp_keyring_load(cfg.key_file, &svc.keys, why, sizeof why) ||
        !(svc.metrics = gp_metrics_new()) || !(svc.peers = gp_peers_new(&svc.http)) ||
        gp_waiters_start(&svc.waiters, &gp_http_suspender) || gp_http_start_embedded(&svc, &daemon_)) {
        fprintf(stderr, "fuzz_http: cannot set up the service: %s\n", why);
        abort();
    }
    reset_store();
    atexit(teardown);
}

/* The value of header `name` in the header block [h, end), copied into out; 0 if absent. */
static int header_value(const char *h, const char *end, const char *name, char *out, size_t size)
{
    size_t n = strlen(name);
    for (const char *p = h; p < end;) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            eol = end;
        if ((size_t)(eol - p) > n + 1 && strncasecmp(p, name, n) == 0 && p[n] == ':') {
            const char *v = p + n + 1;
            while (v < eol && *v == ' ')
                v++;
            size_t len = (size_t)(eol - v);
            while (len && (v[len - 1] == '\r' || v[len - 1] == ' '))
                len--;
            snprintf(out, size, "%.*s", (int)len, v);
            return 1;
        }
        p = eol + 1;
    }
    return 0;
}

/* The statuses libmicrohttpd sends by itself (HTML bodies, no Content-Type): malformed
 * requests, too long a request line or headers, unsupported HTTP versions. */
static int mhd_status(unsigned status)
{
    return status == 400 || status == 413 || status == 414 || status == 431 || status == 501 ||
           status == 505;
}

/* Checks every response in the bytes the daemon sent. */
static void check_responses(const char *out, size_t len)
{
    const char *p = out, *end = out + len;
    while (p < end && end - p > 12 && memcmp(p, "HTTP/1.", 7) == 0) {
        unsigned status = (unsigned)atoi(p + 9);
        const char *hend = memmem(p, (size_t)(end - p), "\r\n\r\n", 4);
        if (!hend)
            return; /* cut off: the connection was closed mid-answer */
        char type[128] = "", length[32] = "";
        int has_type = header_value(p, hend, "Content-Type", type, sizeof type);
        header_value(p, hend, "Content-Length", length, sizeof length);
        const char *body = hend + 4;
        size_t blen = (size_t)strtoull(length, NULL, 10);
        if (blen > (size_t)(end - body) || (blen > 0 && memcmp(body, "HTTP/1.", 7) == 0))
            blen = 0; /* the answer to a HEAD: headers only */
        if (status >= 500 && status != 503 && status != 505)
            __builtin_trap(); /* the daemon never fails on input */
        if (status >= 400 && !has_type && !mhd_status(status))
            __builtin_trap();
        if (status >= 400 && has_type && blen > 0) {
            if (strcmp(type, "application/problem+json") != 0)
                __builtin_trap();
            json_error_t jerr;
            json_t *problem = json_loadb(body, blen, 0, &jerr);
            json_t *detail = json_object_get(problem, "detail");
            if (!problem || json_integer_value(json_object_get(problem, "status")) != status ||
                !json_is_string(detail) || strlen(json_string_value(detail)) < 10)
                __builtin_trap();
            json_decref(problem);
        }
        p = body + blen;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!daemon_)
        setup();
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_STREAM, 0, sv))
        return 0;
    struct sockaddr_in peer;
    memset(&peer, 0, sizeof peer);
    peer.sin_family = AF_INET;
    peer.sin_port = htons(40000);
    peer.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (MHD_add_connection(daemon_, sv[1], (struct sockaddr *)&peer, sizeof peer) != MHD_YES) {
        close(sv[0]);
        close(sv[1]);
        return 0;
    }
    fcntl(sv[0], F_SETFL, fcntl(sv[0], F_GETFL) | O_NONBLOCK);
    size_t sent = 0, cap = 1 << 16, got = 0;
    char *out = malloc(cap);
    int closed = 0;
    for (int round = 0; round < MAX_ROUNDS && !closed && out; round++) {
        if (sent < size) {
            ssize_t n = write(sv[0], data + sent, size - sent);
            if (n > 0 && (sent += (size_t)n) == size)
                shutdown(sv[0], SHUT_WR); /* the client has said all: the daemon sees EOF */
        } else if (size == 0 && round == 0) {
            shutdown(sv[0], SHUT_WR);
        }
        MHD_run(daemon_);
        for (;;) {
            if (got == cap) {
                char *grown = realloc(out, cap *= 2);
                if (!grown)
                    break;
                out = grown;
            }
            ssize_t n = read(sv[0], out + got, cap - got);
            if (n > 0) {
                got += (size_t)n;
                continue;
            }
            closed = n == 0;
            break;
        }
    }
    close(sv[0]);
    /* the daemon notices the closed socket and cleans the connection up */
    for (int round = 0; round < MAX_ROUNDS; round++) {
        const union MHD_DaemonInfo *info = MHD_get_daemon_info(daemon_, MHD_DAEMON_INFO_CURRENT_CONNECTIONS);
        if (!info || info->num_connections == 0)
            break;
        MHD_run(daemon_);
    }
    if (out && getenv("GP_FUZZ_VERBOSE")) /* for triage: what the daemon answered */
        fprintf(stderr, "--- %zu bytes in, %zu out:\n%.*s\n", size, got, (int)(got < 600 ? got : 600),
                out);
    if (out)
        check_responses(out, got);
    free(out);
    if (++inputs % RESET_EVERY == 0)
        reset_store();
    return 0;
}
