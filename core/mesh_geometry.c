/* mesh_geometry.c - what the mesher is given: the outline of every region (the shrunk or
 * unshrunk cells, or the disks polygonised with a shared point at each contact), welded
 * so that outlines that meet share their points exactly, the domain's sides through every
 * point that lies on them, a seed inside each grain, and (band_layers) the band's
 * straight strips with their structured grid of points. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"
#include "periodic.h"

/* Points closer than this times the mean packing radius are one point. Why this value:
 * cells are computed per grain, so a vertex shared by three cells comes out three times
 * with differences of a few ulps of the coordinates (below 1e-11 R, see disk.h); and the
 * Laguerre stage already treats edges under GP_LAGUERRE_EDGE_RTOL as no edge. */
#define WELD_RTOL GP_LAGUERRE_EDGE_RTOL
/* Disks (no cells) whose gap is below this times r_i + r_j touch: their outlines share
 * one point. Packing disks without a joint touch to ~1e-9 of the radius (disk.h); a gap
 * this thin could only be meshed by a cascade of tiny elements. */
#define CONTACT_RTOL 1e-6
/* At a contact the two outlines' edges make a wedge of matrix; each edge next to the
 * contact spans at least the asked minimum angle (twice that against a wall, which is
 * flat), times this margin, so that the wedge is not below the bound the refinement
 * must meet. */
#define CONTACT_WEDGE_MARGIN 1.02
/* Two edges are parallel (a strip's sides) when their unit normals differ by less
 * than this (1 - cos of the angle). Offset cells' facing edges are parallel to rounding. */
#define STRIP_PARALLEL_TOL 1e-9
/* A strip shorter than this times its thickness is left to the junction's triangles. */
#define STRIP_MIN_LENGTH 0.5
/* A strip ends this far (times its thickness) short of where its two sides stop facing
 * each other: its protected ends are never split, so they keep away from the outlines'
 * corners and short edges, where the junction's triangles must be small. */
#define STRIP_PULLBACK 0.75

/* Periodic domains without cells: the disks' images are made this many largest packing
 * radii beyond the periodic sides, so that a disk's contacts across a side are with
 * images in its own triangulation (a touching disk's centre is within 2 R_max). */
#define CONTACT_GHOST_RADII 2.5

/* A point added to an outline edge (a strip's node): polygon, edge, position along it. */
typedef struct edge_point {
    int32_t poly, edge;
    double t;
    int32_t point;
} edge_point;

typedef struct builder {
    const gp_mesh_input *in;
    const gp_mesh_params *params;
    gp_mesh_geometry *out;
    gp_pslg *g;
    gp_error *err;
    double W, H, tol;
    unsigned periodic;       /* the domain's periodic axes */
    const gp_disk *disks;    /* the disks (and, periodic without cells, their images) */
    const gp_rt *rt;         /* their triangulation (disks without cells) */
    size_t nrt;              /* the disks in it */
    /* the outlines before welding: polygon p has raw vertices pstart[p] .. pstart[p+1]-1
       and is (a piece of) grain region[p] */
    size_t npoly;
    size_t *pstart;
    int32_t *region;
    double *raw;
    size_t nraw, raw_cap, pstart_cap, region_cap;
    /* after welding: the point of each raw vertex, and each polygon's ring without repeats */
    int32_t *ring;
    size_t *rstart;
    edge_point *extra;
    size_t nextra, extra_cap;
    gp_pair_map segments;  /* segment -> index in the pslg */
} builder;

static int oom(builder *b)
{
    return gp_error_set(b->err, GP_ENOMEM, NULL, "out of memory for the mesh geometry");
}

static int raw_vertex(builder *b, double x, double y)
{
    if (gp_mesh_reserve((void **)&b->raw, &b->raw_cap, 2 * (b->nraw + 1), sizeof *b->raw))
        return oom(b);
    b->raw[2 * b->nraw] = x;
    b->raw[2 * b->nraw + 1] = y;
    b->nraw++;
    return 0;
}

/* Closes polygon number b->npoly (its vertices are the raw ones added since the last),
 * an outline of grain `grain`. */
static int close_polygon(builder *b, size_t grain)
{
    if (gp_mesh_reserve((void **)&b->pstart, &b->pstart_cap, b->npoly + 2, sizeof *b->pstart) ||
        gp_mesh_reserve((void **)&b->region, &b->region_cap, b->npoly + 1, sizeof *b->region))
        return oom(b);
    if (b->npoly == 0)
        b->pstart[0] = 0;
    b->region[b->npoly] = (int32_t)grain;
    b->pstart[++b->npoly] = b->nraw;
    return 0;
}

/* ---- the outlines: cells ---- */

static int collect_cells(builder *b)
{
    const gp_cells *c = b->in->cells;
    for (size_t i = 0; i < c->count; i++) {
        for (size_t k = c->start[i]; k < c->start[i + 1]; k++)
            if (raw_vertex(b, c->xy[2 * k], c->xy[2 * k + 1]))
                return GP_ENOMEM;
        if (close_polygon(b, i))
            return GP_ENOMEM;
    }
    return 0;
}

/* ---- the outlines: disks with contacts ---- */

typedef struct contact {
    double angle, x, y, min_step; /* min_step: of the outline edges on either side */
    int crossing;                 /* a crossing of a periodic side's line (side_crossings) */
} contact;

static int by_angle(const void *a, const void *b)
{
    double x = ((const contact *)a)->angle, y = ((const contact *)b)->angle;
    return (x > y) - (x < y);
}

/* The angles of the outline vertices strictly between contacts a and b (arc = b - a > 0):
 * steps of at most `step`, the first and last at least their contacts' min_step. */
