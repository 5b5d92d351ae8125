/* out.c - the buffered sink of every writer, and integer and fixed-point formatting. */
#include "grainpack/out.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"

int gp_out_init(gp_out *o, size_t capacity, gp_out_sink sink, void *ctx)
{
    memset(o, 0, sizeof *o);
    if (capacity == 0)
        capacity = GP_OUT_DEFAULT_CAPACITY;
    o->buf = malloc(capacity);
    if (!o->buf)
        return GP_ENOMEM;
    o->cap = capacity;
    o->sink = sink;
    o->ctx = ctx;
    return 0;
}

static int file_sink(void *ctx, const char *data, size_t len)
{
    return fwrite(data, 1, len, (FILE *)ctx) == len ? 0 : GP_EIO;
}

int gp_out_init_file(gp_out *o, FILE *file)
{
    return gp_out_init(o, 0, file_sink, file);
}

int gp_out_flush(gp_out *o)
{
    if (o->err || !o->sink || o->len == 0)
        return o->err;
    int rc = o->sink(o->ctx, o->buf, o->len);
    o->len = 0;
    if (rc)
        o->err = rc;
    return o->err;
}

/* Makes room for `len` more bytes: flushes to the sink, or grows the buffer in memory
 * mode. Returns 0 when the bytes fit. */
static int reserve(gp_out *o, size_t len)
{
    if (o->err)
        return o->err;
    if (o->cap - o->len >= len)
        return 0;
    if (o->sink) {
        if (gp_out_flush(o))
            return o->err;
        if (o->cap >= len)
            return 0;
    }
    size_t cap = o->cap ? o->cap : GP_OUT_DEFAULT_CAPACITY;
    while (cap - o->len < len) {
        if (cap > SIZE_MAX / 2) {
            o->err = GP_ENOMEM;
            return o->err;
        }
        cap *= 2;
    }
    char *grown = realloc(o->buf, cap);
    if (!grown) {
        o->err = GP_ENOMEM;
        return o->err;
    }
    o->buf = grown;
    o->cap = cap;
    return 0;
}

void gp_out_write(gp_out *o, const void *data, size_t len)
{
    if (reserve(o, len) == 0) {
        memcpy(o->buf + o->len, data, len);
        o->len += len;
    }
}

void gp_out_puts(gp_out *o, const char *text)
{
    gp_out_write(o, text, strlen(text));
}

void gp_out_char(gp_out *o, char c)
{
    if (reserve(o, 1) == 0)
        o->buf[o->len++] = c;
}

void gp_out_double(gp_out *o, double x)
{
    if (reserve(o, GP_FMT_DOUBLE_MAX + 1) == 0)
        o->len += gp_fmt_double(o->buf + o->len, x);
}

/* Writes the decimal digits of v, most significant first, into end[-20..-1]; returns where
 * they start. */
static char *digits(uint64_t v, char *end)
{
    char *p = end;
    do {
        *--p = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    return p;
}

void gp_out_uint(gp_out *o, uint64_t v)
{
    char text[24];
    char *p = digits(v, text + sizeof text);
    gp_out_write(o, p, (size_t)(text + sizeof text - p));
}

void gp_out_int(gp_out *o, int64_t v)
{
    if (v < 0) {
        gp_out_char(o, '-');
        gp_out_uint(o, (uint64_t)0 - (uint64_t)v);
    } else {
        gp_out_uint(o, (uint64_t)v);
    }
}

/* Fixed-point numbers are written as a scaled integer when they fit one exactly enough;
 * beyond this the double's own digits run out and the shortest form says as much. */
#define FIXED_MAX_SCALED 9.0e15
#define FIXED_MAX_DECIMALS 9

void gp_out_fixed(gp_out *o, double x, int decimals)
{
    if (decimals < 0)
        decimals = 0;
    if (decimals > FIXED_MAX_DECIMALS)
        decimals = FIXED_MAX_DECIMALS;
    double scale = 1.0;
    for (int i = 0; i < decimals; i++)
        scale *= 10.0;
    double scaled = nearbyint(x * scale);
    if (!isfinite(scaled) || fabs(scaled) > FIXED_MAX_SCALED) {
        gp_out_double(o, x);
        return;
    }
    uint64_t v = (uint64_t)fabs(scaled);
    if (scaled < 0)
        gp_out_char(o, '-');
    uint64_t unit = (uint64_t)scale;
    gp_out_uint(o, v / unit);
    uint64_t frac = v % unit;
    if (frac == 0)
        return;
    char text[FIXED_MAX_DECIMALS + 1];
    int n = decimals;
    while (frac % 10 == 0) { /* trailing zeros say nothing */
        frac /= 10;
        n--;
    }
    for (int i = n - 1; i >= 0; i--) {
        text[1 + i] = (char)('0' + frac % 10);
        frac /= 10;
    }
    text[0] = '.';
    gp_out_write(o, text, (size_t)n + 1);
}

void gp_out_printf(gp_out *o, const char *format, ...)
{
    if (reserve(o, GP_OUT_PRINTF_MAX + 1))
        return;
    va_list ap;
    va_start(ap, format);
    int n = vsnprintf(o->buf + o->len, GP_OUT_PRINTF_MAX + 1, format, ap);
    va_end(ap);
    if (n > 0)
        o->len += (size_t)n < GP_OUT_PRINTF_MAX ? (size_t)n : GP_OUT_PRINTF_MAX;
}

size_t gp_out_take(gp_out *o, char *dst, size_t max)
{
    size_t n = o->len < max ? o->len : max;
    memcpy(dst, o->buf, n);
    memmove(o->buf, o->buf + n, o->len - n);
    o->len -= n;
    return n;
}

void gp_out_free(gp_out *o)
{
    free(o->buf);
    memset(o, 0, sizeof *o);
}
