/* geom_bench.c - the benchmark of the geometry stages (not a test): the balance criterion
 * F before and after each method on the report's cases beside the report's figures, the
 * triangulation kept up by flips against rebuilt, the triangulation build, relocation and
 * Laguerre cells at up to 10^6 grains with time and peak memory. Prints markdown.
 * Usage: grainpack_geom_bench [--quick] [--cpu] [--grains N] [--only TABLES] EXAMPLES_DIR
 * TABLES: a comma-separated subset of quality, cells, updates, relocation (default: all). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "grainpack/balance.h"
#include "grainpack/laguerre.h"
#include "grainpack/pack.h"
#include "grainpack/spec.h"
#include "machine.h"
#include "bench_util.h"

/* The clock of every timing: wall clock, or with --cpu the process's CPU time (one thread:
 * the same on a quiet machine, and far less noisy when other work shares the cores). */
static clockid_t timing_clock = CLOCK_MONOTONIC;

static void load(const char *dir, const char *name, gp_spec *spec)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.json", dir, name);
    gp_error err;
    if (gp_spec_load_file(path, NULL, spec, &err))
        bench_die(path, &err);
}

static void pack(const gp_spec *spec, gp_packing *pk)
{
    gp_pack_params params = gp_spec_pack_params(spec, 0);
    gp_error err;
    if (gp_pack(&params, NULL, pk, &err))
        bench_die("pack", &err);
}

/* Overlapping pairs by brute force over x-sorted disks (independent of the grid). */
static int compare_x(const void *a, const void *b)
{
    double xa = ((const gp_disk *)a)->x, xb = ((const gp_disk *)b)->x;
    return xa < xb ? -1 : (xa > xb ? 1 : 0);
}

static size_t overlaps(const gp_disk *disks, size_t n)
{
    gp_disk *d = malloc(n * sizeof *d);
    memcpy(d, disks, n * sizeof *d);
    qsort(d, n, sizeof *d, compare_x);
    double R_max = 0.0;
    for (size_t i = 0; i < n; i++)
        R_max = fmax(R_max, d[i].R);
    size_t bad = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t k = i + 1; k < n && d[k].x - d[i].x < d[i].R + R_max; k++)
            bad += hypot(d[k].x - d[i].x, d[k].y - d[i].y) < (d[i].R + d[k].R) * (1.0 - GP_CONTACT_RTOL);
    free(d);
    return bad;
}

typedef struct balanced {
    gp_balance_result br;
    double seconds;
    size_t overlaps;
} balanced;

/* Balances a copy of the packing with `method` and `max_step`. */
static balanced balance_copy(const gp_spec *spec, const gp_packing *pk, gp_balance_method method,
                             double max_step, uint32_t cap, gp_rt_update update)
{
    balanced out;
    gp_disk *d = malloc(pk->count * sizeof *d);
    memcpy(d, pk->disks, pk->count * sizeof *d);
    gp_error err;
    gp_rt *rt;
    if (gp_rt_build(d, pk->count, NULL, &rt, &err))
        bench_die("triangulation", &err);
    gp_balance_params params = {method, cap, max_step, update};
    double t0 = bench_seconds(timing_clock);
    if (gp_balance(&spec->domain, d, pk->count, rt, &params, NULL, &out.br, &err))
        bench_die("balance", &err);
    out.seconds = bench_seconds(timing_clock) - t0;
    out.overlaps = overlaps(d, pk->count);
    gp_rt_free(rt);
    free(d);
    return out;
}

