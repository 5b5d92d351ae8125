/* bench.c - the packer's benchmark (not a test): the report's four cases (disks, density,
 * fidelity, median time), the level-band option against the report's rule, a scaling run
 * on the Bagi law from 10^3 to 10^7 disks with disks per second and peak memory, and the
 * packer's limits (the worst laws it accepts: their speed, and how fast a cancel stops
 * them). Prints markdown.
 * Usage: grainpack_bench [--quick] [--cpu] [--max-disks N] [--only SECTION] EXAMPLES_DIR
 * with SECTION one of cases, rules, sampling, scaling, limits; --cpu times the scaling
 * points by the process's CPU clock (one thread: the same on a quiet machine, far less
 * noisy when other work shares the cores). */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "machine.h"

#include "grainpack/pack.h"
#include "grainpack/spec.h"
#include "grainpack/stats.h"
#include "bench_util.h"

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void load(const char *dir, const char *name, gp_spec *spec)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.json", dir, name);
    gp_error err;
    if (gp_spec_load_file(path, NULL, spec, &err)) {
        fprintf(stderr, "%s: %s %s\n", path, err.pointer, err.message);
        exit(1);
    }
}

typedef struct case_result {
    size_t disks;
    double density, max_abs_z, median_ms;
    gp_pack_stats stats; /* of the first run */
} case_result;

/* Packs with `params` `runs` times (the same work each time) and keeps the median time;
 * statistics come from the first run. */
static case_result run_case(const gp_spec *spec, const gp_pack_params *params, int runs)
{
    case_result res;
    memset(&res, 0, sizeof res);
    double times[64];
    for (int i = 0; i < runs; i++) {
        gp_packing pk;
        gp_error err;
        double t0 = bench_now();
        if (gp_pack(params, NULL, &pk, &err)) {
            fprintf(stderr, "pack failed: %s\n", err.message);
            exit(1);
        }
        times[i] = bench_now() - t0;
        if (i == 0) {
            gp_pack_stats_compute(&spec->domain, &spec->dist, &pk, &res.stats);
            res.disks = pk.count;
            res.density = res.stats.packing_density;
            res.max_abs_z = res.stats.max_abs_z;
        }
        gp_packing_free(&pk);
    }
    res.median_ms = 1e3 * median(times, runs);
    return res;
}

/* Mean density and worst |z| over seeds 1..seeds. */
static void seed_average(const gp_spec *spec, gp_pack_params params, int seeds, double *mean,
                         double *zmax)
{
    *mean = 0.0;
    *zmax = 0.0;
    for (int s = 1; s <= seeds; s++) {
        params.seed = (uint64_t)s;
        gp_packing pk;
        gp_error err;
        if (gp_pack(&params, NULL, &pk, &err))
            exit(1);
        gp_pack_stats st;
        gp_pack_stats_compute(&spec->domain, &spec->dist, &pk, &st);
        *mean += st.packing_density / seeds;
        if (st.max_abs_z > *zmax)
            *zmax = st.max_abs_z;
        gp_pack_stats_free(&st);
        gp_packing_free(&pk);
    }
}

/* The report's level rule with a band. */
static gp_pack_params band_rule(const gp_spec *spec, uint32_t band)
{
    gp_pack_params params = gp_spec_pack_params(spec, 0);
    params.rule = GP_FRONT_LEVEL_BAND;
    params.level_band = band;
    return params;
}

/* The default rule made explicit (the pilots run once). */
static gp_pack_params chosen_rule(const gp_spec *spec)
{
    gp_pack_params params = gp_spec_pack_params(spec, 0);
    gp_error err;
    if (gp_pack_default_rule(&spec->dist, &spec->joint, NULL, &params.wait_levels,
                             &params.alive_quantile, &err))
        exit(1);
    params.rule = GP_FRONT_WAIT;
    return params;
}

static const struct {
    const char *name;
    const char *report; /* the report's figures (docs/method.md §3.6) */
} cases[] = {
    {"fixed", "2789 / 0.8762 / 0.04 s"},
    {"variable", "1217 / 0.8019 / 0.02 s"},
    {"iron", "987 / 0.80 / < 0.01 s"},
    {"bagi", "~39000 / 0.84 / 6 s"},
};

