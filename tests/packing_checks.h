/* packing_checks.h - independent checks of a packing's geometry, shared by the tests.
 * They use neither the bucket grid nor the contact predicate of the library, so that a
 * bug there cannot hide itself. */
#ifndef GRAINPACK_TESTS_PACKING_CHECKS_H
#define GRAINPACK_TESTS_PACKING_CHECKS_H

#include <math.h>
#include <stdlib.h>

#include "grainpack/disk.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/pack.h"
#include "grainpack/spec.h"

/* Two packing disks overlap when their centres are closer than (R1 + R2)(1 - 1e-9).
 * Why 1e-9: disks placed tangent to each other are exactly in contact in real numbers
 * and computed in doubles, so their distance comes out within a few ulps of the
 * coordinates (below 1e-12 of a radius in every test here); 1e-9 leaves a thousandfold
 * margin over that rounding while any real overlap, however small to the eye, is far
 * larger. The library's own tolerance (GP_CONTACT_RTOL) is the same value. */
#define TEST_OVERLAP_RTOL 1e-9
/* A disk may cross the boundary by at most this fraction of its radius, for the same
 * reason: disks touching a wall are placed at exactly R from it, up to rounding. */
#define TEST_BOUNDARY_RTOL 1e-9



typedef struct x_index {
    double x;
    size_t index;
} x_index;

static int compare_x(const void *pa, const void *pb)
{
    double xa = ((const x_index *)pa)->x, xb = ((const x_index *)pb)->x;
    return xa < xb ? -1 : (xa > xb ? 1 : 0);
}

/* The number of overlapping pairs, found by a sweep along x (no grid). *worst gets the
 * largest relative overlap 1 - d / (R1 + R2) over all pairs (negative: none touch). */
static inline size_t count_overlaps(const gp_disk *disks, size_t n, double *worst)
{
    x_index *order = malloc((n ? n : 1) * sizeof *order);
    double R_max = 0.0;
    for (size_t i = 0; i < n; i++) {
        order[i] = (x_index){disks[i].x, i};
        if (disks[i].R > R_max)
            R_max = disks[i].R;
    }
    qsort(order, n, sizeof *order, compare_x);
    size_t bad = 0;
    *worst = -1.0;
    for (size_t a = 0; a < n; a++) {
        const gp_disk *p = &disks[order[a].index];
        for (size_t b = a + 1; b < n; b++) {
            const gp_disk *q = &disks[order[b].index];
            if (q->x - p->x >= p->R + R_max)
                break;
            double d = sqrt((q->x - p->x) * (q->x - p->x) + (q->y - p->y) * (q->y - p->y));
            double rel = 1.0 - d / (p->R + q->R);
            if (rel > *worst)
                *worst = rel;
            if (rel > TEST_OVERLAP_RTOL)
                bad++;
        }
    }
    free(order);
    return bad;
}

/* The k x k tiling of a periodic packing: the disks copied by (i W, j H) for
 * 0 <= i, j < k along the periodic axes (k copies, or one along a walled axis), in a new
 * array (the caller's) of *n_out disks. Any two disks that overlap under the minimum-image
 * convention overlap in the 3 x 3 tiling (the middle copy of one and a copy of the other),
 * so count_overlaps on it checks the packing across its sides with no minimum image. */
static inline gp_disk *tile_packing(const gp_disk *disks, size_t n, const gp_domain *dom, int k,
                                    size_t *n_out)
{
    int kx = (dom->periodic & GP_PERIODIC_X) ? k : 1, ky = (dom->periodic & GP_PERIODIC_Y) ? k : 1;
    gp_disk *t = malloc((n ? n : 1) * (size_t)(kx * ky) * sizeof *t);
    size_t m = 0;
    for (int i = 0; i < kx; i++)
        for (int j = 0; j < ky; j++)
            for (size_t a = 0; a < n; a++) {
                t[m] = disks[a];
                t[m].x += i * dom->width;
                t[m].y += j * dom->height;
                m++;
            }
    *n_out = m;
    return t;
}

/* The number of disks whose disk crosses a wall by more than the tolerance, or along a
 * periodic axis whose centre is outside [0, W) x [0, H) (a disk across a periodic side is
 * stored once, at its image inside). */
static inline size_t count_outside(const gp_disk *disks, size_t n, const gp_domain *dom)
{
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        const gp_disk *d = &disks[i];
        double slack = d->R * TEST_BOUNDARY_RTOL;
        int px = (dom->periodic & GP_PERIODIC_X) != 0, py = (dom->periodic & GP_PERIODIC_Y) != 0;
        int out_x = px ? !(d->x >= 0.0 && d->x < dom->width)
                       : (d->x - d->R < -slack || d->x + d->R > dom->width + slack);
        int out_y = py ? !(d->y >= 0.0 && d->y < dom->height)
                       : (d->y - d->R < -slack || d->y + d->R > dom->height + slack);
        bad += out_x || out_y;
    }
    return bad;
}

/* Whether r can be drawn from the law: in one of its bins of positive probability, in
 * its interval, or equal to its radius. */
static inline int radius_in_support(const gp_distribution *dist, double r)
{
    switch (dist->kind) {
    case GP_DIST_CONSTANT: return r == dist->radius;
    case GP_DIST_UNIFORM: return r >= dist->min && r <= dist->max;
    case GP_DIST_HISTOGRAM:
        for (size_t i = 0; i < dist->nbins; i++)
            if (dist->bins[i].p > 0.0 && r >= dist->bins[i].min && r <= dist->bins[i].max)
                return 1;
        return 0;
    }
    return 0;
}

/* Loads examples/<name>.json, aborting the test program if it cannot. */
static inline void load_example(const char *name, gp_spec *spec)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s.json", GP_EXAMPLES_DIR, name);
    gp_error err;
    if (gp_spec_load_file(path, NULL, spec, &err)) {
        fprintf(stderr, "cannot load %s: %s %s\n", path, err.pointer, err.message);
        exit(2);
    }
}

/* A hexagonal patch of `rows` x `cols` touching disks of packing radius 1 (grain radius
 * 0.9) with lower-left centre (x0, y0); returns how many it wrote to d. */
static inline size_t hex_patch(gp_disk *d, int rows, int cols, double x0, double y0)
{
    size_t n = 0;
    for (int i = 0; i < rows; i++)
        for (int j = 0; j < cols; j++)
            d[n++] = (gp_disk){x0 + 2.0 * j + (i % 2), y0 + sqrt(3.0) * i, 0.9, 1.0};
    return n;
}

/* Packs `spec` with `seed` (and its own front rule), aborting the test program if it
 * cannot. */
static inline void pack_seed(const gp_spec *spec, uint64_t seed, gp_packing *pk)
{
    gp_pack_params params = gp_spec_pack_params(spec, 0);
    params.seed = seed;
    gp_error err;
    if (gp_pack(&params, NULL, pk, &err)) {
        fprintf(stderr, "cannot pack seed %llu: %s\n", (unsigned long long)seed, err.message);
        exit(2);
    }
}

#endif
