/* test_spec3d.c - the 3D spec's "balance" and "laguerre" blocks (spec3d.h): the same
 * fields, defaults and 422 pointers as the 2D spec's. */
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
    return check_status();
}
