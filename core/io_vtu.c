/* io_vtu.c - the result as a VTK XML unstructured grid (ASCII), which ParaView, VTK and
 * meshio read: the mesh with its cell data, or without a mesh the grains themselves
 * (cells as polygons, or disk centres as vertices). */
#include <math.h>

#include "grainpack/io_mesh.h"
#include "writer.h"

/* VTK cell types (vtkCellType.h). */
#define VTK_VERTEX 1
#define VTK_TRIANGLE 5
#define VTK_POLYGON 7
#define VTK_QUAD 9
#define VTK_QUADRATIC_TRIANGLE 22
#define VTK_QUADRATIC_QUAD 23
/* F where it is not defined (see io_vtk.c): VTK's ASCII reader does not parse "nan". */
#define VTU_NO_QUALITY (-1.0)
/* Values on one line of a data array: short lines for a person, few bytes for a machine. */
#define VTU_PER_LINE 9

typedef struct array {
    gp_out *o;
    size_t n;
} array;

static array open_array(gp_out *o, const char *type, const char *name, int components)
{
    gp_out_puts(o, "<DataArray type=\"");
    gp_out_puts(o, type);
    gp_out_puts(o, "\" Name=\"");
    gp_out_puts(o, name);
    gp_out_puts(o, "\"");
    if (components > 1) {
        gp_out_puts(o, " NumberOfComponents=\"");
        gp_out_int(o, components);
        gp_out_puts(o, "\"");
    }
    gp_out_puts(o, " format=\"ascii\">\n");
    return (array){o, 0};
}

static void sep(array *a)
{
    if (a->n++)
        gp_out_char(a->o, a->n % VTU_PER_LINE == 1 ? '\n' : ' ');
}

static void put_double(array *a, double x)
{
    sep(a);
    gp_out_double(a->o, x);
}

static void put_int(array *a, int64_t v)
{
    sep(a);
    gp_out_int(a->o, v);
}

static void close_array(array *a)
{
    gp_out_puts(a->o, "\n</DataArray>\n");
}

static void header(gp_out *o, size_t points, size_t cells)
{
    gp_out_puts(o, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
                   "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n"
                   "<Piece NumberOfPoints=\"");
    gp_out_uint(o, points);
    gp_out_puts(o, "\" NumberOfCells=\"");
    gp_out_uint(o, cells);
    gp_out_puts(o, "\">\n<Points>\n");
}

static void points(gp_out *o, const double *xy, size_t stride, size_t n)
{
    array a = open_array(o, "Float64", "Points", 3);
    for (size_t k = 0; k < n; k++) {
        put_double(&a, xy[stride * k]);
        put_double(&a, xy[stride * k + 1]);
        put_int(&a, 0);
    }
    close_array(&a);
    gp_out_puts(o, "</Points>\n<Cells>\n");
}

