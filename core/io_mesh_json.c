/* io_mesh_json.c - the mesh's statistics as JSON: what was asked, what was made. */
#include "io_mesh_json.h"

static const char *const kind_names[] = {"grains_and_band", "cells", "disks_in_matrix"};

json_t *gp_mesh_statistics_json(const gp_spec *spec, const gp_mesh *mesh)
{
    const gp_mesh_stats *s = &mesh->stats;
    const gp_mesh_params *p = &spec->mesh;
    json_t *histogram = json_array();
    for (int b = 0; histogram && b < GP_MESH_QUALITY_BINS; b++)
        if (json_array_append_new(histogram, json_integer((json_int_t)s->quality_histogram[b]))) {
            json_decref(histogram);
            histogram = NULL;
        }
    if (!histogram)
        return NULL;
    const char *second = mesh->kind == GP_MESH_CELLS ? NULL
                         : mesh->kind == GP_MESH_DISKS_IN_MATRIX ? "matrix" : "grain_boundary";
    json_t *stats = json_pack(
        "{s:s, s:{s:f, s:f, s:i, s:i, s:f, s:b}, s:I, s:{s:I, s:I, s:I}, s:I, s:{s:f, s:f, s:I, s:f},"
        " s:{s:f, s:f, s:o, s:s}, s:{s:f, s:f, s:f, s:f, s:f, s:s?, s:f, s:f}, s:I,"
        " s:{s:I, s:f, s:f}}",
        "kind", kind_names[mesh->kind],
        "options", "element_size", p->element_size, "min_angle", p->min_angle, "order", p->order,
        "band_layers", p->band_layers, "band_size", p->band_size,
        "grading", mesh->kind == GP_MESH_GRAINS_AND_BAND && p->grading,
        "nodes", (json_int_t)s->nodes,
        "elements", "triangles", (json_int_t)s->triangles, "quadrilaterals", (json_int_t)s->quads,
        "total", (json_int_t)(s->triangles + s->quads),
        "boundary_edges", (json_int_t)s->boundary_edges,
        "angles", "min", s->min_angle, "max", s->max_angle, "triangles_below_min_angle",
        (json_int_t)s->below_min_angle, "min_input_angle", s->min_input_angle,
        "quality", "min", s->quality_min, "mean", s->quality_mean, "histogram", histogram,
        "measure", "4 sqrt(3) area / sum of squared edges (triangles), smallest corner "
                   "2 |a x b| / (|a|^2 + |b|^2) (quadrilaterals); 10 bins over [0, 1]",
        "areas", "domain", s->domain_area, "elements", s->element_area, "grains", s->grain_area,
        "grain_polygons", s->grain_polygon_area, "second_phase", s->phase_area,
        "second_phase_name", second, "second_phase_polygons", s->phase_polygon_area,
        "relative_error", s->domain_area > 0.0 ? (s->element_area - s->domain_area) / s->domain_area : 0.0,
        "refused_refinements", (json_int_t)s->refused_refinements,
        "band_strips", "count", (json_int_t)s->band_strips, "thickness_min", s->band_thickness_min,
        "thickness_mean", s->band_thickness_mean);
    unsigned per = spec->domain.periodic;
    json_t *axes = json_array();
    if (axes && (per & GP_PERIODIC_X))
        json_array_append_new(axes, json_string("x"));
    if (axes && (per & GP_PERIODIC_Y))
        json_array_append_new(axes, json_string("y"));
    if (!stats) {
        json_decref(axes);
        return NULL;
    }
    if (!axes ||
        json_object_set_new(stats, "periodic",
                            json_pack("{s:o, s:{s:I, s:I}, s:i}", "axes", axes, "node_pairs", "x",
                                      (json_int_t)s->periodic_pairs[0], "y",
                                      (json_int_t)s->periodic_pairs[1], "rounds", s->rounds))) {
        json_decref(stats);
        return NULL;
    }
    return stats;
}
