/* test_spec.c - the job spec: both accepted shapes, defaults, and every error path with
 * its JSON pointer and message. */
#include <jansson.h>
#include <stdlib.h>

#include "check.h"
#include "grainpack/spec.h"

#define IRON_BINS                                                                            \
    "[{\"min\":2.0,\"max\":2.5,\"p\":0.15801024},{\"min\":2.5,\"max\":3.0,\"p\":0.20994879},"  \
    "{\"min\":3.0,\"max\":3.5,\"p\":0.20994879},{\"min\":3.5,\"max\":4.0,\"p\":0.16605706},"   \
    "{\"min\":4.0,\"max\":4.5,\"p\":0.09802487},{\"min\":4.5,\"max\":5.0,\"p\":0.06730066},"   \
    "{\"min\":5.0,\"max\":5.5,\"p\":0.0380395},{\"min\":5.5,\"max\":6.0,\"p\":0.02926116},"    \
    "{\"min\":6.0,\"max\":6.5,\"p\":0.00731529},{\"min\":6.5,\"max\":7.0,\"p\":0.00658376},"   \
    "{\"min\":7.0,\"max\":7.5,\"p\":0.00658376},{\"min\":7.5,\"max\":8.0,\"p\":0.00292612}]"

static int parse(const char *json, gp_spec *spec, gp_error *err)
{
    gp_error_clear(err);
    return gp_spec_parse(json, strlen(json), NULL, spec, err);
}

static void test_whole_request_and_bare_inputs_both_parse(void)
{
    gp_spec a, b;
    gp_error err;
    const char *inputs = "{\"domain\":{\"width\":237,\"height\":300},\"distribution\":{\"kind\":"
                         "\"histogram\",\"bins\":" IRON_BINS "},\"joint\":{\"law\":\"inverse\",\"k\":2.0},\"seed\":1}";
    char whole[2048];
    snprintf(whole, sizeof whole, "{\"inputs\":%s,\"response\":\"document\"}", inputs);
    CHECK(parse(inputs, &a, &err) == 0);
    CHECK(parse(whole, &b, &err) == 0);
    CHECK(a.domain.width == 237 && a.domain.height == 300);
    CHECK(a.dist.kind == GP_DIST_HISTOGRAM && a.dist.nbins == 12 && a.dist.cdf != NULL);
    CHECK(a.joint.law == GP_JOINT_INVERSE && a.joint.k == 2.0);
    CHECK(b.dist.nbins == 12 && b.seed == 1);
    /* ~0.9 x area / mean packing-disk area: about a thousand disks */
    CHECK(a.expected_disks > 900 && a.expected_disks < 1300);
    gp_spec_free(&a);
    gp_spec_free(&b);
}

static void test_defaults_seed_one_no_joint_band_zero(void)
{
    gp_spec s;
    gp_error err;
    CHECK(parse("{\"domain\":{\"width\":10,\"height\":10},\"distribution\":{\"kind\":\"constant\","
                "\"radius\":0.5}}",
                &s, &err) == 0);
    CHECK(s.seed == GP_SPEC_DEFAULT_SEED && s.joint.law == GP_JOINT_NONE && s.level_band == 0);
    gp_spec_free(&s);
    CHECK(parse("{\"domain\":{\"width\":10,\"height\":10},\"distribution\":{\"kind\":\"uniform\","
                "\"min\":0.1,\"max\":0.5},\"joint\":{\"law\":\"power\",\"k\":1,\"exponent\":-0.5},"
                "\"front\":{\"level_band\":2},\"seed\":12345678901}",
                &s, &err) == 0);
    CHECK(s.seed == 12345678901ULL && s.level_band == 2 && s.joint.exponent == -0.5);
    gp_spec_free(&s);
}

/* One error case: the spec, the code, the pointer and a fragment of the message. */
typedef struct error_case {
    const char *json;
    int code;
    const char *pointer;
    const char *message;
} error_case;

#define DOM "\"domain\":{\"width\":50,\"height\":50}"
#define CONST "\"distribution\":{\"kind\":\"constant\",\"radius\":0.5}"

