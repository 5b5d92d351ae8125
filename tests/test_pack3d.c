/* test_pack3d.c - the 3D packer's promises over many seeds and three laws (one radius,
 * the uniform "3D Bagi" law of ratio 7, the iron histogram): no two packing spheres
 * overlap (an O(n k) cell check of the test's own), every sphere inside the box, every
 * sphere tangent to three of the walls and earlier spheres, the radii exactly the law's
 * draws in order (so every bin within 4 standard errors over the pooled seeds), bounded
 * work; bad inputs refused. Also the tangency solve against random configurations. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/pack3d.h"
#include "grainpack/spec.h"
#include "pack3d_internal.h"
#include "pack3d_laws.h"

/* Relative overlap and boundary tolerances, as tests/packing_checks.h's (1e-9: a
 * thousandfold above the rounding of a tangent placement, far below any real overlap). */
#define TEST_RTOL 1e-9
/* A contact: a centre distance within this of R1 + R2, relative (rounding of the solve is
 * ~1e-15; 1e-9 still tells a touching sphere from one a hair away). */
#define CONTACT_RTOL 1e-9
#define SEEDS 24

/* ---- independent checks ---- */

typedef struct cells {
    double side;
    int n[3];
    int *head, *next;
} cells;

static int cell_axis(const cells *c, int a, double v)
{
    int i = (int)floor(v / c->side);
    return i < 0 ? 0 : (i >= c->n[a] ? c->n[a] - 1 : i);
}

/* The overlapping pairs, by a grid of cells of side 2 R_max (each pair met once, from its
 * lower index). *worst: the largest relative overlap 1 - d / (R1 + R2). */
static size_t count_overlaps(const gp_sphere *s, size_t n, const gp_box *box, double *worst)
{
    double R_max = 0.0;
    for (size_t i = 0; i < n; i++)
        R_max = fmax(R_max, s[i].R);
    cells c = {2.0 * R_max, {0, 0, 0}, NULL, NULL};
    const double side[3] = {box->width, box->height, box->depth};
    for (int a = 0; a < 3; a++)
        c.n[a] = (int)ceil(side[a] / c.side) > 0 ? (int)ceil(side[a] / c.side) : 1;
    size_t total = (size_t)c.n[0] * c.n[1] * c.n[2];
    c.head = malloc(total * sizeof *c.head);
    c.next = malloc((n ? n : 1) * sizeof *c.next);
    for (size_t i = 0; i < total; i++)
        c.head[i] = -1;
    for (size_t i = 0; i < n; i++) {
        size_t k = ((size_t)cell_axis(&c, 2, s[i].z) * c.n[1] + cell_axis(&c, 1, s[i].y)) * c.n[0] +
                   cell_axis(&c, 0, s[i].x);
        c.next[i] = c.head[k];
        c.head[k] = (int)i;
    }
    size_t bad = 0;
    *worst = -1.0;
    for (size_t i = 0; i < n; i++) {
        int ci = cell_axis(&c, 0, s[i].x), cj = cell_axis(&c, 1, s[i].y), ck = cell_axis(&c, 2, s[i].z);
        for (int k = ck - 1; k <= ck + 1; k++)
            for (int j = cj - 1; j <= cj + 1; j++)
                for (int l = ci - 1; l <= ci + 1; l++) {
                    if (k < 0 || j < 0 || l < 0 || k >= c.n[2] || j >= c.n[1] || l >= c.n[0])
                        continue;
                    for (int q = c.head[((size_t)k * c.n[1] + j) * c.n[0] + l]; q >= 0; q = c.next[q]) {
                        if ((size_t)q <= i)
                            continue;
                        double dx = s[i].x - s[q].x, dy = s[i].y - s[q].y, dz = s[i].z - s[q].z;
                        double rel = 1.0 - sqrt(dx * dx + dy * dy + dz * dz) / (s[i].R + s[q].R);
                        *worst = fmax(*worst, rel);
                        if (rel > TEST_RTOL)
                            bad++;
                    }
                }
    }
    free(c.head);
    free(c.next);
    return bad;
}

