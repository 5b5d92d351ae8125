/* test_triangulation.c - the regular triangulation module: rings counter-clockwise with
 * the hull where the header says, the empty-power-circle property checked by brute force,
 * hidden vertices reported, degenerate inputs, all the rings at once, and updates after
 * moves (flips, reinsertion, rebuild) that end in the same triangulation as a fresh build
 * and mark every ring they change, and stay regular through moves of a few ulps; a raised
 * cancel flag stops a build, an update, a rebuild and the walk of all the rings. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grainpack/pack.h"
#include "grainpack/rng.h"
#include "grainpack/triangulation.h"
#include "packing_checks.h"

/* The ring of id, aborting the test on a buffer too small (64 is plenty here). */
static size_t ring(const gp_rt *rt, int32_t id, int32_t *out, int *hull)
{
    size_t degree = gp_rt_ring(rt, id, out, 64, hull);
    CHECK(degree <= 64);
    return degree;
}

static void test_hexagonal_patch_rings_are_six_touching_neighbours_ccw(void)
{
    gp_disk d[49];
    size_t n = hex_patch(d, 7, 7, 0.0, 0.0);
    gp_rt *rt;
    gp_error err;
    CHECK(gp_rt_build(d, n, NULL, &rt, &err) == 0);
    CHECK(gp_rt_count(rt) == n && gp_rt_dimension(rt) == 2);
    size_t interior = 0;
    for (size_t i = 0; i < n; i++) {
        int32_t nb[64];
        int hull;
        size_t deg = ring(rt, (int32_t)i, nb, &hull);
        int row = (int)i / 7, col = (int)i % 7;
        int on_border = row == 0 || row == 6 || col == 0 || col == 6;
        if (!on_border) {
            /* an interior disk of the patch: six neighbours, all touching, the triangles
             * (p, nb[k], nb[k+1]) counter-clockwise */
            CHECK_MSG(!hull && deg == 6, "disk %zu: hull %d degree %zu", i, hull, deg);
            for (size_t k = 0; k < deg; k++) {
                const gp_disk *q = &d[nb[k]], *r = &d[nb[(k + 1) % deg]];
                CHECK_NEAR(hypot(q->x - d[i].x, q->y - d[i].y), 2.0, 1e-12);
                CHECK(gp_orient2d(d[i].x, d[i].y, q->x, q->y, r->x, r->y) > 0.0);
            }
            interior++;
        }
    }
    CHECK(interior == 25);
    gp_rt_free(rt);
}

/* For a hull vertex p with ring nb: the edges p -> nb[0] and nb[deg-1] -> p are hull
 * edges, every centre on their left or on them. */
static void check_hull_ring(const gp_disk *d, size_t n, size_t i, const int32_t *nb, size_t deg)
{
    const gp_disk *p = &d[i], *first = &d[nb[0]], *last = &d[nb[deg - 1]];
    for (size_t q = 0; q < n; q++) {
        CHECK_MSG(gp_orient2d(p->x, p->y, first->x, first->y, d[q].x, d[q].y) >= 0.0,
                  "disk %zu right of the hull edge %zu -> %d", q, i, nb[0]);
        CHECK_MSG(gp_orient2d(last->x, last->y, p->x, p->y, d[q].x, d[q].y) >= 0.0,
                  "disk %zu right of the hull edge %d -> %zu", q, nb[deg - 1], i);
    }
}

/* Random disjoint disks of varied radii in a square, by rejection. */
static size_t random_disks(gp_disk *d, size_t want, double side, uint64_t seed)
{
    gp_rng rng;
    gp_rng_seed(&rng, seed);
    size_t n = 0;
    for (int tries = 0; n < want && tries < 100000; tries++) {
        double R = 0.2 + 0.8 * gp_rng_uniform(&rng);
        gp_disk c = {R + (side - 2 * R) * gp_rng_uniform(&rng), R + (side - 2 * R) * gp_rng_uniform(&rng),
                     0.9 * R, R};
        int ok = 1;
        for (size_t k = 0; k < n && ok; k++)
            ok = hypot(c.x - d[k].x, c.y - d[k].y) >= c.R + d[k].R;
        if (ok)
            d[n++] = c;
    }
    return n;
}

