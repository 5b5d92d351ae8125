/* io_format.c - result format names, media types and dispatch. */
#include <string.h>

#include "grainpack/io.h"

static const struct {
    const char *name, *media_type;
} formats[] = {
    [GP_FORMAT_JSON] = {"json", "application/json"},
    [GP_FORMAT_CSV] = {"csv", "text/csv; charset=utf-8"},
    [GP_FORMAT_SVG] = {"svg", "image/svg+xml"},
    /* legacy VTK has no registered media type; this is the one in common use */
    [GP_FORMAT_VTK] = {"vtk", "application/x-vtk"},
};

int gp_format_parse(const char *name, gp_format *out)
{
    for (size_t i = 0; i < gp_format_count(); i++) {
        if (strcmp(name, formats[i].name) == 0) {
            *out = (gp_format)i;
            return 0;
        }
    }
    return GP_EINVAL;
}

size_t gp_format_count(void)
{
    return sizeof formats / sizeof formats[0];
}

const char *gp_format_name(gp_format format)
{
    return formats[format].name;
}

const char *gp_format_media_type(gp_format format)
{
    return formats[format].media_type;
}

int gp_write_result(FILE *out, gp_format format, const gp_spec *spec, const gp_result *result)
{
    switch (format) {
    case GP_FORMAT_JSON: return gp_write_json(out, spec, result);
    case GP_FORMAT_CSV: return gp_write_csv(out, result);
    case GP_FORMAT_SVG: return gp_write_svg(out, spec, result);
    case GP_FORMAT_VTK: return gp_write_vtk(out, spec, result);
    }
    return GP_EINVAL;
}
