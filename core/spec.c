/* spec.c - parsing and validating the job spec (jansson). Every message names the field
 * by its JSON pointer in the submitted document and says what was expected. */
#include "grainpack/spec.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "spec_parts.h"
#include "grainpack/pack.h"

/* Packing density assumed by the disk-count estimate: a little above what the front
 * reaches (0.80-0.88), so that the estimate errs on the high side. */
#define EXPECTED_FILL 0.90

/* Appends "/" + key (escaped per RFC 6901) to base. */
void spec_pointer_key(char *out, const char *base, const char *key)
{
    size_t n = (size_t)snprintf(out, GP_ERROR_POINTER_MAX, "%s/", base);
    for (const char *k = key; *k && n + 3 < GP_ERROR_POINTER_MAX; k++) {
        if (*k == '~') {
            out[n++] = '~';
            out[n++] = '0';
        } else if (*k == '/') {
            out[n++] = '~';
            out[n++] = '1';
        } else {
            out[n++] = *k;
        }
    }
    out[n < GP_ERROR_POINTER_MAX ? n : GP_ERROR_POINTER_MAX - 1] = '\0';
}

static void pointer_index(char *out, const char *base, size_t index)
{
    char key[24];
    snprintf(key, sizeof key, "%zu", index);
    spec_pointer_key(out, base, key);
}

static const char *type_phrase(const json_t *v)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER: return "an integer";
    case JSON_REAL: return "a number";
    case JSON_TRUE: return "true";
    case JSON_FALSE: return "false";
    case JSON_NULL: return "null";
    }
    return "a value";
}

/* Rejects members of obj not in the NULL-terminated list `allowed`. */
int spec_check_members(validator *v, const json_t *obj, const char *base,
                       const char *const *allowed, const char *expected_list)
{
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)obj, key, value) {
        int known = 0;
        for (const char *const *a = allowed; *a; a++)
            known |= strcmp(*a, key) == 0;
        if (!known) {
            char ptr[GP_ERROR_POINTER_MAX];
            spec_pointer_key(ptr, base, key);
            return gp_error_set(v->err, GP_EINVAL, ptr, "unknown field; expected one of %s",
                                expected_list);
        }
    }
    return 0;
}

