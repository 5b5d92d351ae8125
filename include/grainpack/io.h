/* io.h - writers for a job's result: CSV (one line per disk), JSON (disks, cells and
 * statistics), SVG (a picture of the grains and their boundaries), VTK (legacy polydata
 * for ParaView). Writers are deterministic: the same result gives the same bytes. */
#ifndef GRAINPACK_IO_H
#define GRAINPACK_IO_H

#include <jansson.h>
#include <stdio.h>

#include "grainpack/pipeline.h"
#include "grainpack/spec.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_format {
    GP_FORMAT_JSON = 0,
    GP_FORMAT_CSV,
    GP_FORMAT_SVG,
    GP_FORMAT_VTK,
    GP_FORMAT_MSH, /* the mesh: Gmsh MSH 4.1 (io_mesh.h) */
    GP_FORMAT_INP, /* the mesh: Abaqus input */
    GP_FORMAT_VTU  /* the mesh, or the grains without one: VTK XML unstructured grid */
} gp_format;

/* Maps "json", "csv", "svg", "vtk", "msh", "inp" or "vtu" to a format; returns 0 or
 * GP_EINVAL. */
int gp_format_parse(const char *name, gp_format *out);
const char *gp_format_name(gp_format format);
/* How many formats there are: every value from 0 to gp_format_count() - 1 is a format,
 * so a caller can list them without knowing their names (the service does). */
size_t gp_format_count(void);
/* The media type to serve the format with ("text/csv; charset=utf-8", ...). */
const char *gp_format_media_type(gp_format format);

/* The statistics of a result as a new JSON object (caller owns the reference; NULL when
 * out of memory): count, densities, radii, the per-bin target-versus-achieved table with
 * chi-square, and how the front went. Timings are not included (they are not
 * reproducible); the caller adds them where it wants them. */
json_t *gp_statistics_json(const gp_spec *spec, const gp_result *result);

/* Each writer returns 0, or GP_EIO when the stream reports an error (GP_ENOMEM when a
 * JSON value cannot be built). Numbers are written with 17 significant digits where they
 * describe geometry, so a reader gets the exact doubles back. */
int gp_write_csv(FILE *out, const gp_result *result);
int gp_write_json(FILE *out, const gp_spec *spec, const gp_result *result);
int gp_write_svg(FILE *out, const gp_spec *spec, const gp_result *result);
int gp_write_vtk(FILE *out, const gp_spec *spec, const gp_result *result);
/* Writes the result in `format`; GP_EINVAL for msh and inp when the job has no mesh
 * (gp_format_needs_mesh). */
int gp_write_result(FILE *out, gp_format format, const gp_spec *spec, const gp_result *result);

/* Whether the format exists only for jobs with a mesh (msh, inp). */
int gp_format_needs_mesh(gp_format format);

#ifdef __cplusplus
}
#endif
#endif
