/* spec.h - the job spec: JSON text -> struct gp_spec, validated with messages that name
 * the offending field by JSON pointer. Shared by the command line and the service. */
#ifndef GRAINPACK_SPEC_H
#define GRAINPACK_SPEC_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/balance.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/laguerre.h"
#include "grainpack/mesh.h"
#include "grainpack/pack.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Caps a spec must respect. Zero fields take the defaults below. */
typedef struct gp_spec_limits {
    size_t max_disks; /* reject specs expected to pack more disks than this */
    size_t max_bins;  /* reject histograms with more bins than this */
    size_t max_elements; /* reject meshes expected to have more elements than this */
} gp_spec_limits;

#define GP_SPEC_DEFAULT_MAX_DISKS ((size_t)20000000)
#define GP_SPEC_DEFAULT_MAX_BINS ((size_t)10000)
/* About 3 GB of mesh at the stage's ~150 bytes an element (bench/MESH.md). */
#define GP_SPEC_DEFAULT_MAX_ELEMENTS ((size_t)20000000)
#define GP_SPEC_DEFAULT_SEED 1
/* The widest level band a spec may ask for: beyond a few levels the fill stops being
 * layered and density no longer improves (see bench/). */
#define GP_SPEC_MAX_LEVEL_BAND 16
/* Probabilities of a histogram must sum to 1 within this (docs/method.md §2); never renormalised. */
#define GP_SPEC_PROBABILITY_TOL 1e-6
/* The largest sweep cap a spec may ask balancing for: about an hour of sweeps at the
 * largest packings the disk cap allows (bench/). */
#define GP_SPEC_MAX_BALANCE_ITERATIONS 100000

/* The most copies of a periodic domain the picture tiles along an axis: enough to see
 * that the copies join with no seam, and the picture stays the size of one domain's. */
#define GP_PICTURE_MAX_TILE 4

/* What the SVG picture colours grains by. */
typedef enum gp_picture_color {
    GP_PICTURE_COLOR_RADIUS = 0, /* the grain radius r */
    GP_PICTURE_COLOR_QUALITY     /* the balance criterion F (needs the balance stage) */
} gp_picture_color;

typedef struct gp_spec {
    gp_domain domain;
    gp_distribution dist; /* owned; prepared for sampling */
    gp_joint joint;       /* GP_JOINT_NONE when the spec has no joint */
    uint64_t seed;
    uint32_t level_band;   /* see gp_pack_params; "front": {"level_band": n} */
    int level_band_set;    /* "front": {"rule": "level_band"} or a level_band given: the
                              report's rule with that band, instead of the densest rule
                              (GP_FRONT_DEFAULT, "rule": "densest", the default) */
    double expected_disks; /* estimate used against the cap */
    int balance_enabled;   /* the spec has "balance" (method "none" measures F only) */
    gp_balance_params balance; /* "balance": {"method", "max_iterations", "max_step"} */
    int laguerre_enabled;  /* the spec has "laguerre" */
    gp_laguerre_params laguerre; /* "laguerre": {"shrink", "flush_boundary"} */
    gp_picture_color picture_color; /* "picture": {"color"}: quality when balancing, else radius */
    int picture_disks;     /* "picture": {"disks"}: outline the grain disks over the cells */
    int picture_tile;      /* "picture": {"tile"}: copies of a periodic domain drawn along each
                              periodic axis, 1 to GP_PICTURE_MAX_TILE (1 when absent) */
    int mesh_enabled;      /* the spec has "mesh" */
    gp_mesh_params mesh;   /* "mesh": {"element_size", "min_angle", "order", "band_layers",
                              "band_size", "disk_tolerance", "abaqus": {"plane", "reduced"}} */
    double expected_elements; /* the mesh's estimate used against the cap (0 without mesh) */
    size_t max_elements;   /* the cap the spec was checked against: the mesh stage fails
                              when the mesh grows beyond GP_MESH_CAP_SLACK times it (the
                              estimate is good to a factor of about two) */
} gp_spec;

/* Parses and validates a job spec: either the whole execute request {"inputs": {...}}
 * or the bare inputs object. `limits` may be NULL (defaults). On success returns 0 and
 * `spec` owns its distribution (free with gp_spec_free). On failure returns GP_EPARSE
 * (not JSON), GP_EINVAL (invalid field) or GP_ETOOBIG (over a cap), fills err with the
 * JSON pointer of the field (as it appears in `text`) and what was expected, and leaves
 * `spec` zeroed. */
GP_API int gp_spec_parse(const char *text, size_t len, const gp_spec_limits *limits, gp_spec *spec,
                         gp_error *err);

/* Reads the whole file at `path` into a new buffer (the caller frees *text with free()):
 * 0, GP_EIO (with the system's reason) or GP_ENOMEM, with err set. */
GP_API int gp_spec_read_text(const char *path, char **text, size_t *len, gp_error *err);

/* Reads and parses a spec file (as gp_spec_parse; GP_EIO if it cannot be read). */
GP_API int gp_spec_load_file(const char *path, const gp_spec_limits *limits, gp_spec *spec,
                             gp_error *err);

/* The expected number of disks: a packing density of 0.90 (a little above the 0.80-0.88
 * the front reaches, so that the estimate errs on the high side) over the mean
 * packing-disk area. Used for the disk cap. */
GP_API double gp_spec_expected_disks(const gp_domain *domain, const gp_distribution *dist,
                                     const gp_joint *joint);

/* A number of disks no packing of the law in the domain exceeds but with a chance below
 * 1e-9: the cap is checked against it, so that a law whose mean disk area is carried by a
 * few large disks cannot pass the cap on its mean and then pack far more small ones. */
GP_API double gp_spec_disk_bound(const gp_domain *domain, const gp_distribution *dist,
                                 const gp_joint *joint);

/* The packer's parameters for the spec (borrowing from it): its domain, law, joint and
 * seed, and its front rule, the default unless the spec gave a level band. */
GP_API gp_pack_params gp_spec_pack_params(const gp_spec *spec, size_t max_disks);

/* Frees what the spec owns and zeroes it. */
GP_API void gp_spec_free(gp_spec *spec);

#ifdef __cplusplus
}
#endif
#endif
