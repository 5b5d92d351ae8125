/* joint.c - grain-boundary thickness laws. */
#include "grainpack/joint.h"

#include <math.h>
#include <stddef.h>

double gp_joint_thickness(const gp_joint *joint, double r)
{
    if (!joint)
        return 0.0;
    switch (joint->law) {
    case GP_JOINT_CONSTANT: return joint->value;
    case GP_JOINT_INVERSE: return joint->k / r;
    case GP_JOINT_POWER: return joint->k * pow(r, joint->exponent);
    case GP_JOINT_NONE: break;
    }
    return 0.0;
}

double gp_joint_packing_radius(const gp_joint *joint, double r)
{
    return r + gp_joint_thickness(joint, r);
}

void gp_joint_packing_range(const gp_joint *joint, double r_min, double r_max, double *R_min,
                            double *R_max)
{
    double lo = gp_joint_packing_radius(joint, r_min);
    double hi = gp_joint_packing_radius(joint, r_max);
    /* R(r) = r + j(r) is convex (inverse, power with exponent < 0 or > 1) or increasing
     * (constant, power with 0 <= exponent <= 1, k >= 0): the maximum is at an end of the
     * interval, the minimum at an end or where R'(r) = 1 + j'(r) = 0. */
    *R_max = lo > hi ? lo : hi;
    double m = lo < hi ? lo : hi;
    double stationary = -1.0;
    if (joint && joint->law == GP_JOINT_INVERSE && joint->k > 0)
        stationary = sqrt(joint->k);
    else if (joint && joint->law == GP_JOINT_POWER && joint->exponent < 0 && joint->k > 0)
        stationary = pow(-1.0 / (joint->k * joint->exponent), 1.0 / (joint->exponent - 1.0));
    if (stationary > r_min && stationary < r_max) {
        double at = gp_joint_packing_radius(joint, stationary);
        if (at < m)
            m = at;
    }
    *R_min = m;
}

const char *gp_joint_law_name(gp_joint_law law)
{
    switch (law) {
    case GP_JOINT_NONE: return "none";
    case GP_JOINT_CONSTANT: return "constant";
    case GP_JOINT_INVERSE: return "inverse";
    case GP_JOINT_POWER: return "power";
    }
    return "unknown";
}