static int fill_arc(builder *b, const gp_disk *d, double from, double arc, double first,
                    double last, double step)
{
    double head = first, tail = last;
    int n = (int)ceil(arc / step - 1e-9);
    if (n < 1)
        n = 1;
    if (arc / n >= head && arc / n >= tail) {
        head = tail = 0.0; /* uniform steps are long enough */
    } else if (head + tail >= arc) {
        return 0; /* one chord: the contacts are too close for more */
    }
    double a0 = from + head, span = arc - head - tail;
    int m = (int)ceil(span / step - 1e-9);
    if (head == 0.0 && tail == 0.0)
        m = n;
    if (m < 1)
        m = 1;
    /* vertices at a0, a0 + span/m, ..., a0 + span (the last only if a tail step follows) */
    for (int k = head > 0.0 ? 0 : 1; k <= m; k++) {
        if (k == m && tail == 0.0)
            break;
        double a = a0 + span * k / m;
        if (raw_vertex(b, d->x + d->r * cos(a), d->y + d->r * sin(a)))
            return GP_ENOMEM;
    }
    return 0;
}

static int add_contact(contact **list, size_t *n, size_t *cap, double angle, double x, double y,
                       double min_step)
{
    if (gp_mesh_reserve((void **)list, cap, *n + 1, sizeof **list))
        return GP_ENOMEM;
    if (angle < 0.0)
        angle += 2.0 * M_PI;
    (*list)[(*n)++] = (contact){angle, x, y, min_step, 0};
    return 0;
}

/* Drops the crossings of a side's line that lie closer to a contact (around the circle)
 * than the contact's minimum step: the outline's edge from the contact then spans its
 * wedge angle and is cut by the line where it crosses it (a crossing point kept there
 * would make the two touching outlines' edges a cusp of matrix as thin as their gap). */
static void drop_crowded_crossings(contact *list, size_t *n)
{
    size_t w = 0;
    for (size_t k = 0; k < *n; k++) {
        int keep = 1;
        for (size_t c = 0; c < *n && keep && list[k].crossing; c++) {
            if (list[c].crossing)
                continue;
            double gap = fabs(list[k].angle - list[c].angle);
            keep = fmin(gap, 2.0 * M_PI - gap) >= list[c].min_step;
        }
        if (keep)
            list[w++] = list[k];
    }
    *n = w;
}

/* The contacts of disk i with the walls (the sides along walled axes). */
static int wall_contacts(builder *b, const gp_disk *d, double wall_step, contact **list,
                         size_t *n, size_t *cap)
{
    double gap = CONTACT_RTOL * 2.0 * d->r;
    int rc = 0, wx = !(b->periodic & GP_PERIODIC_X), wy = !(b->periodic & GP_PERIODIC_Y);
    if (wx && d->x - d->r <= gap)
        rc |= add_contact(list, n, cap, M_PI, 0.0, d->y, wall_step);
    if (wx && b->W - d->x - d->r <= gap)
        rc |= add_contact(list, n, cap, 0.0, b->W, d->y, wall_step);
    if (wy && d->y - d->r <= gap)
        rc |= add_contact(list, n, cap, -0.5 * M_PI, d->x, 0.0, wall_step);
    if (wy && b->H - d->y - d->r <= gap)
        rc |= add_contact(list, n, cap, 0.5 * M_PI, d->x, b->H, wall_step);
    return rc;
}

/* The points where disk d's outline meets the periodic sides' lines (x = 0 and W along
 * x, y = 0 and H along y; the disk is unwrapped, so it may cross either): where the circle
 * crosses a line, its two crossing points, so that its pieces on either side start on the
 * line at a vertex of the outline and not with a chord nearly along it (a sliver of grain
 * or of matrix as thin as the chord's distance to the line, which the refinement could
 * only fill with a cascade of tiny elements); where the circle passes within `near` of a
 * line (crossing it or not), one point on the line, as where a disk touches a wall. */
static int side_crossings(builder *b, const gp_disk *d, double near, double step, contact **list,
                          size_t *n, size_t *cap)
{
    int rc = 0;
    for (int axis = 0; axis < 2; axis++) {
        if (!(b->periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)))
            continue;
        double c0 = axis == 0 ? d->x : d->y, c1 = axis == 0 ? d->y : d->x;
        double lines[2] = {0.0, axis == 0 ? b->W : b->H};
        for (int k = 0; k < 2; k++) {
            double off = lines[k] - c0, dist = fabs(off);
            double toward = axis == 0 ? (off > 0.0 ? 0.0 : M_PI) : (off > 0.0 ? 0.5 * M_PI : -0.5 * M_PI);
            if (fabs(dist - d->r) <= near) {
                double p[2];
                p[axis] = lines[k];
                p[1 - axis] = c1;
                rc |= add_contact(list, n, cap, toward, p[0], p[1], 2.0 * step);
            } else if (dist < d->r) {
                double half = acos(dist / d->r), chord = sqrt(d->r * d->r - dist * dist);
                for (int sgn = -1; sgn <= 1; sgn += 2) {
                    /* the angle and the point: toward the line, turned by +-half */
                    double a = toward + sgn * half, p[2];
                    p[axis] = lines[k];
                    p[1 - axis] = c1 + (axis == 0 ? 1.0 : -1.0) * sgn * (off > 0.0 ? 1.0 : -1.0) * chord;
                    rc |= add_contact(list, n, cap, a, p[0], p[1], step);
                    if (rc == 0)
                        (*list)[*n - 1].crossing = 1;
                }
            }
        }
    }
    return rc;
}