static void print_case_row(const char *name, const char *rule, const case_result *r, double mean,
                           double zmax, const char *report)
{
    printf("| %s | %s | %zu | %.4f | %.4f | %.2f | %.2f ms | %s |\n", name, rule, r->disks, r->density,
           mean, zmax, r->median_ms, report);
}

static void bench_cases(const char *dir, int runs, int seeds)
{
    printf("### The report's four cases (seed 1, median of %d runs)\n\n", runs);
    printf("The default's time includes its pilots (gp_pack_default_rule); the mean and |z| over seeds "
           "are those of the rule it chose.\n\n");
    printf("| case | rule | disks | packing density | mean density, %d seeds | max abs z, %d seeds | median time | report: disks / density / time |\n",
           seeds, seeds);
    printf("|---|---|---|---|---|---|---|---|\n");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        gp_spec spec;
        load(dir, cases[c].name, &spec);
        gp_pack_params def = gp_spec_pack_params(&spec, 0), chosen = chosen_rule(&spec);
        case_result r = run_case(&spec, &def, runs);
        double mean, zmax;
        seed_average(&spec, chosen, seeds, &mean, &zmax);
        char rule[64];
        snprintf(rule, sizeof rule, "default (wait %u, quantile %g)", chosen.wait_levels,
                 chosen.alive_quantile);
        print_case_row(cases[c].name, rule, &r, mean, zmax, cases[c].report);
        gp_pack_stats_free(&r.stats);
        static const uint32_t bands[] = {0, 1, 4, 16};
        for (size_t b = 0; b < sizeof bands / sizeof bands[0]; b++) {
            gp_pack_params params = band_rule(&spec, bands[b]);
            r = run_case(&spec, &params, runs);
            seed_average(&spec, params, seeds, &mean, &zmax);
            snprintf(rule, sizeof rule, "band %u%s", bands[b], bands[b] ? "" : " (the report's)");
            print_case_row(cases[c].name, rule, &r, mean, zmax, "");
            gp_pack_stats_free(&r.stats);
        }
        gp_spec_free(&spec);
    }
    printf("\n### Achieved versus target histogram (seed 1, default options)\n\n");
    for (size_t c = 1; c < sizeof cases / sizeof cases[0]; c++) {
        gp_spec spec;
        load(dir, cases[c].name, &spec);
        gp_pack_params params = gp_spec_pack_params(&spec, 0);
        case_result r = run_case(&spec, &params, 1);
        printf("**%s** (%zu disks, chi-square %.2f on %d dof, p = %.3f):\n\n", cases[c].name, r.disks,
               r.stats.chi2, r.stats.dof, r.stats.p_value);
        printf("| bin | target | achieved | z |\n|---|---|---|---|\n");
        for (size_t b = 0; b < r.stats.nbins; b++)
            printf("| [%g, %g) | %.4f | %.4f | %+.2f |\n", r.stats.bins[b].min, r.stats.bins[b].max,
                   r.stats.bins[b].target, r.stats.bins[b].achieved, r.stats.bins[b].z);
        printf("\n");
        gp_pack_stats_free(&r.stats);
        gp_spec_free(&spec);
    }
}

/* Mean density per rule on each case: every level band, every waiting candidate the
 * default chooses from, and the default's choice. */
