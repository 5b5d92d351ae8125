/* mesh_bench.c - the benchmark of the mesh stage (not a test): elements per second and
 * bytes per element for the iron case, the fixed case and a 10^5-grain case, with and
 * without band_layers, side by side with Gmsh meshing the same grains and band (written
 * as a .geo file, run as `gmsh -2`, one thread, its Delaunay algorithm, its element size
 * tuned to give about as many triangles). Prints markdown.
 * Usage: grainpack_mesh_bench [--quick] [--no-gmsh] [--no-gmsh-large] [--only iron|fixed|large]
 *                             [--layers 0|2] EXAMPLES_DIR
 * (--no-gmsh-large: Gmsh on the iron and fixed cases only; on 10^5 grains it runs for
 * hours on a loaded machine). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "machine.h"
#include "bench_util.h"

/* Gmsh gets this long per run; beyond, the table says so. */
#define GMSH_TIMEOUT_SECONDS 1800
/* Gmsh's triangle count within this fraction of grainpack's needs no second run. */
#define GMSH_COUNT_TOLERANCE 0.1

/* What one mesh run measured. */
typedef struct measure {
    double wall, cpu, peak_bytes, elements, triangles, quads;
    int timed_out;
} measure;

static double cpu_seconds(const struct rusage *u)
{
    return (double)u->ru_utime.tv_sec + 1e-6 * (double)u->ru_utime.tv_usec +
           (double)u->ru_stime.tv_sec + 1e-6 * (double)u->ru_stime.tv_usec;
}

/* The mesh stage alone, never inlined: profilers single it out by name
 * (`valgrind --tool=callgrind --toggle-collect=mesh_stage`, `perf report --parent`). */
__attribute__((noinline)) static int mesh_stage(const gp_mesh_input *in, const gp_mesh_params *params,
                                                gp_mesh *mesh, gp_error *err)
{
    return gp_mesh_build(in, params, NULL, mesh, err);
}

/* The mesh stage on the structure `r`, in a child process: its time and the growth of
 * its peak resident memory. */
static measure grainpack_mesh(const gp_spec *spec, const gp_result *r)
{
    fflush(stdout); /* the child must not print the parent's buffer again */
    int fds[2];
    if (pipe(fds))
        exit(1);
    pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        struct rusage before, after;
        getrusage(RUSAGE_SELF, &before);
        gp_mesh_input in = {&spec->domain, r->packing.disks, r->packing.count, &r->cells, NULL, 0};
        gp_mesh mesh;
        gp_error err;
        double t0 = bench_now();
        if (mesh_stage(&in, &spec->mesh, &mesh, &err))
            bench_die("mesh", &err);
        measure m = {bench_now() - t0, 0, 0, (double)(mesh.ntri + mesh.nquad), (double)mesh.ntri,
                     (double)mesh.nquad, 0};
        getrusage(RUSAGE_SELF, &after);
        m.cpu = cpu_seconds(&after) - cpu_seconds(&before);
        m.peak_bytes = (double)(after.ru_maxrss - before.ru_maxrss) * 1024.0;
        if (write(fds[1], &m, sizeof m) != (ssize_t)sizeof m)
            _exit(1);
        _exit(0);
    }
    close(fds[1]);
    measure m;
    if (read(fds[0], &m, sizeof m) != (ssize_t)sizeof m)
        exit(1);
    close(fds[0]);
    waitpid(pid, NULL, 0);
    return m;
}

/* The grains and the band as Gmsh geometry: each shrunk cell a plane surface, the band
 * the domain with a hole per grain; points carry the characteristic length cl. */
static void write_geo(const char *path, const gp_spec *spec, const gp_cells *c, double cl)
{
    FILE *f = fopen(path, "w");
    if (!f)
        exit(1);
    fprintf(f, "cl = %.17g;\n", cl);
    long point = 0, line = 0, loop = 0;
    double W = spec->domain.width, H = spec->domain.height;
    double cx[4] = {0, W, W, 0}, cy[4] = {0, 0, H, H};
    for (int k = 0; k < 4; k++)
        fprintf(f, "Point(%ld) = {%.17g, %.17g, 0, cl};\n", ++point, cx[k], cy[k]);
    for (int k = 0; k < 4; k++)
        fprintf(f, "Line(%ld) = {%d, %d};\n", ++line, k + 1, (k + 1) % 4 + 1);
    fprintf(f, "Curve Loop(%ld) = {1, 2, 3, 4};\n", ++loop);
    long *grain_loop = calloc(c->count, sizeof *grain_loop);
    for (size_t i = 0; i < c->count; i++) {
        size_t n = c->start[i + 1] - c->start[i];
        if (n < 3)
            continue;
        long first_point = point + 1, first_line = line + 1;
        for (size_t k = c->start[i]; k < c->start[i + 1]; k++)
            fprintf(f, "Point(%ld) = {%.17g, %.17g, 0, cl};\n", ++point, c->xy[2 * k], c->xy[2 * k + 1]);
        for (size_t k = 0; k < n; k++)
            fprintf(f, "Line(%ld) = {%ld, %ld};\n", ++line, first_point + (long)k,
                    first_point + (long)((k + 1) % n));
        fprintf(f, "Curve Loop(%ld) = {", ++loop);
        for (size_t k = 0; k < n; k++)
            fprintf(f, "%s%ld", k ? ", " : "", first_line + (long)k);
        fputs("};\n", f);
        grain_loop[i] = loop;
        fprintf(f, "Plane Surface(%ld) = {%ld};\nPhysical Surface(\"grain_%zu\") = {%ld};\n", loop, loop, i, loop);
    }
    fprintf(f, "Plane Surface(1) = {1");
    for (size_t i = 0; i < c->count; i++)
        if (grain_loop[i])
            fprintf(f, ", %ld", grain_loop[i]);
    fprintf(f, "};\nPhysical Surface(\"grain_boundary\") = {1};\n");
    free(grain_loop);
    fclose(f);
}