static size_t count_outside(const gp_sphere *s, size_t n, const gp_box *box)
{
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        double slack = s[i].R * TEST_RTOL;
        if (s[i].x - s[i].R < -slack || s[i].y - s[i].R < -slack || s[i].z - s[i].R < -slack ||
            s[i].x + s[i].R > box->width + slack || s[i].y + s[i].R > box->height + slack ||
            s[i].z + s[i].R > box->depth + slack)
            bad++;
    }
    return bad;
}

/* The spheres (after the first) touching fewer than three walls and earlier spheres: the
 * advancing front places every sphere tangent to a triangle's three members. O(n^2)
 * over earlier spheres is fine at the sizes here. */
static size_t count_loose(const gp_sphere *s, size_t n, const gp_box *box)
{
    size_t loose = 0;
    for (size_t i = 1; i < n; i++) {
        int touches = 0;
        const double p[3] = {s[i].x, s[i].y, s[i].z}, side[3] = {box->width, box->height, box->depth};
        for (int a = 0; a < 3; a++)
            touches += (fabs(p[a] - s[i].R) <= CONTACT_RTOL * s[i].R) +
                       (fabs(side[a] - p[a] - s[i].R) <= CONTACT_RTOL * s[i].R);
        for (size_t j = 0; j < i && touches < 3; j++) {
            double dx = s[i].x - s[j].x, dy = s[i].y - s[j].y, dz = s[i].z - s[j].z;
            double sum = s[i].R + s[j].R, d = sqrt(dx * dx + dy * dy + dz * dz);
            touches += fabs(d - sum) <= CONTACT_RTOL * sum;
        }
        loose += touches < 3;
    }
    return loose;
}

/* ---- the properties ---- */

static void check_law(law3 *law, gp_pack3d_order order, int seeds)
{
    const gp_distribution *dist = &law->spec.dist;
    gp_box box = {law->side, law->side * 0.9, law->side * 1.1, 0};
    law3_tally tally;
    law3_tally_init(&tally, dist);
    size_t worst_loose = 0;
    double worst_overlap = -1.0, min_density = 1.0;
    for (int seed = 1; seed <= seeds; seed++) {
        gp_pack3d_params params = {&box, dist, NULL, (uint64_t)seed * 7919u, 0, order};
        gp_packing3d out;
        gp_error err;
        int rc = gp_pack3d(&params, NULL, &out, &err);
        CHECK_MSG(rc == 0, "%s seed %d: %s", law->name, seed, err.message);
        if (rc)
            continue;
        double worst;
        CHECK_MSG(count_overlaps(out.spheres, out.count, &box, &worst) == 0, "%s seed %d: worst %.3g",
                  law->name, seed, worst);
        worst_overlap = fmax(worst_overlap, worst);
        CHECK(count_outside(out.spheres, out.count, &box) == 0);
        size_t loose = count_loose(out.spheres, out.count, &box);
        CHECK_MSG(loose == 0, "%s seed %d: %zu spheres touch fewer than three", law->name, seed, loose);
        worst_loose = loose > worst_loose ? loose : worst_loose;
        double density = law3_check_packing(law->name, seed, &params, &out);
        min_density = fmin(min_density, density);
        CHECK_MSG(density >= law->min_density, "%s seed %d: density %.4f", law->name, seed, density);
        law3_tally_add(&tally, &out);
        gp_packing3d_free(&out);
    }
    double max_z = law3_tally_check(&tally, law->name);
    fprintf(stderr, "  %s order %d: %d seeds, %zu spheres, min density %.4f, worst overlap %.2g, max |z| %.2f\n",
            law->name, (int)order, seeds, tally.pooled, min_density, worst_overlap, max_z);
}

static law3 laws[3] = {
    {.name = "one radius", .seeds = 2, .side = 8.0, .min_density = 0.47},
    {.name = "bagi", .seeds = SEEDS, .side = 4.0, .min_density = 0.46},
    {.name = "iron", .seeds = SEEDS, .side = 64.0, .min_density = 0.46},
};

