/* mesh.h - finite-element meshes of a structure: the grains and the grain-boundary band
 * (or the cells, or the disks in a matrix) meshed conformingly by CGAL's constrained
 * Delaunay refinement, with optional structured quadrilateral layers across the band's
 * straight strips, second-order nodes, and the statistics of the result. */
#ifndef GRAINPACK_MESH_H
#define GRAINPACK_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/disk.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/laguerre.h"
#include "grainpack/progress.h"
#include "grainpack/triangulation.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The largest minimum angle (degrees) a spec may ask for: Delaunay refinement is proved
 * to terminate for a bound B = sin^2(angle) down to 1/8 (Shewchuk; CGAL's mesher, whose
 * default this is), i.e. arcsin(sqrt(1/8)) = 20.7048 degrees. Above it CGAL may not stop. */
#define GP_MESH_MAX_MIN_ANGLE 20.7048
/* The default element size, as a fraction of the law's mean grain radius: about sixty
 * triangles in a grain, enough for a stress field, few enough for 10^5 grains. */
#define GP_MESH_DEFAULT_SIZE_RATIO 0.5
/* The default polygonisation of disk outlines (no cells): the largest distance between
 * an outline edge and its arc, relative to the radius (23 edges for a whole circle). */
#define GP_MESH_DEFAULT_DISK_TOLERANCE 0.01
/* A mesh may grow to this many times the element cap its spec was checked against
 * before the stage gives up: the estimate (gp_mesh_expected_elements) was 0.69 to 1.62
 * times the count made on the reference cases (bench/MESH.md). */
#define GP_MESH_CAP_SLACK 2
/* Periodic domains: an outline vertex closer than this times the mean packing radius to
 * a periodic side's line is put on it before the outlines are cut into pieces. Why: a
 * vertex a little off the line leaves a sliver of band (or grain) as thin as its
 * distance to the line, opening at the small angle of the vertex's edges, which Delaunay
 * refinement can only fill with a cascade of tiny elements (a vertex 2e-4 R from the
 * line made 110,000 extra nodes on the periodic iron mesh); on the line, it is an input
 * corner, which CGAL's clusters handle. The outline moves by less than the polygonised
 * disks' own tolerance (GP_MESH_DEFAULT_DISK_TOLERANCE), and only at such vertices. */
#define GP_MESH_SIDE_SNAP_RTOL 0.01
/* The most layers a spec may ask across a band strip. */
#define GP_MESH_MAX_BAND_LAYERS 64

/* The Abaqus element family: plane stress (CPS3, CPS6, CPS4, CPS8) or plane strain
 * (CPE3, ...). */
typedef enum gp_mesh_plane {
    GP_MESH_PLANE_STRESS = 0,
    GP_MESH_PLANE_STRAIN
} gp_mesh_plane;

typedef struct gp_mesh_params {
    double element_size;   /* longest edge allowed anywhere (> 0) */
    double min_angle;      /* degrees, in [0, GP_MESH_MAX_MIN_ANGLE] */
    int order;             /* 1, or 2 for mid-edge nodes (TRI6, QUAD8) */
    int band_layers;       /* 0: the band is triangles; n: n layers of quadrilaterals across
                              every straight strip of the band (needs offset cells) */
    double band_size;      /* the band's target edge length (its triangles with grading,
                              the quads' length along a strip with band_layers); 0: the
                              band's local thickness */
    int grading;           /* 1: the band's triangles are graded to band_size (shrunk
                              cells only); 0: sized by element_size and min_angle alone */
    double disk_tolerance; /* without cells: outline-to-arc distance / radius, (0, 0.25] */
    gp_mesh_plane plane;   /* Abaqus element types */
    int reduced;           /* Abaqus: reduced integration for quadrilaterals (CPS4R, CPS8R) */
} gp_mesh_params;

/* What the regions of a mesh are. Regions 0 .. ngrains-1 are the grains (one per disk, in
 * the disks' order); region ngrains, when present, is the second phase. */
