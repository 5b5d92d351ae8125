/* test_laguerre.c - the Laguerre cells over many seeds of the reference cases, checked
 * against the definition rather than the construction: every cell convex, counter-
 * clockwise, in the domain and around its disk; no cell reaches into another's power cell
 * (each vertex has no smaller power to any other disk, found by a sweep, not by the
 * triangulation); the unshrunk cells sum to the domain's area; homothetic cells follow the
 * report's formula; offset cells keep exactly j(r1) + j(r2) between neighbours. Then the
 * VTK file read back by a parser of its own, the JSON cells, and the error paths. */
#include <float.h>
#include <jansson.h>
#include <stdlib.h>

#include "check.h"
#include "grainpack/balance.h"
#include "grainpack/io.h"
#include "render_checks.h"
#include "grainpack/laguerre.h"
#include "grainpack/pack.h"
#include "packing_checks.h"

#define SEEDS 8
#define BAGI_SEEDS 2

/* Relative tolerances, each against the quantity it measures. Cell vertices are exact to
 * a few ulps of the grain size (below 1e-14 R in every case here); the packing lets disks
 * overlap by up to 1e-9 (R1 + R2) (GP_CONTACT_RTOL), which moves a radical line toward a
 * centre by up to 1e-9 R_max; the tests allow twice that. */
#define AREA_RTOL 1e-9       /* sum of cell areas against the domain's */
#define PERIODIC_AREA_RTOL 1e-12 /* the same on a periodic domain: no wall to clip at */
#define CONTAIN_RTOL 2e-9    /* a disk inside its cell, relative to R_max */
#define POWER_RTOL 1e-9      /* power distances at a vertex, relative to their size */
#define GAP_RTOL 1e-9        /* the band between offset cells, relative to j1 + j2 */
#define SHAPE_RTOL 1e-12     /* the homothety, relative to R */
/* Vertices are stored in domain coordinates, each to within a few ulps of the domain's
 * size: a turn counts as convex when it is so up to moving its three vertices that much. */
#define VERTEX_ULPS 8.0

typedef struct view {
    const double *v; /* the cell's vertices */
    size_t m;
} view;

static view cell(const gp_cells *c, size_t i)
{
    return (view){c->xy + 2 * c->start[i], c->start[i + 1] - c->start[i]};
}

static double area_of(view c)
{
    double s = 0.0;
    for (size_t k = 0; k < c.m; k++) {
        size_t l = (k + 1) % c.m;
        s += (c.v[2 * k] - c.v[0]) * (c.v[2 * l + 1] - c.v[1]) - (c.v[2 * l] - c.v[0]) * (c.v[2 * k + 1] - c.v[1]);
    }
    return 0.5 * s;
}

/* The smallest signed distance from (x, y) to the lines of the cell's edges, positive
 * inside; edges shorter than 1e-6 R are skipped (their direction is rounding noise, and
 * their neighbours' lines bound the cell there). */
static double inner_distance(view c, double x, double y, double R)
{
    double best = INFINITY;
    for (size_t k = 0; k < c.m; k++) {
        size_t l = (k + 1) % c.m;
        double ex = c.v[2 * l] - c.v[2 * k], ey = c.v[2 * l + 1] - c.v[2 * k + 1], len = hypot(ex, ey);
        if (len < 1e-6 * R)
            continue;
        double d = (ex * (y - c.v[2 * k + 1]) - ey * (x - c.v[2 * k])) / len;
        best = d < best ? d : best;
    }
    return best;
}

static int convex_ccw(view c, double L)
{
    if (c.m < 3 || !(area_of(c) > 0.0))
        return 0;
    double delta = VERTEX_ULPS * L * DBL_EPSILON;
    for (size_t k = 0; k < c.m; k++) {
        const double *a = c.v + 2 * k, *b = c.v + 2 * ((k + 1) % c.m), *d = c.v + 2 * ((k + 2) % c.m);
        double ab = hypot(b[0] - a[0], b[1] - a[1]), bd = hypot(d[0] - b[0], d[1] - b[1]),
               ad = hypot(d[0] - a[0], d[1] - a[1]);
        if (gp_orient2d(a[0], a[1], b[0], b[1], d[0], d[1]) < -delta * (ab + bd + ad))
            return 0;
    }
    return 1;
}

