/* test_geometry.c - tangent placement, joint laws, the domain and the bucket grid. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/disk.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/rng.h"
#include "grid.h"

static void test_placed_disk_touches_both_on_the_left(void)
{
    gp_rng rng;
    gp_rng_seed(&rng, 1);
    int tangent = 1, left = 1;
    for (int i = 0; i < 10000; i++) {
        gp_disk a = {10 * gp_rng_uniform(&rng), 10 * gp_rng_uniform(&rng), 0, 0.1 + gp_rng_uniform(&rng)};
        double angle = 2 * M_PI * gp_rng_uniform(&rng);
        gp_disk b = {0, 0, 0, 0.1 + gp_rng_uniform(&rng)};
        double d = a.R + b.R + 0.5 * gp_rng_uniform(&rng);
        b.x = a.x + d * cos(angle);
        b.y = a.y + d * sin(angle);
        double R = 0.05 + gp_rng_uniform(&rng), x, y;
        if (!gp_place_tangent(&a, &b, R, &x, &y))
            continue;
        tangent &= fabs(hypot(x - a.x, y - a.y) - (a.R + R)) < 1e-12 * (a.R + R + 10);
        tangent &= fabs(hypot(x - b.x, y - b.y) - (b.R + R)) < 1e-12 * (b.R + R + 10);
        left &= gp_orient2d(a.x, a.y, b.x, b.y, x, y) > 0.0;
    }
    CHECK(tangent);
    CHECK(left);
}

static void test_no_placement_when_the_gap_is_wider_than_the_disk(void)
{
    gp_disk a = {0, 0, 0, 1}, b = {5, 0, 0, 1};
    double x, y;
    CHECK(!gp_place_tangent(&a, &b, 1.4, &x, &y)); /* needs d <= 1 + 1 + 2 R = 4.8 */
    CHECK(gp_place_tangent(&a, &b, 1.5, &x, &y));  /* d = 5 = 2 + 3: touches both, on the line */
    CHECK_NEAR(x, 2.5, 1e-12);
    CHECK_NEAR(y, 0.0, 1e-6);
}

static void test_equal_disks_give_the_equilateral_position(void)
{
    gp_disk a = {0, 0, 0, 1}, b = {2, 0, 0, 1};
    double x, y;
    CHECK(gp_place_tangent(&a, &b, 1.0, &x, &y));
    CHECK_NEAR(x, 1.0, 1e-15);
    CHECK_NEAR(y, sqrt(3.0), 1e-15);
}

static void test_overlap_predicate_uses_the_contact_tolerance(void)
{
    gp_disk a = {0, 0, 0, 1}, b = {2, 0, 0, 1};
    CHECK(!gp_disks_overlap(&a, &b)); /* touching */
    b.x = 2.0 * (1.0 - 0.5 * GP_CONTACT_RTOL);
    CHECK(!gp_disks_overlap(&a, &b)); /* within the tolerance */
    b.x = 2.0 * (1.0 - 2.0 * GP_CONTACT_RTOL);
    CHECK(gp_disks_overlap(&a, &b));
}

static void test_joint_laws_and_packing_range(void)
{
    gp_joint none = {GP_JOINT_NONE, 0, 0, 0}, c = {GP_JOINT_CONSTANT, 0.1, 0, 0},
             inv = {GP_JOINT_INVERSE, 0, 2.0, 0}, pw = {GP_JOINT_POWER, 0, 1.0, -0.5};
    CHECK(gp_joint_thickness(&none, 3.0) == 0.0);
    CHECK(gp_joint_thickness(NULL, 3.0) == 0.0);
    CHECK(gp_joint_packing_radius(&c, 0.9) == 0.9 + 0.1);
    CHECK_NEAR(gp_joint_thickness(&inv, 4.0), 0.5, 1e-15);
    CHECK_NEAR(gp_joint_thickness(&pw, 4.0), 0.5, 1e-15);
    double lo, hi;
    /* r + 2/r on [1, 4] is smallest at r = sqrt 2 (2 sqrt 2) and largest at 4 (4.5) */
    gp_joint_packing_range(&inv, 1.0, 4.0, &lo, &hi);
    CHECK_NEAR(lo, 2.0 * sqrt(2.0), 1e-12);
    CHECK_NEAR(hi, 4.5, 1e-12);
    /* r + r^-1/2 on [0.1, 2]: stationary at r = (1/(1*0.5))^(1/(-1.5)) = 2^(-2/3) */
    gp_joint_packing_range(&pw, 0.1, 2.0, &lo, &hi);
    double rs = pow(2.0, -2.0 / 3.0);
    CHECK_NEAR(lo, rs + 1.0 / sqrt(rs), 1e-12);
    CHECK_NEAR(hi, 0.1 + 1.0 / sqrt(0.1), 1e-12);
    CHECK_STR(gp_joint_law_name(GP_JOINT_INVERSE), "inverse");
}

