/* test_pack_fit.c - pack_fit_limit, the radius from which a disk tangent to two others
 * meets a third, against a bisection on the placement itself over many random cases. */
#include <stdlib.h>

#include "check.h"
#include "packer.h"
#include "grainpack/rng.h"

/* Clearance between q and the disk of radius R tangent to a and b on the left of a -> b,
 * placed as the packer places it (docs/method.md §3.1): > 0 apart, < 0 overlapping. */
static double clearance(const gp_disk *a, const gp_disk *b, const gp_disk *q, double R)
{
    double x, y;
    if (!gp_place_tangent(a, b, R, &x, &y))
        return NAN;
    return sqrt((x - q->x) * (x - q->x) + (y - q->y) * (y - q->y)) - R - q->R;
}

static double segment(const gp_disk *a, const gp_disk *b, double *ux, double *uy)
{
    double dx = b->x - a->x, dy = b->y - a->y, d = sqrt(dx * dx + dy * dy);
    *ux = dx / d;
    *uy = dy / d;
    return d;
}

static void test_the_limit_is_where_the_third_disk_is_met(void)
{
    gp_rng rng;
    gp_rng_seed(&rng, 42);
    const double R_lo = 0.05, R_hi = 1.0;
    int exact = 0, whole = 0, unknown = 0;
    for (int trial = 0; trial < 200000; trial++) {
        /* a and b touching (as after a placement) or apart (after a closing), q somewhere
         * near */
        gp_disk a = {0.0, 0.0, 0.0, 0.05 + gp_rng_uniform(&rng)};
        double B = 0.05 + gp_rng_uniform(&rng), t = 2.0 * M_PI * gp_rng_uniform(&rng);
        double apart = trial % 2 ? 0.0 : 0.5 * gp_rng_uniform(&rng);
        gp_disk b = {(a.R + B + apart) * cos(t), (a.R + B + apart) * sin(t), 0.0, B};
        double Q = 0.05 + gp_rng_uniform(&rng);
        double qx = 6.0 * gp_rng_uniform(&rng) - 3.0, qy = 6.0 * gp_rng_uniform(&rng) - 3.0;
        gp_disk q = {qx, qy, 0.0, Q};
        /* the smallest radius with a position: R_lo, or half the gap between a and b */
        double R_first = fmax(R_lo, 0.5 * apart);
        if (!(R_first < R_hi) || sqrt(q.x * q.x + q.y * q.y) < a.R + Q ||
            hypot(q.x - b.x, q.y - b.y) < B + Q || !(clearance(&a, &b, &q, R_hi) < 0.0))
            continue; /* q overlapping a or b, or not in the way of R_hi */
        double ux, uy, d = segment(&a, &b, &ux, &uy);
        double limit = pack_fit_limit(&a, &b, d, ux, uy, &q, R_lo, R_hi);
        CHECK(limit >= R_lo && limit <= R_hi);
        if (limit == R_hi) {
            unknown++;
            continue;
        }
        /* q is in the way from the limit to R_hi (sampled), and not just below it */
        for (int k = 1; k <= 8; k++) {
            double R = limit + (R_hi - limit) * k / 8.0;
            CHECK_MSG(clearance(&a, &b, &q, R) < 1e-9, "trial %d: clear at %g above limit %g", trial, R,
                      limit);
        }
        if (limit <= R_first + 1e-12) {
            whole++;
            CHECK_MSG(limit == R_lo || fabs(limit - R_first) <= 1e-12, "trial %d: limit %g, first %g",
                      trial, limit, R_first);
            CHECK(clearance(&a, &b, &q, R_first) < 1e-9);
            continue;
        }
        exact++;
        CHECK_MSG(fabs(clearance(&a, &b, &q, limit)) < 1e-9, "trial %d: clearance %g at the limit %g",
                  trial, clearance(&a, &b, &q, limit), limit);
        CHECK_MSG(clearance(&a, &b, &q, limit * (1.0 - 1e-6)) > -1e-12, "trial %d: overlap below %g",
                  trial, limit);
    }
    /* most cases have a limit inside the range, a few are blocked throughout (q in the
     * pocket itself) */
    fprintf(stderr, "  %d limits inside the range, %d blocked throughout, %d unknown\n", exact, whole,
            unknown);
    CHECK(exact > 10000 && whole > 0 && unknown * 100 < exact);
}

static void test_apart_disks_and_a_disk_above_the_gap(void)
{
    /* a and b 1 apart: a tangent disk exists from R = 0.5, centred on the gap, then rises
     * as it grows; q above the gap stops it before 0.9 */
    gp_disk a = {0, 0, 0, 1}, b = {3, 0, 0, 1}, q = {1.5, 1.2, 0, 0.5};
    double ux, uy, d = segment(&a, &b, &ux, &uy);
    double limit = pack_fit_limit(&a, &b, d, ux, uy, &q, 0.1, 0.9);
    CHECK(limit > 0.5 && limit < 0.9);
    CHECK(fabs(clearance(&a, &b, &q, limit)) < 1e-12);
    /* a q on the gap itself is in the way of every radius with a position */
    gp_disk on_gap = {1.5, 0.2, 0, 0.3};
    CHECK(pack_fit_limit(&a, &b, d, ux, uy, &on_gap, 0.1, 0.9) == 0.5);
}

int main(void)
{
    RUN(test_the_limit_is_where_the_third_disk_is_met);
    RUN(test_apart_disks_and_a_disk_above_the_gap);
    return check_status();
}