/* Disks sorted by x, to find those near a point without the triangulation. */
typedef struct by_x {
    x_index *order;
    size_t n;
    double R_max;
} by_x;

static by_x sort_by_x(const gp_disk *d, size_t n)
{
    by_x s = {malloc(n * sizeof(x_index)), n, 0.0};
    for (size_t i = 0; i < n; i++) {
        s.order[i] = (x_index){d[i].x, i};
        s.R_max = d[i].R > s.R_max ? d[i].R : s.R_max;
    }
    qsort(s.order, n, sizeof *s.order, compare_x);
    return s;
}

/* Whether some disk has less power at (x, y) than disk i, beyond the tolerance. */
static int vertex_leaves_power_cell(const gp_disk *d, const by_x *s, size_t i, double x, double y)
{
    double pi = (x - d[i].x) * (x - d[i].x) + (y - d[i].y) * (y - d[i].y) - d[i].R * d[i].R;
    double tol = POWER_RTOL * (fabs(pi) + 2.0 * d[i].R * d[i].R);
    /* power below pi needs |x - c|^2 < pi + R^2 <= pi + R_max^2 */
    double reach = sqrt(fmax(pi, 0.0) + s->R_max * s->R_max) + 1e-9;
    size_t lo = 0, hi = s->n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (s->order[mid].x < x - reach)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (size_t k = lo; k < s->n && s->order[k].x <= x + reach; k++) {
        const gp_disk *q = &d[s->order[k].index];
        double pq = (x - q->x) * (x - q->x) + (y - q->y) * (y - q->y) - q->R * q->R;
        if (pq < pi - tol)
            return 1;
    }
    return 0;
}

/* The distance between two convex polygons that do not overlap. */
static double polygon_distance(view a, view b)
{
    double best = INFINITY;
    for (int pass = 0; pass < 2; pass++) {
        view p = pass ? b : a, e = pass ? a : b;
        for (size_t i = 0; i < p.m; i++)
            for (size_t k = 0; k < e.m; k++) {
                const double *e0 = e.v + 2 * k, *e1 = e.v + 2 * ((k + 1) % e.m);
                double ex = e1[0] - e0[0], ey = e1[1] - e0[1], l2 = ex * ex + ey * ey;
                double t = l2 > 0.0 ? ((p.v[2 * i] - e0[0]) * ex + (p.v[2 * i + 1] - e0[1]) * ey) / l2 : 0.0;
                t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
                double dx = p.v[2 * i] - e0[0] - t * ex, dy = p.v[2 * i + 1] - e0[1] - t * ey;
                best = fmin(best, hypot(dx, dy));
            }
    }
    return best;
}

/* The extent, along the direction (ux, uy), of the part of cell c that lies on the line
 * u.x = level (within tol): [*lo, *hi], or lo > hi when no edge lies on it. */
static void extent_on_line(view c, double ux, double uy, double level, double tol, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t k = 0; k < c.m; k++) {
        size_t l = (k + 1) % c.m;
        double a = c.v[2 * k] * ux + c.v[2 * k + 1] * uy, b = c.v[2 * l] * ux + c.v[2 * l + 1] * uy;
        if (fabs(a - level) > tol || fabs(b - level) > tol)
            continue;
        /* along the line: the coordinate on the perpendicular direction (-uy, ux) */
        double ta = -c.v[2 * k] * uy + c.v[2 * k + 1] * ux, tb = -c.v[2 * l] * uy + c.v[2 * l + 1] * ux;
        *lo = fmin(*lo, fmin(ta, tb));
        *hi = fmax(*hi, fmax(ta, tb));
    }
}

typedef struct tally {
    double worst_area, worst_contain, worst_gap;
    size_t cells, pairs, exact_pairs, wider_pairs;
} tally;

/* The disks and, on a periodic domain, their images one period away on every side (the
 * 3 x 3 tiling moved back by a period): *base is where the disks themselves start. */