int spec_get_object(validator *v, const json_t *parent, const char *base, const char *key,
                    int required, const json_t **out, char *ptr)
{
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(parent, key);
    *out = NULL;
    if (!value) {
        if (required)
            return gp_error_set(v->err, GP_EINVAL, ptr, "missing; expected an object");
        return 0;
    }
    if (!json_is_object(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be an object, got %s", type_phrase(value));
    *out = value;
    return 0;
}

/* Reads a required finite number that must be > lower (or >= lower when `inclusive`). */
int spec_get_number(validator *v, const json_t *obj, const char *base, const char *key,
                    double lower, int inclusive, double *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(obj, key);
    const char *bound = inclusive ? ">=" : ">";
    if (!value)
        return gp_error_set(v->err, GP_EINVAL, ptr, "missing; expected a number %s %g", bound, lower);
    if (!json_is_number(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be a number %s %g, got %s", bound, lower,
                            type_phrase(value));
    double x = json_number_value(value);
    if (!isfinite(x) || (inclusive ? !(x >= lower) : !(x > lower)))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be %s %g, got %.17g", bound, lower, x);
    *out = x;
    return 0;
}

static int get_finite(validator *v, const json_t *obj, const char *base, const char *key,
                      double *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(obj, key);
    if (!value)
        return gp_error_set(v->err, GP_EINVAL, ptr, "missing; expected a number");
    if (!json_is_number(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be a number, got %s", type_phrase(value));
    *out = json_number_value(value);
    return 0;
}

/* Reads the "kind"/"law" discriminator of obj and matches it against `names`. */
static int get_choice(validator *v, const json_t *obj, const char *base, const char *key,
                      const char *const *names, const char *expected_list, int *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(obj, key);
    if (!value)
        return gp_error_set(v->err, GP_EINVAL, ptr, "missing; expected one of %s", expected_list);
    if (!json_is_string(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be one of %s, got %s", expected_list,
                            type_phrase(value));
    for (int i = 0; names[i]; i++) {
        if (strcmp(names[i], json_string_value(value)) == 0) {
            *out = i;
            return 0;
        }
    }
    return gp_error_set(v->err, GP_EINVAL, ptr, "must be one of %s, got \"%.64s\"", expected_list,
                        json_string_value(value));
}

/* "periodic": true (every axis), false, or an array of distinct axis names, "x", "y" for
 * a domain (docs/method.md §3.8) and "z" too for a box (docs/3d.md §11); absent is false.
 * Axis k sets bit 1 << k (GP_PERIODIC_X, _Y, _Z). */
int spec_parse_periodic(validator *v, const json_t *obj, const char *base, int axes, unsigned *out)
{
    const char *expected = axes == 3 ? "true, false or an array of distinct \"x\", \"y\", \"z\""
                                     : "true, false or an array of distinct \"x\", \"y\"";
    const char *names = axes == 3 ? "\"x\", \"y\" or \"z\"" : "\"x\" or \"y\"";
    char ptr[GP_ERROR_POINTER_MAX], item_ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, "periodic");
    const json_t *value = json_object_get(obj, "periodic");
    *out = 0;
    if (!value || json_is_false(value))
        return 0;
    if (json_is_true(value)) {
        *out = (1u << axes) - 1;
        return 0;
    }
    if (!json_is_array(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be %s, got %s", expected, type_phrase(value));
    size_t i;
    const json_t *item;
    json_array_foreach(value, i, item) {
        pointer_index(item_ptr, ptr, i);
        const char *axis = json_is_string(item) ? json_string_value(item) : NULL;
        unsigned bit = axis && strlen(axis) == 1 && axis[0] >= 'x' && axis[0] < 'x' + axes
                           ? 1u << (axis[0] - 'x')
                           : 0;
        if (!bit)
            return gp_error_set(v->err, GP_EINVAL, item_ptr, "must be %s, got %s", names,
                                type_phrase(item));
        if (*out & bit)
            return gp_error_set(v->err, GP_EINVAL, item_ptr, "repeats \"%s\"; expected %s", axis,
                                expected);
        *out |= bit;
    }
    return 0;
}

static int parse_domain(validator *v, const json_t *inputs, const char *base, gp_domain *dom)
{
    char ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "domain", 1, &obj, ptr);
    if (rc)
        return rc;
    static const char *const members[] = {"width", "height", "periodic", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "width, height, periodic")))
        return rc;
    if ((rc = spec_get_number(v, obj, ptr, "width", 0.0, 0, &dom->width)))
        return rc;
    if ((rc = spec_get_number(v, obj, ptr, "height", 0.0, 0, &dom->height)))
        return rc;
    return spec_parse_periodic(v, obj, ptr, 2, &dom->periodic);
}

static int parse_histogram(validator *v, const json_t *obj, const char *base, gp_distribution *d)
{
    char ptr[GP_ERROR_POINTER_MAX], bin_ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, "bins");
    const json_t *bins = json_object_get(obj, "bins");
    if (!bins)
        return gp_error_set(v->err, GP_EINVAL, ptr, "missing; expected an array of {min, max, p}");
    if (!json_is_array(bins))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be an array of {min, max, p}, got %s",
                            type_phrase(bins));
    size_t n = json_array_size(bins);
    if (n == 0)
        return gp_error_set(v->err, GP_EINVAL, ptr, "must hold at least one bin");
    if (n > v->max_bins)
        return gp_error_set(v->err, GP_ETOOBIG, ptr, "has %zu bins, more than the limit of %zu", n,
                            v->max_bins);
    d->bins = calloc(n, sizeof *d->bins);
    if (!d->bins)
        return gp_error_set(v->err, GP_ENOMEM, ptr, "out of memory for %zu bins", n);
    d->nbins = n;
    static const char *const members[] = {"min", "max", "p", NULL};
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        const json_t *bin = json_array_get(bins, i);
        gp_bin *b = &d->bins[i];
        int rc;
        pointer_index(bin_ptr, ptr, i);
        if (!json_is_object(bin))
            return gp_error_set(v->err, GP_EINVAL, bin_ptr, "must be an object {min, max, p}, got %s",
                                type_phrase(bin));
        if ((rc = spec_check_members(v, bin, bin_ptr, members, "min, max, p")) ||
            (rc = spec_get_number(v, bin, bin_ptr, "min", 0.0, 0, &b->min)) ||
            (rc = spec_get_number(v, bin, bin_ptr, "max", b->min, 0, &b->max)) ||
            (rc = spec_get_number(v, bin, bin_ptr, "p", 0.0, 1, &b->p)))
            return rc;
        if (b->p > 1.0) {
            char p_ptr[GP_ERROR_POINTER_MAX];
            spec_pointer_key(p_ptr, bin_ptr, "p");
            return gp_error_set(v->err, GP_EINVAL, p_ptr, "must be <= 1, got %.17g", b->p);
        }
        if (i > 0 && b->min < d->bins[i - 1].max) {
            char min_ptr[GP_ERROR_POINTER_MAX];
            spec_pointer_key(min_ptr, bin_ptr, "min");
            return gp_error_set(v->err, GP_EINVAL, min_ptr,
                                "must be >= the previous bin's max %.17g (bins sorted, not "
                                "overlapping), got %.17g",
                                d->bins[i - 1].max, b->min);
        }
        sum += b->p;
    }
    if (fabs(sum - 1.0) > GP_SPEC_PROBABILITY_TOL)
        return gp_error_set(v->err, GP_EINVAL, ptr,
                            "probabilities must sum to 1 within %g, got %.10g", GP_SPEC_PROBABILITY_TOL,
                            sum);
    return 0;
}

int spec_parse_distribution(validator *v, const json_t *inputs, const char *base,
                            gp_distribution *d)
{
    char ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "distribution", 1, &obj, ptr);
    if (rc)
        return rc;
    static const char *const kinds[] = {"constant", "uniform", "histogram", NULL};
    int kind;
    if ((rc = get_choice(v, obj, ptr, "kind", kinds, "constant, uniform, histogram", &kind)))
        return rc;
    d->kind = (gp_dist_kind)kind;
    switch (d->kind) {
    case GP_DIST_CONSTANT: {
        static const char *const members[] = {"kind", "radius", NULL};
        if ((rc = spec_check_members(v, obj, ptr, members, "kind, radius")))
            return rc;
        return spec_get_number(v, obj, ptr, "radius", 0.0, 0, &d->radius);
    }
    case GP_DIST_UNIFORM: {
        static const char *const members[] = {"kind", "min", "max", NULL};
        if ((rc = spec_check_members(v, obj, ptr, members, "kind, min, max")))
            return rc;
        if ((rc = spec_get_number(v, obj, ptr, "min", 0.0, 0, &d->min)))
            return rc;
        return spec_get_number(v, obj, ptr, "max", d->min, 0, &d->max);
    }
    case GP_DIST_HISTOGRAM: {
        static const char *const members[] = {"kind", "bins", NULL};
        if ((rc = spec_check_members(v, obj, ptr, members, "kind, bins")))
            return rc;
        return parse_histogram(v, obj, ptr, d);
    }
    }
    return 0;
}

