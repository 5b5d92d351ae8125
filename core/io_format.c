/* io_format.c - result format names and media types. */
#include <string.h>

#include "grainpack/io.h"
#include "grainpack/io_mesh.h"

static const struct {
    const char *name, *media_type;
    int text;
} formats[] = {
    [GP_FORMAT_JSON] = {"json", "application/json", 1},
    [GP_FORMAT_CSV] = {"csv", "text/csv; charset=utf-8", 1},
    [GP_FORMAT_SVG] = {"svg", "image/svg+xml", 1},
    /* legacy VTK has no registered media type; this is the one in common use */
    [GP_FORMAT_VTK] = {"vtk", "application/x-vtk", 1},
    /* none of the three has a registered media type: these are the descriptive x- ones */
    [GP_FORMAT_MSH] = {"msh", "text/x-gmsh; charset=utf-8", 1},
    [GP_FORMAT_INP] = {"inp", "text/x-abaqus-input; charset=utf-8", 1},
    [GP_FORMAT_VTU] = {"vtu", "application/x-vtu+xml", 1},
    /* Neper's tessellation has none either; not text/plain, which would win a 2D job's
       "Accept: text/plain" for a format it does not have */
    [GP_FORMAT_TESS] = {"tess", "text/x-neper-tess; charset=utf-8", 1},
};

int gp_format_needs_mesh(gp_format format)
{
    return format == GP_FORMAT_MSH || format == GP_FORMAT_INP;
}

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

int gp_format_is_text(gp_format format)
{
    return formats[format].text;
}
