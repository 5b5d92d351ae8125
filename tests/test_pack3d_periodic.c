/* test_pack3d_periodic.c - the 3D packer on boxes periodic along some axes (docs/3d.md
 * §11), over many seeds, every combination of periodic axes and three laws: no two
 * packing spheres overlap under the minimum image (an all-pairs check of the test's own),
 * centres in [0, side) along periodic axes and spheres inside along walled ones, every
 * sphere but the seed cluster tangent to three walls or sphere images, some spheres
 * across a periodic side, the radii exactly the law's draws (every bin within 4 standard
 * errors pooled), bounded work; periodic sides under 12 R_max refused. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/pack3d.h"
#include "grainpack/spec.h"
#include "pack3d_internal.h"
#include "pack3d_laws.h"

/* Relative overlap and contact tolerances, as test_pack3d.c's. */
#define TEST_RTOL 1e-9
#define CONTACT_RTOL 1e-9
/* The periodic axes the seeds cycle through: fully periodic most often (the seed cluster
 * of three spheres), then two, one and no walled axis pair in every orientation. */
static const unsigned MASKS[] = {7, 7, 3, 5, 6, 1, 2, 4};
#define NMASKS (sizeof MASKS / sizeof *MASKS)

static void sides_of(const gp_box *box, double side[3])
{
    side[0] = box->width;
    side[1] = box->height;
    side[2] = box->depth;
}

/* The vector from b to a between their nearest images (independent of the packer's). */
static void delta(const gp_box *box, const gp_sphere *a, const gp_sphere *b, double d[3])
{
    double side[3];
    sides_of(box, side);
    d[0] = a->x - b->x;
    d[1] = a->y - b->y;
    d[2] = a->z - b->z;
    for (int k = 0; k < 3; k++)
        if (box->periodic & (1u << k)) {
            while (d[k] > 0.5 * side[k])
                d[k] -= side[k];
            while (d[k] < -0.5 * side[k])
                d[k] += side[k];
        }
}

static double distance(const gp_box *box, const gp_sphere *a, const gp_sphere *b)
{
    double d[3];
    delta(box, a, b, d);
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* Overlapping pairs under the minimum image, all pairs; *worst the largest 1 - d / (R1 + R2). */
static size_t count_overlaps(const gp_sphere *s, size_t n, const gp_box *box, double *worst)
{
    size_t bad = 0;
    *worst = -1.0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            double rel = 1.0 - distance(box, &s[i], &s[j]) / (s[i].R + s[j].R);
            *worst = fmax(*worst, rel);
            bad += rel > TEST_RTOL;
        }
    return bad;
}

/* Spheres outside: a centre out of [0, side) on a periodic axis, a sphere through a wall
 * on a walled one. *crossing: spheres sticking out across a periodic side (seen there by
 * their images). */
static size_t count_outside(const gp_sphere *s, size_t n, const gp_box *box, size_t *crossing)
{
    double side[3];
    sides_of(box, side);
    size_t bad = 0;
    *crossing = 0;
    for (size_t i = 0; i < n; i++) {
        const double p[3] = {s[i].x, s[i].y, s[i].z};
        double slack = s[i].R * TEST_RTOL;
        int out = 0, across = 0;
        for (int a = 0; a < 3; a++) {
            if (box->periodic & (1u << a)) {
                out |= !(p[a] >= 0.0 && p[a] < side[a]);
                across |= p[a] < s[i].R || p[a] > side[a] - s[i].R;
            } else {
                out |= p[a] - s[i].R < -slack || p[a] + s[i].R > side[a] + slack;
            }
        }
        bad += out;
        *crossing += across;
    }
    return bad;
}

/* The spheres from `first` on touching fewer than three walls and earlier sphere images. */
static size_t count_loose(const gp_sphere *s, size_t n, const gp_box *box, size_t first)
{
    double side[3];
    sides_of(box, side);
    size_t loose = 0;
    for (size_t i = first; i < n; i++) {
        int touches = 0;
        const double p[3] = {s[i].x, s[i].y, s[i].z};
        for (int a = 0; a < 3; a++)
            if (!(box->periodic & (1u << a)))
                touches += (fabs(p[a] - s[i].R) <= CONTACT_RTOL * s[i].R) +
                           (fabs(side[a] - p[a] - s[i].R) <= CONTACT_RTOL * s[i].R);
        for (size_t j = 0; j < i && touches < 3; j++) {
            double sum = s[i].R + s[j].R;
            touches += fabs(distance(box, &s[i], &s[j]) - sum) <= CONTACT_RTOL * sum;
        }
        loose += touches < 3;
    }
    return loose;
}

