/* test_mesh_spec.c - the spec's "mesh" field: defaults, every option read, and every bad
 * option refused before any work with the JSON pointer of the field and what was
 * expected, including a mesh that would need more elements than the cap. */
#include "check.h"
#include "grainpack/spec.h"

#define LAW "\"domain\": {\"width\": 100, \"height\": 100}, \"distribution\": {\"kind\": " \
            "\"constant\", \"radius\": 0.9}, \"joint\": {\"law\": \"constant\", \"value\": 0.1}"

static int parse(const char *json, const gp_spec_limits *limits, gp_spec *spec, gp_error *err)
{
    gp_error_clear(err);
    return gp_spec_parse(json, strlen(json), limits, spec, err);
}

static void refused(const char *json, int code, const char *pointer, const char *words)
{
    gp_spec spec;
    gp_error err;
    int rc = parse(json, NULL, &spec, &err);
    CHECK_MSG(rc == code, "%s: rc %d (%s)", json, rc, err.message);
    CHECK_STR(err.pointer, pointer);
    CHECK_MSG(strstr(err.message, words) != NULL, "\"%s\" lacks \"%s\"", err.message, words);
    if (rc == 0)
        gp_spec_free(&spec);
}

static void test_mesh_is_off_by_default(void)
{
    gp_spec spec;
    gp_error err;
    CHECK(parse("{" LAW "}", NULL, &spec, &err) == 0);
    CHECK(!spec.mesh_enabled);
    gp_spec_free(&spec);
}

static void test_mesh_defaults(void)
{
    gp_spec spec;
    gp_error err;
    CHECK(parse("{" LAW ", \"mesh\": {}}", NULL, &spec, &err) == 0);
    CHECK(spec.mesh_enabled);
    CHECK_NEAR(spec.mesh.element_size, GP_MESH_DEFAULT_SIZE_RATIO * 0.9, 1e-15);
    CHECK_NEAR(spec.mesh.min_angle, GP_MESH_MAX_MIN_ANGLE, 0);
    CHECK(spec.mesh.order == 1 && spec.mesh.band_layers == 0 && spec.mesh.plane == GP_MESH_PLANE_STRESS);
    CHECK(spec.expected_elements > 0.0);
    gp_spec_free(&spec);
}

static void test_mesh_options_read(void)
{
    gp_spec spec;
    gp_error err;
    int rc = parse("{\"inputs\": {" LAW ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": "
                   "{\"element_size\": 0.25, \"min_angle\": 15, \"order\": 2, \"band_layers\": 3, "
                   "\"band_size\": 0.1, \"abaqus\": {\"plane\": \"strain\", \"reduced_integration\": true}}}}",
                   NULL, &spec, &err);
    CHECK_MSG(rc == 0, "%s %s", err.pointer, err.message);
    CHECK_NEAR(spec.mesh.element_size, 0.25, 0);
    CHECK_NEAR(spec.mesh.min_angle, 15, 0);
    CHECK(spec.mesh.order == 2 && spec.mesh.band_layers == 3 && spec.mesh.reduced);
    CHECK(spec.mesh.plane == GP_MESH_PLANE_STRAIN);
    CHECK_NEAR(spec.mesh.band_size, 0.1, 0);
    CHECK(spec.mesh.grading == 1);
    gp_spec_free(&spec);
    /* band_size sizes the band's triangles too: no band_layers needed; grading is read */
    rc = parse("{\"inputs\": {" LAW ", \"laguerre\": {\"shrink\": \"homothetic\"}, \"mesh\": "
               "{\"band_size\": 0.2}}}", NULL, &spec, &err);
    CHECK_MSG(rc == 0, "%s %s", err.pointer, err.message);
    CHECK(spec.mesh.grading == 1 && spec.mesh.band_size == 0.2);
    gp_spec_free(&spec);
    rc = parse("{\"inputs\": {" LAW ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": "
               "{\"grading\": false}}}", NULL, &spec, &err);
    CHECK_MSG(rc == 0, "%s %s", err.pointer, err.message);
    CHECK(spec.mesh.grading == 0);
    gp_spec_free(&spec);
}

