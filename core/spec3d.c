/* spec3d.c - the 3D process's spec (spec3d.h): the box, and the law, joint and seed read
 * by the same parts as the 2D spec's (spec_parts.h). */
#include "grainpack/spec3d.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spec_parts.h"

/* Packing density of the estimate of the sphere count: random close packing, a little
 * above the 0.58-0.61 the front reaches (docs/3d.md §6), so that it errs on the high side. */
#define EXPECTED_FILL 0.64

/* The inputs object of root ({"inputs": {...}} or bare) and its pointer, or NULL. */
static const json_t *inputs_of(const json_t *root, const char **base)
{
    const json_t *wrapped = json_object_get(root, "inputs");
    *base = wrapped ? "/inputs" : "";
    return wrapped ? wrapped : root;
}

gp_process gp_spec_process(const char *text, size_t len)
{
    json_error_t jerr;
    json_t *root = json_loadb(text, len, JSON_DECODE_ANY, &jerr);
    gp_process process = GP_PROCESS_PACK2D;
    if (root && json_is_object(root)) {
        const char *base;
        const json_t *inputs = inputs_of(root, &base);
        const json_t *domain = json_is_object(inputs) ? json_object_get(inputs, "domain") : NULL;
        if (json_is_object(domain) && json_object_get(domain, "depth"))
            process = GP_PROCESS_PACK3D;
    }
    json_decref(root);
    return process;
}

static int parse_box(validator *v, const json_t *inputs, const char *base, gp_box *box)
{
    char ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "domain", 1, &obj, ptr);
    if (rc)
        return rc;
    static const char *const members[] = {"width", "height", "depth", "periodic", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "width, height, depth, periodic")))
        return rc;
    if ((rc = spec_get_number(v, obj, ptr, "width", 0.0, 0, &box->width)) ||
        (rc = spec_get_number(v, obj, ptr, "height", 0.0, 0, &box->height)) ||
        (rc = spec_get_number(v, obj, ptr, "depth", 0.0, 0, &box->depth)))
        return rc;
    return spec_parse_periodic(v, obj, ptr, 3, &box->periodic);
}

/* "picture": {"section": {"axis": "x" | "y" | "z", "at": [0, 1]}}, both optional. */
static int parse_picture(validator *v, const json_t *inputs, const char *base, gp_section3d *section)
{
    char ptr[GP_ERROR_POINTER_MAX], sptr[GP_ERROR_POINTER_MAX], field[GP_ERROR_POINTER_MAX];
    const json_t *picture, *obj;
    section->axis = GP_SECTION3D_DEFAULT_AXIS;
    section->at = GP_SECTION3D_DEFAULT_AT;
    int rc = spec_get_object(v, inputs, base, "picture", 0, &picture, ptr);
    if (rc || !picture)
        return rc;
    static const char *const members[] = {"section", NULL};
    if ((rc = spec_check_members(v, picture, ptr, members, "section (a 3D picture is a section)")) ||
        (rc = spec_get_object(v, picture, ptr, "section", 0, &obj, sptr)) || !obj)
        return rc;
    static const char *const fields[] = {"axis", "at", NULL};
    if ((rc = spec_check_members(v, obj, sptr, fields, "axis, at")))
        return rc;
    const json_t *axis = json_object_get(obj, "axis"), *at = json_object_get(obj, "at");
    if (axis) {
        const char *name = json_string_value(axis);
        spec_pointer_key(field, sptr, "axis");
        if (!name || strlen(name) != 1 || !strchr("xyz", name[0]))
            return gp_error_set(v->err, GP_EINVAL, field, "must be \"x\", \"y\" or \"z\"");
        section->axis = name[0] - 'x';
    }
    if (at) {
        spec_pointer_key(field, sptr, "at");
        if (!json_is_number(at) || !(json_number_value(at) >= 0.0 && json_number_value(at) <= 1.0))
            return gp_error_set(v->err, GP_EINVAL, field,
                                "must be a number in [0, 1]: the fraction of the box along the axis");
        section->at = json_number_value(at);
    }
    return 0;
}

/* What spans the fields: the stages not yet on periodic boxes, the packer's own check
 * (gp_pack3d_check, its pointer under base), then the cap on the expected spheres. */