static gp_disk *with_images(const gp_disk *d, size_t n, const gp_domain *dom, size_t *nt, size_t *base)
{
    gp_disk *t = tile_packing(d, n, dom, 3, nt);
    int px = (dom->periodic & GP_PERIODIC_X) != 0, py = (dom->periodic & GP_PERIODIC_Y) != 0;
    for (size_t k = 0; k < *nt; k++) {
        t[k].x -= px * dom->width;
        t[k].y -= py * dom->height;
    }
    /* tile_packing's block (i, j) starts at (i ky + j) n, ky = 3 or 1 */
    *base = (size_t)(px * (py ? 3 : 1) + py) * n;
    return t;
}

/* Cell j moved to the image of disk j nearest disk i (the cell itself on walls), into
 * buf (room for its vertices); *dj gets that image of the disk. */
static view cell_near(const gp_cells *c, const gp_disk *d, const gp_domain *dom, size_t i, size_t j,
                      double *buf, gp_disk *dj)
{
    view v = cell(c, j);
    double dx = d[j].x - d[i].x, dy = d[j].y - d[i].y, sx, sy;
    gp_domain_min_image(dom, &dx, &dy);
    sx = d[i].x + dx - d[j].x;
    sy = d[i].y + dy - d[j].y;
    *dj = d[j];
    if (!dom->periodic)
        return v;
    dj->x += sx;
    dj->y += sy;
    for (size_t k = 0; k < v.m; k++) {
        buf[2 * k] = v.v[2 * k] + sx;
        buf[2 * k + 1] = v.v[2 * k + 1] + sy;
    }
    return (view){buf, v.m};
}

