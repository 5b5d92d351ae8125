/* main.c - the grainpack command line: runs the job pipeline on a spec file. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "grainpack/io.h"
#include "grainpack/io3d.h"
#include "grainpack/pipeline.h"
#include "grainpack/pipeline3d.h"
#include "grainpack/spec.h"
#include "grainpack/spec3d.h"
#include "grainpack/version.h"

/* Exit statuses, documented in usage(). */
enum { EXIT_OK = 0, EXIT_FAILED = 1, EXIT_USAGE = 2, EXIT_BAD_SPEC = 3 };

static void usage(FILE *out)
{
    fputs("Usage: grainpack run SPEC.json [--process PROCESS] [--format FORMAT] [-o FILE]\n"
          "                     [--max-disks N] [--max-elements N]\n"
          "  or:  grainpack validate SPEC.json [--process PROCESS] [--max-disks N]\n"
          "                     [--max-elements N]\n"
          "  or:  grainpack --help | --version\n"
          "\n"
          "  run       packs the domain the spec describes, balances it, builds its\n"
          "            Laguerre cells and meshes it when the spec asks (\"balance\",\n"
          "            \"laguerre\", \"mesh\"), and writes the result (default JSON with\n"
          "            statistics, to standard output).\n"
          "            SPEC.json is the job spec, either {\"inputs\": {...}} or the bare\n"
          "            inputs object; '-' reads stdin.\n"
          "  validate  checks a spec and prints the expected number of disks.\n"
          "\n"
          "  --process PROCESS    pack2d (disks in a rectangle) or pack3d (spheres in a box,\n"
          "                       docs/3d.md); by default pack3d when the spec's domain has\n"
          "                       a \"depth\", else pack2d\n"
          "  -f, --format FORMAT  pack2d: json (default), csv, svg, vtk (legacy VTK), or\n"
          "                       vtu (VTK XML: the mesh, else the grains), msh (Gmsh 4.1),\n"
          "                       inp (Abaqus); msh and inp need \"mesh\" in the spec\n"
          "                       pack3d: json (default), csv (x,y,z,r,R), vtu (VTK XML:\n"
          "                       the polyhedra, else the sphere centres), tess (Neper's\n"
          "                       tessellation; needs \"laguerre\" in the spec), svg (the\n"
          "                       section of \"picture\": {\"section\": {\"axis\", \"at\"}})\n"
          "  -o FILE              write to FILE instead of standard output\n"
          "  --max-disks N        refuse specs expected to need more than N disks (or\n"
          "                       spheres; default 20000000)\n"
          "  --max-elements N     refuse meshes expected to need more than N elements,\n"
          "                       and stop a mesh that grows beyond (default 20000000)\n"
          "\n"
          "Progress goes to standard error when it is a terminal.\n"
          "Exit status: 0 success, 1 the run failed, 2 usage error, 3 invalid spec.\n",
          out);
}

/* Prints pack progress on one terminal line, only when the percentage changes. */
typedef struct terminal_progress {
    int last_percent;
} terminal_progress;

static void show_progress(void *ctx, const char *stage, double fraction)
{
    terminal_progress *tp = ctx;
    int percent = (int)(fraction * 100.0);
    if (percent == tp->last_percent)
        return;
    tp->last_percent = percent;
    fprintf(stderr, "\r%s %3d%%", stage, percent);
    fflush(stderr);
}

/* What a spec failure exits with, after saying why. */
static int spec_failure(const char *path, int rc, const gp_error *err)
{
    if (err->pointer[0])
        fprintf(stderr, "grainpack: %s: %s: %s\n", path, err->pointer, err->message);
    else
        fprintf(stderr, "grainpack: %s: %s\n", path, err->message);
    return rc == GP_EIO || rc == GP_ENOMEM ? EXIT_FAILED : EXIT_BAD_SPEC;
}

/* The spec's text ('-': standard input) in a new buffer (the caller frees it): 0 or an
 * exit status. */
static int read_spec(const char *path, char **text, size_t *len)
{
    gp_error err;
    gp_error_clear(&err);
    int rc = gp_spec_read_text(strcmp(path, "-") == 0 ? "/dev/stdin" : path, text, len, &err);
    return rc ? spec_failure(path, rc, &err) : 0;
}

/* The process the spec asks for: `forced` when given (-1: none), else by its domain. */
static gp_process spec_process(const char *text, size_t len, int forced)
{
    return forced >= 0 ? (gp_process)forced : gp_spec_process(text, len);
}


