/* io_vtu.c - the result as a VTK XML unstructured grid (ASCII), which ParaView, VTK and
 * meshio read: the mesh with its cell data, or without a mesh the grains themselves
 * (cells as polygons, or disk centres as vertices). */
#include <math.h>

#include "grainpack/io_mesh.h"
#include "vtu_array.h"
#include "writer.h"

/* VTK cell types (vtkCellType.h). */
#define VTK_VERTEX 1
#define VTK_TRIANGLE 5
#define VTK_POLYGON 7
#define VTK_QUAD 9
#define VTK_QUADRATIC_TRIANGLE 22
#define VTK_QUADRATIC_QUAD 23
static void points(gp_out *o, const double *xy, size_t stride, size_t n)
{
    vtu_array a = vtu_open_array(o, "Float64", "Points", 3);
    for (size_t k = 0; k < n; k++) {
        vtu_double(&a, xy[stride * k]);
        vtu_double(&a, xy[stride * k + 1]);
        vtu_int(&a, 0);
    }
    vtu_close_array(&a);
    gp_out_puts(o, "</Points>\n<Cells>\n");
}

static int write_mesh(gp_out *o, const gp_result *result)
{
    const gp_mesh *m = &result->mesh;
    size_t cells = m->ntri + m->nquad;
    int tn = gp_mesh_tri_nodes(m->order), qn = gp_mesh_quad_nodes(m->order);
    vtu_header(o, m->nnodes, cells);
    points(o, m->xy, 2, m->nnodes);
    vtu_array a = vtu_open_array(o, "Int64", "connectivity", 1);
    for (size_t k = 0; k < (size_t)tn * m->ntri; k++)
        vtu_int(&a, m->tri[k]);
    for (size_t k = 0; k < (size_t)qn * m->nquad; k++)
        vtu_int(&a, m->quad[k]);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int64", "offsets", 1);
    for (size_t e = 0; e < cells; e++)
        vtu_int(&a, e < m->ntri ? (int64_t)(tn * (e + 1))
                                : (int64_t)(tn * m->ntri + qn * (e + 1 - m->ntri)));
    vtu_close_array(&a);
    a = vtu_open_array(o, "UInt8", "types", 1);
    for (size_t e = 0; e < cells; e++)
        vtu_int(&a, e < m->ntri ? (m->order == 2 ? VTK_QUADRATIC_TRIANGLE : VTK_TRIANGLE)
                                : (m->order == 2 ? VTK_QUADRATIC_QUAD : VTK_QUAD));
    vtu_close_array(&a);
    gp_out_puts(o, "</Cells>\n<CellData Scalars=\"region\">\n");
    a = vtu_open_array(o, "Int32", "region", 1);
    for (size_t e = 0; e < cells; e++)
        vtu_int(&a, e < m->ntri ? m->tri_region[e] : m->quad_region[e - m->ntri]);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int32", "phase", 1);
    for (size_t e = 0; e < cells; e++)
        vtu_int(&a, gp_mesh_region_phase(m, e < m->ntri ? m->tri_region[e] : m->quad_region[e - m->ntri]));
    vtu_close_array(&a);
    a = vtu_open_array(o, "Float64", "grain_radius", 1);
    for (size_t e = 0; e < cells; e++) {
        int32_t r = e < m->ntri ? m->tri_region[e] : m->quad_region[e - m->ntri];
        vtu_double(&a, (size_t)r < m->ngrains ? result->packing.disks[r].r : 0.0);
    }
    vtu_close_array(&a);
    a = vtu_open_array(o, "Float64", "quality", 1);
    for (size_t e = 0; e < cells; e++)
        vtu_double(&a, e < m->ntri ? gp_mesh_element_quality(m, 0, e)
                                   : gp_mesh_element_quality(m, 1, e - m->ntri));
    vtu_close_array(&a);
    gp_out_puts(o, "</CellData>\n");
    return vtu_footer(o);
}

/* The per-grain arrays, in grain order: cell data of polygons or point data of vertices. */
static void grain_arrays(gp_out *o, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    vtu_array a = vtu_open_array(o, "Int64", "grain_id", 1);
    for (size_t i = 0; i < p->count; i++)
        vtu_int(&a, (int64_t)i);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Float64", "radius", 1);
    for (size_t i = 0; i < p->count; i++)
        vtu_double(&a, p->disks[i].r);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Float64", "packing_radius", 1);
    for (size_t i = 0; i < p->count; i++)
        vtu_double(&a, p->disks[i].R);
    vtu_close_array(&a);
    if (result->has_cells) {
        const gp_cells *c = &result->cells;
        a = vtu_open_array(o, "Float64", "area", 1);
        for (size_t i = 0; i < c->count; i++)
            vtu_double(&a, c->area[i]);
        vtu_close_array(&a);
        a = vtu_open_array(o, "Int32", "neighbours", 1);
        for (size_t i = 0; i < c->count; i++)
            vtu_int(&a, (int64_t)(c->nstart[i + 1] - c->nstart[i]));
        vtu_close_array(&a);
    }
    if (result->has_balance) {
        a = vtu_open_array(o, "Float64", "F", 1);
        for (size_t i = 0; i < p->count; i++)
            vtu_double(&a, isnan(result->balance.F[i]) ? VTU_NO_QUALITY : result->balance.F[i]);
        vtu_close_array(&a);
    }
}

static int write_grains(gp_out *o, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    if (result->has_cells) {
        const gp_cells *c = &result->cells;
        size_t nv = c->start[c->count];
        vtu_header(o, nv, c->count);
        points(o, c->xy, 2, nv);
        vtu_array a = vtu_open_array(o, "Int64", "connectivity", 1);
        for (size_t k = 0; k < nv; k++)
            vtu_int(&a, (int64_t)k);
        vtu_close_array(&a);
        a = vtu_open_array(o, "Int64", "offsets", 1);
        for (size_t i = 0; i < c->count; i++)
            vtu_int(&a, (int64_t)c->start[i + 1]);
        vtu_close_array(&a);
        a = vtu_open_array(o, "UInt8", "types", 1);
        for (size_t i = 0; i < c->count; i++)
            vtu_int(&a, VTK_POLYGON);
        vtu_close_array(&a);
        gp_out_puts(o, "</Cells>\n<CellData Scalars=\"radius\">\n");
        grain_arrays(o, result);
        gp_out_puts(o, "</CellData>\n");
        return vtu_footer(o);
    }
    vtu_header(o, p->count, p->count);
    points(o, p->count ? &p->disks[0].x : NULL, sizeof(gp_disk) / sizeof(double), p->count);
    vtu_array a = vtu_open_array(o, "Int64", "connectivity", 1);
    for (size_t i = 0; i < p->count; i++)
        vtu_int(&a, (int64_t)i);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int64", "offsets", 1);
    for (size_t i = 0; i < p->count; i++)
        vtu_int(&a, (int64_t)i + 1);
    vtu_close_array(&a);
    a = vtu_open_array(o, "UInt8", "types", 1);
    for (size_t i = 0; i < p->count; i++)
        vtu_int(&a, VTK_VERTEX);
    vtu_close_array(&a);
    gp_out_puts(o, "</Cells>\n<PointData Scalars=\"radius\">\n");
    grain_arrays(o, result);
    gp_out_puts(o, "</PointData>\n");
    return vtu_footer(o);
}

int gp_write_vtu(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    (void)spec;
    int checked = gp_mesh_result_check(result, GP_FORMAT_VTU, NULL);
    if (checked)
        return checked;
    return result->has_mesh ? write_mesh(o, result) : write_grains(o, result);
}
