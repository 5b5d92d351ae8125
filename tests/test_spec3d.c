/* test_spec3d.c - the 3D spec's "balance" and "laguerre" blocks (spec3d.h): the same
 * fields, defaults and 422 pointers as the 2D spec's; the box's "periodic" (2D's shape
 * with "z"), its minimum side and the stages not yet on periodic boxes. */
#include <string.h>

#include "check.h"
#include "grainpack/spec3d.h"

#define BOX "\"domain\": {\"width\": 10, \"height\": 10, \"depth\": 10}, " \
            "\"distribution\": {\"kind\": \"constant\", \"radius\": 0.5}"

static int parse(const char *text, gp_spec3d *spec, gp_error *err)
{
    return gp_spec3d_parse(text, strlen(text), NULL, spec, err);
}

static void test_blocks(void)
{
    gp_spec3d s;
    gp_error err;
    CHECK(parse("{" BOX "}", &s, &err) == 0);
    CHECK(!s.balance_enabled && !s.laguerre_enabled);
    gp_spec3d_free(&s);
    CHECK(parse("{\"inputs\": {" BOX ", \"balance\": {\"method\": \"relocation\"}, "
                "\"laguerre\": {\"shrink\": \"offset\", \"flush_boundary\": true}}}", &s, &err) == 0);
    CHECK(s.balance_enabled && s.balance.method == GP_BALANCE_RELOCATION);
    CHECK(s.balance.max_iterations == GP_BALANCE_DEFAULT_MAX_ITERATIONS);
    CHECK(s.balance.max_step == GP_BALANCE_DEFAULT_MAX_STEP);
    CHECK(s.laguerre_enabled && s.laguerre.shrink == GP_SHRINK_OFFSET && s.laguerre.flush_boundary);
    gp_spec3d_free(&s);
    CHECK(parse("{" BOX ", \"balance\": {\"method\": \"laplacian\", \"max_iterations\": 7, \"max_step\": 0.3}}",
                &s, &err) == 0);
    CHECK(s.balance.method == GP_BALANCE_LAPLACIAN && s.balance.max_iterations == 7 && s.balance.max_step == 0.3);
    gp_spec3d_free(&s);
}

#define CUBE(periodic) \
    "\"domain\": {\"width\": 10, \"height\": 10, \"depth\": 10, \"periodic\": " periodic "}, " \
    "\"distribution\": {\"kind\": \"constant\", \"radius\": 0.5}"

static void test_periodic(void)
{
    static const struct {
        const char *json;
        unsigned periodic;
    } good[] = {
        {"{" BOX "}", 0},
        {"{" CUBE("false") "}", 0},
        {"{" CUBE("true") "}", GP_PERIODIC_X | GP_PERIODIC_Y | GP_PERIODIC_Z},
        {"{" CUBE("[]") "}", 0},
        {"{\"inputs\": {" CUBE("[\"z\"]") "}}", GP_PERIODIC_Z},
        {"{" CUBE("[\"y\", \"x\"]") "}", GP_PERIODIC_X | GP_PERIODIC_Y},
    };
    for (size_t k = 0; k < sizeof good / sizeof good[0]; k++) {
        gp_spec3d s;
        gp_error err;
        int rc = parse(good[k].json, &s, &err);
        CHECK_MSG(rc == 0, "%s: %s", good[k].json, err.message);
        CHECK_MSG(rc || s.box.periodic == good[k].periodic, "%s: %u", good[k].json, s.box.periodic);
        if (!rc)
            gp_spec3d_free(&s);
    }
    /* what the refusals say */
    gp_spec3d s;
    gp_error err;
    CHECK(parse("{" CUBE("[\"x\", \"w\"]") "}", &s, &err) == GP_EINVAL &&
          strstr(err.message, "\"x\", \"y\" or \"z\""));
    CHECK(parse("{\"domain\": {\"width\": 10, \"height\": 10, \"depth\": 5.9, \"periodic\": true}, "
                "\"distribution\": {\"kind\": \"constant\", \"radius\": 0.5}}",
                &s, &err) == GP_EINVAL &&
          strstr(err.message, "at least 12 largest packing radii") && strstr(err.message, "depth is 5.9"));
    CHECK(parse("{" CUBE("true") ", \"laguerre\": {\"shrink\": \"offset\"}}", &s, &err) == GP_EINVAL &&
          strstr(err.message, "not yet available on periodic boxes"));
}

static void test_refusals(void)
{
    static const struct {
        const char *json, *pointer;
    } bad[] = {
        {"{\"inputs\": {" BOX ", \"balance\": {\"method\": \"shake\"}}}", "/inputs/balance/method"},
        {"{" BOX ", \"balance\": {\"method\": \"relocation\", \"max_step\": 2}}", "/balance/max_step"},
        {"{" BOX ", \"balance\": {\"method\": \"relocation\", \"max_iterations\": 0}}", "/balance/max_iterations"},
        {"{" BOX ", \"balance\": {\"method\": \"relocation\", \"speed\": 1}}", "/balance/speed"},
        {"{" BOX ", \"balance\": 3}", "/balance"},
        {"{" BOX ", \"laguerre\": {\"shrink\": \"squash\"}}", "/laguerre/shrink"},
        {"{" BOX ", \"laguerre\": {\"shrink\": \"offset\", \"flush_boundary\": 1}}", "/laguerre/flush_boundary"},
        {"{" BOX ", \"mesh\": {}}", "/mesh"},
        {"{" CUBE("1") "}", "/domain/periodic"},
        {"{" CUBE("\"x\"") "}", "/domain/periodic"},
        {"{\"inputs\": {" CUBE("[\"x\", \"w\"]") "}}", "/inputs/domain/periodic/1"},
        {"{" CUBE("[\"z\", \"z\"]") "}", "/domain/periodic/1"},
        {"{" CUBE("[\"x\", 2]") "}", "/domain/periodic/1"},
        /* a periodic side under 12 R_max (6 here); the same side walled is fine */
        {"{\"inputs\": {\"domain\": {\"width\": 10, \"height\": 5.9, \"depth\": 10, \"periodic\": [\"y\"]}, "
         "\"distribution\": {\"kind\": \"constant\", \"radius\": 0.5}}}",
         "/inputs/domain/periodic"},
        /* balancing and polyhedra: not yet on periodic boxes */
        {"{\"inputs\": {" CUBE("true") ", \"balance\": {\"method\": \"relocation\"}}}", "/inputs/balance"},
        {"{\"inputs\": {" CUBE("[\"x\"]") ", \"laguerre\": {\"shrink\": \"offset\"}}}", "/inputs/laguerre"},
        {"{" CUBE("true") ", \"balance\": {\"method\": \"relocation\"}, \"laguerre\": {\"shrink\": \"offset\"}}", "/balance"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        gp_spec3d s;
        gp_error err;
        int rc = parse(bad[k].json, &s, &err);
        CHECK_MSG(rc == GP_EINVAL, "%s: %d", bad[k].json, rc);
        if (rc == GP_EINVAL)
            CHECK_STR(err.pointer, bad[k].pointer);
    }
}

int main(void)
{
    RUN(test_blocks);
    RUN(test_refusals);
    RUN(test_periodic);
    return check_status();
}
