/* writers_bench.c - the writers alone, at 10^6 grains: a result is computed once (the
 * Bagi law on SIDE x SIDE, with or without two sweeps of balancing and offset cells),
 * then each format is written to a file (median of a few runs): seconds, megabytes and
 * grains per second, and the same through the stored sections (gp_sections_source reading
 * a copy in memory: the service's path without the database). Prints markdown.
 * Usage: grainpack_writers_bench [SIDE] [RUNS] [OUTFILE]  (506, 3, /tmp/grainpack-writers.out) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "grainpack/io.h"
#include "sections.h"
#include "machine.h"
#include "bench_util.h"

static int compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The sections of a result copied into memory, read back as a store would be. */
typedef struct stored {
    gp_section sections[GP_SECTIONS_MAX];
    size_t n;
} stored;

static int read_stored(void *ctx, const char *tag, uint64_t offset, void *dst, size_t len)
{
    stored *st = ctx;
    for (size_t i = 0; i < st->n; i++)
        if (strcmp(st->sections[i].tag, tag) == 0 && offset + len <= st->sections[i].size) {
            memcpy(dst, (const char *)st->sections[i].data + offset, len);
            return 0;
        }
    return GP_EPARSE;
}

/* Writes result in format f to path, `through` the sections or from memory; returns the
 * seconds and the bytes in *bytes. */
static double write_once(const char *path, gp_format f, const gp_spec *spec, const gp_result *r,
                         stored *through, const gp_result *summary, long *bytes)
{
    FILE *file = fopen(path, "wb");
    if (!file) {
        perror(path);
        exit(1);
    }
    gp_out out;
    gp_out_init_file(&out, file);
    double t0 = bench_now();
    int rc;
    if (through) {
        gp_sections_source *src = gp_sections_source_new(summary, read_stored, through, 0);
        gp_grain_source g = gp_sections_source_grains(src);
        gp_writer *w = gp_writer_new(f, spec, summary, &g);
        rc = gp_writer_run(w, &out, SIZE_MAX);
        if (rc == 0)
            rc = gp_out_flush(&out);
        gp_writer_free(w);
        gp_sections_source_free(src);
    } else {
        rc = gp_write_result(&out, f, spec, r);
    }
    fflush(file);
    double t = bench_now() - t0;
    *bytes = ftell(file);
    fclose(file);
    gp_out_free(&out);
    if (rc) {
        fprintf(stderr, "writing %s failed: %d\n", gp_format_name(f), rc);
        exit(1);
    }
    return t;
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
    stored st;
    gp_result summary;
    memset(&summary, 0, sizeof summary);
    if (gp_sections_from_result(&r, st.sections, &st.n))
        exit(1);
    for (size_t i = 0; i < st.n; i++)
        if (st.sections[i].summary)
            gp_section_decode_summary(st.sections[i].tag, st.sections[i].version,
                                      st.sections[i].data, st.sections[i].size, &summary);
    printf("**%s**: %zu grains\n\n| format | MB | seconds | M grains/s | MB/s | through the sections |\n"
           "| --- | --- | --- | --- | --- | --- |\n",
           label, r.packing.count);
    for (size_t f = 0; f < gp_format_count(); f++) {
        double t[16], u[16];
        long bytes = 0;
        for (int k = 0; k < runs; k++) {
            t[k] = write_once(path, (gp_format)f, &spec, &r, NULL, NULL, &bytes);
            u[k] = write_once(path, (gp_format)f, &spec, &r, &st, &summary, &bytes);
        }
        qsort(t, (size_t)runs, sizeof *t, compare);
        qsort(u, (size_t)runs, sizeof *u, compare);
        double s = t[runs / 2];
        printf("| %s | %.1f | %.3f | %.2f | %.0f | %.3f s |\n", gp_format_name((gp_format)f),
               (double)bytes / 1e6, s, (double)r.packing.count / s / 1e6, (double)bytes / 1e6 / s,
               u[runs / 2]);
    }
    printf("\n");
    gp_sections_free(st.sections, st.n);
    gp_result_free(&summary);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

int main(int argc, char **argv)
{
    int side = argc > 1 ? atoi(argv[1]) : 506;
    int runs = argc > 2 ? atoi(argv[2]) : 3;
    const char *path = argc > 3 ? argv[3] : "/tmp/grainpack-writers.out";
    if (runs < 1 || runs > 16 || side < 1) {
        fprintf(stderr, "usage: grainpack_writers_bench [SIDE] [RUNS 1-16] [OUTFILE]\n");
        return 2;
    }
    print_machine();
    bench("packing only", 0, side, runs, path);
    bench("balanced (2 sweeps), offset cells, coloured by F", 1, side, runs, path);
    remove(path);
    return 0;
}
