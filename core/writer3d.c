/* writer3d.c - the 3D writers on the 2D writers' engine: the source of a result in
 * memory, the window a pass reads from, and the dispatch to each format's plan. */
#include "writer3d.h"

#include <stdlib.h>
#include <string.h>

static int load_memory(void *ctx, unsigned needs, size_t first, gp_window3d *win)
{
    (void)needs;
    (void)first;
    const gp_result3d *r = ctx;
    *win = (gp_window3d){
        .first = 0,
        .count = r->packing.count,
        .spheres = r->packing.spheres,
        .F = r->has_balance ? r->balance.F : NULL,
        .cells = r->has_cells ? &r->cells : NULL,
    };
    return 0;
}

gp_source3d gp_source3d_memory(const gp_result3d *result)
{
    return (gp_source3d){load_memory, (void *)result, NULL};
}

void gp_source3d_free(gp_source3d *source)
{
    if (source->drop)
        source->drop(source->ctx);
    *source = (gp_source3d){0};
}

/* The name of an array of `needs` that `win` lacks (a result in memory with only its
 * counts has none), or NULL. */
static const char *missing(const gp_window3d *win, unsigned needs)
{
    const gp_cells3d *c = win->cells;
    if ((needs & GP_W3_SPHERES) && !win->spheres)
        return "spheres";
    if ((needs & GP_W3_F) && !win->F)
        return "F";
    if ((needs & ~(GP_W3_SPHERES | GP_W3_F)) && (!c || !c->vstart || !c->fstart))
        return "cells";
    if (((needs & GP_W3_FACES) && (!c->fvstart || !c->fverts)) ||
        ((needs & GP_W3_NEIGHBOURS) && !c->fneighbour) || ((needs & GP_W3_XYZ) && !c->xyz) ||
        ((needs & GP_W3_VOLUME) && !c->volume))
        return "cells";
    return NULL;
}

const gp_window3d *gp_state3d_window(gp_writer *w, gp_out *out, unsigned needs, size_t i)
{
    gp_state3d *st = w->state;
    gp_window3d *win = &st->win;
    if (win->count && i >= win->first && i - win->first < win->count &&
        (needs & ~st->win_needs) == 0)
        return win;
    win->count = 0;
    int rc = st->source.load(st->source.ctx, needs, i, win);
    const char *lacks = rc ? NULL : missing(win, needs);
    if (lacks)
        rc = gp_error_set(&w->error, GP_EINVAL, NULL,
                          "the 3D writers need the result's %s, which has only their counts", lacks);
    if (rc || i < win->first || i - win->first >= win->count) {
        win->count = 0;
        if (!out->err)
            out->err = rc ? rc : GP_EINVAL;
        return NULL;
    }
    st->win_needs = needs;
    return win;
}

int gp_plan3d_state(gp_writer *w, const gp_plan3d_args *a, size_t size)
{
    gp_state3d *st = calloc(1, size);
    if (!st)
        return GP_ENOMEM;
    st->spec = a->spec;
    st->result = a->result;
    st->source = *a->source;
    w->state = st;
    return 0;
}

static int plan(gp_writer *w, void *arg)
{
    const gp_plan3d_args *a = arg;
    switch (a->format) {
    case GP_FORMAT3D_CSV: return gp_plan_csv3d(w, a);
    case GP_FORMAT3D_JSON: return gp_plan_json3d(w, a);
    case GP_FORMAT3D_VTU: return gp_plan_vtu3d(w, a);
    case GP_FORMAT3D_SVG: return gp_plan_svg3d(w, a);
    case GP_FORMAT3D_TESS: break; /* stored as text, never windowed */
    }
    return GP_EINVAL;
}

gp_writer *gp_writer3d_new(gp_format3d format, const gp_spec3d *spec, const gp_result3d *result,
                           const gp_source3d *source)
{
    gp_plan3d_args a = {format, spec, result, source};
    return gp_writer_new_plan(plan, &a);
}

int gp_write3d_memory(gp_out *out, gp_format3d format, const gp_spec3d *spec,
                      const gp_result3d *result)
{
    gp_source3d source = gp_source3d_memory(result);
    gp_writer *w = gp_writer3d_new(format, spec, result, &source);
    if (!w)
        return GP_ENOMEM;
    int rc = gp_writer_run(w, out, SIZE_MAX);
    gp_writer_free(w);
    int flushed = gp_out_flush(out);
    return rc ? rc : flushed;
}
