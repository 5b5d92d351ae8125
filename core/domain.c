/* domain.c - the rectangle [0,W] x [0,H]. */
#include "grainpack/domain.h"

void gp_domain_corner(const gp_domain *domain, int i, double *x, double *y)
{
    switch (i & 3) {
    case 0: *x = 0.0; *y = 0.0; break;
    case 1: *x = domain->width; *y = 0.0; break;
    case 2: *x = domain->width; *y = domain->height; break;
    default: *x = 0.0; *y = domain->height; break;
    }
}

double gp_domain_area(const gp_domain *domain)
{
    return domain->width * domain->height;
}
