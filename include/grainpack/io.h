/* io.h - writers for a job's result: CSV (one line per disk), JSON (disks, cells and
 * statistics), SVG (a picture of the grains and their boundaries), VTK (legacy polydata
 * for ParaView). Writers are deterministic: the same result gives the same bytes. */
#ifndef GRAINPACK_IO_H
#define GRAINPACK_IO_H

#include <stdio.h>

#include "grainpack/api.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_format {
    GP_FORMAT_JSON = 0,
    GP_FORMAT_CSV,
    GP_FORMAT_SVG,
    GP_FORMAT_VTK
} gp_format;

/* Maps "json", "csv", "svg" or "vtk" to a format; returns 0 or GP_EINVAL. */
GP_API int gp_format_parse(const char *name, gp_format *out);
GP_API const char *gp_format_name(gp_format format);
/* How many formats there are: every value from 0 to gp_format_count() - 1 is a format,
 * so a caller can list them without knowing their names (the service does). */
GP_API size_t gp_format_count(void);
/* The media type to serve the format with ("text/csv; charset=utf-8", ...). */
GP_API const char *gp_format_media_type(gp_format format);

/* Each writer returns 0, or GP_EIO when the stream reports an error (GP_ENOMEM when a
 * JSON value cannot be built). Numbers are written with 17 significant digits where they
 * describe geometry, so a reader gets the exact doubles back. */
GP_API int gp_write_csv(FILE *out, const gp_result *result);
GP_API int gp_write_json(FILE *out, const gp_spec *spec, const gp_result *result);
GP_API int gp_write_svg(FILE *out, const gp_spec *spec, const gp_result *result);
GP_API int gp_write_vtk(FILE *out, const gp_spec *spec, const gp_result *result);
GP_API int gp_write_result(FILE *out, gp_format format, const gp_spec *spec,
                           const gp_result *result);

#ifdef __cplusplus
}
#endif
#endif
