/* test_laguerre3d.c - the Laguerre polyhedra of 3D packings (geometry3d.h) on many seeds
 * and the three laws of docs/3d.md (one radius, 3D Bagi, iron with its joint): every cell
 * convex with planar faces counter-clockwise seen from outside, the unshrunk cells tiling
 * the box (volumes to 1e-12), each cell holding its sphere, power faces on the radical
 * planes, walls on the box's sides, offset faces j1 + j2 apart, neighbours symmetric; and
 * the statistics against an independent count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grainpack/geometry3d.h"
#include "grainpack/spec.h"
#include "triangulation3d.h"

/* Geometric tolerance of the checks, relative to the cell's packing radius: vertices are
 * accurate to ~1e-15 R, merged within 1e-12 R (laguerre3d.c). */
#define TOL 1e-9

typedef struct law3 {
    const char *name;
    int seeds;
    double side;
    gp_spec spec; /* owns the law and joint */
} law3;

static law3 laws[3] = {
    {.name = "one radius", .seeds = 3, .side = 7.0},
    {.name = "bagi", .seeds = 8, .side = 3.0},
    {.name = "iron", .seeds = 8, .side = 60.0},
};

static int pack(const law3 *law, uint64_t seed, gp_box *box, gp_packing3d *out)
{
    *box = (gp_box){law->side, law->side * 0.9, law->side * 1.1, 0};
    gp_pack3d_params p = {.box = box, .dist = &law->spec.dist, .joint = &law->spec.joint, .seed = seed};
    gp_error err;
    int rc = gp_pack3d(&p, NULL, out, &err);
    CHECK_MSG(rc == 0, "%s seed %llu: %s", law->name, (unsigned long long)seed, err.message);
    return rc;
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The unit normal (Newell) and a point (the centroid) of face f. */
static void face_plane(const gp_cells3d *c, size_t i, size_t f, double nrm[3], double g[3])
{
    const double *x = c->xyz + 3 * c->vstart[i];
    size_t b = c->fvstart[f], m = c->fvstart[f + 1] - b;
    nrm[0] = nrm[1] = nrm[2] = g[0] = g[1] = g[2] = 0.0;
    for (size_t k = 0; k < m; k++) {
        const double *p = x + 3 * c->fverts[b + k], *q = x + 3 * c->fverts[b + (k + 1) % m];
        nrm[0] += (p[1] - q[1]) * (p[2] + q[2]);
        nrm[1] += (p[2] - q[2]) * (p[0] + q[0]);
        nrm[2] += (p[0] - q[0]) * (p[1] + q[1]);
        for (int a = 0; a < 3; a++)
            g[a] += p[a] / (double)m;
    }
    double len = sqrt(dot(nrm, nrm));
    for (int a = 0; a < 3; a++)
        nrm[a] /= len;
}

/* The face of cell i toward j, or SIZE_MAX. */
static size_t face_toward(const gp_cells3d *c, size_t i, int32_t j)
{
    for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++)
        if (c->fneighbour[f] == j)
            return f;
    return SIZE_MAX;
}

/* An independent volume: tetrahedra from the cell's vertex centroid to each face's fan. */
static double volume_of(const gp_cells3d *c, size_t i)
{
    const double *x = c->xyz + 3 * c->vstart[i];
    size_t nv = c->vstart[i + 1] - c->vstart[i];
    double o[3] = {0, 0, 0}, v = 0.0;
    for (size_t k = 0; k < nv; k++)
        for (int a = 0; a < 3; a++)
            o[a] += x[3 * k + a] / (double)nv;
    for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
        size_t b = c->fvstart[f], m = c->fvstart[f + 1] - b;
        const double *p0 = x + 3 * c->fverts[b];
        for (size_t k = 1; k + 1 < m; k++) {
            const double *p1 = x + 3 * c->fverts[b + k], *p2 = x + 3 * c->fverts[b + k + 1];
            double a[3] = {p0[0] - o[0], p0[1] - o[1], p0[2] - o[2]};
            double u[3] = {p1[0] - o[0], p1[1] - o[1], p1[2] - o[2]};
            double w[3] = {p2[0] - o[0], p2[1] - o[1], p2[2] - o[2]};
            v += a[0] * (u[1] * w[2] - u[2] * w[1]) - a[1] * (u[0] * w[2] - u[2] * w[0]) +
                 a[2] * (u[0] * w[1] - u[1] * w[0]);
        }
    }
    return v / 6.0;
}

