// mesh_cdt.cpp - CGAL's constrained Delaunay triangulation and its Delaunay mesher (the
// segment and triangle refinement levels of Delaunay_mesher_2, with its clusters at small
// input angles) behind the C API of core/mesh_cdt.h. Every entry point catches every
// exception.
//
// Two things differ from CGAL's own Delaunay_mesher_2 driver, for the reasons measured in
// bench/MESH.md:
//  - the queue of bad triangles: CGAL's keeps them in a map ordered by quality and keyed
//    by their vertices' coordinates, which took 62% of the time and made the refinement
//    superlinear (a 100 x 100 square with edges <= 0.3: 5.3 s of CPU); here a stack
//    (last in, first out) with each face's position stored in the face. A new bad face
//    is a neighbour of the last insertion, so the refinement walks the mesh locally
//    and stays in cache: 0.57 s for the same square, 2% more triangles, the same
//    guarantees (Ruppert's proof does not depend on the order);
//  - protected segments (the ends of the band's structured strips, whose nodes are the
//    quadrilaterals' rows) are never split: a triangle whose circumcentre would encroach
//    one is left as it is and counted (Shewchuk's Triangle does the same with -Y). A
//    strip's sides may be split like any segment; the splits are then mirrored onto the
//    facing side and the refinement run again, until both sides have the same nodes.
//    A periodic domain's opposite sides are settled the same way, by translation.
#include "mesh_cdt.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <boost/container/small_vector.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <initializer_list>
#include <new>
#include <numeric>
#include <unordered_set>
#include <vector>

namespace {

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;

// CGAL's mesh vertex, plus the input point it stands for (-1: a Steiner point), its node
// number in the output, whether it ends a protected segment, and the graded region's
// local size there.
template <class Gt, class Vb = CGAL::Delaunay_mesh_vertex_base_2<Gt>>
class Vertex_base : public Vb {
public:
    template <typename Tds2> struct Rebind_TDS {
        typedef typename Vb::template Rebind_TDS<Tds2>::Other Vb2;
        typedef Vertex_base<Gt, Vb2> Other;
    };
    using Vb::Vb;
    int32_t input = -1;
    int32_t node = -1;
    bool guarded = false;
    double size = HUGE_VAL; // graded meshes: the local target edge length of the band here
};

// CGAL's mesh face, plus its place in the stack of bad faces and its region.
template <class Gt, class Fb = CGAL::Delaunay_mesh_face_base_2<Gt>>
class Face_base : public Fb {
public:
    template <typename Tds2> struct Rebind_TDS {
        typedef typename Fb::template Rebind_TDS<Tds2>::Other Fb2;
        typedef Face_base<Gt, Fb2> Other;
    };
    using Fb::Fb;
    // User-provided, as CGAL's own face bases are: the container makes a face with
    // `new (slot) Face_base()`, which would zero-initialize an implicit constructor's
    // object, time stamp included, and the container keeps any stamp but -1 (the one
    // a fresh slot holds). Every face from Tds::create_face() (hole filling when a
    // segment or a point goes in) then had stamp 0: handles order by stamp, so two of
    // them compared equal (Debug: Time_stamper.h's assertion; Release: the edge
    // iterator may skip the edge between two such faces).
    Face_base() : Fb() {}
    std::ptrdiff_t queue_pos = -1;
    int32_t region = -1;
};

typedef CGAL::Triangulation_data_structure_2<Vertex_base<K>, Face_base<K>> Tds;
typedef CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag> Cdt_base;

// A vertex pair, unordered.
struct Vertex_pair_hash {
    size_t operator()(const std::pair<const void *, const void *> &p) const
    {
        std::hash<const void *> h;
        return h(p.first) * 31 + h(p.second);
    }
};

// The triangulation, and which of its constrained edges are protected: the segment
// predicate below sees only the triangulation, so the set lives here.
class Cdt : public Cdt_base {
public:
    std::unordered_set<std::pair<const void *, const void *>, Vertex_pair_hash> protected_edges;

    static std::pair<const void *, const void *> key(const Vertex_handle &a, const Vertex_handle &b)
    {
        const void *x = &*a, *y = &*b;
        return x < y ? std::make_pair(x, y) : std::make_pair(y, x);
    }
    void protect(const Vertex_handle &a, const Vertex_handle &b)
    {
        a->guarded = b->guarded = true;
        protected_edges.insert(key(a, b));
    }
    bool is_protected(const Vertex_handle &a, const Vertex_handle &b) const
    {
        return a->guarded && b->guarded && protected_edges.count(key(a, b)) != 0;
    }
};

} // namespace

// The conflict zone of one insertion (the faces a new point destroys and the edges around
// them), for both levels of the mesher. CGAL's generic one keeps them in std::lists: a
// heap node per face and per edge, made and freed at every insertion, was 40% of the
// stage's instructions (callgrind, iron: 300 of 743 million in new/delete). Here the
// same interface on vectors that hold a usual zone without the heap.
template <> struct CGAL::Triangulation_mesher_level_traits_2<Cdt> : public CGAL::Triangulation_ref_impl<Cdt> {
    typedef Cdt Triangulation;
    typedef Cdt::Point Point;
    typedef Cdt::Vertex_handle Vertex_handle;
    typedef Cdt::Face_handle Face_handle;
    typedef Cdt::Edge Edge;
    using CGAL::Triangulation_ref_impl<Cdt>::triangulation_ref_impl;

    explicit Triangulation_mesher_level_traits_2(Cdt &t) : CGAL::Triangulation_ref_impl<Cdt>(t) {}

    struct Zone {
        // A circumcentre destroys 4 to 5 faces on average, rarely more than a dozen; the
        // boundary of n faces has n + 2 edges. Larger zones spill to the heap.
        typedef boost::container::small_vector<Face_handle, 16> Faces;
        typedef boost::container::small_vector<Edge, 18> Edges;
        typedef Faces::iterator Faces_iterator;
        typedef Edges::iterator Edges_iterator;
        Cdt::Locate_type locate_type;
        Face_handle fh;
        int i;
        Face_handle parent_face; // the face whose circumcentre is inserted, if any
        Faces faces;
        Edges boundary_edges;
    };

    Vertex_handle insert_impl(const Point &p, Zone &zone)
    {
        if (zone.locate_type == Cdt::VERTEX)
            return zone.fh->vertex(zone.i);
        return triangulation_ref_impl().star_hole(p, zone.boundary_edges.begin(), zone.boundary_edges.end(),
                                                  zone.faces.begin(), zone.faces.end());
    }
};