static int collect_disks(builder *b, const gp_progress *progress)
{
    const gp_disk *disks = b->disks;
    size_t n = b->in->ndisks;
    double theta = b->params->min_angle * M_PI / 180.0 * CONTACT_WEDGE_MARGIN;
    double step = 2.0 * acos(1.0 - b->params->disk_tolerance);
    contact *list = NULL;
    size_t nlist = 0, list_cap = 0, ring_cap = 64;
    int32_t *ring = malloc(ring_cap * sizeof *ring);
    int rc = ring ? 0 : oom(b);
    for (size_t i = 0; i < n && rc == 0; i++) {
        if (progress && progress->cancel && (i & 4095) == 4095 &&
            atomic_load_explicit(progress->cancel, memory_order_relaxed)) {
            rc = gp_error_set(b->err, GP_ECANCELED, NULL, "mesh canceled");
            break;
        }
        const gp_disk *d = &disks[i];
        nlist = 0;
        int hull;
        size_t degree = 0;
        if (b->nrt > 1) {
            while ((degree = gp_rt_ring(b->rt, (int32_t)i, ring, ring_cap, &hull)) > ring_cap) {
                if (gp_mesh_reserve((void **)&ring, &ring_cap, degree, sizeof *ring)) {
                    rc = oom(b);
                    break;
                }
            }
        }
        for (size_t k = 0; k < degree && rc == 0; k++) {
            const gp_disk *e = &disks[ring[k]];
            double dx = e->x - d->x, dy = e->y - d->y, dist = sqrt(dx * dx + dy * dy);
            double gap = dist - d->r - e->r;
            if (gap > CONTACT_RTOL * (d->r + e->r))
                continue;
            /* the same point for both disks: computed from the lower index */
            const gp_disk *lo = (size_t)ring[k] < i ? e : d, *hi = lo == d ? e : d;
            double ux = (hi->x - lo->x) / dist, uy = (hi->y - lo->y) / dist;
            double reach = lo->r + 0.5 * gap;
            rc = add_contact(&list, &nlist, &list_cap, atan2(dy, dx), lo->x + ux * reach,
                             lo->y + uy * reach, theta);
        }
        if (rc == 0)
            rc = wall_contacts(b, d, 2.0 * theta, &list, &nlist, &list_cap) ||
                         side_crossings(b, d, b->params->disk_tolerance * d->r, theta, &list, &nlist, &list_cap)
                     ? oom(b) : 0;
        if (rc)
            break;
        drop_crowded_crossings(list, &nlist);
        if (nlist == 0) {
            int m = (int)ceil(2.0 * M_PI / step - 1e-9);
            m = m < 3 ? 3 : m;
            for (int k = 0; k < m && rc == 0; k++)
                rc = raw_vertex(b, d->x + d->r * cos(2.0 * M_PI * k / m),
                                d->y + d->r * sin(2.0 * M_PI * k / m));
        } else {
            qsort(list, nlist, sizeof *list, by_angle);
            for (size_t k = 0; k < nlist && rc == 0; k++) {
                const contact *c = &list[k], *next = &list[(k + 1) % nlist];
                double arc = next->angle - c->angle + (k + 1 == nlist ? 2.0 * M_PI : 0.0);
                if ((rc = raw_vertex(b, c->x, c->y)))
                    break;
                if (arc > 0.0)
                    rc = fill_arc(b, d, c->angle, arc, c->min_step, next->min_step, step);
            }
        }
        if (rc == 0)
            rc = close_polygon(b, i);
    }
    free(list);
    free(ring);
    return rc;
}

/* The disks' outlines on a periodic domain: their contacts across the periodic sides are
 * with images, found in a triangulation of the disks and their images (the one given is
 * of the disks alone). */
static int collect_periodic_disks(builder *b, const gp_progress *progress)
{
    const gp_mesh_input *in = b->in;
    gp_disk *images = NULL;
    int32_t *origin = NULL;
    gp_rt *own_rt = NULL;
    double R_max = 0.0;
    for (size_t i = 0; i < in->ndisks; i++)
        R_max = fmax(R_max, in->disks[i].R);
    int rc = 0;
    if (periodic_images(in->domain, in->disks, in->ndisks, CONTACT_GHOST_RADII * R_max, &images,
                        &origin, &b->nrt))
        rc = oom(b);
    else if (b->nrt > 1)
        rc = gp_rt_build(images, b->nrt, progress, &own_rt, b->err);
    b->disks = images;
    b->rt = own_rt;
    if (rc == 0)
        rc = collect_disks(b, progress);
    b->disks = in->disks;
    b->rt = NULL;
    gp_rt_free(own_rt);
    free(images);
    free(origin);
    return rc;
}

/* ---- periodic domains: the outlines cut into pieces ---- */

/* Puts the outline vertices within GP_MESH_SIDE_SNAP_RTOL mean radii of a periodic side's
 * line on it (docs/method.md §7.2). */
static void snap_to_sides(builder *b)
{
    double R_sum = 0.0;
    for (size_t i = 0; i < b->in->ndisks; i++)
        R_sum += b->in->disks[i].R;
    double eps = GP_MESH_SIDE_SNAP_RTOL * (b->in->ndisks ? R_sum / (double)b->in->ndisks : 0.0);
    for (int axis = 0; axis < 2; axis++) {
        if (!(b->periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)))
            continue;
        double period = axis == 0 ? b->W : b->H;
        for (size_t k = 0; k < b->nraw; k++) {
            double *c = &b->raw[2 * k + axis];
            if (fabs(*c) <= eps)
                *c = 0.0;
            else if (fabs(*c - period) <= eps)
                *c = period;
        }
    }
}

/* Each outline (unwrapped: it may cross the periodic sides) replaced by its pieces in
 * the domain: the parts of the outline inside the domain's translates by a period along
 * the periodic axes, each clipped in unwrapped coordinates (so that the two sides of a
 * line see the same crossing points) and moved back by its translation. A part thinner
 * than the weld tolerance is left out: its points would weld onto the side. */