typedef enum gp_mesh_kind {
    GP_MESH_GRAINS_AND_BAND = 0, /* shrunk cells and the grain-boundary band */
    GP_MESH_CELLS,               /* unshrunk cells: no second phase */
    GP_MESH_DISKS_IN_MATRIX      /* polygonised disks in a matrix */
} gp_mesh_kind;

/* The phase of a region: a grain, the grain-boundary band, or the matrix. */
typedef enum gp_mesh_phase {
    GP_PHASE_GRAIN = 0,
    GP_PHASE_BAND,
    GP_PHASE_MATRIX
} gp_mesh_phase;

/* The four sides of the domain, in the order the writers list them. */
typedef enum gp_mesh_side {
    GP_SIDE_LEFT = 0,
    GP_SIDE_RIGHT,
    GP_SIDE_BOTTOM,
    GP_SIDE_TOP,
    GP_SIDE_COUNT
} gp_mesh_side;

/* Bins of the element-quality histogram over [0, 1]. */
#define GP_MESH_QUALITY_BINS 10

typedef struct gp_mesh_stats {
    size_t nodes, triangles, quads;
    size_t boundary_edges;
    double min_angle, max_angle;  /* degrees, over every corner of every element */
    size_t below_min_angle;       /* triangles with an angle below the bound asked for */
    double min_input_angle;       /* the smallest angle between two input outline edges
                                     at a corner (degrees): below the bound, the refinement
                                     cannot meet it there */
    double quality_min, quality_mean;
    size_t quality_histogram[GP_MESH_QUALITY_BINS];
    double domain_area;
    double element_area;          /* sum over the elements */
    double grain_area;            /* elements of the grains */
    double grain_polygon_area;    /* the grain polygons' own (shoelace) areas */
    double phase_area;            /* elements of the second phase (0 without one) */
    double phase_polygon_area;    /* the domain's area minus the grain polygons' */
    size_t band_strips;           /* strips meshed with quadrilaterals (band_layers) */
    double band_thickness_min, band_thickness_mean; /* of those strips */
    size_t refused_refinements;   /* bad triangles the refinement left: fixing them would
                                     have split a strip's outline or (periodic) a side
                                     locked in the last round */
    size_t periodic_pairs[2];     /* node pairs across the periodic sides along x and y
                                     (gp_mesh_periodic_pairs), corners included; 0 along a
                                     walled axis */
    int rounds;                   /* refinements run until the strips' and periodic sides
                                     matched (1: they matched at once) */
} gp_mesh_stats;

/* A mesh. Node coordinates and connectivities as in Gmsh and VTK: corner nodes counter-
 * clockwise, then (order 2) the mid-edge nodes of edges 0-1, 1-2, 2-0 (triangles) or
 * 0-1, 1-2, 2-3, 3-0 (quadrilaterals). The triangles are sorted by region; the
 * quadrilaterals are all in the second phase. Every array is owned. */
typedef struct gp_mesh {
    gp_mesh_kind kind;
    int order;
    size_t ngrains;       /* the grain regions; the second phase is region ngrains */
    size_t nnodes;
    double *xy;           /* nnodes x, y pairs */
    size_t ntri;
    int32_t *tri;         /* ntri * (order == 1 ? 3 : 6) node indices */
    int32_t *tri_region;
    size_t nquad;
    int32_t *quad;        /* nquad * (order == 1 ? 4 : 8) */
    int32_t *quad_region;
    size_t nbedges;
    int32_t *bedge;       /* nbedges * (order + 1): end nodes (domain counter-clockwise),
                             then the mid node */
    uint8_t *bedge_side;  /* gp_mesh_side of each boundary edge */
    double *region_area;  /* ngrains + 1: the polygon area of each region (the second
                             phase's: the domain's minus the grains') */
    gp_mesh_stats stats;
} gp_mesh;

/* The nodes per triangle and per quadrilateral of a mesh of this order. */
static inline int gp_mesh_tri_nodes(int order) { return order == 2 ? 6 : 3; }
static inline int gp_mesh_quad_nodes(int order) { return order == 2 ? 8 : 4; }

/* The phase of region `region` of `mesh`. */
GP_API gp_mesh_phase gp_mesh_region_phase(const gp_mesh *mesh, int32_t region);

