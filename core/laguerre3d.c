/* laguerre3d.c - the Laguerre (power) polyhedra of a sphere packing clipped to the box and
 * shrunk (geometry3d.h, docs/3d.md §7): each cell is the box cut by the radical planes of
 * the centre's neighbours in the regular triangulation, in coordinates relative to the
 * centre (polyhedron.c), as laguerre.c does with polygons in 2D. On a periodic box the
 * triangulation is the spheres' and their ghosts' (docs/3d.md §11). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/geometry3d.h"
#include "grow.h"
#include "periodic.h"
#include "power_cell3d.h"
#include "triangulation3d.h"

/* Cells between two progress reports and cancel checks: a few milliseconds of work. */
#define CELLS_PER_REPORT 4096

typedef struct builder {
    const gp_box *box;
    size_t n;              /* the spheres; the triangulation's vertices from n on are ghosts */
    const int32_t *origin; /* per ghost, the sphere it copies (NULL: none) */
    double margin, R_max;  /* the ghosts' margin, the largest packing radius */
    int short_margin;      /* set when a cell may reach beyond the ghosts (docs/3d.md §11) */
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
    double power_carry;  /* the rounding left out of out->power_volume_sum (Neumaier) */
} builder;

/* Adds v to *sum with Neumaier's compensation in *carry: a plain sum of 10^5 cell volumes
 * drifts by 1e-12 of the total (measured: 7e-14 at 25 000 cells, 1.2e-12 at 84 000), the
 * tiling test's tolerance; compensated, the error stays at a few ulps of the total. */
static void add_compensated(double *sum, double *carry, double v)
{
    double t = *sum + v;
    *carry += fabs(*sum) >= fabs(v) ? (*sum - t) + v : (v - t) + *sum;
    *sum = t;
}

/* Shrinks the cell in bd->pc.a (docs/3d.md §7): homothetic about the centre, or offset: the
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
    if (label < 0)
        return label;
    int32_t id = bd->pc.ring[label];
    return (size_t)id >= bd->n ? bd->origin[(size_t)id - bd->n] : id; /* a ghost is its grain */
}

/* Whether every site that could cut the unshrunk cell in bd->pc.a is in the triangulation:
 * a site left out cuts the cell only if it is nearer in power than the cell's sphere to a
 * vertex v, so within sqrt(pow(v) + R_max^2) of v; that ball must lie in the box grown by
 * the ghosts' margin along the periodic axes (as laguerre.c's check in 2D). */
