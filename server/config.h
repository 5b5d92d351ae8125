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
    char db_path[PATH_MAX];   /* --db / GRAINPACKD_DB, default DATA_DIR/grainpack.db */
    int workers;              /* --workers / GRAINPACKD_WORKERS, default: number of cores */
    int http_threads;         /* --http-threads / GRAINPACKD_HTTP_THREADS, default: cores */
    size_t max_body;          /* --max-body / GRAINPACKD_MAX_BODY bytes, default 1 MiB */
    size_t max_queued;        /* --max-queued / GRAINPACKD_MAX_QUEUED, default 10000 */
    size_t max_disks;         /* --max-disks / GRAINPACKD_MAX_DISKS, default 2000000 */
    int max_wait;             /* --max-wait / GRAINPACKD_MAX_WAIT seconds of long-poll, default 60 */
    char cors_origins[1024];  /* --cors-origins / GRAINPACKD_CORS_ORIGINS: comma list or "*",
                                 default "" (no CORS headers) */
    char ready_file[PATH_MAX]; /* --ready-file: written with the port once listening */
} gp_config;

/* Fills cfg from defaults, the environment and argv. Returns 0 to run, 1 when --help or
 * --version was printed (exit 0), or -1 after printing an error to `err` (exit 2). */
int gp_config_load(gp_config *cfg, int argc, char **argv, FILE *out, FILE *err);

/* Whether `origin` may call the API from a browser under cfg->cors_origins. */
int gp_config_origin_allowed(const gp_config *cfg, const char *origin);

#endif
