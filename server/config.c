/* config.c - parsing the daemon's flags and environment variables. */
#include "config.h"

#include <arpa/inet.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "grainpack/version.h"

#define DEFAULT_MAX_BODY ((size_t)1 << 20)
#define DEFAULT_MAX_QUEUED ((size_t)10000)
/* A job this size packs in a few seconds and its result (32 bytes a disk) stays
 * under 64 MB in the database; --max-disks raises it. */
#define DEFAULT_MAX_DISKS ((size_t)2000000)
#define DEFAULT_MAX_WAIT 60
/* The engine's own cap on histogram bins (a histogram is sampled by a table this long). */
#define DEFAULT_MAX_BINS ((size_t)10000)
/* A mesh of 2 million elements weighs about 300 MB while it is built and 100 MB as a .msh
 * file (bench/MESH.md): a tenth of the library's default, like the disks. */
#define DEFAULT_MAX_ELEMENTS ((size_t)2000000)
/* A job at the default disk cap packs in seconds; ten minutes leaves room for slow
 * stages and a loaded machine, and still frees a worker held by a runaway job. */
#define DEFAULT_MAX_JOB_SECONDS 600.0
/* A job is run at most this many times: one that was running each time the daemon died
 * (a crash, a kill, a stop it did not answer) is failed instead of claimed at every
 * start. Three lets a job survive two unrelated crashes or kills of the node. */
#define DEFAULT_MAX_JOB_ATTEMPTS 3
/* A node renews its leases every second (and at most a third of this): ten seconds rides
 * out a stall of several renewals (a busy database, a paused virtual machine) and still
 * hands a dead node's jobs to another within seconds. */
#define DEFAULT_LEASE_SECONDS 10.0
/* Enough for a script that submits a parameter sweep, far below the queue's size, so
 * that one user cannot fill the queue for everyone. */
#define DEFAULT_MAX_JOBS_PER_KEY ((size_t)100)
/* A request line and headers of a browser or curl are well under 2 KB; 8 KB is the
 * common limit of HTTP servers (nginx's large_client_header_buffers). */
#define DEFAULT_MAX_HEADER_BYTES ((size_t)8192)
/* Connections kept open at most, and from one address: room for a lab behind one NAT
 * address, and far below the file descriptor limit. */
#define DEFAULT_MAX_CONNECTIONS 1024
#define DEFAULT_MAX_CONNECTIONS_PER_IP 128
/* A client that sends nothing for this long is disconnected, and so is one whose request
 * head is not complete this long after it began (a slow-loris defence: see peers.h). A
 * long-poll is not affected: a suspended connection is not timed out. */
#define DEFAULT_CONNECTION_TIMEOUT 30

typedef enum opt_kind { OPT_TEXT, OPT_SIZE, OPT_INT, OPT_BOOL, OPT_SECONDS } opt_kind;

typedef struct option {
    const char *flag, *env, *help;
    opt_kind kind;
    size_t offset, size; /* where in gp_config, and the field's size for OPT_TEXT */
    size_t min, max;     /* OPT_SIZE, OPT_INT and OPT_SECONDS range */
} option;

#define TEXT(field) OPT_TEXT, offsetof(gp_config, field), sizeof(((gp_config *)0)->field), 0, 0
#define SIZE(field, lo, hi) OPT_SIZE, offsetof(gp_config, field), 0, lo, hi
#define INT(field, lo, hi) OPT_INT, offsetof(gp_config, field), 0, lo, hi
#define BOOL(field) OPT_BOOL, offsetof(gp_config, field), 0, 0, 1 /* a flag without value */
#define SECONDS(field, lo, hi) OPT_SECONDS, offsetof(gp_config, field), 0, lo, hi