static void check_cells(const char *label, const gp_spec *spec, const gp_disk *d, size_t n,
                        const gp_cells *c, gp_shrink shrink, const gp_cells *plain, tally *t)
{
    double W = spec->domain.width, H = spec->domain.height;
    const gp_domain *dom = &spec->domain;
    int px = (dom->periodic & GP_PERIODIC_X) != 0, py = (dom->periodic & GP_PERIODIC_Y) != 0;
    size_t nt, base;
    gp_disk *tiled = with_images(d, n, dom, &nt, &base);
    by_x s = sort_by_x(tiled, nt);
    double *buf = malloc(2 * (c->start[n] + 1) * sizeof *buf);
    size_t bad_shape = 0, bad_contain = 0, bad_domain = 0, bad_power = 0, bad_homothety = 0,
           bad_neighbour = 0;
    double sum = 0.0;
    CHECK(c->count == n);
    for (size_t i = 0; i < n; i++) {
        view v = cell(c, i);
        sum += area_of(v);
        CHECK(fabs(c->area[i] - area_of(v)) <= 1e-12 * (c->area[i] + d[i].R * d[i].R));
        bad_shape += !convex_ccw(v, W > H ? W : H);
        /* the grain disk r in every cell; the packing disk R in the unshrunk one */
        double rho = shrink == GP_SHRINK_NONE ? d[i].R : d[i].r;
        double deficit = (rho - inner_distance(v, d[i].x, d[i].y, d[i].R)) / s.R_max;
        t->worst_contain = fmax(t->worst_contain, deficit);
        bad_contain += deficit > CONTAIN_RTOL;
        for (size_t k = 0; k < v.m; k++) {
            double x = v.v[2 * k], y = v.v[2 * k + 1], slack = 1e-12 * (W > H ? W : H);
            /* offset cells keep j(r) from the walls too */
            double inset = shrink == GP_SHRINK_OFFSET && !spec->laguerre.flush_boundary
                               ? (d[i].R - d[i].r) * (1.0 - GAP_RTOL) : 0.0;
            /* along a periodic axis a cell sticks out of the domain across the side */
            bad_domain += (!px && (x < inset - slack || x > W - inset + slack)) ||
                          (!py && (y < inset - slack || y > H - inset + slack));
            bad_power += vertex_leaves_power_cell(tiled, &s, base + i, x, y);
        }
        if (shrink == GP_SHRINK_HOMOTHETIC) {
            view u = cell(plain, i);
            double f = d[i].r / d[i].R;
            int same = u.m == v.m;
            for (size_t k = 0; k < v.m && same; k++)
                same = hypot(v.v[2 * k] - (d[i].x + f * (u.v[2 * k] - d[i].x)),
                             v.v[2 * k + 1] - (d[i].y + f * (u.v[2 * k + 1] - d[i].y))) <= SHAPE_RTOL * d[i].R;
            bad_homothety += !same;
        }
        /* neighbours: mutual, and an edge of the cell on their radical line */
        for (size_t q = c->nstart[i]; q < c->nstart[i + 1]; q++) {
            size_t j = (size_t)c->neighbours[q];
            int mutual = 0;
            for (size_t r = c->nstart[j]; r < c->nstart[j + 1]; r++)
                mutual |= (size_t)c->neighbours[r] == i;
            bad_neighbour += !mutual;
            if (shrink != GP_SHRINK_OFFSET || j < i)
                continue;
            /* the band between offset neighbours: never narrower than j1 + j2, exactly
             * that wide where both cells keep an edge facing the other */
            gp_disk dj;
            view vj = cell_near(c, d, dom, i, j, buf, &dj);
            double want = (d[i].R - d[i].r) + (dj.R - dj.r);
            double gap = polygon_distance(v, vj);
            /* relative to the band, or to the grain where there is no joint */
            double rel = (gap - want) / (want > 0.0 ? want : d[i].R);
            t->pairs++;
            CHECK_MSG(rel >= -GAP_RTOL, "%s: cells %zu and %zu are %.17g apart, want %.17g", label, i, j, gap, want);
            double len = hypot(dj.x - d[i].x, dj.y - d[i].y);
            double ux = (dj.x - d[i].x) / len, uy = (dj.y - d[i].y) / len;
            /* the radical line is u.x = level; the offset edges sit j_i below and j_j above */
            double level = (dj.x * dj.x + dj.y * dj.y - d[i].x * d[i].x - d[i].y * d[i].y +
                            d[i].R * d[i].R - dj.R * dj.R) / (2.0 * len);
            double tol = 1e-9 * d[i].R, lo_i, hi_i, lo_j, hi_j;
            extent_on_line(v, ux, uy, level - (d[i].R - d[i].r), tol, &lo_i, &hi_i);
            extent_on_line(vj, ux, uy, level + (dj.R - dj.r), tol, &lo_j, &hi_j);
            int facing = fmin(hi_i, hi_j) - fmax(lo_i, lo_j) > tol;
            if (facing) {
                CHECK_MSG(fabs(rel) <= GAP_RTOL, "%s: facing cells %zu and %zu: gap %.17g, want %.17g", label, i, j, gap, want);
                t->worst_gap = fmax(t->worst_gap, fabs(rel));
                t->exact_pairs++;
            } else {
                t->wider_pairs++;
            }
        }
    }
    t->cells += n;
    CHECK_MSG(bad_shape == 0, "%s %s: %zu cells not convex and counter-clockwise", label, gp_shrink_name(shrink), bad_shape);
    CHECK_MSG(bad_contain == 0, "%s %s: %zu cells miss part of their disk", label, gp_shrink_name(shrink), bad_contain);
    CHECK_MSG(bad_domain == 0, "%s %s: %zu vertices outside the domain", label, gp_shrink_name(shrink), bad_domain);
    CHECK_MSG(bad_power == 0, "%s %s: %zu vertices outside their power cell", label, gp_shrink_name(shrink), bad_power);
    CHECK_MSG(bad_homothety == 0, "%s: %zu cells off the homothety", label, bad_homothety);
    CHECK_MSG(bad_neighbour == 0, "%s: %zu one-sided neighbours", label, bad_neighbour);
    if (shrink == GP_SHRINK_NONE) {
        /* the periodic cells, one polygon each, tile the torus (issue 13 asks 1e-12) */
        double rtol = dom->periodic ? PERIODIC_AREA_RTOL : AREA_RTOL;
        double rel = fabs(sum - W * H) / (W * H);
        t->worst_area = fmax(t->worst_area, rel);
        CHECK_MSG(rel <= rtol, "%s: cells sum to %.17g, domain %.17g", label, sum, W * H);
        CHECK(fabs(c->power_area_sum - W * H) <= rtol * W * H);
    }
    free(s.order);
    free(tiled);
    free(buf);
}