int spec_parse_joint(validator *v, const json_t *inputs, const char *base, gp_joint *j)
{
    char ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "joint", 0, &obj, ptr);
    memset(j, 0, sizeof *j);
    if (rc || !obj)
        return rc;
    static const char *const laws[] = {"none", "constant", "inverse", "power", NULL};
    int law;
    if ((rc = get_choice(v, obj, ptr, "law", laws, "none, constant, inverse, power", &law)))
        return rc;
    j->law = (gp_joint_law)law;
    switch (j->law) {
    case GP_JOINT_NONE: {
        static const char *const members[] = {"law", NULL};
        return spec_check_members(v, obj, ptr, members, "law");
    }
    case GP_JOINT_CONSTANT: {
        static const char *const members[] = {"law", "value", NULL};
        if ((rc = spec_check_members(v, obj, ptr, members, "law, value")))
            return rc;
        return spec_get_number(v, obj, ptr, "value", 0.0, 1, &j->value);
    }
    case GP_JOINT_INVERSE: {
        static const char *const members[] = {"law", "k", NULL};
        if ((rc = spec_check_members(v, obj, ptr, members, "law, k")))
            return rc;
        return spec_get_number(v, obj, ptr, "k", 0.0, 1, &j->k);
    }
    case GP_JOINT_POWER: {
        static const char *const members[] = {"law", "k", "exponent", NULL};
        if ((rc = spec_check_members(v, obj, ptr, members, "law, k, exponent")))
            return rc;
        if ((rc = spec_get_number(v, obj, ptr, "k", 0.0, 1, &j->k)))
            return rc;
        return get_finite(v, obj, ptr, "exponent", &j->exponent);
    }
    }
    return 0;
}

/* The spec's names of the front rules: "densest" (the default, gp_pack_default_rule's
 * choice) and "level_band" (the report's rule with a band), in that order. */
static const char *const front_rules[] = {"densest", "level_band", NULL};

static int parse_front(validator *v, const json_t *inputs, const char *base, uint32_t *band,
                       int *band_set)
{
    char ptr[GP_ERROR_POINTER_MAX], band_ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "front", 0, &obj, ptr);
    *band = 0;
    *band_set = 0;
    if (rc || !obj)
        return rc;
    static const char *const members[] = {"rule", "level_band", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "rule, level_band")))
        return rc;
    const json_t *value = json_object_get(obj, "level_band");
    /* a level band alone asks for the report's rule, as it did before the rule existed */
    int rule = value ? 1 : 0;
    if (json_object_get(obj, "rule") &&
        (rc = get_choice(v, obj, ptr, "rule", front_rules, "densest, level_band", &rule)))
        return rc;
    *band_set = rule == 1;
    if (!value)
        return 0;
    spec_pointer_key(band_ptr, ptr, "level_band");
    if (rule != 1)
        return gp_error_set(v->err, GP_EINVAL, band_ptr,
                            "only with \"rule\": \"level_band\" (the densest rule sets its own)");
    if (!json_is_integer(value))
        return gp_error_set(v->err, GP_EINVAL, band_ptr, "must be an integer from 0 to %d, got %s",
                            GP_SPEC_MAX_LEVEL_BAND, type_phrase(value));
    json_int_t n = json_integer_value(value);
    if (n < 0 || n > GP_SPEC_MAX_LEVEL_BAND)
        return gp_error_set(v->err, GP_EINVAL, band_ptr, "must be an integer from 0 to %d, got %lld",
                            GP_SPEC_MAX_LEVEL_BAND, (long long)n);
    *band = (uint32_t)n;
    return 0;
}