static const error_case errors[] = {
    {"{\"inputs\": {", GP_EPARSE, "", "line 1"},
    {"null", GP_EINVAL, "", "got null"},
    {" 42 ", GP_EINVAL, "", "got an integer"},
    {"[1,2]", GP_EINVAL, "", "must be an object"},
    {"{\"inputs\":[]}", GP_EINVAL, "/inputs", "must be an object, got an array"},
    {"{\"inputs\":{" DOM "," CONST "},\"extra\":1}", GP_EINVAL, "/extra", "unknown field"},
    {"{" DOM "," CONST ",\"colour\":\"red\"}", GP_EINVAL, "/colour", "unknown field; expected one of"},
    {"{" CONST "}", GP_EINVAL, "/domain", "missing; expected an object"},
    {"{\"domain\":5," CONST "}", GP_EINVAL, "/domain", "must be an object, got an integer"},
    {"{\"domain\":{\"width\":50}," CONST "}", GP_EINVAL, "/domain/height", "missing"},
    {"{\"domain\":{\"width\":-1,\"height\":5}," CONST "}", GP_EINVAL, "/domain/width", "must be > 0, got -1"},
    {"{\"domain\":{\"width\":\"5\",\"height\":5}," CONST "}", GP_EINVAL, "/domain/width", "got a string"},
    {"{\"domain\":{\"width\":5,\"height\":5,\"depth\":1}," CONST "}", GP_EINVAL, "/domain/depth", "unknown field"},
    {"{" DOM "}", GP_EINVAL, "/distribution", "missing"},
    {"{" DOM ",\"distribution\":{\"kind\":\"normal\"}}", GP_EINVAL, "/distribution/kind", "must be one of constant, uniform, histogram, got \"normal\""},
    {"{" DOM ",\"distribution\":{\"radius\":1}}", GP_EINVAL, "/distribution/kind", "missing"},
    {"{" DOM ",\"distribution\":{\"kind\":7}}", GP_EINVAL, "/distribution/kind", "got an integer"},
    {"{" DOM ",\"distribution\":{\"kind\":\"constant\",\"radius\":0}}", GP_EINVAL, "/distribution/radius", "must be > 0, got 0"},
    {"{" DOM ",\"distribution\":{\"kind\":\"constant\",\"radius\":0.5,\"min\":1}}", GP_EINVAL, "/distribution/min", "unknown field"},
    {"{" DOM ",\"distribution\":{\"kind\":\"uniform\",\"min\":0.4,\"max\":0.2}}", GP_EINVAL, "/distribution/max", "must be > 0.4, got 0.2"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\"}}", GP_EINVAL, "/distribution/bins", "missing"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":{}}}", GP_EINVAL, "/distribution/bins", "must be an array"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[]}}", GP_EINVAL, "/distribution/bins", "at least one bin"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[3]}}", GP_EINVAL, "/distribution/bins/0", "must be an object"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,\"p\":0.5},{\"min\":2,\"max\":3,\"p\":0.6},{\"min\":3,\"max\":4,\"p\":-0.1}]}}",
     GP_EINVAL, "/distribution/bins/2/p", "must be >= 0, got -0.1"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,\"p\":1.5}]}}", GP_EINVAL, "/distribution/bins/0/p", "must be <= 1"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2}]}}", GP_EINVAL, "/distribution/bins/0/p", "missing"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,\"p\":1,\"q\":0}]}}", GP_EINVAL, "/distribution/bins/0/q", "unknown field"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":1,\"p\":1}]}}", GP_EINVAL, "/distribution/bins/0/max", "must be > 1"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,\"p\":0.5},{\"min\":1.5,\"max\":3,\"p\":0.5}]}}",
     GP_EINVAL, "/distribution/bins/1/min", "previous bin's max"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,\"p\":0.5},{\"min\":2,\"max\":3,\"p\":0.4}]}}",
     GP_EINVAL, "/distribution/bins", "must sum to 1 within 1e-06, got 0.9"},
    {"{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,\"p\":0}]}}", GP_EINVAL, "/distribution/bins", "must sum to 1"},
    {"{" DOM "," CONST ",\"joint\":{\"law\":\"log\"}}", GP_EINVAL, "/joint/law", "must be one of none, constant, inverse, power"},
    {"{" DOM "," CONST ",\"joint\":{\"law\":\"constant\",\"value\":-0.1}}", GP_EINVAL, "/joint/value", "must be >= 0, got -0.1"},
    {"{" DOM "," CONST ",\"joint\":{\"law\":\"inverse\"}}", GP_EINVAL, "/joint/k", "missing"},
    {"{" DOM "," CONST ",\"joint\":{\"law\":\"power\",\"k\":1}}", GP_EINVAL, "/joint/exponent", "missing; expected a number"},
    {"{" DOM "," CONST ",\"joint\":{\"law\":\"power\",\"k\":1,\"exponent\":null}}", GP_EINVAL, "/joint/exponent", "got null"},
    {"{" DOM "," CONST ",\"joint\":{\"law\":\"none\",\"k\":1}}", GP_EINVAL, "/joint/k", "unknown field"},
    {"{" DOM "," CONST ",\"joint\":true}", GP_EINVAL, "/joint", "must be an object, got true"},
    {"{" DOM "," CONST ",\"seed\":-3}", GP_EINVAL, "/seed", "must be an integer >= 0, got -3"},
    {"{" DOM "," CONST ",\"seed\":1.5}", GP_EINVAL, "/seed", "got a number"},
    {"{" DOM "," CONST ",\"front\":{\"level_band\":99}}", GP_EINVAL, "/front/level_band", "from 0 to 16, got 99"},
    {"{" DOM "," CONST ",\"front\":{\"band\":1}}", GP_EINVAL, "/front/band", "unknown field"},
    {"{\"domain\":{\"width\":3,\"height\":300},\"distribution\":{\"kind\":\"constant\",\"radius\":2}}", GP_EINVAL, "/distribution",
     "must fit in the domain"},
    {"{\"domain\":{\"width\":10,\"height\":10},\"distribution\":{\"kind\":\"constant\",\"radius\":2},\"joint\":{\"law\":\"power\",\"k\":1,\"exponent\":1e300}}",
     GP_EINVAL, "/joint", "non-finite"},
    {"{\"domain\":{\"width\":1e5,\"height\":1e5}," CONST "}", GP_ETOOBIG, "/domain", "more than the limit of 20000000"},
    {"{\"domain\":{\"width\":5,\"height\":5}," CONST ",\"domain\":{\"width\":6,\"height\":6}}", GP_EPARSE, "", "duplicate"},
    {"{" DOM "," CONST ",\"balance\":[]}", GP_EINVAL, "/balance", "must be an object, got an array"},
    {"{" DOM "," CONST ",\"balance\":{}}", GP_EINVAL, "/balance/method", "missing; expected one of none, laplacian, relocation"},
    {"{" DOM "," CONST ",\"balance\":{\"method\":\"jiggle\"}}", GP_EINVAL, "/balance/method", "got \"jiggle\""},
    {"{" DOM "," CONST ",\"balance\":{\"method\":\"relocation\",\"sweeps\":3}}", GP_EINVAL, "/balance/sweeps", "unknown field; expected one of method, max_iterations, max_step"},
    {"{" DOM "," CONST ",\"balance\":{\"method\":\"relocation\",\"max_iterations\":0}}", GP_EINVAL, "/balance/max_iterations", "from 1 to 100000, got 0"},
    {"{" DOM "," CONST ",\"balance\":{\"method\":\"relocation\",\"max_iterations\":2.5}}", GP_EINVAL, "/balance/max_iterations", "got a number"},
    {"{" DOM "," CONST ",\"balance\":{\"method\":\"laplacian\",\"max_step\":0.01}}", GP_EINVAL, "/balance/max_step", "must be >= 0.05, got 0.01"},
    {"{" DOM "," CONST ",\"balance\":{\"method\":\"laplacian\",\"max_step\":1.5}}", GP_EINVAL, "/balance/max_step", "must be <= 1"},
    {"{" DOM "," CONST ",\"laguerre\":{}}", GP_EINVAL, "/laguerre/shrink", "missing; expected one of homothetic, offset, none"},
    {"{" DOM "," CONST ",\"laguerre\":{\"shrink\":\"erode\"}}", GP_EINVAL, "/laguerre/shrink", "got \"erode\""},
    {"{" DOM "," CONST ",\"laguerre\":{\"shrink\":\"offset\",\"flush_boundary\":1}}", GP_EINVAL, "/laguerre/flush_boundary", "must be true or false, got an integer"},
    {"{" DOM "," CONST ",\"laguerre\":{\"shrink\":\"offset\",\"shrunk\":true}}", GP_EINVAL, "/laguerre/shrunk", "unknown field"},
    {"{" DOM "," CONST ",\"picture\":{\"color\":\"quality\"}}", GP_EINVAL, "/picture/color", "needs the balance stage"},
    {"{" DOM "," CONST ",\"picture\":{\"color\":\"blue\"}}", GP_EINVAL, "/picture/color", "must be one of radius, quality"},
    {"{" DOM "," CONST ",\"picture\":{\"disks\":\"yes\"}}", GP_EINVAL, "/picture/disks", "must be true or false, got a string"},
    {"{\"inputs\":{" DOM "," CONST ",\"balance\":{\"method\":\"none\",\"max_step\":\"big\"}}}", GP_EINVAL, "/inputs/balance/max_step", "got a string"},
};

