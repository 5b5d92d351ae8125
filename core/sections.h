/* sections.h - a result as tagged binary sections, the form a store keeps it in: what
 * each stage produced, each section named by a tag, with the version of its layout, so
 * that a reader skips tags it does not know and a later stage (a mesh) adds its own.
 *
 * Tags and layouts (version 1 but "mesh"; little-endian; f64 = IEEE double, u32/u64/i32
 * integers):
 *   "pack"            the packing's diagnostics (with the front's rule and, for the waiting
 *                     rule, wait_levels and alive_quantile) and statistics (gp_pack_stats,
 *                     with its bins)
 *   "disks"           per grain: x, y, r, R (f64 each, 32 bytes)
 *   "balance"         the balancing run: method, step, F before and after (gp_quality_stats),
 *                     sweeps, stop, moves, how the triangulation followed
 *   "F"               per grain: F after balancing (f64, NaN where undefined)
 *   "cells"           the cells' summary (count, shrink, totals) and gp_cell_stats
 *   "cell_sizes"      per grain: vertices, neighbours of its cell (u32 each)
 *   "cell_xy"         per vertex: x, y (f64 each), cell after cell
 *   "cell_area"       per grain: its cell's area (f64)
 *   "cell_neighbours" per neighbour: its grain id (i32), cell after cell
 *   "mesh"            the mesh's summary: kind, order, counts, each region's polygon area,
 *                     gp_mesh_stats (its periodic node pairs and rounds last: a summary
 *                     stored before them ends without, and reads as 0). Version 2
 *                     (GP_SECTION_MESH_VERSION) has the layout of version 1 and says that
 *                     "mesh_quality" is stored: a reader lists only the summary sections,
 *                     so the version is where it learns it
 *   "mesh_xy"         per node: x, y (f64 each)
 *   "mesh_tri"        per triangle: its 3 (order 1) or 6 (order 2) node indices (i32)
 *   "mesh_tri_region" per triangle: its region (i32)
 *   "mesh_quad"       per quadrilateral: 4 or 8 node indices (i32)
 *   "mesh_quad_region" per quadrilateral: its region (i32)
 *   "mesh_bedge"      per boundary edge: its order + 1 node indices (i32)
 *   "mesh_bedge_side" per boundary edge: its gp_mesh_side (u8)
 *   "mesh_quality"    per element, triangles then quadrilaterals: its quality (f64,
 *                     gp_mesh_element_quality); stored with "mesh" version 2, since meshes
 *                     are downloaded window by window (a result stored before has none: a
 *                     vtu download then reads its mesh whole)
 * The 3D process (pack3d, docs/3d.md) stores:
 *   "pack3d"          the box, the front's counters (spheres, wall spheres, triangles,
 *                     attempts, max level, fill volume) and the statistics of the spheres
 *                     (gp_pack_stats: domain_area is the box's volume, the densities are
 *                     volume fractions)
 *   "spheres"         per grain: x, y, z, r, R (f64 each, 40 bytes; balanced when it ran)
 *   "balance3d"       the balancing run, in the layout of "balance"
 *   "F"               per grain: F after balancing (f64, NaN where undefined), as in 2D
 *   "cells3d"         the polyhedra's summary: count, shrink, the power volumes' sum, the
 *                     totals of vertices, faces and face vertices, gp_cell3d_stats, and the
 *                     length of the stored "tess" text
 *   "cell3d_sizes"    per cell: its vertex and face counts (u32 each)
 *   "cell3d_face_sizes" per face: its vertex count (u32), cell after cell
 *   "cell3d_face_neighbours" per face: the grain across it or GP_WALL3D(k) (i32)
 *   "cell3d_face_vertices" per face vertex: an index into its cell's vertices (u32)
 *   "cell3d_xyz"      per vertex: x, y, z (f64 each), cell after cell
 *   "cell3d_volume"   per cell: its volume (f64)
 *   "tess"            Neper's .tess of the unshrunk power cells, as gp_write_tess writes
 *                     it (text), rendered by the worker: the shrunk cells cannot give it
 *                     back, and an HTTP thread does no geometry (docs/3d.md §10)
 * The small sections ("pack", "balance", "cells", "mesh", "pack3d", "balance3d", "cells3d") make a result's summary: the statistics
 * and everything a writer needs but the per-grain arrays, which a writer reads window by
 * window through gp_sections_source (below) without holding the whole result.
 *
 * Not installed: the layout is the service's store format, free to change with it (a
 * program outside this tree writes a result with gp_writer, io.h). The service and the
 * tests link the static library, where these functions are reachable. */
