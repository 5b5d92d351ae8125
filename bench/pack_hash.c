/* pack_hash.c - one packing of the Bagi law, for comparing versions of the packer: the
 * disks' count, an FNV-1a hash of their bytes (the same hash: bit-identical disks) and the
 * CPU seconds of gp_pack. Small enough to run under callgrind, perf stat or cachegrind.
 * Usage: grainpack_pack_hash TARGET_DISKS default|BAND [periodic] */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "grainpack/pack.h"

/* FNV-1a, 64 bits: any change of any disk's bytes changes it (with overwhelming odds). */
static uint64_t fnv1a(const void *data, size_t n)
{
    const unsigned char *p = data;
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s TARGET_DISKS default|BAND [periodic]\n", argv[0]);
        return 2;
    }
    double target = atof(argv[1]);
    int default_rule = strcmp(argv[2], "default") == 0;
    gp_distribution dist = {.kind = GP_DIST_UNIFORM, .min = 0.06, .max = 0.42};
    gp_joint joint = {GP_JOINT_NONE, 0, 0, 0};
    /* the square holding about `target` disks, as bench.c's scaling points */
    double fill = default_rule ? 0.87 : 0.79;
    double side = sqrt(target * M_PI * gp_distribution_mean_packing_r2(&dist, &joint) / fill);
    gp_domain dom = {side, side, argc > 3 && strcmp(argv[3], "periodic") == 0 ? GP_PERIODIC_X | GP_PERIODIC_Y : 0};
    gp_pack_params params = {.domain = &dom, .dist = &dist, .joint = &joint, .seed = 1,
                             .level_band = default_rule ? 0 : (uint32_t)atoi(argv[2]),
                             .rule = default_rule ? GP_FRONT_DEFAULT : GP_FRONT_LEVEL_BAND};
    gp_packing pk;
    gp_error err;
    double t0 = bench_seconds(CLOCK_PROCESS_CPUTIME_ID);
    if (gp_pack(&params, NULL, &pk, &err))
        bench_die("gp_pack", &err);
    double t = bench_seconds(CLOCK_PROCESS_CPUTIME_ID) - t0;
    printf("%zu disks hash %016llx cpu %.3f s (%.3f us/disk)\n", pk.count,
           (unsigned long long)fnv1a(pk.disks, pk.count * sizeof *pk.disks), t, t / (double)pk.count * 1e6);
    gp_packing_free(&pk);
    return 0;
}
