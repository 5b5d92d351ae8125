/* version.c - the library's own version, for programs that check it against the headers
 * they were built with. */
#include "grainpack/version.h"

const char *gp_version(void)
{
    return GP_VERSION;
}