#ifndef GRAINPACK_CORE_SECTIONS_H
#define GRAINPACK_CORE_SECTIONS_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/io.h"
#include "grainpack/pack3d.h"
#include "grainpack/pipeline.h"
#include "grainpack/pipeline3d.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GP_SECTION_PACK "pack"
#define GP_SECTION_DISKS "disks"
#define GP_SECTION_BALANCE "balance"
#define GP_SECTION_F "F"
#define GP_SECTION_CELLS "cells"
#define GP_SECTION_CELL_SIZES "cell_sizes"
#define GP_SECTION_CELL_XY "cell_xy"
#define GP_SECTION_CELL_AREA "cell_area"
#define GP_SECTION_CELL_NEIGHBOURS "cell_neighbours"
#define GP_SECTION_MESH "mesh"
#define GP_SECTION_MESH_XY "mesh_xy"
#define GP_SECTION_MESH_TRI "mesh_tri"
#define GP_SECTION_MESH_TRI_REGION "mesh_tri_region"
#define GP_SECTION_MESH_QUAD "mesh_quad"
#define GP_SECTION_MESH_QUAD_REGION "mesh_quad_region"
#define GP_SECTION_MESH_BEDGE "mesh_bedge"
#define GP_SECTION_MESH_BEDGE_SIDE "mesh_bedge_side"
#define GP_SECTION_MESH_QUALITY "mesh_quality"

/* The version of the "mesh" section this build writes: 2, its qualities stored. */
#define GP_SECTION_MESH_VERSION 2
#define GP_SECTION_PACK3D "pack3d"
#define GP_SECTION_SPHERES "spheres"
#define GP_SECTION_BALANCE3D "balance3d"
#define GP_SECTION_CELLS3D "cells3d"
#define GP_SECTION_CELL3D_SIZES "cell3d_sizes"
#define GP_SECTION_CELL3D_FACE_SIZES "cell3d_face_sizes"
#define GP_SECTION_CELL3D_FACE_NEIGHBOURS "cell3d_face_neighbours"
#define GP_SECTION_CELL3D_FACE_VERTICES "cell3d_face_vertices"
#define GP_SECTION_CELL3D_XYZ "cell3d_xyz"
#define GP_SECTION_CELL3D_VOLUME "cell3d_volume"
#define GP_SECTION_TESS "tess"

/* The longest tag, with its NUL. */
#define GP_SECTION_TAG_SIZE 24
/* The most sections a result has today: 9 for the grains, 9 for the mesh, and room for a
 * few more. */
#define GP_SECTIONS_MAX 24

typedef struct gp_section {
    char tag[GP_SECTION_TAG_SIZE];
    uint32_t version;   /* of the layout */
    int summary;        /* one of the small sections a summary is decoded from */
    const void *data;   /* the bytes: borrowed from the result, or `owned` */
    size_t size;
    void *owned;        /* malloc'd bytes to free with gp_sections_free, or NULL */
} gp_section;

/* Cuts `result` into sections (at most GP_SECTIONS_MAX, their number in *n). The large
 * arrays are borrowed from the result where their layout is the stored one (the result
 * must then outlive the sections); the rest is encoded into owned buffers. Returns 0 or
 * GP_ENOMEM (then nothing is left to free), GP_ETOOBIG when a cell has more than 2^32
 * vertices. Free with gp_sections_free. */
int gp_sections_from_result(const gp_result *result, gp_section *sections, size_t *n);
void gp_sections_free(gp_section *sections, size_t n);

/* Decodes one summary section into `summary` (which starts zeroed, and takes the
 * sections in any order): "pack" sets the packing's counts and statistics, "balance"
 * has_balance and its figures, "cells" has_cells, the cells' counts and statistics. Other
 * tags are ignored (returns 0). The per-grain arrays stay NULL. Returns 0, GP_ENOMEM, or
 * GP_EPARSE when the bytes do not hold the layout of that version (GP_EINVAL for a
 * version this build does not know). `summary` owns what is decoded: free it with
 * gp_result_free. */
int gp_section_decode_summary(const char *tag, uint32_t version, const void *data, size_t size,
                              gp_result *summary);

/* Reads `len` bytes of section `tag` from byte `offset` into dst: 0, or a negative code
 * (GP_EPARSE when the section is shorter) that stops the writer. */
typedef int (*gp_section_read_fn)(void *ctx, const char *tag, uint64_t offset, void *dst,
                                  size_t len);

/* Reads the mesh's arrays whole (for the SVG picture's edges, a mesh under its cap, and
 * a vtu of a result stored without its qualities) into summary->mesh, whose counts the "mesh" section set; nothing when they are read
 * already. Returns 0, GP_EINVAL (no mesh), GP_ENOMEM, the reader's error, or GP_EPARSE
 * when a node index or a region is out of range. What it reads is owned by `summary`. */
int gp_sections_read_mesh(gp_result *summary, gp_section_read_fn read, void *ctx);

/* The mesh of a stored result (summary->has_mesh), read through `read` (ctx is its
 * argument) `window` records of each array at a time (0: GP_MESH_WINDOW_RECORDS), node
 * indices, regions and sides checked as they are read (GP_EPARSE). `quality`: whether the
 * result has the "mesh_quality" section (without it, loading the qualities fails with
 * GP_EINVAL). `summary` is borrowed and must outlive the source. Returns 0, GP_EINVAL (no
 * mesh) or GP_ENOMEM; free with gp_mesh_source_free. */
