/* pack3d.h - the advancing-front sphere packer in a walled box (docs/3d.md): the 3D
 * analogue of pack.h, with the same radius laws, joint laws and seed semantics. */
#ifndef GRAINPACK_PACK3D_H
#define GRAINPACK_PACK3D_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/out.h"
#include "grainpack/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The third bit of gp_box.periodic, beside domain.h's GP_PERIODIC_X and GP_PERIODIC_Y. */
#define GP_PERIODIC_Z 4u

/* A box [0, width] x [0, height] x [0, depth]: two walls across each axis, or none along
 * the axes of `periodic` (docs/3d.md §11: a sphere may cross such a side and is seen by
 * its images across it; centres are then in [0, side)). */
typedef struct gp_box {
    double width, height, depth;
    unsigned periodic; /* GP_PERIODIC_X | GP_PERIODIC_Y | GP_PERIODIC_Z, 0 for six walls */
} gp_box;

/* A grain: centre (x, y, z), grain radius r and packing radius R = r + j(r). */
typedef struct gp_sphere {
    double x, y, z;
    double r;
    double R;
} gp_sphere;

/* In which order the front's triangles are tried (docs/3d.md §3). */
typedef enum gp_pack3d_order {
    /* the report's level rule: spheres on the walls first (level 0), then each triangle
     * by the lowest level of its spheres, first come first served within a level */
    GP_PACK3D_LEVEL = 0,
    /* the alternative measured against it: a deposition from the floor, each triangle
     * by the height of its lowest sphere */
    GP_PACK3D_LOWEST
} gp_pack3d_order;

/* What to pack. Everything is borrowed for the duration of gp_pack3d. */
typedef struct gp_pack3d_params {
    const gp_box *box;
    const gp_distribution *dist; /* prepared (gp_distribution_prepare) */
    const gp_joint *joint;       /* NULL: no joint */
    uint64_t seed;
    size_t max_spheres;          /* fail with GP_ETOOBIG beyond this many spheres; 0: no cap */
    gp_pack3d_order order;       /* GP_PACK3D_LEVEL (0) unless set */
} gp_pack3d_params;

/* The widest span R_max / R_min of packing radii the 3D packer takes (docs/3d.md §5). A
 * candidate position is tested against the spheres of the grid cells (side 2 R_max) it
 * reaches: up to (6 R_max + 2 R_min)^3 / (4/3 pi R_min^3) small ones, the cube of the
 * ratio, so the ratio bounds the work per sphere. At 10 that is ~60 000 tests at worst;
 * the Bagi case (ratio 7) and the iron law (4) are inside. */
#define GP_PACK3D_MAX_RADIUS_RATIO 10.0

/* A packing: the spheres in the order they were placed, and how the front got there. */
typedef struct gp_packing3d {
    gp_sphere *spheres;   /* owned; count entries */
    size_t count;
    size_t wall_spheres;  /* spheres placed against a wall (level 0) */
    uint64_t triangles;   /* front triangles made */
    uint64_t attempts;    /* triangle tries (a try tests one or two positions) */
    uint32_t max_level;   /* highest sphere level reached */
    double fill_volume;   /* sum of 4/3 pi R^3 over the spheres */
} gp_packing3d;

/* Checks that the law (with `joint`, NULL for none) can be packed in the box: sides
 * positive and finite, the largest packing sphere inside, the radius ratio at most
 * GP_PACK3D_MAX_RADIUS_RATIO, every side at most GP_PACK_MAX_SIDE_RADII smallest radii,
 * every periodic side at least GP_PACK_MIN_PERIOD_RADII largest packing radii (as in 2D:
 * only the nearest image of a sphere can then touch another), no periodic bit but the
 * three axes'. Returns 0 or GP_EINVAL with err set, its pointer relative to a spec's
 * inputs ("/domain/depth", "/domain/periodic", "/distribution"). */
GP_API int gp_pack3d_check(const gp_box *box, const gp_distribution *dist, const gp_joint *joint,
                           gp_error *err);

/* Packs the box (docs/3d.md) until the front is empty. On success returns 0 and `out`
 * owns its spheres (free with gp_packing3d_free). On failure returns GP_EINVAL (what
 * gp_pack3d_check refuses, or an unknown order), GP_ETOOBIG (max_spheres reached, or a grid too large), GP_ENOMEM or
 * GP_ECANCELED, sets err, and leaves `out` zeroed. `progress` may be NULL. */
GP_API int gp_pack3d(const gp_pack3d_params *params, const gp_progress *progress,
                     gp_packing3d *out, gp_error *err);

/* Frees the spheres of a packing and zeroes it (a zeroed one is accepted). */
GP_API void gp_packing3d_free(gp_packing3d *packing);

/* Writes the packing as CSV, a header then one line per sphere in placement order:
 * x,y,z,r,R (shortest decimals that read back exactly), and flushes. Returns the gp_out's
 * error (0 or GP_EIO / GP_ENOMEM). The packing is borrowed. */
GP_API int gp_write_spheres_csv(gp_out *out, const gp_packing3d *packing);

#ifdef __cplusplus
}
#endif
#endif