/* Builds the cells of one structure with every shrink and checks each. */
static void check_structure(const char *label, gp_spec *spec, const gp_disk *d, size_t n, tally *t)
{
    gp_rt *rt;
    gp_error err;
    CHECK(gp_rt_build(d, n, NULL, &rt, &err) == 0);
    gp_cells plain, shrunk;
    gp_laguerre_params none = {GP_SHRINK_NONE, 0};
    CHECK(gp_laguerre(&spec->domain, d, n, rt, &none, NULL, &plain, &err) == 0);
    check_cells(label, spec, d, n, &plain, GP_SHRINK_NONE, NULL, t);
    for (int sh = GP_SHRINK_HOMOTHETIC; sh <= GP_SHRINK_OFFSET; sh++) {
        gp_laguerre_params params = {(gp_shrink)sh, 0};
        spec->laguerre = params;
        CHECK(gp_laguerre(&spec->domain, d, n, rt, &params, NULL, &shrunk, &err) == 0);
        check_cells(label, spec, d, n, &shrunk, (gp_shrink)sh, &plain, t);
        /* shrinking keeps the neighbours of the power diagram */
        CHECK(memcmp(shrunk.neighbours, plain.neighbours, plain.nstart[n] * sizeof(int32_t)) == 0);
        gp_cells_free(&shrunk);
    }
    gp_cells_free(&plain);
    gp_rt_free(rt);
}

static void test_cells_keep_every_promise_on_the_reference_cases(void)
{
    static const char *const cases[] = {"fixed", "variable", "iron", "bagi"};
    for (size_t c = 0; c < 4; c++) {
        gp_spec spec;
        load_example(cases[c], &spec);
        tally t = {0, 0, 0, 0, 0, 0, 0};
        int seeds = c == 0 ? 1 : (c == 3 ? BAGI_SEEDS : SEEDS);
        for (int seed = 1; seed <= seeds; seed++) {
            gp_packing pk;
            gp_error err;
            pack_seed(&spec, (uint64_t)seed, &pk);
            check_structure(cases[c], &spec, pk.disks, pk.count, &t);
            if (seed == 1 && c < 3) {
                /* and once balanced, as the report builds its figures */
                gp_rt *rt;
                CHECK(gp_rt_build(pk.disks, pk.count, NULL, &rt, &err) == 0);
                gp_balance_params bp = {GP_BALANCE_RELOCATION, 0, 0.0, GP_RT_UPDATE_FLIPS};
                gp_balance_result br;
                CHECK(gp_balance(&spec.domain, pk.disks, pk.count, rt, &bp, NULL, &br, &err) == 0);
                gp_balance_result_free(&br);
                gp_rt_free(rt);
                check_structure(cases[c], &spec, pk.disks, pk.count, &t);
            }
            gp_packing_free(&pk);
        }
        CHECK(t.exact_pairs > 10 * t.wider_pairs);
        fprintf(stderr,
                "  %-8s %7zu cells: area sum off by %.1e, disks inside to %.1e R_max; offset: %zu "
                "pairs, %zu at exactly j1 + j2 (worst %.1e), %zu wider (no facing edges)\n",
                cases[c], t.cells, t.worst_area, t.worst_contain, t.pairs, t.exact_pairs, t.worst_gap,
                t.wider_pairs);
        gp_spec_free(&spec);
    }
}

