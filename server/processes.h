/* processes.h - the processes the service hosts ("pack2d", "pack3d"), each one table of
 * functions: its description, its spec's parser, its runner and what it stores, how its
 * stored result is served. The routes and the workers go through this registry and never
 * ask which process they serve; a new process is a new table in processes.c. */
#ifndef GRAINPACKD_PROCESSES_H
#define GRAINPACKD_PROCESSES_H

#include <jansson.h>
#include <stddef.h>

#include "config.h"
#include "grainpack/io.h"
#include "grainpack/progress.h"
#include "grainpack/spec.h"
#include "request.h"
#include "sections.h"
#include "store.h"

/* The most stages a process reports progress for. */
#define GP_PROCESS_MAX_STAGES 8

/* What a successful run produced: the outcome the store keeps (borrowing from `state`, the
 * process's own result, and from `sections`). Freed by the process's free_run. */
typedef struct gp_process_run {
    gp_outcome outcome;
    gp_section sections[GP_SECTIONS_MAX];
    size_t nsections;
    void *state;
    size_t count;   /* grains made, for the log */
    double density; /* their packing density, for the log */
} gp_process_run;

typedef struct gp_process_def {
    const char *id;     /* the path segment: /processes/{id} */
    const char *noun;   /* what it packs, plural: "disks", "spheres" */
    const unsigned char *description; /* its process description (JSON, compiled in) */
    const size_t *description_len;
    /* Parses and checks a spec under `limits`. Returns 0 with *spec set (free with
     * free_spec), or an engine code with err set (its pointer on the field). */
    int (*parse)(const char *text, size_t len, const gp_spec_limits *limits, void **spec,
                 gp_error *err);
    void (*free_spec)(void *spec);
    /* What the job's row keeps of the spec, and the grains expected. */
    void (*columns)(const void *spec, gp_job_columns *out);
    /* The answer to a validation: {"valid", the grains expected, "inputs", "limits"}; a new
     * reference, NULL when out of memory. */
    json_t *(*validation)(const void *spec, const gp_config *cfg);
    /* The stages a run reports progress for, in order; returns how many (at most cap). */
    int (*stages)(const void *spec, const char **stages, int cap);
    /* Runs the job (on a worker). Returns 0 with *run filled (free with free_run), or the
     * failing stage's code with err set (GP_ECANCELED when its flag was raised). */
    int (*run)(void *spec, const gp_config *cfg, const gp_progress *progress,
               gp_process_run *run, gp_error *err);
    void (*free_run)(gp_process_run *run);
    /* Whether its results are served in `format` (for a job whose spec asked for its extra
     * geometry, a 2D mesh or 3D polyhedra, when has_mesh): the status's links list those. */
    int (*serves)(gp_format format, int has_mesh);
    /* Answers GET /jobs/{id}/results in `format` from the stored result `res`, which it
     * takes over (freed here). Only reads what was stored: no geometry. Returns
     * GP_ROUTE_DONE. */
    int (*results)(gp_request *req, gp_stored_result *res, gp_format format, gp_reply *reply);
    /* The statistics document of a stored result (timings are the route's); a new
     * reference, or NULL (500) when it cannot be made. */
    json_t *(*statistics)(const gp_stored_result *res);
} gp_process_def;

/* The stages of a packing process's run as its `stages` lists them: `pack` (the stage
 * its packer reports as), then "triangulation", "balance" and "laguerre" as the spec asks
 * (both processes' pipelines run them on one regular triangulation). Returns how many
 * (at most cap). */
int gp_process_stages(const char *pack, int balance, int laguerre, const char **out, int cap);

/* The processes, in the order /processes lists them. */
extern const gp_process_def gp_process_pack2d;
extern const gp_process_def gp_process_pack3d;

/* The number of processes and the i-th. */
size_t gp_process_count(void);
const gp_process_def *gp_process_at(size_t i);

/* The process named `id`, or NULL. */
const gp_process_def *gp_process_find(const char *id);

/* The process a stored spec was accepted by: a spec is valid for one process only (a 3D
 * box has a depth, a 2D domain has none), so the text tells it and the store needs no
 * column for it. */
const gp_process_def *gp_process_of_spec(const char *text, size_t len);

/* The description of process p (a new reference), or NULL. */
json_t *gp_process_description(const gp_process_def *p);

/* Parses the request's body as a spec of `p` under the service's caps. Returns 0 with *spec
 * set (p->free_spec frees it), or -1 with the 400/422 problem in reply. */
int gp_process_parse_request(const gp_process_def *p, gp_request *req, void **spec,
                             gp_reply *reply);

#endif