static int footer(gp_out *o)
{
    gp_out_puts(o, "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    return gp_out_flush(o);
}

static int write_mesh(gp_out *o, const gp_result *result)
{
    const gp_mesh *m = &result->mesh;
    size_t cells = m->ntri + m->nquad;
    int tn = gp_mesh_tri_nodes(m->order), qn = gp_mesh_quad_nodes(m->order);
    header(o, m->nnodes, cells);
    points(o, m->xy, 2, m->nnodes);
    array a = open_array(o, "Int64", "connectivity", 1);
    for (size_t k = 0; k < (size_t)tn * m->ntri; k++)
        put_int(&a, m->tri[k]);
    for (size_t k = 0; k < (size_t)qn * m->nquad; k++)
        put_int(&a, m->quad[k]);
    close_array(&a);
    a = open_array(o, "Int64", "offsets", 1);
    for (size_t e = 0; e < cells; e++)
        put_int(&a, e < m->ntri ? (int64_t)(tn * (e + 1))
                                : (int64_t)(tn * m->ntri + qn * (e + 1 - m->ntri)));
    close_array(&a);
    a = open_array(o, "UInt8", "types", 1);
    for (size_t e = 0; e < cells; e++)
        put_int(&a, e < m->ntri ? (m->order == 2 ? VTK_QUADRATIC_TRIANGLE : VTK_TRIANGLE)
                                : (m->order == 2 ? VTK_QUADRATIC_QUAD : VTK_QUAD));
    close_array(&a);
    gp_out_puts(o, "</Cells>\n<CellData Scalars=\"region\">\n");
    a = open_array(o, "Int32", "region", 1);
    for (size_t e = 0; e < cells; e++)
        put_int(&a, e < m->ntri ? m->tri_region[e] : m->quad_region[e - m->ntri]);
    close_array(&a);
    a = open_array(o, "Int32", "phase", 1);
    for (size_t e = 0; e < cells; e++)
        put_int(&a, gp_mesh_region_phase(m, e < m->ntri ? m->tri_region[e] : m->quad_region[e - m->ntri]));
    close_array(&a);
    a = open_array(o, "Float64", "grain_radius", 1);
    for (size_t e = 0; e < cells; e++) {
        int32_t r = e < m->ntri ? m->tri_region[e] : m->quad_region[e - m->ntri];
        put_double(&a, (size_t)r < m->ngrains ? result->packing.disks[r].r : 0.0);
    }
    close_array(&a);
    a = open_array(o, "Float64", "quality", 1);
    for (size_t e = 0; e < cells; e++)
        put_double(&a, e < m->ntri ? gp_mesh_element_quality(m, 0, e)
                                   : gp_mesh_element_quality(m, 1, e - m->ntri));
    close_array(&a);
    gp_out_puts(o, "</CellData>\n");
    return footer(o);
}

/* The per-grain arrays, in grain order: cell data of polygons or point data of vertices. */
static void grain_arrays(gp_out *o, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    array a = open_array(o, "Int64", "grain_id", 1);
    for (size_t i = 0; i < p->count; i++)
        put_int(&a, (int64_t)i);
    close_array(&a);
    a = open_array(o, "Float64", "radius", 1);
    for (size_t i = 0; i < p->count; i++)
        put_double(&a, p->disks[i].r);
    close_array(&a);
    a = open_array(o, "Float64", "packing_radius", 1);
    for (size_t i = 0; i < p->count; i++)
        put_double(&a, p->disks[i].R);
    close_array(&a);
    if (result->has_cells) {
        const gp_cells *c = &result->cells;
        a = open_array(o, "Float64", "area", 1);
        for (size_t i = 0; i < c->count; i++)
            put_double(&a, c->area[i]);
        close_array(&a);
        a = open_array(o, "Int32", "neighbours", 1);
        for (size_t i = 0; i < c->count; i++)
            put_int(&a, (int64_t)(c->nstart[i + 1] - c->nstart[i]));
        close_array(&a);
    }
    if (result->has_balance) {
        a = open_array(o, "Float64", "F", 1);
        for (size_t i = 0; i < p->count; i++)
            put_double(&a, isnan(result->balance.F[i]) ? VTU_NO_QUALITY : result->balance.F[i]);
        close_array(&a);
    }
}

static int write_grains(gp_out *o, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    if (result->has_cells) {
        const gp_cells *c = &result->cells;
        size_t nv = c->start[c->count];
        header(o, nv, c->count);
        points(o, c->xy, 2, nv);
        array a = open_array(o, "Int64", "connectivity", 1);
        for (size_t k = 0; k < nv; k++)
            put_int(&a, (int64_t)k);
        close_array(&a);
        a = open_array(o, "Int64", "offsets", 1);
        for (size_t i = 0; i < c->count; i++)
            put_int(&a, (int64_t)c->start[i + 1]);
        close_array(&a);
        a = open_array(o, "UInt8", "types", 1);
        for (size_t i = 0; i < c->count; i++)
            put_int(&a, VTK_POLYGON);
        close_array(&a);
        gp_out_puts(o, "</Cells>\n<CellData Scalars=\"radius\">\n");
        grain_arrays(o, result);
        gp_out_puts(o, "</CellData>\n");
        return footer(o);
    }
    header(o, p->count, p->count);
    points(o, p->count ? &p->disks[0].x : NULL, sizeof(gp_disk) / sizeof(double), p->count);
    array a = open_array(o, "Int64", "connectivity", 1);
    for (size_t i = 0; i < p->count; i++)
        put_int(&a, (int64_t)i);
    close_array(&a);
    a = open_array(o, "Int64", "offsets", 1);
    for (size_t i = 0; i < p->count; i++)
        put_int(&a, (int64_t)i + 1);
    close_array(&a);
    a = open_array(o, "UInt8", "types", 1);
    for (size_t i = 0; i < p->count; i++)
        put_int(&a, VTK_VERTEX);
    close_array(&a);
    gp_out_puts(o, "</Cells>\n<PointData Scalars=\"radius\">\n");
    grain_arrays(o, result);
    gp_out_puts(o, "</PointData>\n");
    return footer(o);
}

int gp_write_vtu(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    (void)spec;
    int checked = gp_mesh_result_check(result, GP_FORMAT_VTU, NULL);
    if (checked)
        return checked;
    return result->has_mesh ? write_mesh(o, result) : write_grains(o, result);
}