static void test_properties_level(void)
{
    for (int i = 0; i < 3; i++)
        check_law(&laws[i], GP_PACK3D_LEVEL, laws[i].seeds);
}

static void test_properties_lowest(void)
{
    for (int i = 0; i < 3; i++)
        check_law(&laws[i], GP_PACK3D_LOWEST, (laws[i].seeds + 3) / 4);
}

/* ---- the tangency solve ---- */

static double uniform(gp_rng *rng, double a, double b)
{
    return a + (b - a) * gp_rng_uniform(rng);
}

/* A random point P and radius R, with members put tangent to the ball (P, R): spheres at
 * R + R_i from P in random directions, walls at R from P. The solve must give P back
 * among its solutions, and every solution must be tangent to every member. */
static void test_tangent(void)
{
    gp_box box = {10.0, 11.0, 12.0, 0};
    const double side[3] = {10.0, 11.0, 12.0};
    gp_rng rng;
    gp_rng_seed(&rng, 5);
    int solved[4] = {0}, found[4] = {0};
    for (int trial = 0; trial < 4000; trial++) {
        int walls = trial % 4;
        double R = uniform(&rng, 0.2, 2.0), P[3];
        for (int a = 0; a < 3; a++)
            P[a] = uniform(&rng, R, side[a] - R);
        gp_sphere s[3];
        int32_t m[3] = {0, 1, 2};
        int axis0 = (int)(gp_rng_next(&rng) % 3);
        for (int w = 0; w < walls; w++) {
            int axis = (axis0 + w) % 3, far = (int)(gp_rng_next(&rng) % 2);
            m[2 - w] = P3_WALL(2 * axis + far);
            P[axis] = far ? side[axis] - R : R;
        }
        for (int i = 0; i < 3 - walls; i++) {
            double u[3], n2;
            do {
                for (int a = 0; a < 3; a++)
                    u[a] = uniform(&rng, -1, 1);
                n2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
            } while (n2 > 1.0 || n2 < 0.01);
            double Ri = uniform(&rng, 0.2, 1.5), k = (R + Ri) / sqrt(n2);
            s[i] = (gp_sphere){P[0] + k * u[0], P[1] + k * u[1], P[2] + k * u[2], Ri, Ri};
        }
        double out[2][3];
        int n = p3_tangent(s, &box, m, R, out);
        CHECK(walls == 3 ? n == 1 : (n == 0 || n == 2));
        if (n == 0)
            continue; /* a flat triangle (MIN_SINE): rare, counted below */
        solved[walls]++;
        double best = INFINITY;
        for (int k = 0; k < n; k++) {
            best = fmin(best, sqrt(pow(out[k][0] - P[0], 2) + pow(out[k][1] - P[1], 2) + pow(out[k][2] - P[2], 2)));
            for (int i = 0; i < 3; i++) {
                if (P3_IS_WALL(m[i])) {
                    int w = P3_WALL_INDEX(m[i]);
                    double at = w % 2 ? side[w / 2] - out[k][w / 2] : out[k][w / 2];
                    CHECK_NEAR(at, R, 1e-12 * R);
                } else {
                    double dx = out[k][0] - s[m[i]].x, dy = out[k][1] - s[m[i]].y, dz = out[k][2] - s[m[i]].z;
                    CHECK_NEAR(sqrt(dx * dx + dy * dy + dz * dz), s[m[i]].R + R, 1e-12 * (s[m[i]].R + R));
                }
            }
        }
        found[walls] += best <= 1e-9 * R;
    }
    /* nearly every configuration is solved, and P is one of the solutions */
    for (int w = 0; w < 4; w++) {
        CHECK_MSG(solved[w] >= 990, "%d walls: %d of 1000 solved", w, solved[w]);
        CHECK_MSG(found[w] == solved[w], "%d walls: P found %d times of %d", w, found[w], solved[w]);
    }
    /* three spheres too far apart for R, two walls across one axis, collinear centres */
    gp_sphere far[3] = {{1, 1, 1, 0, 0.5}, {9, 1, 1, 0, 0.5}, {1, 9, 1, 0, 0.5}};
    double out[2][3];
    CHECK(p3_tangent(far, &box, (int32_t[3]){0, 1, 2}, 1.0, out) == 0);
    CHECK(p3_tangent(far, &box, (int32_t[3]){0, P3_WALL(0), P3_WALL(1)}, 1.0, out) == 0);
    gp_sphere line[3] = {{1, 1, 1, 0, 0.5}, {2, 1, 1, 0, 0.5}, {3, 1, 1, 0, 0.5}};
    CHECK(p3_tangent(line, &box, (int32_t[3]){0, 1, 2}, 1.0, out) == 0);
    /* the corner: one solution, R from each of three walls */
    CHECK(p3_tangent(far, &box, (int32_t[3]){P3_WALL(1), P3_WALL(3), P3_WALL(5)}, 1.0, out) == 1);
    CHECK(out[0][0] == 9.0 && out[0][1] == 10.0 && out[0][2] == 11.0);
}

