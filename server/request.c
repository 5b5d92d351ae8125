/* request.c - a request's headers, query parameters and submitter, as routes read them. */
#include "request.h"

const char *gp_request_query(const gp_request *req, const char *name)
{
    return req->ops->query(req->conn, name);
}

const char *gp_request_header(const gp_request *req, const char *name)
{
    return req->ops->header(req->conn, name);
}

const char *gp_request_submitter(const gp_request *req)
{
    return req->who ? req->who->user : "";
}
