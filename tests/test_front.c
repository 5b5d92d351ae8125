/* test_front.c - the front's loops: placing on a segment, closing by ear and by split,
 * degenerate loops vanishing, the order segments are tried in, and barriers. */
#include <stdlib.h>

#include "check.h"
#include "front.h"
#include "grid.h"

typedef struct fixture {
    gp_domain dom;
    gp_disk *disks;
    uint32_t *levels;
    gp_grid grid;
    front f;
} fixture;

/* n disks of radius 1 on a circle of radius 10 around (20, 20), counter-clockwise, none
 * touching: the loop is a convex polygon. */
static void setup(fixture *fx, int n)
{
    fx->dom = (gp_domain){40, 40, 0};
    fx->disks = calloc(64, sizeof *fx->disks);
    fx->levels = calloc(64, sizeof *fx->levels);
    gp_grid_init(&fx->grid, &fx->dom, 1.0, 64, 1 << 16);
    front_init(&fx->f, (const gp_disk *const *)&fx->disks, (const uint32_t *const *)&fx->levels,
               &fx->grid, 64, 0.05, 1.0);
    for (int i = 0; i < 64; i++)
        front_disk_added(&fx->f, i);
    int32_t ids[64];
    for (int i = 0; i < n; i++) {
        double t = 2 * M_PI * i / n;
        fx->disks[i] = (gp_disk){20 + 10 * cos(t), 20 + 10 * sin(t), 1, 1};
        gp_grid_insert(&fx->grid, i, fx->disks[i].x, fx->disks[i].y);
        ids[i] = i;
    }
    CHECK(front_add_loop(&fx->f, ids, (size_t)n) == 0);
}

static void teardown(fixture *fx)
{
    front_free(&fx->f);
    gp_grid_free(&fx->grid);
    free(fx->disks);
    free(fx->levels);
}

/* The disks of the loop through node u, in order, into out; returns the count. */
static int loop_disks(const front *f, int32_t u, int32_t *out)
{
    int n = 0;
    int32_t v = u;
    do {
        out[n++] = f->nodes[v].disk;
        v = f->nodes[v].next;
    } while (v != u && n < 64);
    return n;
}

static int32_t node_of(const front *f, int32_t disk)
{
    return f->first_node[disk];
}

static void test_loop_links_disks_in_order_and_queues_every_segment(void)
{
    fixture fx;
    setup(&fx, 6);
    int32_t order[64];
    CHECK(loop_disks(&fx.f, node_of(&fx.f, 0), order) == 6);
    for (int i = 0; i < 6; i++)
        CHECK(order[i] == i);
    CHECK(fx.f.active == 6);
    CHECK(front_low_level(&fx.f) == 0);
    teardown(&fx);
}

static void test_place_inserts_the_disk_between_the_segment_ends(void)
{
    fixture fx;
    setup(&fx, 6);
    fx.disks[6] = (gp_disk){21, 19, 1, 1};
    fx.levels[6] = 1;
    CHECK(front_place(&fx.f, node_of(&fx.f, 2), 6, 1) == 0);
    int32_t order[64];
    int n = loop_disks(&fx.f, node_of(&fx.f, 0), order);
    CHECK(n == 7 && order[2] == 2 && order[3] == 6 && order[4] == 3);
    CHECK(fx.f.active == 7);
    /* the two new segments have levels 0 + 1 */
    CHECK(fx.f.nodes[node_of(&fx.f, 2)].level == 1 && fx.f.nodes[node_of(&fx.f, 6)].level == 1);
    teardown(&fx);
}

static void test_close_on_the_disk_after_cuts_an_ear(void)
{
    fixture fx;
    setup(&fx, 6);
    /* segment 1 -> 2 closed on disk 3: disk 2 leaves the loop */
    CHECK(front_close(&fx.f, node_of(&fx.f, 1), node_of(&fx.f, 3)) == 0);
    int32_t order[64];
    int n = loop_disks(&fx.f, node_of(&fx.f, 0), order);
    CHECK(n == 5 && order[1] == 1 && order[2] == 3);
    CHECK(node_of(&fx.f, 2) == FRONT_NONE);
    CHECK(fx.f.active == 5);
    teardown(&fx);
}

static void test_close_on_the_disk_before_cuts_the_other_ear(void)
{
    fixture fx;
    setup(&fx, 6);
    /* segment 1 -> 2 closed on disk 0: disk 1 leaves */
    CHECK(front_close(&fx.f, node_of(&fx.f, 1), node_of(&fx.f, 0)) == 0);
    int32_t order[64];
    int n = loop_disks(&fx.f, node_of(&fx.f, 0), order);
    CHECK(n == 5 && order[0] == 0 && order[1] == 2);
    CHECK(node_of(&fx.f, 1) == FRONT_NONE);
    teardown(&fx);
}

static void test_close_across_splits_the_loop_in_two(void)
{
    fixture fx;
    setup(&fx, 8);
    /* segment 0 -> 1 closed on disk 4: loops 0 4 5 6 7 and 4' 1 2 3 */
    CHECK(front_close(&fx.f, node_of(&fx.f, 0), node_of(&fx.f, 4)) == 0);
    int32_t a[64], b[64];
    int na = loop_disks(&fx.f, node_of(&fx.f, 0), a);
    int nb = loop_disks(&fx.f, node_of(&fx.f, 1), b);
    CHECK(na == 5 && a[0] == 0 && a[1] == 4 && a[2] == 5 && a[4] == 7);
    CHECK(nb == 4 && b[0] == 1 && b[1] == 2 && b[2] == 3 && b[3] == 4);
    /* disk 4 is on both loops, once each, and the loops have different labels */
    int32_t on_a = front_node_on_loop(&fx.f, 4, node_of(&fx.f, 0));
    int32_t on_b = front_node_on_loop(&fx.f, 4, node_of(&fx.f, 1));
    CHECK(on_a != FRONT_NONE && on_b != FRONT_NONE && on_a != on_b);
    CHECK(fx.f.cold[node_of(&fx.f, 0)].loop != fx.f.cold[node_of(&fx.f, 1)].loop);
    CHECK(front_node_on_loop(&fx.f, 2, node_of(&fx.f, 0)) == FRONT_NONE);
    CHECK(fx.f.active == 9);
    teardown(&fx);
}

