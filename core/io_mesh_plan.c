/* io_mesh_plan.c - the mesh formats (msh, inp, vtu) as writer plans: one text step that
 * writes the whole file from the result's mesh. The mesh is not read window by window:
 * the writer's result must hold it whole (in memory, or decoded from the stored
 * sections), and so must VTU's grains when there is no mesh. */
#include "grainpack/io_mesh.h"
#include "writer.h"

static void whole(gp_writer *w, gp_out *out, int param)
{
    int rc = 0;
    switch ((gp_format)param) {
    case GP_FORMAT_MSH: rc = gp_write_msh(out, w->spec, w->result); break;
    case GP_FORMAT_INP: rc = gp_write_inp(out, w->spec, w->result); break;
    default: rc = gp_write_vtu(out, w->spec, w->result); break;
    }
    if (rc && !out->err)
        out->err = rc; /* GP_EINVAL: msh or inp of a result without a mesh */
}

int gp_plan_mesh(gp_writer *w)
{
    gp_writer_text(w, whole, (int)w->format);
    return 0;
}
