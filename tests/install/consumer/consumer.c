/* consumer.c - a program built against the installed libgrainpack, as a user of the
 * library writes it: the one umbrella header, nothing from the source tree. It
 * packs a small domain, balances it and builds the Laguerre cells (the C++ part of the
 * library), checks what came out, and prints one line. Exit status 0 when all is right. */
#include <grainpack/grainpack.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char SPEC[] =
    "{\"inputs\": {\"domain\": {\"width\": 20, \"height\": 20},"
    " \"distribution\": {\"kind\": \"uniform\", \"min\": 0.4, \"max\": 0.9},"
    " \"joint\": {\"law\": \"constant\", \"value\": 0.05},"
    " \"balance\": {\"method\": \"relocation\"}, \"laguerre\": {\"shrink\": \"offset\"},"
    " \"seed\": 7}}";

int main(void)
{
    if (strcmp(gp_version(), GP_VERSION) != 0) {
        fprintf(stderr, "headers %s, library %s\n", GP_VERSION, gp_version());
        return 1;
    }
    gp_spec spec;
    gp_error err;
    if (gp_spec_parse(SPEC, strlen(SPEC), NULL, &spec, &err) != 0) {
        fprintf(stderr, "spec: %s: %s\n", err.pointer, err.message);
        return 1;
    }
    gp_result result;
    if (gp_pipeline_run(&spec, 0, NULL, &result, &err) != 0) {
        fprintf(stderr, "run: %s\n", err.message);
        gp_spec_free(&spec);
        return 1;
    }
    int bad = 0;
    const gp_disk *d = result.packing.disks;
    size_t n = result.packing.count;
    for (size_t i = 0; i < n; i++) {
        if (d[i].x - d[i].R < -1e-9 || d[i].x + d[i].R > 20 + 1e-9 || d[i].y - d[i].R < -1e-9 ||
            d[i].y + d[i].R > 20 + 1e-9)
            bad++;
        for (size_t j = i + 1; j < n; j++)
            if (hypot(d[i].x - d[j].x, d[i].y - d[j].y) < (d[i].R + d[j].R) * (1 - 1e-9))
                bad++;
    }
    int ok = n > 100 && bad == 0 && result.has_balance && result.has_cells &&
             result.cells.count == n && fabs(result.cells.power_area_sum - 400) < 1e-6;
    printf("grainpack %s: %zu disks, packing density %.4f, %zu cells, %d overlaps or disks outside\n",
           gp_version(), n, result.stats.packing_density, result.cells.count, bad);
    gp_result_free(&result);
    gp_spec_free(&spec);
    return ok ? 0 : 1;
}
