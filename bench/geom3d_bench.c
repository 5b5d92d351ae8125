/* geom3d_bench.c - the 3D geometry's figures (bench/PACK3D.md): Laguerre polyhedra per
 * second at 10^5 and 10^6 spheres against the bare regular triangulation's build, and the
 * 3D balancing (F before and after, time) on the three reference laws; --periodic the
 * Laguerre rows alone, in the walled cube then the same cube periodic along all three axes
 * (its own triangulation of the spheres and their ghosts inside, docs/3d.md §11).
 * Usage: grainpack_geom3d_bench [--max-spheres N] [--periodic] [EXAMPLES_DIR] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "grainpack/geometry3d.h"
#include "grainpack/spec.h"
#include "machine.h"

static double cpu(void)
{
    return bench_seconds(CLOCK_PROCESS_CPUTIME_ID);
}

static void pack(const gp_box *box, const gp_distribution *dist, const gp_joint *joint, gp_packing3d *out)
{
    gp_pack3d_params params = {box, dist, joint, 1, 0, GP_PACK3D_LEVEL};
    gp_error err;
    if (gp_pack3d(&params, NULL, out, &err))
        bench_die("gp_pack3d", &err);
}

/* The Laguerre stage at about `target` spheres of radius 0.5 (no joint: shrink none, and
 * offset with a joint of 0.05 for the cost of the second clipping). */
static void laguerre_rate(const gp_distribution *one, const gp_joint *joint, double target, unsigned periodic)
{
    double side = cbrt(target * (4.0 / 3.0 * M_PI * 0.125) / 0.6);
    gp_box box = {side, side, side, periodic};
    gp_packing3d pk;
    double c0 = cpu();
    pack(&box, one, joint, &pk);
    double t_pack = cpu() - c0;
    gp_rt3 *rt;
    gp_error err;
    c0 = cpu();
    if (gp_rt3_build(pk.spheres, pk.count, NULL, &rt, &err))
        bench_die("gp_rt3_build", &err);
    double t_rt = cpu() - c0;
    static const gp_shrink shrinks[2] = {GP_SHRINK_NONE, GP_SHRINK_OFFSET};
    for (int k = 0; k < 2; k++) {
        gp_laguerre_params params = {shrinks[k], 0};
        gp_cells3d cells;
        c0 = cpu();
        if (gp_laguerre3d(&box, pk.spheres, pk.count, rt, &params, NULL, &cells, &err))
            bench_die("gp_laguerre3d", &err);
        double t = cpu() - c0;
        printf("| %zu | %s%s | %.2f | %.2f | %.2f | %.0f | %.2f | %.1f | %.2g |\n", pk.count,
               gp_shrink_name(shrinks[k]), periodic ? " (periodic cube)" : "", t_pack, t_rt, t, (double)pk.count / t, t / t_rt,
               (double)cells.fstart[cells.count] / (double)cells.count,
               (cells.power_volume_sum - side * side * side) / (side * side * side));
        fflush(stdout);
        gp_cells3d_free(&cells);
    }
    gp_rt3_free(rt);
    gp_packing3d_free(&pk);
}

static void balance_row(const char *name, const gp_spec *spec, double side, gp_balance_method method)
{
    gp_box box = {side, side, side, 0};
    gp_packing3d pk;
    pack(&box, &spec->dist, &spec->joint, &pk);
    gp_rt3 *rt;
    gp_error err;
    if (gp_rt3_build(pk.spheres, pk.count, NULL, &rt, &err))
        bench_die("gp_rt3_build", &err);
    gp_balance_params params = {method, 0, 0.0, GP_RT_UPDATE_REBUILD};
    gp_balance_result res;
    double c0 = cpu();
    if (gp_balance3d(&box, pk.spheres, pk.count, rt, &params, NULL, &res, &err))
        bench_die("gp_balance3d", &err);
    double t = cpu() - c0;
    printf("| %s | %s | %zu | %zu | %.3f -> %.3f | %.3f -> %.3f | %u (%s, best %u) | %.2f |\n", name,
           gp_balance_method_name(method), pk.count, res.before.interior, res.before.max, res.after.max,
           res.before.mean, res.after.mean, res.sweeps, gp_balance_stop_name(res.stop), res.best_sweep, t);
    fflush(stdout);
    gp_balance_result_free(&res);
    gp_rt3_free(rt);
    gp_packing3d_free(&pk);
}

int main(int argc, char **argv)
{
    double max_spheres = 1e6;
    const char *examples = "examples";
    int periodic = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--periodic") == 0)
            periodic = 1;
        else if (strcmp(argv[i], "--max-spheres") == 0 && i + 1 < argc)
            max_spheres = atof(argv[++i]);
        else
            examples = argv[i];
    }
    print_machine();
    gp_spec one, bagi, iron;
    gp_error err;
    static const char *const texts[2] = {
        "{\"domain\": {\"width\": 1, \"height\": 1}, \"distribution\": {\"kind\": \"constant\", \"radius\": 0.5}}",
        "{\"domain\": {\"width\": 1, \"height\": 1}, \"distribution\": {\"kind\": \"uniform\", \"min\": 0.06, \"max\": 0.42}}"};
    char path[4096];
    snprintf(path, sizeof path, "%s/iron.json", examples);
    if (gp_spec_parse(texts[0], strlen(texts[0]), NULL, &one, &err) ||
        gp_spec_parse(texts[1], strlen(texts[1]), NULL, &bagi, &err) ||
        gp_spec_load_file(path, NULL, &iron, &err))
        bench_die("spec", &err);
    gp_joint joint = {.law = GP_JOINT_CONSTANT, .value = 0.05};
    printf("\nLaguerre polyhedra (radius 0.5, joint 0.05, cube at density ~0.6; CPU seconds)\n\n");
    printf("| spheres | shrink | pack s | RT3 build s | Laguerre s | cells / s | Laguerre / RT3 | faces a cell | tiling error |\n");
    printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (double n = 1e5; n <= max_spheres * 1.01; n *= 10) {
        laguerre_rate(&one.dist, &joint, n, 0);
        if (periodic)
            laguerre_rate(&one.dist, &joint, n, GP_PERIODIC_X | GP_PERIODIC_Y | GP_PERIODIC_Z);
    }
    if (periodic) {
        gp_spec_free(&one);
        gp_spec_free(&bagi);
        gp_spec_free(&iron);
        return 0;
    }
    printf("\nBalancing 3D (boxes of 8 largest diameters, seed 1, rebuild per sweep; CPU seconds)\n\n");
    printf("| law | method | spheres | interior | F_max | mean F | sweeps | s |\n");
    printf("| --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (int m = 0; m < 2; m++) {
        gp_balance_method method = m ? GP_BALANCE_LAPLACIAN : GP_BALANCE_RELOCATION;
        balance_row("one radius", &one, 8.0, method);
        balance_row("3D Bagi", &bagi, 8 * 0.84, method);
        balance_row("iron (joint k = 2)", &iron, 8 * 16.5, method);
    }
    gp_spec_free(&one);
    gp_spec_free(&bagi);
    gp_spec_free(&iron);
    return 0;
}
