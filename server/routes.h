/* routes.h - the API's endpoints (see openapi.yaml, the contract). Each fills a reply
 * from a request; errors are problem+json replies, never crashes. */
#ifndef GRAINPACKD_ROUTES_H
#define GRAINPACKD_ROUTES_H

#include "request.h"

/* routes_meta.c: what the service is */
int gp_route_landing(gp_request *req, gp_reply *reply);
int gp_route_conformance(gp_request *req, gp_reply *reply);
int gp_route_processes(gp_request *req, gp_reply *reply);
int gp_route_process(gp_request *req, gp_reply *reply);
int gp_route_health(gp_request *req, gp_reply *reply);
int gp_route_metrics(gp_request *req, gp_reply *reply);
int gp_route_openapi(gp_request *req, gp_reply *reply);

/* routes_jobs.c: checking a spec, submitting and following jobs */
int gp_route_validate(gp_request *req, gp_reply *reply);
int gp_route_execute(gp_request *req, gp_reply *reply);
int gp_route_jobs(gp_request *req, gp_reply *reply);
int gp_route_job(gp_request *req, gp_reply *reply);
int gp_route_dismiss(gp_request *req, gp_reply *reply);

/* routes_results.c: what a finished job produced */
int gp_route_results(gp_request *req, gp_reply *reply);
int gp_route_statistics(gp_request *req, gp_reply *reply);

/* routes_web.c: the web page. gp_route_web_wants_page says whether a request for / asks
 * for the page (?f=html, or an Accept that prefers text/html to JSON): 1 or 0, or -1 with
 * a 400 in reply for an unknown f. */
int gp_route_web_file(gp_request *req, gp_reply *reply);
int gp_route_web_page(gp_request *req, gp_reply *reply);
int gp_route_web_wants_page(const gp_request *req, gp_reply *reply);

#endif
