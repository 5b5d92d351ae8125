// triangulation.cpp - the only C++ of grainpack: CGAL's Regular_triangulation_2 (exact
// predicates, inexact constructions) of the disk centres with weights R^2, behind the C
// API of grainpack/triangulation.h. Every entry point catches every exception.
#include "grainpack/triangulation.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <new>
#include <utility>
#include <vector>

namespace {

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Regular_triangulation_vertex_base_2<K> Vb0;
typedef CGAL::Triangulation_vertex_base_with_info_2<int32_t, K, Vb0> Vb;
typedef CGAL::Regular_triangulation_face_base_2<K> Fb;
typedef CGAL::Triangulation_data_structure_2<Vb, Fb> Tds;
typedef CGAL::Regular_triangulation_2<K, Tds> Rt;
typedef Rt::Vertex_handle Vertex_handle;
typedef Rt::Face_handle Face_handle;
typedef K::Point_2 Point;
typedef K::Weighted_point_2 Weighted_point;

// A vertex's flips are capped: Lawson's flips end after a number of flips bounded by the
// edges the move touches, a few dozen here; far beyond that something is wrong and the
// triangulation is built again instead.
const int MAX_FLIPS_PER_MOVE = 10000;

Weighted_point weighted(const gp_disk &d)
{
    return Weighted_point(Point(d.x, d.y), d.R * d.R);
}

} // namespace

struct gp_rt {
    Rt rt;
    std::vector<Vertex_handle> vertex;                // by disk id
    std::vector<std::pair<Face_handle, int>> edges;   // the flip stack, kept between moves
    uint8_t *marks = nullptr;                         // borrowed: see gp_rt_mark_changes
};

namespace {

// Marks the ring of finite vertex v as changed, when the caller asked for marks.
void mark(const gp_rt &t, Vertex_handle v)
{
    if (t.marks && !t.rt.is_infinite(v))
        t.marks[v->info()] = 1;
}

// Marks v and every finite vertex around it.
void mark_star(const gp_rt &t, Vertex_handle v)
{
    mark(t, v);
    Rt::Vertex_circulator c = t.rt.incident_vertices(v), done = c;
    if (c != nullptr)
        do
            mark(t, c);
        while (++c != done);
}

// Comparisons of the spatial sort between two reads of the cancel flag: well under a
// millisecond of work.
const unsigned long COMPARISONS_PER_CHECK = 1UL << 16;

// Thrown out of the spatial sort when the cancel flag is raised (the sort only permutes
// a vector of indices: nothing is left half-built).
struct Sort_canceled {};

// The traits of CGAL's spatial sort over disk indices: the comparisons of
// Spatial_sort_traits_adapter_2 on the centres (x < x, y < y, as the kernel's Less_x_2
// and Less_y_2 on doubles), counted, with the cancel flag read every
// COMPARISONS_PER_CHECK of them. The sort runs O(n log n) comparisons (0.5 s of CPU for
// a million disks): without this it could not be interrupted.
class Sort_traits {
  public:
    struct Shared {
        const std::vector<Point> *points;
        const gp_progress *progress;
        unsigned long comparisons;
    };
    typedef std::size_t Point_2;
    struct Less_x_2 {
        Shared *s;
        bool operator()(std::size_t p, std::size_t q) const
        {
            tick(s);
            return (*s->points)[p].x() < (*s->points)[q].x();
        }
    };
    struct Less_y_2 {
        Shared *s;
        bool operator()(std::size_t p, std::size_t q) const
        {
            tick(s);
            return (*s->points)[p].y() < (*s->points)[q].y();
        }
    };
    explicit Sort_traits(Shared *shared) : s(shared) {}
    Less_x_2 less_x_2_object() const { return Less_x_2{s}; }
    Less_y_2 less_y_2_object() const { return Less_y_2{s}; }

