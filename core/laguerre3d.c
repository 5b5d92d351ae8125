/* laguerre3d.c - the Laguerre (power) polyhedra of a sphere packing clipped to the box and
 * shrunk (geometry3d.h, docs/3d.md §8): each cell is the box cut by the radical planes of
 * the centre's neighbours in the regular triangulation, in coordinates relative to the
 * centre (polyhedron.c), as laguerre.c does with polygons in 2D. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/geometry3d.h"
#include "grow.h"
#include "power_cell3d.h"
#include "triangulation3d.h"

/* Cells between two progress reports and cancel checks: a few milliseconds of work. */
#define CELLS_PER_REPORT 4096

typedef struct builder {
    const gp_box *box;
    const gp_laguerre_params *params;
    size_t *ring_start;
    int32_t *rings;
    power_cell3d pc;     /* the cell being built */
    int32_t *labels;     /* the labels of the unshrunk cell's faces, while it is shrunk */
    size_t labels_cap;
    gp_cells3d *out;
    size_t xyz_cap, f_cap, fv_cap, nverts, nfaces, nfv;
    size_t *nstart;      /* the unshrunk cells' grain neighbours, for the symmetry */
    int32_t *nb;
    size_t nnb, nb_cap;
} builder;

/* Shrinks the cell in bd->pc.a (docs/3d.md §8): homothetic about the centre, or offset: the
 * box cut again by every face's half-space moved inward by j = R - r (walls by j too
 * unless flush_boundary; the erosion of a convex polyhedron by a ball is the intersection
 * of its faces' half-spaces moved in). */
static int shrink(builder *bd)
{
    const gp_sphere *p = bd->pc.p;
    poly *a = &bd->pc.a;
    if (bd->params->shrink == GP_SHRINK_HOMOTHETIC) {
        double s = p->r / p->R;
        for (size_t k = 0; k < 3 * a->nv; k++)
            a->u[k] *= s;
        return 0;
    }
    double j = p->R - p->r;
    if (bd->params->shrink != GP_SHRINK_OFFSET || !(j > 0.0))
        return 0; /* no joint: cutting the cell by its own faces again only adds rounding */
    size_t m = a->nf;
    int32_t *labels = grow(bd->labels, &bd->labels_cap, m ? m : 1, sizeof *labels);
    if (!labels)
        return GP_ENOMEM;
    bd->labels = labels;
    memcpy(labels, a->label, m * sizeof *labels);
    int rc = power_cell3d_box(&bd->pc);
    for (size_t k = 0; k < m && rc == 0 && a->nf > 0; k++) {
        plane3 h;
        if (labels[k] >= 0) {
            h = bd->pc.pl[labels[k]];
            h.c -= j * h.len;
        } else {
            power_cell3d_wall(bd->box, p, GP_WALL3D_INDEX(labels[k]), bd->params->flush_boundary ? 0.0 : j, &h);
        }
        rc = poly_cut(a, h.n, h.c, labels[k], &bd->pc.b, &bd->pc.sc);
    }
    if (rc == 0)
        rc = power_cell3d_tidy(&bd->pc);
    return rc;
}

/* The neighbour a face label names: a grain id, or GP_WALL3D(k) as it is. */
static int32_t neighbour_of(const builder *bd, int32_t label)
{
    return label >= 0 ? bd->pc.ring[label] : label;
}

/* Records the unshrunk cell's grain neighbours (for the symmetry check). */
static int record_neighbours(builder *bd, int32_t i)
{
    int32_t *nb = grow(bd->nb, &bd->nb_cap, bd->nnb + bd->pc.a.nf, sizeof *nb);
    if (!nb)
        return GP_ENOMEM;
    bd->nb = nb;
    for (size_t f = 0; f < bd->pc.a.nf; f++)
        if (bd->pc.a.label[f] >= 0)
            nb[bd->nnb++] = neighbour_of(bd, bd->pc.a.label[f]);
    bd->nstart[i + 1] = bd->nnb;
    return 0;
}

