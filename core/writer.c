/* writer.c - running a writer's steps (writer.h) window by window, resumable between two
 * grains or items; the sources of a result held in memory; format dispatch. */
#include "writer.h"

#include <stdlib.h>
#include <string.h>

void gp_writer_text(gp_writer *w, gp_text_fn fn, int param)
{
    if (w->nsteps == GP_WRITER_MAX_STEPS) {
        w->overflow = 1;
        return;
    }
    w->steps[w->nsteps++] = (gp_writer_step){.text = fn, .param = param};
}

void gp_writer_grains(gp_writer *w, gp_grain_fn fn, unsigned needs, int param)
{
    if (w->nsteps == GP_WRITER_MAX_STEPS) {
        w->overflow = 1;
        return;
    }
    w->steps[w->nsteps++] = (gp_writer_step){.grain = fn, .needs = needs, .param = param};
}

void gp_writer_items(gp_writer *w, gp_item_fn fn, size_t count, int param)
{
    if (w->nsteps == GP_WRITER_MAX_STEPS) {
        w->overflow = 1;
        return;
    }
    w->steps[w->nsteps++] = (gp_writer_step){.item = fn, .count = count, .param = param};
}

const void *gp_writer_mesh(gp_writer *w, gp_out *out, gp_mesh_array a, size_t k)
{
    gp_mesh_window *win = &w->mesh_window[a];
    if (!win->data || k < win->first || k - win->first >= win->count) {
        int rc = w->mesh.load ? w->mesh.load(w->mesh.ctx, a, k, &win->data, &win->count) : GP_EINVAL;
        if (rc) {
            win->data = NULL;
            if (!out->err)
                out->err = rc;
            return NULL;
        }
        win->first = k;
    }
    return (const char *)win->data + (k - win->first) * gp_mesh_record_size(&w->result->mesh, a);
}

void gp_writer_set_mesh(gp_writer *w, const gp_mesh_source *source)
{
    gp_mesh_source_free(&w->mesh);
    w->mesh = *source;
    memset(w->mesh_window, 0, sizeof w->mesh_window);
}

static int load_memory(void *ctx, unsigned needs, size_t first, gp_grain_window *win)
{
    (void)needs;
    (void)first;
    const gp_result *r = ctx;
    *win = (gp_grain_window){
        .first = 0,
        .count = r->packing.count,
        .disks = r->packing.disks,
        .F = r->has_balance ? r->balance.F : NULL,
        .area = r->has_cells ? r->cells.area : NULL,
        .start = r->has_cells ? r->cells.start : NULL,
        .xy = r->has_cells ? r->cells.xy : NULL,
        .nstart = r->has_cells ? r->cells.nstart : NULL,
        .neighbours = r->has_cells ? r->cells.neighbours : NULL,
    };
    return 0;
}

gp_grain_source gp_grain_source_memory(const gp_result *result)
{
    gp_grain_source s = {load_memory, (void *)result, 0, 0};
    if (result->has_cells && result->cells.start) {
        s.vertex_count = result->cells.start[result->cells.count];
        s.neighbour_count = result->cells.nstart[result->cells.count];
    }
    return s;
}

gp_writer *gp_writer_new(gp_format format, const gp_spec *spec, const gp_result *result,
                         const gp_grain_source *source)
{
    gp_writer *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->format = format;
    w->spec = spec;
    w->result = result;
    w->source = *source;
    w->grains = result->packing.count;
    int rc = GP_EINVAL;
    switch (format) {
    case GP_FORMAT_JSON: rc = gp_plan_json(w); break;
    case GP_FORMAT_CSV: rc = gp_plan_csv(w); break;
    case GP_FORMAT_SVG: rc = gp_plan_svg(w); break;
    case GP_FORMAT_VTK: rc = gp_plan_vtk(w); break;
    case GP_FORMAT_MSH: rc = gp_plan_msh(w); break;
    case GP_FORMAT_INP: rc = gp_plan_inp(w); break;
    case GP_FORMAT_VTU: rc = gp_plan_vtu(w); break;
    case GP_FORMAT_TESS: break; /* 3D only (io3d.h): GP_EINVAL */
    }
    /* a mesh in memory is read through windows that point into it */
    if (rc == 0 && (gp_format_needs_mesh(format) || format == GP_FORMAT_VTU) && gp_mesh_result_check(result, GP_FORMAT_MSH, NULL) == 0)
        rc = gp_mesh_source_memory(&result->mesh, &w->mesh);
    if (rc || w->overflow) {
        gp_writer_free(w);
        return NULL;
    }
    return w;
}