static void bench_rules(const char *dir, int seeds)
{
    printf("### Mean packing density per rule (%d seeds; max abs z in brackets)\n\n", seeds);
    printf("| rule |");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        printf(" %s |", cases[c].name);
    printf("\n|---|");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        printf("---|");
    printf("\n");
    gp_spec spec[sizeof cases / sizeof cases[0]];
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        load(dir, cases[c].name, &spec[c]);
    static const struct {
        uint32_t wait;
        double quantile;
    } waits[] = {{1, 0.0}, {4, 0.0}, {16, 0.0}, {4, 0.2}};
    size_t nrules = (GP_SPEC_MAX_LEVEL_BAND + 1) + sizeof waits / sizeof waits[0] + 1;
    for (size_t k = 0; k < nrules; k++) {
        char label[64];
        if (k <= GP_SPEC_MAX_LEVEL_BAND)
            snprintf(label, sizeof label, "band %zu", k);
        else if (k + 1 < nrules)
            snprintf(label, sizeof label, "wait %u, quantile %g", waits[k - GP_SPEC_MAX_LEVEL_BAND - 1].wait,
                     waits[k - GP_SPEC_MAX_LEVEL_BAND - 1].quantile);
        else
            snprintf(label, sizeof label, "**default**");
        printf("| %s |", label);
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            gp_pack_params params;
            if (k <= GP_SPEC_MAX_LEVEL_BAND) {
                params = band_rule(&spec[c], (uint32_t)k);
            } else if (k + 1 < nrules) {
                params = gp_spec_pack_params(&spec[c], 0);
                params.rule = GP_FRONT_WAIT;
                params.wait_levels = waits[k - GP_SPEC_MAX_LEVEL_BAND - 1].wait;
                params.alive_quantile = waits[k - GP_SPEC_MAX_LEVEL_BAND - 1].quantile;
            } else {
                params = chosen_rule(&spec[c]);
            }
            double mean, zmax;
            seed_average(&spec[c], params, seeds, &mean, &zmax);
            printf(" %.4f (%.2f) |", mean, zmax);
            fflush(stdout);
        }
        printf("\n");
    }
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        gp_spec_free(&spec[c]);
    printf("\n");
}

/* The report's figures for the histogram cases came with its literal sampling r' = r
 * (see gp_distribution.report_same_draw); packing the same cases that way shows how much
 * of the gap to its densities that sampling accounts for. */
static void bench_report_sampling(const char *dir, int seeds)
{
    printf("### The report's within-bin sampling (r' = r) against ours (independent draw)\n\n");
    printf("| case | level band | sampling | mean disks | mean packing density, %d seeds |\n", seeds);
    printf("|---|---|---|---|---|\n");
    static const char *const names[] = {"variable", "iron"};
    for (size_t c = 0; c < 2; c++) {
        gp_spec spec;
        load(dir, names[c], &spec);
        for (uint32_t band = 0; band <= 1; band++) {
            for (int same = 0; same <= 1; same++) {
                spec.dist.report_same_draw = same;
                double density = 0.0, disks = 0.0;
                for (int s = 1; s <= seeds; s++) {
                    gp_pack_params params = band_rule(&spec, band);
                    params.seed = (uint64_t)s;
                    gp_packing pk;
                    gp_error err;
                    if (gp_pack(&params, NULL, &pk, &err))
                        exit(1);
                    density += pk.fill_area / gp_domain_area(&spec.domain) / seeds;
                    disks += (double)pk.count / seeds;
                    gp_packing_free(&pk);
                }
                printf("| %s | %u | %s | %.0f | %.4f |\n", names[c], band,
                       same ? "report (r' = r)" : "independent (ours)", disks, density);
            }
        }
        gp_spec_free(&spec);
    }
    printf("\n");
}

/* The clock of the scaling points: wall clock, or with --cpu the process's CPU time. */
static clockid_t scaling_clock = CLOCK_MONOTONIC;

/* One scaling point, in a child process so that its peak memory is its own: the default
 * rule (its pilots included in the time), or the report's rule with `band`. */
