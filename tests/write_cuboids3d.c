/* write_cuboids3d.c - a 3D result whose polyhedra are known exactly: the box cut by planes
 * into hexahedra of unequal sides, the cuts across x tilted (x = cut + TILT (z - depth / 2))
 * so that a section meets slanted edges, one sphere in each cell, written in every 3D
 * format for
 * test_writers3d.py to read back with Neper-format, meshio, VTK and XML readers.
 * Usage: write_cuboids3d DIR. Writes DIR/power.{tess,vtu,json} (unshrunk cells),
 * DIR/shrunk.{vtu,json,svg} (homothetic, balance F on every other grain, NaN on the
 * rest), DIR/spheres.{vtu,svg} (no cells) and DIR/cuboids.json: the cuts, for the test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/io3d.h"

static const double XS[] = {0.0, 1.3, 2.1, 4.0}, YS[] = {0.0, 0.9, 2.5}, ZS[] = {0.0, 1.1, 1.7, 3.0};
#define NX 3
#define NY 2
#define NZ 3
#define CELLS (NX * NY * NZ)
/* Slope of the inner cuts across x, along z. */
#define TILT 0.2
/* r / R: the shrink of the homothetic cells and the grain radius of the spheres. */
#define GRAIN_RATIO 0.8

static const char *SPEC = "{\"domain\": {\"width\": 4, \"height\": 2.5, \"depth\": 3},"
                          " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.2, \"max\": 0.4},"
                          " \"picture\": {\"section\": {\"axis\": \"z\", \"at\": 0.5}}}";

/* Cell id of cuboid (i, j, k); -1 outside. */
static int cell_id(int i, int j, int k)
{
    if (i < 0 || j < 0 || k < 0 || i >= NX || j >= NY || k >= NZ)
        return -1;
    return i + NX * (j + NY * k);
}

/* Where cut i across x is at height z (the walls are not tilted). */
static double xcut(int i, double z)
{
    return XS[i] + (i > 0 && i < NX ? TILT * (z - 0.5 * ZS[NZ]) : 0.0);
}

/* The cells, shrunk about their centres by `scale` (1: the power cells). */
static int make_cells(double scale, gp_cells3d *c)
{
    memset(c, 0, sizeof *c);
    c->count = CELLS;
    c->shrink = scale == 1.0 ? GP_SHRINK_NONE : GP_SHRINK_HOMOTHETIC;
    c->vstart = malloc((CELLS + 1) * sizeof *c->vstart);
    c->xyz = malloc(CELLS * 8 * 3 * sizeof *c->xyz);
    c->fstart = malloc((CELLS + 1) * sizeof *c->fstart);
    c->fvstart = malloc((CELLS * 6 + 1) * sizeof *c->fvstart);
    c->fverts = malloc(CELLS * 24 * sizeof *c->fverts);
    c->fneighbour = malloc(CELLS * 6 * sizeof *c->fneighbour);
    c->volume = malloc(CELLS * sizeof *c->volume);
    if (!c->vstart || !c->xyz || !c->fstart || !c->fvstart || !c->fverts || !c->fneighbour || !c->volume)
        return -1;
    c->vstart[0] = c->fstart[0] = c->fvstart[0] = 0;
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                int id = cell_id(i, j, k);
                double zm = 0.5 * (ZS[k] + ZS[k + 1]);
                double m[3] = {0.5 * (xcut(i, zm) + xcut(i + 1, zm)), 0.5 * (YS[j] + YS[j + 1]), zm};
                for (int b = 0; b < 8; b++) {
                    double z = ZS[k + (b >> 2 & 1)];
                    double v[3] = {xcut(i + (b & 1), z), YS[j + (b >> 1 & 1)], z};
                    for (int a = 0; a < 3; a++)
                        c->xyz[3 * (8 * (size_t)id + (size_t)b) + (size_t)a] = m[a] + scale * (v[a] - m[a]);
                }
                c->vstart[id + 1] = 8 * ((size_t)id + 1);
                c->volume[id] = scale * scale * scale * (xcut(i + 1, zm) - xcut(i, zm)) * (YS[j + 1] - YS[j]) *
                                (ZS[k + 1] - ZS[k]);
                for (int a = 0; a < 3; a++)
                    for (int s = 0; s < 2; s++) {
                        size_t f = 6 * (size_t)id + 2 * (size_t)a + (size_t)s;
                        int b = (a + 1) % 3, cc = (a + 2) % 3;
                        /* (0,0) (1,0) (1,1) (0,1) in (b, c) turns about +a: reversed on side 0 */
                        static const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
                        for (int q = 0; q < 4; q++) {
                            int qq = s ? q : 3 - q;
                            c->fverts[4 * f + (size_t)q] = (uint32_t)((s << a) | (uv[qq][0] << b) | (uv[qq][1] << cc));
                        }
                        c->fvstart[f + 1] = 4 * (f + 1);
                        int n[3] = {i, j, k};
                        n[a] += s ? 1 : -1;
                        int nb = cell_id(n[0], n[1], n[2]);
                        c->fneighbour[f] = nb >= 0 ? nb : GP_WALL3D(2 * a + s);
                    }
                c->fstart[id + 1] = 6 * ((size_t)id + 1);
            }
    double vol = 0.0;
    for (int id = 0; id < CELLS; id++)
        vol += c->volume[id] / (scale * scale * scale);
    c->power_volume_sum = vol;
    return 0;
}

