/* test_laguerre3d_periodic.c - the Laguerre polyhedra of packings in periodic boxes
 * (docs/3d.md §11), on two laws (3D Bagi with a joint, two bins of radii 2-8), every combination of
 * periodic axes, several seeds: the unshrunk cells tile the periodic box (volumes sum to
 * its volume within 1e-12 relative), no vertex of a cell has less power to any image of
 * any sphere than to its own (brute force over the 27 images), faces name grains (no
 * ghost), offset neighbours are j1 + j2 apart across the sides too, homothetic cells are
 * the power cells scaled by (r / R)^3. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grainpack/geometry3d.h"
#include "grainpack/spec.h"

/* Tolerance of the power and distance checks relative to R (vertices are accurate to
 * ~1e-15 R, merged within 1e-12 R), and of the tiling, relative to the box's volume. */
#define TOL 1e-9
#define TILE_RTOL 1e-12
/* Cells per packing whose vertices are checked against every image of every sphere. */
#define POWER_CHECKED 150

static const unsigned MASKS[] = {7, 3, 5, 6, 1, 4};
#define NMASKS (sizeof MASKS / sizeof *MASKS)

static void sides_of(const gp_box *box, double side[3])
{
    side[0] = box->width;
    side[1] = box->height;
    side[2] = box->depth;
}

/* The least power of point v to any image of sphere q. */
static double least_power(const gp_box *box, const double v[3], const gp_sphere *q)
{
    double side[3], best = INFINITY;
    sides_of(box, side);
    const double c[3] = {q->x, q->y, q->z};
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                const int s[3] = {dx, dy, dz};
                double d2 = 0.0;
                int skip = 0;
                for (int a = 0; a < 3; a++) {
                    skip |= s[a] && !((box->periodic >> a) & 1u);
                    double d = v[a] - c[a] - s[a] * side[a];
                    d2 += d * d;
                }
                if (!skip && d2 - q->R * q->R < best)
                    best = d2 - q->R * q->R;
            }
    return best;
}

static int cells(const gp_box *box, const gp_packing3d *p, gp_shrink shrink, gp_cells3d *out)
{
    gp_laguerre_params params = {shrink, 0};
    gp_error err;
    int rc = gp_laguerre3d(box, p->spheres, p->count, NULL, &params, NULL, out, &err);
    CHECK_MSG(rc == 0, "periodic %u cells: %s", box->periodic, err.message);
    return rc;
}

