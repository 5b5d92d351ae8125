/* spec_json.c - a parsed job spec written back as JSON, with every default made
 * explicit: what the validator understood, for a client to show or to submit as it is. */
#include "json_values.h"

/* json_object_set_new that remembers a failure instead of returning it at every call. */
static void put(json_t *obj, const char *key, json_t *value, int *failed)
{
    if (!obj) {
        json_decref(value);
        *failed = 1;
    } else if (!value || json_object_set_new(obj, key, value)) {
        *failed = 1;
    }
}

json_t *gp_json_distribution(const gp_distribution *d, int *failed)
{
    json_t *o = json_object();
    switch (d->kind) {
    case GP_DIST_CONSTANT:
        put(o, "kind", json_string("constant"), failed);
        put(o, "radius", json_real(d->radius), failed);
        break;
    case GP_DIST_UNIFORM:
        put(o, "kind", json_string("uniform"), failed);
        put(o, "min", json_real(d->min), failed);
        put(o, "max", json_real(d->max), failed);
        break;
    case GP_DIST_HISTOGRAM: {
        json_t *bins = json_array();
        for (size_t i = 0; bins && i < d->nbins; i++)
            if (json_array_append_new(bins, json_pack("{s:f, s:f, s:f}", "min", d->bins[i].min,
                                                      "max", d->bins[i].max, "p", d->bins[i].p)))
                *failed = 1;
        put(o, "kind", json_string("histogram"), failed);
        put(o, "bins", bins, failed);
        break;
    }
    }
    return o;
}

json_t *gp_json_joint(const gp_joint *j, int *failed)
{
    json_t *o = json_object();
    put(o, "law", json_string(gp_joint_law_name(j->law)), failed);
    if (j->law == GP_JOINT_CONSTANT)
        put(o, "value", json_real(j->value), failed);
    if (j->law == GP_JOINT_INVERSE || j->law == GP_JOINT_POWER)
        put(o, "k", json_real(j->k), failed);
    if (j->law == GP_JOINT_POWER)
        put(o, "exponent", json_real(j->exponent), failed);
    return o;
}

/* The "mesh" object: band_size and grading only with a band (and band_size only where it
 * sizes something), disk_tolerance only without cells, as the parser refuses them
 * elsewhere (the result must parse again). */
static json_t *mesh_json(const gp_spec *spec, int *failed)
{
    const gp_mesh_params *m = &spec->mesh;
    json_t *o = json_object();
    put(o, "element_size", json_real(m->element_size), failed);
    put(o, "min_angle", json_real(m->min_angle), failed);
    put(o, "order", json_integer(m->order), failed);
    put(o, "band_layers", json_integer(m->band_layers), failed);
    int band = spec->laguerre_enabled && spec->laguerre.shrink != GP_SHRINK_NONE;
    if (band && m->band_size > 0.0 && (m->grading || m->band_layers > 0))
        put(o, "band_size", json_real(m->band_size), failed);
    if (band)
        put(o, "grading", json_boolean(m->grading), failed);
    if (!spec->laguerre_enabled)
        put(o, "disk_tolerance", json_real(m->disk_tolerance), failed);
    put(o, "abaqus", json_pack("{s:s, s:b}", "plane",
                               m->plane == GP_MESH_PLANE_STRAIN ? "strain" : "stress",
                               "reduced_integration", m->reduced), failed);
    return o;
}

json_t *gp_json_periodic(unsigned periodic, int naxes, int *failed)
{
    static const char *const axes[] = {"x", "y", "z"};
    json_t *list = json_array();
    for (int a = 0; a < naxes; a++)
        if (((periodic >> a) & 1u) && (!list || json_array_append_new(list, json_string(axes[a]))))
            *failed = 1;
    return list;
}

/* "periodic" on domain `o` when any of its first `naxes` axes is; a walled domain writes
 * nothing. */
static void put_periodic(json_t *o, unsigned periodic, int naxes, int *failed)
{
    if (periodic & ((1u << naxes) - 1u))
        put(o, "periodic", gp_json_periodic(periodic, naxes, failed), failed);
}

/* The "balance" and "laguerre" blocks, the same in 2D and 3D specs: every field spelled out,
 * defaults included, so that the inputs a result carries run again to the same result. */
static json_t *balance_json(const gp_balance_params *b)
{
    return json_pack("{s:s, s:i, s:f}", "method", gp_balance_method_name(b->method),
                     "max_iterations", (int)b->max_iterations, "max_step", b->max_step);
}

static json_t *laguerre_json(const gp_laguerre_params *l)
{
    return json_pack("{s:s, s:b}", "shrink", gp_shrink_name(l->shrink), "flush_boundary",
                     l->flush_boundary);
}

json_t *gp_spec_json(const gp_spec *spec)
{
    int failed = 0;
    json_t *in = json_object();
    json_t *domain = json_pack("{s:f, s:f}", "width", spec->domain.width, "height", spec->domain.height);
    put_periodic(domain, spec->domain.periodic, 2, &failed);
    put(in, "domain", domain, &failed);
    put(in, "distribution", gp_json_distribution(&spec->dist, &failed), &failed);
    put(in, "joint", gp_json_joint(&spec->joint, &failed), &failed);
    put(in, "seed", json_integer((json_int_t)spec->seed), &failed);
    /* the rule named, so that the densest default parses back as the default */
    put(in, "front", spec->level_band_set
                         ? json_pack("{s:s, s:i}", "rule", "level_band", "level_band", (int)spec->level_band)
                         : json_pack("{s:s}", "rule", "densest"), &failed);
    if (spec->balance_enabled)
        put(in, "balance", balance_json(&spec->balance), &failed);
    if (spec->laguerre_enabled)
        put(in, "laguerre", laguerre_json(&spec->laguerre), &failed);
    if (spec->mesh_enabled)
        put(in, "mesh", mesh_json(spec, &failed), &failed);
    put(in, "picture", json_pack("{s:s, s:b}", "color",
                                 spec->picture_color == GP_PICTURE_COLOR_QUALITY ? "quality" : "radius",
                                 "disks", spec->picture_disks), &failed);
    if (failed) {
        json_decref(in);
        return NULL;
    }
    return in;
}

/* A 3D spec's "domain": width, height, depth, and "periodic" (["x", "z"], ...) when any. */
static json_t *json_box(const gp_box *box, int *failed)
{
    json_t *o = json_pack("{s:f, s:f, s:f}", "width", box->width, "height", box->height, "depth", box->depth);
    put_periodic(o, box->periodic, 3, failed);
    return o;
}

json_t *gp_spec3d_json(const gp_spec3d *spec)
{
    static const char *const axes[] = {"x", "y", "z"};
    int failed = 0;
    json_t *in = json_object();
    put(in, "domain", json_box(&spec->box, &failed), &failed);
    put(in, "distribution", gp_json_distribution(&spec->dist, &failed), &failed);
    put(in, "joint", gp_json_joint(&spec->joint, &failed), &failed);
    put(in, "seed", json_integer((json_int_t)spec->seed), &failed);
    if (spec->balance_enabled)
        put(in, "balance", balance_json(&spec->balance), &failed);
    if (spec->laguerre_enabled)
        put(in, "laguerre", laguerre_json(&spec->laguerre), &failed);
    put(in, "picture", json_pack("{s:{s:s, s:f}}", "section", "axis", axes[spec->section.axis],
                                 "at", spec->section.at), &failed);
    if (failed) {
        json_decref(in);
        return NULL;
    }
    return in;
}
