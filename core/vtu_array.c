/* vtu_array.c - the pieces of a VTK XML unstructured grid (ASCII) that the 2D and 3D
 * writers share: the file's head and tail, and data arrays a few values a line. */
#include "vtu_array.h"

vtu_array vtu_open_array(gp_out *o, const char *type, const char *name, int components)
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
    return (vtu_array){o, 0};
}

static void sep(vtu_array *a)
{
    if (a->n++)
        gp_out_char(a->o, a->n % VTU_PER_LINE == 1 ? '\n' : ' ');
}

void vtu_double(vtu_array *a, double x)
{
    sep(a);
    gp_out_double(a->o, x);
}

void vtu_int(vtu_array *a, int64_t v)
{
    sep(a);
    gp_out_int(a->o, v);
}

void vtu_close_array(vtu_array *a)
{
    gp_out_puts(a->o, "\n</DataArray>\n");
}

void vtu_header(gp_out *o, size_t points, size_t cells)
{
    gp_out_puts(o, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
                   "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n"
                   "<Piece NumberOfPoints=\"");
    gp_out_uint(o, points);
    gp_out_puts(o, "\" NumberOfCells=\"");
    gp_out_uint(o, cells);
    gp_out_puts(o, "\">\n<Points>\n");
}

int vtu_footer(gp_out *o)
{
    gp_out_puts(o, "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    return gp_out_flush(o);
}

