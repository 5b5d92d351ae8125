/* mesh_internal.h - inside the mesh stage: growing arrays, a hash map keyed by point
 * pairs (segments, edges), and the geometry the stage hands the mesher (the polygons of
 * the regions as a straight-line graph, and the band's structured strips). */
#ifndef GRAINPACK_MESH_INTERNAL_H
#define GRAINPACK_MESH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/mesh.h"
#include "mesh_cdt.h"

/* *array (capacity *cap elements of `size` bytes) with room for `need` elements: grown
 * (the capacity doubled until it fits) when needed. Returns 0 or GP_ENOMEM (the array is
 * then untouched). */
int gp_mesh_reserve(void **array, size_t *cap, size_t need, size_t size);

/* An open-addressing hash map from an unordered pair of indices to an int64 value. */
typedef struct gp_pair_map {
    uint64_t *keys; /* GP_PAIR_EMPTY where free */
    int64_t *values;
    size_t cap, count; /* cap a power of two */
} gp_pair_map;

#define GP_PAIR_EMPTY UINT64_MAX

/* Room for about `expected` pairs before the first growth. Returns 0 or GP_ENOMEM. */
int gp_pair_map_init(gp_pair_map *m, size_t expected);
void gp_pair_map_free(gp_pair_map *m);
/* The value of pair {a, b}, or NULL when it is not in the map. */
const int64_t *gp_pair_map_find(const gp_pair_map *m, int32_t a, int32_t b);
/* The value of pair {a, b}: *found is set to whether it was there; when it was not, it
 * is inserted with value `fresh`. Returns NULL when out of memory. */
int64_t *gp_pair_map_get(gp_pair_map *m, int32_t a, int32_t b, int64_t fresh, int *found);

/* The geometry of one mesh: the straight-line graph (grain outlines, domain sides, strip
 * outlines) with a seed per region, each region's polygon area, and the strips meshed
 * as structured quadrilaterals. Every array is owned (gp_mesh_geometry_free). */
typedef struct gp_mesh_geometry {
    gp_pslg pslg;
    gp_mesh_kind kind;
    size_t ngrains;
    double *region_area;      /* ngrains + 1 */
    double min_input_angle;   /* degrees: the smallest angle between two segments at a point */
    int layers;               /* quadrilateral layers across a strip (0: no strips) */
    size_t nstrips;
    size_t *strip_start;      /* nstrips + 1 offsets into strip_points */
    int32_t *strip_points;    /* strip k: (layers + 1) rows of (columns + 1) points, row 0
                                 on the first grain's edge: the outline's are pslg points,
                                 the inner ones -1 (the refinement may add columns) */
    double *strip_thickness;  /* nstrips */
    size_t strip_start_cap, strip_points_cap, strip_thickness_cap;
} gp_mesh_geometry;

/* Builds the geometry of `input` for `params` (see gp_mesh_build). Returns 0 or
 * GP_ENOMEM, GP_ECANCELED, GP_EINVAL (band_layers without offset cells); err says what,
 * and `out` is zeroed on failure. */
int gp_mesh_geometry_build(const gp_mesh_input *input, const gp_mesh_params *params,
                           const gp_progress *progress, gp_mesh_geometry *out, gp_error *err);

void gp_mesh_geometry_free(gp_mesh_geometry *g);

/* The part of polygon xy[0 .. 2n-1] inside box = {x0, x1, y0, y1} (Sutherland-Hodgman),
 * written to `out`; `out` and `work` have room for n + 4 vertices. A crossing of a box
 * line is computed from the edge's endpoint of lower coordinate: the same edge clipped
 * by the boxes on either side of a line gives the same point, bit for bit. Returns the
 * vertices of the part (0: none). */
size_t gp_mesh_clip_box(const double *xy, size_t n, const double box[4], double *out, double *work);

/* Periodic domains: makes the points of `g` on opposite periodic sides (x = 0 and W
 * along x, y = 0 and H along y) translates of each other, bit for bit: points within
 * tol along the side become one coordinate, a point without a partner gets one. Returns
 * 0 or GP_ENOMEM. */
int gp_mesh_match_sides(gp_pslg *g, unsigned periodic, double W, double H, double tol);

/* A node on a periodic side: its coordinate along the side, its index. */
typedef struct gp_side_point {
    double along;
    int32_t point;
} gp_side_point;

/* The nodes on the two sides across `axis` of a periodic domain (coordinate 0 and the
 * period), gathered window by window: what gp_mesh_periodic_pairs pairs, without the
 * whole of the nodes at once (a download reads them through windows). */
typedef struct gp_side_nodes {
    int axis;
    double period;
    gp_side_point *lo, *hi;
    size_t nlo, nhi, cap_lo, cap_hi;
} gp_side_nodes;

void gp_side_nodes_init(gp_side_nodes *s, const gp_domain *d, int axis);
/* Adds nodes first .. first + n - 1 (xy: their 2 n coordinates). Returns 0 or GP_ENOMEM. */
int gp_side_nodes_add(gp_side_nodes *s, const double *xy, size_t first, size_t n);
/* The pairs, as gp_mesh_periodic_pairs returns them; frees what s gathered. */
int gp_side_nodes_pairs(gp_side_nodes *s, int32_t **pairs, size_t *n);
void gp_side_nodes_free(gp_side_nodes *s);

/* Fills mesh->stats from the elements (angles, quality, areas) against the bound
 * `min_angle` (degrees) and the geometry's polygon areas. */
void gp_mesh_compute_stats(gp_mesh *mesh, double min_angle, const gp_domain *domain,
                           double min_input_angle);

#endif