/* The power circle of triangle (a, b, c): the point o with equal power to all three, and
 * that power. */
static void orthocentre(const gp_disk *a, const gp_disk *b, const gp_disk *c, double *ox,
                        double *oy, double *power)
{
    double bx = b->x - a->x, by = b->y - a->y, cx = c->x - a->x, cy = c->y - a->y;
    double kb = 0.5 * (bx * bx + by * by + a->R * a->R - b->R * b->R);
    double kc = 0.5 * (cx * cx + cy * cy + a->R * a->R - c->R * c->R);
    double det = bx * cy - by * cx;
    double ux = (kb * cy - kc * by) / det, uy = (bx * kc - cx * kb) / det;
    *ox = a->x + ux;
    *oy = a->y + uy;
    *power = ux * ux + uy * uy - a->R * a->R;
}

static void test_triangles_have_empty_power_circles_by_brute_force(void)
{
    enum { WANT = 300 };
    for (uint64_t seed = 1; seed <= 5; seed++) {
        gp_disk d[WANT];
        size_t n = random_disks(d, WANT, 30.0, seed);
        gp_rt *rt;
        gp_error err;
        CHECK(gp_rt_build(d, n, NULL, &rt, &err) == 0);
        CHECK(gp_rt_is_regular(rt));
        size_t triangles = 0, hull = 0;
        for (size_t i = 0; i < n; i++) {
            int32_t nb[64];
            int on_hull;
            size_t deg = ring(rt, (int32_t)i, nb, &on_hull);
            if (on_hull) {
                hull++;
                check_hull_ring(d, n, i, nb, deg);
            }
            for (size_t k = 0; k + (on_hull ? 1 : 0) < deg; k++) {
                const gp_disk *a = &d[i], *b = &d[nb[k]], *c = &d[nb[(k + 1) % deg]];
                CHECK(gp_orient2d(a->x, a->y, b->x, b->y, c->x, c->y) > 0.0);
                double ox, oy, power;
                orthocentre(a, b, c, &ox, &oy, &power);
                /* no centre has less power at o than the triangle's own three (with a
                 * relative margin for the rounding of o) */
                for (size_t q = 0; q < n; q++) {
                    double pq = (ox - d[q].x) * (ox - d[q].x) + (oy - d[q].y) * (oy - d[q].y) - d[q].R * d[q].R;
                    CHECK_MSG(pq >= power - 1e-9 * (fabs(power) + 1.0), "seed %llu: disk %zu in the power circle of (%zu, %d, %d)",
                              (unsigned long long)seed, q, i, nb[k], nb[(k + 1) % deg]);
                }
                triangles++;
            }
        }
        /* Euler: each triangle is counted at its three corners; 2n - 2 - h triangles */
        CHECK_MSG(triangles == 3 * (2 * n - 2 - hull), "%zu corners for %zu vertices, %zu on the hull", triangles, n, hull);
        gp_rt_free(rt);
    }
}

static void test_hidden_and_duplicate_disks_are_geometry_errors(void)
{
    /* a small disk near the centre of a big one: its power cell is empty */
    gp_disk nested[4] = {{0, 0, 1, 1}, {5, 0, 1, 1}, {0, 5, 1, 1}, {0.05, 0, 0.05, 0.1}};
    gp_rt *rt;
    gp_error err;
    CHECK(gp_rt_build(nested, 4, NULL, &rt, &err) == GP_EGEOM);
    CHECK(rt == NULL);
    CHECK_MSG(strstr(err.message, "disk 3") && strstr(err.message, "hidden"), "%s", err.message);

    gp_disk twins[4] = {{0, 0, 1, 1}, {5, 0, 1, 1}, {0, 5, 1, 1}, {5, 0, 1, 1}};
    CHECK(gp_rt_build(twins, 4, NULL, &rt, &err) == GP_EGEOM);
    CHECK(strstr(err.message, "hidden") != NULL);
}