/* A spec file's name and its text, read once (standard input cannot be read twice). */
typedef struct spec_text {
    const char *path;
    char *text;
    size_t len;
} spec_text;

static int load_spec(const spec_text *st, size_t max_disks, size_t max_elements, gp_spec *spec)
{
    gp_spec_limits limits = {.max_disks = max_disks, .max_elements = max_elements};
    gp_error err;
    gp_error_clear(&err);
    int rc = gp_spec_parse(st->text, st->len, &limits, spec, &err);
    return rc ? spec_failure(st->path, rc, &err) : 0;
}

static int load_spec3d(const spec_text *st, size_t max_disks, gp_spec3d *spec)
{
    gp_spec_limits limits = {.max_disks = max_disks};
    gp_error err;
    gp_error_clear(&err);
    int rc = gp_spec3d_parse(st->text, st->len, &limits, spec, &err);
    return rc ? spec_failure(st->path, rc, &err) : 0;
}

/* Opens the output (NULL path: standard output), or says why not and returns NULL. */
static FILE *open_output(const char *out_path)
{
    FILE *out = out_path ? fopen(out_path, "wb") : stdout;
    if (!out)
        fprintf(stderr, "grainpack: cannot write %s: %s\n", out_path, strerror(errno));
    return out;
}

/* Writes to out_path (NULL: standard output) with `write`, which returns 0 or a GP_E code;
 * on any failure says so and removes the file. Returns an exit status. */
static int write_output(const char *out_path, int (*write)(gp_out *sink, const void *ctx), const void *ctx)
{
    FILE *out = open_output(out_path);
    if (!out)
        return EXIT_FAILED;
    gp_out sink;
    int rc = gp_out_init_file(&sink, out);
    if (rc == 0)
        rc = write(&sink, ctx);
    gp_out_free(&sink);
    if (out_path && fclose(out) != 0)
        rc = GP_EIO;
    else if (!out_path && fflush(out) != 0)
        rc = GP_EIO;
    if (!rc)
        return EXIT_OK;
    fprintf(stderr, "grainpack: writing %s failed: %s\n", out_path ? out_path : "stdout", gp_strerror(rc));
    if (out_path)
        remove(out_path);
    return EXIT_FAILED;
}

/* What the 2D run writes. */
typedef struct result_output {
    gp_format format;
    const gp_spec *spec;
    const gp_result *result;
} result_output;

static int write_result(gp_out *sink, const void *ctx)
{
    const result_output *what = ctx;
    return gp_write_result(sink, what->format, what->spec, what->result);
}

/* What the 3D run writes. */
typedef struct result3d_output {
    gp_format3d format;
    const gp_spec3d *spec;
    const gp_result3d *result;
    gp_error *err;
} result3d_output;

static int write_result3d(gp_out *sink, const void *ctx)
{
    const result3d_output *what = ctx;
    return gp_write_result3d(sink, what->format, what->spec, what->result, what->err);
}

/* The 3D process (docs/3d.md): packs the box, runs the stages the spec asks for and
 * writes the result in `format`. */
