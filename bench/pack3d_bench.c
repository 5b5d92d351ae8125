/* pack3d_bench.c - the 3D packer's figures (bench/PACK3D.md): density and time of the
 * three reference laws in boxes of 20 largest diameters under both orders of the front,
 * and the rate and memory at 10^5 and 10^6 spheres of one radius. --fingerprint prints
 * instead a hash of the reference packings' spheres (a pure speed change must leave them
 * to the bit), --case LAW packs one small box of a law alone (for callgrind's instruction
 * counts: one, bagi or iron; million: the 10^6 packing of one radius of --fingerprint),
 * --periodic the reference laws' rows in a cube periodic along all three axes beside the
 * walled one (level rule; docs/3d.md §11).
 * Usage: grainpack_pack3d_bench [--seeds N] [--max-spheres N] [--fingerprint] [--case LAW]
 *        [--periodic] [EXAMPLES_DIR] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_util.h"
#include "grainpack/pack3d.h"
#include "grainpack/spec.h"
#include "machine.h"

/* The peak resident set of the process (VmHWM) in bytes; with reset, first brings the
 * peak down to the current resident set (Linux's clear_refs "5"). */
static double peak_rss(int reset)
{
    if (reset) {
        FILE *f = fopen("/proc/self/clear_refs", "w");
        if (f) {
            fputs("5", f);
            fclose(f);
        }
    }
    double kb = 0.0;
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmHWM:", 6) == 0)
            kb = atof(line + 6);
    if (f)
        fclose(f);
    return kb * 1024.0;
}

static double pack_once(const gp_box *box, const gp_distribution *dist, uint64_t seed,
                        gp_pack3d_order order, gp_packing3d *out, double *cpu)
{
    gp_pack3d_params params = {box, dist, NULL, seed, 0, order};
    gp_error err;
    double c0 = bench_seconds(CLOCK_PROCESS_CPUTIME_ID), t0 = bench_now();
    if (gp_pack3d(&params, NULL, out, &err))
        bench_die("gp_pack3d", &err);
    double t = bench_now() - t0;
    *cpu = bench_seconds(CLOCK_PROCESS_CPUTIME_ID) - c0;
    return t;
}

/* The law's rows: mean and spread of the density over the seeds, spheres, times; both
 * orders in a walled box, or with `periodic` the level rule in a walled box then in a
 * fully periodic one. */
static void law_row(const char *name, const gp_distribution *dist, double side, int seeds, int periodic)
{
    static const char *const orders[3] = {"level (walls first)", "lowest first", "level, periodic cube"};
    for (int o = 0; o < 2; o++) {
        int row = periodic ? 2 * o : o;
        gp_box box = {side, side, side, row == 2 ? GP_PERIODIC_X | GP_PERIODIC_Y | GP_PERIODIC_Z : 0};
        double sum = 0, sum2 = 0, cpu_sum = 0, wall_sum = 0, lo = 1, hi = 0;
        size_t n = 0;
        for (int s = 1; s <= seeds; s++) {
            gp_packing3d out;
            double cpu, wall = pack_once(&box, dist, (uint64_t)s, row == 1 ? GP_PACK3D_LOWEST : GP_PACK3D_LEVEL,
                                         &out, &cpu);
            double d = out.fill_volume / (side * side * side);
            sum += d;
            sum2 += d * d;
            lo = fmin(lo, d);
            hi = fmax(hi, d);
            cpu_sum += cpu;
            wall_sum += wall;
            n += out.count;
            gp_packing3d_free(&out);
        }
        double mean = sum / seeds, sd = seeds > 1 ? sqrt(fmax(0, (sum2 - seeds * mean * mean) / (seeds - 1))) : 0;
        printf("| %s | %s | %g | %.0f | %.4f +- %.4f (%.4f-%.4f) | %.1f ms | %.1f ms | %.0f |\n", name,
               orders[row], side, (double)n / seeds, mean, sd, lo, hi, 1e3 * wall_sum / seeds,
               1e3 * cpu_sum / seeds, (double)n / cpu_sum);
        fflush(stdout);
    }
}

/* The side of the cube of the scaling rows (and of the 10^6 fingerprint): one radius 0.5,
 * `target` spheres at a density of ~0.62. */
static double scaling_side(double target)
{
    return cbrt(target * (4.0 / 3.0 * M_PI * 0.125) / 0.62);
}

/* Runs in a child process of its own, forked before any other packing (so that no freed
 * heap of the parent's is reused unseen), with the peak resident set reset first. */
static void scaling_row(const gp_distribution *dist, double target)
{
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0) {
        perror("fork");
        exit(1);
    }
    if (pid > 0) {
        int status;
        waitpid(pid, &status, 0);
        return;
    }
    double side = scaling_side(target);
    gp_box box = {side, side, side, 0};
    double before = peak_rss(1);
    gp_packing3d out;
    double cpu, wall = pack_once(&box, dist, 1, GP_PACK3D_LEVEL, &out, &cpu);
    double after = peak_rss(0);
    printf("| %.0f | %.2f | %zu | %.4f | %.2f s | %.2f s | %.0f | %.0f | %.0f |\n", target, side, out.count,
           out.fill_volume / (side * side * side), wall, cpu, out.count / wall, out.count / cpu,
           (after - before) / (double)out.count);
    fflush(stdout);
    gp_packing3d_free(&out);
    _exit(0);
}

