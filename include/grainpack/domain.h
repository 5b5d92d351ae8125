/* domain.h - the region to fill. A rectangle [0,W] x [0,H], as in the report. */
#ifndef GRAINPACK_DOMAIN_H
#define GRAINPACK_DOMAIN_H

#include "grainpack/api.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gp_domain {
    double width, height;
} gp_domain;

/* The number of corners of the domain's boundary, counter-clockwise from (0,0). */
#define GP_DOMAIN_CORNERS 4

/* Corner i (0 <= i < GP_DOMAIN_CORNERS), counter-clockwise starting at the origin. */
GP_API void gp_domain_corner(const gp_domain *domain, int i, double *x, double *y);

GP_API double gp_domain_area(const gp_domain *domain);

/* Whether the disk (x, y, R) lies inside the domain, allowing it to stick out by at most
 * `slack` (a non-negative length; the packer uses R * GP_CONTACT_RTOL, see disk.h).
 * Inline: it runs for every candidate disk. */
static inline int gp_domain_contains_disk(const gp_domain *domain, double x, double y, double R,
                                          double slack)
{
    return x - R >= -slack && y - R >= -slack && x + R <= domain->width + slack &&
           y + R <= domain->height + slack;
}

#ifdef __cplusplus
}
#endif
#endif
