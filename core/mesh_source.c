/* mesh_source.c - the records of a mesh's arrays (mesh_source.h), and the source of a
 * mesh in memory: windows that point into its arrays, qualities computed per window. */
#include "mesh_source.h"

#include <stdlib.h>

#include "grainpack/error.h"

size_t gp_mesh_record_size(const gp_mesh *m, gp_mesh_array a)
{
    switch (a) {
    case GP_MESH_XY: return 2 * sizeof(double);
    case GP_MESH_TRI: return (size_t)gp_mesh_tri_nodes(m->order) * sizeof(int32_t);
    case GP_MESH_QUAD: return (size_t)gp_mesh_quad_nodes(m->order) * sizeof(int32_t);
    case GP_MESH_BEDGE: return (size_t)(m->order + 1) * sizeof(int32_t);
    case GP_MESH_BEDGE_SIDE: return 1;
    case GP_MESH_QUALITY: return sizeof(double);
    default: return sizeof(int32_t); /* the regions */
    }
}

size_t gp_mesh_record_count(const gp_mesh *m, gp_mesh_array a)
{
    switch (a) {
    case GP_MESH_XY: return m->nnodes;
    case GP_MESH_TRI:
    case GP_MESH_TRI_REGION: return m->ntri;
    case GP_MESH_QUAD:
    case GP_MESH_QUAD_REGION: return m->nquad;
    case GP_MESH_BEDGE:
    case GP_MESH_BEDGE_SIDE: return m->nbedges;
    default: return m->ntri + m->nquad; /* the qualities */
    }
}

double gp_mesh_quality_at(const gp_mesh *m, size_t e)
{
    return e < m->ntri ? gp_mesh_element_quality(m, 0, e) : gp_mesh_element_quality(m, 1, e - m->ntri);
}

typedef struct memory_mesh {
    const gp_mesh *m;
    double quality[GP_MESH_WINDOW_RECORDS];
} memory_mesh;

static int load_memory(void *ctx, gp_mesh_array a, size_t first, const void **data, size_t *count)
{
    const memory_mesh *mm = ctx;
    const gp_mesh *m = mm->m;
    size_t left = gp_mesh_record_count(m, a) - first;
    *count = left;
    switch (a) {
    case GP_MESH_XY: *data = m->xy + 2 * first; break;
    case GP_MESH_TRI: *data = m->tri + (size_t)gp_mesh_tri_nodes(m->order) * first; break;
    case GP_MESH_TRI_REGION: *data = m->tri_region + first; break;
    case GP_MESH_QUAD: *data = m->quad + (size_t)gp_mesh_quad_nodes(m->order) * first; break;
    case GP_MESH_QUAD_REGION: *data = m->quad_region + first; break;
    case GP_MESH_BEDGE: *data = m->bedge + (size_t)(m->order + 1) * first; break;
    case GP_MESH_BEDGE_SIDE: *data = m->bedge_side + first; break;
    default: {
        memory_mesh *w = ctx;
        size_t n = left < GP_MESH_WINDOW_RECORDS ? left : GP_MESH_WINDOW_RECORDS;
        for (size_t k = 0; k < n; k++)
            w->quality[k] = gp_mesh_quality_at(m, first + k);
        *data = w->quality;
        *count = n;
    }
    }
    return 0;
}

int gp_mesh_source_memory(const gp_mesh *m, gp_mesh_source *out)
{
    memory_mesh *mm = malloc(sizeof *mm);
    if (!mm)
        return GP_ENOMEM;
    mm->m = m;
    *out = (gp_mesh_source){load_memory, mm, free};
    return 0;
}

void gp_mesh_source_free(gp_mesh_source *s)
{
    if (s->drop)
        s->drop(s->ctx);
    *s = (gp_mesh_source){0};
}