static int cut_pieces(builder *b)
{
    snap_to_sides(b);
    size_t npoly = b->npoly, most = 0;
    size_t *pstart = b->pstart;
    int32_t *region = b->region;
    double *raw = b->raw;
    for (size_t p = 0; p < npoly; p++)
        most = pstart[p + 1] - pstart[p] > most ? pstart[p + 1] - pstart[p] : most;
    double *piece = malloc(2 * (most + 4) * sizeof *piece), *work = malloc(2 * (most + 4) * sizeof *work);
    b->npoly = b->nraw = b->pstart_cap = b->region_cap = b->raw_cap = 0;
    b->pstart = NULL;
    b->region = NULL;
    b->raw = NULL;
    int rc = piece && work ? 0 : oom(b);
    int kx = (b->periodic & GP_PERIODIC_X) != 0, ky = (b->periodic & GP_PERIODIC_Y) != 0;
    for (size_t p = 0; p < npoly && rc == 0; p++) {
        const double *xy = raw + 2 * pstart[p];
        size_t n = pstart[p + 1] - pstart[p];
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (size_t k = 0; k < n; k++)
            for (int a = 0; a < 2; a++) {
                lo[a] = fmin(lo[a], xy[2 * k + a]);
                hi[a] = fmax(hi[a], xy[2 * k + a]);
            }
        for (int sx = -kx; sx <= kx && rc == 0; sx++)
            for (int sy = -ky; sy <= ky && rc == 0; sy++) {
                double box[4] = {sx * b->W, (sx + 1) * b->W, sy * b->H, (sy + 1) * b->H};
                if (fmin(hi[0], box[1]) - fmax(lo[0], box[0]) <= b->tol ||
                    fmin(hi[1], box[3]) - fmax(lo[1], box[2]) <= b->tol)
                    continue;
                size_t m = gp_mesh_clip_box(xy, n, box, piece, work);
                for (size_t k = 0; k < m && rc == 0; k++)
                    rc = raw_vertex(b, piece[2 * k] - box[0], piece[2 * k + 1] - box[2]);
                if (rc == 0 && m >= 3)
                    rc = close_polygon(b, (size_t)region[p]);
                else if (rc == 0)
                    b->nraw -= m;
            }
    }
    free(piece);
    free(work);
    free(pstart);
    free(region);
    free(raw);
    return rc;
}

/* ---- welding ---- */

/* Puts raw coordinates within tol of a wall exactly on it. */
static void snap_to_walls(builder *b)
{
    for (size_t k = 0; k < b->nraw; k++) {
        double *x = &b->raw[2 * k], *y = x + 1;
        if (fabs(*x) <= b->tol)
            *x = 0.0;
        else if (fabs(*x - b->W) <= b->tol)
            *x = b->W;
        if (fabs(*y) <= b->tol)
            *y = 0.0;
        else if (fabs(*y - b->H) <= b->tol)
            *y = b->H;
    }
}

/* One pslg point per cluster of raw vertices within tol: a grid of cells of side tol
 * (hashed), each point looked for in the 3 x 3 cells around it. Fills b->ring with the
 * point of every raw vertex. */
static int weld(builder *b)
{
    b->ring = malloc((b->nraw ? b->nraw : 1) * sizeof *b->ring);
    int32_t *next = malloc((b->nraw ? b->nraw : 1) * sizeof *next); /* chains by pslg point */
    gp_pair_map cells;
    if (!b->ring || !next || gp_pair_map_init(&cells, b->nraw)) {
        free(next);
        return oom(b);
    }
    int rc = 0;
    /* (the cells' hash is of an unordered pair and of truncated coordinates: cells that
       collide share a chain, which only costs comparisons) */
    for (size_t k = 0; k < b->nraw && rc == 0; k++) {
        double x = b->raw[2 * k], y = b->raw[2 * k + 1];
        int64_t cx = (int64_t)floor(x / b->tol), cy = (int64_t)floor(y / b->tol);
        int32_t found_point = -1;
        for (int dx = -1; dx <= 1 && found_point < 0; dx++)
            for (int dy = -1; dy <= 1 && found_point < 0; dy++) {
                const int64_t *head = gp_pair_map_find(&cells, (int32_t)(cx + dx), (int32_t)(cy + dy));
                for (int64_t p = head ? *head : -1; p >= 0; p = next[p]) {
                    double ex = b->g->xy[2 * p] - x, ey = b->g->xy[2 * p + 1] - y;
                    if (ex * ex + ey * ey <= b->tol * b->tol) {
                        found_point = (int32_t)p;
                        break;
                    }
                }
            }
        if (found_point < 0) {
            found_point = gp_pslg_point(b->g, x, y);
            int found;
            int64_t *head = gp_pair_map_get(&cells, (int32_t)cx, (int32_t)cy, -1, &found);
            if (found_point < 0 || !head) {
                rc = oom(b);
                break;
            }
            next[found_point] = (int32_t)*head;
            *head = found_point;
        }
        b->ring[k] = found_point;
    }
    free(next);
    gp_pair_map_free(&cells);
    return rc;
}

/* Drops repeated consecutive points from every polygon's ring (in place): b->rstart. */
static int clean_rings(builder *b)
{
    b->rstart = malloc((b->npoly + 1) * sizeof *b->rstart);
    if (!b->rstart)
        return oom(b);
    size_t w = 0;
    for (size_t p = 0; p < b->npoly; p++) {
        size_t begin = w;
        b->rstart[p] = w;
        for (size_t k = b->pstart[p]; k < b->pstart[p + 1]; k++)
            if (w == begin || b->ring[w - 1] != b->ring[k])
                b->ring[w++] = b->ring[k];
        while (w - begin > 1 && b->ring[w - 1] == b->ring[begin])
            w--;
        if (w - begin < 3)
            w = begin; /* a grain shrunk to nothing: no region */
    }
    b->rstart[b->npoly] = w;
    return 0;
}