namespace {

typedef Cdt::Vertex_handle Vertex_handle;
typedef Cdt::Face_handle Face_handle;
typedef Cdt::Point Point;

// The size of a face of the graded region: the fixed size when one is asked, else the
// smallest local size of its corners (HUGE_VAL where none was measured).
double graded_face_size(const Face_handle &fh, double fixed)
{
    if (fixed > 0.0)
        return fixed;
    return std::min(fh->vertex(0)->size, std::min(fh->vertex(1)->size, fh->vertex(2)->size));
}

// The local size a new vertex inherits from the corners of what it splits: their mean
// over those that have one. (The smallest would spread, one insertion after the other,
// the smallest size of the band to all of it.)
double inherited_size(std::initializer_list<Vertex_handle> corners)
{
    double sum = 0.0;
    int n = 0;
    for (const Vertex_handle &v : corners)
        if (v->size < HUGE_VAL) {
            sum += v->size;
            n++;
        }
    return n ? sum / n : HUGE_VAL;
}

// CGAL's criteria (Delaunay_mesh_size_criteria_2: a face is imperatively bad when its
// longest edge is over the size bound, bad when its smallest angle's squared sine is under
// the shape bound), except that the size bound of a face of the graded region (the band)
// is its own (graded_face_size) when smaller than the element size.
struct Criteria {
    typedef CGAL::Delaunay_mesh_size_criteria_2<Cdt>::Quality Quality;
    double shape_bound, size_bound; // 0: no size bound
    int32_t graded_region;          // -1: none
    double graded_size;             // 0: the corners' local sizes

    double face_size(const Face_handle &fh) const
    {
        if (graded_region < 0 || fh->region != graded_region)
            return size_bound;
        double s = graded_face_size(fh, graded_size);
        return size_bound > 0.0 && size_bound < s ? size_bound : s;
    }

    struct Is_bad {
        const Criteria &c;
        CGAL::Mesh_2::Face_badness operator()(const Quality &q) const
        {
            if (q.size() > 1.0)
                return CGAL::Mesh_2::IMPERATIVELY_BAD;
            return q.sine() < c.shape_bound ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
        }
        CGAL::Mesh_2::Face_badness operator()(const Face_handle &fh, Quality &q) const
        {
            const Point &a = fh->vertex(0)->point(), &b = fh->vertex(1)->point(), &p = fh->vertex(2)->point();
            double abx = b.x() - a.x(), aby = b.y() - a.y(), apx = p.x() - a.x(), apy = p.y() - a.y();
            double bpx = p.x() - b.x(), bpy = p.y() - b.y();
            double la = bpx * bpx + bpy * bpy, lb = apx * apx + apy * apy, lc = abx * abx + aby * aby;
            if (la < lb) // sorted: la >= lb >= lc
                std::swap(la, lb);
            if (lb < lc)
                std::swap(lb, lc);
            if (la < lb)
                std::swap(la, lb);
            double longest = la, second = lb;
            double h = c.face_size(fh);
            q.second = h > 0.0 && h < HUGE_VAL ? longest / (h * h) : 0.0;
            if (q.second > 1.0) {
                q.first = 1.0; // the sine does not matter: the face is split anyway
                return CGAL::Mesh_2::IMPERATIVELY_BAD;
            }
            double twice_area = abx * apy - aby * apx;
            q.first = twice_area * twice_area / (longest * second);
            return q.first < c.shape_bound ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
        }
    };
    Is_bad is_bad_object() const { return Is_bad{*this}; }
};
// The double-precision dot product below decides its sign when it exceeds this fraction of
// the sum of its two terms' magnitudes: its rounding error is at most 4 units in the last
// place of that sum (two differences, a product, a sum), 9e-16 of it; 1e-14 leaves room.
const double DOT_SIGN_FILTER = 1e-14;
// ... and when that sum is above this: no product underflowed.
const double DOT_SIGN_FILTER_MIN = 1e-250;

// Whether p sees the segment ab at an acute angle (it does not encroach the segment):
// (a - p).(b - p) > 0, in doubles when their rounding cannot change the sign, else by
// CGAL's exact Angle_2. Angle_2 alone (interval arithmetic for every call) was 6% of the
// stage's instructions (callgrind, iron).
bool sees_acute(const Point &a, const Point &p, const Point &b)
{
    double ax = a.x() - p.x(), ay = a.y() - p.y(), bx = b.x() - p.x(), by = b.y() - p.y();
    double xx = ax * bx, yy = ay * by, dot = xx + yy, mag = std::fabs(xx) + std::fabs(yy);
    if (std::fabs(dot) > DOT_SIGN_FILTER * mag && mag > DOT_SIGN_FILTER_MIN)
        return dot > 0.0;
    return CGAL::angle(a, p, b) == CGAL::ACUTE;
}

// CGAL's segment test (Is_locally_conforming_Gabriel: a segment is encroached when a
// point sees it at a right or obtuse angle), with the filtered test above, except that a
// protected segment is never encroached: it is never split.
struct Gabriel_unless_protected {
    // the segment of edge i of fh, against the two vertices facing it
    bool operator()(const Cdt &tr, const Face_handle &fh, const int i) const
    {
        const Vertex_handle &a = fh->vertex(Cdt::cw(i)), &b = fh->vertex(Cdt::ccw(i));
        if (tr.is_protected(a, b))
            return true;
        const Vertex_handle &c = fh->vertex(i);
        Vertex_handle d = tr.tds().mirror_vertex(fh, i);
        return (tr.is_infinite(c) || sees_acute(a->point(), c->point(), b->point())) &&
               (tr.is_infinite(d) || sees_acute(a->point(), d->point(), b->point()));
    }
    bool operator()(const Cdt &tr, const Vertex_handle &va, const Vertex_handle &vb) const
    {
        if (tr.is_protected(va, vb))
            return true;
        Face_handle fh;
        int i = 0;
        if (!tr.is_edge(va, vb, fh, i))
            return true; /* not reached: CGAL asks about edges of the triangulation */
        return (*this)(tr, fh, i);
    }
    // the segment against a point about to be inserted
    bool operator()(const Cdt &tr, const Face_handle &fh, const int i, const Point &p) const
    {
        return (*this)(tr, fh->vertex(Cdt::cw(i)), fh->vertex(Cdt::ccw(i)), p);
    }
    bool operator()(const Cdt &tr, const Vertex_handle &va, const Vertex_handle &vb,
                    const Point &p) const
    {
        return tr.is_protected(va, vb) || sees_acute(va->point(), p, vb->point());
    }
};

typedef CGAL::Mesh_2::Refine_edges_with_clusters<Cdt, Gabriel_unless_protected> Edges_level;

// The triangle level of the mesher: the interface of CGAL's Refine_faces_base (the
// Mesher_level concept), with the bad faces on a stack and protected segments honoured.
template <typename Tr, typename Crit, typename Previous>
class Stack_faces_base : public CGAL::Triangulation_mesher_level_traits_2<Tr> {
public:
    typedef CGAL::Triangulation_mesher_level_traits_2<Tr> Traits;
    typedef typename Traits::Zone Zone;
    typedef typename Crit::Quality Quality;
    using Traits::triangulation_ref_impl;
    // what CGAL's Refine_faces names of its queue type (for its debugging iterators)
    struct Bad_faces {
        typedef std::pair<Face_handle, Quality> Direct_entry;
        typedef const Direct_entry *const_iterator;
    };

