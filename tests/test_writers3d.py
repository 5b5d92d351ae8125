"""test_writers3d.py - the 3D writers read back by other programs: on cuboid cells known
exactly (write_cuboids3d), the .tess by tess_reader.py (written from Neper's documentation),
the VTU by meshio and by VTK's XML reader (polyhedron volumes by vtkCellSizeFilter), the
JSON by Python's json, the section SVG by Python's XML parser (the cut of each cuboid and
sphere where it must be); then `grainpack run` on real 3D packings in every format, its
refusals, and examples/iron3d_section.svg made again from examples/iron3d.json (set
GP_REGENERATE=1 to write it). Usage: test_writers3d.py write_cuboids3d grainpack EXAMPLES"""
import json
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tess_reader  # noqa: E402

import meshio  # noqa: E402
import vtk  # noqa: E402
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

CUBOIDS, BIN, EXAMPLES = sys.argv[1], sys.argv[2], sys.argv[3]
SVG = "{http://www.w3.org/2000/svg}"
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what, file=sys.stderr)


def close(a, b, rtol=1e-12):
    return abs(a - b) <= rtol * max(1.0, abs(a), abs(b))


def cells(info, scale=1.0):
    """Each cell in the writer's order (x fastest, then y, then z): its 8 vertices (bit 0
    the x side, 1 the y side, 2 the z side), centre, volume and its section by z = at,
    shrunk about the centre by scale. The inner cuts across x are tilted along z."""
    xs, ys, zs, tilt = info["xs"], info["ys"], info["zs"], info["tilt"]
    D = zs[-1]

    def xcut(i, z):
        return xs[i] + (tilt * (z - D / 2) if 0 < i < len(xs) - 1 else 0.0)

    out = []
    for k in range(len(zs) - 1):
        for j in range(len(ys) - 1):
            for i in range(len(xs) - 1):
                zm = (zs[k] + zs[k + 1]) / 2
                m = ((xcut(i, zm) + xcut(i + 1, zm)) / 2, (ys[j] + ys[j + 1]) / 2, zm)
                verts = []
                for b in range(8):
                    z = zs[k + (b >> 2 & 1)]
                    v = (xcut(i + (b & 1), z), ys[j + (b >> 1 & 1)], z)
                    verts.append(tuple(c + scale * (a - c) for a, c in zip(v, m)))

                def section(at, i=i, j=j, k=k, m=m):
                    """(x range, y range) of the cut by z = at, or None."""
                    z = m[2] + (at - m[2]) / scale  # where the unshrunk cell is cut
                    if not zs[k] < z < zs[k + 1]:
                        return None
                    sx = [m[0] + scale * (xcut(i + d, z) - m[0]) for d in (0, 1)]
                    sy = [m[1] + scale * (ys[j + d] - m[1]) for d in (0, 1)]
                    return sx, sy
                vol = scale ** 3 * (xcut(i + 1, zm) - xcut(i, zm)) * (ys[j + 1] - ys[j]) * (zs[k + 1] - zs[k])
                out.append(dict(verts=verts, centre=m, volume=vol, section=section))
    return out