static double ring_area(const builder *b, size_t p)
{
    size_t begin = b->rstart[p], n = b->rstart[p + 1] - begin;
    if (n < 3)
        return 0.0;
    const double *xy = b->g->xy;
    double x0 = xy[2 * b->ring[begin]], y0 = xy[2 * b->ring[begin] + 1], sum = 0.0;
    for (size_t k = 1; k + 1 < n; k++) {
        int32_t u = b->ring[begin + k], v = b->ring[begin + k + 1];
        sum += (xy[2 * u] - x0) * (xy[2 * v + 1] - y0) - (xy[2 * u + 1] - y0) * (xy[2 * v] - x0);
    }
    return 0.5 * sum;
}

/* ---- the band's strips ---- */

static int add_extra(builder *b, int32_t poly, int32_t edge, double t, int32_t point)
{
    if (gp_mesh_reserve((void **)&b->extra, &b->extra_cap, b->nextra + 1, sizeof *b->extra))
        return oom(b);
    b->extra[b->nextra++] = (edge_point){poly, edge, t, point};
    return 0;
}

/* A segment of the pslg, once (a repeated one keeps the first; protected if either is). */
static int segment(builder *b, int32_t u, int32_t v, int protect)
{
    if (u == v)
        return 0;
    int found;
    int64_t *at = gp_pair_map_get(&b->segments, u, v, (int64_t)b->g->nsegs, &found);
    if (!at)
        return oom(b);
    if (!found)
        return gp_pslg_segment(b->g, u, v, protect) ? oom(b) : 0;
    if (protect)
        b->g->seg_protected[*at] = 1;
    return 0;
}

/* One side of a strip: an edge (a -> b) of polygon `poly`, or a wall (poly < 0), with the
 * strip's extent [s0, s1] along the unit tangent (tx, ty). */
typedef struct strip_side {
    int32_t poly, edge;
    int reversed;       /* run from the edge's end to its start */
    int32_t a, b;       /* the side's end points as run (grain sides) */
    double ax, ay, bx, by;
} strip_side;

/* The point of column c of a side, whose columns run over parameters [u0, u1] of the
 * tangent. */
static int side_point(builder *b, const strip_side *s, double tx, double ty, double u0, double u1,
                      int m, int c, int32_t *out)
{
    double u = u0 + (u1 - u0) * c / m, sa = s->ax * tx + s->ay * ty;
    double x = s->ax + tx * (u - sa), y = s->ay + ty * (u - sa);
    if (s->poly < 0) {
        /* on a wall: exactly on it */
        if (fabs(s->ax - s->bx) == 0.0)
            x = s->ax;
        else
            y = s->ay;
    }
    *out = gp_pslg_point(b->g, x, y);
    if (*out < 0)
        return oom(b);
    if (s->poly < 0)
        return 0;
    double ex = s->bx - s->ax, ey = s->by - s->ay, len2 = ex * ex + ey * ey;
    double t = ((x - s->ax) * ex + (y - s->ay) * ey) / len2;
    return add_extra(b, s->poly, s->edge, s->reversed ? 1.0 - t : t, *out);
}

/* The strip between side A (a grain's edge, tangent (tx, ty) its direction) and side B
 * (the facing grain's edge, run backwards, or a wall), thickness w. */
static int make_strip(builder *b, const strip_side *A, const strip_side *B, double tx, double ty,
                      double w)
{
    int n = b->params->band_layers;
    double a0 = A->ax * tx + A->ay * ty, a1 = A->bx * tx + A->by * ty;
    double b0 = B->ax * tx + B->ay * ty, b1 = B->bx * tx + B->by * ty;
    double s0 = fmax(a0, b0) + STRIP_PULLBACK * w, s1 = fmin(a1, b1) - STRIP_PULLBACK * w;
    if (!(s1 - s0 >= STRIP_MIN_LENGTH * w))
        return 0;
    double h = b->params->band_size > 0.0 ? b->params->band_size : w;
    double m_real = ceil((s1 - s0) / h - 1e-9);
    if (m_real > 1e6)
        m_real = 1e6; /* the element cap refuses such a strip anyway */
    int m = m_real < 1.0 ? 1 : (int)m_real;
    size_t cols = (size_t)m + 1, count = (size_t)(n + 1) * cols;
    gp_mesh_geometry *o = b->out;
    if (gp_mesh_reserve((void **)&o->strip_points, &o->strip_points_cap,
                        o->strip_start[o->nstrips] + count, sizeof *o->strip_points) ||
        gp_mesh_reserve((void **)&o->strip_start, &o->strip_start_cap, o->nstrips + 2,
                        sizeof *o->strip_start) ||
        gp_mesh_reserve((void **)&o->strip_thickness, &o->strip_thickness_cap, o->nstrips + 1,
                        sizeof *o->strip_thickness))
        return oom(b);
    int32_t *grid = o->strip_points + o->strip_start[o->nstrips];
    int rc = 0;
    for (int c = 0; c <= m && rc == 0; c++) {
        rc = side_point(b, A, tx, ty, s0, s1, m, c, &grid[c]);
        if (rc == 0)
            rc = side_point(b, B, tx, ty, s0, s1, m, c, &grid[(size_t)n * cols + c]);
    }
    /* the ends' inner points: the ends are protected, so these stay the strip's rows */
    const double *xy = b->g->xy;
    for (int r = 1; r < n && rc == 0; r++)
        for (int c = 0; c <= m && rc == 0; c++) {
            int32_t *at = &grid[(size_t)r * cols + c];
            *at = -1; /* inner columns: made once the refinement has settled the sides */
            if (c != 0 && c != m)
                continue;
            int32_t pa = grid[c], pb = grid[(size_t)n * cols + c];
            double f = (double)r / n;
            *at = gp_pslg_point(b->g, xy[2 * pa] + f * (xy[2 * pb] - xy[2 * pa]),
                                xy[2 * pa + 1] + f * (xy[2 * pb + 1] - xy[2 * pa + 1]));
            xy = b->g->xy; /* the points may have moved */
            if (*at < 0)
                rc = oom(b);
        }
    for (int r = 0; r < n && rc == 0; r++) {
        rc = segment(b, grid[(size_t)r * cols], grid[(size_t)(r + 1) * cols], 1);
        if (rc == 0)
            rc = segment(b, grid[(size_t)r * cols + m], grid[(size_t)(r + 1) * cols + m], 1);
    }
    if (rc)
        return rc;
    /* a hole seed: the middle of the first column */
    xy = b->g->xy;
    int32_t q[4] = {grid[0], grid[1], grid[(size_t)n * cols + 1], grid[(size_t)n * cols]};
    double sx = 0.0, sy = 0.0;
    for (int k = 0; k < 4; k++) {
        sx += 0.25 * xy[2 * q[k]];
        sy += 0.25 * xy[2 * q[k] + 1];
    }
    if (gp_pslg_seed(b->g, sx, sy, -1) ||
        gp_pslg_strip(b->g, grid[0], grid[m], grid[(size_t)n * cols], grid[(size_t)n * cols + m]))
        return oom(b);
    o->strip_thickness[o->nstrips] = w;
    o->strip_start[o->nstrips + 1] = o->strip_start[o->nstrips] + count;
    o->nstrips++;
    return 0;
}

