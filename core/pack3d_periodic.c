/* pack3d_periodic.c - the 3D packer on a box periodic along some axes (docs/3d.md §11):
 * the image arithmetic (minimum image, wrapping, the grid's cells modulo the box), the
 * overlap test against the nearest images, and the seed cluster the front starts from. */
#include <math.h>

#include "grainpack/disk.h"
#include "pack3d_internal.h"

static void box_sides(const gp_box *box, double side[3])
{
    side[0] = box->width;
    side[1] = box->height;
    side[2] = box->depth;
}

void p3_min_image(const gp_box *box, double d[3])
{
    double side[3];
    box_sides(box, side);
    for (int a = 0; a < 3; a++)
        if (p3_periodic_axis(box, a)) {
            /* one side at most: both points are in [0, side) (a division and nearbyint
             * cost more than the packer's own grid query) */
            if (d[a] > 0.5 * side[a])
                d[a] -= side[a];
            else if (d[a] < -0.5 * side[a])
                d[a] += side[a];
        }
}

/* t brought into [0, period): floor leaves t + period == period for a tiny negative t,
 * taken as 0 (as domain.c's wrap does in 2D). */
static double wrap_axis(double t, double period)
{
    if (t >= 0.0 && t < period)
        return t;
    t -= period * floor(t / period);
    return t < period ? t : 0.0;
}

void p3_wrap(const gp_box *box, double p[3])
{
    double side[3];
    box_sides(box, side);
    for (int a = 0; a < 3; a++)
        if (p3_periodic_axis(box, a))
            p[a] = wrap_axis(p[a], side[a]);
}

void p3_grid_span(const p3_grid *grid, unsigned periodic, const double p[3], double reach, int32_t lo[3],
                  int32_t count[3])
{
    int32_t hi[3];
    p3_grid_range(grid, p[0], p[1], p[2], reach, lo, hi);
    for (int a = 0; a < 3; a++) {
        count[a] = hi[a] - lo[a] + 1;
        if (!((periodic >> a) & 1u))
            continue;
        /* p is in [0, side) and reach below a side (GP_PACK_MIN_PERIOD_RADII), so the
         * unclamped indices are within one grid of the box's */
        int32_t l = (int32_t)floor((p[a] - reach) * grid->inv[a]);
        int32_t h = (int32_t)floor((p[a] + reach) * grid->inv[a]);
        if (h - l + 1 >= grid->n[a]) {
            lo[a] = 0;
            count[a] = grid->n[a];
        } else {
            lo[a] = l < 0 ? l + grid->n[a] : l;
            count[a] = h - l + 1;
        }
    }
}

/* Whether the packing sphere (p, R) overlaps the nearest image of b beyond GP_CONTACT_RTOL. */
static int overlaps_image(const gp_box *box, const double p[3], double R, const gp_sphere *b)
{
    double d[3] = {p[0] - b->x, p[1] - b->y, p[2] - b->z};
    p3_min_image(box, d);
    double reach = (R + b->R) * (1.0 - GP_CONTACT_RTOL);
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach * reach;
}

/* The first sphere of the cell list from s on whose nearest image overlaps (p, R), or
 * P3_NONE. */
static int32_t list_first_overlap(const p3_packer *pk, int32_t s, const double p[3], double R)
{
    for (; s != P3_NONE; s = pk->grid.next[s])
        if (overlaps_image(pk->box, p, R, &pk->spheres[s]))
            return s;
    return P3_NONE;
}

/* The first sphere whose nearest image overlaps (p, R), or P3_NONE: the cell of p first,
 * where the sphere in the way most often is (as pack3d_grid.c's query). */
static int32_t first_overlap(const p3_packer *pk, const double p[3], double R)
{
    const p3_grid *grid = &pk->grid;
    int32_t home[3], unused[3], lo[3], count[3];
    p3_grid_range(grid, p[0], p[1], p[2], 0.0, home, unused);
    int32_t s = list_first_overlap(pk, p3_grid_cell(grid, home[0], home[1], home[2]), p, R);
    if (s != P3_NONE)
        return s;
    p3_grid_span(grid, pk->box->periodic, p, R + pk->R_max, lo, count);
    for (int32_t k = lo[2]; k < lo[2] + count[2]; k++)
        for (int32_t j = lo[1]; j < lo[1] + count[1]; j++)
            for (int32_t i = lo[0]; i < lo[0] + count[0]; i++) {
                int32_t c[3] = {p3_wrap_cell(i, grid->n[0]), p3_wrap_cell(j, grid->n[1]),
                                p3_wrap_cell(k, grid->n[2])};
                if (c[0] == home[0] && c[1] == home[1] && c[2] == home[2])
                    continue;
                if ((s = list_first_overlap(pk, p3_grid_cell(grid, c[0], c[1], c[2]), p, R)) != P3_NONE)
                    return s;
            }
    return P3_NONE;
}