/* FNV-1a over the bytes of the spheres (centres and radii as stored, so to the bit). */
static unsigned long long spheres_hash(const gp_packing3d *out)
{
    const unsigned char *b = (const unsigned char *)out->spheres;
    unsigned long long h = 1469598103934665603ULL;
    for (size_t i = 0; i < out->count * sizeof *out->spheres; i++) {
        h ^= b[i];
        h *= 1099511628211ULL;
    }
    return h;
}

/* One packing's line: its spheres, density, tries and hash. */
static void fingerprint_row(const char *name, const gp_distribution *dist, double side, uint64_t seed,
                            gp_pack3d_order order)
{
    gp_box box = {side, side, side, 0};
    gp_packing3d out;
    double cpu;
    pack_once(&box, dist, seed, order, &out, &cpu);
    printf("%s side %g seed %llu order %d: %zu spheres density %.6f attempts %llu triangles %llu hash %016llx\n",
           name, side, (unsigned long long)seed, (int)order, out.count, out.fill_volume / (side * side * side),
           (unsigned long long)out.attempts, (unsigned long long)out.triangles, spheres_hash(&out));
    fflush(stdout);
    gp_packing3d_free(&out);
}

int main(int argc, char **argv)
{
    int seeds = 5;
    double max_spheres = 1e6;
    const char *examples = "examples", *one_case = NULL;
    int fingerprint = 0, periodic = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--seeds") && i + 1 < argc)
            seeds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--fingerprint"))
            fingerprint = 1;
        else if (!strcmp(argv[i], "--periodic"))
            periodic = 1;
        else if (!strcmp(argv[i], "--case") && i + 1 < argc)
            one_case = argv[++i];
        else if (!strcmp(argv[i], "--max-spheres") && i + 1 < argc)
            max_spheres = atof(argv[++i]);
        else
            examples = argv[i];
    }
    print_machine();
    gp_distribution one = {.kind = GP_DIST_CONSTANT, .radius = 0.5};
    gp_distribution bagi = {.kind = GP_DIST_UNIFORM, .min = 0.06, .max = 0.42};
    char path[4096];
    snprintf(path, sizeof path, "%s/iron.json", examples);
    gp_spec iron;
    gp_error err;
    if (gp_spec_load_file(path, NULL, &iron, &err))
        bench_die(path, &err);

    /* the boxes of the instruction counts (bench/PACK3D.md): 16 diameters, 12 largest ones
     * for the Bagi law and 10 for iron, a few thousand spheres each */
    if (one_case) {
        if (!strcmp(one_case, "one"))
            fingerprint_row("one radius 0.5", &one, 16.0, 1, GP_PACK3D_LEVEL);
        else if (!strcmp(one_case, "bagi"))
            fingerprint_row("3D Bagi", &bagi, 12 * 0.84, 1, GP_PACK3D_LEVEL);
        else if (!strcmp(one_case, "iron"))
            fingerprint_row("iron", &iron.dist, 10 * 16.0, 1, GP_PACK3D_LEVEL);
        else if (!strcmp(one_case, "million"))
            fingerprint_row("one radius 0.5, 10^6", &one, scaling_side(1e6), 1, GP_PACK3D_LEVEL);
        else {
            fprintf(stderr, "unknown case %s (one, bagi, iron or million)\n", one_case);
            return 2;
        }
        gp_spec_free(&iron);
        return 0;
    }
    if (fingerprint) {
        for (int o = 0; o < 2; o++) {
            fingerprint_row("one radius 0.5", &one, 20.0, 1, (gp_pack3d_order)o);
            for (int s = 1; s <= 3; s++)
                fingerprint_row("3D Bagi", &bagi, 20 * 0.84, (uint64_t)s, (gp_pack3d_order)o);
            for (int s = 1; s <= 2; s++)
                fingerprint_row("iron", &iron.dist, 20 * 16.0, (uint64_t)s, (gp_pack3d_order)o);
        }
        if (max_spheres >= 1e6)
            fingerprint_row("one radius 0.5, 10^6", &one, scaling_side(1e6), 1, GP_PACK3D_LEVEL);
        gp_spec_free(&iron);
        return 0;
    }

    if (!periodic) { /* with --periodic the laws' rows alone */
        printf("\n| spheres asked | box side | spheres | density | wall | CPU | spheres/s (wall) | spheres/s (CPU) | bytes per sphere (peak RSS growth) |\n");
        printf("|---|---|---|---|---|---|---|---|---|\n");
        for (double n = 1e5; n <= max_spheres * 1.01; n *= 10)
            scaling_row(&one, n);
    }
    printf("\n| law | order | box side | spheres | density (mean +- sd, min-max over %d seeds) | wall | CPU | spheres per CPU s |\n",
           seeds);
    printf("|---|---|---|---|---|---|---|---|\n");
    law_row("one radius 0.5", &one, 20.0, 2, periodic); /* the same packing for every seed */
    law_row("uniform 0.06-0.42 (3D Bagi)", &bagi, 20 * 0.84, seeds, periodic);
    law_row("iron histogram, 2-8 (no joint)", &iron.dist, 20 * 16.0, seeds, periodic);

    gp_spec_free(&iron);
    return 0;
}