static void test_degenerate_inputs_have_rings_too(void)
{
    gp_rt *rt;
    gp_error err;
    int32_t nb[64];
    int hull;
    CHECK(gp_rt_build(NULL, 0, NULL, &rt, &err) == 0);
    CHECK(gp_rt_count(rt) == 0 && gp_rt_dimension(rt) == -1);
    gp_rt_free(rt);

    gp_disk one = {1, 1, 0.5, 1};
    CHECK(gp_rt_build(&one, 1, NULL, &rt, &err) == 0);
    CHECK(gp_rt_dimension(rt) == 0 && ring(rt, 0, nb, &hull) == 0 && hull == 1);
    gp_rt_free(rt);

    /* a row: dimension 1, each disk's neighbours are the ones beside it */
    gp_disk row[5];
    for (int i = 0; i < 5; i++)
        row[i] = (gp_disk){1.0 + 2.0 * ((i * 3) % 5), 1.0, 0.9, 1.0};
    CHECK(gp_rt_build(row, 5, NULL, &rt, &err) == 0);
    CHECK(gp_rt_dimension(rt) == 1);
    for (int i = 0; i < 5; i++) {
        size_t deg = ring(rt, i, nb, &hull);
        int ends = row[i].x == 1.0 || row[i].x == 9.0;
        CHECK_MSG(deg == (ends ? 1u : 2u) && hull, "disk at x = %g: %zu neighbours", row[i].x, deg);
        for (size_t k = 0; k < deg; k++)
            CHECK_NEAR(fabs(row[nb[k]].x - row[i].x), 2.0, 0.0);
    }
    gp_rt_free(rt);
}

/* Whether the rings of two triangulations of the same disks hold the same neighbours. */
static size_t count_ring_differences(const gp_rt *a, const gp_rt *b, size_t n)
{
    size_t differ = 0;
    for (size_t i = 0; i < n; i++) {
        int32_t na[64], nb[64];
        int ha, hb;
        size_t da = ring(a, (int32_t)i, na, &ha), db = ring(b, (int32_t)i, nb, &hb);
        int same = da == db && ha == hb;
        for (size_t k = 0; k < da && same; k++) {
            int found = 0;
            for (size_t m = 0; m < db; m++)
                found |= na[k] == nb[m];
            same = found;
        }
        differ += !same;
    }
    return differ;
}

/* Checks gp_rt_rings against gp_rt_ring vertex by vertex: the same rings, in the same
 * order from the same start, and the same hull flags. */
static void check_all_rings(const gp_rt *rt, size_t n)
{
    size_t *start = malloc((n + 1) * sizeof *start);
    uint8_t *hull = malloc(n ? n : 1);
    int32_t *ids;
    CHECK(gp_rt_rings(rt, start, hull, &ids, NULL) == 0);
    size_t wrong = 0;
    for (size_t i = 0; i < n; i++) {
        int32_t nb[64];
        int h;
        size_t deg = ring(rt, (int32_t)i, nb, &h);
        int same = start[i + 1] - start[i] == deg && hull[i] == h;
        for (size_t k = 0; k < deg && same; k++)
            same = ids[start[i] + k] == nb[k];
        wrong += !same;
    }
    CHECK_MSG(wrong == 0, "%zu of %zu rings differ", wrong, n);
    free(ids);
    free(start);
    free(hull);
}

/* Every ring of rt as gp_rt_ring gives it, end to end, with each ring's start. */
typedef struct ring_copy {
    size_t *start;
    int32_t *ids;
    int *hull;
} ring_copy;

static ring_copy copy_rings(const gp_rt *rt, size_t n)
{
    ring_copy c = {malloc((n + 1) * sizeof(size_t)), malloc(64 * (n ? n : 1) * sizeof(int32_t)),
                   malloc((n ? n : 1) * sizeof(int))};
    c.start[0] = 0;
    for (size_t i = 0; i < n; i++)
        c.start[i + 1] = c.start[i] + ring(rt, (int32_t)i, c.ids + c.start[i], &c.hull[i]);
    return c;
}