static void check_packing(const gp_box *box, const gp_packing3d *p, const char *name)
{
    gp_cells3d c;
    if (cells(box, p, GP_SHRINK_NONE, &c))
        return;
    double V = box->width * box->height * box->depth, sum = 0.0;
    for (size_t i = 0; i < c.count; i++)
        sum += c.volume[i];
    CHECK_MSG(fabs(sum - V) <= TILE_RTOL * V && fabs(c.power_volume_sum - V) <= TILE_RTOL * V,
              "%s periodic %u: volumes sum to %.17g, %.17g for a box of %.17g", name, box->periodic, sum,
              c.power_volume_sum, V);
    size_t ghosts = 0, walls = 0, far = 0;
    for (size_t i = 0; i < c.count; i++)
        for (size_t f = c.fstart[i]; f < c.fstart[i + 1]; f++) {
            int32_t j = c.fneighbour[f];
            ghosts += !GP_IS_WALL3D(j) && (j < 0 || (size_t)j >= p->count);
            walls += GP_IS_WALL3D(j) && ((box->periodic >> (GP_WALL3D_INDEX(j) / 2)) & 1u);
        }
    CHECK_MSG(ghosts == 0 && walls == 0, "%s periodic %u: %zu faces name a ghost, %zu a periodic wall", name,
              box->periodic, ghosts, walls);
    /* no vertex nearer in power to another sphere's image than to its own sphere */
    for (size_t i = 0; i < c.count && i < POWER_CHECKED; i++) {
        const gp_sphere *s = &p->spheres[i];
        for (size_t v = c.vstart[i]; v < c.vstart[i + 1]; v++) {
            const double *x = c.xyz + 3 * v;
            double own = (x[0] - s->x) * (x[0] - s->x) + (x[1] - s->y) * (x[1] - s->y) +
                         (x[2] - s->z) * (x[2] - s->z) - s->R * s->R;
            for (size_t q = 0; q < p->count; q++)
                far += q != i && least_power(box, x, &p->spheres[q]) < own - TOL * s->R * s->R;
        }
    }
    CHECK_MSG(far == 0, "%s periodic %u: %zu vertices nearer in power to another sphere", name, box->periodic,
              far);
    /* homothetic: each cell the power cell scaled by r / R */
    gp_cells3d h;
    if (cells(box, p, GP_SHRINK_HOMOTHETIC, &h) == 0) {
        size_t bad = 0;
        for (size_t i = 0; i < c.count; i++) {
            double k = p->spheres[i].r / p->spheres[i].R;
            bad += fabs(h.volume[i] - k * k * k * c.volume[i]) > 1e-12 * c.volume[i];
        }
        CHECK_MSG(bad == 0, "%s periodic %u: %zu homothetic volumes", name, box->periodic, bad);
        gp_cells3d_free(&h);
    }
    /* offset: each face j(r) inside the power face, so j1 + j2 between neighbours (the
     * face's plane at j from the radical plane: its distance to the centre along the
     * neighbour's nearest image) */
    gp_cells3d o;
    if (cells(box, p, GP_SHRINK_OFFSET, &o) == 0) {
        double side[3];
        sides_of(box, side);
        size_t bad = 0;
        for (size_t i = 0; i < o.count; i++) {
            const gp_sphere *s = &p->spheres[i];
            for (size_t f = o.fstart[i]; f < o.fstart[i + 1]; f++) {
                int32_t j = o.fneighbour[f];
                if (GP_IS_WALL3D(j))
                    continue;
                const gp_sphere *q = &p->spheres[j];
                double n[3] = {q->x - s->x, q->y - s->y, q->z - s->z};
                for (int a = 0; a < 3; a++)
                    if ((box->periodic >> a) & 1u)
                        n[a] -= side[a] * nearbyint(n[a] / side[a]);
                double d = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                double radical = (d * d + s->R * s->R - q->R * q->R) / (2.0 * d);
                const double *x = o.xyz + 3 * (o.vstart[i] + o.fverts[o.fvstart[f]]);
                double along = ((x[0] - s->x) * n[0] + (x[1] - s->y) * n[1] + (x[2] - s->z) * n[2]) / d;
                bad += fabs(radical - along - (s->R - s->r)) > TOL * s->R;
            }
        }
        CHECK_MSG(bad == 0, "%s periodic %u: %zu offset faces not j from the radical plane", name,
                  box->periodic, bad);
        gp_cells3d_free(&o);
    }
    gp_cells3d_free(&c);
}

static void check_law(const char *name, const char *json, double side, int seeds)
{
    gp_spec spec;
    gp_error err;
    if (gp_spec_parse(json, strlen(json), NULL, &spec, &err)) {
        CHECK_MSG(0, "%s: %s", name, err.message);
        return;
    }
    for (int seed = 1; seed <= seeds; seed++) {
        gp_box box = {side, side * 0.9, side * 1.1, MASKS[seed % NMASKS]};
        gp_pack3d_params params = {&box, &spec.dist, &spec.joint, (uint64_t)seed, 0, GP_PACK3D_LEVEL};
        gp_packing3d p;
        int rc = gp_pack3d(&params, NULL, &p, &err);
        CHECK_MSG(rc == 0, "%s seed %d: %s", name, seed, err.message);
        if (rc)
            continue;
        check_packing(&box, &p, name);
        gp_packing3d_free(&p);
    }
    gp_spec_free(&spec);
}

static void test_cells_tile_the_periodic_box(void)
{
    check_law("bagi with a joint",
              "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": {\"kind\": \"uniform\", "
              "\"min\": 0.06, \"max\": 0.42}, \"joint\": {\"law\": \"constant\", \"value\": 0.02}}",
              6.0, 6);
    check_law("two bins", "{\"domain\": {\"width\": 100, \"height\": 100}, \"distribution\": {\"kind\": \"histogram\", "
                      "\"bins\": [{\"min\": 2, \"max\": 4, \"p\": 0.5}, {\"min\": 4, \"max\": 8, \"p\": 0.5}]}}",
              110.0, 4);
}

int main(void)
{
    RUN(test_cells_tile_the_periodic_box);
    return check_status();
}
