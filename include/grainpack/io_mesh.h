/* io_mesh.h - the result as a finite-element mesh: Gmsh MSH 4.1, Abaqus input, VTK XML
 * unstructured grid (.vtu). Writers emit into a gp_out and are deterministic: the same
 * result gives the same bytes. Numbers are written as the shortest decimal that reads
 * back to the same double. */
#ifndef GRAINPACK_IO_MESH_H
#define GRAINPACK_IO_MESH_H

#include "grainpack/api.h"
#include "grainpack/out.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Gmsh MSH 4.1 (ASCII): one surface entity and physical group per region with elements
 * ("grain_<id>", "grain_boundary" or "matrix"), one curve entity and physical group per
 * domain side ("left", "right", "bottom", "top") with its line elements. Needs the mesh
 * stage and its arrays: GP_EINVAL without them (gp_writer_error says which). Returns 0 or
 * o->err. */
GP_API int gp_write_msh(gp_out *o, const gp_spec *spec, const gp_result *result);

/* Abaqus input: nodes, elements (CPS3/CPS6/CPS4/CPS8 for plane stress, CPE* for plane
 * strain, R for reduced integration of quadrilaterals, as the spec asks), an element set
 * per grain ("grain_<id>") and for the second phase, a node set per domain side. Needs
 * the mesh stage and its arrays (GP_EINVAL). */
GP_API int gp_write_inp(gp_out *o, const gp_spec *spec, const gp_result *result);

/* VTK XML unstructured grid (ASCII). With a mesh: its elements, with cell data region,
 * phase (0 grain, 1 grain boundary, 2 matrix), grain_radius (the grain's r; 0 in the
 * second phase) and quality. Without one: the grains, as polygons when the job has
 * cells (cell data grain_id, radius, packing_radius, area, neighbours, F), else as
 * vertices at the disk centres (the same arrays as point data, without area and
 * neighbours). GP_EINVAL when the result lacks the arrays this reads. */
GP_API int gp_write_vtu(gp_out *o, const gp_spec *spec, const gp_result *result);

#ifdef __cplusplus
}
#endif
#endif