typedef struct tally {
    size_t cells, faces, bad_convex, bad_planar, bad_orient, bad_sphere, bad_power, bad_wall,
        bad_sym, bad_gap, bad_volume, gaps_checked;
} tally;

/* The checks every shrink shares: convex, planar, outward, the inscribed sphere `inner`
 * (r or R), and the cell's volume; `shrink` says what the faces' planes must be. */
static void check_cells(const gp_box *box, const gp_sphere *s, size_t n, const gp_cells3d *c,
                        gp_shrink shrink, int flush, tally *t)
{
    double side[3] = {box->width, box->height, box->depth};
    for (size_t i = 0; i < n; i++) {
        const gp_sphere *p = &s[i];
        double ctr[3] = {p->x, p->y, p->z}, tol = TOL * p->R;
        double inner = shrink == GP_SHRINK_NONE ? p->R : p->r, j = p->R - p->r;
        const double *x = c->xyz + 3 * c->vstart[i];
        size_t nv = c->vstart[i + 1] - c->vstart[i];
        t->cells++;
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
            t->faces++;
            double nrm[3], g[3];
            face_plane(c, i, f, nrm, g);
            double off = dot(nrm, g) - dot(nrm, ctr); /* the plane's distance from the centre */
            size_t b = c->fvstart[f], m = c->fvstart[f + 1] - b;
            for (size_t k = 0; k < m; k++)
                if (fabs(dot(nrm, x + 3 * c->fverts[b + k]) - dot(nrm, g)) > tol)
                    t->bad_planar++;
            for (size_t k = 0; k < nv; k++)
                if (dot(nrm, x + 3 * k) - dot(nrm, g) > tol)
                    t->bad_convex++;
            if (off < inner - tol)
                t->bad_sphere++;
            int32_t q = c->fneighbour[f];
            if (GP_IS_WALL3D(q)) {
                int k = GP_WALL3D_INDEX(q), axis = k / 2;
                double want = (k % 2 ? 1.0 : -1.0), inset = shrink == GP_SHRINK_OFFSET && !flush ? j : 0.0;
                double at = k % 2 ? side[axis] - inset : inset;
                if (fabs(nrm[axis] - want) > TOL)
                    t->bad_orient++;
                for (size_t v = 0; v < m; v++)
                    if (shrink != GP_SHRINK_HOMOTHETIC && fabs(x[3 * c->fverts[b + v] + axis] - at) > tol)
                        t->bad_wall++;
                continue;
            }
            const gp_sphere *o = &s[q];
            double d[3] = {o->x - p->x, o->y - p->y, o->z - p->z}, len = sqrt(dot(d, d));
            if (dot(nrm, d) < len * (1.0 - TOL))
                t->bad_orient++;
            if (shrink == GP_SHRINK_NONE)
                for (size_t v = 0; v < m; v++) {
                    const double *y = x + 3 * c->fverts[b + v];
                    double a[3] = {y[0] - p->x, y[1] - p->y, y[2] - p->z};
                    double e[3] = {y[0] - o->x, y[1] - o->y, y[2] - o->z};
                    double pow_p = dot(a, a) - p->R * p->R, pow_q = dot(e, e) - o->R * o->R;
                    if (fabs(pow_p - pow_q) > tol * (len + p->R))
                        t->bad_power++;
                }
            size_t back = face_toward(c, (size_t)q, (int32_t)i);
            if (shrink != GP_SHRINK_OFFSET && back == SIZE_MAX)
                t->bad_sym++;
            if (shrink == GP_SHRINK_OFFSET && back != SIZE_MAX) {
                /* the two shrunk faces on parallel planes j_p + j_q apart */
                double n2[3], g2[3];
                face_plane(c, (size_t)q, back, n2, g2);
                double gap = (dot(d, g2) - dot(d, g)) / len;
                t->gaps_checked++;
                if (fabs(gap - (j + o->R - o->r)) > tol)
                    t->bad_gap++;
            }
            if (face_toward(c, i, q) != f)
                t->bad_sym++; /* listed twice */
        }
        if (fabs(volume_of(c, i) - c->volume[i]) > 1e-12 * p->R * p->R * p->R * 100)
            t->bad_volume++;
    }
}

static void report(const char *what, const tally *t)
{
    CHECK_MSG(t->bad_convex + t->bad_planar + t->bad_orient + t->bad_sphere + t->bad_power +
                      t->bad_wall + t->bad_sym + t->bad_gap + t->bad_volume == 0,
              "%s: %zu cells, %zu faces: convex %zu planar %zu orient %zu sphere %zu power %zu wall "
              "%zu symmetry %zu gap %zu (of %zu) volume %zu",
              what, t->cells, t->faces, t->bad_convex, t->bad_planar, t->bad_orient, t->bad_sphere,
              t->bad_power, t->bad_wall, t->bad_sym, t->bad_gap, t->gaps_checked, t->bad_volume);
}

