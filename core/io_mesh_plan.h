/* io_mesh_plan.h - what the mesh formats' plans (io_msh.c, io_inp.c, io_vtu.c) share:
 * the check that the writer can read a mesh, and what they learn of it in passes over
 * its windows before the first element is written (io_mesh_plan.c). */
#ifndef GRAINPACK_IO_MESH_PLAN_H
#define GRAINPACK_IO_MESH_PLAN_H

#include "writer.h"

/* What a format knows of the mesh before writing it: the triangles of region r are
 * [tri_start[r], tri_start[r + 1]) (they are stored sorted by region), the quadrilaterals
 * all in the last region; the boundary edges on each side. */
typedef struct gp_mesh_layout {
    size_t *tri_start;                 /* regions + 1 */
    size_t side_count[GP_SIDE_COUNT];
} gp_mesh_layout;

/* Whether the writer can write its format: a mesh it reads (or, vtu without a mesh, the
 * grains' arrays); when not, w->error says why and out->err is set. Returns 0 or that
 * error. */
int gp_mesh_plan_check(gp_writer *w, gp_out *out);

/* Fills `layout` (tri_start allocated: free with gp_mesh_layout_free) in one pass over
 * the regions and the boundary edges' sides. Returns 0 or an error (also set in out->err). */
int gp_mesh_layout_read(gp_writer *w, gp_out *out, gp_mesh_layout *layout);
void gp_mesh_layout_free(gp_mesh_layout *layout);

/* The elements of region r: its triangles, and the quadrilaterals in the last region. */
size_t gp_mesh_layout_elements(const gp_mesh *m, const gp_mesh_layout *layout, size_t r);

/* gp_mesh_periodic_pairs of the writer's mesh, its nodes read window by window. */
int gp_mesh_plan_pairs(gp_writer *w, gp_out *out, int axis, int32_t **pairs, size_t *n);

/* The region of element e (triangles, then quadrilaterals); -1 when the source failed. */
int32_t gp_mesh_plan_region(gp_writer *w, gp_out *out, size_t e);

#endif
