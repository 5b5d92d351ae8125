/* main.c - grainpackd: reads its options and keys, opens the store, starts the workers
 * and the HTTP server; on SIGHUP reads the key file again; on SIGTERM/SIGINT stops
 * accepting, queues running jobs again and closes cleanly. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "auth.h"
#include "config.h"
#include "grainpack/version.h"
#include "http.h"
#include "log.h"
#include "nodes.h"
#include "peers.h"
#include "service.h"
#include "workers.h"

/* How long a stop waits for the workers. They return within milliseconds of their flag
 * (bench/CANCEL.md); this bounds a stop when one does not (a stage that ignores its flag,
 * a store write held up by another process's lock), well within systemd's default
 * TimeoutStopSec of 90 s. Such a job stays running in the store and is queued again at
 * the next start. */
#define STOP_WORKERS_SECONDS 5.0

/* Creates the directory that holds the database file, if missing (one level). */
static int make_db_dir(const char *db_path)
{
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", db_path);
    char *slash = strrchr(dir, '/');
    if (!slash || slash == dir)
        return 0;
    *slash = '\0';
    if (mkdir(dir, 0750) == 0 || errno == EEXIST)
        return 0;
    gp_log("cannot create the data directory %s: %s", dir, strerror(errno));
    return -1;
}

/* Takes DB_PATH.lock for the daemon's lifetime (the descriptor stays open; the kernel
 * drops the lock when the process ends, however it ends). A second daemon on the same
 * database would queue again the jobs the first one is running, so it must not start.
 * Returns the descriptor or -1. */
static int lock_database(const char *db_path)
{
    char path[PATH_MAX + 8];
    snprintf(path, sizeof path, "%s.lock", db_path);
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0640);
    if (fd < 0) {
        gp_log("cannot open %s: %s", path, strerror(errno));
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        gp_log("another grainpackd is using %s (%s is locked)", db_path, path);
        close(fd);
        return -1;
    }
    return fd;
}

