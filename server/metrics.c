/* metrics.c - Prometheus counters, gauges and stage-duration histograms. */
#include "metrics.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/pipeline.h"

/* Bucket bounds in seconds: an iron job packs in about a millisecond, a 10^7-disk job in
 * minutes, so the buckets span six decades. */
static const double bucket_bounds[] = {0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1,
                                       0.25,   0.5,   1,      2.5,   5,    10,    30,    60,
                                       300};
#define NBUCKETS (sizeof bucket_bounds / sizeof bucket_bounds[0])

static const char *const outcome_names[] = {"successful", "failed",    "timed_out", "dismissed",
                                            "discarded",  "requeued",  "abandoned"};
#define NOUTCOMES (sizeof outcome_names / sizeof outcome_names[0])

/* Durations are summed in microseconds so that the sum stays an atomic integer. */
typedef struct stage_histogram {
    _Atomic(const char *) name;
    atomic_ulong buckets[NBUCKETS]; /* not cumulative; summed when rendered */
    atomic_ulong count;
    atomic_ullong sum_us;
} stage_histogram;

struct gp_metrics {
    atomic_ulong requests[600]; /* by status code */
    atomic_ulong outcomes[NOUTCOMES];
    atomic_ulong pipeline_runs;   /* gp_pipeline_run calls (and rederivations) */
    atomic_long downloads;        /* result downloads streaming now */
    atomic_ulong downloads_total; /* result downloads started */
    pthread_mutex_t stage_lock; /* taken only to claim a histogram for a new stage name */
    stage_histogram stages[GP_MAX_STAGES];
};

gp_metrics *gp_metrics_new(void)
{
    gp_metrics *m = calloc(1, sizeof *m);
    if (m)
        pthread_mutex_init(&m->stage_lock, NULL);
    return m;
}

void gp_metrics_free(gp_metrics *m)
{
    if (!m)
        return;
    pthread_mutex_destroy(&m->stage_lock);
    free(m);
}

void gp_metrics_request(gp_metrics *m, unsigned status)
{
    if (status < 600)
        atomic_fetch_add(&m->requests[status], 1);
}

void gp_metrics_pipeline_run(gp_metrics *m)
{
    atomic_fetch_add(&m->pipeline_runs, 1);
}

void gp_metrics_download(gp_metrics *m, int delta)
{
    atomic_fetch_add(&m->downloads, delta);
    if (delta > 0)
        atomic_fetch_add(&m->downloads_total, 1);
}

void gp_metrics_outcome(gp_metrics *m, const char *outcome)
{
    for (size_t i = 0; i < NOUTCOMES; i++)
        if (strcmp(outcome, outcome_names[i]) == 0)
            atomic_fetch_add(&m->outcomes[i], 1);
}

static stage_histogram *stage_slot(gp_metrics *m, const char *stage)
{
    for (int i = 0; i < GP_MAX_STAGES; i++) {
        const char *name = atomic_load(&m->stages[i].name);
        if (name && strcmp(name, stage) == 0)
            return &m->stages[i];
    }
    stage_histogram *slot = NULL;
    pthread_mutex_lock(&m->stage_lock);
    for (int i = 0; i < GP_MAX_STAGES && !slot; i++) {
        const char *name = atomic_load(&m->stages[i].name);
        if (!name)
            atomic_store(&m->stages[i].name, stage);
        if (!name || strcmp(name, stage) == 0)
            slot = &m->stages[i];
    }
    pthread_mutex_unlock(&m->stage_lock);
    return slot;
}

void gp_metrics_stage(gp_metrics *m, const char *stage, double seconds)
{
    stage_histogram *h = stage_slot(m, stage);
    if (!h)
        return;
    size_t b = 0;
    while (b < NBUCKETS && seconds > bucket_bounds[b])
        b++;
    if (b < NBUCKETS)
        atomic_fetch_add(&h->buckets[b], 1);
    atomic_fetch_add(&h->count, 1);
    atomic_fetch_add(&h->sum_us, (unsigned long long)(seconds * 1e6 + 0.5));
}

/* Writes a label value with the escapes of the text format (backslash, quote, newline). */
static void put_label_value(FILE *f, const char *value)
{
    for (const char *c = value; *c; c++) {
        if (*c == '\\' || *c == '"')
            fputc('\\', f);
        if (*c == '\n')
            fputs("\\n", f);
        else
            fputc(*c, f);
    }
}

