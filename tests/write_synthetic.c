/* write_synthetic.c - writes a made-up result whose numbers are hard to print (random
 * bit patterns, subnormals, integers, huge and tiny magnitudes, both zeros, NaN where F
 * allows it) in every format, and the exact doubles beside them, for
 * test_writers_round_trip.py to read back with other programs' parsers.
 * Usage: write_synthetic DIR. Writes DIR/result.{json,csv,svg,vtk} and DIR/expected.bin:
 * the grain count n, the vertex count m, the neighbour count q (uint64 each), then n
 * records of x, y, r, R, F, area (float64), the n + 1 vertex offsets and n + 1 neighbour
 * offsets (uint64), the m vertices (x, y float64), the q neighbour ids (int32). */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/io.h"
#include "grainpack/rng.h"
#include "packing_checks.h"

/* Grains of the made-up result: enough for every kind of value to come many times. */
#define GRAINS 3000

/* A double of one of the hard kinds, chosen by the generator. */
static double hard_double(gp_rng *rng)
{
    double x;
    uint64_t bits;
    switch (gp_rng_next(rng) % 9) {
    case 0: /* any finite bit pattern */
        do {
            bits = gp_rng_next(rng);
            memcpy(&x, &bits, sizeof x);
        } while (!isfinite(x));
        return x;
    case 1: /* subnormal */
        bits = gp_rng_next(rng) & ((UINT64_C(1) << 52) - 1);
        memcpy(&x, &bits, sizeof x);
        return gp_rng_next(rng) & 1 ? -x : x;
    case 2: /* an integer, up to 2^53 and beyond */
        return (double)(int64_t)(gp_rng_next(rng) >> (gp_rng_next(rng) % 64));
    case 3: /* huge */
        return (gp_rng_uniform(rng) + 0.5) * pow(10.0, 200.0 + 108.0 * gp_rng_uniform(rng));
    case 4: /* tiny, still normal */
        return (gp_rng_uniform(rng) + 0.5) * pow(10.0, -300.0 - 7.0 * gp_rng_uniform(rng));
    case 5: /* at the switch between plain and exponential notation */
        return (gp_rng_uniform(rng) + 0.1) * pow(10.0, (double)(int)(gp_rng_next(rng) % 30) - 9.0);
    case 6: {
        static const double edge[] = {0.0, -0.0, DBL_MAX, -DBL_MAX, DBL_MIN, DBL_TRUE_MIN, 0.1,
                                      0.06, 1e21, 1e-7, 9007199254740993.0, 5e-324};
        return edge[gp_rng_next(rng) % (sizeof edge / sizeof edge[0])];
    }
    default: /* everyday coordinates */
        return 500.0 * gp_rng_uniform(rng);
    }
}

static int write_file(const char *dir, const char *name, gp_format format, const gp_spec *spec,
                      const gp_result *result)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    gp_out out;
    int rc = gp_out_init_file(&out, f);
    if (rc == 0)
        rc = gp_write_result(&out, format, spec, result);
    gp_out_free(&out);
    return fclose(f) || rc ? -1 : 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: write_synthetic DIR\n");
        return 2;
    }
    gp_spec spec;
    load_example("iron", &spec);
    spec.balance_enabled = spec.laguerre_enabled = 1;
    spec.picture_disks = 1; /* the SVG draws the disks over the cells: both kinds of numbers */
    gp_rng rng;
    gp_rng_seed(&rng, 20261122);
    size_t n = GRAINS;
    gp_result r;
    memset(&r, 0, sizeof r);
    r.packing.count = r.stats.count = r.cells.count = r.balance.count = n;
    r.has_balance = r.has_cells = 1;
    r.packing.disks = malloc(n * sizeof *r.packing.disks);
    r.balance.F = malloc(n * sizeof *r.balance.F);
    r.cells.area = malloc(n * sizeof *r.cells.area);
    r.cells.start = malloc((n + 1) * sizeof *r.cells.start);
    r.cells.nstart = malloc((n + 1) * sizeof *r.cells.nstart);
    r.cells.start[0] = r.cells.nstart[0] = 0;
    for (size_t i = 0; i < n; i++) {
        r.packing.disks[i] = (gp_disk){hard_double(&rng), hard_double(&rng), hard_double(&rng),
                                       hard_double(&rng)};
        /* F is NaN off the interior, else >= 0 */
        r.balance.F[i] = gp_rng_next(&rng) % 5 == 0 ? NAN : fabs(hard_double(&rng));
        r.cells.area[i] = hard_double(&rng);
        r.cells.start[i + 1] = r.cells.start[i] + 3 + gp_rng_next(&rng) % 6;
        r.cells.nstart[i + 1] = r.cells.nstart[i] + gp_rng_next(&rng) % 8;
    }
    size_t m = r.cells.start[n], q = r.cells.nstart[n];
    r.cells.xy = malloc(2 * m * sizeof *r.cells.xy);
    r.cells.neighbours = malloc((q ? q : 1) * sizeof *r.cells.neighbours);
    for (size_t k = 0; k < 2 * m; k++)
        r.cells.xy[k] = hard_double(&rng);
    for (size_t k = 0; k < q; k++)
        r.cells.neighbours[k] = (int32_t)(gp_rng_next(&rng) % n);
    r.cell_stats.max_neighbours = 0;
    r.cell_stats.neighbour_histogram = calloc(1, sizeof *r.cell_stats.neighbour_histogram);

    const char *dir = argv[1];
    int failed = write_file(dir, "result.json", GP_FORMAT_JSON, &spec, &r) ||
                 write_file(dir, "result.csv", GP_FORMAT_CSV, &spec, &r) ||
                 write_file(dir, "result.svg", GP_FORMAT_SVG, &spec, &r) ||
                 write_file(dir, "result.vtk", GP_FORMAT_VTK, &spec, &r);
    char path[1024];
    snprintf(path, sizeof path, "%s/expected.bin", dir);
    FILE *f = fopen(path, "wb");
    if (!f) {
        failed = 1;
    } else {
        uint64_t counts[3] = {n, m, q};
        fwrite(counts, sizeof counts, 1, f);
        for (size_t i = 0; i < n; i++) {
            const gp_disk *d = &r.packing.disks[i];
            double rec[6] = {d->x, d->y, d->r, d->R, r.balance.F[i], r.cells.area[i]};
            fwrite(rec, sizeof rec, 1, f);
        }
        for (size_t i = 0; i <= n; i++) {
            uint64_t v = r.cells.start[i];
            fwrite(&v, sizeof v, 1, f);
        }
        for (size_t i = 0; i <= n; i++) {
            uint64_t v = r.cells.nstart[i];
            fwrite(&v, sizeof v, 1, f);
        }
        fwrite(r.cells.xy, sizeof *r.cells.xy, 2 * m, f);
        fwrite(r.cells.neighbours, sizeof *r.cells.neighbours, q, f);
        failed |= fclose(f) != 0;
    }
    gp_result_free(&r);
    gp_spec_free(&spec);
    if (failed)
        fprintf(stderr, "write_synthetic: cannot write into %s\n", dir);
    return failed;
}
