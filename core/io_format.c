/* io_format.c - result format names, media types and dispatch. */
#include <string.h>

#include "grainpack/io.h"
#include "grainpack/io_mesh.h"

static const struct {
    const char *name, *media_type;
} formats[] = {
    [GP_FORMAT_JSON] = {"json", "application/json"},
    [GP_FORMAT_CSV] = {"csv", "text/csv; charset=utf-8"},
    [GP_FORMAT_SVG] = {"svg", "image/svg+xml"},
    /* legacy VTK has no registered media type; this is the one in common use */
    [GP_FORMAT_VTK] = {"vtk", "application/x-vtk"},
    /* none of the three has a registered media type: these are the descriptive x- ones */
    [GP_FORMAT_MSH] = {"msh", "text/x-gmsh; charset=utf-8"},
    [GP_FORMAT_INP] = {"inp", "text/x-abaqus-input; charset=utf-8"},
    [GP_FORMAT_VTU] = {"vtu", "application/x-vtu+xml"},
};

int gp_format_needs_mesh(gp_format format)
{
    return format == GP_FORMAT_MSH || format == GP_FORMAT_INP;
}

/* A gp_out writer on a FILE. */
static int write_out(FILE *out, int (*writer)(gp_out *, const gp_spec *, const gp_result *),
                     const gp_spec *spec, const gp_result *result)
{
    gp_out o;
    if (gp_out_init_file(&o, out))
        return GP_ENOMEM;
    int rc = writer(&o, spec, result);
    if (rc == 0)
        rc = gp_out_flush(&o);
    gp_out_free(&o);
    return rc;
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

int gp_write_result(FILE *out, gp_format format, const gp_spec *spec, const gp_result *result)
{
    switch (format) {
    case GP_FORMAT_JSON: return gp_write_json(out, spec, result);
    case GP_FORMAT_CSV: return gp_write_csv(out, result);
    case GP_FORMAT_SVG: return gp_write_svg(out, spec, result);
    case GP_FORMAT_VTK: return gp_write_vtk(out, spec, result);
    case GP_FORMAT_MSH: return write_out(out, gp_write_msh, spec, result);
    case GP_FORMAT_INP: return write_out(out, gp_write_inp, spec, result);
    case GP_FORMAT_VTU: return write_out(out, gp_write_vtu, spec, result);
    }
    return GP_EINVAL;
}
