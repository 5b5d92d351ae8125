/* vtu_array.h - the pieces of a VTK XML unstructured grid (ASCII) that the 2D (io_vtu.c)
 * and 3D (io_vtu3d.c) writers share (internal to core/). */
#ifndef GRAINPACK_CORE_VTU_ARRAY_H
#define GRAINPACK_CORE_VTU_ARRAY_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/out.h"

/* Values on one line of a data array: short lines for a person, few bytes for a machine. */
#define VTU_PER_LINE 9

/* F where it is not defined (see io_vtk.c): VTK's ASCII reader does not parse "nan". */
#define VTU_NO_QUALITY (-1.0)

/* A data array being written: its sink and how many values it has. */
typedef struct vtu_array {
    gp_out *o;
    size_t n;
} vtu_array;

/* <DataArray type name (NumberOfComponents) format="ascii">. */
vtu_array vtu_open_array(gp_out *o, const char *type, const char *name, int components);
void vtu_double(vtu_array *a, double x);
void vtu_int(vtu_array *a, int64_t v);
void vtu_close_array(vtu_array *a);
/* The file's head up to <Points> (one Piece of `points` points and `cells` cells). */
void vtu_header(gp_out *o, size_t points, size_t cells);
/* Closes the Piece and the file and flushes: returns out's error. */
int vtu_footer(gp_out *o);

#endif
