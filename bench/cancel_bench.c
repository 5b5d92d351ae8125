/* cancel_bench.c - how soon the pipeline stops once its cancel flag is raised (a DELETE,
 * a job past --max-job-seconds, a stop of the daemon), in each stage: one full run is
 * timed stage by stage, then the same job is run again and again with the flag raised at
 * evenly spread moments, and the time from the flag to the pipeline's return is measured.
 * Prints markdown. Not a test: wall-clock figures, read with the load average, and the
 * CPU time the job's thread spent from the flag to its return (what the wall-clock time
 * would be on an idle core).
 * Usage: grainpack_cancel_bench [--grains N] [--runs K] [--sweeps S] */
#define _GNU_SOURCE /* getloadavg */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "machine.h"
#include "bench_util.h"

#define MAX_RUNS 200

/* What the progress callback saw: the stage running, and when each stage first
 * reported (the full run's stage boundaries). */
typedef struct watch {
    const char *stage;
    const char *stages[16];
    double first[16];
    int nstages;
} watch;

static void on_progress(void *ctx, const char *stage, double fraction)
{
    (void)fraction;
    watch *w = ctx;
    __atomic_store_n(&w->stage, stage, __ATOMIC_RELAXED);
    if (w->nstages == 0 || strcmp(w->stages[w->nstages - 1], stage) != 0) {
        if (w->nstages < 16) {
            w->stages[w->nstages] = stage;
            w->first[w->nstages++] = bench_now();
        }
    }
}

typedef struct run {
    const gp_spec *spec;
    gp_cancel_flag cancel;
    watch w;
    int rc;
    double ended, ended_cpu;
    size_t disks;
} run;

/* The CPU seconds a thread has used so far (from any thread). */
static double thread_cpu(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void *run_main(void *arg)
{
    run *r = arg;
    gp_progress progress = {on_progress, &r->w, &r->cancel};
    gp_result result;
    gp_error err;
    r->rc = gp_pipeline_run(r->spec, 0, &progress, &result, &err);
    r->ended = bench_now();
    r->ended_cpu = thread_cpu(CLOCK_THREAD_CPUTIME_ID);
    if (r->rc == 0) {
        r->disks = result.packing.count;
        gp_result_free(&result);
    }
    return NULL;
}

static double load_now(void)
{
    double load = -1.0;
    getloadavg(&load, 1);
    return load;
}

static int compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    double grains = 1e6;
    int runs = 20, sweeps = 3;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--grains") == 0)
            grains = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--runs") == 0)
            runs = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--sweeps") == 0)
            sweeps = atoi(argv[i + 1]);
    }
    runs = runs < 1 ? 1 : runs > MAX_RUNS ? MAX_RUNS : runs;
    /* radius 1, joint 0.1: about 0.82 of the area is disks of area 3.8 */
    double side = 0.0;
    for (double s = 1.0; s * s * 0.82 / 3.8 < grains; s *= 1.001)
        side = s;
    char text[512];
    snprintf(text, sizeof text,
             "{\"inputs\": {\"domain\": {\"width\": %.0f, \"height\": %.0f},"
             " \"distribution\": {\"kind\": \"constant\", \"radius\": 1},"
             " \"joint\": {\"law\": \"constant\", \"value\": 0.1},"
             " \"balance\": {\"method\": \"relocation\", \"max_iterations\": %d},"
             " \"laguerre\": {\"shrink\": \"offset\"}, \"seed\": 1}}",
             side, side, sweeps);
    gp_spec spec;
    gp_error err;
    if (gp_spec_parse(text, strlen(text), NULL, &spec, &err)) {
        fprintf(stderr, "spec: %s\n", err.message);
        return 1;
    }
    print_machine();

    run full;
    memset(&full, 0, sizeof full);
    full.spec = &spec;
    atomic_init(&full.cancel, 0);
    double t0 = bench_now();
    run_main(&full);
    double total = full.ended - t0;
    if (full.rc) {
        fprintf(stderr, "the full run failed: %d\n", full.rc);
        return 1;
    }
    printf("\nOne job of %zu disks (relocation, %d sweeps at most, Laguerre cells): %.2f s in all; "
           "stages began at", full.disks, sweeps, total);
    for (int s = 0; s < full.w.nstages; s++)
        printf("%s %s %.2f s", s ? "," : "", full.w.stages[s], full.w.first[s] - t0);
    printf(".\n\n");

    /* the flag raised at k/(runs+1) of the full run, k = 1..runs */
    double latency[MAX_RUNS], cpu[MAX_RUNS];
    const char *stage[MAX_RUNS];
    printf("| flag raised at | stage | stopped after | CPU time of the job's thread meanwhile |\n"
           "|---|---|---|---|\n");
    for (int k = 0; k < runs; k++) {
        run *r = calloc(1, sizeof *r);
        r->spec = &spec;
        r->w.stage = "pack";
        atomic_init(&r->cancel, 0);
        pthread_t thread;
        double start = bench_now(), at = total * (k + 1) / (runs + 1);
        pthread_create(&thread, NULL, run_main, r);
        struct timespec ts = {(time_t)at, (long)((at - (double)(time_t)at) * 1e9)};
        nanosleep(&ts, NULL);
        stage[k] = __atomic_load_n(&r->w.stage, __ATOMIC_RELAXED);
        clockid_t clock;
        pthread_getcpuclockid(thread, &clock);
        double raised = bench_now(), raised_cpu = thread_cpu(clock);
        atomic_store(&r->cancel, 1);
        pthread_join(thread, NULL);
        latency[k] = r->rc == GP_ECANCELED ? r->ended - raised : -1.0;
        cpu[k] = r->ended_cpu - raised_cpu;
        if (r->rc == GP_ECANCELED) /* else it returned before the flag: nothing to time */
            printf("| %.2f s | %s | %.1f ms | %.1f ms |\n", raised - start, stage[k],
                   1e3 * (r->ended - raised), 1e3 * cpu[k]);
        else
            printf("| %.2f s | %s | finished before the flag | - |\n", raised - start, stage[k]);
        free(r);
    }
    double sorted[MAX_RUNS], sorted_cpu[MAX_RUNS];
    int n = 0;
    for (int k = 0; k < runs; k++)
        if (latency[k] >= 0) {
            sorted_cpu[n] = cpu[k];
            sorted[n++] = latency[k];
        }
    qsort(sorted, (size_t)n, sizeof *sorted, compare);
    qsort(sorted_cpu, (size_t)n, sizeof *sorted_cpu, compare);
    if (n)
        printf("\n%d cancellations: median %.1f ms, max %.1f ms (CPU: median %.1f ms, max %.1f ms); "
               "load average %.2f at the end.\n", n, 1e3 * sorted[n / 2], 1e3 * sorted[n - 1],
               1e3 * sorted_cpu[n / 2], 1e3 * sorted_cpu[n - 1], load_now());
    gp_spec_free(&spec);
    return 0;
}
