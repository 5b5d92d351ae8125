/* polyhedron.h - a convex polyhedron cut by half-spaces (internal to core/): the 3D
 * analogue of laguerre.c's polygon cut, for the Laguerre polyhedra of core/laguerre3d.c.
 * Coordinates are relative to a point inside (the grain's centre), so that they stay
 * accurate to a few ulps of the cell's size wherever the cell lies. */
#ifndef GRAINPACK_CORE_POLYHEDRON_H
#define GRAINPACK_CORE_POLYHEDRON_H

#include <stddef.h>
#include <stdint.h>

/* Vertices u (x y z interleaved) and faces: face f has the vertices
 * fv[fs[f]] .. fv[fs[f + 1] - 1], counter-clockwise seen from outside, and a label (what
 * cut it: the caller's number). Owns its arrays; zero-initialise before first use. */
typedef struct poly {
    double *u;
    size_t nv, vcap;
    uint32_t *fv;
    size_t fvcap;
    size_t *fs;
    int32_t *label;
    size_t nf, fcap;
} poly;

/* Scratch of poly_cut, kept between calls. Zero-initialise; free with poly_scratch_free. */
typedef struct poly_scratch {
    double *d;        /* signed distance of each vertex to the plane */
    uint32_t *map;    /* old vertex -> new vertex */
    size_t cap;
    uint32_t *cross;  /* (a, b, new vertex) of each edge cut */
    size_t ncross, cross_cap;
    uint32_t *cap_edge; /* (from, to) edges of the new face */
    size_t ncap, cap_edge_cap;
    double *angle;
    size_t angle_cap;
} poly_scratch;

/* Makes p the box [lo, hi] (per axis; relative coordinates), its six faces labelled
 * wall_label[k], k = 0 x = lo, 1 x = hi, 2 y = lo, 3 y = hi, 4 z = lo, 5 z = hi. Returns 0
 * or GP_ENOMEM. */
int poly_box(poly *p, const double lo[3], const double hi[3], const int32_t wall_label[6]);

/* Cuts p by the half-space u.n <= c; the new face (if it has area) gets `label`. The result
 * goes to `out` and the two are swapped (p then holds the cut polyhedron); p is left alone
 * when no vertex is outside. A vertex exactly on the plane stays, the plane's crossing of
 * an edge is computed once for both faces of the edge (from its inner end), so the faces
 * agree on every vertex. Returns 0 or GP_ENOMEM; p may become empty (nf = 0). */
int poly_cut(poly *p, const double n[3], double c, int32_t label, poly *out, poly_scratch *s);

/* Merges vertices within `merge` of an earlier one and drops the faces left with fewer
 * than three vertices or, through keep(), those the caller finds negligible; unused
 * vertices are removed. keep(ctx, label, area) decides on each remaining face (NULL
 * keeps all). Done in place with `out` as scratch (swapped). Returns 0 or GP_ENOMEM. */
int poly_tidy(poly *p, double merge, int (*keep)(void *ctx, int32_t label, double area), void *ctx,
              poly *out, poly_scratch *s);

/* The area of face f. */
double poly_face_area(const poly *p, size_t f);

/* The volume of p (positive; p closed, faces outward, the origin anywhere). */
double poly_volume(const poly *p);

void poly_free(poly *p);
void poly_scratch_free(poly_scratch *s);

#endif
