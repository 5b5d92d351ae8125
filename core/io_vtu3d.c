/* io_vtu3d.c - the 3D result as a VTK XML unstructured grid (ASCII): the Laguerre
 * polyhedra as VTK_POLYHEDRON cells, or without cells the sphere centres as vertices,
 * with the grains' data on the cells. ParaView, VTK and meshio read it. */
#include <math.h>

#include "grainpack/io3d.h"
#include "vtu_array.h"

/* VTK cell types (vtkCellType.h). */
#define VTK_VERTEX 1
#define VTK_POLYHEDRON 42

/* The Cells element of the polyhedra: connectivity = each cell's own vertices; "faces" =
 * per cell its face count then each face's size and point ids, "faceoffsets" = where
 * each cell's stream ends in "faces" (VTK's polyhedron layout before VTK 9.4, which 9.4
 * still reads). */
static void polyhedra(gp_out *o, const gp_cells3d *c)
{
    vtu_array a = vtu_open_array(o, "Int64", "connectivity", 1);
    for (size_t k = 0; k < c->vstart[c->count]; k++)
        vtu_int(&a, (int64_t)k);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int64", "offsets", 1);
    for (size_t i = 0; i < c->count; i++)
        vtu_int(&a, (int64_t)c->vstart[i + 1]);
    vtu_close_array(&a);
    a = vtu_open_array(o, "UInt8", "types", 1);
    for (size_t i = 0; i < c->count; i++)
        vtu_int(&a, VTK_POLYHEDRON);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int64", "faces", 1);
    for (size_t i = 0; i < c->count; i++) {
        vtu_int(&a, (int64_t)(c->fstart[i + 1] - c->fstart[i]));
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
            vtu_int(&a, (int64_t)(c->fvstart[f + 1] - c->fvstart[f]));
            for (size_t k = c->fvstart[f]; k < c->fvstart[f + 1]; k++)
                vtu_int(&a, (int64_t)(c->vstart[i] + c->fverts[k]));
        }
    }
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int64", "faceoffsets", 1);
    int64_t end = 0;
    for (size_t i = 0; i < c->count; i++) {
        end += 1;
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++)
            end += 1 + (int64_t)(c->fvstart[f + 1] - c->fvstart[f]);
        vtu_int(&a, end);
    }
    vtu_close_array(&a);
}

static void vertices(gp_out *o, size_t n)
{
    vtu_array a = vtu_open_array(o, "Int64", "connectivity", 1);
    for (size_t i = 0; i < n; i++)
        vtu_int(&a, (int64_t)i);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Int64", "offsets", 1);
    for (size_t i = 0; i < n; i++)
        vtu_int(&a, (int64_t)i + 1);
    vtu_close_array(&a);
    a = vtu_open_array(o, "UInt8", "types", 1);
    for (size_t i = 0; i < n; i++)
        vtu_int(&a, VTK_VERTEX);
    vtu_close_array(&a);
}

int gp_write_vtu3d(gp_out *o, const gp_result3d *result)
{
    const gp_packing3d *pk = &result->packing;
    const gp_cells3d *c = result->has_cells ? &result->cells : NULL;
    size_t n = pk->count, points = c ? c->vstart[c->count] : n;
    vtu_header(o, points, n);
    vtu_array a = vtu_open_array(o, "Float64", "Points", 3);
    for (size_t k = 0; k < points; k++) {
        if (c) {
            for (int d = 0; d < 3; d++)
                vtu_double(&a, c->xyz[3 * k + (size_t)d]);
        } else {
            vtu_double(&a, pk->spheres[k].x);
            vtu_double(&a, pk->spheres[k].y);
            vtu_double(&a, pk->spheres[k].z);
        }
    }
    vtu_close_array(&a);
    gp_out_puts(o, "</Points>\n<Cells>\n");
    if (c)
        polyhedra(o, c);
    else
        vertices(o, n);
    gp_out_puts(o, "</Cells>\n<CellData Scalars=\"grain\">\n");
    a = vtu_open_array(o, "Int32", "grain", 1);
    for (size_t i = 0; i < n; i++)
        vtu_int(&a, (int64_t)i);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Float64", "r", 1);
    for (size_t i = 0; i < n; i++)
        vtu_double(&a, pk->spheres[i].r);
    vtu_close_array(&a);
    a = vtu_open_array(o, "Float64", "R", 1);
    for (size_t i = 0; i < n; i++)
        vtu_double(&a, pk->spheres[i].R);
    vtu_close_array(&a);
    if (c) {
        a = vtu_open_array(o, "Float64", "volume", 1);
        for (size_t i = 0; i < n; i++)
            vtu_double(&a, c->volume[i]);
        vtu_close_array(&a);
    }
    if (result->has_balance) {
        a = vtu_open_array(o, "Float64", "F", 1);
        for (size_t i = 0; i < n; i++)
            vtu_double(&a, isnan(result->balance.F[i]) ? VTU_NO_QUALITY : result->balance.F[i]);
        vtu_close_array(&a);
    }
    gp_out_puts(o, "</CellData>\n");
    return vtu_footer(o);
}
