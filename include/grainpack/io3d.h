/* io3d.h - writers for a 3D job's result (docs/3d.md §8): CSV (pack3d.h), JSON (inputs,
 * statistics, spheres, polyhedra), VTK XML unstructured grid with polyhedral cells, Neper's
 * tessellation (.tess) and an SVG picture of a section. Each writes the whole result
 * from memory into a gp_out and flushes it; the same result gives the same bytes (the
 * service runs the same writers window by window over its stored arrays). */
#ifndef GRAINPACK_IO3D_H
#define GRAINPACK_IO3D_H

#include "grainpack/api.h"
#include "grainpack/error.h"
#include "grainpack/geometry3d.h"
#include "grainpack/out.h"
#include "grainpack/pipeline3d.h"
#include "grainpack/spec3d.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gp_format3d {
    GP_FORMAT3D_CSV = 0, /* x,y,z,r,R per sphere */
    GP_FORMAT3D_JSON,    /* inputs, statistics, spheres and (with cells) polyhedra */
    GP_FORMAT3D_VTU,     /* the polyhedra (VTK_POLYHEDRON), or the spheres as vertices */
    GP_FORMAT3D_TESS,    /* Neper's tessellation of the unshrunk power cells (cells only) */
    GP_FORMAT3D_SVG      /* the section picture: circles, and polygons with cells */
} gp_format3d;

/* "csv", "json", "vtu", "tess" or "svg" to a format: 0 or GP_EINVAL. */
GP_API int gp_format3d_parse(const char *name, gp_format3d *out);
GP_API const char *gp_format3d_name(gp_format3d format);
/* Every value from 0 to gp_format3d_count() - 1 is a format. */
GP_API size_t gp_format3d_count(void);
GP_API const char *gp_format3d_media_type(gp_format3d format);

/* Whether `result` can be written in `format`: 0, or GP_EINVAL with a message saying what
 * the spec lacks (tess needs the Laguerre stage). */
GP_API int gp_format3d_check(gp_format3d format, const gp_result3d *result, gp_error *err);

/* The JSON document: {"inputs": the spec with its defaults, "statistics", "balance" and
 * "cells" (their statistics, when they ran), "spheres": [{"id", "x", "y", "z", "r", "R",
 * "F" (with balance; null where undefined)}], "polyhedra" (with cells): [{"id", "volume",
 * "faces", "neighbours": grain ids, "walls": wall indices (geometry3d.h)}]}. */
GP_API int gp_write_json3d(gp_out *out, const gp_spec3d *spec, const gp_result3d *result);

/* VTK XML UnstructuredGrid (version 1.0): with cells, one VTK_POLYHEDRON per grain
 * (its own vertices, "faces"/"faceoffsets" as VTK documents them), else one VTK_VERTEX
 * per sphere centre; cell data grain id, r, R, volume (cells only) and F (balance only,
 * NaN where undefined). */
GP_API int gp_write_vtu3d(gp_out *out, const gp_result3d *result);

/* Neper's .tess (format 3.4, as Neper 4 writes it) of the unshrunk power cells `power`
 * (power->shrink must be GP_SHRINK_NONE) of spheres[0..power->count-1] in `box`: vertices
 * welded across cells (within GP_TESS_WELD_RTOL of the smallest packing radius), one face
 * per grain pair or per grain on a wall, edges from the welded faces, and a cube domain.
 * Returns 0, GP_ENOMEM, out's error, or GP_EINVAL/GP_EGEOM with err (cells not unshrunk,
 * or a face that does not weld into a closed polyhedron). */
GP_API int gp_write_tess(gp_out *out, const gp_box *box, const gp_sphere *spheres,
                         const gp_cells3d *power, gp_error *err);

/* Why the weld tolerance: the power cells' vertices are computed per cell to a few ulps
 * of the box (~1e-15 R), and a face below GP_LAGUERRE_EDGE_RTOL^2 R^2 is dropped, which
 * leaves its vertices up to ~1e-9 R apart in the cells beside it: 1e-7 of the smallest
 * radius welds both and is far below any real edge between grains. */
#define GP_TESS_WELD_RTOL 1e-7

/* The section picture: the plane spec->section cuts the spheres (circles of the grain
 * radius r) and, with cells, the polyhedra (polygons); the box's section as the frame. */
GP_API int gp_write_section_svg(gp_out *out, const gp_spec3d *spec, const gp_result3d *result);

/* Writes the result in `format` (tess builds the unshrunk power cells again when the
 * result's are shrunk). Returns 0, out's error, or what gp_format3d_check or the writer
 * refuses, with err. */
GP_API int gp_write_result3d(gp_out *out, gp_format3d format, const gp_spec3d *spec,
                             const gp_result3d *result, gp_error *err);

#ifdef __cplusplus
}
#endif
#endif
