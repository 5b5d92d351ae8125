/* test_nearby.c - the disks near a balancing centre's positions (core/nearby.h): whether a
 * position is clear answers as a brute-force test over every disk does, for positions in
 * and out of the gathered box, after disks have moved and after the sort. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/rng.h"
#include "nearby.h"
#include "packing_checks.h"

#define DISKS 2000
#define QUERIES 2000

/* Brute force over every disk but `id`, with the tests' own tolerance: the disks closer
 * than (R + R_q)(1 - TEST_OVERLAP_RTOL). */
static int clear_by_brute_force(const gp_disk *d, size_t n, int32_t id, double R, double x, double y)
{
    for (size_t q = 0; q < n; q++) {
        double reach = (R + d[q].R) * (1.0 - TEST_OVERLAP_RTOL);
        if ((int32_t)q != id && hypot(d[q].x - x, d[q].y - y) < reach)
            return 0;
    }
    return 1;
}

/* Random queries around random disks: a box around the disk, positions inside it, at its
 * edge and outside it; counts the disagreements with brute force and how many of each
 * answer were seen (both must occur for the test to mean anything). */
static size_t disagreements(nearby *nb, const gp_disk *d, size_t n, const gp_domain *dom, gp_rng *rng,
                            size_t *clear, size_t *blocked, size_t *outside)
{
    size_t wrong = 0;
    for (int k = 0; k < QUERIES; k++) {
        int32_t id = (int32_t)(gp_rng_uniform(rng) * (double)n);
        double R = d[id].R, half = 2.0 * R * gp_rng_uniform(rng);
        double x0 = d[id].x - half, y0 = d[id].y - half * gp_rng_uniform(rng);
        double x1 = d[id].x + half * gp_rng_uniform(rng), y1 = d[id].y + half;
        CHECK(nearby_gather(nb, d, id, R, x0, y0, x1, y1, 1e-6 * R) == 0);
        for (int t = 0; t < 8; t++) {
            /* t < 6 in the box, 6 on a corner, 7 anywhere near the disk */
            double u = gp_rng_uniform(rng), v = gp_rng_uniform(rng);
            double x = t < 6 ? x0 + u * (x1 - x0) : (t == 6 ? x1 : d[id].x + 6.0 * R * (u - 0.5));
            double y = t < 6 ? y0 + v * (y1 - y0) : (t == 6 ? y0 : d[id].y + 6.0 * R * (v - 0.5));
            if (x < 0.0 || y < 0.0 || x > dom->width || y > dom->height)
                continue;
            int got = nearby_is_clear(nb, d, id, R, x, y), want = clear_by_brute_force(d, n, id, R, x, y);
            wrong += got != want;
            *clear += want;
            *blocked += !want;
            *outside += x < x0 || x > x1 || y < y0 || y > y1;
        }
    }
    return wrong;
}

static void test_clear_positions_are_those_brute_force_finds(void)
{
    /* disks of radii 0.2 to 1 at random, overlapping or not: the predicate does not care */
    gp_domain dom = {60.0, 40.0, 0};
    gp_disk *d = malloc(DISKS * sizeof *d);
    gp_rng rng;
    gp_rng_seed(&rng, 11);
    double R_max = 0.0;
    for (size_t i = 0; i < DISKS; i++) {
        double R = 0.2 + 0.8 * gp_rng_uniform(&rng);
        d[i] = (gp_disk){R + (dom.width - 2 * R) * gp_rng_uniform(&rng),
                         R + (dom.height - 2 * R) * gp_rng_uniform(&rng), R, R};
        R_max = fmax(R_max, R);
    }
    nearby nb;
    CHECK(nearby_init(&nb, &dom, d, DISKS, R_max) == 0);
    size_t clear = 0, blocked = 0, outside = 0;
    CHECK(disagreements(&nb, d, DISKS, &dom, &rng, &clear, &blocked, &outside) == 0);

    /* a third of the disks move (some twice) and wait in the lists: the answers follow */
    for (size_t i = 0; i < DISKS; i += 3)
        for (size_t twice = 0; twice < 1 + i % 2; twice++) {
            double old_x = d[i].x, old_y = d[i].y;
            d[i].x = fmin(fmax(d[i].x + 3.0 * (gp_rng_uniform(&rng) - 0.5), d[i].R), dom.width - d[i].R);
            d[i].y = fmin(fmax(d[i].y + 3.0 * (gp_rng_uniform(&rng) - 0.5), d[i].R), dom.height - d[i].R);
            nearby_move(&nb, d, (int32_t)i, old_x, old_y);
        }
    CHECK(disagreements(&nb, d, DISKS, &dom, &rng, &clear, &blocked, &outside) == 0);
    nearby_sort(&nb, d);
    CHECK(disagreements(&nb, d, DISKS, &dom, &rng, &clear, &blocked, &outside) == 0);
    CHECK_MSG(clear > 1000 && blocked > 1000 && outside > 1000, "clear %zu, blocked %zu, outside the box %zu",
              clear, blocked, outside);
    nearby_free(&nb);
    free(d);
}

static void test_gathering_keeps_only_disks_that_can_reach_the_box(void)
{
    /* a row of unit disks 3 apart: a box around disk 5 of half-width 1.25 can be reached
     * by disks whose centres are within 1 + 1 of it, that is its neighbours 3 away (1.75
     * from the box's edge) but not the next ones (4.75 from it) */
    gp_domain dom = {40.0, 4.0, 0};
    gp_disk d[12];
    for (int i = 0; i < 12; i++)
        d[i] = (gp_disk){1.5 + 3.0 * i, 2.0, 1.0, 1.0};
    nearby nb;
    CHECK(nearby_init(&nb, &dom, d, 12, 1.0) == 0);
    CHECK(nearby_gather(&nb, d, 5, 1.0, d[5].x - 1.25, 1.5, d[5].x + 1.25, 2.5, 0.0) == 0);
    CHECK_MSG(nb.gn == 2, "%zu gathered", nb.gn);
    for (size_t k = 0; k < nb.gn; k++)
        CHECK(fabs(nb.gx[k] - d[5].x) == 3.0);
    nearby_free(&nb);
}

int main(void)
{
    RUN(test_gathering_keeps_only_disks_that_can_reach_the_box);
    RUN(test_clear_positions_are_those_brute_force_finds);
    return check_status();
}