static void bench_quality(const char *dir)
{
    static const struct {
        const char *name, *report;
    } cases[] = {{"fixed", "1.962 / 1.87 / 1.33"}, {"variable", "(not given)"}, {"iron", "(not given)"}};
    printf("### The balance criterion F on the report's cases (seed 1)\n\n");
    printf("F_max and mean F over the interior centres; *relocation* uses our default first step "
           "(the whole way, max_step %.2f), *relocation, report's steps* starts at w = %.2f as "
           "report Algorithm 3 does. Overlaps are counted by an independent sweep after each run.\n\n",
           GP_BALANCE_DEFAULT_MAX_STEP, GP_BALANCE_REPORT_MAX_STEP);
    printf("| case | grains | before | Laplacian | relocation | relocation, report's steps | "
           "overlaps after | sweeps (Laplacian / relocation) | report F_max: before / Laplacian / relocation |\n");
    printf("|---|---|---|---|---|---|---|---|---|\n");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        gp_spec spec;
        load(dir, cases[c].name, &spec);
        gp_packing pk;
        pack(&spec, &pk);
        balanced lap = balance_copy(&spec, &pk, GP_BALANCE_LAPLACIAN, 0.0, 0, GP_RT_UPDATE_FLIPS);
        balanced rel = balance_copy(&spec, &pk, GP_BALANCE_RELOCATION, 0.0, 0, GP_RT_UPDATE_FLIPS);
        balanced rep = balance_copy(&spec, &pk, GP_BALANCE_RELOCATION, GP_BALANCE_REPORT_MAX_STEP, 0,
                                    GP_RT_UPDATE_FLIPS);
        printf("| %s | %zu | %.3f / %.4f | %.3f / %.4f | %.3f / %.4f | %.3f / %.4f | %zu / %zu / %zu | "
               "%u / %u | %s |\n",
               cases[c].name, pk.count, lap.br.before.max, lap.br.before.mean, lap.br.after.max,
               lap.br.after.mean, rel.br.after.max, rel.br.after.mean, rep.br.after.max,
               rep.br.after.mean, lap.overlaps, rel.overlaps, rep.overlaps, lap.br.sweeps,
               rel.br.sweeps, cases[c].report);
        gp_balance_result_free(&lap.br);
        gp_balance_result_free(&rel.br);
        gp_balance_result_free(&rep.br);
        gp_packing_free(&pk);
        gp_spec_free(&spec);
    }
    printf("\nCells are F_max / mean F.\n\n");
}

/* The variable law of the report (joint 0.1) in a square holding about `grains`. */
static void scaled_variable(const char *dir, double grains, gp_spec *spec)
{
    load(dir, "variable", spec);
    /* the report's 50 x 50 holds about 1260 grains */
    double side = 50.0 * sqrt(grains / 1260.0);
    spec->domain = (gp_domain){side, side, 0};
}

/* Runs `work` in a child process and reports its peak resident memory growth. */
typedef void (*child_work)(const gp_spec *spec, const gp_packing *pk, const void *ctx, double *out);

static void in_child(child_work work, const gp_spec *spec, const gp_packing *pk, const void *ctx,
                     double *out, int nout, double *peak_bytes)
{
    int fds[2];
    if (pipe(fds))
        exit(1);
    pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        struct rusage before, after;
        getrusage(RUSAGE_SELF, &before);
        double values[16];
        work(spec, pk, ctx, values);
        getrusage(RUSAGE_SELF, &after);
        values[nout] = (double)(after.ru_maxrss - before.ru_maxrss) * 1024.0;
        ssize_t size = (ssize_t)((nout + 1) * sizeof(double));
        if (write(fds[1], values, (size_t)size) != size)
            _exit(1);
        _exit(0);
    }
    close(fds[1]);
    double values[16];
    ssize_t size = (ssize_t)((nout + 1) * sizeof(double));
    if (read(fds[0], values, (size_t)size) != size)
        exit(1);
    close(fds[0]);
    waitpid(pid, NULL, 0);
    memcpy(out, values, (size_t)nout * sizeof *out);
    *peak_bytes = values[nout];
}

/* out: seconds to build */
static void work_build(const gp_spec *spec, const gp_packing *pk, const void *ctx, double *out)
{
    (void)spec;
    (void)ctx;
    gp_error err;
    gp_rt *rt;
    double t0 = bench_seconds(timing_clock);
    if (gp_rt_build(pk->disks, pk->count, NULL, &rt, &err))
        bench_die("triangulation", &err);
    out[0] = bench_seconds(timing_clock) - t0;
    gp_rt_free(rt);
}

