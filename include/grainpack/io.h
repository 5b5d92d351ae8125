/* io.h - writers for a job's result: CSV (one line per disk), JSON (disks, cells and
 * statistics), SVG (a picture of the grains and their boundaries), VTK (legacy polydata
 * for ParaView). Writers are deterministic: the same result gives the same bytes.
 *
 * A writer emits into a gp_out (out.h) and reads the per-grain arrays (disks, F, cells)
 * through a gp_grain_source, window by window: from a result in memory (the command
 * line), or from a store read piece by piece (the service streams a download without
 * holding the result). It can stop once enough bytes are out and go on later
 * (gp_writer_run), so a server renders a response as the socket takes it. */
#ifndef GRAINPACK_IO_H
#define GRAINPACK_IO_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/api.h"
#include "grainpack/out.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_format {
    GP_FORMAT_JSON = 0,
    GP_FORMAT_CSV,
    GP_FORMAT_SVG,
    GP_FORMAT_VTK,
    GP_FORMAT_MSH, /* the mesh: Gmsh MSH 4.1 (io_mesh.h) */
    GP_FORMAT_INP, /* the mesh: Abaqus input */
    GP_FORMAT_VTU, /* the mesh, or the grains without one: VTK XML unstructured grid */
    GP_FORMAT_TESS /* a 3D job's tessellation (Neper's .tess, io3d.h): no 2D writer has it */
} gp_format;

/* Maps "json", "csv", "svg", "vtk", "msh", "inp", "vtu" or "tess" to a format; returns 0
 * or GP_EINVAL. */
GP_API int gp_format_parse(const char *name, gp_format *out);
GP_API const char *gp_format_name(gp_format format);
/* How many formats there are: every value from 0 to gp_format_count() - 1 is a format,
 * so a caller can list them without knowing their names (the service does). */
GP_API size_t gp_format_count(void);
/* The media type to serve the format with ("text/csv; charset=utf-8", ...). */
GP_API const char *gp_format_media_type(gp_format format);
/* Whether the format is text, which compresses well (every format today; a binary one
 * would not be worth compressing again). */
GP_API int gp_format_is_text(gp_format format);

/* Which per-grain arrays a writer step reads (bits of `needs`). */
enum {
    GP_GRAINS_DISKS = 1,      /* disks */
    GP_GRAINS_F = 2,          /* F (a result with balance only) */
    GP_GRAINS_AREA = 4,       /* cell areas (with cells only) */
    GP_GRAINS_POLYGONS = 8,   /* start, xy (with cells only) */
    GP_GRAINS_NEIGHBOURS = 16 /* nstart, neighbours (with cells only) */
};

/* A window on the per-grain arrays of a result: grains first .. first + count - 1.
 * disks, F and area are indexed from the window's first grain (disks[0] is grain
 * `first`). start and nstart hold count + 1 absolute offsets, as in gp_cells: the
 * vertices of grain first + j are k = start[j] .. start[j + 1] - 1, at xy[2 (k -
 * vertex_base)] and xy[2 (k - vertex_base) + 1]; its neighbours are neighbours[k -
 * neighbour_base] for k = nstart[j] .. nstart[j + 1] - 1. Arrays not asked for may be
 * NULL. */
typedef struct gp_grain_window {
    size_t first, count;
    const gp_disk *disks;
    const double *F;
    const double *area;
    const size_t *start;
    size_t vertex_base;
    const double *xy;
    const size_t *nstart;
    size_t neighbour_base;
    const int32_t *neighbours;
} gp_grain_window;

/* Where a writer reads the per-grain arrays. `load` fills *win with a window holding
 * grain `first` (first < the result's grain count) and at least the arrays of `needs`;
 * the window stays valid until the next call. Writers ask for grains in order, from 0
 * up, one pass after another. Returns 0 or a negative code (which stops the writer).
 * vertex_count and neighbour_count are the totals over all cells (0 without cells). */
typedef struct gp_grain_source {
    int (*load)(void *ctx, unsigned needs, size_t first, gp_grain_window *win);
    void *ctx;
    size_t vertex_count, neighbour_count;
} gp_grain_source;

/* The source of a result in memory: one window over all of its arrays. `result` is
 * borrowed and must outlive the source. */
GP_API gp_grain_source gp_grain_source_memory(const gp_result *result);

typedef struct gp_writer gp_writer;

/* A writer of `result` in `format`. `spec`, `result` and `source` are borrowed and must
 * outlive the writer; of `result` only the summary is read (counts, statistics, the
 * balance and cell summaries: everything but the per-grain arrays, which come from
 * `source`). Returns NULL when out of memory. Free with gp_writer_free. */
GP_API gp_writer *gp_writer_new(gp_format format, const gp_spec *spec,
                                const gp_result *result, const gp_grain_source *source);

/* Writes on into `out` until out->len reaches `want` bytes or the result is all out
 * (SIZE_MAX: to the end; out may have a sink that takes the bytes as they come). A step
 * of text may pass `want` by a few kilobytes. Returns 1 when more is to come, 0 when
 * done, or a negative code: out's error (GP_ENOMEM, the sink's) or the source's. */
GP_API int gp_writer_run(gp_writer *w, gp_out *out, size_t want);

/* Why the last gp_writer_run failed, when the writer itself refused (code GP_EINVAL: a
 * result without the mesh or the arrays its format reads, e.g. msh of a job that asked
 * for no mesh); code 0 when the failure was the sink's or the source's, or none. Owned
 * by the writer. */
GP_API const gp_error *gp_writer_error(const gp_writer *w);

GP_API void gp_writer_free(gp_writer *w);

/* Writes the whole result (in memory) in `format` into `out` and flushes it. Returns 0,
 * GP_ENOMEM or the sink's error (GP_EIO for a file). */
GP_API int gp_write_result(gp_out *out, gp_format format, const gp_spec *spec,
                           const gp_result *result);

/* Whether the format exists only for jobs with a mesh (msh, inp). */
GP_API int gp_format_needs_mesh(gp_format format);

#ifdef __cplusplus
}
#endif
#endif