static void check_law(law3 *law)
{
    tally none = {0}, offset = {0}, flush = {0}, homo = {0};
    double worst_tiling = 0.0;
    for (int seed = 1; seed <= law->seeds; seed++) {
        gp_box box;
        gp_packing3d pk;
        if (pack(law, (uint64_t)seed, &box, &pk))
            return;
        gp_rt3 *rt;
        gp_error err;
        CHECK_MSG(gp_rt3_build(pk.spheres, pk.count, NULL, &rt, &err) == 0, "%s", err.message);
        if (!rt) {
            gp_packing3d_free(&pk);
            return;
        }
        const gp_laguerre_params params[4] = {
            {GP_SHRINK_NONE, 0}, {GP_SHRINK_OFFSET, 0}, {GP_SHRINK_OFFSET, 1}, {GP_SHRINK_HOMOTHETIC, 0}};
        tally *tallies[4] = {&none, &offset, &flush, &homo};
        double V = box.width * box.height * box.depth;
        for (int k = 0; k < 4; k++) {
            gp_cells3d c;
            int rc = gp_laguerre3d(&box, pk.spheres, pk.count, rt, &params[k], NULL, &c, &err);
            CHECK_MSG(rc == 0, "%s seed %d: %s", law->name, seed, err.message);
            if (rc)
                continue;
            CHECK(c.count == pk.count && c.shrink == params[k].shrink);
            double tiling = fabs(c.power_volume_sum - V) / V;
            worst_tiling = tiling > worst_tiling ? tiling : worst_tiling;
            CHECK_MSG(tiling <= 1e-12, "%s seed %d: power volumes %.17g, box %.17g", law->name, seed,
                      c.power_volume_sum, V);
            if (k == 0) {
                double sum = 0.0;
                for (size_t i = 0; i < c.count; i++)
                    sum += c.volume[i];
                CHECK_MSG(fabs(sum - V) <= 1e-12 * V, "%s seed %d: cell volumes %.17g, box %.17g",
                          law->name, seed, sum, V);
            }
            check_cells(&box, pk.spheres, pk.count, &c, params[k].shrink, params[k].flush_boundary, tallies[k]);
            gp_cells3d_free(&c);
        }
        gp_rt3_free(rt);
        gp_packing3d_free(&pk);
    }
    char what[96];
    snprintf(what, sizeof what, "%s none", law->name);
    report(what, &none);
    snprintf(what, sizeof what, "%s offset", law->name);
    report(what, &offset);
    snprintf(what, sizeof what, "%s offset flush", law->name);
    report(what, &flush);
    snprintf(what, sizeof what, "%s homothetic", law->name);
    report(what, &homo);
    if (law->spec.joint.law != GP_JOINT_NONE)
        CHECK_MSG(offset.gaps_checked > offset.cells, "%s: only %zu offset gaps checked", law->name,
                  offset.gaps_checked);
    fprintf(stderr, "  %s: %zu cells, %.1f faces a cell, worst tiling error %.2g, %zu offset gaps\n",
            law->name, none.cells, (double)none.faces / (double)none.cells, worst_tiling,
            offset.gaps_checked);
}

static void test_properties(void)
{
    for (int i = 0; i < 3; i++)
        check_law(&laws[i]);
}

