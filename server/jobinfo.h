/* jobinfo.h - a job as the API shows it: the OGC statusInfo object with its links. */
#ifndef GRAINPACKD_JOBINFO_H
#define GRAINPACKD_JOBINFO_H

#include <jansson.h>

#include "store.h"

/* A new statusInfo object (NULL when out of memory); the caller owns the reference. */
json_t *gp_job_status_info(const gp_job *job);

#endif
