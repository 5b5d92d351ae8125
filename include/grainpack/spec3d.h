/* spec3d.h - the job spec of the 3D process ("pack3d", docs/3d.md): a box with a depth,
 * the radius law, the joint and the seed, parsed and checked like the 2D spec (spec.h),
 * and which process a spec asks for. */
#ifndef GRAINPACK_SPEC3D_H
#define GRAINPACK_SPEC3D_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/distribution.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/pack3d.h"
#include "grainpack/spec.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The plane of the section picture (docs/3d.md §8): normal to `axis` (0 x, 1 y, 2 z), at
 * the fraction `at` in [0, 1] of the box along it. */
typedef struct gp_section3d {
    int axis;
    double at;
} gp_section3d;

/* The section picture's default: across z, through the middle of the box. */
#define GP_SECTION3D_DEFAULT_AXIS 2
#define GP_SECTION3D_DEFAULT_AT 0.5

typedef struct gp_spec3d {
    gp_box box;
    gp_distribution dist;    /* owned; prepared for sampling */
    gp_joint joint;          /* GP_JOINT_NONE when the spec has none */
    uint64_t seed;
    double expected_spheres; /* a density of 0.64 over the mean packing-sphere volume */
    gp_section3d section;    /* "picture": {"section": {"axis", "at"}} */
} gp_spec3d;

/* The processes a spec may ask for. */
typedef enum gp_process {
    GP_PROCESS_PACK2D = 0,
    GP_PROCESS_PACK3D
} gp_process;

/* The process a spec is for: GP_PROCESS_PACK3D when its domain (under "inputs" or bare)
 * has a "depth", GP_PROCESS_PACK2D otherwise, also for text that is not a spec at all
 * (the 2D parser then says why). */
GP_API gp_process gp_spec_process(const char *text, size_t len);

/* Parses and validates a 3D spec: {"inputs": {...}} or the bare inputs, with "domain"
 * {"width", "height", "depth"}, "distribution", "joint" (optional), "seed" (optional), "picture" (optional:
 * {"section": {"axis": "x" | "y" | "z", "at": a fraction in [0, 1]}}, default z at 0.5).
 * `limits` may be NULL; its max_disks caps the expected number of spheres. On success
 * returns 0 and `spec` owns its law (gp_spec3d_free). On failure returns GP_EPARSE,
 * GP_EINVAL or GP_ETOOBIG with err's pointer on the field, and leaves `spec` zeroed. */
GP_API int gp_spec3d_parse(const char *text, size_t len, const gp_spec_limits *limits,
                           gp_spec3d *spec, gp_error *err);

/* Reads and parses a 3D spec file (as gp_spec3d_parse; GP_EIO if it cannot be read). */
GP_API int gp_spec3d_load_file(const char *path, const gp_spec_limits *limits, gp_spec3d *spec,
                               gp_error *err);

/* The packer's parameters for the spec (borrowing from it). */
GP_API gp_pack3d_params gp_spec3d_pack_params(const gp_spec3d *spec, size_t max_spheres);

/* Frees what the spec owns and zeroes it. */
GP_API void gp_spec3d_free(gp_spec3d *spec);

#ifdef __cplusplus
}
#endif
#endif
