/* writers_before.c - the writers as they were up to main d61457b (a FILE *, printf
 * "%.17g"), timed as bench/writers_bench.c times today's: the same two results at 10^6
 * grains, the same runs, the median. Not part of the build (the API it calls is gone):
 * compiled against that commit's library, for the "before" column of bench/RESULTS.md:
 *   mkdir /tmp/old && git archive d61457b | tar -x -C /tmp/old && cmake -S /tmp/old -B /tmp/old/build
 *     -DCMAKE_BUILD_TYPE=Release && cmake --build /tmp/old/build --target grainpack_core
 *   cc -std=c11 -D_POSIX_C_SOURCE=200809L -O2 -I/tmp/old/include bench/writers_before.c
 *     /tmp/old/build/core/libgrainpack.a -ljansson -ldouble-conversion -lgmp -lmpfr -lm
 *     -lstdc++ -o writers_before
 * Usage: writers_before [SIDE] [RUNS] [OUTFILE]  (506, 3) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "grainpack/io.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void bench(const char *label, int stages, int side, int runs, const char *path)
{
    char text[512];
    snprintf(text, sizeof text,
             "{\"inputs\": {\"domain\": {\"width\": %d, \"height\": %d}, \"distribution\":"
             " {\"kind\": \"uniform\", \"min\": 0.06, \"max\": 0.42}%s}}",
             side, side,
             stages ? ", \"balance\": {\"method\": \"relocation\", \"max_iterations\": 2},"
                      " \"laguerre\": {\"shrink\": \"offset\"}, \"picture\": {\"color\": \"quality\"}"
                    : "");
    gp_spec spec;
    gp_result r;
    gp_error err;
    if (gp_spec_parse(text, strlen(text), NULL, &spec, &err) ||
        gp_pipeline_run(&spec, 0, NULL, &r, &err)) {
        fprintf(stderr, "%s\n", err.message);
        exit(1);
    }
    printf("**%s** (before): %zu grains\n\n| format | MB | seconds | M grains/s |\n| --- | --- | --- | --- |\n",
           label, r.packing.count);
    for (size_t f = 0; f < 4; f++) {
        double t[16];
        long bytes = 0;
        for (int k = 0; k < runs; k++) {
            FILE *file = fopen(path, "wb");
            double t0 = now();
            if (gp_write_result(file, (gp_format)f, &spec, &r)) {
                fprintf(stderr, "write failed\n");
                exit(1);
            }
            fflush(file);
            t[k] = now() - t0;
            bytes = ftell(file);
            fclose(file);
        }
        qsort(t, (size_t)runs, sizeof *t, compare);
        double s = t[runs / 2];
        printf("| %s | %.1f | %.3f | %.2f |\n", gp_format_name((gp_format)f), (double)bytes / 1e6, s,
               (double)r.packing.count / s / 1e6);
    }
    printf("\n");
    gp_result_free(&r);
    gp_spec_free(&spec);
}

int main(int argc, char **argv)
{
    int side = argc > 1 ? atoi(argv[1]) : 506;
    int runs = argc > 2 ? atoi(argv[2]) : 3;
    const char *path = argc > 3 ? argv[3] : "/tmp/grainpack-writers-before.out";
    bench("packing only", 0, side, runs, path);
    bench("balanced (2 sweeps), offset cells, coloured by F", 1, side, runs, path);
    remove(path);
    return 0;
}