/* Reads an optional boolean member; *out keeps its value when the member is absent. */
static int get_bool(validator *v, const json_t *obj, const char *base, const char *key, int *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(obj, key);
    if (!value)
        return 0;
    if (!json_is_boolean(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be true or false, got %s", type_phrase(value));
    *out = json_is_true(value);
    return 0;
}

int spec_parse_balance(validator *v, const json_t *inputs, const char *base, int *enabled,
                       gp_balance_params *balance)
{
    char ptr[GP_ERROR_POINTER_MAX], member[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "balance", 0, &obj, ptr);
    if (rc || !obj)
        return rc;
    static const char *const members[] = {"method", "max_iterations", "max_step", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "method, max_iterations, max_step")))
        return rc;
    static const char *const methods[] = {"none", "laplacian", "relocation", NULL};
    int method;
    if ((rc = get_choice(v, obj, ptr, "method", methods, "none, laplacian, relocation", &method)))
        return rc;
    *enabled = 1;
    balance->method = (gp_balance_method)method;
    balance->max_iterations = GP_BALANCE_DEFAULT_MAX_ITERATIONS;
    balance->max_step = GP_BALANCE_DEFAULT_MAX_STEP;
    balance->update = GP_RT_UPDATE_FLIPS;
    const json_t *value = json_object_get(obj, "max_iterations");
    if (value) {
        spec_pointer_key(member, ptr, "max_iterations");
        if (!json_is_integer(value))
            return gp_error_set(v->err, GP_EINVAL, member, "must be an integer from 1 to %d, got %s",
                                GP_SPEC_MAX_BALANCE_ITERATIONS, type_phrase(value));
        json_int_t n = json_integer_value(value);
        if (n < 1 || n > GP_SPEC_MAX_BALANCE_ITERATIONS)
            return gp_error_set(v->err, GP_EINVAL, member, "must be an integer from 1 to %d, got %lld",
                                GP_SPEC_MAX_BALANCE_ITERATIONS, (long long)n);
        balance->max_iterations = (uint32_t)n;
    }
    if (json_object_get(obj, "max_step")) {
        /* the steps tried go down by 0.05 to 0.05 (docs/method.md §4.4): a smaller first step tries none */
        if ((rc = spec_get_number(v, obj, ptr, "max_step", 0.05, 1, &balance->max_step)))
            return rc;
        if (balance->max_step > 1.0) {
            spec_pointer_key(member, ptr, "max_step");
            return gp_error_set(v->err, GP_EINVAL, member, "must be <= 1 (the whole way to the target), got %.17g",
                                balance->max_step);
        }
    }
    return 0;
}

int spec_parse_laguerre(validator *v, const json_t *inputs, const char *base, int *enabled,
                        gp_laguerre_params *laguerre)
{
    char ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "laguerre", 0, &obj, ptr);
    if (rc || !obj)
        return rc;
    static const char *const members[] = {"shrink", "flush_boundary", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "shrink, flush_boundary")))
        return rc;
    static const char *const shrinks[] = {"none", "homothetic", "offset", NULL};
    int shrink;
    if ((rc = get_choice(v, obj, ptr, "shrink", shrinks, "homothetic, offset, none", &shrink)))
        return rc;
    *enabled = 1;
    laguerre->shrink = (gp_shrink)shrink;
    return get_bool(v, obj, ptr, "flush_boundary", &laguerre->flush_boundary);
}

/* Reads an optional number in [lower, upper] (lower excluded when `open_lower`). */
static int get_bounded(validator *v, const json_t *obj, const char *base, const char *key,
                       double lower, int open_lower, double upper, double *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(obj, key);
    if (!value)
        return 0;
    const char *open = open_lower ? "(" : "[";
    if (!json_is_number(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be a number in %s%g, %g], got %s", open,
                            lower, upper, type_phrase(value));
    double x = json_number_value(value);
    if (!isfinite(x) || (open_lower ? !(x > lower) : !(x >= lower)) || !(x <= upper))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be a number in %s%g, %g], got %.17g", open,
                            lower, upper, x);
    *out = x;
    return 0;
}

/* Reads an optional integer in [lower, upper]. */
static int get_integer(validator *v, const json_t *obj, const char *base, const char *key,
                       int lower, int upper, int *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, key);
    const json_t *value = json_object_get(obj, key);
    if (!value)
        return 0;
    if (!json_is_integer(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be an integer from %d to %d, got %s", lower,
                            upper, type_phrase(value));
    json_int_t n = json_integer_value(value);
    if (n < lower || n > upper)
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be an integer from %d to %d, got %lld", lower,
                            upper, (long long)n);
    *out = (int)n;
    return 0;
}

/* "min_angle": refused above what Delaunay refinement is proved to reach. */
static int get_min_angle(validator *v, const json_t *obj, const char *base, double *out)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, "min_angle");
    const json_t *value = json_object_get(obj, "min_angle");
    if (value && json_is_number(value) && json_number_value(value) > GP_MESH_MAX_MIN_ANGLE)
        return gp_error_set(v->err, GP_EINVAL, ptr,
                            "must be <= %g degrees, got %.17g: CGAL's Delaunay refinement is "
                            "guaranteed to end only for a minimum angle up to arcsin(sqrt(1/8))",
                            GP_MESH_MAX_MIN_ANGLE, json_number_value(value));
    return get_bounded(v, obj, base, "min_angle", 0.0, 0, GP_MESH_MAX_MIN_ANGLE, out);
}

/* The largest element size a spec may ask for: no grain is larger than the domain. */
#define SPEC_MAX_ELEMENT_SIZE 1e300

static int parse_abaqus(validator *v, const json_t *mesh, const char *base, gp_mesh_params *m)
{
    char ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, mesh, base, "abaqus", 0, &obj, ptr);
    if (rc || !obj)
        return rc;
    static const char *const members[] = {"plane", "reduced_integration", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "plane, reduced_integration")))
        return rc;
    if (json_object_get(obj, "plane")) {
        static const char *const planes[] = {"stress", "strain", NULL};
        int plane;
        if ((rc = get_choice(v, obj, ptr, "plane", planes, "stress, strain", &plane)))
            return rc;
        m->plane = (gp_mesh_plane)plane;
    }
    return get_bool(v, obj, ptr, "reduced_integration", &m->reduced);
}

