/* mesh_cdt.h - inside the core: the planar straight-line graph the mesh stage builds, and
 * its constrained Delaunay refinement by CGAL (core/mesh_cdt.cpp) behind a C API. */
#ifndef GRAINPACK_MESH_CDT_H
#define GRAINPACK_MESH_CDT_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/error.h"
#include "grainpack/progress.h"

#ifdef __cplusplus
extern "C" {
#define GP_CDT_NOEXCEPT noexcept
#else
#define GP_CDT_NOEXCEPT
#endif

/* Points, the segments between them that the mesh must follow, and one seed point inside
 * each region. A seed's region -1 marks a hole: what it reaches is not meshed (the band's
 * structured strips, meshed by the caller). A strip is a hole between two parallel sides
 * (segments from a0 to a1 and from b0 to b1, run the same way) and two protected ends
 * (a0 to b0, a1 to b1): the refinement may split its sides, and then splits the other
 * side at the same places, so that the sides end with matching nodes. Every array is
 * owned (gp_pslg_free). */
typedef struct gp_pslg {
    size_t npoints;
    double *xy;
    size_t nsegs;
    int32_t *seg;            /* point indices, two per segment */
    uint8_t *seg_protected;  /* 1: never split (a strip's outline, whose nodes are fixed) */
    size_t nseeds;
    double *seed_xy;
    int32_t *seed_region;
    int32_t default_region;  /* the region of what no seed reaches; -1: there must be none */
    size_t nstrips;
    int32_t *strip_corners;  /* a0, a1, b0, b1 of each strip */
    size_t npairs;           /* periodic sides: side a (a0 to a1) and side b (b0 to b1), a
                                translate of a; the refinement splits them like any side,
                                then puts on each the translates of the other's nodes
                                (bit for bit: the sides are axis-parallel, so a translate
                                keeps the coordinate along the side and sets the other) */
    int32_t pair_corners[2 * 4]; /* a0, a1, b0, b1 of each pair (at most one per axis) */
    size_t xy_cap, seg_cap, protected_cap, seed_xy_cap, seed_region_cap, strip_cap; /* allocated */
} gp_pslg;

/* Appends a point and returns its index, or -1 when out of memory. */
int32_t gp_pslg_point(gp_pslg *g, double x, double y);
/* Appends a segment; returns 0 or GP_ENOMEM. */
int gp_pslg_segment(gp_pslg *g, int32_t a, int32_t b, int protect);
/* Appends a seed; returns 0 or GP_ENOMEM. */
int gp_pslg_seed(gp_pslg *g, double x, double y, int32_t region);
/* Appends a strip (its sides and ends must be segments too); returns 0 or GP_ENOMEM. */
int gp_pslg_strip(gp_pslg *g, int32_t a0, int32_t a1, int32_t b0, int32_t b1);
void gp_pslg_free(gp_pslg *g);

/* The graded region's local size is the band's thickness times this: elements about as
 * long as the band is thick (issue 11), one row of triangles across a strip. */
#define GP_CDT_GRADED_SIZE_PER_THICKNESS 1.5

typedef struct gp_cdt_params {
    double size_bound;        /* the longest edge allowed (0: none) */
    double shape_bound;       /* sin^2 of the smallest angle allowed (0: none) */
    int32_t graded_region;    /* the region whose faces get a size bound of their own (the
                                 band), or -1 */
    double graded_size;       /* that bound (when under size_bound), or 0: the region's
                                 local thickness, measured on its outline before refining */
    size_t max_triangles;     /* GP_ETOOBIG beyond this (0: no cap) */
    double expected_triangles;/* for progress: the fraction reported is faces / this */
    const gp_progress *progress; /* stage "mesh"; may be NULL */
    double progress_from, progress_to; /* the part of the stage's progress this covers */
} gp_cdt_params;

/* The refined triangulation: every node, the node of each input point, and the
 * triangles of the meshed regions (counter-clockwise) with their region. Owned arrays. */
typedef struct gp_cdt_mesh {
    size_t nnodes;
    double *xy;
    int32_t *point_node;  /* npoints entries */
    size_t ntri;
    int32_t *tri;
    int32_t *region;
    size_t dropped;       /* bad triangles left alone: refining them would have split a
                             protected segment */
    size_t *strip_start;  /* nstrips + 1 offsets into strip_sides */
    int32_t *strip_sides; /* strip k: the nodes of side a (a0 .. a1), then as many of side b */
    int rounds;           /* refinements run until every strip's and periodic pair's sides
                             matched */
} gp_cdt_mesh;

/* Inserts the points and segments of `g` in a CGAL constrained Delaunay triangulation,
 * refines it (CGAL's Delaunay mesher: encroached segments split, bad triangles get their
 * circumcentre) until no triangle has an edge over size_bound (over its own bound in
 * the graded region) or an angle under the shape bound, except where that would split a
 * protected segment, mirrors the splits of
 * strip sides onto the facing sides (and of periodic sides onto their translates) and
 * refines again until they match (the last round protects the sides), then labels the
 * triangles by region. Returns 0 and fills `out` (free with gp_cdt_mesh_free), or
 * GP_ENOMEM, GP_ECANCELED, GP_ETOOBIG, GP_EGEOM (a seed's region leaks into another's, or
 * triangles no seed reaches with default_region -1) or GP_EINTERNAL (CGAL threw); err
 * says what and `out` is zeroed. */
int gp_cdt_refine(const gp_pslg *g, const gp_cdt_params *params, gp_cdt_mesh *out,
                  gp_error *err);

void gp_cdt_mesh_free(gp_cdt_mesh *m) GP_CDT_NOEXCEPT;

#ifdef __cplusplus
}
#endif
#endif