static const option options[] = {
    {"--host", "GRAINPACKD_HOST", "address to listen on (default 127.0.0.1)", TEXT(host)},
    {"--port", "GRAINPACKD_PORT", "port (default 8080; 0 picks a free one)", INT(port, 0, 65535)},
    {"--data-dir", "GRAINPACKD_DATA_DIR", "directory of the database (default ./data)",
     TEXT(data_dir)},
    {"--db", "GRAINPACKD_DB",
     "database: a sqlite file (default DATA_DIR/grainpack.db) or a postgresql:// URI, which "
     "nodes share (password from PGPASSWORD or ~/.pgpass)",
     TEXT(db_path)},
    {"--node", "GRAINPACKD_NODE", "this node's name in a shared store (default: the host name)",
     TEXT(node)},
    {"--lease-seconds", "GRAINPACKD_LEASE_SECONDS",
     "a shared store: seconds a running job's claim lasts unless its node renews it; a dead "
     "node's jobs run again elsewhere after it (default 10)",
     SECONDS(lease_seconds, 1, 3600)},
    {"--workers", "GRAINPACKD_WORKERS", "worker threads running jobs (default: cores)",
     INT(workers, 1, 256)},
    {"--http-threads", "GRAINPACKD_HTTP_THREADS", "HTTP threads (default: cores)",
     INT(http_threads, 1, 256)},
    {"--max-body", "GRAINPACKD_MAX_BODY", "largest request body in bytes (default 1048576)",
     SIZE(max_body, 64, (size_t)1 << 30)},
    {"--max-queued", "GRAINPACKD_MAX_QUEUED", "jobs waiting before 503 (default 10000)",
     SIZE(max_queued, 1, (size_t)1 << 30)},
    {"--max-disks", "GRAINPACKD_MAX_DISKS", "largest job in expected disks (default 2000000)",
     SIZE(max_disks, 1, (size_t)1 << 40)},
    {"--max-bins", "GRAINPACKD_MAX_BINS", "most histogram bins in a spec (default 10000)",
     SIZE(max_bins, 1, (size_t)1 << 24)},
    {"--max-elements", "GRAINPACKD_MAX_ELEMENTS",
     "largest mesh in expected elements; a mesh growing beyond fails (default 2000000)",
     SIZE(max_elements, 1, (size_t)1 << 40)},
    {"--max-job-seconds", "GRAINPACKD_MAX_JOB_SECONDS",
     "seconds a job may run before it is stopped and failed (default 600; 0: no limit)",
     SECONDS(max_job_seconds, 0, 10000000)},
    {"--max-job-attempts", "GRAINPACKD_MAX_JOB_ATTEMPTS",
     "times a job is started before a job the daemon died running is failed (default 3)",
     INT(max_job_attempts, 1, 1000)},
    {"--max-jobs-per-key", "GRAINPACKD_MAX_JOBS_PER_KEY",
     "accepted and running jobs one API key may have before 429 (default 100; 0: no limit)",
     SIZE(max_jobs_per_key, 0, (size_t)1 << 30)},
    {"--max-wait", "GRAINPACKD_MAX_WAIT", "longest ?wait= of GET /jobs/{id} in seconds (default 60)",
     INT(max_wait, 0, 3600)},
    {"--max-header-bytes", "GRAINPACKD_MAX_HEADER_BYTES",
     "largest request line plus headers in bytes before 414/431 (default 8192)",
     SIZE(max_header_bytes, 1024, (size_t)1 << 20)},
    {"--max-connections", "GRAINPACKD_MAX_CONNECTIONS", "connections open at once (default 1024)",
     INT(max_connections, 1, 1000000)},
    {"--max-connections-per-ip", "GRAINPACKD_MAX_CONNECTIONS_PER_IP",
     "connections open at once from one address before 429 (default 128)",
     INT(max_connections_per_ip, 1, 1000000)},
    {"--connection-timeout", "GRAINPACKD_CONNECTION_TIMEOUT",
     "seconds a client may stay silent, or take to send a request head, before it is "
     "disconnected (default 30)",
     INT(connection_timeout, 1, 3600)},
    {"--key-file", "GRAINPACKD_KEY_FILE",
     "API keys (see README, Access control); without it the service is open to anyone",
     TEXT(key_file)},
    {"--insecure-open", "GRAINPACKD_INSECURE_OPEN",
     "run without a key file on an address other than loopback (no value; env: 1)",
     BOOL(insecure_open)},
    {"--cors-origins", "GRAINPACKD_CORS_ORIGINS",
     "browser origins allowed to call the API: comma-separated, or * (default none)",
     TEXT(cors_origins)},
    {"--ready-file", NULL, "file to write the port to once listening", TEXT(ready_file)},
};
#define NOPTIONS (sizeof options / sizeof options[0])