/* out: build seconds, cells seconds */
static void work_laguerre(const gp_spec *spec, const gp_packing *pk, const void *ctx, double *out)
{
    (void)ctx;
    gp_error err;
    gp_rt *rt;
    double t0 = bench_seconds(timing_clock);
    if (gp_rt_build(pk->disks, pk->count, NULL, &rt, &err))
        bench_die("triangulation", &err);
    out[0] = bench_seconds(timing_clock) - t0;
    gp_laguerre_params params = {GP_SHRINK_OFFSET, 0};
    gp_cells cells;
    t0 = bench_seconds(timing_clock);
    if (gp_laguerre(&spec->domain, pk->disks, pk->count, rt, &params, NULL, &cells, &err))
        bench_die("laguerre", &err);
    out[1] = bench_seconds(timing_clock) - t0;
    gp_cells_free(&cells);
    gp_rt_free(rt);
}

/* How a relocation run is asked for. */
typedef struct relocation_run {
    gp_rt_update update;
    uint32_t cap;
} relocation_run;

/* out: seconds, sweeps, stop, F_max before and after, mean F before and after, best sweep,
 * reinsertions, rebuilds, overlaps */
static void work_relocation(const gp_spec *spec, const gp_packing *pk, const void *ctx, double *out)
{
    const relocation_run *run = ctx;
    balanced b = balance_copy(spec, pk, GP_BALANCE_RELOCATION, 0.0, run->cap, run->update);
    out[0] = b.seconds;
    out[1] = b.br.sweeps;
    out[2] = b.br.stop;
    out[3] = b.br.before.max;
    out[4] = b.br.after.max;
    out[5] = b.br.before.mean;
    out[6] = b.br.after.mean;
    out[7] = b.br.best_sweep;
    out[8] = (double)b.br.triangulation.reinserted;
    out[9] = (double)b.br.triangulation.rebuilds;
    out[10] = (double)b.overlaps;
    gp_balance_result_free(&b.br);
}

static double median3(double a, double b, double c)
{
    return fmax(fmin(a, b), fmin(fmax(a, b), c));
}

/* Whether table `name` is asked for: every table when `only` is NULL. */
static int wanted(const char *only, const char *name)
{
    return !only || strstr(only, name) != NULL;
}

static void bench_cells(const char *dir, double max_grains)
{
    printf("### Stages on the report's variable law (joint 0.1) scaled up (seed 1)\n\n");
    printf("Peak memory is the growth of the maximum resident set of a child process running the "
           "stage on an existing packing. The Laguerre time includes building its triangulation.\n\n");
    printf("| grains | triangulation build (median of 3) | build MB | Laguerre cells (offset) | cells per second | "
           "Laguerre / build | Laguerre MB |\n|---|---|---|---|---|---|---|\n");
    for (double g = 1e4; g <= max_grains * 1.01; g *= 10) {
        gp_spec spec;
        scaled_variable(dir, g, &spec);
        gp_packing pk;
        pack(&spec, &pk);
        double t[3], mb_build, lag[2], mb_lag;
        for (int k = 0; k < 3; k++)
            in_child(work_build, &spec, &pk, NULL, &t[k], 1, &mb_build);
        in_child(work_laguerre, &spec, &pk, NULL, lag, 2, &mb_lag);
        double build = median3(t[0], t[1], t[2]);
        printf("| %zu | %.3f s | %.0f | %.3f s | %.2f M/s | %.2f | %.0f |\n", pk.count, build,
               mb_build / 1e6, lag[1], (double)pk.count / lag[1] / 1e6, (lag[0] + lag[1]) / build,
               mb_lag / 1e6);
        fflush(stdout);
        gp_packing_free(&pk);
        gp_spec_free(&spec);
    }
    printf("\n");
}