gp_writer *gp_writer_new_plan(int (*plan)(gp_writer *w, void *arg), void *arg)
{
    gp_writer *w = calloc(1, sizeof *w);
    if (w && (plan(w, arg) || w->overflow)) {
        gp_writer_free(w);
        return NULL;
    }
    return w;
}

void gp_writer_free(gp_writer *w)
{
    if (!w)
        return;
    if (w->drop && w->state)
        w->drop(w->state);
    free(w->state);
    gp_mesh_source_free(&w->mesh);
    free(w);
}

/* Whether `win` lacks an array of `needs`: a result in memory with only its counts (a
 * summary) has none, and a pass must not read through NULL. */
static int missing(const gp_grain_window *win, unsigned needs)
{
    return ((needs & GP_GRAINS_DISKS) && !win->disks) || ((needs & GP_GRAINS_F) && !win->F) ||
           ((needs & GP_GRAINS_AREA) && !win->area) ||
           ((needs & GP_GRAINS_POLYGONS) && (!win->start || !win->xy)) ||
           ((needs & GP_GRAINS_NEIGHBOURS) && (!win->nstart || !win->neighbours));
}

/* Runs the pass of step s from grain w->next until the grains end or out holds `want`
 * bytes. Returns 0 or the source's error. */
static int run_pass(gp_writer *w, const gp_writer_step *s, gp_out *out, size_t want)
{
    while (w->next < w->grains && out->len < want && !out->err) {
        gp_grain_window win;
        int rc = w->source.load(w->source.ctx, s->needs, w->next, &win);
        if (rc)
            return rc;
        if (missing(&win, s->needs))
            return gp_error_set(&w->error, GP_EINVAL, NULL,
                                "%s needs the grains' arrays in the result, which has only their counts",
                                gp_format_name(w->format));
        size_t j = w->next - win.first;
        while (j < win.count && out->len < want) /* a file sink keeps len below its capacity */
            s->grain(w, out, &win, j++, s->param);
        w->next = win.first + j;
    }
    return 0;
}

int gp_writer_run(gp_writer *w, gp_out *out, size_t want)
{
    while (w->step < w->nsteps) {
        if (out->err)
            return out->err;
        if (out->len >= want)
            return 1;
        const gp_writer_step *s = &w->steps[w->step];
        if (s->text) {
            s->text(w, out, s->param);
        } else if (s->item) {
            while (w->next < s->count && out->len < want && !out->err)
                s->item(w, out, w->next++, s->param);
            if (w->next < s->count)
                continue; /* out is full (or failed): the next call goes on */
        } else {
            int rc = run_pass(w, s, out, want);
            if (rc)
                return rc;
            if (w->next < w->grains)
                continue; /* out is full (or failed): the next call goes on */
        }
        w->step++;
        w->next = 0;
    }
    return out->err;
}

const gp_error *gp_writer_error(const gp_writer *w)
{
    return &w->error;
}

int gp_write_result(gp_out *out, gp_format format, const gp_spec *spec, const gp_result *result)
{
    gp_grain_source source = gp_grain_source_memory(result);
    gp_writer *w = gp_writer_new(format, spec, result, &source);
    if (!w)
        return GP_ENOMEM;
    int rc = gp_writer_run(w, out, SIZE_MAX);
    gp_writer_free(w);
    int flushed = gp_out_flush(out);
    return rc ? rc : flushed;
}