    size_t dropped = 0;

protected:
    struct Entry {
        Face_handle face;
        Quality quality;
    };
    Crit &criteria;
    Previous &previous;
    std::vector<Entry> stack;
    CGAL::Mesh_2::Face_badness current_badness = CGAL::Mesh_2::NOT_BAD;
    int32_t inserted_region = -1; // of the face whose circumcentre is going in
    double inserted_size = HUGE_VAL;

    void push(const Face_handle &f, const Quality &q)
    {
        if (f->queue_pos >= 0) {
            stack[f->queue_pos].quality = q;
            return;
        }
        f->queue_pos = static_cast<std::ptrdiff_t>(stack.size());
        stack.push_back(Entry{f, q});
    }
    void remove(const Face_handle &f)
    {
        std::ptrdiff_t i = f->queue_pos;
        if (i < 0)
            return;
        f->queue_pos = -1;
        if (static_cast<size_t>(i) + 1 != stack.size()) {
            stack[i] = stack.back();
            stack[i].face->queue_pos = i;
        }
        stack.pop_back();
    }
    void test(const Face_handle &f)
    {
        Quality q;
        if (criteria.is_bad_object()(f, q) != CGAL::Mesh_2::NOT_BAD)
            push(f, q);
    }

public:
    Stack_faces_base(Tr &t, Crit &c, Previous &p) : Traits(t), criteria(c), previous(p) {}