static void bench_updates(const char *dir, double max_grains, int quick)
{
    printf("### Relocation: the triangulation kept up by flips or rebuilt after each sweep\n\n");
    printf("The same sweeps either way (capped at %d here); the difference is the update.\n\n", quick ? 5 : 10);
    printf("| grains | update | sweeps | time | per sweep | reinsertions | rebuilds | MB |\n|---|---|---|---|---|---|---|---|\n");
    for (double g = 1e5; g <= max_grains * 1.01; g *= 10) {
        gp_spec spec;
        scaled_variable(dir, g, &spec);
        gp_packing pk;
        pack(&spec, &pk);
        for (int mode = GP_RT_UPDATE_FLIPS; mode <= GP_RT_UPDATE_REBUILD; mode++) {
            relocation_run run = {(gp_rt_update)mode, quick ? 5 : 10};
            double v[11], mb;
            in_child(work_relocation, &spec, &pk, &run, v, 11, &mb);
            printf("| %zu | %s | %.0f | %.2f s | %.3f s | %.0f | %.0f | %.0f |\n", pk.count,
                   mode == GP_RT_UPDATE_FLIPS ? "flips" : "rebuild", v[1], v[0], v[0] / v[1], v[8], v[9],
                   mb / 1e6);
            fflush(stdout);
        }
        gp_packing_free(&pk);
        gp_spec_free(&spec);
    }
    printf("\n");
}

static void bench_relocation(const char *dir, double max_grains)
{
    printf("### Relocation to the end (default options: flips, stop when a sweep moves nothing, %d "
           "sweeps bring no progress, or from %d interior centres %d sweeps no meaningful progress)\n\n",
           GP_BALANCE_STALL_SWEEPS, GP_BALANCE_STEADY_MIN_INTERIOR, GP_BALANCE_STEADY_SWEEPS);
    printf("| grains | sweeps | stop | best sweep | time | per sweep | F_max | mean F | overlaps after | MB |\n"
           "|---|---|---|---|---|---|---|---|---|---|\n");
    for (double g = 1e4; g <= max_grains * 1.01; g *= 10) {
        gp_spec spec;
        scaled_variable(dir, g, &spec);
        gp_packing pk;
        pack(&spec, &pk);
        relocation_run run = {GP_RT_UPDATE_FLIPS, 0};
        double v[11], mb;
        in_child(work_relocation, &spec, &pk, &run, v, 11, &mb);
        printf("| %zu | %.0f | %s | %.0f | %.1f s | %.3f s | %.3f -> %.3f | %.4f -> %.4f | %.0f | %.0f |\n",
               pk.count, v[1], gp_balance_stop_name((gp_balance_stop)v[2]), v[7], v[0], v[0] / v[1],
               v[3], v[4], v[5], v[6], v[10], mb / 1e6);
        fflush(stdout);
        gp_packing_free(&pk);
        gp_spec_free(&spec);
    }
    printf("\n");
}

int main(int argc, char **argv)
{
    int quick = 0;
    double grains = 1e6;
    const char *dir = NULL, *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--grains") == 0 && i + 1 < argc)
            grains = atof(argv[++i]);
        else if (strcmp(argv[i], "--cpu") == 0)
            timing_clock = CLOCK_PROCESS_CPUTIME_ID;
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
            only = argv[++i];
        else
            dir = argv[i];
    }
    if (!dir) {
        fprintf(stderr, "usage: grainpack_geom_bench [--quick] [--cpu] [--grains N] [--only TABLES] "
                        "EXAMPLES_DIR\n");
        return 2;
    }
    print_machine();
    if (timing_clock == CLOCK_PROCESS_CPUTIME_ID)
        printf("Times are CPU seconds of the process (--cpu), not wall clock.\n\n");
    if (wanted(only, "quality"))
        bench_quality(dir);
    double max_grains = quick ? 1e5 : grains;
    if (wanted(only, "cells"))
        bench_cells(dir, max_grains);
    if (wanted(only, "updates"))
        bench_updates(dir, max_grains, quick);
    if (wanted(only, "relocation"))
        bench_relocation(dir, max_grains);
    return 0;
}
