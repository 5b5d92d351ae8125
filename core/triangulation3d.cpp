// triangulation3d.cpp - CGAL's Regular_triangulation_3 (exact predicates, inexact
// constructions) of the sphere centres with weights R^2, behind the C API of
// grainpack/geometry3d.h and core/triangulation3d.h. Every entry point catches every
// exception.
#include "triangulation3d.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <new>
#include <vector>

namespace {

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Regular_triangulation_vertex_base_3<K> Vb0;
typedef CGAL::Triangulation_vertex_base_with_info_3<int32_t, K, Vb0> Vb;
// the hidden points are not kept: a packing has none, and a list per cell would cost
// memory and time for nothing (a hidden sphere is found by its missing vertex)
typedef CGAL::Regular_triangulation_cell_base_3<K, CGAL::Triangulation_cell_base_3<K>,
                                                CGAL::Discard_hidden_points> Cb;
typedef CGAL::Triangulation_data_structure_3<Vb, Cb> Tds;
typedef CGAL::Regular_triangulation_3<K, Tds> Rt;
typedef Rt::Vertex_handle Vertex_handle;
typedef Rt::Cell_handle Cell_handle;
typedef K::Point_3 Point;
typedef K::Weighted_point_3 Weighted_point;

// Comparisons of the spatial sort between two reads of the cancel flag: well under a
// millisecond of work.
const unsigned long COMPARISONS_PER_CHECK = 1UL << 16;

// Thrown out of the spatial sort when the cancel flag is raised (the sort only permutes
// a vector of indices: nothing is left half-built).
struct Sort_canceled {};

// The traits of CGAL's spatial sort over sphere indices: the comparisons of the centres'
// coordinates, counted, with the cancel flag read every COMPARISONS_PER_CHECK of them
// (as core/triangulation.cpp does in 2D: the sort could not be interrupted otherwise).
class Sort_traits {
  public:
    struct Shared {
        const gp_sphere *spheres;
        const gp_progress *progress;
        unsigned long comparisons;
    };
    typedef std::size_t Point_3;
    template <int axis> struct Less {
        Shared *s;
        bool operator()(std::size_t p, std::size_t q) const
        {
            tick(s);
            const gp_sphere &a = s->spheres[p], &b = s->spheres[q];
            return axis == 0 ? a.x < b.x : axis == 1 ? a.y < b.y : a.z < b.z;
        }
    };
    typedef Less<0> Less_x_3;
    typedef Less<1> Less_y_3;
    typedef Less<2> Less_z_3;
    explicit Sort_traits(Shared *shared) : s(shared) {}
    Less_x_3 less_x_3_object() const { return Less_x_3{s}; }
    Less_y_3 less_y_3_object() const { return Less_y_3{s}; }
    Less_z_3 less_z_3_object() const { return Less_z_3{s}; }

  private:
    Shared *s;
    static void tick(Shared *s)
    {
        if (++s->comparisons % COMPARISONS_PER_CHECK == 0 && gp_canceled(gp_progress_cancel(s->progress)))
            throw Sort_canceled();
    }
};

// Spheres inserted between two reads of the cancel flag (and progress reports): a few
// milliseconds of work (3D insertions cost some microseconds each).
const size_t INSERT_BATCH = 2048;

} // namespace

struct gp_rt3 {
    Rt rt;
    std::vector<Vertex_handle> vertex; // by sphere id
};