static void check_law(law3 *law)
{
    const gp_distribution *dist = &law->spec.dist;
    law3_tally tally;
    law3_tally_init(&tally, dist);
    size_t crossing_all = 0;
    double worst_overlap = -1.0, min_density = 1.0;
    for (int seed = 1; seed <= law->seeds; seed++) {
        gp_box box = {law->side, law->side * 0.9, law->side * 1.1, MASKS[seed % NMASKS]};
        gp_pack3d_params params = {&box, dist, NULL, (uint64_t)seed * 7919u, 0, GP_PACK3D_LEVEL};
        gp_packing3d out;
        gp_error err;
        int rc = gp_pack3d(&params, NULL, &out, &err);
        CHECK_MSG(rc == 0, "%s seed %d periodic %u: %s", law->name, seed, box.periodic, err.message);
        if (rc)
            continue;
        double worst;
        CHECK_MSG(count_overlaps(out.spheres, out.count, &box, &worst) == 0,
                  "%s seed %d periodic %u: worst %.3g", law->name, seed, box.periodic, worst);
        worst_overlap = fmax(worst_overlap, worst);
        size_t crossing;
        CHECK(count_outside(out.spheres, out.count, &box, &crossing) == 0);
        CHECK_MSG(crossing > 0, "%s seed %d: no sphere across a periodic side", law->name, seed);
        crossing_all += crossing;
        /* the seed cluster: one sphere against two walls, two against one, three with none */
        int walled = 3 - __builtin_popcount(box.periodic);
        size_t first = walled >= 2 ? 1 : walled == 1 ? 2 : 3;
        size_t loose = count_loose(out.spheres, out.count, &box, first);
        CHECK_MSG(loose == 0, "%s seed %d periodic %u: %zu spheres touch fewer than three", law->name,
                  seed, box.periodic, loose);
        double density = law3_check_packing(law->name, seed, &params, &out);
        min_density = fmin(min_density, density);
        CHECK_MSG(density >= law->min_density, "%s seed %d periodic %u: density %.4f", law->name, seed,
                  box.periodic, density);
        law3_tally_add(&tally, &out);
        gp_packing3d_free(&out);
    }
    double max_z = law3_tally_check(&tally, law->name);
    fprintf(stderr,
            "  %s: %d seeds, %zu spheres (%zu across a side), min density %.4f, worst overlap %.2g, "
            "max |z| %.2f\n",
            law->name, law->seeds, tally.pooled, crossing_all, min_density, worst_overlap, max_z);
}

static law3 laws[3] = {
    {.name = "one radius", .seeds = 8, .side = 8.0, .min_density = 0.46},
    {.name = "bagi", .seeds = 16, .side = 6.0, .min_density = 0.50},
    {.name = "iron", .seeds = 16, .side = 108.0, .min_density = 0.50},
};

static void test_properties(void)
{
    for (int i = 0; i < 3; i++)
        check_law(&laws[i]);
}

/* A periodic side under 12 R_max, or an unknown axis bit, is refused with the periodic
 * field's pointer; the same side with walls is packed. */
static void test_bad_inputs(void)
{
    const gp_distribution *one = &laws[0].spec.dist; /* radius 0.5: periodic sides >= 6 */
    gp_box box = {8, 5.9, 8, GP_PERIODIC_Y};
    gp_pack3d_params p = {&box, one, NULL, 1, 0, GP_PACK3D_LEVEL};
    gp_packing3d out;
    gp_error err;
    CHECK(gp_pack3d(&p, NULL, &out, &err) == GP_EINVAL && out.count == 0 &&
          strcmp(err.pointer, "/domain/periodic") == 0 && strstr(err.message, "12"));
    box.periodic = GP_PERIODIC_X | GP_PERIODIC_Z; /* the short side walled */
    CHECK(gp_pack3d(&p, NULL, &out, &err) == 0 && out.count > 0);
    gp_packing3d_free(&out);
    box.periodic = 8u;
    CHECK(gp_pack3d(&p, NULL, &out, &err) == GP_EINVAL && strcmp(err.pointer, "/domain/periodic") == 0);
}

int main(void)
{
    if (load_laws3(laws))
        return 1;
    RUN(test_properties);
    RUN(test_bad_inputs);
    for (int i = 0; i < 3; i++)
        gp_spec_free(&laws[i].spec);
    return check_status();
}
