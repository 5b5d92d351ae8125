/* writer3d.h - inside the 3D writers (io_csv3d.c, io_json3d.c, io_vtu3d.c, io_svg3d.c,
 * writer3d.c, sections3d.c): a 3D result written window by window on the 2D writers'
 * engine (writer.h), from a result in memory (the command line) or from the stored
 * sections (the service's downloads), the same steps and so the same bytes either way. */
#ifndef GRAINPACK_WRITER3D_H
#define GRAINPACK_WRITER3D_H

#include "grainpack/io3d.h"
#include "writer.h"

/* The arrays a pass reads of a window (gp_source3d's `needs`). */
enum {
    GP_W3_SPHERES = 1u,    /* spheres */
    GP_W3_F = 2u,          /* F (balanced results) */
    GP_W3_CELLS = 4u,      /* the cells' vstart and fstart */
    GP_W3_FACES = 8u,      /* with GP_W3_CELLS: fvstart and fverts */
    GP_W3_NEIGHBOURS = 16u, /* with GP_W3_CELLS: fneighbour */
    GP_W3_XYZ = 32u,       /* with GP_W3_CELLS: xyz */
    GP_W3_VOLUME = 64u,    /* with GP_W3_CELLS: volume */
};

/* Grains first .. first + count - 1 of a 3D result, with the arrays a pass asked for
 * (the others NULL). */
typedef struct gp_window3d {
    size_t first, count;
    const gp_sphere *spheres; /* count */
    const double *F;          /* count */
    /* the window's `count` cells, their offsets (vstart, fstart, fvstart) counted from
     * the window's own first vertex, face and face vertex, as if the window were all */
    const gp_cells3d *cells;
    size_t vertex_base; /* the index of the window's first vertex among all the cells' */
} gp_window3d;

/* Where a 3D writer reads the per-grain arrays: `load` fills *win with a window holding
 * grain `first` (below the result's count) with at least the arrays of `needs`, valid
 * until the next call; writers ask for grains in order, one pass after another. Returns
 * 0 or a negative code (which stops the writer). `drop` frees ctx (NULL: nothing). */
typedef struct gp_source3d {
    int (*load)(void *ctx, unsigned needs, size_t first, gp_window3d *win);
    void *ctx;
    void (*drop)(void *ctx);
} gp_source3d;

/* The source of a result in memory: one window over all of it. `result` is borrowed and
 * must outlive the source, which needs no freeing. */
gp_source3d gp_source3d_memory(const gp_result3d *result);
void gp_source3d_free(gp_source3d *source);

/* A writer of `result` in `format` (csv, json, vtu or svg; tess is not written window by
 * window: its text is stored, io3d.h). Of `result` only the summary is read (counts,
 * statistics, the balance and cells' summaries); the arrays come from `source`. `spec`
 * (NULL for csv and vtu), `result` and `source` are borrowed and must outlive the
 * writer. Run it with gp_writer_run (io.h); NULL when out of memory or for tess. */
gp_writer *gp_writer3d_new(gp_format3d format, const gp_spec3d *spec, const gp_result3d *result,
                           const gp_source3d *source);

/* Writes the whole result (in memory) in `format` (not tess) into `out` and flushes it.
 * Returns 0, GP_ENOMEM, the sink's error, or GP_EINVAL when the result lacks an array. */
int gp_write3d_memory(gp_out *out, gp_format3d format, const gp_spec3d *spec,
                      const gp_result3d *result);

/* What every 3D format's state (w->state) starts with. */
typedef struct gp_state3d {
    const gp_spec3d *spec;
    const gp_result3d *result; /* its summary */
    gp_source3d source;        /* borrowed */
    gp_window3d win;           /* the window loaded last, and the arrays it holds */
    unsigned win_needs;
} gp_state3d;

/* The window that holds grain i with the arrays of `needs`: the last one when it does,
 * else the source's. NULL when the source fails or lacks an array: out->err is then set
 * (and the writer's error says which array is missing). */
const gp_window3d *gp_state3d_window(gp_writer *w, gp_out *out, unsigned needs, size_t i);

/* What a format's plan is given. */
typedef struct gp_plan3d_args {
    gp_format3d format;
    const gp_spec3d *spec;
    const gp_result3d *result;
    const gp_source3d *source;
} gp_plan3d_args;

/* Allocates the writer's state (`size` bytes, zeroed, a gp_state3d first, set from
 * `a`): 0 or GP_ENOMEM. */
int gp_plan3d_state(gp_writer *w, const gp_plan3d_args *a, size_t size);

/* Each 3D format's plan (writer.h's gp_writer_new_plan): its state and steps. Returns 0
 * or GP_ENOMEM. */
int gp_plan_csv3d(gp_writer *w, const gp_plan3d_args *a);
int gp_plan_json3d(gp_writer *w, const gp_plan3d_args *a);
int gp_plan_vtu3d(gp_writer *w, const gp_plan3d_args *a);
int gp_plan_svg3d(gp_writer *w, const gp_plan3d_args *a);

#endif