static int parse_mesh(validator *v, const json_t *inputs, const char *base, gp_spec *spec)
{
    char ptr[GP_ERROR_POINTER_MAX], member[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    int rc = spec_get_object(v, inputs, base, "mesh", 0, &obj, ptr);
    if (rc || !obj)
        return rc;
    static const char *const members[] = {"element_size", "min_angle", "order", "band_layers",
                                          "band_size", "grading", "disk_tolerance", "abaqus", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members,
                            "element_size, min_angle, order, band_layers, band_size, grading, "
                            "disk_tolerance, abaqus")))
        return rc;
    gp_mesh_params *m = &spec->mesh;
    spec->mesh_enabled = 1;
    gp_mesh_params_default(&spec->dist, m);
    if ((rc = get_bounded(v, obj, ptr, "element_size", 0.0, 1, SPEC_MAX_ELEMENT_SIZE, &m->element_size)) ||
        (rc = get_min_angle(v, obj, ptr, &m->min_angle)) ||
        (rc = get_integer(v, obj, ptr, "order", 1, 2, &m->order)) ||
        (rc = get_integer(v, obj, ptr, "band_layers", 0, GP_MESH_MAX_BAND_LAYERS, &m->band_layers)) ||
        (rc = get_bounded(v, obj, ptr, "band_size", 0.0, 1, SPEC_MAX_ELEMENT_SIZE, &m->band_size)) ||
        (rc = get_bool(v, obj, ptr, "grading", &m->grading)) ||
        (rc = get_bounded(v, obj, ptr, "disk_tolerance", 0.0, 1, 0.25, &m->disk_tolerance)) ||
        (rc = parse_abaqus(v, obj, ptr, m)))
        return rc;
    if (m->band_layers > 0 && (!spec->laguerre_enabled || spec->laguerre.shrink != GP_SHRINK_OFFSET)) {
        spec_pointer_key(member, ptr, "band_layers");
        return gp_error_set(v->err, GP_EINVAL, member,
                            "needs \"laguerre\": {\"shrink\": \"offset\"} (the band's strips have "
                            "parallel sides only between offset cells)");
    }
    int band = spec->laguerre_enabled && spec->laguerre.shrink != GP_SHRINK_NONE;
    static const char *const band_options[] = {"band_size", "grading"};
    for (size_t k = 0; k < sizeof band_options / sizeof *band_options; k++)
        if (json_object_get(obj, band_options[k]) && !band) {
            spec_pointer_key(member, ptr, band_options[k]);
            return gp_error_set(v->err, GP_EINVAL, member,
                                "sizes the grain-boundary band: it needs \"laguerre\": {\"shrink\": "
                                "\"offset\"} or \"homothetic\"");
        }
    if (json_object_get(obj, "band_size") && !m->grading && m->band_layers == 0) {
        spec_pointer_key(member, ptr, "band_size");
        return gp_error_set(v->err, GP_EINVAL, member, "sizes nothing with \"grading\": false and no "
                                                       "band_layers");
    }
    if (json_object_get(obj, "disk_tolerance") && spec->laguerre_enabled) {
        spec_pointer_key(member, ptr, "disk_tolerance");
        return gp_error_set(v->err, GP_EINVAL, member, "polygonises disks in a matrix: it has no "
                                                       "meaning with Laguerre cells");
    }
    return 0;
}

static int parse_picture(validator *v, const json_t *inputs, const char *base, gp_spec *spec)
{
    char ptr[GP_ERROR_POINTER_MAX], color_ptr[GP_ERROR_POINTER_MAX];
    const json_t *obj;
    spec->picture_color = spec->balance_enabled ? GP_PICTURE_COLOR_QUALITY : GP_PICTURE_COLOR_RADIUS;
    spec->picture_tile = 1;
    int rc = spec_get_object(v, inputs, base, "picture", 0, &obj, ptr);
    if (rc || !obj)
        return rc;
    static const char *const members[] = {"color", "disks", "tile", NULL};
    if ((rc = spec_check_members(v, obj, ptr, members, "color, disks, tile")))
        return rc;
    if ((rc = get_integer(v, obj, ptr, "tile", 1, GP_PICTURE_MAX_TILE, &spec->picture_tile)))
        return rc;
    if (spec->picture_tile > 1 && !spec->domain.periodic) {
        char tile_ptr[GP_ERROR_POINTER_MAX];
        spec_pointer_key(tile_ptr, ptr, "tile");
        return gp_error_set(v->err, GP_EINVAL, tile_ptr,
                            "tiles a periodic domain only; add \"periodic\" to the domain or leave "
                            "\"tile\" out");
    }
    if (json_object_get(obj, "color")) {
        static const char *const colors[] = {"radius", "quality", NULL};
        int color;
        if ((rc = get_choice(v, obj, ptr, "color", colors, "radius, quality", &color)))
            return rc;
        spec->picture_color = (gp_picture_color)color;
        spec_pointer_key(color_ptr, ptr, "color");
        if (spec->picture_color == GP_PICTURE_COLOR_QUALITY && !spec->balance_enabled)
            return gp_error_set(v->err, GP_EINVAL, color_ptr,
                                "\"quality\" needs the balance stage: add \"balance\": {\"method\": ...}");
    }
    return get_bool(v, obj, ptr, "disks", &spec->picture_disks);
}