static void test_flush_boundary_keeps_cells_on_the_walls(void)
{
    gp_spec spec;
    load_example("variable", &spec);
    gp_packing pk;
    gp_error err;
    pack_seed(&spec, 1, &pk);
    gp_rt *rt;
    CHECK(gp_rt_build(pk.disks, pk.count, NULL, &rt, &err) == 0);
    gp_cells c;
    spec.laguerre = (gp_laguerre_params){GP_SHRINK_OFFSET, 1};
    CHECK(gp_laguerre(&spec.domain, pk.disks, pk.count, rt, &spec.laguerre, NULL, &c, &err) == 0);
    tally t = {0, 0, 0, 0, 0, 0, 0};
    check_cells("variable flush", &spec, pk.disks, pk.count, &c, GP_SHRINK_OFFSET, NULL, &t);
    /* every wall is lined with cells that reach it */
    size_t on_wall[4] = {0, 0, 0, 0};
    for (size_t k = 0; k < c.start[c.count]; k++) {
        on_wall[0] += c.xy[2 * k + 1] == 0.0;
        on_wall[1] += c.xy[2 * k] == spec.domain.width;
        on_wall[2] += c.xy[2 * k + 1] == spec.domain.height;
        on_wall[3] += c.xy[2 * k] == 0.0;
    }
    CHECK(on_wall[0] > 50 && on_wall[1] > 50 && on_wall[2] > 50 && on_wall[3] > 50);
    gp_cells_free(&c);
    gp_rt_free(rt);
    gp_packing_free(&pk);
    gp_spec_free(&spec);
}

/* Reads one whitespace-separated token; NULL at the end. */
static char *token(char **cursor)
{
    char *p = *cursor;
    while (*p == ' ' || *p == '\n')
        p++;
    if (!*p)
        return NULL;
    char *start = p;
    while (*p && *p != ' ' && *p != '\n')
        p++;
    if (*p)
        *p++ = '\0';
    *cursor = p;
    return start;
}

/* A minimal reader of the legacy VTK polydata we write: returns the number of polygons
 * (or vertices) and checks the structure and the grain data against the disks. */
static size_t read_vtk(char *text, const gp_disk *d, size_t n)
{
    char *cur = strstr(text, "DATASET POLYDATA");
    CHECK(strncmp(text, "# vtk DataFile Version 3.0\n", 27) == 0 && cur && strstr(text, "\nASCII\n"));
    if (!cur)
        return 0;
    cur += strlen("DATASET POLYDATA");
    CHECK_STR(token(&cur), "POINTS");
    size_t npoints = strtoull(token(&cur), NULL, 10);
    token(&cur); /* the type */
    for (size_t k = 0; k < 3 * npoints; k++)
        CHECK(token(&cur) != NULL);
    char *kind = token(&cur);
    size_t ncells = strtoull(token(&cur), NULL, 10), size = strtoull(token(&cur), NULL, 10), used = 0;
    CHECK(strcmp(kind, "POLYGONS") == 0 || strcmp(kind, "VERTICES") == 0);
    for (size_t i = 0; i < ncells; i++) {
        size_t m = strtoull(token(&cur), NULL, 10);
        used += m + 1;
        for (size_t k = 0; k < m; k++)
            CHECK(strtoull(token(&cur), NULL, 10) < npoints);
    }
    CHECK(used == size);
    char *data = token(&cur);
    CHECK(strcmp(data, "CELL_DATA") == 0 || strcmp(data, "POINT_DATA") == 0);
    CHECK(strtoull(token(&cur), NULL, 10) == ncells);
    size_t arrays = 0;
    char *word;
    while ((word = token(&cur))) {
        CHECK_STR(word, "SCALARS");
        char *name = token(&cur);
        token(&cur);
        token(&cur); /* type and components */
        CHECK_STR(token(&cur), "LOOKUP_TABLE");
        token(&cur);
        for (size_t i = 0; i < ncells; i++) {
            double v = strtod(token(&cur), NULL);
            if (strcmp(name, "grain_id") == 0)
                CHECK(v == (double)i);
            else if (strcmp(name, "radius") == 0 && i < n)
                CHECK(v == d[i].r);
            else if (strcmp(name, "packing_radius") == 0 && i < n)
                CHECK(v == d[i].R);
        }
        arrays++;
    }
    CHECK(arrays >= 3);
    return ncells;
}

static char *render(gp_format format, const gp_spec *spec, const gp_result *r)
{
    return render_text(format, spec, r, NULL);
}