/* The 2D elements of a .msh 4.1 file: the sum over its element blocks of dimension 2. */
static double msh_surface_elements(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1.0;
    char line[4096];
    double count = 0.0;
    while (fgets(line, sizeof line, f) && strncmp(line, "$Elements", 9) != 0)
        ;
    long blocks = 0;
    if (!fgets(line, sizeof line, f) || sscanf(line, "%ld", &blocks) != 1) {
        fclose(f);
        return -1.0;
    }
    for (long b = 0; b < blocks; b++) {
        int dim, tag, type;
        long n;
        if (!fgets(line, sizeof line, f) || sscanf(line, "%d %d %d %ld", &dim, &tag, &type, &n) != 4)
            break;
        if (dim == 2)
            count += (double)n;
        for (long k = 0; k < n && fgets(line, sizeof line, f); k++)
            ;
    }
    fclose(f);
    return count;
}

/* `gmsh -2` on the .geo (one thread, Delaunay), in a child: wall and CPU time, peak
 * memory, triangles made. */
static measure gmsh_mesh(const char *geo, const char *msh)
{
    measure m = {0};
    double t0 = bench_now();
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        alarm(GMSH_TIMEOUT_SECONDS);
        if (!freopen("/dev/null", "w", stdout))
            _exit(127);
        execlp("gmsh", "gmsh", "-2", geo, "-o", msh, "-format", "msh41", "-algo", "del2d", "-nt", "1",
               "-v", "1", (char *)NULL);
        _exit(127);
    }
    int status;
    struct rusage u;
    wait4(pid, &status, 0, &u);
    m.wall = bench_now() - t0;
    m.cpu = cpu_seconds(&u);
    m.peak_bytes = (double)u.ru_maxrss * 1024.0;
    if (WIFSIGNALED(status)) {
        m.timed_out = 1;
        return m;
    }
    m.elements = m.triangles = msh_surface_elements(msh);
    return m;
}

/* Gmsh at about grainpack's triangle count: a first run at the size bound times
 * *cl_ratio (the ratio a previous case found, 1 at first), then, when the count is off by
 * more than GMSH_COUNT_TOLERANCE, the size scaled by the square root of the count ratio
 * (unless `one_run`: the large case, where a run takes minutes). *cl_ratio is updated. */
static measure gmsh_matched(const gp_spec *spec, const gp_result *r, double target, const char *tmp,
                            double *cl_ratio, int one_run)
{
    char geo[512], msh[512];
    snprintf(geo, sizeof geo, "%s/bench.geo", tmp);
    snprintf(msh, sizeof msh, "%s/bench.msh", tmp);
    double cl = spec->mesh.element_size * *cl_ratio;
    measure m = {0};
    for (int round = 0; round < (one_run ? 1 : 2); round++) {
        write_geo(geo, spec, &r->cells, cl);
        m = gmsh_mesh(geo, msh);
        if (m.timed_out || m.elements <= 0)
            break;
        *cl_ratio = cl / spec->mesh.element_size * sqrt(m.elements / target);
        if (fabs(m.elements / target - 1.0) <= GMSH_COUNT_TOLERANCE)
            break;
        cl = spec->mesh.element_size * *cl_ratio;
    }
    remove(geo);
    remove(msh);
    return m;
}

static void row(const char *name, size_t grains, int layers, const measure *g, const measure *gm)
{
    printf("| %s | %zu | %d | %.0f (%.0f quads) | %.3f | %.3f | %.2f M | %.0f |", name, grains,
           layers, g->elements, g->quads, g->wall, g->cpu, g->elements / g->cpu / 1e6,
           g->peak_bytes / g->elements);
    if (!gm)
        printf(" | | | | | |\n");
    else if (gm->timed_out)
        printf(" > %d s | | | | | |\n", GMSH_TIMEOUT_SECONDS);
    else
        printf(" %.0f | %.3f | %.3f | %.2f M | %.0f | %.1f |\n", gm->elements, gm->wall, gm->cpu,
               gm->elements / gm->cpu / 1e6, gm->peak_bytes / gm->elements,
               (gm->cpu / gm->elements) / (g->cpu / g->elements));
    fflush(stdout);
}