static void test_domain_corners_and_containment(void)
{
    gp_domain d = {237, 300, 0};
    double x, y;
    gp_domain_corner(&d, 2, &x, &y);
    CHECK(x == 237 && y == 300);
    CHECK(gp_domain_area(&d) == 237.0 * 300.0);
    CHECK(gp_domain_contains_disk(&d, 5, 5, 5, 0));
    CHECK(!gp_domain_contains_disk(&d, 5, 5, 5.001, 0));
    CHECK(gp_domain_contains_disk(&d, 5, 5, 5.001, 0.01));
}

static void test_grid_finds_exactly_the_overlaps_brute_force_finds(void)
{
    gp_domain dom = {20, 10, 0};
    enum { N = 2000 };
    gp_disk *disks = malloc(N * sizeof *disks);
    gp_rng rng;
    gp_rng_seed(&rng, 3);
    gp_grid grid;
    CHECK(gp_grid_init(&grid, &dom, 0.5, 16, 1 << 20) == 0);
    CHECK(gp_grid_reserve(&grid, N) == 0);
    for (int i = 0; i < N; i++) {
        disks[i] = (gp_disk){20 * gp_rng_uniform(&rng), 10 * gp_rng_uniform(&rng), 0,
                             0.05 + 0.45 * gp_rng_uniform(&rng)};
        gp_grid_insert(&grid, i, disks[i].x, disks[i].y);
    }
    /* remove a few, to exercise removal */
    for (int i = 0; i < N; i += 7)
        gp_grid_remove(&grid, i, disks[i].x, disks[i].y);
    int mismatches = 0;
    int32_t found[N];
    for (int t = 0; t < 500; t++) {
        double x = 20 * gp_rng_uniform(&rng), y = 10 * gp_rng_uniform(&rng);
        double R = 0.05 + 0.45 * gp_rng_uniform(&rng);
        size_t n = gp_grid_overlaps(&grid, disks, x, y, R, 1, 2, found, N);
        size_t expected = 0;
        for (int i = 0; i < N; i++) {
            if (i % 7 == 0 || i == 1 || i == 2)
                continue;
            gp_disk c = {x, y, R, R};
            expected += gp_disks_overlap(&c, &disks[i]);
        }
        mismatches += n != expected;
        int32_t first = gp_grid_first_overlap(&grid, disks, x, y, R, 1, 2);
        mismatches += (first == GP_GRID_NONE) != (expected == 0);
    }
    CHECK_MSG(mismatches == 0, "%d queries disagree with brute force", mismatches);
    gp_grid_free(&grid);
    free(disks);
}

static void test_grid_refuses_too_many_cells(void)
{
    gp_domain dom = {1e6, 1e6, 0};
    gp_grid grid;
    CHECK(gp_grid_init(&grid, &dom, 0.001, 16, 1000000) == GP_ETOOBIG);
}

int main(void)
{
    RUN(test_placed_disk_touches_both_on_the_left);
    RUN(test_no_placement_when_the_gap_is_wider_than_the_disk);
    RUN(test_equal_disks_give_the_equilateral_position);
    RUN(test_overlap_predicate_uses_the_contact_tolerance);
    RUN(test_joint_laws_and_packing_range);
    RUN(test_domain_corners_and_containment);
    RUN(test_grid_finds_exactly_the_overlaps_brute_force_finds);
    RUN(test_grid_refuses_too_many_cells);
    return check_status();
}
