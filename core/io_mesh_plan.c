/* io_mesh_plan.c - what the mesh formats' plans share: whether the writer can read a
 * mesh (a result in memory that lacks its arrays is refused with a message, not read
 * through NULL), and what a format needs before the elements, learnt in passes over the
 * mesh's windows: no format holds more of the mesh than a window of each array. */
#include "io_mesh_plan.h"

#include <stdlib.h>
#include <string.h>

#include "grainpack/io_mesh.h"
#include "mesh_internal.h"

/* Whether `p` is there when `count` items are expected of it. */
static int present(const void *p, size_t count)
{
    return count == 0 || p != NULL;
}

int gp_mesh_result_check(const gp_result *r, gp_format format, gp_error *err)
{
    const char *name = gp_format_name(format);
    if (!r->has_mesh) {
        if (format != GP_FORMAT_VTU)
            return gp_error_set(err, GP_EINVAL, NULL,
                                "%s needs a mesh: the result has none (the spec asked for no "
                                "\"mesh\")", name);
        if (!present(r->packing.disks, r->packing.count) ||
            (r->has_cells && (!r->cells.start || !present(r->cells.xy, r->cells.start[r->cells.count]))))
            return gp_error_set(err, GP_EINVAL, NULL,
                                "vtu without a mesh needs the grains' arrays in the result, "
                                "which has only their counts");
        return 0;
    }
    const gp_mesh *m = &r->mesh;
    int tn = gp_mesh_tri_nodes(m->order), qn = gp_mesh_quad_nodes(m->order);
    if (!present(m->xy, m->nnodes) || !present(m->tri, m->ntri) || !present(m->tri_region, m->ntri) ||
        !present(m->quad, m->nquad) || !present(m->quad_region, m->nquad) ||
        !present(m->bedge, m->nbedges) || !present(m->bedge_side, m->nbedges) || tn == 0 || qn == 0 ||
        !m->region_area)
        return gp_error_set(err, GP_EINVAL, NULL,
                            "%s needs the mesh's arrays in the result, which has only its counts "
                            "(%zu nodes, %zu triangles, %zu quadrilaterals)",
                            name, m->nnodes, m->ntri, m->nquad);
    if (format == GP_FORMAT_VTU && !present(r->packing.disks, m->ngrains))
        return gp_error_set(err, GP_EINVAL, NULL,
                            "vtu needs the grains' radii in the result, which has only their count");
    return 0;
}

int gp_mesh_plan_check(gp_writer *w, gp_out *out)
{
    const gp_result *r = w->result;
    int rc = 0;
    if (!r->has_mesh || !w->mesh.load)
        rc = gp_mesh_result_check(r, w->format, &w->error);
    else if (!r->mesh.region_area)
        rc = gp_error_set(&w->error, GP_EINVAL, NULL, "%s needs the mesh's summary",
                          gp_format_name(w->format));
    if (rc && !out->err)
        out->err = rc;
    return rc;
}

int gp_mesh_layout_read(gp_writer *w, gp_out *out, gp_mesh_layout *layout)
{
    const gp_mesh *m = &w->result->mesh;
    size_t nregions = m->ngrains + 1, t = 0;
    memset(layout->side_count, 0, sizeof layout->side_count);
    if (!(layout->tri_start = malloc((nregions + 1) * sizeof *layout->tri_start))) {
        if (!out->err)
            out->err = GP_ENOMEM;
        return GP_ENOMEM;
    }
    /* region r starts at the first triangle of a region >= r */
    for (size_t r = 0; r <= nregions; r++) {
        while (t < m->ntri) {
            const int32_t *region = gp_writer_mesh(w, out, GP_MESH_TRI_REGION, t);
            if (!region)
                return out->err;
            if ((size_t)*region >= r)
                break;
            t++;
        }
        layout->tri_start[r] = t;
    }
    for (size_t e = 0; e < m->nbedges; e++) {
        const uint8_t *side = gp_writer_mesh(w, out, GP_MESH_BEDGE_SIDE, e);
        if (!side)
            return out->err;
        layout->side_count[*side]++;
    }
    return 0;
}

void gp_mesh_layout_free(gp_mesh_layout *layout)
{
    free(layout->tri_start);
    layout->tri_start = NULL;
}

size_t gp_mesh_layout_elements(const gp_mesh *m, const gp_mesh_layout *layout, size_t r)
{
    return layout->tri_start[r + 1] - layout->tri_start[r] + (r == m->ngrains ? m->nquad : 0);
}

int gp_mesh_plan_pairs(gp_writer *w, gp_out *out, int axis, int32_t **pairs, size_t *n)
{
    *pairs = NULL;
    *n = 0;
    const gp_domain *d = &w->spec->domain;
    if (!(d->periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)))
        return 0;
    gp_side_nodes s;
    gp_side_nodes_init(&s, d, axis);
    const gp_mesh *m = &w->result->mesh;
    int rc = 0;
    for (size_t k = 0; k < m->nnodes && rc == 0;) {
        const double *xy = gp_writer_mesh(w, out, GP_MESH_XY, k);
        if (!xy) {
            rc = out->err;
            break;
        }
        /* the rest of the window the node is in */
        const gp_mesh_window *win = &w->mesh_window[GP_MESH_XY];
        size_t count = win->first + win->count - k;
        rc = gp_side_nodes_add(&s, xy, k, count);
        k += count;
    }
    if (rc) {
        gp_side_nodes_free(&s);
        return rc;
    }
    return gp_side_nodes_pairs(&s, pairs, n);
}

int32_t gp_mesh_plan_region(gp_writer *w, gp_out *out, size_t e)
{
    size_t ntri = w->result->mesh.ntri;
    const int32_t *r = e < ntri ? gp_writer_mesh(w, out, GP_MESH_TRI_REGION, e)
                                : gp_writer_mesh(w, out, GP_MESH_QUAD_REGION, e - ntri);
    return r ? *r : -1;
}