static void test_mesh_bad_options_refused_with_pointer(void)
{
    refused("{" LAW ", \"mesh\": {\"element_size\": 0}}", GP_EINVAL, "/mesh/element_size", "(0,");
    refused("{" LAW ", \"mesh\": {\"element_size\": -1}}", GP_EINVAL, "/mesh/element_size", "number");
    refused("{" LAW ", \"mesh\": {\"element_size\": \"big\"}}", GP_EINVAL, "/mesh/element_size", "a string");
    refused("{" LAW ", \"mesh\": {\"min_angle\": 25}}", GP_EINVAL, "/mesh/min_angle", "guaranteed");
    refused("{" LAW ", \"mesh\": {\"min_angle\": 20.71}}", GP_EINVAL, "/mesh/min_angle", "20.70");
    refused("{" LAW ", \"mesh\": {\"min_angle\": -1}}", GP_EINVAL, "/mesh/min_angle", "[0,");
    refused("{" LAW ", \"mesh\": {\"order\": 3}}", GP_EINVAL, "/mesh/order", "from 1 to 2");
    refused("{" LAW ", \"mesh\": {\"order\": 1.5}}", GP_EINVAL, "/mesh/order", "integer");
    refused("{" LAW ", \"mesh\": {\"band_layers\": 2}}", GP_EINVAL, "/mesh/band_layers", "offset");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"homothetic\"}, \"mesh\": {\"band_layers\": 2}}",
            GP_EINVAL, "/mesh/band_layers", "offset");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_layers\": 65}}",
            GP_EINVAL, "/mesh/band_layers", "from 0 to 64");
    refused("{" LAW ", \"mesh\": {\"band_size\": 0.1}}", GP_EINVAL, "/mesh/band_size", "shrink");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"none\"}, \"mesh\": {\"grading\": true}}", GP_EINVAL,
            "/mesh/grading", "shrink");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"grading\": 1}}", GP_EINVAL,
            "/mesh/grading", "true or false");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_size\": 0}}", GP_EINVAL,
            "/mesh/band_size", "(0,");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"grading\": false, "
            "\"band_size\": 0.1}}", GP_EINVAL, "/mesh/band_size", "grading");
    refused("{" LAW ", \"mesh\": {\"disk_tolerance\": 0.5}}", GP_EINVAL, "/mesh/disk_tolerance", "0.25]");
    refused("{" LAW ", \"laguerre\": {\"shrink\": \"none\"}, \"mesh\": {\"disk_tolerance\": 0.1}}",
            GP_EINVAL, "/mesh/disk_tolerance", "Laguerre");
    refused("{" LAW ", \"mesh\": {\"abaqus\": {\"plane\": \"axisymmetric\"}}}", GP_EINVAL,
            "/mesh/abaqus/plane", "stress, strain");
    refused("{" LAW ", \"mesh\": {\"elements\": 5}}", GP_EINVAL, "/mesh/elements", "unknown field");
    refused("{\"inputs\": {" LAW ", \"mesh\": []}}", GP_EINVAL, "/inputs/mesh", "an object");
}

/* Too many elements for the cap: refused at the element size, before any packing. */
static void test_mesh_over_the_element_cap(void)
{
    refused("{" LAW ", \"mesh\": {\"element_size\": 0.001}}", GP_ETOOBIG, "/mesh/element_size",
            "more than the limit of 20000000");
    gp_spec spec;
    gp_error err;
    gp_spec_limits small = {.max_elements = 1000};
    CHECK(parse("{" LAW ", \"mesh\": {}}", &small, &spec, &err) == GP_ETOOBIG);
    CHECK_STR(err.pointer, "/mesh/element_size");
    gp_spec_limits large = {.max_elements = 100000000};
    CHECK(parse("{" LAW ", \"mesh\": {\"element_size\": 0.03}}", &large, &spec, &err) == 0);
    CHECK(spec.max_elements == 100000000);
    gp_spec_free(&spec);
}

int main(void)
{
    RUN(test_mesh_is_off_by_default);
    RUN(test_mesh_defaults);
    RUN(test_mesh_options_read);
    RUN(test_mesh_bad_options_refused_with_pointer);
    RUN(test_mesh_over_the_element_cap);
    return check_status();
}