  private:
    Shared *s;
    static void tick(Shared *s)
    {
        if (++s->comparisons % COMPARISONS_PER_CHECK == 0 && gp_canceled(gp_progress_cancel(s->progress)))
            throw Sort_canceled();
    }
};

// Fills t.rt and t.vertex from the disks; returns 0, GP_ECANCELED or GP_EGEOM (hidden
// vertex) with err. What CGAL's range insertion with info does (the same spatial sort of
// the same indices, then one insertion after another, each from the last one's face), so
// the same disks give the same triangulation; but the cancel flag is read during the
// sort and between batches of insertions.
int build_into(gp_rt &t, const gp_disk *disks, size_t n, const gp_progress *progress, bool report,
               gp_error *err)
{
    t.rt.clear();
    std::vector<Point> points;
    std::vector<std::size_t> order(n);
    points.reserve(n);
    for (size_t i = 0; i < n; i++) {
        points.emplace_back(disks[i].x, disks[i].y);
        order[i] = i;
    }
    Sort_traits::Shared shared = {&points, progress, 0};
    try {
        CGAL::spatial_sort(order.begin(), order.end(), Sort_traits(&shared));
    } catch (const Sort_canceled &) {
        return gp_error_set(err, GP_ECANCELED, NULL,
                            "regular triangulation canceled while sorting %zu disks", n);
    }
    Face_handle hint;
    for (size_t k = 0; k < n; k++) {
        if (k % GP_RT_INSERT_BATCH == 0 && k > 0 && progress) {
            if (gp_canceled(progress->cancel))
                return gp_error_set(err, GP_ECANCELED, NULL,
                                    "regular triangulation canceled after %zu of %zu disks", k, n);
            if (report && progress->report)
                progress->report(progress->ctx, "triangulation", static_cast<double>(k) / static_cast<double>(n));
        }
        size_t i = order[k];
        Vertex_handle v = t.rt.insert(weighted(disks[i]), hint);
        if (v != Vertex_handle()) {
            v->info() = static_cast<int32_t>(i);
            hint = v->face();
        }
    }
    t.vertex.assign(n, Vertex_handle());
    for (Rt::Finite_vertices_iterator v = t.rt.finite_vertices_begin();
         v != t.rt.finite_vertices_end(); ++v) {
        int32_t id = v->info();
        if (id < 0 || static_cast<size_t>(id) >= n || t.vertex[id] != Vertex_handle())
            return gp_error_set(err, GP_EGEOM, NULL,
                                "regular triangulation: two vertices claim disk %d", id);
        t.vertex[id] = v;
    }
    if (t.marks)
        std::fill(t.marks, t.marks + n, uint8_t(1));
    for (size_t i = 0; i < n; i++)
        if (t.vertex[i] == Vertex_handle())
            return gp_error_set(err, GP_EGEOM, NULL,
                                "regular triangulation: disk %zu at (%.17g, %.17g), R = %.17g, is "
                                "hidden (it overlaps another disk or shares its centre)",
                                i, disks[i].x, disks[i].y, disks[i].R);
    return 0;
}

// A power test computed in doubles is trusted when it exceeds this fraction of the sum
// of the absolute values of its terms. Why this value: with every input difference
// rounded once, the determinant's rounding error stays below about 20 ulps of that sum
// (2e-15 of it); 1e-12 leaves a margin of hundreds, and a test too close to call goes to
// CGAL's exact predicate, so the answer is always the exact one.
const double POWER_TEST_FILTER = 1e-12;

// rt.power_test(f, t) for a finite face f, the sign of CGAL's determinant
// (power_side_of_oriented_power_circleC2, translated to t), first in plain doubles.
// CGAL's own filter evaluates it in interval arithmetic, switching the FPU rounding mode
// each time: a third of the updates' time. Exact either way.
CGAL::Oriented_side power_test(const Rt &rt, Face_handle f, const Weighted_point &t)
{
    const Weighted_point &p = f->vertex(0)->point(), &q = f->vertex(1)->point(), &r = f->vertex(2)->point();
    double tx = t.x(), ty = t.y(), tw = t.weight();
    double px = p.x() - tx, py = p.y() - ty, pz = px * px + py * py - p.weight() + tw;
    double qx = q.x() - tx, qy = q.y() - ty, qz = qx * qx + qy * qy - q.weight() + tw;
    double rx = r.x() - tx, ry = r.y() - ty, rz = rx * rx + ry * ry - r.weight() + tw;
    // the lifted coordinates' size before cancellation, for the error bound
    double pa = px * px + py * py + std::fabs(p.weight()) + std::fabs(tw);
    double qa = qx * qx + qy * qy + std::fabs(q.weight()) + std::fabs(tw);
    double ra = rx * rx + ry * ry + std::fabs(r.weight()) + std::fabs(tw);
    double det = px * (qy * rz - qz * ry) - py * (qx * rz - qz * rx) + pz * (qx * ry - qy * rx);
    double bound = std::fabs(px) * (std::fabs(qy) * ra + qa * std::fabs(ry)) +
                   std::fabs(py) * (std::fabs(qx) * ra + qa * std::fabs(rx)) +
                   pa * (std::fabs(qx * ry) + std::fabs(qy * rx));
    if (det > POWER_TEST_FILTER * bound)
        return CGAL::ON_POSITIVE_SIDE;
    if (det < -POWER_TEST_FILTER * bound)
        return CGAL::ON_NEGATIVE_SIDE;
    return rt.power_test(f, t);
}

// Lawson's flips from the edges of the faces around v until every edge they reach is
// locally regular. Returns false when a non-regular edge cannot be flipped (its
// quadrilateral is not convex) or the flips run away.
bool flip_around(gp_rt &t, Vertex_handle v, gp_rt_update_stats &stats)
{
    Rt &rt = t.rt;
    std::vector<std::pair<Face_handle, int>> &stack = t.edges;
    // every edge whose two triangles have v as a vertex: the link edge and one spoke of
    // each triangle around v (the other spoke is the next triangle's)
    stack.clear();
    Rt::Face_circulator fc = rt.incident_faces(v), done = fc;
    do {
        int i = fc->index(v);
        stack.emplace_back(fc, i);
        stack.emplace_back(fc, Rt::ccw(i));
    } while (++fc != done);
    int flips = 0;
    while (!stack.empty()) {
        Face_handle f = stack.back().first;
        int i = stack.back().second;
        stack.pop_back();
        Face_handle g = f->neighbor(i);
        if (rt.is_infinite(f) || rt.is_infinite(g))
            continue; // hull edges: the hull does not change, see gp_rt_update_moved
        const Weighted_point &d = g->vertex(g->index(f))->point();
        if (power_test(rt, f, d) != CGAL::ON_POSITIVE_SIDE)
            continue; // locally regular (or exactly co-power-circular: either diagonal)
        const Weighted_point &a = f->vertex(i)->point();
        const Weighted_point &b = f->vertex(Rt::ccw(i))->point();
        const Weighted_point &c = f->vertex(Rt::cw(i))->point();
        if (rt.orientation(a, b, d) != CGAL::LEFT_TURN || rt.orientation(a, d, c) != CGAL::LEFT_TURN)
            return false;
        if (++flips > MAX_FLIPS_PER_MOVE)
            return false;
        // the four vertices of the quadrilateral gain or lose a neighbour
        mark(t, f->vertex(i));
        mark(t, f->vertex(Rt::ccw(i)));
        mark(t, f->vertex(Rt::cw(i)));
        mark(t, g->vertex(g->index(f)));
        rt.flip(f, i);
        stats.flips++;
        for (int j = 0; j < 3; j++) {
            stack.emplace_back(f, j);
            stack.emplace_back(g, j);
        }
    }
    return true;
}

// Whether v can move to p without folding a triangle of its star: v must be interior and
// p on the left of every edge of its link.
bool can_move_in_place(const Rt &rt, Vertex_handle v, const Point &p)
{
    Rt::Face_circulator fc = rt.incident_faces(v), done = fc;
    do {
        if (rt.is_infinite(fc))
            return false;
        int i = fc->index(v);
        if (CGAL::orientation(p, fc->vertex(Rt::ccw(i))->point().point(),
                              fc->vertex(Rt::cw(i))->point().point()) != CGAL::LEFT_TURN)
            return false;
    } while (++fc != done);
    return true;
}

enum move_outcome { MOVED, NEEDS_REBUILD };

move_outcome move_vertex(gp_rt &t, int32_t id, const Weighted_point &wp, gp_rt_update_stats &stats)
{
    Vertex_handle v = t.vertex[id];
    if (t.rt.dimension() < 2)
        return NEEDS_REBUILD;
    if (can_move_in_place(t.rt, v, wp.point())) {
        v->set_point(wp);
        stats.moved_in_place++;
        return flip_around(t, v, stats) ? MOVED : NEEDS_REBUILD;
    }
    // remove and insert again: the triangulation stays regular throughout. Removing
    // retriangulates the hole among v's neighbours; inserting flips only edges whose
    // ends end up around the new vertex: those are all the rings that change.
    mark_star(t, v);
    Vertex_handle near;
    Rt::Vertex_circulator c = t.rt.incident_vertices(v), done = c;
    do
        near = c;
    while (t.rt.is_infinite(near) && ++c != done);
    t.rt.remove(v);
    Vertex_handle w = t.rt.insert(wp, near->face());
    if (w == Vertex_handle() || w->is_hidden() || t.rt.number_of_hidden_vertices() > 0)
        return NEEDS_REBUILD; // the rebuild names the disk
    w->info() = id;
    t.vertex[id] = w;
    mark_star(t, w);
    stats.reinserted++;
    return MOVED;
}

} // namespace

