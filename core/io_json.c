/* io_json.c - the statistics object and the full JSON result. */
#include "grainpack/io.h"

/* json_object_set_new that remembers a failure instead of returning it at every call. */
static void put(json_t *obj, const char *key, json_t *value, int *failed)
{
    if (!value || json_object_set_new(obj, key, value))
        *failed = 1;
}

static json_t *distribution_json(const gp_pack_stats *st, int *failed)
{
    json_t *bins = json_array();
    for (size_t i = 0; bins && i < st->nbins; i++) {
        const gp_bin_stat *b = &st->bins[i];
        json_t *bin = json_object();
        if (!bin) {
            *failed = 1;
            break;
        }
        put(bin, "min", json_real(b->min), failed);
        put(bin, "max", json_real(b->max), failed);
        put(bin, "target", json_real(b->target), failed);
        put(bin, "count", json_integer((json_int_t)b->count), failed);
        put(bin, "achieved", json_real(b->achieved), failed);
        put(bin, "z", json_real(b->z), failed);
        if (json_array_append_new(bins, bin))
            *failed = 1;
    }
    json_t *d = json_object();
    if (!d) {
        json_decref(bins);
        *failed = 1;
        return NULL;
    }
    put(d, "bins", bins, failed);
    put(d, "chi2", json_real(st->chi2), failed);
    put(d, "dof", json_integer(st->dof), failed);
    put(d, "p_value", json_real(st->p_value), failed);
    put(d, "max_abs_z", json_real(st->max_abs_z), failed);
    return d;
}

json_t *gp_statistics_json(const gp_spec *spec, const gp_result *result)
{
    const gp_pack_stats *st = &result->stats;
    const gp_packing *pk = &result->packing;
    int failed = 0;
    json_t *root = json_object();
    json_t *radius = json_object();
    json_t *front = json_object();
    if (!root || !radius || !front) {
        json_decref(root);
        json_decref(radius);
        json_decref(front);
        return NULL;
    }
    put(root, "count", json_integer((json_int_t)st->count), &failed);
    put(root, "domain_area", json_real(st->domain_area), &failed);
    put(root, "packing_density", json_real(st->packing_density), &failed);
    put(root, "grain_fraction", json_real(st->grain_fraction), &failed);
    put(radius, "min", json_real(st->r_min), &failed);
    put(radius, "max", json_real(st->r_max), &failed);
    put(radius, "mean", json_real(st->r_mean), &failed);
    put(root, "radius", radius, &failed);
    put(root, "distribution", distribution_json(st, &failed), &failed);
    put(front, "initial_disks", json_integer((json_int_t)pk->initial_front), &failed);
    put(front, "attempts", json_integer((json_int_t)pk->attempts), &failed);
    put(front, "closures", json_integer((json_int_t)pk->closures), &failed);
    put(front, "frozen", json_integer((json_int_t)pk->frozen), &failed);
    put(front, "level_band", json_integer((json_int_t)spec->level_band), &failed);
    put(front, "max_level", json_integer((json_int_t)pk->max_level), &failed);
    put(root, "front", front, &failed);
    put(root, "seed", json_integer((json_int_t)spec->seed), &failed);
    if (failed) {
        json_decref(root);
        return NULL;
    }
    return root;
}

int gp_write_json(FILE *out, const gp_spec *spec, const gp_result *result)
{
    json_t *stats = gp_statistics_json(spec, result);
    if (!stats)
        return GP_ENOMEM;
    fprintf(out, "{\n\"domain\": {\"width\": %.17g, \"height\": %.17g},\n\"statistics\": ",
            spec->domain.width, spec->domain.height);
    int rc = json_dumpf(stats, out, JSON_COMPACT | JSON_REAL_PRECISION(17)) ? GP_EIO : 0;
    json_decref(stats);
    fputs(",\n\"disks\": [", out);
    const gp_packing *p = &result->packing;
    for (size_t i = 0; i < p->count; i++)
        fprintf(out, "%s\n{\"x\":%.17g,\"y\":%.17g,\"r\":%.17g,\"R\":%.17g}", i ? "," : "",
                p->disks[i].x, p->disks[i].y, p->disks[i].r, p->disks[i].R);
    fputs("\n]\n}\n", out);
    return rc ? rc : (ferror(out) ? GP_EIO : 0);
}