/* The statistics against a count made here, on one iron packing with offset cells. */
static void test_stats(void)
{
    gp_box box;
    gp_packing3d pk;
    if (pack(&laws[2], 7, &box, &pk))
        return;
    gp_rt3 *rt;
    gp_error err;
    gp_cells3d c;
    gp_laguerre_params params = {GP_SHRINK_OFFSET, 0};
    CHECK(gp_rt3_build(pk.spheres, pk.count, NULL, &rt, &err) == 0);
    CHECK(gp_laguerre3d(&box, pk.spheres, pk.count, rt, &params, NULL, &c, &err) == 0);
    gp_cell3d_stats st;
    CHECK(gp_cell3d_stats_compute(&box, &laws[2].spec.dist, pk.spheres, &c, &st) == 0);
    double V = box.width * box.height * box.depth, sum = 0.0, vmax = 0.0;
    size_t walls = 0, faces = 0, hist = 0;
    for (size_t i = 0; i < c.count; i++) {
        sum += c.volume[i];
        vmax = c.volume[i] > vmax ? c.volume[i] : vmax;
        for (size_t f = c.fstart[i]; f < c.fstart[i + 1]; f++, faces++)
            walls += GP_IS_WALL3D(c.fneighbour[f]);
    }
    for (size_t k = 0; k <= st.max_faces; k++)
        hist += st.faces_histogram[k];
    CHECK(st.count == pk.count && st.faces == faces && hist == pk.count);
    CHECK_NEAR(st.boundary_fraction, 1.0 - sum / V, 1e-12);
    CHECK(st.boundary_fraction > 0.05 && st.boundary_fraction < 0.9);
    CHECK_NEAR(st.volume_max, vmax, 0.0);
    CHECK_NEAR(st.faces_mean, (double)faces / (double)c.count, 1e-12);
    CHECK_NEAR(st.neighbours_mean, (double)(faces - walls) / (double)c.count, 1e-12);
    CHECK(fabs(st.tiling_error) <= 1e-12);
    /* offset cells hold their grain: r_eq >= r */
    CHECK(st.req_ratio_mean > 1.0);
    gp_cell3d_stats_free(&st);
    gp_cells3d_free(&c);
    gp_rt3_free(rt);
    gp_packing3d_free(&pk);
}

/* Two spheres on one centre hide one vertex, and a centre outside its cell (an overlap, or
 * outside the box) makes no cell: GP_EGEOM. */
static void test_refusals(void)
{
    gp_sphere s[3] = {{1, 1, 1, 0.5, 0.5}, {1, 1, 1, 0.1, 0.1}, {2, 2, 2, 0.5, 0.5}};
    gp_rt3 *rt;
    gp_error err;
    CHECK(gp_rt3_build(s, 3, NULL, &rt, &err) == GP_EGEOM && rt == NULL);
    gp_sphere lap[3] = {{1, 1, 1, 0.5, 0.5}, {1.1, 1, 1, 0.1, 0.1}, {2, 2, 2, 0.5, 0.5}};
    gp_box box = {3, 3, 3, 0};
    gp_laguerre_params params = {GP_SHRINK_NONE, 0};
    gp_cells3d c;
    CHECK(gp_rt3_build(lap, 3, NULL, &rt, &err) == 0);
    CHECK(gp_laguerre3d(&box, lap, 3, rt, &params, NULL, &c, &err) == GP_EGEOM && c.xyz == NULL);
    gp_rt3_free(rt);
    gp_sphere t[2] = {{1, 1, 1, 0.5, 0.5}, {1.8, 1, 1, 0.5, 0.5}};
    CHECK(gp_rt3_build(t, 2, NULL, &rt, &err) == 0);
    CHECK(gp_laguerre3d(&box, t, 2, rt, &params, NULL, &c, &err) == 0);
    CHECK_NEAR(c.power_volume_sum, 27.0, 1e-12);
    /* two cells split by the radical plane x = 1.4 */
    CHECK_NEAR(c.volume[0], 1.4 * 9.0, 1e-12);
    gp_cells3d_free(&c);
    gp_rt3_free(rt);
    gp_sphere out[2] = {{1, 1, 1, 0.5, 0.5}, {4, 1, 1, 0.5, 0.5}};
    CHECK(gp_rt3_build(out, 2, NULL, &rt, &err) == 0);
    CHECK(gp_laguerre3d(&box, out, 2, rt, &params, NULL, &c, &err) == GP_EGEOM && c.xyz == NULL);
    gp_rt3_free(rt);
}

int main(void)
{
    static const char *const specs[2] = {
        "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": "
        "{\"kind\": \"constant\", \"radius\": 0.5}, \"joint\": {\"law\": \"constant\", \"value\": 0.05}}",
        "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": "
        "{\"kind\": \"uniform\", \"min\": 0.06, \"max\": 0.42}, \"joint\": {\"law\": \"constant\", \"value\": 0.01}}"};
    gp_error err;
    for (int i = 0; i < 2; i++)
        if (gp_spec_parse(specs[i], strlen(specs[i]), NULL, &laws[i].spec, &err)) {
            fprintf(stderr, "%s: %s\n", laws[i].name, err.message);
            return 1;
        }
    if (gp_spec_load_file(GP_EXAMPLES_DIR "/iron.json", NULL, &laws[2].spec, &err)) {
        fprintf(stderr, "iron: %s\n", err.message);
        return 1;
    }
    RUN(test_refusals);
    RUN(test_properties);
    RUN(test_stats);
    for (int i = 0; i < 3; i++)
        gp_spec_free(&laws[i].spec);
    return check_status();
}
