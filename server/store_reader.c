/* store_reader.c - reading a stored result's sections, whichever the backend: the summary
 * sections decoded whole when a result is opened, the per-grain ones piece by piece for a
 * download (gp_result_reader), one chunk query at a time through the backend's
 * find_section and read_chunk. */
#include "store_ops.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "sections.h"

static const gp_store_ops *db_ops(gp_db *db)
{
    return ((const gp_store_head *)(const void *)((const gp_db_head *)(const void *)db)->store)
        ->ops;
}

/* Reads the whole of a small section (a summary one) into a new buffer (caller frees). */
static int read_whole(gp_db *db, const gp_section_ref *ref, unsigned char **out)
{
    size_t bytes = (size_t)ref->bytes, got = 0;
    /* a chunk is read whole into the buffer's end: room for one beyond the section */
    *out = malloc(bytes + GP_STORE_CHUNK);
    if (!*out)
        return GP_ENOMEM;
    for (int64_t chunk = 0; got < bytes; chunk++) {
        size_t len = 0;
        int rc = db_ops(db)->read_chunk(db, ref->section, chunk, *out + got, &len);
        if (rc)
            return rc;
        if (len == 0 || len > bytes - got)
            return GP_SRV_ENOTFOUND; /* a chunk missing or longer than the section says */
        got += len;
    }
    return 0;
}

int gp_store_decode_summary(gp_db *db, const char *id, const gp_section_ref *refs, size_t n,
                            gp_stored_result *res)
{
    /* every process's result has summary sections: none means no result */
    if (n == 0)
        return GP_SRV_ENOTFOUND;
    for (size_t i = 0; i < n && i < GP_SECTIONS_MAX; i++) {
        unsigned char *bytes = NULL;
        int rc = read_whole(db, &refs[i], &bytes);
        if (rc == 0)
            rc = gp_section_decode_summary(refs[i].tag, refs[i].version, bytes,
                                           (size_t)refs[i].bytes, &res->summary);
        if (rc == GP_EPARSE || rc == GP_EINVAL) {
            free(bytes);
            gp_log("store: job %s: its result section %s (version %u) cannot be decoded", id,
                   refs[i].tag, refs[i].version);
            return GP_SRV_EDB;
        }
        if (rc) {
            free(bytes);
            return rc;
        }
        /* kept as stored, for a process that decodes its own summary (processes.h) */
        gp_section *raw = &res->raw[res->nraw++];
        snprintf(raw->tag, sizeof raw->tag, "%s", refs[i].tag);
        raw->version = refs[i].version;
        raw->summary = 1;
        raw->data = raw->owned = bytes;
        raw->size = (size_t)refs[i].bytes;
        res->mesh_quality |= strcmp(refs[i].tag, GP_SECTION_MESH) == 0 &&
                             refs[i].version == GP_SECTION_MESH_VERSION;
    }
    return 0;
}

void gp_stored_result_free(gp_stored_result *r)
{
    free(r->spec_text);
    gp_result_free(&r->summary);
    gp_sections_free(r->raw, r->nraw);
    memset(r, 0, sizeof *r);
}

/* The reader's cache: for each section read so far, where it is and its last chunk. */
typedef struct reader_section {
    char tag[GP_SECTION_TAG_SIZE];
    int64_t id;
    uint64_t bytes;
    int64_t chunk; /* the chunk held in data, -1: none */
    unsigned char *data;
    size_t len;
} reader_section;

struct gp_result_reader {
    int64_t key;
    reader_section sections[GP_SECTIONS_MAX];
    size_t n;
};

gp_result_reader *gp_result_reader_new(int64_t key)
{
    gp_result_reader *r = calloc(1, sizeof *r);
    if (r)
        r->key = key;
    return r;
}

void gp_result_reader_free(gp_result_reader *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < r->n; i++)
        free(r->sections[i].data);
    free(r);
}

/* The reader's entry of section `tag`, looked up in the store on first use. */
static int find_section(gp_result_reader *r, gp_db *db, const char *tag, reader_section **out)
{
    for (size_t i = 0; i < r->n; i++) {
        if (strcmp(r->sections[i].tag, tag) == 0) {
            *out = &r->sections[i];
            return 0;
        }
    }
    if (r->n == GP_SECTIONS_MAX)
        return GP_SRV_ENOTFOUND;
    reader_section *sec = &r->sections[r->n];
    memset(sec, 0, sizeof *sec);
    int rc = db_ops(db)->find_section(db, r->key, tag, &sec->id, &sec->bytes);
    if (rc)
        return rc;
    snprintf(sec->tag, sizeof sec->tag, "%s", tag);
    sec->chunk = -1;
    if (!(sec->data = malloc(GP_STORE_CHUNK)))
        return GP_ENOMEM;
    r->n++;
    *out = sec;
    return 0;
}

/* Brings chunk `chunk` of sec into its cache: one query, its own read transaction. */
static int load_chunk(gp_db *db, reader_section *sec, int64_t chunk)
{
    if (sec->chunk == chunk)
        return 0;
    size_t len = 0;
    int rc = db_ops(db)->read_chunk(db, sec->id, chunk, sec->data, &len);
    if (rc)
        return rc;
    sec->len = len;
    sec->chunk = chunk;
    return 0;
}

int gp_result_reader_read(gp_result_reader *r, gp_db *db, const char *tag, uint64_t offset,
                          void *dst, size_t len)
{
    reader_section *sec;
    int rc = find_section(r, db, tag, &sec);
    if (rc)
        return rc;
    if (offset > sec->bytes || len > sec->bytes - offset)
        return GP_SRV_ENOTFOUND;
    unsigned char *to = dst;
    while (len > 0) {
        int64_t chunk = (int64_t)(offset / GP_STORE_CHUNK);
        size_t at = (size_t)(offset % GP_STORE_CHUNK);
        if ((rc = load_chunk(db, sec, chunk)))
            return rc;
        if (at >= sec->len)
            return GP_SRV_ENOTFOUND; /* a chunk shorter than the section says */
        size_t n = sec->len - at < len ? sec->len - at : len;
        memcpy(to, sec->data + at, n);
        to += n;
        offset += n;
        len -= n;
    }
    return 0;
}
