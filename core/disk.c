/* disk.c - placing a disk tangent to two others. */
#include "grainpack/disk.h"

#include <math.h>

int gp_place_tangent(const gp_disk *c1, const gp_disk *c2, double R, double *x, double *y)
{
    double a = c1->R + R, b = c2->R + R;
    double ux = c2->x - c1->x, uy = c2->y - c1->y;
    double d = sqrt(ux * ux + uy * uy);
    if (!(d > 0.0) || d > a + b || d < fabs(a - b))
        return 0;
    ux /= d;
    uy /= d;
    double along = (a * a - b * b + d * d) / (2.0 * d);
    double h2 = a * a - along * along;
    double h = h2 > 0.0 ? sqrt(h2) : 0.0; /* rounding can push a tangency slightly negative */
    *x = c1->x + along * ux - h * uy;
    *y = c1->y + along * uy + h * ux;
    return 1;
}