    void scan_triangulation_impl()
    {
        for (const Entry &e : stack)
            e.face->queue_pos = -1;
        stack.clear();
        Tr &t = triangulation_ref_impl();
        for (auto f = t.finite_faces_begin(); f != t.finite_faces_end(); ++f)
            if (f->is_in_domain())
                test(f);
    }
    Zone conflicts_zone_impl(const Point &p, Face_handle fh)
    {
        Zone zone;
        Tr &t = triangulation_ref_impl();
        zone.fh = t.locate(p, zone.locate_type, zone.i, fh);
        zone.parent_face = fh;
        t.get_conflicts_and_boundary(p, std::back_inserter(zone.faces),
                                      std::back_inserter(zone.boundary_edges), fh);
        return zone;
    }
    bool no_longer_element_to_refine_impl() const { return stack.empty(); }
    Face_handle get_next_element_impl()
    {
        current_badness = criteria.is_bad_object()(stack.back().quality);
        return stack.back().face;
    }
    void pop_next_element_impl() { remove(stack.back().face); }
    Point refinement_point_impl(const Face_handle &f) const
    {
        return triangulation_ref_impl().circumcenter(f);
    }
    void before_conflicts_impl(const Face_handle &, const Point &)
    {
        previous.set_imperative_refinement(current_badness == CGAL::Mesh_2::IMPERATIVELY_BAD);
    }
    CGAL::Mesher_level_conflict_status test_point_conflict_from_superior_impl(const Point &, Zone &)
    {
        return CGAL::NO_CONFLICT;
    }
    // A circumcentre is refused (and the triangle left bad) when it falls outside the
    // triangle's own conflict zone (beyond a protected segment: an unprotected one would
    // have been encroached and split first), on a vertex, or inside the diametral circle
    // of a protected segment.
    CGAL::Mesher_level_conflict_status private_test_point_conflict_impl(const Point &p, Zone &zone)
    {
        const Tr &t = triangulation_ref_impl();
        bool inside = zone.locate_type != Tr::VERTEX && zone.fh->is_in_domain() &&
                      std::find(zone.faces.begin(), zone.faces.end(), zone.fh) != zone.faces.end();
        for (auto e = zone.boundary_edges.begin(); inside && e != zone.boundary_edges.end(); ++e) {
            const Face_handle &f = e->first;
            Vertex_handle a = f->vertex(Tr::cw(e->second)), b = f->vertex(Tr::ccw(e->second));
            if (f->is_constrained(e->second) && t.is_protected(a, b) &&
                !sees_acute(a->point(), p, b->point()))
                inside = false;
        }
        if (inside)
            return CGAL::NO_CONFLICT;
        dropped++;
        return CGAL::CONFLICT_AND_ELEMENT_SHOULD_BE_DROPPED;
    }
    // fh: the face whose circumcentre goes in (its zone, bounded by segments, is all of
    // its region), or none when the segment level splits a segment (its visitor then
    // restores the marks on each side)
    void before_insertion_impl(const Face_handle &fh, const Point &, Zone &zone)
    {
        for (auto f = zone.faces.begin(); f != zone.faces.end(); ++f) {
            if ((*f)->is_in_domain())
                remove(*f);
            (*f)->set_in_domain(false);
        }
        if (fh != Face_handle()) {
            inserted_region = fh->region;
            inserted_size = inherited_size({fh->vertex(0), fh->vertex(1), fh->vertex(2)});
        }
    }
    void after_insertion_impl(const Vertex_handle &v)
    {
        auto fc = triangulation_ref_impl().incident_faces(v), done = fc;
        do {
            fc->set_in_domain(true);
            fc->region = inserted_region;
        } while (++fc != done);
        v->size = inserted_size;
        compute_new_bad_faces(v);
    }
    template <typename E, typename Z> void after_no_insertion_impl(const E &, const Point &, Z &) {}
    // called by CGAL's segment-level visitor after a segment was split, too
    void compute_new_bad_faces(const Vertex_handle &v)
    {
        Tr &t = triangulation_ref_impl();
        auto fc = t.incident_faces(v), done = fc;
        do
            if (!t.is_infinite(fc) && fc->is_in_domain())
                test(fc);
        while (++fc != done);
    }
};

typedef Stack_faces_base<Cdt, Criteria, Edges_level> Faces_base;
typedef CGAL::Mesh_2::Refine_faces<Cdt, Criteria, Edges_level, Faces_base> Faces_level;

// The visitors of the two levels (CGAL's Refine_edges_visitor and its faces-level
// wrapper), which also carry the region of each side of a segment across its split: the
// graded criteria need the region of every face during the refinement. Mesher levels
// pass visitors by value: what a split remembers lives in Edge_split, owned by the caller.
struct Edge_split {
    Vertex_handle a, b;
    bool in_domain_right, in_domain_left;
    int32_t region_right, region_left;
};

class Edges_visitor : public CGAL::Null_mesh_visitor {
    Faces_level *faces;
    Edge_split *split;

public:
    typedef Cdt::Edge Edge;
    typedef CGAL::Triangulation_mesher_level_traits_2<Cdt>::Zone Zone;

    Edges_visitor(Faces_level &f, Edge_split &s) : faces(&f), split(&s) {}
    CGAL::Null_mesh_visitor previous_level() const { return CGAL::Null_mesh_visitor(); }

    void before_conflicts(const Edge &e, const Point &)
    {
        const Face_handle &right = e.first, &left = e.first->neighbor(e.second);
        split->a = right->vertex(Cdt::cw(e.second));
        split->b = right->vertex(Cdt::ccw(e.second));
        split->in_domain_right = right->is_in_domain();
        split->in_domain_left = left->is_in_domain();
        split->region_right = right->region;
        split->region_left = left->region;
    }
    void before_insertion(const Edge &, const Point &p, Zone &z)
    {
        faces->before_insertion_impl(Face_handle(), p, z);
    }
    // the faces around v from [a, v] to [v, b] counter-clockwise were at the right of
    // [a, b], the others at its left
    void after_insertion(const Vertex_handle &v)
    {
        Cdt &t = faces->triangulation_ref_impl();
        Face_handle fh;
        int i = 0;
        t.is_edge(split->a, v, fh, i);
        auto fc = t.incident_faces(v, fh), start = fc;
        do {
            if (!t.is_infinite(fc)) {
                fc->set_in_domain(split->in_domain_right);
                fc->region = split->region_right;
            }
            ++fc;
        } while (fc->vertex(Cdt::ccw(fc->index(v))) != split->b);
        do {
            if (!t.is_infinite(fc)) {
                fc->set_in_domain(split->in_domain_left);
                fc->region = split->region_left;
            }
            ++fc;
        } while (fc != start);
        v->size = inherited_size({split->a, split->b});
        faces->compute_new_bad_faces(v);
    }
    template <typename E, typename P, typename Z> void after_no_insertion(const E &, const P &, const Z &) const {}
};

// (CGAL's takes the zone by value: a copy of it at every insertion.)
class Faces_visitor {
    Edges_visitor edges;

public:
    Faces_visitor(Faces_level &f, Edge_split &s) : edges(f, s) {}
    Edges_visitor &previous_level() { return edges; }
    template <typename E, typename P> void before_conflicts(const E &, const P &) const {}
    template <typename E, typename P, typename Z> void before_insertion(const E &, const P &, const Z &) const {}
    template <typename V> void after_insertion(const V &) const {}
    template <typename E, typename P, typename Z> void after_no_insertion(const E &, const P &, const Z &) const {}
};

// Refinement steps between two looks at the cancel flag: each step inserts at most one
// point (about a microsecond), so a few milliseconds.
const unsigned STEPS_PER_CHECK = 4096;
// Points and segments inserted between two looks at the cancel flag.
const size_t INSERTS_PER_CHECK = 16384;
// Refinements run at most until the strips' sides (and the periodic sides) match; the
// last protects them (no more splits), so it always ends. Two rounds are usual
// (bench/MESH.md, bench/PERIODIC.md).
const int MAX_ROUNDS = 6;
// With periodic sides the third round is the last (locked): the second mirrors the
// first's splits, after which each further round adds about one node per sharp corner
// where a grain's outline crosses a periodic side at a small angle (the clusters there
// are never done, and each round splits their shells once more), and never matches. On
// the periodic iron mesh (bench/PERIODIC.md, seeds 1-3) locking at round 3 leaves 19 to
// 30 refused refinements, at round 6 18 to 34 with 1% more triangles, at round 2 739 to
// 831 (the mirrored nodes' neighbourhoods not yet refined).
const int MAX_PAIR_ROUNDS = 3;
// A node of a strip's side is one of the facing side's when their positions along the
// side (from 0 to 1) differ by less than this: both come from the same halvings of the
// same fractions, to rounding.
const double SIDE_MATCH_TOL = 1e-9;
// Two nodes of periodic sides are translates when their coordinates along the sides
// differ by less than this fraction of the side's length: CGAL splits the sides' segments
// at computed points (midpoints, and around small input angles its clusters' shells, from
// a square root) that may differ by a few ulps from one side to the other. align_pairs
// then makes them equal, bit for bit.
const double PAIR_MATCH_TOL = 1e-12;
// The next node along a side is the constrained neighbour whose direction deviates from
// the side's by less than this (sine): split points are midpoints, on the side to
// rounding; every other constrained edge there leaves at an angle.
const double SIDE_DIRECTION_TOL = 1e-6;

struct Run {
    const gp_pslg &g;
    const gp_cdt_params &params;
    gp_error *err;
    Cdt cdt;
    std::vector<Vertex_handle> vertex; // of each input point
    size_t dropped = 0;
    int rounds = 0;

