/* out.h - a buffered byte sink, and the number formats every writer uses: the shortest
 * decimal that reads back to the same double (Dragonbox, from Debian), fixed
 * decimals for picture coordinates, integers. Writers emit into a gp_out; where the bytes
 * go (a FILE, a growing buffer a server drains piece by piece) is the sink's business. */
#ifndef GRAINPACK_OUT_H
#define GRAINPACK_OUT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Receives `len` bytes; returns 0, or a negative GP_E code that stops the output. */
typedef int (*gp_out_sink)(void *ctx, const char *data, size_t len);

/* A buffer in front of a sink. With a sink, the buffer is handed to it whenever it fills
 * (and by gp_out_flush). Without one (memory mode), the buffer grows and its owner takes
 * bytes off its front with gp_out_take. The first error (GP_ENOMEM, or the sink's) is
 * kept in `err` and every later write is ignored, so a writer checks once, at the end. */
typedef struct gp_out {
    char *buf;       /* owned */
    size_t len, cap;
    gp_out_sink sink; /* NULL: memory mode */
    void *ctx;
    int err;
} gp_out;

/* The buffer size a file sink gets: large enough that write calls cost nothing. */
#define GP_OUT_DEFAULT_CAPACITY ((size_t)1 << 16)

/* The longest text gp_fmt_double writes, without the terminating NUL: a sign, 17
 * digits, a point, "e-324". */
#define GP_FMT_DOUBLE_MAX 32

/* Sets `o` up with a buffer of `capacity` bytes (0: GP_OUT_DEFAULT_CAPACITY) in front of
 * `sink` (NULL: memory mode). Returns 0 or GP_ENOMEM (then `o` is zeroed). Free with
 * gp_out_free. */
int gp_out_init(gp_out *o, size_t capacity, gp_out_sink sink, void *ctx);

/* A sink writing to `file` (borrowed): GP_EIO when fwrite falls short. */
int gp_out_init_file(gp_out *o, FILE *file);

void gp_out_write(gp_out *o, const void *data, size_t len);
void gp_out_puts(gp_out *o, const char *text);
/* gp_out_puts of a string literal, its length known when compiled (no strlen on the hot
 * paths). */
#define GP_OUT_LITERAL(o, literal) gp_out_write((o), "" literal, sizeof(literal) - 1)
void gp_out_char(gp_out *o, char c);
/* The shortest decimal that reads back (strtod) to exactly x: 0.06, 1e-7, 123456, 1.5e+300;
 * "NaN", "Infinity" and "-Infinity" for the non-finite (writers that cannot show them
 * test first). */
void gp_out_double(gp_out *o, double x);
/* x rounded to `decimals` digits after the point, trailing zeros (and a bare point)
 * dropped: for picture coordinates, where a screen shows no more. */
void gp_out_fixed(gp_out *o, double x, int decimals);
void gp_out_int(gp_out *o, int64_t v);
void gp_out_uint(gp_out *o, uint64_t v);
/* printf into the buffer: for captions and other text off the hot paths (at most
 * GP_OUT_PRINTF_MAX bytes; longer text is cut). */
#define GP_OUT_PRINTF_MAX 1024
void gp_out_printf(gp_out *o, const char *format, ...) __attribute__((format(printf, 2, 3)));

/* Hands what is buffered to the sink (no-op in memory mode). Returns o->err. */
int gp_out_flush(gp_out *o);

/* Memory mode: moves up to `max` bytes from the front of the buffer to dst and returns
 * how many. */
size_t gp_out_take(gp_out *o, char *dst, size_t max);

/* Frees the buffer and zeroes `o` (without flushing). */
void gp_out_free(gp_out *o);

/* The text gp_out_double writes, NUL-terminated, into buf (at least GP_FMT_DOUBLE_MAX +
 * 1 bytes); returns its length. */
size_t gp_fmt_double(char *buf, double x);

#ifdef __cplusplus
}
#endif
#endif
