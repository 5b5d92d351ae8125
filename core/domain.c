/* domain.c - the rectangle [0,W] x [0,H], walled or periodic. */
#include "grainpack/domain.h"

#include <math.h>

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

/* The image of t in [0, period): t - floor(t / period) period can round up to period
 * itself for a t just below 0, which is folded back to 0. */
static double wrap_axis(double t, double period)
{
    if (t >= 0.0 && t < period)
        return t;
    t -= period * floor(t / period);
    return t < period ? t : 0.0;
}

void gp_domain_min_image(const gp_domain *domain, double *dx, double *dy)
{
    if (domain->periodic & GP_PERIODIC_X)
        *dx -= domain->width * nearbyint(*dx / domain->width);
    if (domain->periodic & GP_PERIODIC_Y)
        *dy -= domain->height * nearbyint(*dy / domain->height);
}

void gp_domain_wrap(const gp_domain *domain, double *x, double *y)
{
    if (domain->periodic & GP_PERIODIC_X)
        *x = wrap_axis(*x, domain->width);
    if (domain->periodic & GP_PERIODIC_Y)
        *y = wrap_axis(*y, domain->height);
}