    bool canceled() const
    {
        const gp_progress *pr = params.progress;
        return pr && pr->cancel && pr->cancel->load(std::memory_order_relaxed);
    }
    void report(double fraction) const
    {
        const gp_progress *pr = params.progress;
        if (pr && pr->report)
            pr->report(pr->ctx, "mesh",
                       params.progress_from + (params.progress_to - params.progress_from) *
                                                  std::min(1.0, std::max(0.0, fraction)));
    }
    int cancel_error() const
    {
        return gp_error_set(err, GP_ECANCELED, NULL, "mesh canceled");
    }

    // The indices of n points xy[0 .. 2n-1], in CGAL's spatial (Hilbert) order: walks
    // and insertions from one to the next stay short.
    static std::vector<size_t> spatial_order(const double *xy, size_t n, std::vector<Point> &points)
    {
        points.clear();
        points.reserve(n);
        for (size_t i = 0; i < n; i++)
            points.emplace_back(xy[2 * i], xy[2 * i + 1]);
        std::vector<size_t> order(n);
        std::iota(order.begin(), order.end(), size_t(0));
        typedef CGAL::Pointer_property_map<Point>::const_type Point_map;
        typedef CGAL::Spatial_sort_traits_adapter_2<K, Point_map> Sort_traits;
        const std::vector<Point> &fixed = points;
        CGAL::spatial_sort(order.begin(), order.end(), Sort_traits(CGAL::make_property_map(fixed)));
        return order;
    }

    int insert_points()
    {
        std::vector<Point> points;
        std::vector<size_t> order = spatial_order(g.xy, g.npoints, points);
        vertex.assign(g.npoints, Vertex_handle());
        Face_handle hint;
        for (size_t k = 0; k < order.size(); k++) {
            if (k % INSERTS_PER_CHECK == INSERTS_PER_CHECK - 1 && canceled())
                return cancel_error();
            size_t i = order[k];
            Vertex_handle v = cdt.insert(points[i], hint);
            if (v->input < 0)
                v->input = static_cast<int32_t>(i); // a repeated point keeps the first index
            vertex[i] = v;
            hint = v->face();
        }
        return 0;
    }

    int insert_segments()
    {
        for (size_t s = 0; s < g.nsegs; s++) {
            if (s % INSERTS_PER_CHECK == INSERTS_PER_CHECK - 1 && canceled())
                return cancel_error();
            Vertex_handle a = vertex[g.seg[2 * s]], b = vertex[g.seg[2 * s + 1]];
            if (a != b)
                cdt.insert_constraint(a, b);
        }
        // a protected segment crossed by another, or through a point, was split: its
        // strip's nodes would no longer be the mesh's
        for (size_t s = 0; s < g.nsegs; s++) {
            if (!g.seg_protected[s])
                continue;
            Vertex_handle a = vertex[g.seg[2 * s]], b = vertex[g.seg[2 * s + 1]];
            Face_handle f;
            int i;
            if (!cdt.is_edge(a, b, f, i))
                return gp_error_set(err, GP_EGEOM, NULL,
                                    "mesh: the strip end from (%.17g, %.17g) to (%.17g, %.17g) "
                                    "crosses another outline",
                                    a->point().x(), a->point().y(), b->point().x(), b->point().y());
            cdt.protect(a, b);
        }
        return 0;
    }

    // Flood fill from `start` across unconstrained edges, within in-domain faces unless
    // `hole` (then it clears their in-domain mark); regions that meet are an error.
    int flood(Face_handle start, int32_t region, bool hole, size_t seed)
    {
        std::vector<Face_handle> todo;
        auto visit = [&](Face_handle f) -> int {
            if (cdt.is_infinite(f))
                return 0;
            if (hole) {
                if (!f->is_in_domain())
                    return 0;
                f->set_in_domain(false);
            } else {
                if (!f->is_in_domain() || f->region == region)
                    return 0;
                if (f->region >= 0)
                    return gp_error_set(err, GP_EGEOM, NULL,
                                        "mesh: regions %d and %d are not separated by an outline "
                                        "(seed %zu)", f->region, region, seed);
                f->region = region;
            }
            todo.push_back(f);
            return 0;
        };
        int rc = visit(start);
        while (rc == 0 && !todo.empty()) {
            Face_handle f = todo.back();
            todo.pop_back();
            for (int i = 0; i < 3 && rc == 0; i++)
                if (!f->is_constrained(i))
                    rc = visit(f->neighbor(i));
        }
        return rc;
    }