/* Appends the cell in bd->pc.a to the output as cell i. */
static int emit(builder *bd, int32_t i)
{
    gp_cells3d *out = bd->out;
    const poly *a = &bd->pc.a;
    const gp_sphere *p = bd->pc.p;
    double *xyz = grow(out->xyz, &bd->xyz_cap, 3 * (bd->nverts + a->nv), sizeof *xyz);
    if (!xyz)
        return GP_ENOMEM;
    out->xyz = xyz;
    size_t f_need = bd->nfaces + a->nf + 1;
    if (f_need > bd->f_cap) {
        size_t cap = grow_capacity(bd->f_cap, f_need);
        size_t *fvstart = cap ? grow_realloc(out->fvstart, cap, sizeof *fvstart) : NULL;
        if (!fvstart)
            return GP_ENOMEM;
        out->fvstart = fvstart;
        int32_t *fn = grow_realloc(out->fneighbour, cap, sizeof *fn);
        if (!fn)
            return GP_ENOMEM;
        out->fneighbour = fn;
        bd->f_cap = cap;
    }
    uint32_t *fverts = grow(out->fverts, &bd->fv_cap, bd->nfv + a->fs[a->nf] + 1, sizeof *fverts);
    if (!fverts)
        return GP_ENOMEM;
    out->fverts = fverts;
    double centre[3] = {p->x, p->y, p->z};
    for (size_t k = 0; k < 3 * a->nv; k++)
        xyz[3 * bd->nverts + k] = centre[k % 3] + a->u[k];
    bd->nverts += a->nv;
    out->vstart[i + 1] = bd->nverts;
    for (size_t f = 0; f < a->nf; f++) {
        out->fvstart[bd->nfaces] = bd->nfv;
        out->fneighbour[bd->nfaces++] = neighbour_of(bd, a->label[f]);
        for (size_t k = a->fs[f]; k < a->fs[f + 1]; k++)
            fverts[bd->nfv++] = a->fv[k];
    }
    out->fvstart[bd->nfaces] = bd->nfv;
    out->fstart[i + 1] = bd->nfaces;
    out->volume[i] = poly_volume(a);
    return 0;
}

static int build_cell(builder *bd, int32_t i, gp_error *err)
{
    const int32_t *ring = bd->rings + bd->ring_start[i];
    size_t degree = bd->ring_start[i + 1] - bd->ring_start[i];
    int holds_centre, rc = power_cell3d_build(&bd->pc, i, ring, degree, &holds_centre);
    if (rc == 0 && holds_centre && bd->pc.a.nf >= 4) {
        bd->out->power_volume_sum += poly_volume(&bd->pc.a);
        if ((rc = record_neighbours(bd, i)) == 0 && (rc = shrink(bd)) == 0)
            rc = emit(bd, i);
    }
    if (rc)
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the cell of sphere %d", i);
    if (!holds_centre || bd->pc.a.nf < 4)
        return gp_error_set(err, GP_EGEOM, NULL,
                            "sphere %d at (%.17g, %.17g, %.17g) is outside its own power cell: it "
                            "overlaps another sphere or lies outside the box",
                            i, bd->pc.p->x, bd->pc.p->y, bd->pc.p->z);
    return 0;
}

/* Whether the unshrunk cell of i lists j. */
static int lists(const builder *bd, int32_t i, int32_t j)
{
    for (size_t m = bd->nstart[i]; m < bd->nstart[i + 1]; m++)
        if (bd->nb[m] == j)
            return 1;
    return 0;
}

/* Drops from the output every face of i toward a grain j whose cell does not have i
 * among its neighbours: the two cells tidy their shared face separately, and only a face
 * whose area is within rounding of the threshold can be kept on one side only. */
