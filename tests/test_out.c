/* test_out.c - the writers' number formats read back exactly, and the buffered sink keeps
 * every byte in order whatever its size. */
#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "grainpack/error.h"
#include "grainpack/out.h"
#include "grainpack/rng.h"

/* Formats x, reads it back with strtod, compares the bits (so -0 and 0 differ). */
static int round_trips(double x)
{
    char text[GP_FMT_DOUBLE_MAX + 1];
    size_t n = gp_fmt_double(text, x);
    if (n == 0 || n > GP_FMT_DOUBLE_MAX || text[n] != '\0')
        return 0;
    char *end = NULL;
    double back = strtod(text, &end);
    if (*end != '\0')
        return 0;
    return memcmp(&back, &x, sizeof x) == 0;
}

static void test_shortest_double_reads_back_to_the_same_bits(void)
{
    gp_rng rng;
    gp_rng_seed(&rng, 2026);
    size_t failures = 0;
    for (int i = 0; i < 1000000; i++) {
        uint64_t bits = gp_rng_next(&rng);
        double x;
        memcpy(&x, &bits, sizeof x);
        if (!isfinite(x))
            continue;
        if (!round_trips(x) && failures++ < 5)
            CHECK_MSG(0, "random bits %016llx do not read back", (unsigned long long)bits);
    }
    for (int i = 0; i < 100000; i++) { /* values of everyday size */
        double x = (gp_rng_uniform(&rng) - 0.5) * 1000.0;
        if (!round_trips(x) && failures++ < 5)
            CHECK_MSG(0, "%.17g does not read back", x);
    }
    CHECK(failures == 0);
    const double special[] = {0.0, -0.0, 1.0, -1.0, 0.1, 0.06, 1e-6, 1e-7, 1e21, 1e22, 123456789.0,
                              9007199254740993.0, DBL_MAX, -DBL_MAX, DBL_MIN, DBL_TRUE_MIN,
                              4.9406564584124654e-324, 2.2250738585072009e-308, 1e-300, 1e300,
                              0.3, 2.0 / 3.0, 506.0, 0.42};
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
        CHECK_MSG(round_trips(special[i]), "%.17g does not read back", special[i]);
}

static void test_shortest_double_is_the_short_form(void)
{
    char text[GP_FMT_DOUBLE_MAX + 1];
    gp_fmt_double(text, 0.06);
    CHECK_STR(text, "0.06"); /* %.17g wrote 0.059999999999999998 */
    gp_fmt_double(text, 100.0);
    CHECK_STR(text, "100");
    gp_fmt_double(text, 1e-7);
    CHECK_STR(text, "1e-7");
    gp_fmt_double(text, 1.5e300);
    CHECK_STR(text, "1.5e+300");
    gp_fmt_double(text, -2.5);
    CHECK_STR(text, "-2.5");
    gp_fmt_double(text, NAN);
    CHECK_STR(text, "NaN");
    gp_fmt_double(text, -INFINITY);
    CHECK_STR(text, "-Infinity");
}

/* Memory mode: everything written, taken back in pieces. */
static char *render_fixed(double x, int decimals)
{
    static char text[64];
    gp_out o;
    CHECK(gp_out_init(&o, 4, NULL, NULL) == 0);
    gp_out_fixed(&o, x, decimals);
    size_t n = gp_out_take(&o, text, sizeof text - 1);
    text[n] = '\0';
    CHECK(o.err == 0 && o.len == 0);
    gp_out_free(&o);
    return text;
}

static void test_fixed_rounds_and_drops_trailing_zeros(void)
{
    CHECK_STR(render_fixed(12.3456, 2), "12.35");
    CHECK_STR(render_fixed(12.0, 2), "12");
    CHECK_STR(render_fixed(12.10, 2), "12.1");
    CHECK_STR(render_fixed(-0.004, 2), "0");
    CHECK_STR(render_fixed(-0.006, 2), "-0.01");
    CHECK_STR(render_fixed(0.05, 3), "0.05");
    CHECK_STR(render_fixed(999.9996, 3), "1000");
    CHECK_STR(render_fixed(1e300, 2), "1e+300");
}

static void test_integers(void)
{
    gp_out o;
    CHECK(gp_out_init(&o, 1, NULL, NULL) == 0);
    gp_out_int(&o, INT64_MIN);
    gp_out_char(&o, ' ');
    gp_out_uint(&o, UINT64_MAX);
    gp_out_char(&o, ' ');
    gp_out_int(&o, 0);
    char text[80];
    size_t n = gp_out_take(&o, text, sizeof text - 1);
    text[n] = '\0';
    CHECK_STR(text, "-9223372036854775808 18446744073709551615 0");
    gp_out_free(&o);
}

typedef struct collected {
    char data[1 << 16];
    size_t len;
    int calls;
    int fail_after; /* the sink refuses its call number fail_after (0: never) */
} collected;

static int collect(void *ctx, const char *data, size_t len)
{
    collected *c = ctx;
    if (++c->calls == c->fail_after)
        return GP_EIO;
    memcpy(c->data + c->len, data, len);
    c->len += len;
    return 0;
}

static void test_sink_gets_every_byte_in_order_and_keeps_the_first_error(void)
{
    static collected c;
    gp_out o;
    CHECK(gp_out_init(&o, 7, collect, &c) == 0);
    char expect[1 << 15];
    size_t n = 0;
    for (int i = 0; i < 2000; i++) {
        int len = snprintf(expect + n, sizeof expect - n, "%d,", i);
        gp_out_int(&o, i);
        gp_out_char(&o, ',');
        n += (size_t)len;
    }
    gp_out_puts(&o, "a longer piece than the whole buffer");
    memcpy(expect + n, "a longer piece than the whole buffer", 36);
    n += 36;
    CHECK(gp_out_flush(&o) == 0);
    CHECK(c.len == n && memcmp(c.data, expect, n) == 0);
    gp_out_free(&o);

    memset(&c, 0, sizeof c);
    c.fail_after = 3;
    CHECK(gp_out_init(&o, 8, collect, &c) == 0);
    for (int i = 0; i < 100; i++)
        gp_out_puts(&o, "0123456789");
    CHECK(gp_out_flush(&o) == GP_EIO);
    CHECK(c.calls == 3); /* nothing more was sent after the failure */
    gp_out_free(&o);
}

int main(void)
{
    RUN(test_shortest_double_reads_back_to_the_same_bits);
    RUN(test_shortest_double_is_the_short_form);
    RUN(test_fixed_rounds_and_drops_trailing_zeros);
    RUN(test_integers);
    RUN(test_sink_gets_every_byte_in_order_and_keeps_the_first_error);
    return check_status();
}
