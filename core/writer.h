/* writer.h - inside the writers (core/io_*.c and writer.c only): a writer is a list of
 * steps, each either a piece of text from the result's summary or a pass over the grains
 * emitting something per grain; writer.c runs them, stopping and resuming between two
 * grains. A format builds its list in its plan function. */
#ifndef GRAINPACK_WRITER_H
#define GRAINPACK_WRITER_H

#include "grainpack/io.h"

/* The most steps a format's plan may have: the SVG picture's is the longest, with three
 * steps (open, grains, close) for each of its 17 colour groups, twice over. */
#define GP_WRITER_MAX_STEPS 128

typedef void (*gp_text_fn)(gp_writer *w, gp_out *out, int param);
/* Emits grain win->first + j. */
typedef void (*gp_grain_fn)(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j,
                            int param);

typedef struct gp_writer_step {
    gp_text_fn text;   /* a text step, or */
    gp_grain_fn grain; /* a pass over every grain */
    unsigned needs;    /* GP_GRAINS_... the pass reads */
    int param;         /* handed to the function: a colour class, an array... */
} gp_writer_step;

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
};

void gp_writer_text(gp_writer *w, gp_text_fn fn, int param);
void gp_writer_grains(gp_writer *w, gp_grain_fn fn, unsigned needs, int param);

/* Each format's plan: adds its steps, sets up its state. Returns 0 or GP_ENOMEM. */
int gp_plan_csv(gp_writer *w);
int gp_plan_json(gp_writer *w);
int gp_plan_svg(gp_writer *w);
int gp_plan_vtk(gp_writer *w);
/* msh, inp and vtu: the whole file in one text step, from the result's mesh (io_mesh_plan.c). */
int gp_plan_mesh(gp_writer *w);
/* Whether `r` holds what `format` (msh, inp, vtu) reads of it: the mesh's arrays, and
 * the grains' radii (vtu), or the grains' arrays (vtu without a mesh). Returns 0, or
 * GP_EINVAL with err saying what is missing. */
int gp_mesh_result_check(const gp_result *r, gp_format format, gp_error *err);

#endif