static void test_balance_laguerre_and_picture_fields(void)
{
    gp_spec s;
    gp_error err;
    /* absent: both stages off, pictures coloured by radius */
    CHECK(parse("{" DOM "," CONST "}", &s, &err) == 0);
    CHECK(!s.balance_enabled && !s.laguerre_enabled && s.picture_color == GP_PICTURE_COLOR_RADIUS && !s.picture_disks);
    gp_spec_free(&s);
    /* present: defaults filled in, pictures coloured by F once there is an F */
    CHECK(parse("{" DOM "," CONST ",\"balance\":{\"method\":\"relocation\"},\"laguerre\":{\"shrink\":\"homothetic\"}}", &s, &err) == 0);
    CHECK(s.balance_enabled && s.balance.method == GP_BALANCE_RELOCATION);
    CHECK(s.balance.max_iterations == GP_BALANCE_DEFAULT_MAX_ITERATIONS && s.balance.max_step == GP_BALANCE_DEFAULT_MAX_STEP);
    CHECK(s.laguerre_enabled && s.laguerre.shrink == GP_SHRINK_HOMOTHETIC && !s.laguerre.flush_boundary);
    CHECK(s.picture_color == GP_PICTURE_COLOR_QUALITY);
    gp_spec_free(&s);
    CHECK(parse("{" DOM "," CONST ",\"balance\":{\"method\":\"laplacian\",\"max_iterations\":7,\"max_step\":0.3},"
                "\"laguerre\":{\"shrink\":\"offset\",\"flush_boundary\":true},\"picture\":{\"color\":\"radius\",\"disks\":true}}",
                &s, &err) == 0);
    CHECK(s.balance.method == GP_BALANCE_LAPLACIAN && s.balance.max_iterations == 7 && s.balance.max_step == 0.3);
    CHECK(s.laguerre.shrink == GP_SHRINK_OFFSET && s.laguerre.flush_boundary);
    CHECK(s.picture_color == GP_PICTURE_COLOR_RADIUS && s.picture_disks);
    gp_spec_free(&s);
    CHECK(parse("{" DOM "," CONST ",\"balance\":{\"method\":\"none\"},\"laguerre\":{\"shrink\":\"none\"}}", &s, &err) == 0);
    CHECK(s.balance_enabled && s.balance.method == GP_BALANCE_NONE && s.laguerre_enabled && s.laguerre.shrink == GP_SHRINK_NONE);
    gp_spec_free(&s);
}