/* ---- bad inputs ---- */

static int refused(gp_pack3d_params *params, int code)
{
    gp_packing3d out;
    gp_error err;
    memset(&out, 0x5a, sizeof out);
    int rc = gp_pack3d(params, NULL, &out, &err);
    return rc == code && out.spheres == NULL && out.count == 0 && err.message[0];
}

static void cancel_at_once(void *ctx, const char *stage, double fraction)
{
    (void)stage;
    (void)fraction;
    atomic_store((gp_cancel_flag *)ctx, 1);
}

static void test_bad_inputs(void)
{
    const gp_distribution *one = &laws[0].spec.dist; /* radius 0.5 */
    gp_box box = {8, 8, 8, 0};
    gp_pack3d_params p = {&box, one, NULL, 1, 0, GP_PACK3D_LEVEL};
    const double bad_sides[] = {0.0, -1.0, NAN, INFINITY, 0.9 /* under a diameter */};
    for (size_t i = 0; i < sizeof bad_sides / sizeof *bad_sides; i++) {
        gp_box b = box;
        b.depth = bad_sides[i];
        p.box = &b;
        CHECK_MSG(refused(&p, GP_EINVAL), "depth %g", bad_sides[i]);
    }
    /* a side of more than 10^6 smallest radii */
    gp_box huge = {8, 8, 1e7, 0};
    p.box = &huge;
    CHECK(refused(&p, GP_EINVAL));
    p.box = &box;
    p.order = (gp_pack3d_order)7;
    CHECK(refused(&p, GP_EINVAL));
    p.order = GP_PACK3D_LEVEL;
    /* a radius ratio above GP_PACK3D_MAX_RADIUS_RATIO */
    gp_distribution wide = {.kind = GP_DIST_UNIFORM, .min = 0.01, .max = 0.5};
    p.dist = &wide;
    CHECK(refused(&p, GP_EINVAL));
    p.dist = one;
    /* the cap on spheres, and cancellation */
    p.max_spheres = 10;
    CHECK(refused(&p, GP_ETOOBIG));
    p.max_spheres = 0;
    gp_cancel_flag flag = 0;
    gp_progress progress = {cancel_at_once, &flag, &flag};
    gp_packing3d out;
    gp_error err;
    CHECK(gp_pack3d(&p, &progress, &out, &err) == GP_ECANCELED && out.count == 0 && !out.spheres);
    /* a box of exactly one diameter: one sphere, touching all six walls */
    gp_box tight = {1.0, 1.0, 1.0, 0};
    p.box = &tight;
    CHECK(gp_pack3d(&p, NULL, &out, &err) == 0 && out.count == 1);
    gp_packing3d_free(&out);
    gp_packing3d_free(&out); /* a second free is harmless */
}

int main(void)
{
    if (load_laws3(laws))
        return 1;
    RUN(test_tangent);
    RUN(test_properties_level);
    RUN(test_properties_lowest);
    RUN(test_bad_inputs);
    for (int i = 0; i < 3; i++)
        gp_spec_free(&laws[i].spec);
    return check_status();
}
