/* io_mesh_plan.c - the mesh formats (msh, inp, vtu) as writer plans: one text step that
 * writes the whole file from the result's mesh. The mesh is not read window by window:
 * the writer's result must hold it whole (in memory, or decoded from the stored
 * sections), and so must VTU's grains; a result that lacks them is refused with a
 * message (gp_writer_error), not read through NULL. */
#include "grainpack/io_mesh.h"
#include "writer.h"

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

static void whole(gp_writer *w, gp_out *out, int param)
{
    gp_format format = (gp_format)param;
    int rc = gp_mesh_result_check(w->result, format, &w->error);
    if (rc == 0) {
        switch (format) {
        case GP_FORMAT_MSH: rc = gp_write_msh(out, w->spec, w->result); break;
        case GP_FORMAT_INP: rc = gp_write_inp(out, w->spec, w->result); break;
        default: rc = gp_write_vtu(out, w->spec, w->result); break;
        }
    }
    if (rc && !out->err)
        out->err = rc;
}

int gp_plan_mesh(gp_writer *w)
{
    gp_writer_text(w, whole, (int)w->format);
    return 0;
}
