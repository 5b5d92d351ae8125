/* io_format3d.c - the 3D formats by name, what each needs of a result, and the one entry
 * that writes a result in any of them. */
#include <stdlib.h>
#include <string.h>

#include "grainpack/io3d.h"

static const struct {
    const char *name, *media_type;
} FORMATS[] = {
    [GP_FORMAT3D_CSV] = {"csv", "text/csv; charset=utf-8"},
    [GP_FORMAT3D_JSON] = {"json", "application/json"},
    [GP_FORMAT3D_VTU] = {"vtu", "application/xml"},
    [GP_FORMAT3D_TESS] = {"tess", "text/plain; charset=utf-8"},
    [GP_FORMAT3D_SVG] = {"svg", "image/svg+xml"},
};
#define NFORMATS (sizeof FORMATS / sizeof FORMATS[0])

int gp_format3d_parse(const char *name, gp_format3d *out)
{
    for (size_t i = 0; i < NFORMATS; i++)
        if (strcmp(name, FORMATS[i].name) == 0) {
            *out = (gp_format3d)i;
            return 0;
        }
    return GP_EINVAL;
}

const char *gp_format3d_name(gp_format3d format)
{
    return (size_t)format < NFORMATS ? FORMATS[format].name : "unknown";
}

size_t gp_format3d_count(void)
{
    return NFORMATS;
}

const char *gp_format3d_media_type(gp_format3d format)
{
    return (size_t)format < NFORMATS ? FORMATS[format].media_type : "application/octet-stream";
}

int gp_format3d_check(gp_format3d format, const gp_result3d *result, gp_error *err)
{
    if ((size_t)format >= NFORMATS)
        return gp_error_set(err, GP_EINVAL, NULL, "unknown format");
    if (format == GP_FORMAT3D_TESS && !result->has_cells)
        return gp_error_set(err, GP_EINVAL, NULL,
                            "tess is the Laguerre tessellation: the spec must ask for cells "
                            "(\"cells\": {...})");
    return 0;
}

/* Frees what gp_result3d_power_cells made (every array of a gp_cells3d is owned). */
static void free_power(gp_cells3d *c)
{
    free(c->vstart);
    free(c->xyz);
    free(c->fstart);
    free(c->fvstart);
    free(c->fverts);
    free(c->fneighbour);
    free(c->volume);
}

static int write_tess(gp_out *out, const gp_spec3d *spec, const gp_result3d *result, gp_error *err)
{
    if (result->cells.shrink == GP_SHRINK_NONE)
        return gp_write_tess(out, &spec->box, result->packing.spheres, &result->cells, err);
    gp_cells3d power;
    int rc = gp_result3d_power_cells(spec, result, &power, err);
    if (rc)
        return rc;
    rc = gp_write_tess(out, &spec->box, result->packing.spheres, &power, err);
    free_power(&power);
    return rc;
}

int gp_write_result3d(gp_out *out, gp_format3d format, const gp_spec3d *spec, const gp_result3d *result,
                      gp_error *err)
{
    int rc = gp_format3d_check(format, result, err);
    if (rc)
        return rc;
    switch (format) {
    case GP_FORMAT3D_CSV: return gp_write_spheres_csv(out, &result->packing);
    case GP_FORMAT3D_JSON: return gp_write_json3d(out, spec, result);
    case GP_FORMAT3D_VTU: return gp_write_vtu3d(out, result);
    case GP_FORMAT3D_TESS: return write_tess(out, spec, result, err);
    case GP_FORMAT3D_SVG: return gp_write_section_svg(out, spec, result);
    }
    return GP_EINVAL;
}
