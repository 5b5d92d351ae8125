/* metrics.h - counters and histograms the daemon exposes at /metrics, in the Prometheus
 * text format. Every update is a lock-free atomic add except the first sight of a stage
 * name, so HTTP threads and workers may update at will. */
#ifndef GRAINPACKD_METRICS_H
#define GRAINPACKD_METRICS_H

#include <stddef.h>

#include "store.h"

typedef struct gp_metrics gp_metrics;

/* A new zeroed set of metrics (NULL when out of memory); free with gp_metrics_free. */
gp_metrics *gp_metrics_new(void);
void gp_metrics_free(gp_metrics *m);

/* One HTTP request answered with `status`. */
void gp_metrics_request(gp_metrics *m, unsigned status);

/* How a worker's run of a job ended: "successful", "failed", "timed_out" (stopped by
 * --max-job-seconds), "dismissed" (canceled by a DELETE), "discarded" (finished after a
 * DELETE: result dropped) or "requeued". */
void gp_metrics_outcome(gp_metrics *m, const char *outcome);

/* The job pipeline is about to run (a worker), or a stored result's stages to be derived
 * again (the migration of a version 2 database): counted so that a test can tell that a
 * download ran none. */
void gp_metrics_pipeline_run(gp_metrics *m);

/* A result download started (delta 1) or ended (delta -1). */
void gp_metrics_download(gp_metrics *m, int delta);

/* A pipeline stage took `seconds` (histogram per stage name; names are static strings
 * from the engine, at most GP_MAX_STAGES of them are tracked). */
void gp_metrics_stage(gp_metrics *m, const char *stage, double seconds);

/* The state the text needs besides the counters. */
typedef struct gp_metrics_gauges {
    long jobs[GP_JOB_NSTATUS]; /* jobs in the store by status */
    long queue_depth;          /* accepted jobs waiting for a worker */
    int workers, workers_busy, workers_abandoned;
    unsigned long slow_heads;     /* connections closed for a late request head */
    long connections;             /* HTTP connections open */
    unsigned long polls_hung_up;  /* long-polls ended by their client's hang-up */
    const char *node, *store;     /* the node's name and its store's kind (the info metric) */
} gp_metrics_gauges;

/* The whole exposition as a malloc'd text (caller frees), NULL when out of memory. */
char *gp_metrics_render(gp_metrics *m, const gp_metrics_gauges *g, size_t *len);

#endif
