/* periodic_balance_bench.c - balancing on the torus against walls (bench/PERIODIC.md, not a
 * test): the four reference cases of examples/ packed walled and on the torus (seed 1),
 * then balanced by Laplacian smoothing and by relocation; on the torus relocation also
 * with the ghost layer made again every sweep (GP_RT_UPDATE_REBUILD) in place of ghosts
 * moved with their disks and edge flips. Prints Markdown rows: the grains with F after,
 * F_max and mean F before -> after, sweeps, layers made again, CPU seconds of gp_balance.
 * Usage: grainpack_periodic_balance_bench EXAMPLES_DIR [case ...] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "grainpack/balance.h"
#include "grainpack/pack.h"
#include "grainpack/spec.h"

/* Balances a copy of the packing; prints its row. */
static void balance_row(const char *name, const gp_spec *spec, const gp_packing *pk, gp_balance_method method,
                        gp_rt_update update)
{
    gp_disk *d = malloc(pk->count * sizeof *d);
    memcpy(d, pk->disks, pk->count * sizeof *d);
    gp_error err;
    gp_rt *rt = NULL;
    double t0 = bench_seconds(CLOCK_PROCESS_CPUTIME_ID);
    /* walls: the triangulation the pipeline hands over, counted in; the torus builds its own */
    if (!spec->domain.periodic && gp_rt_build(d, pk->count, NULL, &rt, &err))
        bench_die("triangulation", &err);
    gp_balance_params params = {method, 0, 0.0, update};
    gp_balance_result br;
    if (gp_balance(&spec->domain, d, pk->count, rt, &params, NULL, &br, &err))
        bench_die("balance", &err);
    double cpu = bench_seconds(CLOCK_PROCESS_CPUTIME_ID) - t0;
    printf("| %s | %s | %zu | %zu | %s%s | %.3f -> %.3f | %.4f -> %.4f | %u (%u) %s | %llu | %.2f |\n", name,
           spec->domain.periodic ? "torus" : "walled", pk->count, br.after.interior, gp_balance_method_name(method),
           update == GP_RT_UPDATE_REBUILD ? ", layer each sweep" : "", br.before.max, br.after.max,
           br.before.mean, br.after.mean, br.sweeps, br.best_sweep, gp_balance_stop_name(br.stop),
           (unsigned long long)br.triangulation.rebuilds, cpu);
    fflush(stdout);
    gp_balance_result_free(&br);
    gp_rt_free(rt);
    free(d);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s EXAMPLES_DIR [case ...]\n", argv[0]);
        return 2;
    }
    static const char *const all[] = {"fixed", "variable", "iron", "bagi"};
    const char *const *cases = argc > 2 ? (const char *const *)argv + 2 : all;
    int ncases = argc > 2 ? argc - 2 : 4;
    printf("| case | domain | grains | with F | method | F_max | mean F | sweeps (best) stop | layers made again | CPU (s) |\n");
    printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (int c = 0; c < ncases; c++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.json", argv[1], cases[c]);
        gp_spec spec;
        gp_error err;
        if (gp_spec_load_file(path, NULL, &spec, &err))
            bench_die(path, &err);
        for (int torus = 0; torus <= 1; torus++) {
            spec.domain.periodic = torus ? GP_PERIODIC_X | GP_PERIODIC_Y : 0;
            gp_pack_params params = gp_spec_pack_params(&spec, 0);
            params.seed = 1;
            gp_packing pk;
            if (gp_pack(&params, NULL, &pk, &err))
                bench_die("pack", &err);
            balance_row(cases[c], &spec, &pk, GP_BALANCE_LAPLACIAN, GP_RT_UPDATE_FLIPS);
            balance_row(cases[c], &spec, &pk, GP_BALANCE_RELOCATION, GP_RT_UPDATE_FLIPS);
            if (torus)
                balance_row(cases[c], &spec, &pk, GP_BALANCE_RELOCATION, GP_RT_UPDATE_REBUILD);
            gp_packing_free(&pk);
        }
        gp_spec_free(&spec);
    }
    return 0;
}
