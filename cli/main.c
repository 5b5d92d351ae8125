/* main.c - the grainpack command line: runs the job pipeline on a spec file. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "grainpack/io.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "grainpack/version.h"

/* Exit statuses, documented in usage(). */
enum { EXIT_OK = 0, EXIT_FAILED = 1, EXIT_USAGE = 2, EXIT_BAD_SPEC = 3 };

static void usage(FILE *out)
{
    fputs("Usage: grainpack run SPEC.json [--format json|csv|svg|vtk] [-o FILE] [--max-disks N]\n"
          "  or:  grainpack validate SPEC.json [--max-disks N]\n"
          "  or:  grainpack --help | --version\n"
          "\n"
          "  run       packs the domain the spec describes, balances it and builds its\n"
          "            Laguerre cells when the spec asks (\"balance\", \"laguerre\"), and\n"
          "            writes the result (default JSON with statistics, to standard output).\n"
          "            SPEC.json is the job spec, either {\"inputs\": {...}} or the bare\n"
          "            inputs object; '-' reads stdin.\n"
          "  validate  checks a spec and prints the expected number of disks.\n"
          "\n"
          "  -f, --format FORMAT  json (default), csv, svg or vtk\n"
          "  -o FILE              write to FILE instead of standard output\n"
          "  --max-disks N        refuse specs expected to need more than N disks\n"
          "                       (default 20000000)\n"
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

static int load_spec(const char *path, size_t max_disks, gp_spec *spec)
{
    gp_spec_limits limits = {.max_disks = max_disks};
    gp_error err;
    gp_error_clear(&err);
    int rc = strcmp(path, "-") == 0 ? gp_spec_load_file("/dev/stdin", &limits, spec, &err)
                                    : gp_spec_load_file(path, &limits, spec, &err);
    if (rc == 0)
        return 0;
    if (err.pointer[0])
        fprintf(stderr, "grainpack: %s: %s: %s\n", path, err.pointer, err.message);
    else
        fprintf(stderr, "grainpack: %s: %s\n", path, err.message);
    return rc == GP_EIO || rc == GP_ENOMEM ? EXIT_FAILED : EXIT_BAD_SPEC;
}

static int run(const char *spec_path, gp_format format, const char *out_path, size_t max_disks)
{
    gp_spec spec;
    int status = load_spec(spec_path, max_disks, &spec);
    if (status)
        return status;

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
    }

    FILE *out = out_path ? fopen(out_path, "wb") : stdout;
    if (!out) {
        fprintf(stderr, "grainpack: cannot write %s: %s\n", out_path, strerror(errno));
        status = EXIT_FAILED;
    } else {
        gp_out sink;
        rc = gp_out_init_file(&sink, out);
        if (rc == 0)
            rc = gp_write_result(&sink, format, &spec, &result);
        gp_out_free(&sink);
        if (out_path && fclose(out) != 0)
            rc = GP_EIO;
        else if (!out_path && fflush(out) != 0)
            rc = GP_EIO;
        if (rc) {
            fprintf(stderr, "grainpack: writing %s failed: %s\n", out_path ? out_path : "stdout",
                    gp_strerror(rc));
            if (out_path)
                remove(out_path);
            status = EXIT_FAILED;
        }
    }
    gp_result_free(&result);
    gp_spec_free(&spec);
    return status;
}

static int validate(const char *spec_path, size_t max_disks)
{
    gp_spec spec;
    int status = load_spec(spec_path, max_disks, &spec);
    if (status)
        return status;
    printf("%s: valid, about %.0f disks expected\n", spec_path, spec.expected_disks);
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
    const char *command = argv[1], *spec_path = NULL, *out_path = NULL;
    gp_format format = GP_FORMAT_JSON;
    size_t max_disks = 0;
    if (strcmp(command, "run") != 0 && strcmp(command, "validate") != 0) {
        fprintf(stderr, "grainpack: unknown command '%s'\n", command);
        usage(stderr);
        return EXIT_USAGE;
    }
    for (int i = 2; i < argc; i++) {
        const char *arg = argv[i];
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        if ((strcmp(arg, "--format") == 0 || strcmp(arg, "-f") == 0) && value) {
            if (gp_format_parse(value, &format)) {
                fprintf(stderr, "grainpack: unknown format '%s' (expected json, csv, svg or vtk)\n", value);
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
    if (strcmp(command, "validate") == 0)
        return validate(spec_path, max_disks);
    return run(spec_path, format, out_path, max_disks);
}