    void mark_holes()
    {
        for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
            f->set_in_domain(!cdt.is_infinite(f));
        std::vector<Point> points;
        Face_handle hint;
        for (size_t s : spatial_order(g.seed_xy, g.nseeds, points)) {
            if (g.seed_region[s] >= 0)
                continue;
            Face_handle f = cdt.locate(points[s], hint);
            if (f != Face_handle())
                flood(f, -1, true, s);
            hint = f;
        }
    }

    int refine()
    {
        Criteria criteria{params.shape_bound, params.size_bound, params.graded_region, params.graded_size};
        CGAL::Null_mesher_level null_level;
        CGAL::Mesh_2::Clusters<Cdt> clusters(cdt);
        Edges_level edges(cdt, clusters, null_level);
        Faces_level faces(cdt, criteria, edges);
        Edge_split split;
        Faces_visitor visitor(faces, split);
        clusters.create_clusters();
        edges.scan_triangulation();
        faces.scan_triangulation();
        unsigned steps = 0;
        // the data structure's count, infinite faces included: Triangulation_2's own
        // walks around the infinite vertex (every node on the domain's sides) to leave
        // them out, a cache miss each, which was 14% of the stage on 10^5 grains (perf)
        const Cdt::Triangulation_data_structure &tds = cdt.tds();
        while (!faces.is_algorithm_done()) {
            faces.one_step(visitor);
            if (++steps % STEPS_PER_CHECK)
                continue;
            if (canceled())
                return cancel_error();
            if (params.max_triangles && tds.number_of_faces() > params.max_triangles)
                return gp_error_set(err, GP_ETOOBIG, NULL,
                                    "mesh: more than %zu elements; ask for a larger element_size "
                                    "or raise the limit",
                                    params.max_triangles);
            if (params.expected_triangles > 0.0)
                report(static_cast<double>(tds.number_of_faces()) / params.expected_triangles);
        }
        dropped += faces.dropped;
        return 0;
    }

    // The nodes of the side from `from` to `to`, along constrained edges.
    int side_chain(Vertex_handle from, Vertex_handle to, std::vector<Vertex_handle> &chain)
    {
        chain.assign(1, from);
        double dx = to->point().x() - from->point().x(), dy = to->point().y() - from->point().y();
        double len = std::sqrt(dx * dx + dy * dy);
        dx /= len;
        dy /= len;
        for (Vertex_handle v = from; v != to;) {
            Vertex_handle next;
            auto e = cdt.incident_edges(v), done = e;
            do {
                if (cdt.is_infinite(*e) || !e->first->is_constrained(e->second))
                    continue;
                Vertex_handle a = e->first->vertex(Cdt::cw(e->second));
                Vertex_handle w = a == v ? e->first->vertex(Cdt::ccw(e->second)) : a;
                double ux = w->point().x() - v->point().x(), uy = w->point().y() - v->point().y();
                double along = ux * dx + uy * dy, across = std::fabs(ux * dy - uy * dx);
                if (along > 0.0 && across <= SIDE_DIRECTION_TOL * along)
                    next = w;
            } while (++e != done);
            if (next == Vertex_handle() || chain.size() > cdt.number_of_vertices())
                return gp_error_set(err, GP_EINTERNAL, NULL,
                                    "mesh: lost the strip side at (%.17g, %.17g)", v->point().x(),
                                    v->point().y());
            chain.push_back(next);
            v = next;
        }
        return 0;
    }

    static double position(const std::vector<Vertex_handle> &chain, size_t k)
    {
        const Point &a = chain.front()->point(), &b = chain.back()->point(), &p = chain[k]->point();
        double dx = b.x() - a.x(), dy = b.y() - a.y();
        return ((p.x() - a.x()) * dx + (p.y() - a.y()) * dy) / (dx * dx + dy * dy);
    }

    // Inserts into `chain` (a side) a node at each position of `other` it lacks; returns
    // how many.
    size_t mirror(std::vector<Vertex_handle> &chain, const std::vector<Vertex_handle> &other)
    {
        size_t added = 0, k = 0;
        for (size_t o = 1; o + 1 < other.size(); o++) {
            double t = position(other, o);
            while (k + 1 < chain.size() && position(chain, k + 1) < t - SIDE_MATCH_TOL)
                k++;
            if (std::fabs(position(chain, k + 1) - t) <= SIDE_MATCH_TOL)
                continue;
            const Point &a = chain.front()->point(), &b = chain.back()->point();
            Point p(a.x() + t * (b.x() - a.x()), a.y() + t * (b.y() - a.y()));
            Face_handle f;
            int i = 0;
            if (!cdt.is_edge(chain[k], chain[k + 1], f, i))
                continue; /* not reached: the chain is made of edges */
            Vertex_handle v = cdt.insert(p, Cdt::EDGE, f, i);
            chain.insert(chain.begin() + static_cast<std::ptrdiff_t>(k + 1), v);
            added++;
        }
        return added;
    }

    // The coordinate of v along an axis-parallel side (`vertical`: along y).
    static double along(const Vertex_handle &v, bool vertical)
    {
        return vertical ? v->point().y() : v->point().x();
    }