static void test_vtk_and_json_carry_every_cell(void)
{
    gp_spec spec;
    load_example("iron", &spec);
    spec.balance_enabled = 1;
    spec.balance = (gp_balance_params){GP_BALANCE_RELOCATION, 0, 0.0, GP_RT_UPDATE_FLIPS};
    spec.laguerre_enabled = 1;
    spec.laguerre = (gp_laguerre_params){GP_SHRINK_OFFSET, 0};
    gp_result r;
    gp_error err;
    CHECK(gp_pipeline_run(&spec, 0, NULL, &r, &err) == 0);
    CHECK(r.has_cells && r.has_balance);
    char *vtk = render(GP_FORMAT_VTK, &spec, &r);
    CHECK(strstr(vtk, "POLYGONS") != NULL);
    CHECK(read_vtk(vtk, r.packing.disks, r.packing.count) == r.packing.count);
    free(vtk);

    char *text = render(GP_FORMAT_JSON, &spec, &r);
    json_error_t jerr;
    json_t *root = json_loads(text, 0, &jerr);
    CHECK_MSG(root != NULL, "%s", jerr.text);
    json_t *cells = json_object_get(root, "cells");
    CHECK(json_array_size(cells) == r.packing.count);
    size_t exact = 0;
    for (size_t i = 0; i < json_array_size(cells); i++) {
        json_t *c = json_array_get(cells, i), *poly = json_object_get(c, "polygon");
        view v = cell(&r.cells, i);
        int same = json_integer_value(json_object_get(c, "id")) == (json_int_t)i && json_array_size(poly) == v.m &&
                   json_array_size(json_object_get(c, "neighbours")) == r.cells.nstart[i + 1] - r.cells.nstart[i];
        for (size_t k = 0; k < v.m && same; k++)
            same = json_real_value(json_array_get(json_array_get(poly, k), 0)) == v.v[2 * k] &&
                   json_real_value(json_array_get(json_array_get(poly, k), 1)) == v.v[2 * k + 1];
        exact += same;
    }
    CHECK(exact == r.packing.count);
    json_t *stats = json_object_get(json_object_get(root, "statistics"), "cells");
    CHECK(json_integer_value(json_object_get(stats, "count")) == (json_int_t)r.packing.count);
    CHECK(json_real_value(json_object_get(stats, "band_fraction")) > 0.1);
    json_t *disk0 = json_array_get(json_object_get(root, "disks"), 0);
    CHECK(json_object_get(disk0, "F") != NULL);
    json_decref(root);
    free(text);

    /* a store keeps the final disks only: F and the cells rebuilt from them are the same */
    gp_result kept;
    memset(&kept, 0, sizeof kept);
    kept.packing.count = r.packing.count;
    kept.packing.disks = malloc(r.packing.count * sizeof *kept.packing.disks);
    memcpy(kept.packing.disks, r.packing.disks, r.packing.count * sizeof *kept.packing.disks);
    CHECK(gp_pack_stats_compute(&spec.domain, &spec.dist, &kept.packing, &kept.stats) == 0);
    CHECK(gp_result_rederive(&spec, &kept, &err) == 0);
    CHECK(kept.has_cells && kept.has_balance && kept.balance.after_only);
    CHECK(kept.balance.after.max == r.balance.after.max && kept.balance.after.mean == r.balance.after.mean);
    char *a = render(GP_FORMAT_VTK, &spec, &r), *b = render(GP_FORMAT_VTK, &spec, &kept);
    CHECK(strcmp(a, b) == 0);
    free(a);
    free(b);
    a = render(GP_FORMAT_JSON, &spec, &r);
    b = render(GP_FORMAT_JSON, &spec, &kept);
    CHECK(strcmp(strstr(a, "\"disks\": ["), strstr(b, "\"disks\": [")) == 0); /* disks, F and cells */
    CHECK(strstr(b, "\"before\"") == NULL && strstr(b, "\"after\"") != NULL);
    free(a);
    free(b);
    gp_result_free(&kept);

    /* without cells the VTK file holds the centres as vertices */
    gp_result_free(&r);
    spec.laguerre_enabled = 0;
    spec.balance_enabled = 0;
    CHECK(gp_pipeline_run(&spec, 0, NULL, &r, &err) == 0);
    vtk = render(GP_FORMAT_VTK, &spec, &r);
    CHECK(strstr(vtk, "VERTICES") != NULL);
    CHECK(read_vtk(vtk, r.packing.disks, r.packing.count) == r.packing.count);
    free(vtk);
    gp_result_free(&r);
    gp_spec_free(&spec);
}