/* "grain", "grain_boundary" or "matrix". */
GP_API const char *gp_mesh_phase_name(gp_mesh_phase phase);

/* "left", "right", "bottom", "top". */
GP_API const char *gp_mesh_side_name(gp_mesh_side side);

/* The quality of an element, in [0, 1] (1: equilateral triangle, square): for a
 * triangle 4 sqrt(3) area / (sum of squared edge lengths), for a quadrilateral the
 * smallest 2 |a x b| / (|a|^2 + |b|^2) over its corners (a, b its two edges there). */
GP_API double gp_mesh_element_quality(const gp_mesh *mesh, int quad, size_t index);

/* The signed area of triangle `index` or quadrilateral `index` (corner nodes). */
GP_API double gp_mesh_element_area(const gp_mesh *mesh, int quad, size_t index);

/* The default parameters: element size GP_MESH_DEFAULT_SIZE_RATIO times the mean grain
 * radius of `dist`, the largest guaranteed minimum angle, order 1, no layers, the band graded to
 * its local thickness. */
GP_API void gp_mesh_params_default(const gp_distribution *dist, gp_mesh_params *params);

/* The mean grain radius of a law. */
GP_API double gp_mesh_mean_radius(const gp_distribution *dist);

/* An estimate of the elements a mesh with `params` will have (0.69 to 1.62 times the
 * count made on the reference cases, seeds and options of bench/MESH.md;
 * tests/test_mesh_estimate.c holds it within 0.6 to 1.7), for a structure of
 * `expected_disks` grains of law `dist` with joint `joint` in `domain`, with cells shrunk
 * by `shrink` (`has_cells` 0: disks in a matrix). Used to refuse specs over a cap before
 * any work. */
GP_API double gp_mesh_expected_elements(const gp_domain *domain, const gp_distribution *dist,
                                        const gp_joint *joint, double expected_disks, int has_cells,
                                        gp_shrink shrink, const gp_mesh_params *params);

/* What to mesh: the domain, the disks, and their cells when the Laguerre stage ran (NULL:
 * the disks in a matrix, and `rt` must be their regular triangulation, to find contacts;
 * it is not used with cells). Borrowed. */
typedef struct gp_mesh_input {
    const gp_domain *domain;
    const gp_disk *disks;
    size_t ndisks;
    const gp_cells *cells;
    const gp_rt *rt;
    size_t max_elements;  /* fail with GP_ETOOBIG when the mesh grows beyond this (0: none) */
} gp_mesh_input;

/* Builds the mesh (the pipeline's stage "mesh"): reports progress, honours
 * progress->cancel (checked every few milliseconds, also inside the refinement). On
 * success returns 0 and `out` owns its arrays (free with gp_mesh_free). Fails with
 * GP_ENOMEM, GP_ECANCELED, GP_ETOOBIG (over max_elements), GP_EINVAL (band_layers without
 * offset cells), GP_EGEOM (a region the constraints did not close) or GP_EINTERNAL (CGAL
 * failed); err says what; `out` is zeroed. */
GP_API int gp_mesh_build(const gp_mesh_input *input, const gp_mesh_params *params,
                         const gp_progress *progress, gp_mesh *out, gp_error *err);

GP_API void gp_mesh_free(gp_mesh *mesh);

/* The node pairs of a mesh of a domain periodic along `axis` (0: x, 1: y): the nodes on
 * the low side (x = 0, or y = 0) and their translates on the high side (x = W, y = H),
 * the same coordinate along the side bit for bit, sorted along it, corners included:
 * *pairs gets 2 * *n node indices (low, high), owned by the caller. With the axis not
 * periodic: 0 and no pairs. Returns 0, GP_ENOMEM, or GP_EGEOM when the sides' nodes do
 * not pair up one to one (not a periodic mesh). */
GP_API int gp_mesh_periodic_pairs(const gp_mesh *mesh, const gp_domain *domain, int axis,
                                  int32_t **pairs, size_t *n);

#ifdef __cplusplus
}
#endif
#endif