    // Inserts into `chain` (a periodic side, run towards rising coordinates) the
    // translate of each node of `other` (its translate) it lacks: the same coordinate
    // along the side, the side's own across it, so that the pair matches bit for bit.
    // Returns how many.
    size_t mirror_translate(std::vector<Vertex_handle> &chain, const std::vector<Vertex_handle> &other)
    {
        bool vertical = chain.front()->point().x() == chain.back()->point().x();
        double across = vertical ? chain.front()->point().x() : chain.front()->point().y();
        size_t added = 0, k = 0;
        double tol = PAIR_MATCH_TOL * std::fabs(along(chain.back(), vertical) - along(chain.front(), vertical));
        for (size_t o = 1; o + 1 < other.size(); o++) {
            double t = along(other[o], vertical);
            while (k + 1 < chain.size() && along(chain[k + 1], vertical) < t)
                k++;
            if (k + 1 >= chain.size() || std::fabs(along(chain[k + 1], vertical) - t) <= tol ||
                std::fabs(along(chain[k], vertical) - t) <= tol)
                continue;
            Face_handle f;
            int i = 0;
            if (!cdt.is_edge(chain[k], chain[k + 1], f, i))
                continue; /* not reached: the chain is made of edges */
            Vertex_handle v = cdt.insert(vertical ? Point(across, t) : Point(t, across), Cdt::EDGE, f, i);
            chain.insert(chain.begin() + static_cast<std::ptrdiff_t>(k + 1), v);
            added++;
        }
        return added;
    }

    // The two opposite sides given by corners c[0] -> c[1] and c[2] -> c[3] (a strip, or a
    // periodic pair), as chains of nodes. With `what` (naming them in the message) their
    // lengths must agree; NULL while nodes are still being mirrored from one to the other.
    int side_pair(const int32_t *c, std::vector<Vertex_handle> &a, std::vector<Vertex_handle> &b,
                  const char *what)
    {
        int rc;
        if ((rc = side_chain(vertex[c[0]], vertex[c[1]], a)) ||
            (rc = side_chain(vertex[c[2]], vertex[c[3]], b)))
            return rc;
        if (what && a.size() != b.size())
            return gp_error_set(err, GP_EINTERNAL, NULL, "mesh: %s sides ended with %zu and %zu nodes",
                                what, a.size(), b.size());
        return 0;
    }

    // Walks the sides of every strip (`pairs` false) or periodic pair (true) given by
    // their corners; mirrors the nodes one has onto the other, or (`lock`) protects them.
    // Clears *matched when some side needed a node.
    int settle_sides(const int32_t *corners, size_t count, bool pairs, bool lock, bool *matched)
    {
        std::vector<Vertex_handle> a, b;
        for (size_t s = 0; s < count; s++) {
            int rc = side_pair(corners + 4 * s, a, b, NULL);
            if (rc)
                return rc;
            if (lock) {
                for (size_t k = 0; k + 1 < a.size(); k++)
                    cdt.protect(a[k], a[k + 1]);
                for (size_t k = 0; k + 1 < b.size(); k++)
                    cdt.protect(b[k], b[k + 1]);
                continue;
            }
            size_t added = pairs ? mirror_translate(a, b) + mirror_translate(b, a) : mirror(a, b) + mirror(b, a);
            if (added)
                *matched = false;
        }
        return 0;
    }

    // Once the periodic sides match: each node of a high side (right, top) takes the
    // coordinate along the side of its translate on the low side, bit for bit (they
    // differ by a few ulps at most, PAIR_MATCH_TOL: moving a node so little along a
    // straight side changes no triangle's orientation).
    int align_pairs()
    {
        std::vector<Vertex_handle> a, b;
        for (size_t s = 0; s < g.npairs; s++) {
            int rc = side_pair(g.pair_corners + 4 * s, a, b, "periodic");
            if (rc)
                return rc;
            bool vertical = a.front()->point().x() == a.back()->point().x();
            for (size_t k = 1; k + 1 < a.size(); k++) {
                double t = along(a[k], vertical), across = vertical ? b[k]->point().x() : b[k]->point().y();
                if (along(b[k], vertical) != t)
                    b[k]->set_point(vertical ? Point(across, t) : Point(t, across));
            }
        }
        return 0;
    }

    // The strips' sides and the periodic pairs, settled as settle_sides says. Sets
    // *matched when none needed a node.
    int settle_strips(bool lock, bool *matched)
    {
        *matched = true;
        int rc = settle_sides(g.strip_corners, g.nstrips, false, lock, matched);
        return rc ? rc : settle_sides(g.pair_corners, g.npairs, true, lock, matched);
    }

    int label()
    {
        std::vector<Point> points;
        Face_handle hint;
        for (size_t s : spatial_order(g.seed_xy, g.nseeds, points)) {
            int32_t region = g.seed_region[s];
            if (region < 0)
                continue;
            Face_handle f = cdt.locate(points[s], hint);
            hint = f;
            if (f == Face_handle() || cdt.is_infinite(f) || !f->is_in_domain())
                return gp_error_set(err, GP_EGEOM, NULL,
                                    "mesh: the seed of region %d at (%.17g, %.17g) is outside the "
                                    "meshed domain", region, g.seed_xy[2 * s], g.seed_xy[2 * s + 1]);
            if (f->region == region)
                continue;
            int rc = flood(f, region, false, s);
            if (rc)
                return rc;
        }
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
            if (!f->is_in_domain() || f->region >= 0)
                continue;
            if (g.default_region < 0)
                return gp_error_set(err, GP_EGEOM, NULL,
                                    "mesh: the triangle at (%.17g, %.17g) is in no region",
                                    f->vertex(0)->point().x(), f->vertex(0)->point().y());
            f->region = g.default_region;
        }
        return 0;
    }

    // The regions from the seeds again, from scratch: the refinement keeps them on its
    // new faces, but the mirrored strip nodes and the output take them from here.
    int relabel()
    {
        for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
            f->region = -1;
        return label();
    }