static void test_a_disk_outside_its_cell_is_a_geometry_error(void)
{
    gp_domain dom = {10, 10, 0};
    gp_disk out_of_domain[3] = {{2, 2, 0.9, 1}, {5, 5, 0.9, 1}, {11, 5, 0.9, 1}};
    /* the small disk's centre is inside the big one: its power cell lies beyond it */
    gp_disk overlapping[3] = {{2, 2, 1.8, 2}, {3.5, 2, 0.9, 1}, {7, 7, 0.9, 1}};
    gp_disk *cases[2] = {out_of_domain, overlapping};
    for (int c = 0; c < 2; c++) {
        gp_rt *rt;
        gp_error err;
        CHECK(gp_rt_build(cases[c], 3, NULL, &rt, &err) == 0);
        gp_laguerre_params params = {GP_SHRINK_NONE, 0};
        gp_cells cells;
        CHECK(gp_laguerre(&dom, cases[c], 3, rt, &params, NULL, &cells, &err) == GP_EGEOM);
        CHECK(cells.xy == NULL && strstr(err.message, "outside its own power cell") != NULL);
        gp_rt_free(rt);
    }
}

static void test_one_disk_owns_the_whole_domain(void)
{
    gp_domain dom = {4, 3, 0};
    gp_disk one = {1, 1, 0.5, 0.8};
    gp_rt *rt;
    gp_error err;
    CHECK(gp_rt_build(&one, 1, NULL, &rt, &err) == 0);
    gp_laguerre_params params = {GP_SHRINK_OFFSET, 0};
    gp_cells c;
    CHECK(gp_laguerre(&dom, &one, 1, rt, &params, NULL, &c, &err) == 0);
    /* the domain inset by j = 0.3 on every side */
    CHECK(c.start[1] == 4);
    CHECK_NEAR(c.area[0], (4 - 0.6) * (3 - 0.6), 1e-12);
    CHECK_NEAR(c.power_area_sum, 12.0, 1e-12);
    gp_cells_free(&c);
    gp_rt_free(rt);
}

static void test_periodic_cells_tile_the_torus(void)
{
    /* the reference laws on the torus and on strips periodic along one axis: every check
     * above, with the power cells among all the periodic images (the 3x3 tiling) and the
     * offset band measured to the nearest image of each neighbour */
    static const struct {
        const char *name;
        double width, height;
    } cases[] = {{"fixed", 30, 30}, {"variable", 20, 24}, {"iron", 160, 140}, {"bagi", 8, 9}};
    static const unsigned modes[] = {GP_PERIODIC_X | GP_PERIODIC_Y, GP_PERIODIC_X, GP_PERIODIC_Y};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        gp_spec spec;
        load_example(cases[c].name, &spec);
        spec.domain.width = cases[c].width;
        spec.domain.height = cases[c].height;
        tally t = {0, 0, 0, 0, 0, 0, 0};
        for (size_t m = 0; m < 3; m++) {
            spec.domain.periodic = modes[m];
            for (int seed = 1; seed <= 3; seed++) {
                gp_packing pk;
                pack_seed(&spec, (uint64_t)seed, &pk);
                check_structure(cases[c].name, &spec, pk.disks, pk.count, &t);
                gp_packing_free(&pk);
            }
        }
        CHECK(t.exact_pairs > 10 * t.wider_pairs);
        fprintf(stderr,
                "  periodic %-8s %6zu cells: area sum off by %.1e; offset: %zu pairs, %zu at "
                "exactly j1 + j2 (worst %.1e), %zu wider\n",
                cases[c].name, t.cells, t.worst_area, t.pairs, t.exact_pairs, t.worst_gap, t.wider_pairs);
        gp_spec_free(&spec);
    }
}

int main(void)
{
    RUN(test_periodic_cells_tile_the_torus);
    RUN(test_one_disk_owns_the_whole_domain);
    RUN(test_a_disk_outside_its_cell_is_a_geometry_error);
    RUN(test_flush_boundary_keeps_cells_on_the_walls);
    RUN(test_vtk_and_json_carry_every_cell);
    RUN(test_cells_keep_every_promise_on_the_reference_cases);
    return check_status();
}