/* Writes the bound port to path through a rename, so a reader never sees half of it. */
static int write_ready_file(const char *path, unsigned port)
{
    char tmp[PATH_MAX + 8];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f || fprintf(f, "%u\n", port) < 0 || fclose(f) != 0 || rename(tmp, path) != 0) {
        gp_log("cannot write the ready file %s: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    gp_config cfg;
    int rc = gp_config_load(&cfg, argc, argv, stdout, stderr);
    if (rc)
        return rc > 0 ? 0 : 2;

    /* every thread inherits this mask: the signals are taken by sigwait below only */
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGTERM);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &signals, NULL);
    signal(SIGPIPE, SIG_IGN); /* a client that hangs up must not kill the daemon */
    /* a file size limit reached is a write error sqlite reports (the disk is full), not a
     * reason to die */
    signal(SIGXFSZ, SIG_IGN);

    gp_service svc;
    memset(&svc, 0, sizeof svc);
    svc.cfg = &cfg;
    svc.started = gp_monotonic_seconds();
    atomic_init(&svc.queued, 0);
    atomic_init(&svc.accepting, 1);
    atomic_init(&svc.http.open, 0);
    atomic_init(&svc.http.slow_heads, 0);
    struct MHD_Daemon *http = NULL;
    gp_nodes *nodes = NULL;
    int status = 1, requeued = 0, given_up = 0, lock_fd = -1;
    char why[512];
    if (cfg.key_file[0]) {
        if (gp_keyring_load(cfg.key_file, &svc.keys, why, sizeof why)) {
            gp_log("%s", why);
            goto done;
        }
        gp_log("%zu API keys read from %s", gp_keyring_count(svc.keys), cfg.key_file);
    } else {
        gp_log("no key file: the service is open to anyone who reaches %s (--key-file to "
               "require API keys)", cfg.host);
    }
    /* a sqlite file is one node's (locked); a PostgreSQL database is shared by nodes */
    int shared = gp_store_location_is_pg(cfg.db_path);
    char where[PATH_MAX];
    gp_store_redact(cfg.db_path, where, sizeof where);
    if (!shared && (make_db_dir(cfg.db_path) || (lock_fd = lock_database(cfg.db_path)) < 0))
        goto done;
    gp_store_options store_options = {cfg.node, cfg.lease_seconds, cfg.max_job_attempts};
    if (gp_store_open(cfg.db_path, &svc.store, why, sizeof why) ||
        gp_store_configure(svc.store, &store_options)) {
        gp_log("cannot open the job store %s: %s", where, why);
        goto done;
    }
    gp_db *db = gp_store_acquire(svc.store, 1);
    long counts[GP_JOB_NSTATUS];
    if (!db || gp_store_recover(db, cfg.max_job_attempts, &requeued, &given_up) ||
        gp_store_count(db, counts)) {
        gp_store_release(svc.store, db);
        gp_log("cannot read the job store %s", where);
        goto done;
    }
    gp_store_release(svc.store, db);
    if (given_up)
        gp_log("%d jobs the daemon died running %d times failed instead of being queued again "
               "(--max-job-attempts)", given_up, cfg.max_job_attempts);
    atomic_store(&svc.queued, counts[GP_JOB_ACCEPTED]);
    if (gp_cursor_keys_init(&svc.cursor_keys)) {
        gp_log("cannot draw the page cursors' keys from the kernel's random source");
        goto done;
    }
    /* nodes sharing a store share the keys: a page's next link works on any node */
    if (shared && gp_store_secret(svc.store, "cursor keys", &svc.cursor_keys,
                                  sizeof svc.cursor_keys)) {
        gp_log("cannot read the page cursors' keys from the job store %s", where);
        goto done;
    }
    if (!(svc.metrics = gp_metrics_new()) || !(svc.peers = gp_peers_new(&svc.http)) ||
        gp_peers_watch(svc.peers, (double)cfg.connection_timeout) ||
        gp_waiters_start(&svc.waiters, &gp_http_suspender) || gp_pool_start(&svc, &svc.pool) ||
        gp_nodes_start(&svc, &nodes)) {
        gp_log("out of memory starting up");
        goto done;
    }
    unsigned port;
    if (gp_http_start(&svc, &http, &port))
        goto done;
    gp_log("grainpackd %s (pid %ld) listening on %s port %u; store %s %s (%ld jobs waiting, %d "
           "of them queued again after a stop); %d workers; node %s",
           GP_VERSION, (long)getpid(), cfg.host, port, gp_store_kind(svc.store), where,
           counts[GP_JOB_ACCEPTED], requeued, cfg.workers, cfg.node);
    if (cfg.ready_file[0] && write_ready_file(cfg.ready_file, port))
        goto done;

    for (;;) {
        int sig = 0;
        if (sigwait(&signals, &sig) != 0)
            continue;
        if (sig == SIGHUP) {
            if (!svc.keys)
                gp_log("received SIGHUP: no key file to read again (the service is open)");
            else if (gp_keyring_reload(svc.keys, why, sizeof why) == 0)
                gp_log("received SIGHUP: %zu API keys read again from %s",
                       gp_keyring_count(svc.keys), cfg.key_file);
            else
                gp_log("received SIGHUP: %s; the previous keys stay in use", why);
            continue;
        }
        gp_log("received %s: stopping (no new jobs; running jobs are queued again)",
               sig == SIGTERM ? "SIGTERM" : "SIGINT");
        break;
    }
    status = 0;

done:
    atomic_store(&svc.accepting, 0);
    if (http)
        gp_http_quiesce(http);
    double stop_began = gp_monotonic_seconds();
    int stuck = gp_pool_stop(svc.pool, STOP_WORKERS_SECONDS);
    if (!stuck) /* the leases were renewed until the workers gave their jobs back */
        gp_nodes_stop(nodes);
    gp_waiters_stop(svc.waiters);
    if (http)
        gp_http_stop(http);
    if (stuck) {
        /* those threads still use the pool, the store and the metrics: nothing is freed,
         * the process ends here (sqlite's journal makes this as safe as a crash) */
        gp_log("%d worker threads did not stop within %.0f s; their jobs stay running in the "
               "store and are queued again at the next start; stopping now (%.1f s)",
               stuck, STOP_WORKERS_SECONDS, gp_monotonic_seconds() - stop_began);
        fflush(stderr);
        _exit(status);
    }
    gp_pool_free(svc.pool);
    gp_waiters_free(svc.waiters);
    gp_metrics_free(svc.metrics);
    gp_peers_free(svc.peers);
    gp_keyring_free(svc.keys);
    gp_store_close(svc.store);
    if (lock_fd >= 0)
        close(lock_fd);
    if (status == 0)
        gp_log("grainpackd stopped cleanly");
    return status;
}