static void test_a_triangle_closed_vanishes(void)
{
    fixture fx;
    setup(&fx, 3);
    CHECK(front_close(&fx.f, node_of(&fx.f, 0), node_of(&fx.f, 2)) == 0);
    CHECK(fx.f.active == 0 && fx.f.frozen == 0);
    for (int i = 0; i < 3; i++)
        CHECK(node_of(&fx.f, i) == FRONT_NONE);
    teardown(&fx);
}

static void test_newest_untried_first_then_the_best_fit(void)
{
    fixture fx;
    setup(&fx, 6);
    /* all six are untried at level 0: the newest (disk 5's segment) comes first */
    int32_t top = front_top(&fx.f, 0);
    CHECK(fx.f.nodes[top].disk == 5);
    front_mark_failed(&fx.f, top, 0.6);
    CHECK(fx.f.nodes[front_top(&fx.f, 0)].disk == 4);
    /* an untried segment is eligible for any radius, a failed one only below its radius */
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.9)].disk == 4);
    /* once all have failed (4 for 0.5, 3 for 0.4, ... 0 for 0.1), the first segment is
     * the tightest pocket, the one that failed for the smallest radius; the one a radius
     * is tried on next is the best fit, the one whose limit is the least above the radius */
    for (int i = 4; i >= 0; i--)
        front_mark_failed(&fx.f, front_top(&fx.f, 0), 0.1 * (i + 1));
    CHECK(fx.f.nodes[front_top(&fx.f, 0)].disk == 0);
    CHECK(front_next_eligible(&fx.f, 0, 0.6) == FRONT_NONE);
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.55)].disk == 5);
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.45)].disk == 4);
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.15)].disk == 1);
    front_mark_failed(&fx.f, node_of(&fx.f, 5), 0.45); /* a smaller failure lowers it */
    CHECK(fx.f.nodes[node_of(&fx.f, 5)].fail_R == 0.45);
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.35)].disk == 3);
    /* 0.449 is in 0.45's class, which counts as failed for it: 4 (0.5) is the best fit */
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.449)].disk == 4);
    CHECK(fx.f.nodes[front_next_eligible(&fx.f, 0, 0.46)].disk == 4);
    CHECK(front_next_eligible(&fx.f, 0, 0.5) == FRONT_NONE);
    front_mark_failed(&fx.f, node_of(&fx.f, 4), 0.9);  /* a larger one does not raise it */
    CHECK(fx.f.nodes[node_of(&fx.f, 4)].fail_R == 0.5);
    front_freeze(&fx.f, node_of(&fx.f, 4));
    CHECK(fx.f.active == 5 && fx.f.frozen == 1);
    CHECK(front_next_eligible(&fx.f, 0, 0.46) == FRONT_NONE);
    front_freeze(&fx.f, node_of(&fx.f, 0));
    CHECK(fx.f.nodes[front_top(&fx.f, 0)].disk == 1);
    CHECK(front_next_eligible(&fx.f, 0, 0.05) != FRONT_NONE);
    teardown(&fx);
}

static void test_gap_segments_are_barriers_and_touching_ones_are_not(void)
{
    fixture fx;
    setup(&fx, 6); /* neighbours are 10 apart with radius 1: every segment spans a gap */
    /* a disk sitting on the middle of segment 0 -> 1 crosses it */
    double mx = 0.5 * (fx.disks[0].x + fx.disks[1].x), my = 0.5 * (fx.disks[0].y + fx.disks[1].y);
    int32_t hit = front_barrier_crossed(&fx.f, mx, my, 0.5, FRONT_NONE);
    CHECK(hit == node_of(&fx.f, 0));
    CHECK(front_barrier_crossed(&fx.f, mx, my, 0.5, node_of(&fx.f, 0)) == FRONT_NONE);
    CHECK(front_barrier_crossed(&fx.f, 20, 20, 0.5, FRONT_NONE) == FRONT_NONE);
    /* after a placement the new segments are covered by touching disks: no barrier */
    double x, y;
    CHECK(gp_place_tangent(&fx.disks[0], &fx.disks[1], 4.5, &x, &y));
    fx.disks[6] = (gp_disk){x, y, 4.5, 4.5};
    CHECK(front_place(&fx.f, node_of(&fx.f, 0), 6, 1) == 0);
    CHECK(front_barrier_crossed(&fx.f, mx, my, 0.5, FRONT_NONE) == FRONT_NONE);
    teardown(&fx);
}

int main(void)
{
    RUN(test_loop_links_disks_in_order_and_queues_every_segment);
    RUN(test_place_inserts_the_disk_between_the_segment_ends);
    RUN(test_close_on_the_disk_after_cuts_an_ear);
    RUN(test_close_on_the_disk_before_cuts_the_other_ear);
    RUN(test_close_across_splits_the_loop_in_two);
    RUN(test_a_triangle_closed_vanishes);
    RUN(test_newest_untried_first_then_the_best_fit);
    RUN(test_gap_segments_are_barriers_and_touching_ones_are_not);
    return check_status();
}
