/* disk.h - a packed grain and the geometric predicates every stage shares. */
#ifndef GRAINPACK_DISK_H
#define GRAINPACK_DISK_H

#include "grainpack/api.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A grain: centre (x, y), grain radius r and packing radius R = r + j(r). Two grains whose
 * packing disks touch are separated by a boundary of thickness j(r1) + j(r2). */
typedef struct gp_disk {
    double x, y;
    double r;
    double R;
} gp_disk;

/* Relative contact tolerance. Two packing disks overlap when the distance of their
 * centres is below (R1 + R2)(1 - GP_CONTACT_RTOL). Why this value: a disk placed tangent
 * to two others is computed in doubles, so its distance to them is exact only to a few
 * ulps of the coordinates; the disk cap keeps coordinates below ~1e5 radii, so the
 * rounding stays below ~1e-11 of a radius. 1e-9 leaves a wide margin above that and is
 * still far below anything physical (a nanometre grain would overlap by 1e-18 m). */
#define GP_CONTACT_RTOL 1e-9

/* Whether packing disks a and b overlap beyond the contact tolerance. */
static inline int gp_disks_overlap(const gp_disk *a, const gp_disk *b)
{
    double dx = a->x - b->x, dy = a->y - b->y;
    double reach = (a->R + b->R) * (1.0 - GP_CONTACT_RTOL);
    return dx * dx + dy * dy < reach * reach;
}

/* Twice the signed area of triangle (a, b, c): > 0 when c is on the left of a -> b. */
static inline double gp_orient2d(double ax, double ay, double bx, double by, double cx,
                                 double cy)
{
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

/* The centre of a disk of radius R tangent to disks (c1, R1) and (c2, R2), on the left of
 * the oriented segment c1 -> c2 (docs/method.md §3.1). Returns 1 and sets (*x, *y) when such a disk
 * exists (|a - b| <= d <= a + b with a = R1 + R, b = R2 + R), 0 otherwise. */
GP_API int gp_place_tangent(const gp_disk *c1, const gp_disk *c2, double R, double *x, double *y);

#ifdef __cplusplus
}
#endif
#endif