static void free_rings(ring_copy *c)
{
    free(c->start);
    free(c->ids);
    free(c->hull);
}

/* The vertices whose ring differs between a and b that `marks` leaves unmarked. */
static size_t unmarked_changes(const ring_copy *a, const ring_copy *b, const uint8_t *marks, size_t n)
{
    size_t missed = 0;
    for (size_t i = 0; i < n; i++) {
        size_t da = a->start[i + 1] - a->start[i], db = b->start[i + 1] - b->start[i];
        int same = da == db && a->hull[i] == b->hull[i] &&
                   memcmp(a->ids + a->start[i], b->ids + b->start[i], da * sizeof *a->ids) == 0;
        missed += !same && !marks[i];
    }
    return missed;
}

static void test_all_rings_at_once_are_the_rings_one_by_one(void)
{
    gp_spec spec;
    load_example("iron", &spec);
    gp_packing pk;
    gp_error err;
    pack_seed(&spec, 2, &pk);
    gp_rt *rt;
    CHECK(gp_rt_build(pk.disks, pk.count, NULL, &rt, &err) == 0);
    check_all_rings(rt, pk.count);
    gp_rt_free(rt);
    /* a patch with its hull, a row (dimension 1), one disk, none */
    gp_disk d[49];
    size_t n = hex_patch(d, 7, 7, 0.0, 0.0);
    for (size_t m = 0; m <= n; m = m < 8 ? m + 1 : n) {
        CHECK(gp_rt_build(d, m, NULL, &rt, &err) == 0);
        check_all_rings(rt, m);
        gp_rt_free(rt);
        if (m == n)
            break;
    }
    gp_packing_free(&pk);
    gp_spec_free(&spec);
}

static void test_updates_after_moves_match_a_fresh_build(void)
{
    gp_spec spec;
    load_example("variable", &spec);
    gp_packing pk;
    gp_error err;
    pack_seed(&spec, 3, &pk);
    /* shrunk to a third, the disks can move far without overlapping: moves of up to 0.4
     * of the original radius along each axis fold some triangles (reinsertion) and flip
     * many edges, and keep every pair (R1 + R2)(1 - 0.57) >= (R1 + R2) / 3 apart */
    for (size_t i = 0; i < pk.count; i++)
        pk.disks[i].R *= 1.0 / 3.0;
    gp_rt *rt, *fresh;
    CHECK(gp_rt_build(pk.disks, pk.count, NULL, &rt, &err) == 0);
    gp_rng rng;
    gp_rng_seed(&rng, 7);
    int32_t *ids = malloc(pk.count * sizeof *ids);
    uint8_t *marks = calloc(pk.count, 1);
    gp_rt_mark_changes(rt, marks);
    gp_rt_update_stats st = {0, 0, 0, 0};
    for (int round = 0; round < 3; round++) {
        ring_copy before = copy_rings(rt, pk.count);
        size_t moved = 0;
        for (size_t i = 0; i < pk.count; i += 2) {
            double step = (round == 2 ? 1.2 : 0.3) * pk.disks[i].R;
            pk.disks[i].x += step * (2.0 * gp_rng_uniform(&rng) - 1.0);
            pk.disks[i].y += step * (2.0 * gp_rng_uniform(&rng) - 1.0);
            ids[moved++] = (int32_t)i;
        }
        CHECK(gp_rt_update_moved(rt, pk.disks, pk.count, ids, moved, GP_RT_UPDATE_FLIPS, &st, NULL, &err) == 0);
        CHECK(gp_rt_is_regular(rt));
        check_all_rings(rt, pk.count);
        /* every ring the update changed is marked, and not every ring is: a disk far
         * from the moves keeps its ring */
        ring_copy after = copy_rings(rt, pk.count);
        size_t marked = 0;
        for (size_t i = 0; i < pk.count; i++)
            marked += marks[i];
        CHECK_MSG(unmarked_changes(&before, &after, marks, pk.count) == 0, "round %d", round);
        CHECK_MSG(marked > 0 && marked < pk.count, "round %d: %zu of %zu marked", round, marked, pk.count);
        memset(marks, 0, pk.count);
        free_rings(&before);
        free_rings(&after);
        CHECK(gp_rt_build(pk.disks, pk.count, NULL, &fresh, &err) == 0);
        CHECK_MSG(count_ring_differences(rt, fresh, pk.count) == 0, "round %d", round);
        gp_rt_free(fresh);
    }
    CHECK_MSG(st.moved_in_place > 0 && st.flips > 0 && st.reinserted > 0 && st.rebuilds == 0,
              "in place %llu, flips %llu, reinserted %llu, rebuilds %llu", (unsigned long long)st.moved_in_place,
              (unsigned long long)st.flips, (unsigned long long)st.reinserted, (unsigned long long)st.rebuilds);
    /* the rebuild mode gives the same triangulation */
    gp_rt_update_stats rb = {0, 0, 0, 0};
    CHECK(gp_rt_update_moved(rt, pk.disks, pk.count, ids, 1, GP_RT_UPDATE_REBUILD, &rb, NULL, &err) == 0);
    CHECK(rb.rebuilds == 1 && gp_rt_is_regular(rt));
    /* a rebuild marks every vertex */
    size_t marked = 0;
    for (size_t i = 0; i < pk.count; i++)
        marked += marks[i];
    CHECK(marked == pk.count);
    gp_rt_mark_changes(rt, NULL);
    free(marks);
    free(ids);
    gp_rt_free(rt);
    gp_packing_free(&pk);
    gp_spec_free(&spec);
}