extern "C" int gp_rt_build(const gp_disk *disks, size_t n, const gp_progress *progress, gp_rt **out,
                           gp_error *err)
{
    *out = NULL;
    if (n > static_cast<size_t>(INT32_MAX))
        return gp_error_set(err, GP_ETOOBIG, NULL, "regular triangulation: %zu disks, more than %d",
                            n, INT32_MAX);
    gp_rt *t = NULL;
    try {
        t = new gp_rt;
        int rc = build_into(*t, disks, n, progress, true, err);
        if (rc) {
            delete t;
            return rc;
        }
    } catch (const std::bad_alloc &) {
        delete t;
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory building the triangulation of %zu disks", n);
    } catch (const std::exception &e) {
        delete t;
        return gp_error_set(err, GP_EINTERNAL, NULL, "regular triangulation: %s", e.what());
    } catch (...) {
        delete t;
        return gp_error_set(err, GP_EINTERNAL, NULL, "regular triangulation: unknown failure");
    }
    *out = t;
    return 0;
}

extern "C" void gp_rt_free(gp_rt *rt) noexcept
{
    delete rt;
}

extern "C" size_t gp_rt_count(const gp_rt *rt) noexcept
{
    return rt->vertex.size();
}

extern "C" int gp_rt_dimension(const gp_rt *rt) noexcept
{
    return rt->rt.dimension();
}