int spec_parse_seed(validator *v, const json_t *inputs, const char *base, uint64_t *seed)
{
    char ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(ptr, base, "seed");
    const json_t *value = json_object_get(inputs, "seed");
    *seed = GP_SPEC_DEFAULT_SEED;
    if (!value)
        return 0;
    if (!json_is_integer(value))
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be an integer >= 0, got %s",
                            type_phrase(value));
    json_int_t s = json_integer_value(value);
    if (s < 0)
        return gp_error_set(v->err, GP_EINVAL, ptr, "must be an integer >= 0, got %lld", (long long)s);
    *seed = (uint64_t)s;
    return 0;
}

/* The JSON pointer of the field giving the law's smallest radius, into out
 * (GP_ERROR_POINTER_MAX bytes). */
void spec_smallest_radius_pointer(const char *base, const gp_distribution *dist, char *out)
{
    char law[GP_ERROR_POINTER_MAX], bins[GP_ERROR_POINTER_MAX], bin[GP_ERROR_POINTER_MAX];
    spec_pointer_key(law, base, "distribution");
    switch (dist->kind) {
    case GP_DIST_CONSTANT: spec_pointer_key(out, law, "radius"); return;
    case GP_DIST_UNIFORM: spec_pointer_key(out, law, "min"); return;
    case GP_DIST_HISTOGRAM: {
        size_t i = 0; /* bins are sorted: the first drawn one holds the smallest radius */
        while (i + 1 < dist->nbins && !(dist->bins[i].p > 0.0))
            i++;
        spec_pointer_key(bins, law, "bins");
        pointer_index(bin, bins, i);
        spec_pointer_key(out, bin, "min");
        return;
    }
    }
    snprintf(out, GP_ERROR_POINTER_MAX, "%s", law);
}

double gp_spec_expected_disks(const gp_domain *domain, const gp_distribution *dist,
                              const gp_joint *joint)
{
    double mean_R2 = gp_distribution_mean_packing_r2(dist, joint);
    return EXPECTED_FILL * gp_domain_area(domain) / (M_PI * mean_R2);
}

/* The chance, at most, that a packing holds more disks than gp_spec_disk_bound says. */
#define DISK_BOUND_RISK 1e-9

double gp_spec_disk_bound(const gp_domain *domain, const gp_distribution *dist,
                          const gp_joint *joint)
{
    /* Disjoint disks inside the domain cover at most its area, so a packing of n disks has
     * drawn n radii whose R^2 sum to at most A / pi. For X = R^2 with mean mu, variance
     * var, and mu - X <= spread, Bernstein's inequality bounds the chance that n draws sum
     * to no more than n mu - t by exp(-t^2 / (2 n var + 2 spread t / 3)); the bound is the
     * least n (found by bisection, the exponent growing with n) that makes it at most
     * DISK_BOUND_RISK with t = n mu - A / pi. It exceeds the plain estimate most where a
     * few large disks carry the mean of R^2: leave them out and the small ones number far
     * more. (Hoeffding's inequality, with the range R_max^2 - R_min^2 in place of the
     * variance, gives a looser bound on such laws.) */
    double mu = gp_distribution_packing_moment(dist, joint, 2);
    double var = gp_distribution_packing_moment(dist, joint, 4) - mu * mu;
    double r_min, r_max, R_min, R_max;
    gp_distribution_support(dist, &r_min, &r_max);
    gp_joint_packing_range(joint, r_min, r_max, &R_min, &R_max);
    double spread = mu - R_min * R_min, area = gp_domain_area(domain) / M_PI;
    double log_risk = -log(DISK_BOUND_RISK);
    if (!(mu > 0.0))
        return INFINITY;
    if (var < 0.0)
        var = 0.0;
    double lo = area / mu, hi = 2.0 * lo + 16.0;
    for (int grow = 0; grow < 64; grow++) {
        double t = hi * mu - area;
        if (t * t >= log_risk * (2.0 * hi * var + 2.0 * spread * t / 3.0))
            break;
        hi *= 2.0;
    }
    for (int i = 0; i < 64 && hi - lo > 0.5; i++) {
        double n = 0.5 * (lo + hi), t = n * mu - area;
        if (t * t >= log_risk * (2.0 * n * var + 2.0 * spread * t / 3.0))
            hi = n;
        else
            lo = n;
    }
    /* and n disks of radius R_min at least cover n pi R_min^2 <= A: a hard bound */
    double hard = area / (R_min * R_min);
    return ceil(hi < hard ? hi : hard);
}

/* Checks that spans the fields: the law fits the domain, j(r) stays finite on the
 * support, the packer can pack the law in bounded time and to the contact tolerance, and
 * the disk count is under the cap however the draws fall (but for DISK_BOUND_RISK). */