    // Each vertex of the graded region's outline gets its local size: the band's
    // thickness there, the distance from a face's segment (a grain's outline or the
    // domain's side) to the face's opposite corner (on the facing outline: no cell is
    // concave), the smallest over the faces of the region around it, times
    // GP_CDT_GRADED_SIZE_PER_THICKNESS.
    void measure_graded_sizes()
    {
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
            if (f->region != params.graded_region)
                continue;
            for (int i = 0; i < 3; i++) {
                Vertex_handle o = f->vertex(i), a = f->vertex(Cdt::cw(i)), b = f->vertex(Cdt::ccw(i));
                // a strip's end runs across the band, not along it
                if (!f->is_constrained(i) || cdt.is_protected(a, b))
                    continue;
                double ex = b->point().x() - a->point().x(), ey = b->point().y() - a->point().y();
                double ox = o->point().x() - a->point().x(), oy = o->point().y() - a->point().y();
                double len2 = ex * ex + ey * ey;
                if (!(len2 > 0.0))
                    continue;
                // to the segment, not its line: a corner beyond the segment's end (at a
                // junction) may lie near the line and far from the segment
                double t = std::min(1.0, std::max(0.0, (ox * ex + oy * ey) / len2));
                double dx = ox - t * ex, dy = oy - t * ey;
                double size = GP_CDT_GRADED_SIZE_PER_THICKNESS * std::sqrt(dx * dx + dy * dy);
                for (Vertex_handle v : {o, a, b})
                    v->size = std::min(v->size, size);
            }
        }
    }

    template <typename T> static T *alloc(size_t n)
    {
        return static_cast<T *>(malloc((n ? n : 1) * sizeof(T)));
    }

    int output(gp_cdt_mesh *out)
    {
        size_t nv = cdt.number_of_vertices(), nt = 0;
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
            nt += f->is_in_domain();
        out->xy = alloc<double>(2 * nv);
        out->point_node = alloc<int32_t>(g.npoints);
        out->tri = alloc<int32_t>(3 * nt);
        out->region = alloc<int32_t>(nt);
        out->strip_start = alloc<size_t>(g.nstrips + 1);
        if (!out->xy || !out->point_node || !out->tri || !out->region || !out->strip_start)
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for a mesh of %zu triangles", nt);
        size_t k = 0;
        for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v, k++) {
            v->node = static_cast<int32_t>(k);
            out->xy[2 * k] = v->point().x();
            out->xy[2 * k + 1] = v->point().y();
        }
        out->nnodes = nv;
        for (size_t i = 0; i < g.npoints; i++)
            out->point_node[i] = vertex[i]->node;
        k = 0;
        for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
            if (!f->is_in_domain())
                continue;
            for (int i = 0; i < 3; i++)
                out->tri[3 * k + i] = f->vertex(i)->node;
            out->region[k++] = f->region;
        }
        out->ntri = nt;
        // the strips' sides, as they ended
        std::vector<int32_t> sides;
        std::vector<Vertex_handle> a, b;
        out->strip_start[0] = 0;
        for (size_t s = 0; s < g.nstrips; s++) {
            int rc = side_pair(g.strip_corners + 4 * s, a, b, "a strip's");
            if (rc)
                return rc;
            for (const Vertex_handle &v : a)
                sides.push_back(v->node);
            for (const Vertex_handle &v : b)
                sides.push_back(v->node);
            out->strip_start[s + 1] = sides.size();
        }
        out->strip_sides = alloc<int32_t>(sides.size());
        if (!out->strip_sides)
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the strips");
        std::copy(sides.begin(), sides.end(), out->strip_sides);
        return 0;
    }

    int run(gp_cdt_mesh *out)
    {
        if (g.npoints > static_cast<size_t>(INT32_MAX) / 2)
            return gp_error_set(err, GP_ETOOBIG, NULL, "mesh: %zu input points", g.npoints);
        int rc;
        if ((rc = insert_points()) || (rc = insert_segments()))
            return rc;
        report(0.0);
        for (bool matched = false; !matched;) {
            bool last = ++rounds >= (g.npairs ? MAX_PAIR_ROUNDS : MAX_ROUNDS);
            if (last && (rc = settle_strips(true, &matched)))
                return rc;
            mark_holes();
            // the graded criteria need every face's region from the start
            if (params.graded_region >= 0 && (rc = relabel()))
                return rc;
            if (params.graded_region >= 0 && rounds == 1)
                measure_graded_sizes();
            if ((rc = refine()) || (rc = settle_strips(false, &matched)))
                return rc;
            if (last && !matched)
                return gp_error_set(err, GP_EINTERNAL, NULL, "mesh: protected strip sides were split");
        }
        // graded: the regions are those the last relabel gave, kept by the refinement
        // on its new faces, and nothing was inserted after it (the loop ends when the
        // strips needed no node; align_pairs only moves nodes by ulps along their side);
        // labelling again was 8% of the stage (callgrind, iron)
        if ((rc = align_pairs()) || (params.graded_region < 0 && (rc = label())))
            return rc;
        if (cdt.number_of_vertices() > static_cast<size_t>(INT32_MAX))
            return gp_error_set(err, GP_ETOOBIG, NULL, "mesh: more than %d nodes", INT32_MAX);
        out->dropped = dropped;
        out->rounds = rounds;
        return output(out);
    }
};

} // namespace

extern "C" int gp_cdt_refine(const gp_pslg *g, const gp_cdt_params *params, gp_cdt_mesh *out,
                             gp_error *err)
{
    std::memset(out, 0, sizeof *out);
    int rc;
    try {
        Run run{*g, *params, err, Cdt(), {}};
        rc = run.run(out);
    } catch (const std::bad_alloc &) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory meshing");
    } catch (const std::exception &e) {
        rc = gp_error_set(err, GP_EINTERNAL, NULL, "mesh: CGAL: %s", e.what());
    } catch (...) {
        rc = gp_error_set(err, GP_EINTERNAL, NULL, "mesh: CGAL: unknown failure");
    }
    if (rc)
        gp_cdt_mesh_free(out);
    return rc;
}

extern "C" void gp_cdt_mesh_free(gp_cdt_mesh *m) noexcept
{
    free(m->xy);
    free(m->point_node);
    free(m->tri);
    free(m->region);
    free(m->strip_start);
    free(m->strip_sides);
    std::memset(m, 0, sizeof *m);
}
