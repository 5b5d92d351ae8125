/* pack3d_solve.c - where a sphere of radius R touches the three members of a front
 * triangle (docs/3d.md §2): its centre is R + R_i from each sphere's centre and R from
 * each wall, in closed form with two mirror solutions. */
#include <math.h>

#include "pack3d_internal.h"

/* The smallest sine of the angle a solve divides by (collinear centres, or two centres
 * above one another across a wall): its rounding error grows as 1e-16 over that sine, so
 * at 1e-3 a solution stays within ~1e-13 of tangent, far inside GP_CONTACT_RTOL. Such
 * flat triangles would only place a sphere in a sliver the neighbours' triangles reach. */
#define MIN_SINE 1e-3
/* A squared half-chord within this of zero, relative to the squares it is the difference
 * of, is rounding (a few ulps of those squares): the contact is tangent, the two solutions
 * meet, and the half-chord is taken as zero. Its square root would otherwise be ~1e-8 of
 * a radius of noise, which leaves the member distances exact (the error is of second
 * order there) but moves the sphere by that much against a fourth sphere that touches the
 * same point, as the spheres of an ordered region do. */
#define ROUNDING 1e-14

/* The half-chord whose square v is computed from terms of size `scale`^2; -1 when v is
 * negative beyond rounding (no solution). */
static double half_chord(double v, double scale)
{
    double noise = ROUNDING * scale * scale;
    if (v > noise)
        return sqrt(v);
    return v >= -noise ? 0.0 : -1.0;
}

/* The walls are axis-aligned, so a wall member fixes one coordinate of the centre: R
 * from the near side, side - R from the far one. */
static double wall_coordinate(const gp_box *box, int w, double R)
{
    const double side[3] = {box->width, box->height, box->depth};
    return w % 2 ? side[w / 2] - R : R;
}

/* Three spheres: the centre at distances rho[i] from c[i] (trilateration in the frame of
 * c[0], c[0] -> c[1] and the plane of the three). */
static int three_spheres(const double c[3][3], const double rho[3], double out[2][3])
{
    double u[3], v[3];
    for (int a = 0; a < 3; a++) {
        u[a] = c[1][a] - c[0][a];
        v[a] = c[2][a] - c[0][a];
    }
    double d = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(d > 0.0))
        return 0;
    double e1[3] = {u[0] / d, u[1] / d, u[2] / d};
    double i = e1[0] * v[0] + e1[1] * v[1] + e1[2] * v[2];
    double ey[3] = {v[0] - i * e1[0], v[1] - i * e1[1], v[2] - i * e1[2]};
    double j = sqrt(ey[0] * ey[0] + ey[1] * ey[1] + ey[2] * ey[2]);
    /* (nearly) collinear centres: no plane to mirror in */
    if (!(j > MIN_SINE * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])))
        return 0;
    double e2[3] = {ey[0] / j, ey[1] / j, ey[2] / j};
    double e3[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0]};
    double x = (rho[0] * rho[0] - rho[1] * rho[1] + d * d) / (2.0 * d);
    double y = (rho[0] * rho[0] - rho[2] * rho[2] + i * i + j * j) / (2.0 * j) - i / j * x;
    double z = half_chord(rho[0] * rho[0] - x * x - y * y, rho[0]);
    if (z < 0.0)
        return 0;
    for (int s = 0; s < 2; s++) {
        double zs = s ? -z : z;
        for (int a = 0; a < 3; a++)
            out[s][a] = c[0][a] + x * e1[a] + y * e2[a] + zs * e3[a];
    }
    return 2;
}

/* One wall fixing axis `a` at `at`, two spheres: in the plane of the other two axes, the
 * circles the spheres cut there, intersected. */
static int two_spheres_wall(const double c[2][3], const double rho[2], int a, double at,
                            double out[2][3])
{
    int p = (a + 1) % 3, q = (a + 2) % 3;
    double h0 = at - c[0][a], h1 = at - c[1][a];
    double s0 = rho[0] * rho[0] - h0 * h0, s1 = rho[1] * rho[1] - h1 * h1; /* circle radii^2 */
    if (!(s0 >= 0.0) || !(s1 >= 0.0))
        return 0;
    double dp = c[1][p] - c[0][p], dq = c[1][q] - c[0][q];
    double d = sqrt(dp * dp + dq * dq);
    if (!(d > MIN_SINE * (rho[0] + rho[1])))
        return 0;
    double along = (s0 - s1 + d * d) / (2.0 * d);
    double h = half_chord(s0 - along * along, rho[0]), up = dp / d, uq = dq / d;
    if (h < 0.0)
        return 0;
    for (int s = 0; s < 2; s++) {
        double hs = s ? -h : h;
        out[s][a] = at;
        out[s][p] = c[0][p] + along * up - hs * uq;
        out[s][q] = c[0][q] + along * uq + hs * up;
    }
    return 2;
}

/* Two walls fixing axes a and b, one sphere: the line where they meet, cut by the sphere. */
static int sphere_two_walls(const double c[3], double rho, int a, double at_a, int b, double at_b,
                            double out[2][3])
{
    int f = 3 - a - b; /* the free axis */
    double da = at_a - c[a], db = at_b - c[b];
    double t = half_chord(rho * rho - da * da - db * db, rho);
    if (t < 0.0)
        return 0;
    for (int s = 0; s < 2; s++) {
        out[s][a] = at_a;
        out[s][b] = at_b;
        out[s][f] = c[f] + (s ? -t : t);
    }
    return 2;
}

int p3_tangent(const gp_sphere *spheres, const gp_box *box, const int32_t m[3], double R,
               double out[2][3])
{
    double c[3][3], rho[3];
    int axis[3], ns = 0, nw = 0;
    double at[3];
    for (int i = 0; i < 3; i++) {
        if (P3_IS_WALL(m[i])) {
            int w = P3_WALL_INDEX(m[i]);
            for (int k = 0; k < nw; k++)
                if (axis[k] == w / 2)
                    return 0; /* two walls across one axis: the box is wider than 2 R */
            axis[nw] = w / 2;
            at[nw++] = wall_coordinate(box, w, R);
        } else {
            const gp_sphere *s = &spheres[m[i]];
            c[ns][0] = s->x;
            c[ns][1] = s->y;
            c[ns][2] = s->z;
            if (box->periodic && ns > 0) {
                /* the image of the member nearest the first sphere member (docs/3d.md §11) */
                double d[3] = {c[ns][0] - c[0][0], c[ns][1] - c[0][1], c[ns][2] - c[0][2]};
                p3_min_image(box, d);
                for (int a = 0; a < 3; a++)
                    c[ns][a] = c[0][a] + d[a];
            }
            rho[ns++] = s->R + R;
        }
    }
    switch (nw) {
    case 0:
        return three_spheres((const double(*)[3])c, rho, out);
    case 1:
        return two_spheres_wall((const double(*)[3])c, rho, axis[0], at[0], out);
    case 2:
        return sphere_two_walls(c[0], rho[0], axis[0], at[0], axis[1], at[1], out);
    default:
        out[0][axis[0]] = at[0];
        out[0][axis[1]] = at[1];
        out[0][axis[2]] = at[2];
        return 1;
    }
}
