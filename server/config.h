/* config.h - the daemon's options: command-line flags with environment fallbacks and
 * defaults, in that order of precedence. */
#ifndef GRAINPACKD_CONFIG_H
#define GRAINPACKD_CONFIG_H

#include <limits.h>
#include <stddef.h>
#include <stdio.h>

typedef struct gp_config {
    char host[64];            /* --host / GRAINPACKD_HOST, default 127.0.0.1 */
    int port;                 /* --port / GRAINPACKD_PORT, default 8080; 0 picks a free port */
    char data_dir[PATH_MAX];  /* --data-dir / GRAINPACKD_DATA_DIR, default ./data */
    char db_path[PATH_MAX];   /* --db / GRAINPACKD_DB: a sqlite file, default
                                 DATA_DIR/grainpack.db, or a postgresql:// URI */
    char node[64];            /* --node / GRAINPACKD_NODE: the node's name, default the host name */
    double lease_seconds;     /* --lease-seconds / GRAINPACKD_LEASE_SECONDS a shared store's
                                 claim lasts unrenewed, default 10 */
    int workers;              /* --workers / GRAINPACKD_WORKERS, default: number of cores */
    int http_threads;         /* --http-threads / GRAINPACKD_HTTP_THREADS, default: cores */
    size_t max_body;          /* --max-body / GRAINPACKD_MAX_BODY bytes, default 1 MiB */
    size_t max_queued;        /* --max-queued / GRAINPACKD_MAX_QUEUED, default 10000 */
    size_t max_disks;         /* --max-disks / GRAINPACKD_MAX_DISKS, default 2000000 */
    size_t max_bins;          /* --max-bins / GRAINPACKD_MAX_BINS histogram bins, default 10000 */
    size_t max_elements;      /* --max-elements / GRAINPACKD_MAX_ELEMENTS of a mesh, default 2000000 */
    double max_job_seconds;   /* --max-job-seconds / GRAINPACKD_MAX_JOB_SECONDS of running per
                                 job, default 600; 0: no limit */
    int max_job_attempts;     /* --max-job-attempts / GRAINPACKD_MAX_JOB_ATTEMPTS: times a job is
                                 started; one the daemon died running that often is failed at
                                 the next start instead of queued again; default 3 */
    size_t max_jobs_per_key;  /* --max-jobs-per-key / GRAINPACKD_MAX_JOBS_PER_KEY accepted and
                                 running jobs of one key, default 100; 0: no limit */
    int max_wait;             /* --max-wait / GRAINPACKD_MAX_WAIT seconds of long-poll, default 60 */
    size_t max_header_bytes;  /* --max-header-bytes / GRAINPACKD_MAX_HEADER_BYTES of request
                                 line and headers, default 8192 */
    int max_connections;      /* --max-connections / GRAINPACKD_MAX_CONNECTIONS, default 1024 */
    int max_connections_per_ip; /* --max-connections-per-ip / GRAINPACKD_MAX_CONNECTIONS_PER_IP,
                                   default 128 */
    int connection_timeout;   /* --connection-timeout / GRAINPACKD_CONNECTION_TIMEOUT seconds a
                                 silent client keeps its connection, and a request head may
                                 take, default 30 */
    char key_file[PATH_MAX];  /* --key-file / GRAINPACKD_KEY_FILE: API keys; "" runs open */
    int insecure_open;        /* --insecure-open / GRAINPACKD_INSECURE_OPEN=1: run open (no key
                                 file) on an address other than loopback */
    char cors_origins[1024];  /* --cors-origins / GRAINPACKD_CORS_ORIGINS: comma list or "*",
                                 default "" (no CORS headers) */
    char ready_file[PATH_MAX]; /* --ready-file: written with the port once listening */
} gp_config;

/* Fills cfg from defaults, the environment and argv. Returns 0 to run, 1 when --help or
 * --version was printed (exit 0), or -1 after printing an error to `err` (exit 2): a bad
 * value, or no key file on an address other than loopback without --insecure-open
 * (anyone who reaches the port could read and delete every job). */
int gp_config_load(gp_config *cfg, int argc, char **argv, FILE *out, FILE *err);

/* Whether host (a numeric address) is a loopback address: 127.0.0.0/8, ::1, or
 * ::ffff:127.x.y.z. */
int gp_config_is_loopback(const char *host);

/* Whether `origin` may call the API from a browser under cfg->cors_origins. */
int gp_config_origin_allowed(const gp_config *cfg, const char *origin);

#endif