static void side_of_edge(const builder *b, size_t p, size_t k, strip_side *s)
{
    size_t begin = b->rstart[p], n = b->rstart[p + 1] - begin;
    s->poly = (int32_t)p;
    s->edge = (int32_t)k;
    s->reversed = 0;
    s->a = b->ring[begin + k];
    s->b = b->ring[begin + (k + 1) % n];
    s->ax = b->g->xy[2 * s->a];
    s->ay = b->g->xy[2 * s->a + 1];
    s->bx = b->g->xy[2 * s->b];
    s->by = b->g->xy[2 * s->b + 1];
}

/* The edge of polygon p whose outward normal is (nx, ny), or -1. */
static long edge_facing(const builder *b, size_t p, double nx, double ny)
{
    size_t n = b->rstart[p + 1] - b->rstart[p];
    for (size_t k = 0; k < n; k++) {
        strip_side s;
        side_of_edge(b, p, k, &s);
        double ex = s.bx - s.ax, ey = s.by - s.ay, len = sqrt(ex * ex + ey * ey);
        if (len > 0.0 && (ey * nx - ex * ny) / len >= 1.0 - STRIP_PARALLEL_TOL)
            return (long)k;
    }
    return -1;
}

/* Whether an edge faces a wall (its outward normal points straight at it) at distance
 * j (the grain's joint, so not flush); *wall gets the wall's side of the strip, run the
 * same way as the edge, and *w the distance. */
static int facing_wall(const builder *b, const strip_side *s, double j, strip_side *wall, double *w)
{
    double ex = s->bx - s->ax, ey = s->by - s->ay, len = sqrt(ex * ex + ey * ey);
    double nx = ey / len, ny = -ex / len, lim = 1.0 - STRIP_PARALLEL_TOL;
    memset(wall, 0, sizeof *wall);
    wall->poly = -1;
    if (nx <= -lim) { /* left */
        *w = 0.5 * (s->ax + s->bx);
        wall->ax = 0.0, wall->ay = s->ay, wall->bx = 0.0, wall->by = s->by;
    } else if (nx >= lim) {
        *w = b->W - 0.5 * (s->ax + s->bx);
        wall->ax = b->W, wall->ay = s->ay, wall->bx = b->W, wall->by = s->by;
    } else if (ny <= -lim) {
        *w = 0.5 * (s->ay + s->by);
        wall->ax = s->ax, wall->ay = 0.0, wall->bx = s->bx, wall->by = 0.0;
    } else if (ny >= lim) {
        *w = b->H - 0.5 * (s->ay + s->by);
        wall->ax = s->ax, wall->ay = b->H, wall->bx = s->bx, wall->by = b->H;
    } else {
        return 0;
    }
    return *w > b->tol && fabs(*w - j) <= 1e-6 * j;
}

static int build_strips(builder *b)
{
    const gp_cells *cells = b->in->cells;
    const gp_disk *disks = b->in->disks;
    b->out->strip_start = calloc(1, sizeof *b->out->strip_start);
    if (!b->out->strip_start)
        return oom(b);
    b->out->strip_start_cap = 1;
    b->out->layers = b->params->band_layers;
    for (size_t i = 0; i < b->npoly; i++) {
        size_t n = b->rstart[i + 1] - b->rstart[i];
        for (size_t k = 0; k < n; k++) {
            strip_side A, B;
            side_of_edge(b, i, k, &A);
            double ex = A.bx - A.ax, ey = A.by - A.ay, len = sqrt(ex * ex + ey * ey);
            double tx = ex / len, ty = ey / len, nx = ty, ny = -tx;
            int partner = 0, rc = 0;
            for (size_t m = cells->nstart[i]; m < cells->nstart[i + 1] && !partner; m++) {
                size_t j = (size_t)cells->neighbours[m];
                double dx = disks[j].x - disks[i].x, dy = disks[j].y - disks[i].y;
                double dl = sqrt(dx * dx + dy * dy);
                if ((nx * dx + ny * dy) / dl < 1.0 - STRIP_PARALLEL_TOL)
                    continue;
                partner = 1;
                long e = j > i ? edge_facing(b, j, -nx, -ny) : -1;
                if (e < 0)
                    break; /* made from j, or j's edge was shrunk away */
                side_of_edge(b, j, (size_t)e, &B);
                /* B run backwards, so that both go along (tx, ty) */
                strip_side Br = B;
                Br.a = B.b, Br.b = B.a, Br.ax = B.bx, Br.ay = B.by, Br.bx = B.ax, Br.by = B.ay;
                Br.reversed = 1;
                double w = nx * (B.ax - A.ax) + ny * (B.ay - A.ay);
                rc = w > 0.0 ? make_strip(b, &A, &Br, tx, ty, w) : 0;
            }
            double w;
            if (!partner && facing_wall(b, &A, disks[i].R - disks[i].r, &B, &w))
                rc = make_strip(b, &A, &B, tx, ty, w);
            if (rc)
                return rc;
        }
    }
    return 0;
}