static int check_whole(validator *v, const char *base, gp_spec *spec)
{
    char dist_ptr[GP_ERROR_POINTER_MAX], joint_ptr[GP_ERROR_POINTER_MAX],
        domain_ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(dist_ptr, base, "distribution");
    spec_pointer_key(joint_ptr, base, "joint");
    spec_pointer_key(domain_ptr, base, "domain");
    double r_min, r_max, R_min, R_max;
    gp_distribution_support(&spec->dist, &r_min, &r_max);
    if (!(r_max > 0.0))
        return gp_error_set(v->err, GP_EINVAL, dist_ptr, "must give some bin a probability > 0");
    gp_joint_packing_range(&spec->joint, r_min, r_max, &R_min, &R_max);
    if (!isfinite(R_max) || !isfinite(R_min))
        return gp_error_set(v->err, GP_EINVAL, joint_ptr,
                            "gives a non-finite thickness on the radius range [%g, %g]", r_min, r_max);
    double side = spec->domain.width < spec->domain.height ? spec->domain.width : spec->domain.height;
    if (2.0 * R_max > side)
        return gp_error_set(v->err, GP_EINVAL, dist_ptr,
                            "the largest packing disk (diameter %g, grain radius up to %g plus "
                            "joint) must fit in the domain, whose smaller side is %g",
                            2.0 * R_max, r_max, side);
    gp_pack_law_limit limit = gp_pack_check_law(&spec->domain, &spec->dist, &spec->joint, v->err);
    if (limit != GP_PACK_LAW_OK) {
        /* the joint is at fault when the grain radii alone are within the ratio */
        if (limit == GP_PACK_LAW_PERIOD)
            spec_pointer_key(v->err->pointer, domain_ptr, "periodic");
        else if (limit == GP_PACK_LAW_RATIO && r_max <= GP_PACK_MAX_RADIUS_RATIO * r_min)
            snprintf(v->err->pointer, sizeof v->err->pointer, "%s", joint_ptr);
        else
            spec_smallest_radius_pointer(base, &spec->dist, v->err->pointer);
        return GP_EINVAL;
    }
    spec->expected_disks = gp_spec_expected_disks(&spec->domain, &spec->dist, &spec->joint);
    double bound = gp_spec_disk_bound(&spec->domain, &spec->dist, &spec->joint);
    if (!(bound <= (double)v->max_disks))
        return gp_error_set(v->err, GP_ETOOBIG, domain_ptr,
                            "about %.3g disks expected and up to %.3g possible, more than the limit "
                            "of %zu; use a smaller domain or larger grains",
                            spec->expected_disks, bound, v->max_disks);
    spec->max_elements = v->max_elements;
    if (!spec->mesh_enabled)
        return 0;
    char size_ptr[GP_ERROR_POINTER_MAX], mesh_ptr[GP_ERROR_POINTER_MAX];
    spec_pointer_key(mesh_ptr, base, "mesh");
    if (spec->domain.periodic && spec->mesh.band_layers > 0) {
        char layers_ptr[GP_ERROR_POINTER_MAX];
        spec_pointer_key(layers_ptr, mesh_ptr, "band_layers");
        return gp_error_set(v->err, GP_EINVAL, layers_ptr,
                            "is not available on a periodic domain (the band's strips would be "
                            "cut by the periodic sides); leave it out: the band is then meshed "
                            "with triangles");
    }
    spec_pointer_key(size_ptr, mesh_ptr, "element_size");
    spec->expected_elements = gp_mesh_expected_elements(
        &spec->domain, &spec->dist, &spec->joint, spec->expected_disks, spec->laguerre_enabled,
        spec->laguerre.shrink, &spec->mesh);
    if (!(spec->expected_elements <= (double)v->max_elements))
        return gp_error_set(v->err, GP_ETOOBIG, size_ptr,
                            "about %.3g elements expected (element size %g), more than the limit "
                            "of %zu; ask for larger elements or a smaller domain",
                            spec->expected_elements, spec->mesh.element_size, v->max_elements);
    return 0;
}

static int parse_root(validator *v, const json_t *root, gp_spec *spec)
{
    if (!json_is_object(root))
        return gp_error_set(v->err, GP_EINVAL, "", "must be an object {\"inputs\": {...}}, got %s",
                            type_phrase(root));
    const json_t *inputs = root;
    const char *base = "";
    const json_t *wrapped = json_object_get(root, "inputs");
    if (wrapped) {
        /* an OGC API - Processes execute request: outputs/response/subscriber are allowed
         * and have no effect on the packing */
        static const char *const members[] = {"inputs", "outputs", "response", "subscriber", NULL};
        int rc = spec_check_members(v, root, "", members, "inputs, outputs, response, subscriber");
        if (rc)
            return rc;
        if (!json_is_object(wrapped))
            return gp_error_set(v->err, GP_EINVAL, "/inputs", "must be an object, got %s",
                                type_phrase(wrapped));
        inputs = wrapped;
        base = "/inputs";
    }
    static const char *const members[] = {"domain", "distribution", "joint", "seed", "front",
                                          "balance", "laguerre", "mesh", "picture", NULL};
    int rc;
    if ((rc = spec_check_members(v, inputs, base, members,
                            "domain, distribution, joint, seed, front, balance, laguerre, mesh, "
                            "picture")) ||
        (rc = parse_domain(v, inputs, base, &spec->domain)) ||
        (rc = spec_parse_distribution(v, inputs, base, &spec->dist)) ||
        (rc = spec_parse_joint(v, inputs, base, &spec->joint)) ||
        (rc = spec_parse_seed(v, inputs, base, &spec->seed)) ||
        (rc = parse_front(v, inputs, base, &spec->level_band, &spec->level_band_set)) ||
        (rc = spec_parse_balance(v, inputs, base, &spec->balance_enabled, &spec->balance)) ||
        (rc = spec_parse_laguerre(v, inputs, base, &spec->laguerre_enabled, &spec->laguerre)) ||
        (rc = parse_mesh(v, inputs, base, spec)) ||
        (rc = parse_picture(v, inputs, base, spec)) || (rc = check_whole(v, base, spec)))
        return rc;
    if (gp_distribution_prepare(&spec->dist))
        return gp_error_set(v->err, GP_ENOMEM, "", "out of memory");
    return 0;
}