/* Moves of a few ulps on a square grid, where every four neighbours share a power circle
 * exactly: the power tests of the flips are as close to zero as doubles allow, where a
 * test computed in doubles alone would misjudge the sign; the update must still end in a
 * regular triangulation (checked with CGAL's exact predicates). */
static void test_updates_stay_regular_on_near_ties(void)
{
    enum { SIDE = 8 };
    /* a pitch and an origin that doubles do not hold exactly: the lifted coordinates of
     * the tests are rounded, and their errors are of the size of the moves */
    const double pitch = 0.3, x0 = 10.1, y0 = 20.7;
    gp_disk d[SIDE * SIDE];
    for (int i = 0; i < SIDE * SIDE; i++)
        d[i] = (gp_disk){x0 + pitch * (i % SIDE), y0 + pitch * (i / SIDE), 0.13, 0.13};
    gp_rt *rt;
    gp_error err;
    CHECK(gp_rt_build(d, SIDE * SIDE, NULL, &rt, &err) == 0);
    gp_rng rng;
    gp_rng_seed(&rng, 11);
    int32_t ids[SIDE * SIDE];
    for (int round = 0; round < 40; round++) {
        size_t moved = 0;
        for (int i = 0; i < SIDE * SIDE; i++) {
            if (gp_rng_uniform(&rng) < 0.5)
                continue;
            /* back to the grid every fourth round (ties), else up to 3 ulps of 16 off it */
            double ulp = 0x1p-48, kx = round % 4 ? floor(7.0 * gp_rng_uniform(&rng)) - 3.0 : 0.0,
                   ky = round % 4 ? floor(7.0 * gp_rng_uniform(&rng)) - 3.0 : 0.0;
            d[i].x = x0 + pitch * (i % SIDE) + kx * ulp;
            d[i].y = y0 + pitch * (i / SIDE) + ky * ulp;
            ids[moved++] = i;
        }
        CHECK(gp_rt_update_moved(rt, d, SIDE * SIDE, ids, moved, GP_RT_UPDATE_FLIPS, NULL, NULL, &err) == 0);
        CHECK_MSG(gp_rt_is_regular(rt), "round %d", round);
    }
    gp_rt_free(rt);
}

/* A progress callback that counts its calls, checks the fractions rise, and raises the
 * flag at the call `raise_at` (0: never). */
typedef struct build_watch {
    gp_cancel_flag flag;
    int calls, raise_at;
    double last;
} build_watch;

static void watch_build(void *ctx, const char *stage, double fraction)
{
    build_watch *w = ctx;
    CHECK_STR(stage, "triangulation");
    CHECK(fraction > w->last && fraction < 1.0);
    w->last = fraction;
    if (++w->calls == w->raise_at)
        atomic_store(&w->flag, 1);
}

