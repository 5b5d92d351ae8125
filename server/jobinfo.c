/* jobinfo.c - statusInfo objects (OGC API - Processes, Part 1, statusInfo.yaml). */
#include "jobinfo.h"

#include <stdio.h>

#include "grainpack/io.h"
#include "processes.h"
#include "routes.h"

#define OGC_RESULTS_REL "http://www.opengis.net/def/rel/ogc/1.0/results"

static void put_time(json_t *obj, const char *key, const char *value)
{
    if (value[0]) /* not set yet: omitted, as the OGC schema allows */
        json_object_set_new(obj, key, json_string(value));
}

json_t *gp_job_status_info(const gp_job *job)
{
    char self[64], results[80], stats[80];
    snprintf(self, sizeof self, "/jobs/%s", job->id);
    snprintf(results, sizeof results, "/jobs/%s/results", job->id);
    snprintf(stats, sizeof stats, "/jobs/%s/statistics", job->id);
    json_t *links = json_pack("[{s:s, s:s, s:s, s:s}]", "href", self, "rel", "self", "type",
                              "application/json", "title", "this job's status");
    const gp_process_def *process = gp_process_find(job->process);
    if (!process)
        process = &gp_process_pack2d;
    if (links && job->status == GP_JOB_SUCCESSFUL) {
        json_array_append_new(links,
                              json_pack("{s:s, s:s, s:s, s:s}", "href", results, "rel",
                                        OGC_RESULTS_REL, "type",
                                        "application/json", "title", "the result (?f= picks the format)"));
        /* the other formats, one link each, so that a client lists the downloads without
         * knowing them: a format the engine gains appears here by itself */
        for (size_t i = 0; i < gp_format_count(); i++) {
            gp_format f = (gp_format)i;
            if (f == GP_FORMAT_JSON || !process->serves(f, job->has_mesh))
                continue;
            char href[96], title[48];
            snprintf(href, sizeof href, "%s?f=%s", results, gp_format_name(f));
            snprintf(title, sizeof title, "the result as %s", gp_format_name(f));
            json_array_append_new(links, json_pack("{s:s, s:s, s:s, s:s}", "href", href, "rel",
                                                   OGC_RESULTS_REL, "type", gp_format_media_type(f),
                                                   "title", title));
        }
        json_array_append_new(links, json_pack("{s:s, s:s, s:s, s:s}", "href", stats, "rel",
                                               "statistics", "type", "application/json", "title",
                                               "densities, distribution fidelity, timings"));
    }
    json_t *info = json_pack("{s:s, s:s, s:s, s:s, s:s, s:i, s:o}", "processID", process->id,
                             "type", "process", "jobID", job->id, "status",
                             gp_job_status_name(job->status), "message", job->message,
                             "progress", job->progress, "links", links);
    if (!info)
        return NULL;
    put_time(info, "created", job->created);
    put_time(info, "started", job->started);
    put_time(info, "finished", job->finished);
    put_time(info, "updated", job->updated);
    return info;
}