static void test_each_error_names_the_field_and_the_expectation(void)
{
    for (size_t i = 0; i < sizeof errors / sizeof errors[0]; i++) {
        const error_case *c = &errors[i];
        gp_spec s;
        gp_error err;
        int rc = parse(c->json, &s, &err);
        CHECK_MSG(rc == c->code, "case %zu: code %d, expected %d (%s %s)", i, rc, c->code, err.pointer, err.message);
        CHECK_MSG(strcmp(err.pointer, c->pointer) == 0, "case %zu: pointer \"%s\", expected \"%s\"", i,
                  err.pointer, c->pointer);
        CHECK_MSG(strstr(err.message, c->message) != NULL, "case %zu: message \"%s\" lacks \"%s\"", i,
                  err.message, c->message);
        CHECK_MSG(s.dist.bins == NULL && s.dist.cdf == NULL, "case %zu: spec not left empty", i);
    }
}

static void test_pointers_in_a_wrapped_request_start_with_inputs(void)
{
    gp_spec s;
    gp_error err;
    CHECK(parse("{\"inputs\":{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,"
                "\"max\":2,\"p\":-0.1}]}}}",
                &s, &err) == GP_EINVAL);
    CHECK_STR(err.pointer, "/inputs/distribution/bins/0/p");
}

