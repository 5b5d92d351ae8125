/* domain.h - the region to fill. A rectangle [0,W] x [0,H], as in the report, with walls,
 * or periodic along x and/or y (a representative volume element: what leaves one side
 * comes back on the other, docs/method.md §3.8). */
#ifndef GRAINPACK_DOMAIN_H
#define GRAINPACK_DOMAIN_H

#include "grainpack/api.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bits of gp_domain.periodic: the axes along which the domain repeats. */
#define GP_PERIODIC_X 1u
#define GP_PERIODIC_Y 2u

typedef struct gp_domain {
    double width, height;
    unsigned periodic; /* GP_PERIODIC_X | GP_PERIODIC_Y, 0 for walls on all four sides */
} gp_domain;

/* The number of corners of the domain's boundary, counter-clockwise from (0,0). */
#define GP_DOMAIN_CORNERS 4

/* Corner i (0 <= i < GP_DOMAIN_CORNERS), counter-clockwise starting at the origin. */
GP_API void gp_domain_corner(const gp_domain *domain, int i, double *x, double *y);

GP_API double gp_domain_area(const gp_domain *domain);

/* Whether the disk (x, y, R) lies inside the domain, allowing it to stick out by at most
 * `slack` (a non-negative length; the packer uses R * GP_CONTACT_RTOL, see disk.h). Along
 * a periodic axis every position is inside (the disk's other part is across the side).
 * Inline: it runs for every candidate disk. */
static inline int gp_domain_contains_disk(const gp_domain *domain, double x, double y, double R,
                                          double slack)
{
    return ((domain->periodic & GP_PERIODIC_X) ||
            (x - R >= -slack && x + R <= domain->width + slack)) &&
           ((domain->periodic & GP_PERIODIC_Y) ||
            (y - R >= -slack && y + R <= domain->height + slack));
}

/* Turns the vector (*dx, *dy) between two points into the shortest one between their
 * periodic images (the minimum-image convention); unchanged along walled axes. */
GP_API void gp_domain_min_image(const gp_domain *domain, double *dx, double *dy);

/* Brings (*x, *y) into [0, W) x [0, H) along the periodic axes (the image of the point
 * that lies in the domain); unchanged along walled axes. */
GP_API void gp_domain_wrap(const gp_domain *domain, double *x, double *y);

#ifdef __cplusplus
}
#endif
#endif