static void symmetrize(builder *bd)
{
    gp_cells3d *c = bd->out;
    int dropped = 0;
    for (size_t i = 0; i < c->count; i++)
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
            int32_t j = c->fneighbour[f];
            if (!GP_IS_WALL3D(j) && !lists(bd, j, (int32_t)i)) {
                c->fneighbour[f] = INT32_MIN;
                dropped = 1;
            }
        }
    if (!dropped)
        return;
    size_t wf = 0, wv = 0;
    for (size_t i = 0; i < c->count; i++) {
        size_t begin = c->fstart[i], end = c->fstart[i + 1];
        c->fstart[i] = wf;
        for (size_t f = begin; f < end; f++) {
            size_t vb = c->fvstart[f], ve = c->fvstart[f + 1];
            if (c->fneighbour[f] == INT32_MIN)
                continue;
            c->fneighbour[wf] = c->fneighbour[f];
            c->fvstart[wf++] = wv;
            memmove(c->fverts + wv, c->fverts + vb, (ve - vb) * sizeof *c->fverts);
            wv += ve - vb;
        }
    }
    c->fstart[c->count] = wf;
    c->fvstart[wf] = wv;
}

int gp_laguerre3d(const gp_box *box, const gp_sphere *spheres, size_t n, const gp_rt3 *rt,
                  const gp_laguerre_params *params, const gp_progress *progress, gp_cells3d *out,
                  gp_error *err)
{
    memset(out, 0, sizeof *out);
    builder bd;
    memset(&bd, 0, sizeof bd);
    bd.box = box;
    bd.pc.box = box;
    bd.pc.spheres = spheres;
    bd.params = params;
    bd.out = out;
    out->count = n;
    out->shrink = params->shrink;
    out->vstart = calloc(n + 1, sizeof *out->vstart);
    out->fstart = calloc(n + 1, sizeof *out->fstart);
    out->volume = calloc(n ? n : 1, sizeof *out->volume);
    bd.nstart = calloc(n + 1, sizeof *bd.nstart);
    bd.ring_start = malloc((n + 1) * sizeof *bd.ring_start);
    int rc = 0;
    if (gp_rt3_count(rt) != n)
        rc = gp_error_set(err, GP_EINTERNAL, NULL, "laguerre 3D: a triangulation of %zu spheres for %zu",
                          gp_rt3_count(rt), n);
    else if (!out->vstart || !out->fstart || !out->volume || !bd.nstart || !bd.ring_start ||
             (rc = gp_rt3_rings(rt, bd.ring_start, NULL, &bd.rings, progress)))
        rc = rc == GP_ECANCELED ? gp_error_set(err, GP_ECANCELED, NULL, "laguerre cells canceled")
                                : gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the cells of %zu spheres", n);
    for (size_t i = 0; i < n && rc == 0; i++) {
        if (progress && i % CELLS_PER_REPORT == CELLS_PER_REPORT - 1) {
            if (gp_canceled(progress->cancel)) {
                rc = gp_error_set(err, GP_ECANCELED, NULL, "laguerre cells canceled");
                break;
            }
            if (progress->report)
                progress->report(progress->ctx, "laguerre", (double)i / (double)n);
        }
        rc = build_cell(&bd, (int32_t)i, err);
    }
    if (rc == 0 && !out->fvstart) {
        /* no sphere: no face, but the offsets exist */
        out->fvstart = calloc(1, sizeof *out->fvstart);
        if (!out->fvstart)
            rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the cells");
    }
    if (rc == 0) {
        symmetrize(&bd);
        if (progress && progress->report)
            progress->report(progress->ctx, "laguerre", 1.0);
    }
    power_cell3d_free(&bd.pc);
    free(bd.labels);
    free(bd.ring_start);
    free(bd.rings);
    free(bd.nstart);
    free(bd.nb);
    if (rc)
        gp_cells3d_free(out);
    return rc;
}

void gp_cells3d_free(gp_cells3d *cells)
{
    free(cells->vstart);
    free(cells->xyz);
    free(cells->fstart);
    free(cells->fvstart);
    free(cells->fverts);
    free(cells->fneighbour);
    free(cells->volume);
    memset(cells, 0, sizeof *cells);
}