int p3_periodic_fits(p3_packer *pk, const double p[3], double R)
{
    double side[3];
    box_sides(pk->box, side);
    double slack = R * GP_CONTACT_RTOL;
    for (int a = 0; a < 3; a++)
        if (!p3_periodic_axis(pk->box, a) && (!(p[a] - R >= -slack) || !(p[a] + R <= side[a] + slack)))
            return 0;
    if (pk->blocker != P3_NONE && overlaps_image(pk->box, p, R, &pk->spheres[pk->blocker]))
        return 0;
    int32_t q = first_overlap(pk, p, R);
    if (q == P3_NONE)
        return 1;
    pk->blocker = q;
    return 0;
}

/* The squared distance from p to the first sphere's centre, minimum image. */
static double seed_distance2(const p3_packer *pk, const double p[3])
{
    const gp_sphere *s = &pk->spheres[0];
    double d[3] = {p[0] - s->x, p[1] - s->y, p[2] - s->z};
    p3_min_image(pk->box, d);
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

int p3_periodic_prefer(const p3_packer *pk, const double a[3], const double b[3])
{
    return seed_distance2(pk, b) < seed_distance2(pk, a);
}

/* Places the pending radius at p (wrapped), level 0, and makes its triangles with what is
 * already there. Returns its id or a negative GP_E code with err set. */
static int32_t seed(p3_packer *pk, double p[3])
{
    p3_wrap(pk->box, p);
    int32_t id = p3_add_sphere(pk, p, 0);
    if (id >= 0 && p3_link(pk, id, P3_NONE))
        return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the front");
    return id;
}

/* With walls left, the first sphere goes against the walls at 0 of the walled axes, in
 * the middle of the periodic ones: against two walls it makes the triangle (sphere, wall,
 * wall), whose positions run along their edge; against one wall a second sphere goes
 * beside it on that wall (2 sqrt(R R') on along the first periodic axis), and the
 * triangle (sphere, sphere, wall) follows. With no wall, three mutually tangent spheres
 * in the middle of the box make the triangle of the cluster, open on both sides, as 2D's
 * torus starts (docs/method.md §3.8). Every seed is of level 0: the front grows out of
 * the cluster as it grows out of the walls. */
int p3_periodic_start(p3_packer *pk)
{
    const gp_box *box = pk->box;
    double side[3];
    box_sides(box, side);
    int walled = 0, first_periodic = -1;
    double p[3];
    for (int a = 0; a < 3; a++) {
        double R = pk->pending_R;
        if (p3_periodic_axis(box, a)) {
            p[a] = 0.5 * side[a];
            if (first_periodic < 0)
                first_periodic = a;
        } else {
            p[a] = R;
            walled++;
        }
    }
    double R0 = pk->pending_R;
    int32_t s0 = seed(pk, p);
    if (s0 < 0 || walled >= 2)
        return s0 < 0 ? s0 : 0;
    const gp_sphere c0 = pk->spheres[s0];
    double R1 = pk->pending_R, q[3] = {c0.x, c0.y, c0.z};
    if (walled == 1) {
        for (int a = 0; a < 3; a++)
            if (!p3_periodic_axis(box, a))
                q[a] = R1;
        q[first_periodic] += 2.0 * sqrt(R0 * R1);
        int32_t s1 = seed(pk, q);
        return s1 < 0 ? s1 : 0;
    }
    q[0] += R0 + R1;
    int32_t s1 = seed(pk, q);
    if (s1 < 0)
        return s1;
    /* the third in the plane z = c0.z, at R0 + R2 from c0 and R1 + R2 from c1 */
    double R2 = pk->pending_R, d = R0 + R1, a = R0 + R2, b = R1 + R2;
    double along = (a * a - b * b + d * d) / (2.0 * d);
    double r[3] = {c0.x + along, c0.y + sqrt(a * a - along * along), c0.z};
    int32_t s2 = seed(pk, r);
    return s2 < 0 ? s2 : 0;
}