static int run3d(const spec_text *st, gp_format3d format, const char *out_path, size_t max_disks)
{
    gp_spec3d spec;
    int status = load_spec3d(st, max_disks, &spec);
    if (status)
        return status;
    if (format == GP_FORMAT3D_TESS && !spec.laguerre_enabled) { /* refused before the work */
        fprintf(stderr, "grainpack: %s: --format tess is the Laguerre tessellation: add \"laguerre\": {} "
                        "to the spec\n", st->path);
        gp_spec3d_free(&spec);
        return EXIT_USAGE;
    }
    terminal_progress tp = {-1};
    gp_progress progress = {show_progress, &tp, NULL};
    int tty = isatty(STDERR_FILENO);
    gp_result3d result;
    gp_error err;
    gp_error_clear(&err);
    int rc = gp_pipeline3d_run(&spec, max_disks ? max_disks : GP_SPEC_DEFAULT_MAX_DISKS,
                               tty ? &progress : NULL, &result, &err);
    if (tty)
        fputs("\r          \r", stderr);
    if (rc) {
        fprintf(stderr, "grainpack: %s: %s\n", st->path, err.message);
        gp_spec3d_free(&spec);
        return EXIT_FAILED;
    }
    if (gp_format3d_check(format, &result, &err)) {
        fprintf(stderr, "grainpack: %s: --format %s: %s\n", st->path, gp_format3d_name(format), err.message);
        gp_result3d_free(&result);
        gp_spec3d_free(&spec);
        return EXIT_USAGE;
    }
    if (tty)
    {
        fprintf(stderr, "grainpack: %zu spheres, packing density %.4f, %.1f ms\n", result.stats.count,
                result.stats.packing_density, 1e3 * gp_result3d_stage_seconds(&result, "pack"));
        if (result.has_cells)
            fprintf(stderr, "grainpack: %zu polyhedra (%s), %.2f faces each, boundary phase %.4f of the "
                            "box, %.1f ms\n",
                    result.cell_stats.count, gp_shrink_name(result.cells.shrink), result.cell_stats.faces_mean,
                    result.cell_stats.boundary_fraction, 1e3 * gp_result3d_stage_seconds(&result, "laguerre"));
    }
    result3d_output what = {format, &spec, &result, &err};
    status = write_output(out_path, write_result3d, &what);
    if (status && err.code)
        fprintf(stderr, "grainpack: %s: %s\n", st->path, err.message);
    gp_result3d_free(&result);
    gp_spec3d_free(&spec);
    return status;
}

static int run(const spec_text *st, gp_format format, const char *out_path, size_t max_disks,
               size_t max_elements)
{
    const char *spec_path = st->path;
    gp_spec spec;
    int status = load_spec(st, max_disks, max_elements, &spec);
    if (status)
        return status;
    if (gp_format_needs_mesh(format) && !spec.mesh_enabled) {
        fprintf(stderr, "grainpack: %s: --format %s needs a mesh: add \"mesh\": {} to the spec\n",
                spec_path, gp_format_name(format));
        gp_spec_free(&spec);
        return EXIT_USAGE;
    }

    terminal_progress tp = {-1};
    gp_progress progress = {show_progress, &tp, NULL};
    int tty = isatty(STDERR_FILENO);
    gp_result result;
    gp_error err;
    gp_error_clear(&err);
    int rc = gp_pipeline_run(&spec, max_disks ? max_disks : GP_SPEC_DEFAULT_MAX_DISKS,
                             tty ? &progress : NULL, &result, &err);
    if (tty)
        fputs("\r          \r", stderr);
    if (rc) {
        fprintf(stderr, "grainpack: %s: %s\n", spec_path, err.message);
        gp_spec_free(&spec);
        return EXIT_FAILED;
    }
    if (tty) {
        fprintf(stderr, "grainpack: %zu disks, packing density %.4f, %.1f ms\n", result.stats.count,
                result.stats.packing_density, 1e3 * gp_result_stage_seconds(&result, "pack"));
        if (result.has_balance)
            fprintf(stderr, "grainpack: %s: F_max %.4f -> %.4f, mean F %.4f -> %.4f, %u sweeps, %.1f ms\n",
                    gp_balance_method_name(result.balance.method), result.balance.before.max,
                    result.balance.after.max, result.balance.before.mean, result.balance.after.mean,
                    result.balance.sweeps, 1e3 * gp_result_stage_seconds(&result, "balance"));
        if (result.has_cells)
            fprintf(stderr, "grainpack: %zu cells (%s), boundary band %.4f of the domain, %.1f ms\n",
                    result.cell_stats.count, gp_shrink_name(result.cells.shrink),
                    result.cell_stats.band_fraction, 1e3 * gp_result_stage_seconds(&result, "laguerre"));
        if (result.has_mesh)
            fprintf(stderr, "grainpack: mesh: %zu nodes, %zu triangles, %zu quadrilaterals, angles "
                            "%.2f to %.2f degrees, %.1f ms\n",
                    result.mesh.stats.nodes, result.mesh.stats.triangles, result.mesh.stats.quads,
                    result.mesh.stats.min_angle, result.mesh.stats.max_angle,
                    1e3 * gp_result_stage_seconds(&result, "mesh"));
    }

    result_output what = {format, &spec, &result};
    status = write_output(out_path, write_result, &what);
    gp_result_free(&result);
    gp_spec_free(&spec);
    return status;
}

static int validate3d(const spec_text *st, size_t max_disks)
{
    gp_spec3d spec;
    int status = load_spec3d(st, max_disks, &spec);
    if (status)
        return status;
    printf("%s: valid (pack3d), about %.0f spheres expected\n", st->path, spec.expected_spheres);
    gp_spec3d_free(&spec);
    return EXIT_OK;
}

