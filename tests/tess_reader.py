"""tess_reader.py - an independent reader of Neper's tessellation files (.tess), written
from Neper's documentation of the format (doc/fileformat.rst, "Tessellation File"; the
fields of format 3.4 that Neper 4 writes), not from grainpack's writer, and the checks a
valid 3D tessellation of a box passes: identifiers 1..n, every face's edges joining its
consecutive vertices with the documented signs, the face equations (unit normal, vertices
on the plane, normal along the vertex loop), every face listed by exactly two polyhedra
with opposite signs or by one and by a domain face, every edge in at least three faces
inside the box (two on its faces), Euler's formula per polyhedron, outward faces, the
volumes summing to the box's, and the domain's corners, edges and faces where they are.

Usage as a program: tess_reader.py FILE.tess (prints the counts and volumes, exits 1 on
a failed check). As a module: read(path) -> Tess, check(tess) -> list of failures."""
import math
import sys


class Tess:
    pass


def _tokens(path):
    with open(path) as f:
        for line in f:
            for tok in line.split():
                yield tok


def read(path):
    """Parses the file into a Tess: vertices {id: (x, y, z)}, edges {id: (v1, v2)},
    faces {id: dict(verts, edges, eq=(d, a, b, c))}, polys {id: [signed face ids]},
    seeds {id: (x, y, z, w)}, domain dict(type, vertices, edges, faces)."""
    t = Tess()
    toks = _tokens(path)
    nxt = lambda: next(toks)
    assert nxt() == "***tess", "no ***tess"
    t.seeds, t.vertices, t.edges, t.faces, t.polys = {}, {}, {}, {}, {}
    t.domain = {"vertices": {}, "edges": {}, "faces": {}}
    tok = nxt()
    while tok != "***end":
        if tok == "**format":
            t.format = nxt()
            tok = nxt()
        elif tok == "**general":
            t.dim, t.type = int(nxt()), nxt()
            tok = nxt()
        elif tok == "**cell":
            t.ncells = int(nxt())
            tok = nxt()
            while tok.startswith("*") and not tok.startswith("**"):
                if tok == "*seed":
                    for _ in range(t.ncells):
                        i = int(nxt())
                        t.seeds[i] = tuple(float(nxt()) for _ in range(4))
                elif tok == "*id":
                    t.ids = [int(nxt()) for _ in range(t.ncells)]
                elif tok == "*crysym":
                    nxt()
                else:
                    raise ValueError("cell field %s not read by this reader" % tok)
                tok = nxt()
        elif tok == "**vertex":
            for _ in range(int(nxt())):
                i = int(nxt())
                t.vertices[i] = tuple(float(nxt()) for _ in range(3))
                int(nxt())  # state
            tok = nxt()
        elif tok == "**edge":
            for _ in range(int(nxt())):
                i = int(nxt())
                t.edges[i] = (int(nxt()), int(nxt()))
                int(nxt())  # state
            tok = nxt()
        elif tok == "**face":
            for _ in range(int(nxt())):
                i = int(nxt())
                verts = [int(nxt()) for _ in range(int(nxt()))]
                edges = [int(nxt()) for _ in range(int(nxt()))]
                eq = tuple(float(nxt()) for _ in range(4))  # d a b c
                state, point = int(nxt()), int(nxt())
                ppt = tuple(float(nxt()) for _ in range(3))
                t.faces[i] = dict(verts=verts, edges=edges, eq=eq, state=state, point=point, ppt=ppt)
            tok = nxt()
        elif tok == "**polyhedron":
            for _ in range(int(nxt())):
                i = int(nxt())
                t.polys[i] = [int(nxt()) for _ in range(int(nxt()))]
            tok = nxt()
        elif tok == "**domain":
            tok = nxt()
            while tok.startswith("*") and not tok.startswith("**") and tok != "***end":
                if tok == "*general":
                    t.domain["type"] = nxt()
                elif tok == "*vertex":
                    for _ in range(int(nxt())):
                        i = int(nxt())
                        xyz = tuple(float(nxt()) for _ in range(3))
                        label = nxt()
                        tv = [int(nxt()) for _ in range(int(nxt()))]
                        t.domain["vertices"][i] = dict(xyz=xyz, label=label, tess=tv)
                elif tok == "*edge":
                    for _ in range(int(nxt())):
                        i = int(nxt())
                        dv = [int(nxt()) for _ in range(int(nxt()))]
                        label = nxt()
                        te = [int(nxt()) for _ in range(int(nxt()))]
                        t.domain["edges"][i] = dict(verts=dv, label=label, tess=te)
                elif tok == "*face":
                    for _ in range(int(nxt())):
                        i = int(nxt())
                        dv = [int(nxt()) for _ in range(int(nxt()))]
                        de = [int(nxt()) for _ in range(int(nxt()))]
                        ftype = nxt()
                        params = [float(nxt()) for _ in range(int(nxt()))]
                        label = nxt()
                        tf = [int(nxt()) for _ in range(int(nxt()))]
                        t.domain["faces"][i] = dict(verts=dv, edges=de, type=ftype, params=params,
                                                    label=label, tess=tf)
                else:
                    raise ValueError("domain field %s not read by this reader" % tok)
                tok = nxt()
        else:
            raise ValueError("unexpected %r" % tok)
    return t


