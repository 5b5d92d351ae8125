/* tess_conform.h - making the welded faces of a 3D tessellation conforming (io_tess.c):
 * no vertex inside another face's edge. */
#ifndef GP_TESS_CONFORM_H
#define GP_TESS_CONFORM_H

#include <stddef.h>
#include <stdint.h>

/* The welded faces of a tessellation: nf vertex loops, face f's vertices (welded ids) at
 * fverts[fvstart[f] .. fvstart[f + 1]); vertex v at xyz[3 v]. Cell i lists its faces at
 * cface[cstart[i] .. cstart[i + 1]) as signed 1-based face ids, 0 for a face welded away. */
typedef struct tess_faces {
    size_t nf;
    size_t *fvstart;  /* nf + 1 */
    uint32_t *fverts;
    const double *xyz;
    size_t ncells;
    const size_t *cstart;
    const int64_t *cface;
} tess_faces;

/* Degenerate power cells (equal spheres in a lattice, where four or more cells meet along a
 * line) are computed one by one, and a vertex on such a line may be in the loops of some
 * faces along it and not of others: a T-junction, which Neper's format (and any mesher)
 * refuses. In a conforming tessellation every edge of a cell is in exactly two of its
 * faces; an edge (a, b) in one face only is split at the vertices of the cell's other
 * such edges that lie inside it (within tol of the segment), in every face that has it.
 * Returns the number of vertices inserted (0: the faces were conforming), or GP_ENOMEM.
 * fvstart and fverts are replaced (the old arrays freed) when vertices were inserted; the
 * caller keeps owning them. Run it again until it returns 0: an insertion can show a
 * neighbouring cell's missing vertex. */
long gp_tess_conform(tess_faces *faces, double tol);

#endif