static void scale_point(double target, int default_rule, uint32_t band)
{
    int fds[2];
    if (pipe(fds))
        exit(1);
    pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        struct rusage before, after;
        getrusage(RUSAGE_SELF, &before);
        gp_distribution dist = {.kind = GP_DIST_UNIFORM, .min = 0.06, .max = 0.42};
        gp_joint joint = {GP_JOINT_NONE, 0, 0, 0};
        /* the Bagi law fills about 0.87 of the domain with the default rule and 0.79 with
         * the report's: pick the square whose area holds `target` disks */
        double fill = default_rule ? 0.87 : 0.79;
        double side = sqrt(target * M_PI * gp_distribution_mean_packing_r2(&dist, &joint) / fill);
        gp_domain dom = {side, side, 0};
        gp_pack_params params = {.domain = &dom, .dist = &dist, .joint = &joint, .seed = 1,
                                 .level_band = band,
                                 .rule = default_rule ? GP_FRONT_DEFAULT : GP_FRONT_LEVEL_BAND};
        gp_packing pk;
        gp_error err;
        double t0 = bench_seconds(scaling_clock);
        int rc = gp_pack(&params, NULL, &pk, &err);
        double t = bench_seconds(scaling_clock) - t0;
        getrusage(RUSAGE_SELF, &after);
        double bytes = (double)(after.ru_maxrss - before.ru_maxrss) * 1024.0;
        char line[256];
        int n = snprintf(line, sizeof line, "%d %zu %.6f %.0f %.4f\n", rc, pk.count, t, bytes,
                         pk.fill_area / (side * side));
        if (write(fds[1], line, (size_t)n) != n)
            _exit(1);
        _exit(0);
    }
    close(fds[1]);
    char buf[256] = {0};
    ssize_t got = read(fds[0], buf, sizeof buf - 1);
    close(fds[0]);
    waitpid(pid, NULL, 0);
    int rc;
    size_t count;
    double t, bytes, density;
    if (got <= 0 || sscanf(buf, "%d %zu %lf %lf %lf", &rc, &count, &t, &bytes, &density) != 5 || rc) {
        printf("| %.0e | failed | | | | |\n", target);
        return;
    }
    char rule[32];
    snprintf(rule, sizeof rule, default_rule ? "default" : "band %u", band);
    printf("| %s | %zu | %.4f | %.3f s | %.2f M/s | %.0f |\n", rule, count, density, t,
           (double)count / t / 1e6, bytes / (double)count);
    fflush(stdout);
}

static void bench_scaling(double max_disks)
{
    printf("### Scaling on the Bagi law (uniform radii 0.06-0.42, no joint, seed 1)\n\n");
    printf("Peak memory is the growth of the process's maximum resident set during the run.\n\n");
    printf("| rule | disks | packing density | time | disks per second | peak bytes per disk |\n");
    printf("|---|---|---|---|---|---|\n");
    for (int def = 1; def >= 0; def--)
        for (double n = 1e3; n <= max_disks * 1.01; n *= 10)
            scale_point(n, def, 0);
    printf("\n");
}

/* A law of two narrow bins, the small one drawn with probability p_small, in a square. */
typedef struct two_bins {
    gp_bin bins[2];
    gp_distribution dist;
    gp_domain dom;
} two_bins;

static void two_bins_init(two_bins *tb, double r_small, double r_large, double p_small, double side)
{
    tb->bins[0] = (gp_bin){r_small, 1.05 * r_small, p_small};
    tb->bins[1] = (gp_bin){r_large / 1.05, r_large, 1.0 - p_small};
    tb->dist = (gp_distribution){.kind = GP_DIST_HISTOGRAM, .nbins = 2, .bins = tb->bins};
    tb->dom = (gp_domain){side, side, 0};
    if (gp_distribution_prepare(&tb->dist))
        exit(1);
}

typedef struct cancel_run {
    const gp_pack_params *params;
    gp_cancel_flag flag;
    int rc;
    double returned; /* when gp_pack returned */
} cancel_run;

static void *cancel_thread(void *arg)
{
    cancel_run *cr = arg;
    gp_progress progress = {NULL, NULL, &cr->flag};
    gp_packing pk;
    gp_error err;
    cr->rc = gp_pack(cr->params, &progress, &pk, &err);
    cr->returned = bench_now();
    if (cr->rc == 0)
        gp_packing_free(&pk);
    return NULL;
}

/* The worst laws the packer takes, at its radius-ratio cap: disks per second, and the
 * time from raising the cancel flag to gp_pack's return, after `after` seconds of work. */
