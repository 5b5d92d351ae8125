/* embedded.h - files of the repository compiled into the daemon (embed.cmake makes
 * embedded_files.c and web_files.c at build time): the OpenAPI document, the process
 * descriptions, and the web page's files (server/web/) with the report's examples. */
#ifndef GRAINPACKD_EMBEDDED_H
#define GRAINPACKD_EMBEDDED_H

#include <stddef.h>

extern const unsigned char gp_openapi_yaml[];
extern const size_t gp_openapi_yaml_len;
extern const unsigned char gp_process_pack2d_json[];
extern const size_t gp_process_pack2d_json_len;
extern const unsigned char gp_process_pack3d_json[];
extern const size_t gp_process_pack3d_json_len;

/* One served file: its name under /ui/, its bytes and a strong ETag (quoted). */
typedef struct gp_embedded_file {
    const char *name;
    const unsigned char *bytes;
    size_t len;
    const char *etag;
} gp_embedded_file;

/* The web page's files, served at /ui/NAME (index.html also at / for browsers). */
extern const gp_embedded_file gp_web_files[];
extern const size_t gp_web_files_count;

#endif