static int validate(const spec_text *st, size_t max_disks, size_t max_elements)
{
    const char *spec_path = st->path;
    gp_spec spec;
    int status = load_spec(st, max_disks, max_elements, &spec);
    if (status)
        return status;
    printf("%s: valid, about %.0f disks expected", spec_path, spec.expected_disks);
    if (spec.mesh_enabled)
        printf(", about %.0f mesh elements", spec.expected_elements);
    putchar('\n');
    gp_spec_free(&spec);
    return EXIT_OK;
}

static int parse_count(const char *text, size_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || end == text || *end || v == 0 || text[0] == '-')
        return -1;
    *out = (size_t)v;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        usage(stdout);
        return EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("grainpack %s\n", GP_VERSION);
        return EXIT_OK;
    }
    const char *command = argv[1], *spec_path = NULL, *out_path = NULL, *format_name = "json";
    int process = -1;
    size_t max_disks = 0, max_elements = 0;
    if (strcmp(command, "run") != 0 && strcmp(command, "validate") != 0) {
        fprintf(stderr, "grainpack: unknown command '%s'\n", command);
        usage(stderr);
        return EXIT_USAGE;
    }
    for (int i = 2; i < argc; i++) {
        const char *arg = argv[i];
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        if ((strcmp(arg, "--format") == 0 || strcmp(arg, "-f") == 0) && value) {
            format_name = value; /* parsed once the process is known */
            i++;
        } else if (strcmp(arg, "--process") == 0 && value) {
            if (strcmp(value, "pack2d") == 0) {
                process = GP_PROCESS_PACK2D;
            } else if (strcmp(value, "pack3d") == 0) {
                process = GP_PROCESS_PACK3D;
            } else {
                fprintf(stderr, "grainpack: unknown process '%s' (expected pack2d or pack3d)\n", value);
                return EXIT_USAGE;
            }
            i++;
        } else if (strcmp(arg, "-o") == 0 && value) {
            out_path = value;
            i++;
        } else if (strcmp(arg, "--max-disks") == 0 && value) {
            if (parse_count(value, &max_disks)) {
                fprintf(stderr, "grainpack: --max-disks expects a positive integer, got '%s'\n", value);
                return EXIT_USAGE;
            }
            i++;
        } else if (strcmp(arg, "--max-elements") == 0 && value) {
            if (parse_count(value, &max_elements)) {
                fprintf(stderr, "grainpack: --max-elements expects a positive integer, got '%s'\n",
                        value);
                return EXIT_USAGE;
            }
            i++;
        } else if ((arg[0] != '-' || strcmp(arg, "-") == 0) && !spec_path) {
            spec_path = arg;
        } else {
            fprintf(stderr, "grainpack: unexpected argument '%s'\n", arg);
            usage(stderr);
            return EXIT_USAGE;
        }
    }
    if (!spec_path) {
        fprintf(stderr, "grainpack: %s needs a spec file\n", command);
        usage(stderr);
        return EXIT_USAGE;
    }
    spec_text st = {spec_path, NULL, 0};
    int status = read_spec(spec_path, &st.text, &st.len);
    if (status)
        return status;
    int is3d = spec_process(st.text, st.len, process) == GP_PROCESS_PACK3D;
    gp_format format = GP_FORMAT_JSON;
    gp_format3d format3d = GP_FORMAT3D_JSON;
    if (is3d && gp_format3d_parse(format_name, &format3d)) {
        fprintf(stderr, "grainpack: unknown format '%s' for pack3d (expected json, csv, vtu, tess or "
                        "svg)\n", format_name);
        status = EXIT_USAGE;
    } else if (!is3d && gp_format_parse(format_name, &format)) {
        fprintf(stderr, "grainpack: unknown format '%s' (expected json, csv, svg, vtk, vtu, msh "
                        "or inp)\n", format_name);
        status = EXIT_USAGE;
    } else if (strcmp(command, "validate") == 0) {
        status = is3d ? validate3d(&st, max_disks) : validate(&st, max_disks, max_elements);
    } else {
        status = is3d ? run3d(&st, format3d, out_path, max_disks)
                      : run(&st, format, out_path, max_disks, max_elements);
    }
    free(st.text);
    return status;
}