struct gp_mesh_source;
int gp_sections_mesh_source(const gp_result *summary, gp_section_read_fn read, void *ctx,
                            size_t window, int quality, struct gp_mesh_source *out);

/* Grains a window of a stored result holds: the buffers then take about 300 bytes a
 * grain (disks, F, area, a cell's six or so vertices), some 300 KB. */
#define GP_SECTIONS_WINDOW_GRAINS 1024

typedef struct gp_sections_source gp_sections_source;

/* The per-grain arrays of a stored result, read through `read` (ctx is its argument)
 * window by window, `window` grains at a time (0: GP_SECTIONS_WINDOW_GRAINS). `summary`
 * (decoded by gp_section_decode_summary) is borrowed and must outlive the source.
 * Returns NULL when out of memory. Free with gp_sections_source_free. */
gp_sections_source *gp_sections_source_new(const gp_result *summary, gp_section_read_fn read,
                                           void *ctx, size_t window);
/* The source for gp_writer_new; valid while `s` lives. */
gp_grain_source gp_sections_source_grains(gp_sections_source *s);
void gp_sections_source_free(gp_sections_source *s);

/* The summary of a 3D packing: the box, the packing's counters (spheres NULL) and the
 * statistics of its spheres against the law. */
typedef struct gp_summary3d {
    gp_box box;
    gp_packing3d packing;
    gp_pack3d_stats stats; /* owned (its bins) */
} gp_summary3d;

/* The 3D statistics seen as 2D's (box_volume as domain_area, the bins borrowed): what the
 * store's columns and per-bin rows take from either. */
gp_pack_stats gp_pack3d_stats_view(const gp_pack3d_stats *stats);

/* Cuts a 3D packing into sections ("pack3d", "spheres"; at most GP_SECTIONS_MAX, *n of
 * them): the spheres borrowed from `packing`, which must outlive them. Returns 0 or
 * GP_ENOMEM (nothing left to free). Free with gp_sections_free. */
int gp_sections_from_packing3d(const gp_box *box, const gp_packing3d *packing,
                               const gp_pack3d_stats *stats, gp_section *sections, size_t *n);

/* Decodes a "pack3d" section into `out` (zeroed first; free with gp_summary3d_free).
 * Returns 0, GP_ENOMEM, GP_EPARSE (bytes not of the layout) or GP_EINVAL (another tag or
 * an unknown version). */
int gp_section_decode_summary3d(const char *tag, uint32_t version, const void *data, size_t size,
                                gp_summary3d *out);
void gp_summary3d_free(gp_summary3d *summary);

/* Cuts a whole 3D result into sections: those of gp_sections_from_packing3d, then
 * "balance3d" and "F" when it balanced, the "cells3d" ones when it made polyhedra, and
 * `tess` (tess_len bytes, NULL: none) as the "tess" section. The arrays are borrowed from
 * `result` and `tess`, which must outlive the sections. Returns 0, GP_ENOMEM or
 * GP_ETOOBIG (a cell with more than 2^32 vertices or faces); nothing left to free then.
 * Free with gp_sections_free. */
int gp_sections_from_result3d(const gp_box *box, const gp_result3d *result, const char *tess,
                              size_t tess_len, gp_section *sections, size_t *n);

/* Decodes the summary sections of a 3D result (raw[0..nraw-1], "pack3d", "balance3d",
 * "cells3d"; others skipped) into *box and `out` (zeroed first): its counts, statistics,
 * has_balance and has_cells, every array NULL; *tess_len gets the stored .tess text's
 * length (0: none). Returns 0, GP_ENOMEM, GP_EPARSE or GP_EINVAL (no "pack3d", unknown
 * version). `out` owns what is decoded: free with gp_result3d_free. */
int gp_section_decode_result3d(const gp_section *raw, size_t nraw, gp_box *box, gp_result3d *out,
                               size_t *tess_len);

/* Cells a window of a stored 3D result holds: about 1 KB a cell (its vertices, faces and
 * face vertices), half a megabyte. */
#define GP_SECTIONS_WINDOW_CELLS3D 512

/* The arrays of a stored 3D result (`summary`, decoded by gp_section_decode_result3d,
 * borrowed: it must outlive the source) for the 3D writers (writer3d.h), read through
 * `read` (ctx is its argument) `window` grains at a time (0: GP_SECTIONS_WINDOW_CELLS3D),
 * checked as they are read (GP_EPARSE from the writer: sizes that overrun the summary's
 * totals, a face with more vertices than its cell, a face vertex out of its cell, a
 * neighbour neither a grain nor a wall). Returns 0 or GP_ENOMEM; free with
 * gp_source3d_free. */
struct gp_source3d;
int gp_sections_source3d(const gp_result3d *summary, gp_section_read_fn read, void *ctx,
                         size_t window, struct gp_source3d *out);

#ifdef __cplusplus
}
#endif
#endif
