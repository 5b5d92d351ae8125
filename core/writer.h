/* writer.h - inside the writers (core/io_*.c and writer.c only): a writer is a list of
 * steps, each a piece of text from the result's summary, a pass over the grains emitting
 * something per grain, or a pass over numbered items (a mesh's nodes, elements...);
 * writer.c runs them, stopping and resuming between two grains or items. A format builds
 * its list in its plan function. */
#ifndef GRAINPACK_WRITER_H
#define GRAINPACK_WRITER_H

#include "grainpack/io.h"
#include "mesh_source.h"

/* The most steps a format's plan may have: the SVG picture's is the longest, with three
 * steps (open, grains, close) for each of its 17 colour groups, twice over. */
#define GP_WRITER_MAX_STEPS 128

typedef void (*gp_text_fn)(gp_writer *w, gp_out *out, int param);
/* Emits grain win->first + j. */
typedef void (*gp_grain_fn)(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j,
                            int param);

/* Emits item k of a pass over `count` items. */
typedef void (*gp_item_fn)(gp_writer *w, gp_out *out, size_t k, int param);

typedef struct gp_writer_step {
    gp_text_fn text;   /* a text step, or */
    gp_grain_fn grain; /* a pass over every grain, or */
    gp_item_fn item;   /* a pass over items 0 .. count - 1 */
    unsigned needs;    /* GP_GRAINS_... the pass reads */
    size_t count;      /* the items */
    int param;         /* handed to the function: a colour class, an array... */
} gp_writer_step;

/* The window of one mesh array a writer read last (gp_writer_mesh). */
typedef struct gp_mesh_window {
    const void *data;
    size_t first, count;
} gp_mesh_window;

struct gp_writer {
    gp_format format;
    const gp_spec *spec;
    const gp_result *result; /* its summary only */
    gp_grain_source source;
    size_t grains;           /* result->packing.count */
    gp_writer_step steps[GP_WRITER_MAX_STEPS];
    int nsteps, step;        /* the list, and the step under way */
    size_t next;             /* the next grain of a pass under way */
    int overflow;            /* a plan added more than GP_WRITER_MAX_STEPS steps: a bug */
    void *state;             /* the format's own (malloc'd, freed with the writer) */
    void (*drop)(void *state); /* frees what the state holds besides itself, or NULL */
    gp_error error;          /* why a step failed, when the writer knows (gp_writer_error) */
    gp_mesh_source mesh;     /* where the mesh formats read the mesh (load NULL: nowhere) */
    gp_mesh_window mesh_window[GP_MESH_ARRAYS];
};

void gp_writer_text(gp_writer *w, gp_text_fn fn, int param);
void gp_writer_grains(gp_writer *w, gp_grain_fn fn, unsigned needs, int param);
void gp_writer_items(gp_writer *w, gp_item_fn fn, size_t count, int param);

/* Record k of mesh array `a`, read through the writer's mesh source (the window that
 * holds it is loaded when it is not the last one read): valid until the next call for
 * the same array. NULL when the source fails: out->err is then set. */
const void *gp_writer_mesh(gp_writer *w, gp_out *out, gp_mesh_array a, size_t k);

/* A writer whose steps `plan` adds (with `arg`): the formats of another process than
 * the 2D result's (the 3D writers, writer3d.h), run by gp_writer_run like the 2D ones.
 * Its format, spec and result are unset: the plan's state holds what it writes from.
 * Returns NULL when out of memory or when the plan fails. Free with gp_writer_free. */
gp_writer *gp_writer_new_plan(int (*plan)(gp_writer *w, void *arg), void *arg);

/* Each format's plan: adds its steps, sets up its state. Returns 0 or GP_ENOMEM. */
int gp_plan_csv(gp_writer *w);
int gp_plan_json(gp_writer *w);
int gp_plan_svg(gp_writer *w);
int gp_plan_vtk(gp_writer *w);
/* msh, inp and vtu of a mesh, reading it window by window (gp_writer_mesh) */
int gp_plan_msh(gp_writer *w);
int gp_plan_inp(gp_writer *w);
int gp_plan_vtu(gp_writer *w);
/* Whether `r` holds what `format` (msh, inp, vtu) reads of it: the mesh's arrays, and
 * the grains' radii (vtu), or the grains' arrays (vtu without a mesh). Returns 0, or
 * GP_EINVAL with err saying what is missing. */
int gp_mesh_result_check(const gp_result *r, gp_format format, gp_error *err);

#endif