static int within_ghosts(const builder *bd)
{
    const poly *a = &bd->pc.a;
    const gp_sphere *p = bd->pc.p;
    const double centre[3] = {p->x, p->y, p->z}, side[3] = {bd->box->width, bd->box->height, bd->box->depth};
    for (size_t v = 0; v < a->nv; v++) {
        const double *u = a->u + 3 * v;
        double rho = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2] - p->R * p->R + bd->R_max * bd->R_max);
        for (int k = 0; k < 3; k++)
            if (((bd->box->periodic >> k) & 1u) &&
                !(centre[k] + u[k] - rho >= -bd->margin && centre[k] + u[k] + rho <= side[k] + bd->margin))
                return 0;
    }
    return 1;
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
    if (rc == 0 && holds_centre && bd->pc.a.nf >= 4 && bd->box->periodic && !within_ghosts(bd)) {
        bd->short_margin = 1;
        return GP_EGEOM; /* gp_laguerre3d widens the margin and builds the cells again */
    }
    if (rc == 0 && holds_centre && bd->pc.a.nf >= 4) {
        add_compensated(&bd->out->power_volume_sum, &bd->power_carry, poly_volume(&bd->pc.a));
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

/* The cells of spheres[0..n-1] from rt, the triangulation of spheres[0..m-1] (ghosts from
 * n on, copies of origin[g - n], within `margin` of the periodic sides). Returns 0 or a GP_E
 * code with err set; *short_margin set (and GP_EGEOM) when a cell may reach past the ghosts. */
static int cells_of(const gp_box *box, const gp_sphere *spheres, size_t n, size_t m, const int32_t *origin,
                    double margin, const gp_rt3 *rt, const gp_laguerre_params *params,
                    const gp_progress *progress, gp_cells3d *out, int *short_margin, gp_error *err)
{
    memset(out, 0, sizeof *out);
    builder bd;
    memset(&bd, 0, sizeof bd);
    bd.box = box;
    bd.n = n;
    bd.origin = origin;
    bd.margin = margin;
    for (size_t i = 0; i < n; i++)
        bd.R_max = spheres[i].R > bd.R_max ? spheres[i].R : bd.R_max;
    bd.pc.box = box;
    for (int k = 0; k < 3; k++)
        bd.pc.grow[k] = ((box->periodic >> k) & 1u) ? margin : 0.0;
    bd.pc.spheres = spheres;
    bd.params = params;
    bd.out = out;
    out->count = n;
    out->shrink = params->shrink;
    out->vstart = calloc(n + 1, sizeof *out->vstart);
    out->fstart = calloc(n + 1, sizeof *out->fstart);
    out->volume = calloc(n ? n : 1, sizeof *out->volume);
    bd.nstart = calloc(n + 1, sizeof *bd.nstart);
    bd.ring_start = malloc((m + 1) * sizeof *bd.ring_start);
    int rc = 0;
    if (gp_rt3_count(rt) != m)
        rc = gp_error_set(err, GP_EINTERNAL, NULL, "laguerre 3D: a triangulation of %zu spheres for %zu",
                          gp_rt3_count(rt), m);
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
        out->power_volume_sum += bd.power_carry;
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
    *short_margin = bd.short_margin;
    return rc;
}

/* The spheres followed by their images one period away along the periodic axes whose
 * centres lie within `margin` (at most a period) of the box: *all and *origin (per image,
 * the sphere it copies) are the caller's to free. 0 or GP_ENOMEM. */
static int images3d(const gp_box *box, const gp_sphere *spheres, size_t n, double margin, gp_sphere **all,
                    int32_t **origin, size_t *m)
{
    const double side[3] = {box->width, box->height, box->depth};
    int k[3];
    for (int a = 0; a < 3; a++)
        k[a] = (box->periodic >> a) & 1u;
    size_t cap = n + n / 2 + 16, count = n, ocap = cap - n;
    gp_sphere *s = malloc(cap * sizeof *s);
    int32_t *from = malloc(ocap * sizeof *from);
    if (!s || !from)
        goto oom;
    memcpy(s, spheres, n * sizeof *s);
    for (size_t i = 0; i < n; i++)
        for (int dx = -k[0]; dx <= k[0]; dx++)
            for (int dy = -k[1]; dy <= k[1]; dy++)
                for (int dz = -k[2]; dz <= k[2]; dz++) {
                    const int shift[3] = {dx, dy, dz};
                    gp_sphere g = spheres[i];
                    double *c[3] = {&g.x, &g.y, &g.z};
                    int inside = !(dx == 0 && dy == 0 && dz == 0);
                    for (int a = 0; a < 3 && inside; a++) {
                        *c[a] += shift[a] * side[a];
                        inside = !shift[a] || (*c[a] >= -margin && *c[a] < side[a] + margin);
                    }
                    if (!inside)
                        continue;
                    void *a = s;
                    int rc = periodic_append(&a, &cap, &count, n, &g, sizeof g, &from, &ocap, (int32_t)i);
                    s = a;
                    if (rc)
                        goto oom;
                }
    *all = s;
    *origin = from;
    *m = count;
    return 0;
oom:
    free(s);
    free(from);
    return GP_ENOMEM;
}

/* The cells on a periodic box: the ghost layer from PERIODIC_MARGIN_RADII R_max on,
 * doubled (up to the shortest periodic side) while a cell may reach past it. */
static int periodic_cells(const gp_box *box, const gp_sphere *spheres, size_t n,
                          const gp_laguerre_params *params, const gp_progress *progress, gp_cells3d *out,
                          gp_error *err)
{
    const double side[3] = {box->width, box->height, box->depth};
    double R_max = 0.0, last = INFINITY;
    for (size_t i = 0; i < n; i++)
        R_max = spheres[i].R > R_max ? spheres[i].R : R_max;
    for (int a = 0; a < 3; a++)
        if (((box->periodic >> a) & 1u) && side[a] < last)
            last = side[a];
    double margin = PERIODIC_MARGIN_RADII * R_max < last ? PERIODIC_MARGIN_RADII * R_max : last;
    for (;;) {
        gp_sphere *all;
        int32_t *origin;
        size_t m;
        gp_rt3 *rt = NULL;
        if (images3d(box, spheres, n, margin, &all, &origin, &m))
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the periodic images");
        int short_margin = 0, rc = gp_rt3_build(all, m, progress, &rt, err);
        if (rc == 0)
            rc = cells_of(box, all, n, m, origin, margin, rt, params, progress, out, &short_margin, err);
        gp_rt3_free(rt);
        free(all);
        free(origin);
        if (!short_margin)
            return rc;
        if (!(margin < last))
            return gp_error_set(err, GP_EGEOM, NULL,
                                "a periodic cell reaches beyond a whole period of images: the box is "
                                "too small for its largest void");
        margin = 2.0 * margin < last ? 2.0 * margin : last;
    }
}

int gp_laguerre3d(const gp_box *box, const gp_sphere *spheres, size_t n, const gp_rt3 *rt,
                  const gp_laguerre_params *params, const gp_progress *progress, gp_cells3d *out,
                  gp_error *err)
{
    if (box->periodic)
        return periodic_cells(box, spheres, n, params, progress, out, err);
    int short_margin;
    return cells_of(box, spheres, n, n, NULL, 0.0, rt, params, progress, out, &short_margin, err);
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