/* ---- segments ---- */

static int by_edge_position(const void *a, const void *b)
{
    const edge_point *x = a, *y = b;
    if (x->poly != y->poly)
        return x->poly < y->poly ? -1 : 1;
    if (x->edge != y->edge)
        return x->edge < y->edge ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

static int outline_segments(builder *b)
{
    if (b->nextra) /* no array at all when no point fell on another outline's edge */
        qsort(b->extra, b->nextra, sizeof *b->extra, by_edge_position);
    size_t e = 0;
    for (size_t p = 0; p < b->npoly; p++) {
        size_t begin = b->rstart[p], n = b->rstart[p + 1] - begin;
        for (size_t k = 0; k < n; k++) {
            int32_t from = b->ring[begin + k], to = b->ring[begin + (k + 1) % n];
            int32_t prev = from;
            for (; e < b->nextra && b->extra[e].poly == (int32_t)p && b->extra[e].edge == (int32_t)k; e++) {
                int rc = segment(b, prev, b->extra[e].point, 0);
                if (rc)
                    return rc;
                prev = b->extra[e].point;
            }
            int rc = segment(b, prev, to, 0);
            if (rc)
                return rc;
        }
    }
    return 0;
}

typedef struct wall_point {
    double along;
    int32_t point;
} wall_point;

static int by_along(const void *a, const void *b)
{
    double x = ((const wall_point *)a)->along, y = ((const wall_point *)b)->along;
    return (x > y) - (x < y);
}

/* The domain's sides, counter-clockwise, through every point lying on them; the periodic
 * ones paired. */
static int wall_segments(builder *b)
{
    int32_t corner[4];
    double cx[4] = {0.0, b->W, b->W, 0.0}, cy[4] = {0.0, 0.0, b->H, b->H};
    for (int c = 0; c < 4; c++) {
        /* a corner may already be a point (a cell's) */
        corner[c] = -1;
        for (size_t k = 0; k < b->g->npoints && corner[c] < 0; k++)
            if (b->g->xy[2 * k] == cx[c] && b->g->xy[2 * k + 1] == cy[c])
                corner[c] = (int32_t)k;
        if (corner[c] < 0 && (corner[c] = gp_pslg_point(b->g, cx[c], cy[c])) < 0)
            return oom(b);
    }
    /* the periodic pairs, each side run towards rising coordinates: left and right,
       bottom and top */
    static const int pair_corners[2][4] = {{0, 3, 1, 2}, {0, 1, 3, 2}};
    for (int axis = 0; axis < 2; axis++)
        if (b->periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)) {
            for (int k = 0; k < 4; k++)
                b->g->pair_corners[4 * b->g->npairs + k] = corner[pair_corners[axis][k]];
            b->g->npairs++;
        }
    wall_point *list = malloc((b->g->npoints + 2) * sizeof *list);
    if (!list)
        return oom(b);
    int rc = 0;
    for (int side = 0; side < 4 && rc == 0; side++) {
        /* bottom (y = 0, x rising), right (x = W, y rising), top (y = H, x falling),
           left (x = 0, y falling) */
        size_t n = 0;
        for (size_t k = 0; k < b->g->npoints; k++) {
            double x = b->g->xy[2 * k], y = b->g->xy[2 * k + 1];
            int on = side == 0 ? y == 0.0 : side == 1 ? x == b->W : side == 2 ? y == b->H : x == 0.0;
            if (on)
                list[n++] = (wall_point){side == 0 ? x : side == 1 ? y : side == 2 ? -x : -y, (int32_t)k};
        }
        qsort(list, n, sizeof *list, by_along);
        for (size_t k = 0; k + 1 < n && rc == 0; k++) {
            rc = segment(b, list[k].point, list[k + 1].point, 0);
        }
    }
    free(list);
    return rc;
}

/* The seed of polygon p's region: its disk's centre on a walled domain (the centre is in
 * its outline); on a periodic one, where a piece may not hold the centre, the mean of the
 * piece's corners (inside: a piece is convex, being a convex outline cut by a box). */
static int seed(builder *b, size_t p)
{
    double x = b->in->disks[b->region[p]].x, y = b->in->disks[b->region[p]].y;
    if (b->periodic) {
        size_t begin = b->rstart[p], n = b->rstart[p + 1] - begin;
        x = y = 0.0;
        for (size_t k = 0; k < n; k++) {
            x += b->g->xy[2 * b->ring[begin + k]] / (double)n;
            y += b->g->xy[2 * b->ring[begin + k] + 1] / (double)n;
        }
    }
    return gp_pslg_seed(b->g, x, y, b->region[p]) ? oom(b) : 0;
}