static void test_a_raised_flag_stops_builds_updates_and_measures(void)
{
    enum { ROWS = 100, COLS = 100, N = ROWS * COLS };
    gp_disk *d = malloc(N * sizeof *d);
    size_t n = hex_patch(d, ROWS, COLS, 0.0, 0.0);
    gp_error err;
    gp_rt *rt = NULL;
    /* untouched, the build reports between its batches and ends */
    build_watch w = {0, 0, 0, 0.0};
    gp_progress progress = {watch_build, &w, &w.flag};
    CHECK(gp_rt_build(d, n, &progress, &rt, &err) == 0 && rt);
    CHECK_MSG(w.calls == (int)((n - 1) / GP_RT_INSERT_BATCH), "%d reports", w.calls);
    gp_rt_free(rt);
    /* raised at the first report, it stops at the next batch: no triangulation, no second
     * report */
    build_watch stop = {0, 0, 1, 0.0};
    gp_progress stopping = {watch_build, &stop, &stop.flag};
    rt = (gp_rt *)&stop; /* must come back NULL */
    CHECK(gp_rt_build(d, n, &stopping, &rt, &err) == GP_ECANCELED && rt == NULL);
    CHECK(stop.calls == 1 && strstr(err.message, "canceled after 8192 of 10000") != NULL);
    /* raised before, the build stops in its spatial sort (10^4 disks: over 10^5
     * comparisons, a check every 2^16); an update of more than a batch of moves stops,
     * and so does a rebuild */
    gp_cancel_flag raised;
    atomic_init(&raised, 1);
    gp_progress canceled = {NULL, NULL, &raised};
    CHECK(gp_rt_build(d, n, &canceled, &rt, &err) == GP_ECANCELED && rt == NULL);
    CHECK(strstr(err.message, "while sorting") != NULL);
    CHECK(gp_rt_build(d, n, NULL, &rt, &err) == 0);
    int32_t *ids = malloc(N * sizeof *ids);
    for (size_t i = 0; i < n; i++)
        ids[i] = (int32_t)i;
    CHECK(gp_rt_update_moved(rt, d, n, ids, n, GP_RT_UPDATE_FLIPS, NULL, &canceled, &err) == GP_ECANCELED);
    gp_rt_free(rt);
    CHECK(gp_rt_build(d, n, NULL, &rt, &err) == 0);
    CHECK(gp_rt_update_moved(rt, d, n, ids, 1, GP_RT_UPDATE_REBUILD, NULL, &canceled, &err) == GP_ECANCELED);
    gp_rt_free(rt);
    /* the walk of all the rings (10^4 vertices, fewer than GP_RT_RINGS_PER_CHECK: the
     * check after the walk) stops too, and hands back no array */
    CHECK(gp_rt_build(d, n, NULL, &rt, &err) == 0);
    size_t *start = malloc((n + 1) * sizeof *start);
    int32_t *rings = (int32_t *)&raised; /* must come back NULL */
    CHECK(gp_rt_rings(rt, start, NULL, &rings, &canceled) == GP_ECANCELED && rings == NULL);
    CHECK(gp_rt_rings(rt, start, NULL, &rings, NULL) == 0 && rings != NULL);
    free(rings);
    free(start);
    gp_rt_free(rt);
    free(ids);
    free(d);
}

int main(void)
{
    RUN(test_hexagonal_patch_rings_are_six_touching_neighbours_ccw);
    RUN(test_triangles_have_empty_power_circles_by_brute_force);
    RUN(test_hidden_and_duplicate_disks_are_geometry_errors);
    RUN(test_degenerate_inputs_have_rings_too);
    RUN(test_all_rings_at_once_are_the_rings_one_by_one);
    RUN(test_updates_after_moves_match_a_fresh_build);
    RUN(test_updates_stay_regular_on_near_ties);
    RUN(test_a_raised_flag_stops_builds_updates_and_measures);
    return check_status();
}
