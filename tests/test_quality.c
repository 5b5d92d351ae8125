/* test_quality.c - the cell-inside test of F (core/quality.h) on a walled domain: the same
 * answer, centre by centre, as the power vertices found by dividing for every one of them
 * (quality_cell_inside skips the divisions where a vertex is clearly inside), on the
 * reference cases' packings, with cells inside and cells crossing the walls both seen. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/triangulation.h"
#include "packing_checks.h"
#include "quality.h"

#define SEEDS 4
#define RING_CAP 64

/* The rule of quality_cell_inside written out: every power vertex of the triangles around
 * p, divided for, inside the walls; a triangle not turning left fails. */
static int inside_by_division(const gp_domain *dom, const gp_disk *d, int32_t i, const int32_t *ring,
                              size_t degree)
{
    const gp_disk *p = &d[i];
    for (size_t k = 0; k < degree; k++) {
        const gp_disk *a = &d[ring[k]], *b = &d[ring[(k + 1) % degree]];
        double ax = a->x - p->x, ay = a->y - p->y, bx = b->x - p->x, by = b->y - p->y;
        double ca = 0.5 * (ax * ax + ay * ay + p->R * p->R - a->R * a->R);
        double cb = 0.5 * (bx * bx + by * by + p->R * p->R - b->R * b->R);
        double det = ax * by - ay * bx;
        if (!(det > 0.0))
            return 0;
        double ox = p->x + (ca * by - cb * ay) / det, oy = p->y + (ax * cb - bx * ca) / det;
        if (!(ox >= 0.0 && oy >= 0.0 && ox <= dom->width && oy <= dom->height))
            return 0;
    }
    return 1;
}

/* Compares the two on every interior centre of one packing; counts the answers. */
static size_t compare(const gp_domain *dom, const gp_disk *d, size_t n, size_t *inside, size_t *outside)
{
    gp_rt *rt;
    gp_error err;
    if (gp_rt_build(d, n, NULL, &rt, &err) != 0) {
        CHECK_MSG(0, "triangulation: %s", err.message);
        return 1;
    }
    quality_frame frame = {dom, 0.0, 0.0};
    size_t wrong = 0;
    for (int32_t i = 0; i < (int32_t)n; i++) {
        int32_t ring[RING_CAP];
        int hull;
        size_t degree = gp_rt_ring(rt, i, ring, RING_CAP, &hull);
        if (hull || degree < 3 || degree > RING_CAP)
            continue;
        int got = quality_cell_inside(&frame, d, i, ring, degree), want = inside_by_division(dom, d, i, ring, degree);
        wrong += got != want;
        *inside += want;
        *outside += !want;
    }
    gp_rt_free(rt);
    return wrong;
}

static void test_cells_inside_as_by_division(void)
{
    /* the reference cases' packings: most cells far inside, those along the walls
     * crossing them through the thin triangles beyond the outer disks */
    const char *cases[] = {"variable", "iron", "fixed"};
    size_t inside = 0, outside = 0;
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++)
        for (uint64_t seed = 1; seed <= SEEDS; seed++) {
            gp_spec spec;
            load_example(cases[c], &spec);
            gp_packing pk;
            pack_seed(&spec, seed, &pk);
            size_t wrong = compare(&spec.domain, pk.disks, pk.count, &inside, &outside);
            CHECK_MSG(wrong == 0, "%s seed %llu: %zu centres answered otherwise", cases[c],
                      (unsigned long long)seed, wrong);
            gp_packing_free(&pk);
            gp_spec_free(&spec);
        }
    CHECK_MSG(inside > 10000 && outside > 300, "inside %zu, outside %zu", inside, outside);
}

int main(void)
{
    RUN(test_cells_inside_as_by_division);
    return check_status();
}