/* The smallest angle between two segments at a point, over every point. */
static int input_angles(builder *b)
{
    gp_pslg *g = b->g;
    size_t *start = calloc(g->npoints + 1, sizeof *start);
    double *angle = malloc((2 * g->nsegs + 1) * sizeof *angle);
    if (!start || !angle) {
        free(start);
        free(angle);
        return oom(b);
    }
    for (size_t s = 0; s < 2 * g->nsegs; s++)
        start[g->seg[s] + 1]++;
    for (size_t p = 0; p < g->npoints; p++)
        start[p + 1] += start[p];
    for (size_t s = 0; s < g->nsegs; s++) {
        int32_t u = g->seg[2 * s], v = g->seg[2 * s + 1];
        double dx = g->xy[2 * v] - g->xy[2 * u], dy = g->xy[2 * v + 1] - g->xy[2 * u + 1];
        angle[start[u]++] = atan2(dy, dx);
        angle[start[v]++] = atan2(-dy, -dx);
    }
    for (size_t p = g->npoints; p > 0; p--)
        start[p] = start[p - 1];
    start[0] = 0;
    double min = 2.0 * M_PI;
    for (size_t p = 0; p < g->npoints; p++) {
        size_t n = start[p + 1] - start[p];
        double *a = angle + start[p];
        for (size_t i = 1; i < n; i++) /* insertion sort: a handful each */
            for (size_t j = i; j > 0 && a[j - 1] > a[j]; j--) {
                double t = a[j];
                a[j] = a[j - 1];
                a[j - 1] = t;
            }
        for (size_t i = 0; i + 1 < n; i++)
            min = fmin(min, a[i + 1] - a[i]);
        if (n > 1)
            min = fmin(min, a[0] + 2.0 * M_PI - a[n - 1]);
    }
    b->out->min_input_angle = min * 180.0 / M_PI;
    free(start);
    free(angle);
    return 0;
}

int gp_mesh_geometry_build(const gp_mesh_input *in, const gp_mesh_params *params,
                           const gp_progress *progress, gp_mesh_geometry *out, gp_error *err)
{
    memset(out, 0, sizeof *out);
    builder b;
    memset(&b, 0, sizeof b);
    b.in = in;
    b.params = params;
    b.out = out;
    b.g = &out->pslg;
    b.err = err;
    b.W = in->domain->width;
    b.H = in->domain->height;
    b.periodic = in->domain->periodic;
    double R_sum = 0.0;
    for (size_t i = 0; i < in->ndisks; i++)
        R_sum += in->disks[i].R;
    b.tol = WELD_RTOL * (in->ndisks ? R_sum / (double)in->ndisks : fmin(b.W, b.H));
    out->ngrains = in->ndisks;
    if (!in->cells)
        out->kind = GP_MESH_DISKS_IN_MATRIX;
    else
        out->kind = in->cells->shrink == GP_SHRINK_NONE ? GP_MESH_CELLS : GP_MESH_GRAINS_AND_BAND;
    int rc = 0;
    if (params->band_layers > 0 && (!in->cells || in->cells->shrink != GP_SHRINK_OFFSET)) {
        rc = gp_error_set(err, GP_EINVAL, NULL,
                          "band_layers needs Laguerre cells shrunk by \"offset\" (whose facing "
                          "edges are parallel)");
        goto done;
    }
    if (b.periodic && params->band_layers > 0) {
        rc = gp_error_set(err, GP_EINVAL, NULL,
                          "band_layers is not available on a periodic domain (the strips would "
                          "be cut by the periodic sides)");
        goto done;
    }
    b.disks = in->disks;
    b.rt = in->rt;
    b.nrt = in->ndisks;
    if (in->cells)
        rc = collect_cells(&b);
    else
        rc = b.periodic ? collect_periodic_disks(&b, progress) : collect_disks(&b, progress);
    if (rc || (b.periodic && (rc = cut_pieces(&b))))
        goto done;
    snap_to_walls(&b);
    if (gp_pair_map_init(&b.segments, b.nraw)) {
        rc = oom(&b);
        goto done;
    }
    if ((rc = weld(&b)) || (rc = clean_rings(&b)))
        goto done;
    if (b.periodic && gp_mesh_match_sides(b.g, b.periodic, b.W, b.H, b.tol)) {
        rc = oom(&b);
        goto done;
    }
    out->region_area = calloc(out->ngrains + 1, sizeof *out->region_area);
    if (!out->region_area) {
        rc = oom(&b);
        goto done;
    }
    double grains = 0.0;
    for (size_t p = 0; p < b.npoly; p++) {
        double a = ring_area(&b, p);
        out->region_area[b.region[p]] += a;
        grains += a;
    }
    out->region_area[out->ngrains] = out->kind == GP_MESH_CELLS ? 0.0 : b.W * b.H - grains;
    if (params->band_layers > 0 && (rc = build_strips(&b)))
        goto done;
    if ((rc = outline_segments(&b)) || (rc = wall_segments(&b)))
        goto done;
    for (size_t p = 0; p < b.npoly && rc == 0; p++)
        if (b.rstart[p + 1] > b.rstart[p])
            rc = seed(&b, p);
    if (rc)
        goto done;
    b.g->default_region = out->kind == GP_MESH_CELLS ? -1 : (int32_t)out->ngrains;
    rc = input_angles(&b);
done:
    free(b.pstart);
    free(b.region);
    free(b.raw);
    free(b.ring);
    free(b.rstart);
    free(b.extra);
    gp_pair_map_free(&b.segments);
    if (rc)
        gp_mesh_geometry_free(out);
    return rc;
}

void gp_mesh_geometry_free(gp_mesh_geometry *g)
{
    gp_pslg_free(&g->pslg);
    free(g->region_area);
    free(g->strip_start);
    free(g->strip_points);
    free(g->strip_thickness);
    memset(g, 0, sizeof *g);
}
