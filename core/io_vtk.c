/* io_vtk.c - the result as VTK legacy polydata (ASCII), which ParaView and VTK read: the
 * Laguerre cells as polygons with the grain id, radii, area and neighbour count as cell
 * data, or, without cells, the disk centres as vertices with the same per-grain data. */
#include <math.h>

#include "grainpack/io.h"

/* F where it is not defined (centres on the convex hull or along the walls): legacy VTK
 * readers do not parse "nan", and F >= 0 otherwise. */
#define VTK_NO_QUALITY (-1.0)

static void write_scalars_header(FILE *out, const char *name, const char *type)
{
    fprintf(out, "SCALARS %s %s 1\nLOOKUP_TABLE default\n", name, type);
}

/* The per-grain arrays, in grain order, as CELL_DATA or POINT_DATA. */
static void write_grain_data(FILE *out, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    write_scalars_header(out, "grain_id", "int");
    for (size_t i = 0; i < p->count; i++)
        fprintf(out, "%zu\n", i);
    write_scalars_header(out, "radius", "double");
    for (size_t i = 0; i < p->count; i++)
        fprintf(out, "%.17g\n", p->disks[i].r);
    write_scalars_header(out, "packing_radius", "double");
    for (size_t i = 0; i < p->count; i++)
        fprintf(out, "%.17g\n", p->disks[i].R);
    if (result->has_cells) {
        const gp_cells *c = &result->cells;
        write_scalars_header(out, "area", "double");
        for (size_t i = 0; i < c->count; i++)
            fprintf(out, "%.17g\n", c->area[i]);
        write_scalars_header(out, "neighbours", "int");
        for (size_t i = 0; i < c->count; i++)
            fprintf(out, "%zu\n", c->nstart[i + 1] - c->nstart[i]);
    }
    if (result->has_balance) {
        write_scalars_header(out, "F", "double");
        for (size_t i = 0; i < p->count; i++) {
            double F = result->balance.F[i];
            fprintf(out, "%.17g\n", isnan(F) ? VTK_NO_QUALITY : F);
        }
    }
}

int gp_write_vtk(FILE *out, const gp_spec *spec, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    fprintf(out, "# vtk DataFile Version 3.0\ngrainpack %s: %zu grains in %.17g x %.17g, seed %llu\n"
                 "ASCII\nDATASET POLYDATA\n",
            result->has_cells ? "cells" : "disks", p->count, spec->domain.width,
            spec->domain.height, (unsigned long long)spec->seed);
    if (result->has_cells) {
        const gp_cells *c = &result->cells;
        size_t nv = c->start[c->count];
        fprintf(out, "POINTS %zu double\n", nv);
        for (size_t k = 0; k < nv; k++)
            fprintf(out, "%.17g %.17g 0\n", c->xy[2 * k], c->xy[2 * k + 1]);
        fprintf(out, "POLYGONS %zu %zu\n", c->count, c->count + nv);
        for (size_t i = 0; i < c->count; i++) {
            fprintf(out, "%zu", c->start[i + 1] - c->start[i]);
            for (size_t k = c->start[i]; k < c->start[i + 1]; k++)
                fprintf(out, " %zu", k);
            fputc('\n', out);
        }
        fprintf(out, "CELL_DATA %zu\n", c->count);
    } else {
        fprintf(out, "POINTS %zu double\n", p->count);
        for (size_t i = 0; i < p->count; i++)
            fprintf(out, "%.17g %.17g 0\n", p->disks[i].x, p->disks[i].y);
        fprintf(out, "VERTICES %zu %zu\n", p->count, 2 * p->count);
        for (size_t i = 0; i < p->count; i++)
            fprintf(out, "1 %zu\n", i);
        fprintf(out, "POINT_DATA %zu\n", p->count);
    }
    write_grain_data(out, result);
    return ferror(out) ? GP_EIO : 0;
}
