/* processes.c - the registry of the service's processes (processes.h): the table, the
 * lookups, and what every process does alike (its description, parsing a request). */
#include "processes.h"

#include <string.h>

#include "grainpack/spec3d.h"
#include "problem.h"

static const gp_process_def *const processes[] = {&gp_process_pack2d, &gp_process_pack3d};

size_t gp_process_count(void)
{
    return sizeof processes / sizeof processes[0];
}

const gp_process_def *gp_process_at(size_t i)
{
    return i < gp_process_count() ? processes[i] : NULL;
}

const gp_process_def *gp_process_find(const char *id)
{
    for (size_t i = 0; i < gp_process_count(); i++)
        if (strcmp(processes[i]->id, id) == 0)
            return processes[i];
    return NULL;
}

const gp_process_def *gp_process_of_spec(const char *text, size_t len)
{
    return gp_spec_process(text, len) == GP_PROCESS_PACK3D ? &gp_process_pack3d
                                                           : &gp_process_pack2d;
}

json_t *gp_process_description(const gp_process_def *p)
{
    json_error_t err;
    return json_loadb((const char *)p->description, *p->description_len, 0, &err);
}

int gp_process_parse_request(const gp_process_def *p, gp_request *req, void **spec,
                             gp_reply *reply)
{
    gp_spec_limits limits = {req->svc->cfg->max_disks, req->svc->cfg->max_bins,
                             req->svc->cfg->max_elements};
    gp_error err;
    gp_error_clear(&err);
    if (p->parse(req->body, req->body_len, &limits, spec, &err)) {
        gp_problem_from_spec_error(reply, req->path, &err);
        return -1;
    }
    return 0;
}

int gp_process_stages(const char *pack, int balance, int laguerre, const char **out, int cap)
{
    const char *all[] = {pack, balance || laguerre ? "triangulation" : NULL,
                         balance ? "balance" : NULL, laguerre ? "laguerre" : NULL};
    int n = 0;
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        if (all[i] && n < cap)
            out[n++] = all[i];
    return n;
}
