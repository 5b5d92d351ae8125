/* joint.h - grain-boundary (joint) thickness laws j(r) and the packing radius R = r + j(r). */
#ifndef GRAINPACK_JOINT_H
#define GRAINPACK_JOINT_H

#include "grainpack/api.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_joint_law {
    GP_JOINT_NONE = 0, /* j(r) = 0 */
    GP_JOINT_CONSTANT, /* j(r) = value */
    GP_JOINT_INVERSE,  /* j(r) = k / r (the report's iron example: k = 2) */
    GP_JOINT_POWER     /* j(r) = k r^exponent */
} gp_joint_law;

typedef struct gp_joint {
    gp_joint_law law;
    double value;    /* GP_JOINT_CONSTANT */
    double k;        /* GP_JOINT_INVERSE, GP_JOINT_POWER */
    double exponent; /* GP_JOINT_POWER */
} gp_joint;

/* j(r) for a grain of radius r > 0. */
GP_API double gp_joint_thickness(const gp_joint *joint, double r);

/* The packing radius R = r + j(r). */
GP_API double gp_joint_packing_radius(const gp_joint *joint, double r);

/* The range [*R_min, *R_max] of the packing radius over r in [r_min, r_max].
 * Every law here is convex or monotone in r, which the function relies on. */
GP_API void gp_joint_packing_range(const gp_joint *joint, double r_min, double r_max, double *R_min,
                                   double *R_max);

/* "none", "constant", "inverse" or "power". */
GP_API const char *gp_joint_law_name(gp_joint_law law);

#ifdef __cplusplus
}
#endif
#endif