/* Sets up the validator for `limits` (NULL: the defaults) and parses the text: 0 with
 * *root the caller's (json_decref), or GP_EPARSE with err set. */
static int load_json(const char *text, size_t len, const gp_spec_limits *limits, gp_error *err,
                     validator *v, json_t **root)
{
    *root = NULL;
    *v = (validator){err, GP_SPEC_DEFAULT_MAX_DISKS, GP_SPEC_DEFAULT_MAX_BINS,
                     GP_SPEC_DEFAULT_MAX_ELEMENTS};
    if (limits && limits->max_disks)
        v->max_disks = limits->max_disks;
    if (limits && limits->max_bins)
        v->max_bins = limits->max_bins;
    if (limits && limits->max_elements)
        v->max_elements = limits->max_elements;
    /* jansson reads a NUL byte between tokens as if it were white space; JSON has none */
    const char *nul = memchr(text, '\0', len);
    if (nul)
        return gp_error_set(err, GP_EPARSE, "", "a NUL byte at offset %zu: JSON text has none",
                            (size_t)(nul - text));
    json_error_t jerr;
    /* any JSON value is well-formed: `null` or `5` is valid JSON that is not a spec, so
     * it is refused as invalid (with what it is), not as malformed */
    *root = json_loadb(text, len, JSON_REJECT_DUPLICATES | JSON_DECODE_ANY, &jerr);
    if (!*root)
        return gp_error_set(err, GP_EPARSE, "", "line %d, column %d: %s", jerr.line, jerr.column,
                            jerr.text);
    return 0;
}

int spec_parse_text(const char *text, size_t len, const gp_spec_limits *limits, gp_error *err,
                    int (*parse)(validator *v, const json_t *root, void *spec), void *spec)
{
    validator v;
    json_t *root = NULL;
    int rc = load_json(text, len, limits, err, &v, &root);
    if (rc == 0)
        rc = parse(&v, root, spec);
    json_decref(root);
    return rc;
}

static int parse_root_2d(validator *v, const json_t *root, void *spec)
{
    return parse_root(v, root, spec);
}

int gp_spec_parse(const char *text, size_t len, const gp_spec_limits *limits, gp_spec *spec,
                  gp_error *err)
{
    memset(spec, 0, sizeof *spec);
    int rc = spec_parse_text(text, len, limits, err, parse_root_2d, spec);
    if (rc)
        gp_spec_free(spec);
    return rc;
}

/* Room a spec file read asks for at each fread beyond what it holds: specs are a few
 * hundred bytes to a few megabytes (a long histogram); the buffer doubles as it fills. */
#define READ_CHUNK 4096

int gp_spec_read_text(const char *path, char **text_out, size_t *len_out, gp_error *err)
{
    *text_out = NULL;
    *len_out = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return gp_error_set(err, GP_EIO, NULL, "cannot open %s: %s", path, strerror(errno));
    char *text = NULL;
    size_t len = 0, cap = 0;
    int rc = 0;
    for (;;) {
        char *grown = grow(text, &cap, len + READ_CHUNK, 1);
        if (!grown) {
            rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory reading %s", path);
            break;
        }
        text = grown;
        size_t got = fread(text + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            if (ferror(f))
                rc = gp_error_set(err, GP_EIO, NULL, "cannot read %s: %s", path, strerror(errno));
            break;
        }
    }
    fclose(f);
    if (rc) {
        free(text);
        return rc;
    }
    *text_out = text;
    *len_out = len;
    return 0;
}

int spec_load_file(const char *path, const gp_spec_limits *limits, gp_error *err,
                   int (*parse)(const char *text, size_t len, const gp_spec_limits *limits,
                                void *spec, gp_error *err),
                   void *spec)
{
    char *text;
    size_t len;
    int rc = gp_spec_read_text(path, &text, &len, err);
    if (rc == 0)
        rc = parse(text, len, limits, spec, err);
    free(text);
    return rc;
}

static int parse_2d(const char *text, size_t len, const gp_spec_limits *limits, void *spec, gp_error *err)
{
    return gp_spec_parse(text, len, limits, spec, err);
}

int gp_spec_load_file(const char *path, const gp_spec_limits *limits, gp_spec *spec,
                      gp_error *err)
{
    memset(spec, 0, sizeof *spec);
    return spec_load_file(path, limits, err, parse_2d, spec);
}

gp_pack_params gp_spec_pack_params(const gp_spec *spec, size_t max_disks)
{
    gp_pack_params params = {
        .domain = &spec->domain,
        .dist = &spec->dist,
        .joint = &spec->joint,
        .seed = spec->seed,
        .max_disks = max_disks,
        .level_band = spec->level_band,
        .rule = spec->level_band_set ? GP_FRONT_LEVEL_BAND : GP_FRONT_DEFAULT,
    };
    return params;
}

void gp_spec_free(gp_spec *spec)
{
    gp_distribution_free(&spec->dist);
    memset(spec, 0, sizeof *spec);
}