static void usage(FILE *out)
{
    fputs("Usage: grainpackd [OPTION VALUE]...\n"
          "The grainpack job service: OGC API - Processes over HTTP, jobs in sqlite or PostgreSQL.\n\n",
          out);
    for (size_t i = 0; i < NOPTIONS; i++)
        fprintf(out, "  %-25s %s%s%s\n", options[i].flag, options[i].help,
                options[i].env ? "; env " : "", options[i].env ? options[i].env : "");
    fputs("  --help, --version\n\nSIGTERM or SIGINT stops it cleanly: running jobs are queued "
          "again. SIGHUP reads the key file again.\n",
          out);
}

/* Stores `value` into the field of `opt`; -1 with a message when it does not fit. */
static int set_option(gp_config *cfg, const option *opt, const char *value, const char *source,
                      FILE *err)
{
    char *field = (char *)cfg + opt->offset;
    if (opt->kind == OPT_BOOL) {
        int on = strcmp(value, "1") == 0 || strcmp(value, "yes") == 0 || strcmp(value, "true") == 0;
        if (!on && strcmp(value, "0") != 0 && strcmp(value, "no") != 0 &&
            strcmp(value, "false") != 0) {
            fprintf(err, "grainpackd: %s: expected 1 or 0, got '%s'\n", source, value);
            return -1;
        }
        *(int *)(void *)field = on;
        return 0;
    }
    if (opt->kind == OPT_SECONDS) {
        char *end;
        errno = 0;
        double v = strtod(value, &end);
        if (errno || end == value || *end || !(v >= (double)opt->min && v <= (double)opt->max)) {
            fprintf(err, "grainpackd: %s: expected seconds from %zu to %zu, got '%s'\n", source,
                    opt->min, opt->max, value);
            return -1;
        }
        *(double *)(void *)field = v;
        return 0;
    }
    if (opt->kind == OPT_TEXT) {
        if (strlen(value) >= opt->size) {
            fprintf(err, "grainpackd: %s: value too long (at most %zu characters)\n", source,
                    opt->size - 1);
            return -1;
        }
        memcpy(field, value, strlen(value) + 1);
        return 0;
    }
    char *end;
    errno = 0;
    unsigned long long v = strtoull(value, &end, 10);
    size_t lo = opt->min, hi = opt->max;
    if (errno || end == value || *end || value[0] == '-' || v < lo || v > hi) {
        fprintf(err, "grainpackd: %s: expected an integer from %zu to %zu, got '%s'\n", source, lo,
                hi, value);
        return -1;
    }
    if (opt->kind == OPT_INT)
        *(int *)(void *)field = (int)v;
    else
        *(size_t *)(void *)field = (size_t)v;
    return 0;
}

