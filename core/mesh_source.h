/* mesh_source.h - where the mesh writers (msh, inp, vtu) read a mesh's arrays: window by
 * window, from a mesh in memory or from a stored result's sections (sections.h), so that
 * a download holds a window of each array, never the whole mesh. */
#ifndef GRAINPACK_MESH_SOURCE_H
#define GRAINPACK_MESH_SOURCE_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/io.h"
#include "grainpack/mesh.h"

/* The arrays, each a list of records: a node's x, y (2 f64), a triangle's or a
 * quadrilateral's nodes (i32 each), an element's region (i32), a boundary edge's order + 1
 * nodes (i32) and its side (u8), an element's quality (f64, triangles then quadrilaterals:
 * gp_mesh_element_quality). */
typedef enum gp_mesh_array {
    GP_MESH_XY,
    GP_MESH_TRI,
    GP_MESH_TRI_REGION,
    GP_MESH_QUAD,
    GP_MESH_QUAD_REGION,
    GP_MESH_BEDGE,
    GP_MESH_BEDGE_SIDE,
    GP_MESH_QUALITY,
    GP_MESH_ARRAYS
} gp_mesh_array;

/* Records a source hands over at once: a few hundred kilobytes of buffers over all the
 * arrays (a second-order triangle's record is 24 bytes), and few enough calls. */
#define GP_MESH_WINDOW_RECORDS ((size_t)4096)

/* `load` points *data at the records of array `a` from record `first` on (first < the
 * array's count), *count of them (at least 1); they stay valid until the next load of the
 * same array. Node indices and regions are in range (a source that reads them from a
 * store checks them). Returns 0 or a negative code, which stops the writer. `drop` frees
 * ctx (NULL: nothing to free). */
typedef struct gp_mesh_source {
    int (*load)(void *ctx, gp_mesh_array a, size_t first, const void **data, size_t *count);
    void *ctx;
    void (*drop)(void *ctx);
} gp_mesh_source;

/* The bytes of one record of array `a` of mesh `m` (its order), and the records. */
size_t gp_mesh_record_size(const gp_mesh *m, gp_mesh_array a);
size_t gp_mesh_record_count(const gp_mesh *m, gp_mesh_array a);

/* The source of a mesh held in memory (its arrays borrowed: `m` must outlive the
 * source); qualities are computed a window at a time. Returns 0 or GP_ENOMEM. Free with
 * gp_mesh_source_free. */
int gp_mesh_source_memory(const gp_mesh *m, gp_mesh_source *out);
void gp_mesh_source_free(gp_mesh_source *s);

/* Makes writer `w` (msh, inp, vtu) read the mesh from `source` (taken over: freed with
 * the writer) instead of the result's arrays: a download's windows on the stored mesh. */
void gp_writer_set_mesh(gp_writer *w, const gp_mesh_source *source);

/* The quality of element e (triangles, then quadrilaterals) of a mesh in memory. */
double gp_mesh_quality_at(const gp_mesh *m, size_t e);

#endif