static void test_keys_are_escaped_in_pointers(void)
{
    gp_spec s;
    gp_error err;
    CHECK(parse("{" DOM "," CONST ",\"a/b~c\":1}", &s, &err) == GP_EINVAL);
    CHECK_STR(err.pointer, "/a~1b~0c");
}

static void test_caps_are_configurable(void)
{
    const char *json = "{\"domain\":{\"width\":100,\"height\":100}," CONST "}";
    gp_spec s;
    gp_error err;
    gp_spec_limits small = {.max_disks = 1000};
    CHECK(gp_spec_parse(json, strlen(json), &small, &s, &err) == GP_ETOOBIG);
    CHECK(strstr(err.message, "1000") != NULL);
    gp_spec_limits few_bins = {.max_bins = 1};
    const char *two = "{" DOM ",\"distribution\":{\"kind\":\"histogram\",\"bins\":[{\"min\":1,\"max\":2,"
                      "\"p\":0.5},{\"min\":2,\"max\":3,\"p\":0.5}]}}";
    CHECK(gp_spec_parse(two, strlen(two), &few_bins, &s, &err) == GP_ETOOBIG);
    CHECK_STR(err.pointer, "/distribution/bins");
}

static void test_example_files_load(void)
{
    static const char *const names[] = {"fixed", "variable", "iron", "bagi"};
    for (size_t i = 0; i < 4; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s.json", GP_EXAMPLES_DIR, names[i]);
        gp_spec s;
        gp_error err;
        CHECK_MSG(gp_spec_load_file(path, NULL, &s, &err) == 0, "%s: %s", path, err.message);
        gp_spec_free(&s);
    }
    gp_spec s;
    gp_error err;
    CHECK(gp_spec_load_file("/nonexistent/spec.json", NULL, &s, &err) == GP_EIO);
    CHECK(strstr(err.message, "/nonexistent/spec.json") != NULL);
}

/* Whether two parsed specs are the same job: every field the stages read. */
static int same_spec(const gp_spec *a, const gp_spec *b)
{
    int same = a->domain.width == b->domain.width && a->domain.height == b->domain.height &&
               a->dist.kind == b->dist.kind && a->dist.radius == b->dist.radius &&
               a->dist.min == b->dist.min && a->dist.max == b->dist.max &&
               a->dist.nbins == b->dist.nbins && a->joint.law == b->joint.law &&
               a->joint.value == b->joint.value && a->joint.k == b->joint.k &&
               a->joint.exponent == b->joint.exponent && a->seed == b->seed &&
               a->level_band == b->level_band && a->expected_disks == b->expected_disks &&
               a->balance_enabled == b->balance_enabled &&
               a->balance.method == b->balance.method &&
               a->balance.max_iterations == b->balance.max_iterations &&
               a->balance.max_step == b->balance.max_step &&
               a->laguerre_enabled == b->laguerre_enabled &&
               a->laguerre.shrink == b->laguerre.shrink &&
               a->laguerre.flush_boundary == b->laguerre.flush_boundary &&
               a->picture_color == b->picture_color && a->picture_disks == b->picture_disks;
    for (size_t i = 0; same && i < a->dist.nbins; i++)
        same = a->dist.bins[i].min == b->dist.bins[i].min &&
               a->dist.bins[i].max == b->dist.bins[i].max && a->dist.bins[i].p == b->dist.bins[i].p;
    return same;
}