/* Which rows of a case run (--layers): both, or only the one without or with layers. */
static enum { ROWS_BOTH, ROWS_PLAIN, ROWS_LAYERS } rows = ROWS_BOTH;

static void bench_case(const char *name, gp_spec *spec, int with_gmsh, const char *tmp,
                       double *cl_ratio, int one_run)
{
    /* the structure once: packing and offset cells, then the mesh stage alone */
    spec->mesh_enabled = 0;
    spec->laguerre_enabled = 1;
    spec->laguerre.shrink = GP_SHRINK_OFFSET;
    gp_result r;
    gp_error err;
    if (gp_pipeline_run(spec, 0, NULL, &r, &err))
        bench_die(name, &err);
    gp_mesh_params_default(&spec->dist, &spec->mesh);
    if (rows != ROWS_LAYERS) {
        measure plain = grainpack_mesh(spec, &r);
        measure gm = {0};
        if (with_gmsh)
            gm = gmsh_matched(spec, &r, plain.triangles, tmp, cl_ratio, one_run);
        row(name, r.packing.count, 0, &plain, with_gmsh ? &gm : NULL);
    }
    if (rows != ROWS_PLAIN) {
        spec->mesh.band_layers = 2;
        measure layers = grainpack_mesh(spec, &r);
        row(name, r.packing.count, 2, &layers, NULL);
    }
    gp_result_free(&r);
}

static void load(const char *dir, const char *name, gp_spec *spec)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.json", dir, name);
    gp_error err;
    if (gp_spec_load_file(path, NULL, spec, &err))
        bench_die(path, &err);
}

int main(int argc, char **argv)
{
    int quick = 0, gmsh = 1, gmsh_large = 1;
    const char *dir = NULL, *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--no-gmsh") == 0)
            gmsh = 0;
        else if (strcmp(argv[i], "--no-gmsh-large") == 0)
            gmsh_large = 0;
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (strcmp(argv[i], "--layers") == 0 && i + 1 < argc)
            rows = strcmp(argv[++i], "0") == 0 ? ROWS_PLAIN : ROWS_LAYERS;
        else
            dir = argv[i];
    }
    if (!dir) {
        fprintf(stderr, "usage: grainpack_mesh_bench [--quick] [--no-gmsh] [--no-gmsh-large] "
                        "[--only iron|fixed|large] [--layers 0|2] EXAMPLES_DIR\n");
        return 2;
    }
    char tmp[] = "/tmp/grainpack_mesh_bench.XXXXXX";
    if (!mkdtemp(tmp))
        return 1;
    print_machine();
    printf("Mesh stage alone (the packing and cells made before), default element size (half the "
           "mean grain radius), minimum angle 20.7 degrees, offset cells; Gmsh %s on the same "
           "grains and band, `gmsh -2 -algo del2d -nt 1`, its size tuned to about grainpack's "
           "triangle count (Gmsh makes no layers: its one run is set beside both rows). Rates "
           "and the ratio are per CPU second (user + system, of the child process), which a "
           "loaded machine changes less than wall time; bytes/element is the growth of the "
           "peak resident memory.\n\n",
           gmsh ? "4.8" : "(not run)");
    printf("| case | grains | band_layers | elements | wall s | CPU s | elements/CPU s | bytes/element "
           "| Gmsh triangles | Gmsh wall s | Gmsh CPU s | Gmsh elements/CPU s | Gmsh bytes/element "
           "| grainpack faster by (CPU per element) |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    gp_spec spec;
    double cl_ratio = 1.0;
    if (!only || strcmp(only, "iron") == 0) {
        load(dir, "iron", &spec);
        bench_case("iron", &spec, gmsh, tmp, &cl_ratio, 0);
        gp_spec_free(&spec);
    }
    load(dir, "fixed", &spec);
    cl_ratio = 1.0;
    if (!only || strcmp(only, "fixed") == 0)
        bench_case("fixed", &spec, gmsh, tmp, &cl_ratio, 0);
    if (only ? strcmp(only, "large") == 0 : !quick) {
        /* the fixed case scaled to 10^5 grains: it holds about 2,790 in 100 x 100 */
        double side = 100.0 * sqrt(1e5 / 2790.0);
        spec.domain = (gp_domain){side, side, 0};
        /* Gmsh once, at the size ratio the fixed case found (the same grains, scaled) */
        bench_case("fixed, 10^5 grains", &spec, gmsh && gmsh_large, tmp, &cl_ratio, 1);
    }
    gp_spec_free(&spec);
    rmdir(tmp);
    return 0;
}