char *gp_metrics_render(gp_metrics *m, const gp_metrics_gauges *g, size_t *len)
{
    char *text = NULL;
    FILE *f = open_memstream(&text, len);
    if (!f)
        return NULL;
    /* the node's identity as an info metric: a node's figures are told apart by the
     * scrape's own target label; this one adds the node's name and store to join on
     * (group_left), as Prometheus' *_info convention has it, without a label more on
     * every series */
    fputs("# HELP grainpack_node_info This node: its name (--node) and its job store.\n"
          "# TYPE grainpack_node_info gauge\n", f);
    fputs("grainpack_node_info{node=\"", f);
    put_label_value(f, g->node ? g->node : "");
    fprintf(f, "\",store=\"%s\"} 1\n", g->store ? g->store : "");
    fputs("# HELP grainpack_http_requests_total HTTP requests answered, by status code.\n"
          "# TYPE grainpack_http_requests_total counter\n",
          f);
    for (unsigned code = 100; code < 600; code++) {
        unsigned long n = atomic_load(&m->requests[code]);
        if (n)
            fprintf(f, "grainpack_http_requests_total{code=\"%u\"} %lu\n", code, n);
    }
    fputs("# HELP grainpack_jobs Jobs in the store, by status.\n# TYPE grainpack_jobs gauge\n", f);
    for (int s = 0; s < GP_JOB_NSTATUS; s++)
        fprintf(f, "grainpack_jobs{status=\"%s\"} %ld\n", gp_job_status_name((gp_job_status)s),
                g->jobs[s]);
    fprintf(f,
            "# HELP grainpack_queue_depth Accepted jobs waiting for a worker.\n"
            "# TYPE grainpack_queue_depth gauge\ngrainpack_queue_depth %ld\n"
            "# HELP grainpack_workers Worker threads.\n# TYPE grainpack_workers gauge\n"
            "grainpack_workers %d\n"
            "# HELP grainpack_workers_busy Workers running a job.\n"
            "# TYPE grainpack_workers_busy gauge\ngrainpack_workers_busy %d\n"
            "# HELP grainpack_workers_abandoned Worker threads given up on (told to stop, "
            "still running after seconds; another took each one's place).\n"
            "# TYPE grainpack_workers_abandoned gauge\ngrainpack_workers_abandoned %d\n",
            g->queue_depth, g->workers, g->workers_busy, g->workers_abandoned);
    fprintf(f,
            "# HELP grainpack_http_slow_heads_total Connections answered 408 and closed: their "
            "request head was not complete within --connection-timeout.\n"
            "# TYPE grainpack_http_slow_heads_total counter\ngrainpack_http_slow_heads_total %lu\n"
            "# HELP grainpack_http_long_polls_hung_up_total Long-polls ended because their "
            "client closed the connection.\n"
            "# TYPE grainpack_http_long_polls_hung_up_total counter\n"
            "grainpack_http_long_polls_hung_up_total %lu\n"
            "# HELP grainpack_http_connections HTTP connections open, waiting long-polls "
            "included.\n# TYPE grainpack_http_connections gauge\ngrainpack_http_connections %ld\n",
            g->slow_heads, g->polls_hung_up, g->connections);
    fputs("# HELP grainpack_job_runs_total Worker runs of a job, by how they ended.\n"
          "# TYPE grainpack_job_runs_total counter\n",
          f);
    for (size_t i = 0; i < NOUTCOMES; i++)
        fprintf(f, "grainpack_job_runs_total{outcome=\"%s\"} %lu\n", outcome_names[i],
                atomic_load(&m->outcomes[i]));
    fprintf(f,
            "# HELP grainpack_pipeline_runs_total Runs of the job pipeline (packing and the "
            "stages after it) in this process: workers only; a download renders what is stored.\n"
            "# TYPE grainpack_pipeline_runs_total counter\ngrainpack_pipeline_runs_total %lu\n"
            "# HELP grainpack_downloads Result downloads being streamed now.\n"
            "# TYPE grainpack_downloads gauge\ngrainpack_downloads %ld\n"
            "# HELP grainpack_downloads_total Result downloads started (304 answers not counted).\n"
            "# TYPE grainpack_downloads_total counter\ngrainpack_downloads_total %lu\n",
            atomic_load(&m->pipeline_runs), atomic_load(&m->downloads),
            atomic_load(&m->downloads_total));
    fputs("# HELP grainpack_stage_duration_seconds Wall-clock time of pipeline stages.\n"
          "# TYPE grainpack_stage_duration_seconds histogram\n",
          f);
    for (int i = 0; i < GP_MAX_STAGES; i++) {
        stage_histogram *h = &m->stages[i];
        const char *name = atomic_load(&h->name);
        if (!name)
            continue;
        unsigned long cumulative = 0;
        for (size_t b = 0; b < NBUCKETS; b++) {
            cumulative += atomic_load(&h->buckets[b]);
            fprintf(f, "grainpack_stage_duration_seconds_bucket{stage=\"%s\",le=\"%g\"} %lu\n",
                    name, bucket_bounds[b], cumulative);
        }
        unsigned long count = atomic_load(&h->count);
        fprintf(f,
                "grainpack_stage_duration_seconds_bucket{stage=\"%s\",le=\"+Inf\"} %lu\n"
                "grainpack_stage_duration_seconds_sum{stage=\"%s\"} %.6f\n"
                "grainpack_stage_duration_seconds_count{stage=\"%s\"} %lu\n",
                name, count, name, (double)atomic_load(&h->sum_us) * 1e-6, name, count);
    }
    if (fclose(f) != 0) {
        free(text);
        return NULL;
    }
    return text;
}
