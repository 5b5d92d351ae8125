/* embedded.h - files of the repository compiled into the daemon (embed.cmake makes
 * embedded_files.c at build time): the OpenAPI document and the process description. */
#ifndef GRAINPACKD_EMBEDDED_H
#define GRAINPACKD_EMBEDDED_H

#include <stddef.h>

extern const unsigned char gp_openapi_yaml[];
extern const size_t gp_openapi_yaml_len;
extern const unsigned char gp_process_pack2d_json[];
extern const size_t gp_process_pack2d_json_len;

#endif
