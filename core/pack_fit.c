/* pack_fit.c - how large a disk tangent to two others may grow before it meets a third.
 * When a radius fails against a segment because a disk q is in the way, this limit tells
 * every radius the segment cannot take because of q, so that the front skips the segment
 * for all of them instead of trying it again for each (docs/method.md §3.5). */
#include <math.h>

#include "packer.h"

/* How near zero, relative to its terms, the clearance must be at a root of the squared
 * equation for the root to be one of the clearance itself: the roots' rounding is ~1e-15
 * of the terms, a root of the other branch leaves a clearance of the terms' size. */
#define ROOT_RTOL 1e-9

/* In the frame of the segment (a at the origin, u along a -> b, n = u turned left), the
 * disk of radius R tangent to a (radius A) and b (radius B), at distance d, has its centre
 * at x(R) u + h(R) n with x(R) = x0 + k R (docs/method.md §3.1) and
 * h(R)^2 = (A + R)^2 - x(R)^2. Its clearance to q (centre (qx, qy), radius Q) is
 *     g(R) = |c - q|^2 - (R + Q)^2 = L0 + L1 R - 2 qy h(R),
 * negative when they overlap: the clearance is linear in R but for the one square root,
 * so g(R) = 0 squares into a quadratic in R (the Apollonius problem of the circle tangent
 * to three, solved for its radius). */
double pack_fit_limit(const gp_disk *a, const gp_disk *b, double d, double ux, double uy,
                      const gp_disk *q, double R_lo, double R_hi)
{
    double A = a->R, B = b->R, Q = q->R;
    if (!(d > 0.0))
        return R_hi;
    /* apart, the two disks have a tangent disk from (d - A - B) / 2 up only */
    double R_exist = 0.5 * (d - A - B);
    if (R_lo < R_exist)
        R_lo = R_exist;
    if (!(R_lo < R_hi))
        return R_hi;
    double wx = q->x - a->x, wy = q->y - a->y;
    double qx = wx * ux + wy * uy, qy = -wx * uy + wy * ux;
    double x0 = (d * d + A * A - B * B) / (2.0 * d), k = (A - B) / d;
    double L0 = A * A - 2.0 * x0 * qx + qx * qx + qy * qy - Q * Q;
    double L1 = 2.0 * (A - k * qx - Q);
    double h2a = 1.0 - k * k, h2b = 2.0 * (A - k * x0), h2c = A * A - x0 * x0;
    double qy2 = 4.0 * qy * qy;
    double alpha = L1 * L1 - qy2 * h2a, beta = 2.0 * L0 * L1 - qy2 * h2b,
           gamma = L0 * L0 - qy2 * h2c;
    double roots[2];
    int nroots = 0;
    if (alpha == 0.0) {
        if (beta != 0.0)
            roots[nroots++] = -gamma / beta;
    } else {
        double disc = beta * beta - 4.0 * alpha * gamma;
        if (disc >= 0.0) {
            /* the form without cancellation for each root */
            double t = -0.5 * (beta + copysign(sqrt(disc), beta));
            roots[nroots++] = t / alpha;
            if (t != 0.0)
                roots[nroots++] = gamma / t;
        }
    }
    /* the largest root below R_hi where the unsquared equation holds (squaring let in
     * the roots of L0 + L1 R = -2 qy h too): past it q is in the way up to R_hi */
    double limit = -1.0;
    for (int i = 0; i < nroots; i++) {
        double r = roots[i];
        if (!(r > R_lo && r < R_hi))
            continue;
        double h = sqrt(fmax(0.0, (h2a * r + h2b) * r + h2c)), lin = L0 + L1 * r;
        if (fabs(lin - 2.0 * qy * h) > ROOT_RTOL * (fabs(L0) + fabs(L1) * r + fabs(2.0 * qy * h)))
            continue;
        if (r > limit)
            limit = r;
    }
    if (limit > 0.0)
        return limit;
    /* no tangency in (R_lo, R_hi): q is in the way of every radius there if it is of the
     * smallest; otherwise the limit is unknown and the radius that failed stands */
    double h = sqrt(fmax(0.0, (h2a * R_lo + h2b) * R_lo + h2c));
    return L0 + L1 * R_lo - 2.0 * qy * h < 0.0 ? R_lo : R_hi;
}