int gp_config_load(gp_config *cfg, int argc, char **argv, FILE *out, FILE *err)
{
    memset(cfg, 0, sizeof *cfg);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    snprintf(cfg->host, sizeof cfg->host, "127.0.0.1");
    cfg->port = 8080;
    snprintf(cfg->data_dir, sizeof cfg->data_dir, "data");
    cfg->workers = cfg->http_threads = cores > 0 ? (int)cores : 1;
    cfg->max_body = DEFAULT_MAX_BODY;
    cfg->max_queued = DEFAULT_MAX_QUEUED;
    cfg->max_disks = DEFAULT_MAX_DISKS;
    cfg->max_bins = DEFAULT_MAX_BINS;
    cfg->max_elements = DEFAULT_MAX_ELEMENTS;
    cfg->max_job_seconds = DEFAULT_MAX_JOB_SECONDS;
    cfg->max_job_attempts = DEFAULT_MAX_JOB_ATTEMPTS;
    cfg->lease_seconds = DEFAULT_LEASE_SECONDS;
    cfg->max_jobs_per_key = DEFAULT_MAX_JOBS_PER_KEY;
    cfg->max_wait = DEFAULT_MAX_WAIT;
    cfg->max_header_bytes = DEFAULT_MAX_HEADER_BYTES;
    cfg->max_connections = DEFAULT_MAX_CONNECTIONS;
    cfg->max_connections_per_ip = DEFAULT_MAX_CONNECTIONS_PER_IP;
    cfg->connection_timeout = DEFAULT_CONNECTION_TIMEOUT;
    for (size_t i = 0; i < NOPTIONS; i++) {
        const char *value = options[i].env ? getenv(options[i].env) : NULL;
        if (value && *value && set_option(cfg, &options[i], value, options[i].env, err))
            return -1;
    }
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--help") == 0 || strcmp(argv[a], "-h") == 0) {
            usage(out);
            return 1;
        }
        if (strcmp(argv[a], "--version") == 0) {
            fprintf(out, "grainpackd %s\n", GP_VERSION);
            return 1;
        }
        const option *opt = NULL;
        for (size_t i = 0; i < NOPTIONS && !opt; i++)
            if (strcmp(argv[a], options[i].flag) == 0)
                opt = &options[i];
        if (!opt) {
            fprintf(err, "grainpackd: unknown option '%s'\n", argv[a]);
            usage(err);
            return -1;
        }
        if (opt->kind == OPT_BOOL) {
            set_option(cfg, opt, "1", opt->flag, err);
            continue;
        }
        if (a + 1 >= argc) {
            fprintf(err, "grainpackd: %s needs a value\n", argv[a]);
            return -1;
        }
        if (set_option(cfg, opt, argv[a + 1], opt->flag, err))
            return -1;
        a++;
    }
    if (!cfg->db_path[0]) {
        int n = snprintf(cfg->db_path, sizeof cfg->db_path, "%s/grainpack.db", cfg->data_dir);
        if (n < 0 || (size_t)n >= sizeof cfg->db_path) {
            fprintf(err, "grainpackd: data directory path too long\n");
            return -1;
        }
    }
    if (!cfg->node[0] && (gethostname(cfg->node, sizeof cfg->node) != 0 || !cfg->node[0]))
        snprintf(cfg->node, sizeof cfg->node, "grainpackd");
    cfg->node[sizeof cfg->node - 1] = '\0'; /* gethostname does not say when it truncated */
    if (!cfg->key_file[0] && !cfg->insecure_open && !gp_config_is_loopback(cfg->host)) {
        fprintf(err,
                "grainpackd: refusing to listen on %s without a key file: anyone who reaches "
                "the port could read and delete every job. Give --key-file FILE (README, "
                "\"Access control\"), or --insecure-open to run open anyway.\n",
                cfg->host);
        return -1;
    }
    return 0;
}

int gp_config_is_loopback(const char *host)
{
    struct in_addr v4;
    struct in6_addr v6;
    if (inet_pton(AF_INET, host, &v4) == 1)
        return (ntohl(v4.s_addr) >> 24) == 127;
    if (inet_pton(AF_INET6, host, &v6) != 1)
        return 0;
    static const unsigned char mapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
    if (memcmp(v6.s6_addr, mapped, 12) == 0)
        return v6.s6_addr[12] == 127;
    return memcmp(&v6, &in6addr_loopback, sizeof v6) == 0;
}

int gp_config_origin_allowed(const gp_config *cfg, const char *origin)
{
    if (!origin || !cfg->cors_origins[0])
        return 0;
    if (strcmp(cfg->cors_origins, "*") == 0)
        return 1;
    size_t n = strlen(origin);
    for (const char *p = cfg->cors_origins; *p;) {
        while (*p == ',' || *p == ' ')
            p++;
        const char *end = p;
        while (*end && *end != ',' && *end != ' ')
            end++;
        if ((size_t)(end - p) == n && n && strncmp(p, origin, n) == 0)
            return 1;
        p = end;
    }
    return 0;
}