static void test_spec_json_reads_back_as_the_same_spec_with_defaults_explicit(void)
{
    static const char *const specs[] = {
        "{\"inputs\":{\"domain\":{\"width\":237,\"height\":300},\"distribution\":{\"kind\":"
        "\"histogram\",\"bins\":" IRON_BINS "},\"joint\":{\"law\":\"inverse\",\"k\":2.0}}}",
        "{" DOM "," CONST "}",
        "{\"domain\":{\"width\":10.1,\"height\":0.7e1},\"distribution\":{\"kind\":\"uniform\","
        "\"min\":0.1,\"max\":0.3},\"joint\":{\"law\":\"power\",\"k\":0.1,\"exponent\":-0.5},"
        "\"front\":{\"level_band\":3},\"seed\":9223372036854775807}",
        "{" DOM "," CONST ",\"joint\":{\"law\":\"constant\",\"value\":0.1},\"balance\":"
        "{\"method\":\"laplacian\",\"max_iterations\":7,\"max_step\":0.3},\"laguerre\":"
        "{\"shrink\":\"offset\",\"flush_boundary\":true},\"picture\":{\"color\":\"radius\","
        "\"disks\":true}}",
        "{" DOM "," CONST ",\"balance\":{\"method\":\"relocation\"},\"laguerre\":{\"shrink\":"
        "\"homothetic\"}}",
    };
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++) {
        gp_spec a, b;
        gp_error err;
        CHECK_MSG(parse(specs[i], &a, &err) == 0, "case %zu: %s %s", i, err.pointer, err.message);
        json_t *first = gp_spec_json(&a);
        CHECK(first != NULL);
        char *text = json_dumps(first, JSON_COMPACT);
        CHECK_MSG(parse(text, &b, &err) == 0, "case %zu: %s does not parse: %s %s", i, text,
                  err.pointer, err.message);
        CHECK_MSG(same_spec(&a, &b), "case %zu: %s is another spec", i, text);
        json_t *second = gp_spec_json(&b);
        CHECK_MSG(json_equal(first, second), "case %zu: not a fixed point", i);
        /* the defaults are written out: a reader sees what the job will do */
        CHECK(json_integer_value(json_object_get(first, "seed")) == (json_int_t)a.seed);
        CHECK(json_object_get(json_object_get(first, "joint"), "law") != NULL);
        CHECK(json_object_get(json_object_get(first, "front"), "level_band") != NULL);
        CHECK(json_object_get(json_object_get(first, "picture"), "color") != NULL);
        CHECK((json_object_get(first, "balance") != NULL) == a.balance_enabled);
        if (a.balance_enabled)
            CHECK(json_integer_value(json_object_get(json_object_get(first, "balance"),
                                                     "max_iterations")) == a.balance.max_iterations);
        free(text);
        json_decref(first);
        json_decref(second);
        gp_spec_free(&a);
        gp_spec_free(&b);
    }
}

int main(void)
{
    RUN(test_whole_request_and_bare_inputs_both_parse);
    RUN(test_defaults_seed_one_no_joint_band_zero);
    RUN(test_balance_laguerre_and_picture_fields);
    RUN(test_each_error_names_the_field_and_the_expectation);
    RUN(test_pointers_in_a_wrapped_request_start_with_inputs);
    RUN(test_keys_are_escaped_in_pointers);
    RUN(test_caps_are_configurable);
    RUN(test_example_files_load);
    RUN(test_spec_json_reads_back_as_the_same_spec_with_defaults_explicit);
    return check_status();
}