static int check_whole(validator *v, const char *base, gp_spec3d *spec)
{
    double r_min, r_max;
    gp_distribution_support(&spec->dist, &r_min, &r_max);
    char ptr[GP_ERROR_POINTER_MAX];
    if (spec->box.periodic && (spec->balance_enabled || spec->laguerre_enabled)) {
        spec_pointer_key(ptr, base, spec->balance_enabled ? "balance" : "laguerre");
        return gp_error_set(v->err, GP_EINVAL, ptr,
                            "is not yet available on periodic boxes (docs/3d.md §11); leave it out, "
                            "or leave out the domain's \"periodic\"");
    }
    if (!(r_max > 0.0)) {
        spec_pointer_key(ptr, base, "distribution");
        return gp_error_set(v->err, GP_EINVAL, ptr, "must give some bin a probability > 0");
    }
    if (gp_pack3d_check(&spec->box, &spec->dist, &spec->joint, v->err)) {
        char relative[32]; /* "/domain/height" or "/distribution" */
        snprintf(relative, sizeof relative, "%.31s", v->err->pointer);
        if (strcmp(relative, "/distribution") == 0 && strstr(v->err->message, "ratio"))
            spec_smallest_radius_pointer(base, &spec->dist, v->err->pointer);
        else
            snprintf(v->err->pointer, sizeof v->err->pointer, "%.16s%s", base, relative); /* base: "" or "/inputs" */
        return GP_EINVAL;
    }
    double volume = spec->box.width * spec->box.height * spec->box.depth;
    spec->expected_spheres = EXPECTED_FILL * volume /
                             (4.0 / 3.0 * M_PI * gp_distribution_packing_moment(&spec->dist, &spec->joint, 3));
    if (!(spec->expected_spheres <= (double)v->max_disks)) {
        spec_pointer_key(ptr, base, "domain");
        return gp_error_set(v->err, GP_ETOOBIG, ptr,
                            "about %.3g spheres expected, more than the limit of %zu; use a smaller "
                            "box or larger grains",
                            spec->expected_spheres, v->max_disks);
    }
    return 0;
}

static int parse_root(validator *v, const json_t *root, void *out)
{
    gp_spec3d *spec = out;
    if (!json_is_object(root))
        return gp_error_set(v->err, GP_EINVAL, "", "must be an object {\"inputs\": {...}}");
    const char *base;
    const json_t *inputs = inputs_of(root, &base);
    int rc;
    if (*base) {
        static const char *const members[] = {"inputs", "outputs", "response", "subscriber", NULL};
        if ((rc = spec_check_members(v, root, "", members, "inputs, outputs, response, subscriber")))
            return rc;
        if (!json_is_object(inputs))
            return gp_error_set(v->err, GP_EINVAL, "/inputs", "must be an object");
    }
    static const char *const members[] = {"domain", "distribution", "joint", "seed", "balance", "laguerre",
                                          "picture", NULL};
    if ((rc = spec_check_members(v, inputs, base, members,
                                 "domain, distribution, joint, seed, balance, laguerre, picture")) ||
        (rc = parse_box(v, inputs, base, &spec->box)) ||
        (rc = spec_parse_distribution(v, inputs, base, &spec->dist)) ||
        (rc = spec_parse_joint(v, inputs, base, &spec->joint)) ||
        (rc = spec_parse_seed(v, inputs, base, &spec->seed)) ||
        (rc = spec_parse_balance(v, inputs, base, &spec->balance_enabled, &spec->balance)) ||
        (rc = spec_parse_laguerre(v, inputs, base, &spec->laguerre_enabled, &spec->laguerre)) ||
        (rc = parse_picture(v, inputs, base, &spec->section)) || (rc = check_whole(v, base, spec)))
        return rc;
    if (gp_distribution_prepare(&spec->dist))
        return gp_error_set(v->err, GP_ENOMEM, "", "out of memory");
    return 0;
}

int gp_spec3d_parse(const char *text, size_t len, const gp_spec_limits *limits, gp_spec3d *spec,
                    gp_error *err)
{
    memset(spec, 0, sizeof *spec);
    int rc = spec_parse_text(text, len, limits, err, parse_root, spec);
    if (rc)
        gp_spec3d_free(spec);
    return rc;
}

static int parse_3d(const char *text, size_t len, const gp_spec_limits *limits, void *spec, gp_error *err)
{
    return gp_spec3d_parse(text, len, limits, spec, err);
}

int gp_spec3d_load_file(const char *path, const gp_spec_limits *limits, gp_spec3d *spec,
                        gp_error *err)
{
    memset(spec, 0, sizeof *spec);
    return spec_load_file(path, limits, err, parse_3d, spec);
}

gp_pack3d_params gp_spec3d_pack_params(const gp_spec3d *spec, size_t max_spheres)
{
    gp_pack3d_params params = {&spec->box, &spec->dist, &spec->joint, spec->seed, max_spheres,
                               GP_PACK3D_LEVEL};
    return params;
}

void gp_spec3d_free(gp_spec3d *spec)
{
    gp_distribution_free(&spec->dist);
    memset(spec, 0, sizeof *spec);
}