namespace {

// Fills t from the spheres: spatial sort, then one insertion after another from the last
// one's cell, the cancel flag read during the sort and between batches. Returns 0,
// GP_ECANCELED or GP_EGEOM (a sphere without a vertex) with err.
int build_into(gp_rt3 &t, const gp_sphere *spheres, size_t n, const gp_progress *progress,
               bool report, gp_error *err)
{
    t.rt.clear();
    std::vector<std::size_t> order(n);
    for (size_t i = 0; i < n; i++)
        order[i] = i;
    Sort_traits::Shared shared = {spheres, progress, 0};
    try {
        CGAL::spatial_sort(order.begin(), order.end(), Sort_traits(&shared));
    } catch (const Sort_canceled &) {
        return gp_error_set(err, GP_ECANCELED, NULL,
                            "regular triangulation canceled while sorting %zu spheres", n);
    }
    Cell_handle hint;
    for (size_t k = 0; k < n; k++) {
        if (k % INSERT_BATCH == 0 && k > 0 && progress) {
            if (gp_canceled(progress->cancel))
                return gp_error_set(err, GP_ECANCELED, NULL,
                                    "regular triangulation canceled after %zu of %zu spheres", k, n);
            if (report && progress->report)
                progress->report(progress->ctx, "triangulation", static_cast<double>(k) / static_cast<double>(n));
        }
        const gp_sphere &s = spheres[order[k]];
        Vertex_handle v = t.rt.insert(Weighted_point(Point(s.x, s.y, s.z), s.R * s.R), hint);
        if (v != Vertex_handle()) {
            v->info() = static_cast<int32_t>(order[k]);
            hint = v->cell();
        }
    }
    t.vertex.assign(n, Vertex_handle());
    for (Rt::Finite_vertices_iterator v = t.rt.finite_vertices_begin(); v != t.rt.finite_vertices_end(); ++v) {
        int32_t id = v->info();
        if (id < 0 || static_cast<size_t>(id) >= n || t.vertex[id] != Vertex_handle())
            return gp_error_set(err, GP_EGEOM, NULL, "regular triangulation: two vertices claim sphere %d", id);
        t.vertex[id] = v;
    }
    for (size_t i = 0; i < n; i++)
        if (t.vertex[i] == Vertex_handle())
            return gp_error_set(err, GP_EGEOM, NULL,
                                "regular triangulation: sphere %zu at (%.17g, %.17g, %.17g), R = %.17g, "
                                "is hidden (it overlaps another sphere or shares its centre)",
                                i, spheres[i].x, spheres[i].y, spheres[i].z, spheres[i].R);
    return 0;
}

// Runs f (which returns a GP_ code) with every exception turned into one.
template <class F> int guarded(F f, gp_error *err)
{
    try {
        return f();
    } catch (const std::bad_alloc &) {
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory in the 3D regular triangulation");
    } catch (const std::exception &e) {
        return gp_error_set(err, GP_EINTERNAL, NULL, "regular triangulation 3D: %s", e.what());
    } catch (...) {
        return gp_error_set(err, GP_EINTERNAL, NULL, "regular triangulation 3D: unknown failure");
    }
}

} // namespace

extern "C" int gp_rt3_build(const gp_sphere *spheres, size_t n, const gp_progress *progress,
                            gp_rt3 **out, gp_error *err)
{
    *out = NULL;
    if (n > static_cast<size_t>(INT32_MAX))
        return gp_error_set(err, GP_ETOOBIG, NULL, "regular triangulation: %zu spheres, more than %d",
                            n, INT32_MAX);
    gp_rt3 *t = NULL;
    int rc = guarded([&] {
        t = new gp_rt3;
        return build_into(*t, spheres, n, progress, true, err);
    }, err);
    if (rc) {
        delete t;
        return rc;
    }
    if (progress && progress->report)
        progress->report(progress->ctx, "triangulation", 1.0);
    *out = t;
    return 0;
}

extern "C" int gp_rt3_rebuild(gp_rt3 *rt, const gp_sphere *spheres, size_t n,
                              const gp_progress *progress, gp_error *err)
{
    return guarded([&] { return build_into(*rt, spheres, n, progress, false, err); }, err);
}

extern "C" void gp_rt3_free(gp_rt3 *rt)
{
    delete rt;
}

extern "C" size_t gp_rt3_count(const gp_rt3 *rt) noexcept
{
    return rt->vertex.size();
}

extern "C" int gp_rt3_dimension(const gp_rt3 *rt) noexcept
{
    return rt->rt.dimension();
}