def vtk_read(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def vtk_volumes(grid):
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.ComputeVolumeOn()
    sizes.Update()
    return vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume"))


def svg_shapes(path):
    root = ET.parse(path).getroot()
    box = [float(v) for v in root.get("viewBox").split()]
    circles = [(float(c.get("cx")), float(c.get("cy")), float(c.get("r")), int(c.get("data-grain")))
               for c in root.iter(SVG + "circle")]
    polygons = [([tuple(float(x) for x in p.split(",")) for p in poly.get("points").split()],
                 int(poly.get("data-grain"))) for poly in root.iter(SVG + "polygon")]
    return root, box, circles, polygons


def polygon_area(pts):
    return 0.5 * sum(pts[k][0] * pts[(k + 1) % len(pts)][1] - pts[(k + 1) % len(pts)][0] * pts[k][1]
                     for k in range(len(pts)))


def check_circles(name, box, circles):
    """Inside the box's section, no two overlapping (relative 1e-9)."""
    W, H = box[2], box[3]
    for cx, cy, r, g in circles:
        check(r > 0 and cx - r >= -1e-9 * r and cy - r >= -1e-9 * r and cx + r <= W + 1e-9 * r
              and cy + r <= H + 1e-9 * r, "%s: circle of grain %d outside the section" % (name, g))
    for a in range(len(circles)):
        for b in range(a):
            p, q = circles[a], circles[b]
            check(math.dist(p[:2], q[:2]) >= (p[2] + q[2]) * (1 - 1e-9),
                  "%s: circles of grains %d and %d overlap" % (name, p[3], q[3]))


with tempfile.TemporaryDirectory() as tmp:
    p = subprocess.run([CUBOIDS, tmp], capture_output=True, text=True)
    check(p.returncode == 0, "write_cuboids3d: %s" % p.stderr)
    check("tess is the Laguerre tessellation" in p.stderr, "tess without cells not refused")
    info = json.load(open(os.path.join(tmp, "cuboids.json")))
    power, shrunk = cells(info), cells(info, info["ratio"])
    W, H, D = info["xs"][-1], info["ys"][-1], info["zs"][-1]

    # .tess: the documented structure, and each polyhedron the cuboid it must be
    t = tess_reader.read(os.path.join(tmp, "power.tess"))
    bad = tess_reader.check(t, (W, H, D))
    check(not bad, "power.tess: %s" % bad[:5])
    check(len(t.polys) == len(power) and len(t.vertices) == 4 * 3 * 4 and len(t.faces) == 75,
          "power.tess counts: %d polyhedra, %d vertices, %d faces (18, 48, 75 for 3 x 2 x 3 cuboids)"
          % (len(t.polys), len(t.vertices), len(t.faces)))
    for i, c in enumerate(power):
        check(close(t.volumes[i + 1], c["volume"], 1e-12), "tess polyhedron %d volume" % (i + 1))
        polyverts = {t.vertices[v] for sf in t.polys[i + 1] for v in t.faces[abs(sf)]["verts"]}
        check(len(polyverts) == 8 and all(min(math.dist(p, q) for q in c["verts"]) < 1e-12 for p in polyverts),
              "tess polyhedron %d is not its cell" % (i + 1))

    # VTU with polyhedra: meshio and VTK, volumes against the cuboids and the file's own
    for name, boxes in (("power", power), ("shrunk", shrunk)):
        path = os.path.join(tmp, name + ".vtu")
        m = meshio.read(path)
        blocks = [b for b in m.cells if b.type.startswith("polyhedron")]
        check(sum(len(b.data) for b in blocks) == len(boxes) and len(m.cells) == len(blocks),
              "%s.vtu: meshio reads %r" % (name, m.cells))
        vol = m.cell_data["volume"][0]
        for i, c in enumerate(boxes):
            check(close(vol[i], c["volume"]), "%s.vtu: volume data of %d" % (name, i))
        if blocks:  # the faces meshio read: each polyhedron's 6 quads on its cell's vertices
            for i, cell in enumerate(blocks[0].data):
                pts = {tuple(m.points[v]) for face in cell for v in face}
                check(len(cell) == 6 and all(len(face) == 4 for face in cell) and len(pts) == 8 and
                      all(min(math.dist(p, q) for q in boxes[i]["verts"]) < 1e-12 for p in pts),
                      "%s.vtu: meshio polyhedron %d" % (name, i))
        # VTK's documented layout: "faceoffsets" is where each cell's face stream ends
        root = ET.parse(path).getroot()
        arrays = {a.get("Name"): [int(x) for x in a.text.split()] for a in root.iter("DataArray")
                  if a.get("Name") in ("faces", "faceoffsets", "offsets", "connectivity")}
        pos, ends = 0, []
        for _ in boxes:
            nfaces = arrays["faces"][pos]
            pos += 1
            for _ in range(nfaces):
                pos += 1 + arrays["faces"][pos]
            ends.append(pos)
        check(pos == len(arrays["faces"]) and ends == arrays["faceoffsets"], "%s.vtu: faceoffsets" % name)
        grid = vtk_read(path)
        check(grid.GetNumberOfCells() == len(boxes) and all(grid.GetCellType(i) == 42 for i in range(len(boxes))),
              "%s.vtu: VTK reads %d cells" % (name, grid.GetNumberOfCells()))
        vv = vtk_volumes(grid)
        for i, c in enumerate(boxes):
            check(close(vv[i], c["volume"], 1e-9), "%s.vtu: VTK volume of %d: %g, want %g" % (name, i, vv[i], c["volume"]))
        if name == "shrunk":
            F = vtk_to_numpy(grid.GetCellData().GetArray("F"))
            check(all((F[i] == -1.0) if i % 2 == 0 else close(F[i], 0.01 * i) for i in range(len(boxes))),
                  "shrunk.vtu: F (-1 where undefined)")
    m = meshio.read(os.path.join(tmp, "spheres.vtu"))
    check(len(m.points) == len(power) and m.cells[0].type == "vertex", "spheres.vtu: %r" % m.cells)

    # JSON: volumes, neighbours symmetric and walls, F null where undefined
    for name, boxes in (("power", power), ("shrunk", shrunk)):
        doc = json.load(open(os.path.join(tmp, name + ".json")))
        check(doc["process"] == "pack3d" and doc["inputs"]["domain"] == {"width": 4, "height": 2.5, "depth": 3},
              "%s.json: head" % name)
        polys = doc["polyhedra"]
        check(len(polys) == len(boxes) and len(doc["spheres"]) == len(boxes), "%s.json: counts" % name)
        for i, p in enumerate(polys):
            check(close(p["volume"], boxes[i]["volume"]) and p["faces"] == 6 and
                  len(p["neighbours"]) + len(p["walls"]) == 6, "%s.json: polyhedron %d" % (name, i))
            for nb in p["neighbours"]:
                check(i in polys[nb]["neighbours"], "%s.json: %d -> %d not symmetric" % (name, i, nb))
        if name == "shrunk":
            check(all((s["F"] is None) == (s["id"] % 2 == 0) for s in doc["spheres"]), "shrunk.json: F")

    # section SVG: z = D / 2 cuts the middle layer of shrunk cells, through their slanted edges
    at = 0.5 * D
    root, box, circles, polygons = svg_shapes(os.path.join(tmp, "shrunk.svg"))
    check(box == [0, 0, W, H] and root.get("data-axis") == "z", "shrunk.svg: viewBox %r" % box)
    cut = [i for i, c in enumerate(shrunk) if c["section"](at)]
    check(len(cut) == 6 and sorted(g for _, g in polygons) == cut,
          "shrunk.svg: polygons of %r, want %r" % ([g for _, g in polygons], cut))
    for pts, g in polygons:
        sx, sy = shrunk[g]["section"](at)
        corners = [(sx[0], sy[0]), (sx[1], sy[0]), (sx[1], sy[1]), (sx[0], sy[1])]
        check(len(pts) == 4 and close(polygon_area(pts), (sx[1] - sx[0]) * (sy[1] - sy[0])) and
              all(min(math.dist(p, q) for q in corners) < 1e-12 for p in pts),
              "shrunk.svg: polygon of grain %d is not its cell's cut: %r, want %r" % (g, pts, corners))
    check(len(circles) > 0, "shrunk.svg: no circle")
    check_circles("shrunk.svg", box, circles)

    # grainpack run: a real packing in every format
    spec = {"domain": {"width": 6, "height": 5, "depth": 4},
            "distribution": {"kind": "uniform", "min": 0.2, "max": 0.5},
            "joint": {"law": "constant", "value": 0.05}, "seed": 3,
            "picture": {"section": {"axis": "x", "at": 0.4}}}
    path = os.path.join(tmp, "spec.json")
    json.dump(spec, open(path, "w"))
    out = {}
    for fmt in ("json", "csv", "vtu", "svg"):
        dst = os.path.join(tmp, "run." + fmt)
        p = subprocess.run([BIN, "run", path, "-f", fmt, "-o", dst], capture_output=True, text=True)
        check(p.returncode == 0, "run -f %s: %s" % (fmt, p.stderr))
        out[fmt] = dst
    doc = json.load(open(out["json"]))
    n = doc["statistics"]["count"]
    check(n == len(doc["spheres"]) and n > 100 and
          close(doc["statistics"]["packing_density"],
                sum(4 / 3 * math.pi * s["R"] ** 3 for s in doc["spheres"]) / 120, 1e-9),
          "run.json: %d spheres, density" % n)
    check(sum(b["count"] for b in doc["statistics"]["distribution"]["bins"]) == n, "run.json: bins")
    m = meshio.read(out["vtu"])
    check(len(m.points) == n and len(m.cells[0].data) == n, "run.vtu: %d points" % len(m.points))
    _, box, circles, _ = svg_shapes(out["svg"])
    check(box == [0, 0, 5, 4], "run.svg: the x section is y by z: %r" % box)
    want = [s for s in doc["spheres"] if abs(s["x"] - 2.4) < s["r"]]
    check(len(circles) == len(want) and len(want) > 5, "run.svg: %d circles, %d spheres cut" % (len(circles), len(want)))
    check_circles("run.svg", box, circles)
    by_id = {s["id"]: s for s in doc["spheres"]}
    for cx, cy, r, g in circles:  # x is cut, y right and z up: the circle of the grain radius
        s = by_id[g]
        check(close(cx, s["y"]) and close(cy, s["z"]) and close(r, math.sqrt(s["r"] ** 2 - (s["x"] - 2.4) ** 2), 1e-9),
              "run.svg: circle of grain %d" % g)

    # refusals: a format the result cannot give, an unknown one, bad sections (with pointers)
    def refused(args, status, text, stdin=None):
        p = subprocess.run([BIN] + args, capture_output=True, text=True, input=stdin)
        check(p.returncode == status and text in p.stderr, "%r: exit %d, %s" % (args, p.returncode, p.stderr.strip()))

    refused(["run", path, "-f", "tess"], 2, "the spec must ask for cells")
    refused(["run", path, "-f", "msh"], 2, "unknown format 'msh' for pack3d")
    for section, pointer in (({"axis": "w"}, "/picture/section/axis"), ({"at": 1.5}, "/picture/section/at"),
                             ({"at": "half"}, "/picture/section/at"), ({"plane": 1}, "/picture/section/plane"),
                             ("z", "/picture/section")):
        bad = dict(spec, picture={"section": section})
        refused(["run", "-"], 3, pointer, json.dumps(bad))
    refused(["run", "-"], 3, "/picture/tile", json.dumps(dict(spec, picture={"tile": 2})))

# the example: iron3d.json's section, made again byte for byte
example = os.path.join(EXAMPLES, "iron3d.json")
picture = os.path.join(EXAMPLES, "iron3d_section.svg")
p = subprocess.run([BIN, "run", example, "-f", "svg"], capture_output=True)
check(p.returncode == 0, "iron3d: %s" % p.stderr)
if os.environ.get("GP_REGENERATE"):
    open(picture, "wb").write(p.stdout)
check(open(picture, "rb").read() == p.stdout, "examples/iron3d_section.svg is not what iron3d.json makes "
      "(GP_REGENERATE=1 writes it)")

if failures:
    print("%d failures" % len(failures), file=sys.stderr)
    sys.exit(1)
print("ok")
