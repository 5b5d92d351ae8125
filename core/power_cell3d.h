/* power_cell3d.h - the power cell of one sphere clipped to the box (internal to core/):
 * the box cut by the radical planes of the sphere's triangulation neighbours, nearest
 * first, then tidied (polyhedron.h). Shared by the Laguerre polyhedra (laguerre3d.c) and
 * the interior test of F (balance3d.c). */
#ifndef GRAINPACK_CORE_POWER_CELL3D_H
#define GRAINPACK_CORE_POWER_CELL3D_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/geometry3d.h"
#include "polyhedron.h"

/* Vertices of a cell closer than this fraction of its packing radius are one. Why this
 * value: vertices are computed to a few ulps of the radius (relative coordinates), about
 * 1e-15 R, and a vertex where more than four cells meet (five centres on one power sphere,
 * common where the packing is ordered) comes out as several within that noise, joined by
 * edges of 1e-15 R; 1e-12 R joins those with a margin of a thousand, while moving a
 * vertex by at most that much changes the volumes by about 1e-12 of a cell, the tiling
 * test's tolerance (and far less in practice: such vertices are rare). */
#define POWER_CELL3D_MERGE_RTOL 1e-12

/* A half-space u.n <= c relative to the centre, |n| = len. */
typedef struct plane3 {
    double n[3];
    double c, len;
} plane3;

/* The cell under construction and its scratch; zero-initialise, set box and spheres. A
 * face's label is the neighbour's position in the ring (>= 0) or GP_WALL3D(k). */
typedef struct power_cell3d {
    const gp_box *box;
    double grow[3];      /* the box grown by this on both sides of each axis (the ghost
                          * margin of a periodic axis, laguerre3d.c); 0 on walled axes */
    const gp_sphere *spheres;
    const gp_sphere *p;  /* the sphere of the cell */
    const int32_t *ring; /* its ring */
    plane3 *pl;          /* the radical plane of each ring neighbour */
    size_t pl_cap;
    uint32_t *order;     /* ring positions, nearest plane first */
    size_t order_cap;
    poly a, b;           /* the cell, and the scratch the cuts swap with it */
    poly_scratch sc;
} power_cell3d;

/* The power cell of spheres[i] with the given ring clipped to the box, tidied (faces
 * below GP_LAGUERRE_EDGE_RTOL^2 R^2 dropped, vertices within POWER_CELL3D_MERGE_RTOL R
 * merged), into pc->a. *holds_centre is cleared (and pc->a left alone) when the centre is
 * not strictly inside every half-space: an overlap, or a centre outside the box. Returns
 * 0 or GP_ENOMEM. */
int power_cell3d_build(power_cell3d *pc, int32_t i, const int32_t *ring, size_t degree,
                       int *holds_centre);

/* Starts pc->a as the box (grown by pc->grow) relative to pc->p's centre (0 or GP_ENOMEM). */
int power_cell3d_box(power_cell3d *pc);

/* Wall k (GP_WALL3D's numbering) as a half-space relative to p, moved inward by inset. */
void power_cell3d_wall(const gp_box *box, const gp_sphere *p, int k, double inset, plane3 *h);

/* Tidies pc->a as power_cell3d_build does (0 or GP_ENOMEM). */
int power_cell3d_tidy(power_cell3d *pc);

void power_cell3d_free(power_cell3d *pc);

#endif
