/* io_svg_mesh.h - inside the core: the mesh's edges drawn over the picture (io_svg.c). */
#ifndef GRAINPACK_IO_SVG_MESH_H
#define GRAINPACK_IO_SVG_MESH_H

#include "grainpack/out.h"
#include "grainpack/pipeline.h"

/* Whether the mesh is coarse enough to draw (a bound on its edges). */
int gp_svg_mesh_drawable(const gp_mesh *mesh);

/* The mesh's edges as one path, y flipped in a domain of height H, coordinates with
 * `decimals` digits; nothing without a mesh or when it is too fine. Returns o->err. */
int gp_svg_mesh(gp_out *o, const gp_result *result, double H, int decimals);

#endif