// Room for the rings of gp_rt3_rings' walk: about fifteen neighbours a vertex in a
// packing's triangulation, and two entries of bookkeeping per ring; grown if needed.
const size_t RING_ENTRIES_PER_VERTEX = 18;

extern "C" int gp_rt3_rings(const gp_rt3 *rt, size_t *start, uint8_t *infinite, int32_t **ids,
                            const gp_progress *progress) noexcept
{
    *ids = NULL;
    const gp_cancel_flag *cancel = gp_progress_cancel(progress);
    const Rt &r = rt->rt;
    size_t n = rt->vertex.size();
    std::fill(start, start + n + 1, size_t(0));
    if (infinite)
        std::fill(infinite, infinite + n, uint8_t(1));
    if (r.dimension() < 1)
        return (*ids = static_cast<int32_t *>(malloc(sizeof(int32_t)))) ? 0 : GP_ENOMEM;
    // one walk in the triangulation's memory order appends each ring to `walk` as (id,
    // degree, ring), then the rings are copied to their places by id (as gp_rt_rings does
    // in 2D: visiting the vertices by id jumps across the whole structure)
    int32_t *walk = NULL;
    try {
        std::vector<int32_t> buf;
        buf.reserve(RING_ENTRIES_PER_VERTEX * n + 16);
        std::vector<Vertex_handle> adj;
        Vertex_handle inf = r.infinite_vertex();
        size_t walked = 0;
        for (Rt::Finite_vertices_iterator v = r.finite_vertices_begin(); v != r.finite_vertices_end(); ++v) {
            if (++walked % GP_RT3_RINGS_PER_CHECK == 0 && gp_canceled(cancel))
                return GP_ECANCELED;
            adj.clear();
            r.tds().adjacent_vertices(v, std::back_inserter(adj));
            int32_t id = v->info();
            size_t at = buf.size();
            buf.push_back(id);
            buf.push_back(0);
            bool on_hull = false;
            for (Vertex_handle a : adj) {
                if (a == inf)
                    on_hull = true;
                else
                    buf.push_back(a->info());
            }
            size_t degree = buf.size() - at - 2;
            buf[at + 1] = static_cast<int32_t>(degree);
            start[id + 1] = degree;
            if (infinite)
                infinite[id] = on_hull ? 1 : 0;
        }
        if (gp_canceled(cancel))
            return GP_ECANCELED;
        for (size_t i = 0; i < n; i++)
            start[i + 1] += start[i];
        walk = static_cast<int32_t *>(malloc((start[n] ? start[n] : 1) * sizeof *walk));
        if (!walk)
            return GP_ENOMEM;
        for (size_t at = 0; at < buf.size(); at += 2 + static_cast<size_t>(buf[at + 1]))
            std::copy(buf.begin() + at + 2, buf.begin() + at + 2 + buf[at + 1], walk + start[buf[at]]);
    } catch (...) {
        free(walk);
        return GP_ENOMEM; // the walk only allocates (CGAL's adjacency does not throw otherwise)
    }
    *ids = walk;
    return 0;
}

extern "C" int gp_rt3_tetrahedra(const gp_rt3 *rt, int32_t **tets, size_t *count) noexcept
{
    const Rt &r = rt->rt;
    size_t n = r.dimension() == 3 ? r.number_of_finite_cells() : 0;
    *count = 0;
    *tets = static_cast<int32_t *>(malloc((n ? 4 * n : 1) * sizeof **tets));
    if (!*tets)
        return GP_ENOMEM;
    if (n == 0)
        return 0;
    for (Rt::Finite_cells_iterator c = r.finite_cells_begin(); c != r.finite_cells_end(); ++c) {
        for (int k = 0; k < 4; k++)
            (*tets)[4 * *count + k] = c->vertex(k)->info();
        ++*count;
    }
    return 0;
}

extern "C" int gp_rt3_is_valid(const gp_rt3 *rt) noexcept
{
    try {
        return rt->rt.is_valid() && rt->rt.number_of_vertices() == rt->vertex.size();
    } catch (...) {
        return 0;
    }
}