namespace {

// The ring of v as gp_rt_ring gives it (see there).
size_t ring_of(const Rt &r, Vertex_handle v, int32_t *out, size_t cap, int *hull)
{
    *hull = 1;
    if (r.dimension() < 1)
        return 0;
    size_t n = 0, after_infinite = 0;
    bool infinite = false;
    Vertex_handle inf = r.infinite_vertex();
    if (r.dimension() < 2) {
        Rt::Vertex_circulator c = r.incident_vertices(v), done = c;
        do {
            if (c != inf && n++ < cap)
                out[n - 1] = c->info();
        } while (++c != done);
        return n;
    }
    // the faces around v counter-clockwise, by hand: face f holds (v, a, b) in that
    // order with a = f->vertex(ccw(i)); the next face shares the edge (v, b). A little
    // faster than CGAL's vertex circulator (0.19 s against 0.22 s for 10^6 rings), and
    // every stage asks for every ring.
    Face_handle f = v->face(), start = f;
    do {
        int i = f->index(v);
        Vertex_handle a = f->vertex(Rt::ccw(i));
        if (a == inf) {
            infinite = true;
            after_infinite = n;
        } else if (n++ < cap) {
            out[n - 1] = a->info();
        }
        f = f->neighbor(Rt::ccw(i));
    } while (f != start);
    *hull = infinite ? 1 : 0;
    if (n > cap)
        return n;
    // a canonical start, whatever face CGAL's circulator starts from: just after the
    // outside of the hull, or the smallest id (so that updates and rebuilds agree)
    size_t first = after_infinite;
    if (!infinite)
        first = static_cast<size_t>(std::min_element(out, out + n) - out);
    std::rotate(out, out + first, out + n);
    return n;
}

} // namespace

extern "C" size_t gp_rt_ring(const gp_rt *rt, int32_t id, int32_t *out, size_t cap,
                             int *hull) noexcept
{
    return ring_of(rt->rt, rt->vertex[id], out, cap, hull);
}

// Room for the rings of gp_rt_rings' walk: six neighbours a vertex on average (Euler), a
// few more along the hull, and two entries of bookkeeping per ring.
const size_t RING_ENTRIES_PER_VERTEX = 9;