static void bench_limits(int quick)
{
    static const struct {
        const char *label;
        double r_small, r_large, p_small, side;
    } laws[] = {
        {"ratio 10, small 99.999%", 0.1, 1.0, 0.99999, 40},
        {"ratio 100, half small", 0.01, 1.0, 0.5, 400},
        {"ratio 100, small 99.9%", 0.01, 1.0, 0.999, 30},
        {"ratio 100, small 99.999%", 0.01, 1.0, 0.99999, 30},
    };
    double after = quick ? 0.2 : 1.0;
    printf("### The packer's limits: the worst laws it accepts\n\n");
    printf("Two narrow bins (width 5%%) at the cap of GP_PACK_MAX_RADIUS_RATIO = %g; the cancel flag "
           "raised after %.1f s of packing (or when the packing ended first).\n\n",
           GP_PACK_MAX_RADIUS_RATIO, after);
    printf("| law | domain | disks | time | disks per second | time to stop after cancel |\n");
    printf("|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < sizeof laws / sizeof laws[0]; i++) {
        two_bins tb;
        two_bins_init(&tb, laws[i].r_small, laws[i].r_large, laws[i].p_small, laws[i].side);
        gp_joint joint = {GP_JOINT_NONE, 0, 0, 0};
        gp_pack_params params = {.domain = &tb.dom, .dist = &tb.dist, .joint = &joint, .seed = 1,
                                 .rule = GP_FRONT_DEFAULT};
        /* a full run for the speed, capped so that the slowest stays within a minute */
        gp_packing pk;
        gp_error err;
        params.max_disks = quick ? 20000 : 200000;
        double t0 = bench_seconds(scaling_clock);
        int rc = gp_pack(&params, NULL, &pk, &err);
        double t = bench_seconds(scaling_clock) - t0;
        size_t count = rc == 0 ? pk.count : params.max_disks;
        if (rc == 0)
            gp_packing_free(&pk);
        else if (rc != GP_ETOOBIG) {
            printf("| %s | failed: %s | | | | |\n", laws[i].label, err.message);
            continue;
        }
        params.max_disks = 0;
        cancel_run cr = {&params, 0, 0, 0.0};
        atomic_init(&cr.flag, 0);
        pthread_t th;
        if (pthread_create(&th, NULL, cancel_thread, &cr))
            exit(1);
        struct timespec nap = {(time_t)after, (long)((after - floor(after)) * 1e9)};
        nanosleep(&nap, NULL);
        double raised = bench_now();
        atomic_store(&cr.flag, 1);
        pthread_join(th, NULL);
        char stop[64];
        if (cr.rc == GP_ECANCELED)
            snprintf(stop, sizeof stop, "%.2f ms", 1e3 * (cr.returned - raised));
        else
            snprintf(stop, sizeof stop, "finished first");
        printf("| %s | %g x %g | %zu%s | %.2f s | %.0f | %s |\n", laws[i].label, laws[i].side,
               laws[i].side, count, rc == GP_ETOOBIG ? " (capped)" : "", t, (double)count / t, stop);
        fflush(stdout);
        free(tb.dist.cdf);
    }
    printf("\n");
}

int main(int argc, char **argv)
{
    int quick = 0;
    double max_disks = 1e7;
    const char *dir = NULL, *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--max-disks") == 0 && i + 1 < argc)
            max_disks = atof(argv[++i]);
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (strcmp(argv[i], "--cpu") == 0)
            scaling_clock = CLOCK_PROCESS_CPUTIME_ID;
        else
            dir = argv[i];
    }
    if (!dir) {
        fprintf(stderr, "usage: grainpack_bench [--quick] [--cpu] [--max-disks N] [--only SECTION] "
                        "EXAMPLES_DIR\n");
        return 2;
    }
    print_machine();
    if (scaling_clock == CLOCK_PROCESS_CPUTIME_ID)
        printf("The scaling points are timed in CPU seconds of the process (--cpu), not wall clock.\n\n");
    if (!only || strcmp(only, "cases") == 0)
        bench_cases(dir, quick ? 3 : 15, quick ? 5 : 50);
    if (!only || strcmp(only, "rules") == 0)
        bench_rules(dir, quick ? 5 : 50);
    if (!only || strcmp(only, "sampling") == 0)
        bench_report_sampling(dir, quick ? 5 : 50);
    if (!only || strcmp(only, "scaling") == 0)
        bench_scaling(quick ? 1e5 : max_disks);
    if (!only || strcmp(only, "limits") == 0)
        bench_limits(quick);
    return 0;
}
