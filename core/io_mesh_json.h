/* io_mesh_json.h - inside the core: the mesh's statistics as JSON, for the result's
 * statistics object (io_json.c). */
#ifndef GRAINPACK_IO_MESH_JSON_H
#define GRAINPACK_IO_MESH_JSON_H

#include <jansson.h>

#include "grainpack/mesh.h"
#include "grainpack/spec.h"

/* A new JSON object (caller owns the reference; NULL when out of memory): the options
 * used, counts by element type, angles, quality histogram, the phases' areas against
 * their polygons'. */
json_t *gp_mesh_statistics_json(const gp_spec *spec, const gp_mesh *mesh);

#endif