def _sub(p, q):
    return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def _cross(p, q):
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def _dot(p, q):
    return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]


def face_area_vector(t, f):
    """Half the sum of cross products around the loop: area times the unit normal of the
    loop's turning (right-hand rule)."""
    pts = [t.vertices[v] for v in t.faces[f]["verts"]]
    s = (0.0, 0.0, 0.0)
    for k in range(len(pts)):
        c = _cross(pts[k], pts[(k + 1) % len(pts)])
        s = (s[0] + c[0], s[1] + c[1], s[2] + c[2])
    return (0.5 * s[0], 0.5 * s[1], 0.5 * s[2])


def poly_volume(t, p):
    """Divergence theorem over the signed faces: sum of (centroid . area vector) / 3, with
    a face's area vector reversed where the polyhedron lists it negative."""
    vol = 0.0
    for sf in t.polys[p]:
        f = abs(sf)
        pts = [t.vertices[v] for v in t.faces[f]["verts"]]
        # fan triangulation: exact for a planar polygon
        for k in range(1, len(pts) - 1):
            vol += math.copysign(1, sf) * _dot(pts[0], _cross(pts[k], pts[k + 1])) / 6.0
    return vol


def check(t, box=None, rtol=1e-9):
    """The documented structure and a valid tessellation of the box (W, H, D); returns the
    failures (empty: all good)."""
    bad = []
    if t.format != "3.4" or t.dim != 3 or t.type != "standard":
        bad.append("header: format %s, dim %s, type %s" % (t.format, t.dim, t.type))
    for name, table in (("vertex", t.vertices), ("edge", t.edges), ("face", t.faces), ("polyhedron", t.polys)):
        if sorted(table) != list(range(1, len(table) + 1)):
            bad.append("%s ids are not 1..%d" % (name, len(table)))
    if len(t.polys) != t.ncells:
        bad.append("%d polyhedra for %d cells" % (len(t.polys), t.ncells))
    if t.seeds and sorted(t.seeds) != list(range(1, t.ncells + 1)):
        bad.append("seed ids")
    if box is None:
        xs = [v[0] for v in t.vertices.values()]
        ys = [v[1] for v in t.vertices.values()]
        zs = [v[2] for v in t.vertices.values()]
        box = (max(xs), max(ys), max(zs))
    scale = max(box)
    tol = rtol * scale
    for e, (a, b) in t.edges.items():
        if a not in t.vertices or b not in t.vertices or a == b:
            bad.append("edge %d joins %d and %d" % (e, a, b))
    # faces: edges along the loop with the documented signs, the plane equation
    edge_faces = {e: 0 for e in t.edges}
    for f, face in t.faces.items():
        vs, es = face["verts"], face["edges"]
        if len(vs) < 3 or len(vs) != len(es) or len(set(vs)) != len(vs):
            bad.append("face %d: %d vertices, %d edges" % (f, len(vs), len(es)))
            continue
        for k, se in enumerate(es):
            a, b = t.edges.get(abs(se), (None, None))
            want = (vs[k], vs[(k + 1) % len(vs)])
            if (a, b) != (want if se > 0 else want[::-1]):
                bad.append("face %d: edge %d is not %d -> %d" % (f, se, want[0], want[1]))
            edge_faces[abs(se)] = edge_faces.get(abs(se), 0) + 1
        d, a, b, c = face["eq"]
        n = (a, b, c)
        if abs(_dot(n, n) - 1.0) > 1e-9:
            bad.append("face %d: normal not unit" % f)
        for v in vs:
            if abs(_dot(n, t.vertices[v]) - d) > tol:
                bad.append("face %d: vertex %d off its plane by %g" % (f, v, _dot(n, t.vertices[v]) - d))
                break
        av = face_area_vector(t, f)
        if _dot(av, n) <= 0.0:
            bad.append("face %d: equation's normal against its vertex loop" % f)
    # polyhedra: faces shared by two with opposite signs, or on the domain
    listed = {}
    for p, fs in t.polys.items():
        for sf in fs:
            listed.setdefault(abs(sf), []).append((p, sf > 0))
    on_domain = {}
    for df in t.domain["faces"].values():
        for f in df["tess"]:
            on_domain[f] = on_domain.get(f, 0) + 1
    for f in t.faces:
        who = listed.get(f, [])
        if len(who) == 2:
            if who[0][1] == who[1][1] or who[0][0] == who[1][0] or f in on_domain:
                bad.append("face %d: listed by %r (same sign or also on the domain)" % (f, who))
        elif len(who) == 1:
            if on_domain.get(f) != 1 or not who[0][1]:
                bad.append("face %d: in one polyhedron only, not on the domain once, outward" % f)
        else:
            bad.append("face %d: listed by %d polyhedra" % (f, len(who)))
    on_domain_edge = set()
    for de in t.domain["edges"].values():
        on_domain_edge.update(de["tess"])
    boundary_edges = set()
    for f in on_domain:
        boundary_edges.update(abs(se) for se in t.faces[f]["edges"])
    for e, count in edge_faces.items():
        need = 2 if e in boundary_edges else 3
        if count < need:
            bad.append("edge %d in %d faces (at least %d)" % (e, count, need))
    # each polyhedron closed: Euler, every edge in two of its faces, positive volume
    total = 0.0
    t.volumes = {}
    for p, fs in t.polys.items():
        edges, verts = {}, set()
        for sf in fs:
            for se in t.faces[abs(sf)]["edges"]:
                edges[abs(se)] = edges.get(abs(se), 0) + 1
            verts.update(t.faces[abs(sf)]["verts"])
        if len(verts) - len(edges) + len(fs) != 2:
            bad.append("polyhedron %d: V - E + F = %d" % (p, len(verts) - len(edges) + len(fs)))
        if any(c != 2 for c in edges.values()):
            bad.append("polyhedron %d: not closed" % p)
        vol = poly_volume(t, p)
        t.volumes[p] = vol
        if vol <= 0.0:
            bad.append("polyhedron %d: volume %g (faces not outward)" % (p, vol))
        total += vol
    W, H, D = box
    if abs(total - W * H * D) > 1e-9 * W * H * D:
        bad.append("volumes sum to %.17g, the box is %.17g" % (total, W * H * D))
    # the domain: a cube's 8 corners, 12 edges, 6 faces where they should be
    dom = t.domain
    if dom.get("type") != "cube" or len(dom["vertices"]) != 8 or len(dom["edges"]) != 12 or len(dom["faces"]) != 6:
        bad.append("domain: %s with %d/%d/%d" % (dom.get("type"), len(dom["vertices"]), len(dom["edges"]),
                                                 len(dom["faces"])))
        return bad
    side = {"x": W, "y": H, "z": D}
    for dv in dom["vertices"].values():
        lab = dv["label"]
        want = tuple(side[lab[2 * k]] * int(lab[2 * k + 1]) for k in range(3))
        if math.dist(dv["xyz"], want) > tol or len(dv["tess"]) != 1 or \
                math.dist(t.vertices[dv["tess"][0]], want) > tol:
            bad.append("domain vertex %s at %r" % (lab, dv["xyz"]))
    def on_plane(p, lab):
        axis = "xyz".index(lab[0])
        return abs(p[axis] - side[lab[0]] * int(lab[1])) <= tol
    for de in dom["edges"].values():
        labs = (de["label"][:2], de["label"][2:])
        for e in de["tess"]:
            if not all(on_plane(t.vertices[v], lab) for v in t.edges[e] for lab in labs):
                bad.append("domain edge %s: tess edge %d is not on it" % (de["label"], e))
    area = {}
    for df in dom["faces"].values():
        lab = df["label"]
        d, a, b, c = df["params"]
        axis = "xyz".index(lab[0])
        want_n = [0.0, 0.0, 0.0]
        want_n[axis] = 1.0 if lab[1] == "0" else -1.0  # Neper's domain normals point inward
        if df["type"] != "plane" or [a, b, c] != want_n or abs(d - want_n[axis] * side[lab[0]] * int(lab[1])) > tol:
            bad.append("domain face %s: %s %r" % (lab, df["type"], df["params"]))
        total_area = 0.0
        for f in df["tess"]:
            if not all(on_plane(t.vertices[v], lab) for v in t.faces[f]["verts"]):
                bad.append("domain face %s: tess face %d is not on it" % (lab, f))
            total_area += math.sqrt(_dot(face_area_vector(t, f), face_area_vector(t, f)))
        others = [side[k] for k in "xyz" if k != lab[0]]
        if abs(total_area - others[0] * others[1]) > 1e-9 * others[0] * others[1]:
            bad.append("domain face %s: its faces cover %.17g of %.17g" % (lab, total_area, others[0] * others[1]))
    return bad


if __name__ == "__main__":
    tess = read(sys.argv[1])
    failures = check(tess)
    print("%d cells, %d vertices, %d edges, %d faces; volume %.17g" %
          (tess.ncells, len(tess.vertices), len(tess.edges), len(tess.faces), sum(tess.volumes.values())))
    for f in failures[:20]:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)