extern "C" int gp_rt_rings(const gp_rt *rt, size_t *start, uint8_t *hull, int32_t **ids,
                           const gp_progress *progress) noexcept
{
    const gp_cancel_flag *cancel = gp_progress_cancel(progress);
    size_t walked = 0;
    const Rt &r = rt->rt;
    size_t n = rt->vertex.size();
    *ids = NULL;
    // one walk of the vertices in the triangulation's memory order (a vertex and its
    // faces were allocated together, so the walk stays in cache, where visiting them by
    // id jumps across the whole triangulation for every ring) appends each ring to
    // `walk` as (id, degree, ring); the rings are then copied to their places by id, a
    // read in order of a compact buffer (a second walk of the triangulation, to count the
    // rings first, cost a third of the rings' time at 10^6 grains)
    size_t cap = RING_ENTRIES_PER_VERTEX * n + 16, used = 0;
    int32_t *walk = static_cast<int32_t *>(malloc(cap * sizeof *walk));
    if (!walk)
        return GP_ENOMEM;
    std::fill(start, start + n + 1, size_t(0));
    for (Rt::Finite_vertices_iterator v = r.finite_vertices_begin(); v != r.finite_vertices_end(); ++v) {
        if (++walked % GP_RT_RINGS_PER_CHECK == 0 && gp_canceled(cancel)) {
            free(walk);
            return GP_ECANCELED;
        }
        int on_hull;
        size_t degree;
        for (;;) {
            if (cap - used >= 2 && (degree = ring_of(r, v, walk + used + 2, cap - used - 2, &on_hull)) <= cap - used - 2)
                break;
            int32_t *grown = cap <= SIZE_MAX / 4 / sizeof *walk
                                 ? static_cast<int32_t *>(realloc(walk, 2 * cap * sizeof *walk)) : NULL;
            if (!grown) {
                free(walk);
                return GP_ENOMEM;
            }
            walk = grown;
            cap *= 2;
        }
        int32_t id = v->info();
        walk[used] = id;
        walk[used + 1] = static_cast<int32_t>(degree);
        used += 2 + degree;
        start[id + 1] = degree;
        if (hull)
            hull[id] = static_cast<uint8_t>(on_hull);
    }
    if (gp_canceled(cancel)) {
        free(walk);
        return GP_ECANCELED;
    }
    for (size_t i = 0; i < n; i++)
        start[i + 1] += start[i];
    int32_t *out = static_cast<int32_t *>(malloc((start[n] ? start[n] : 1) * sizeof *out));
    if (!out) {
        free(walk);
        return GP_ENOMEM;
    }
    for (size_t at = 0; at < used; at += 2 + static_cast<size_t>(walk[at + 1]))
        std::copy(walk + at + 2, walk + at + 2 + walk[at + 1], out + start[walk[at]]);
    free(walk);
    *ids = out;
    return 0;
}

extern "C" void gp_rt_mark_changes(gp_rt *rt, uint8_t *marks) noexcept
{
    rt->marks = marks;
}

// How many moves ahead gp_rt_update_moved asks for a vertex, then for its face: a move
// takes about a microsecond, a read from memory a tenth of that, and the face's address is
// in the vertex.
const size_t UPDATE_AHEAD_VERTEX = 8;
const size_t UPDATE_AHEAD_FACE = 4;

extern "C" int gp_rt_update_moved(gp_rt *rt, const gp_disk *disks, size_t ndisks,
                                  const int32_t *ids, size_t nids, gp_rt_update mode,
                                  gp_rt_update_stats *stats, const gp_progress *progress,
                                  gp_error *err)
{
    gp_rt_update_stats local = {0, 0, 0, 0};
    gp_rt_update_stats &st = stats ? *stats : local;
    try {
        bool rebuild = mode == GP_RT_UPDATE_REBUILD;
        for (size_t k = 0; k < nids && !rebuild; k++) {
            if (k % GP_RT_INSERT_BATCH == GP_RT_INSERT_BATCH - 1 && gp_canceled(gp_progress_cancel(progress)))
                return gp_error_set(err, GP_ECANCELED, NULL,
                                    "triangulation update canceled after %zu of %zu moves", k, nids);
            // the moved ids jump across the structure (the packer's order): ask the memory
            // for the vertices, then their faces, a few moves ahead (only a hint)
            if (k + UPDATE_AHEAD_VERTEX < nids)
                __builtin_prefetch(&*rt->vertex[ids[k + UPDATE_AHEAD_VERTEX]]);
            if (k + UPDATE_AHEAD_FACE < nids)
                __builtin_prefetch(&*rt->vertex[ids[k + UPDATE_AHEAD_FACE]]->face());
            rebuild = move_vertex(*rt, ids[k], weighted(disks[ids[k]]), st) == NEEDS_REBUILD;
        }
        if (rebuild) {
            st.rebuilds++;
            return build_into(*rt, disks, ndisks, progress, false, err);
        }
        return 0;
    } catch (const std::bad_alloc &) {
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory updating the triangulation");
    } catch (const std::exception &e) {
        return gp_error_set(err, GP_EINTERNAL, NULL, "regular triangulation: %s", e.what());
    } catch (...) {
        return gp_error_set(err, GP_EINTERNAL, NULL, "regular triangulation: unknown failure");
    }
}

extern "C" int gp_rt_is_regular(const gp_rt *rt) noexcept
{
    try {
        return rt->rt.is_valid() && rt->rt.number_of_hidden_vertices() == 0;
    } catch (...) {
        return 0;
    }
}