static void free_cells(gp_cells3d *c)
{
    free(c->vstart);
    free(c->xyz);
    free(c->fstart);
    free(c->fvstart);
    free(c->fverts);
    free(c->fneighbour);
    free(c->volume);
    memset(c, 0, sizeof *c);
}

static int write_file(const char *dir, const char *name, gp_format3d format, const gp_spec3d *spec,
                      const gp_result3d *result)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    gp_out out;
    gp_error err;
    gp_error_clear(&err);
    if (!f || gp_out_init_file(&out, f)) {
        fprintf(stderr, "cannot write %s\n", path);
        return 1;
    }
    int rc = gp_write_result3d(&out, format, spec, result, &err);
    gp_out_free(&out);
    fclose(f);
    if (rc)
        fprintf(stderr, "%s: %s (%d)\n", path, err.message, rc);
    return rc != 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: write_cuboids3d DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    gp_spec3d spec;
    gp_error err;
    gp_error_clear(&err);
    if (gp_spec3d_parse(SPEC, strlen(SPEC), NULL, &spec, &err)) {
        fprintf(stderr, "spec: %s: %s\n", err.pointer, err.message);
        return 1;
    }
    gp_result3d result;
    memset(&result, 0, sizeof result);
    gp_sphere spheres[CELLS];
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                double R = 0.5 * fmin(fmin(XS[i + 1] - XS[i], YS[j + 1] - YS[j]), ZS[k + 1] - ZS[k]);
                double zm = 0.5 * (ZS[k] + ZS[k + 1]);
                spheres[cell_id(i, j, k)] = (gp_sphere){0.5 * (xcut(i, zm) + xcut(i + 1, zm)),
                                                        0.5 * (YS[j] + YS[j + 1]), zm, GRAIN_RATIO * R, R};
            }
    result.packing.spheres = spheres;
    result.packing.count = CELLS;
    int failed = gp_pack3d_stats_compute(&spec.box, &spec.dist, &result.packing, &result.stats);

    failed |= write_file(dir, "spheres.vtu", GP_FORMAT3D_VTU, &spec, &result);
    failed |= write_file(dir, "spheres.svg", GP_FORMAT3D_SVG, &spec, &result);
    /* tess refused without cells */
    failed |= !write_file(dir, "refused.tess", GP_FORMAT3D_TESS, &spec, &result);

    result.has_cells = 1;
    failed |= make_cells(1.0, &result.cells);
    result.cell_stats.count = CELLS;
    failed |= write_file(dir, "power.tess", GP_FORMAT3D_TESS, &spec, &result);
    failed |= write_file(dir, "power.vtu", GP_FORMAT3D_VTU, &spec, &result);
    failed |= write_file(dir, "power.json", GP_FORMAT3D_JSON, &spec, &result);
    free_cells(&result.cells);

    failed |= make_cells(GRAIN_RATIO, &result.cells);
    double F[CELLS];
    for (int i = 0; i < CELLS; i++)
        F[i] = i % 2 ? 0.01 * i : NAN;
    result.has_balance = 1;
    result.balance.F = F;
    result.balance.count = CELLS;
    failed |= write_file(dir, "shrunk.vtu", GP_FORMAT3D_VTU, &spec, &result);
    failed |= write_file(dir, "shrunk.json", GP_FORMAT3D_JSON, &spec, &result);
    failed |= write_file(dir, "shrunk.svg", GP_FORMAT3D_SVG, &spec, &result);
    free_cells(&result.cells);

    char path[4096];
    snprintf(path, sizeof path, "%s/cuboids.json", dir);
    FILE *f = fopen(path, "w");
    if (f) {
        fprintf(f, "{\"xs\": [0, 1.3, 2.1, 4.0], \"ys\": [0, 0.9, 2.5], \"zs\": [0, 1.1, 1.7, 3.0], "
                   "\"ratio\": %.17g, \"tilt\": %.17g}\n", GRAIN_RATIO, TILT);
        fclose(f);
    }
    gp_pack3d_stats_free(&result.stats);
    gp_spec3d_free(&spec);
    return failed || !f;
}
