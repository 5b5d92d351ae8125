#!/usr/bin/env python3
"""test_mesh_readers.py - every mesh format read back by the field's own tools, and the
counts and groups they find equal to what grainpack's statistics report (periodic meshes:
the $Periodic section read by Gmsh and meshio, the Abaqus side sets paired in order):
Gmsh itself (python3-gmsh: opens the .msh, lists its physical groups, counts its
elements, and runs its own quality check, whose inverse condition numbers must be
those of the statistics), meshio (python3-meshio: .msh, .inp and .vtu) and VTK's XML
reader (python3-vtk9: the reader ParaView uses) for .vtu, with and without a mesh.
Also: the same spec gives the same bytes, msh/inp refused without a mesh, and
examples/iron_mesh.msh is what the current build makes and Gmsh opens it.
Usage: test_mesh_readers.py GRAINPACK EXAMPLES_DIR"""

import json
import os
import subprocess
import sys
import tempfile

import gmsh
import meshio
import meshio.abaqus._abaqus as meshio_abaqus
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

GRAINPACK, EXAMPLES = sys.argv[1], sys.argv[2]
failures = []
checks = [0]

# meshio 5's Abaqus table knows CPS3, CPS4(R) and CPE6 of the plane families only; the
# others grainpack writes are Abaqus's own names for the same shapes (Abaqus Analysis
# User's Guide, "Two-dimensional solid element library").
for name, shape in {"CPS6": "triangle6", "CPS8": "quad8", "CPS8R": "quad8", "CPE3": "triangle",
                    "CPE4": "quad", "CPE4R": "quad", "CPE8": "quad8", "CPE8R": "quad8"}.items():
    meshio_abaqus.abaqus_to_meshio_type.setdefault(name, shape)


def check(cond, what):
    checks[0] += 1
    if not cond:
        failures.append(what)
        print("FAIL:", what, file=sys.stderr)


IRON_LAW = {"kind": "histogram", "bins": [
    {"min": 2.0, "max": 3.0, "p": 0.37}, {"min": 3.0, "max": 4.0, "p": 0.38},
    {"min": 4.0, "max": 6.0, "p": 0.23}, {"min": 6.0, "max": 8.0, "p": 0.02}]}


def spec(**extra):
    s = {"domain": {"width": 50, "height": 40}, "distribution": IRON_LAW,
         "joint": {"law": "inverse", "k": 2.0}, "seed": 3}
    s.update(extra)
    return s


def grainpack(tmp, name, s, fmt):
    path = os.path.join(tmp, name + ".json")
    with open(path, "w") as f:
        json.dump({"inputs": s}, f)
    out = os.path.join(tmp, f"{name}.{fmt}")
    subprocess.run([GRAINPACK, "run", path, "-f", fmt, "-o", out], check=True)
    return out


def mesh_stats(tmp, name, s):
    with open(grainpack(tmp, name, s, "json")) as f:
        return json.load(f)["statistics"]["mesh"]


def gmsh_check(path, st, order, grains_with_elements, second):
    """Gmsh opens the file: groups, counts, its own quality measure."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(path)
        names = {gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups()}
        expected = {f"grain_{g}" for g in grains_with_elements} | {"left", "right", "bottom", "top"}
        if second:
            expected.add(second)
        check(names == expected, f"{path}: Gmsh's physical groups differ: {sorted(names ^ expected)[:5]}")
        types, tags, _ = gmsh.model.mesh.getElements(2)
        count = {int(t): len(g) for t, g in zip(types, tags)}
        tri, quad = (9, 16) if order == 2 else (2, 3)
        check(count.get(tri, 0) == st["elements"]["triangles"], f"{path}: Gmsh counts {count.get(tri, 0)} triangles")
        check(count.get(quad, 0) == st["elements"]["quadrilaterals"], f"{path}: Gmsh counts {count.get(quad, 0)} quads")
        types1, tags1, _ = gmsh.model.mesh.getElements(1)
        check(sum(len(t) for t in tags1) == st["boundary_edges"], f"{path}: Gmsh counts other boundary edges")
        nodes, _, _ = gmsh.model.mesh.getNodes()
        check(len(nodes) == st["nodes"], f"{path}: Gmsh reads {len(nodes)} nodes")
        # Gmsh's own quality check: the inverse condition number of every element. For a
        # straight triangle it is 4 sqrt(3) area / sum of squared edges, the statistics'
        # measure; so the minimum over triangles is the same number.
        gmsh.plugin.setNumber("AnalyseMeshQuality", "ICNMeasure", 1)
        gmsh.plugin.setNumber("AnalyseMeshQuality", "CreateView", 1)
        gmsh.plugin.setNumber("AnalyseMeshQuality", "DimensionOfElements", 2)
        gmsh.plugin.run("AnalyseMeshQuality")
        view = gmsh.view.getTags()[-1]
        _, etags, data, _, _ = gmsh.view.getModelData(view, 0)
        icn = dict(zip(etags, (d[0] for d in data)))
        check(len(icn) == st["elements"]["total"], f"{path}: Gmsh's quality check saw {len(icn)} elements")
        tri_tags = set(tags[list(types).index(tri)]) if tri in count else set()
        tri_icn = [v for t, v in icn.items() if t in tri_tags]
        check(min(icn.values()) > 0, f"{path}: Gmsh finds an invalid element (ICN {min(icn.values())})")
        if tri_icn and st["elements"]["quadrilaterals"] == 0:
            check(abs(min(tri_icn) - st["quality"]["min"]) < 1e-6,
                  f"{path}: Gmsh's smallest ICN {min(tri_icn)} is not the statistics' {st['quality']['min']}")
    finally:
        gmsh.finalize()


def meshio_check(tmp, name, st, order, plane_strain=False):
    tri, quad = ("triangle6", "quad8") if order == 2 else ("triangle", "quad")
    nodes, ntri, nquad = st["nodes"], st["elements"]["triangles"], st["elements"]["quadrilaterals"]
    for fmt in ("msh", "inp", "vtu"):
        m = meshio.read(os.path.join(tmp, f"{name}.{fmt}"))
        got_tri = sum(len(c.data) for c in m.cells if c.type == tri)
        got_quad = sum(len(c.data) for c in m.cells if c.type == quad)
        check(len(m.points) == nodes, f"{name}.{fmt}: meshio reads {len(m.points)} nodes, not {nodes}")
        check((got_tri, got_quad) == (ntri, nquad), f"{name}.{fmt}: meshio reads {got_tri} {tri}, {got_quad} {quad}")
        if fmt == "inp":
            sides = {k.lower() for k in m.point_sets}
            check(sides == {"left", "right", "bottom", "top"}, f"{name}.inp: node sets {sides}")
            with open(os.path.join(tmp, f"{name}.inp")) as f:
                types = {line.split("=")[1].strip() for line in f if line.startswith("*Element")}
            want = "CPE" if plane_strain else "CPS"
            check(all(t.startswith(want) for t in types), f"{name}.inp: element types {types}")
        if fmt == "vtu":
            for array in ("region", "phase", "grain_radius", "quality"):
                check(array in m.cell_data, f"{name}.vtu: meshio finds no cell array {array}")
            quality = np.concatenate(m.cell_data["quality"])
            check(abs(quality.mean() - st["quality"]["mean"]) < 1e-9, f"{name}.vtu: quality mean differs")


def periodic_check(tmp, name, s, st):
    """A periodic mesh: Gmsh reads the $Periodic section (right a copy of left, top of
    bottom, by the translation of one period) and its node pairs are every node of the
    sides, translates of each other; the Abaqus node sets of opposite sides pair up in
    order (k-th with k-th), meshio reading the same members."""
    W, H = s["domain"]["width"], s["domain"]["height"]
    per = s["domain"]["periodic"]
    axes = ["x", "y"] if per is True else per
    check(st["periodic"]["axes"] == axes, f"{name}: statistics say periodic {st['periodic']['axes']}")
    path = os.path.join(tmp, name + ".msh")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(path)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        xy = dict(zip((int(t) for t in tags), coords.reshape(-1, 3)[:, :2]))
        # curves: left 1, right 2, bottom 3, top 4
        for axis, (copy, master, shift) in (("x", (2, 1, (W, 0))), ("y", (4, 3, (0, H)))):
            if axis not in axes:
                continue
            tag_master, nodes, masters, affine = gmsh.model.mesh.getPeriodicNodes(1, copy)
            check(tag_master == master, f"{name}: Gmsh says curve {copy} copies {tag_master}")
            want = [1, 0, 0, shift[0], 0, 1, 0, shift[1], 0, 0, 1, 0, 0, 0, 0, 1]
            check(list(affine) == want, f"{name}: Gmsh reads the affine map {list(affine)}")
            k = 0 if axis == "x" else 1
            period = W if axis == "x" else H
            low = {t for t, p in xy.items() if p[k] == 0.0}
            high = {t for t, p in xy.items() if p[k] == period}
            check(len(nodes) == st["periodic"]["node_pairs"][axis] == len(low) == len(high),
                  f"{name}: {len(nodes)} pairs along {axis} for {len(low)} and {len(high)} side nodes")
            check(set(int(t) for t in nodes) == high and set(int(t) for t in masters) == low,
                  f"{name}: Gmsh's pairs along {axis} are not the sides' nodes")
            bad = [(a, b) for a, b in zip(nodes, masters) if xy[int(a)][1 - k] != xy[int(b)][1 - k]]
            check(not bad, f"{name}: {len(bad)} pairs along {axis} are not translates, e.g. {bad[:2]}")
    finally:
        gmsh.finalize()
    # meshio reads the same links
    links = meshio.read(path).gmsh_periodic or []
    check(sorted(tuple(int(t) for t in link[1]) for link in links) ==
          sorted({"x": (2, 1), "y": (4, 3)}[a] for a in axes), f"{name}.msh: meshio reads the links {links}")
    check(all(len(link[3]) == st["periodic"]["node_pairs"]["x" if link[1][0] == 2 else "y"] for link in links),
          f"{name}.msh: meshio reads other node pairs")
    # Abaqus: the sets in the file's order
    sets, current = {}, None
    with open(os.path.join(tmp, name + ".inp")) as f:
        for line in f:
            if line.startswith("*"):
                current = None
                if line.lower().startswith("*nset"):
                    current = line.split("nset=")[1].split(",")[0].strip()
                    sets[current] = []
            elif current:
                sets[current] += [int(v) for v in line.replace(",", " ").split()]
    m = meshio.read(os.path.join(tmp, name + ".inp"))
    for axis, (lo, hi) in (("x", ("left", "right")), ("y", ("bottom", "top"))):
        if axis not in axes:
            continue
        k = 0 if axis == "x" else 1
        a, b = m.points[np.array(sets[lo]) - 1], m.points[np.array(sets[hi]) - 1]
        check(len(a) == len(b) == st["periodic"]["node_pairs"][axis], f"{name}.inp: {lo} {len(a)}, {hi} {len(b)}")
        check(np.all(a[:, 1 - k] == b[:, 1 - k]) and np.all(a[:, k] == 0.0) and
              np.all(b[:, k] == (W if axis == "x" else H)), f"{name}.inp: {lo} and {hi} do not pair in order")
        check(np.all(np.diff(a[:, 1 - k]) > 0), f"{name}.inp: {lo} is not in order along the side")
        for side in (lo, hi):
            got = {int(i) + 1 for i in m.point_sets[side]}
            check(got == set(sets[side]), f"{name}.inp: meshio reads other members of {side}")


def vtk_read(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    check(reader.GetErrorCode() == 0, f"{path}: VTK's reader reports error {reader.GetErrorCode()}")
    return reader.GetOutput()


def vtk_check(path, st):
    grid = vtk_read(path)
    check(grid.GetNumberOfPoints() == st["nodes"], f"{path}: VTK reads {grid.GetNumberOfPoints()} points")
    check(grid.GetNumberOfCells() == st["elements"]["total"], f"{path}: VTK reads {grid.GetNumberOfCells()} cells")
    cd = grid.GetCellData()
    names = {cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays())}
    check(names == {"region", "phase", "grain_radius", "quality"}, f"{path}: VTK reads arrays {names}")
    # the areas VTK computes for its own cells add up to the domain
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.Update()
    area = vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Area")).sum()
    check(abs(area - st["areas"]["domain"]) < 1e-9 * st["areas"]["domain"], f"{path}: VTK's areas sum to {area}")


def main():
    with tempfile.TemporaryDirectory() as tmp:
        cases = [
            ("band", spec(laguerre={"shrink": "offset"}, mesh={}), 1, "grain_boundary", False),
            ("layers", spec(laguerre={"shrink": "offset"},
                            mesh={"band_layers": 2, "order": 2, "abaqus": {"plane": "strain"}}), 2,
             "grain_boundary", True),
            ("cells", spec(laguerre={"shrink": "none"}, mesh={"order": 2}), 2, None, False),
            ("matrix", spec(mesh={}), 1, "matrix", False),
            # periodic: a period of 12 largest packing radii at least
            ("torus", spec(domain={"width": 100, "height": 100, "periodic": True},
                           laguerre={"shrink": "offset"}, mesh={"element_size": 4}), 1, "grain_boundary", False),
            ("strip", spec(domain={"width": 100, "height": 60, "periodic": ["x"]},
                           laguerre={"shrink": "none"}, mesh={"element_size": 4, "order": 2}), 2, None, False),
            ("torus_matrix", spec(domain={"width": 100, "height": 100, "periodic": True},
                                  mesh={"element_size": 4}), 1, "matrix", False),
        ]
        for name, s, order, second, strain in cases:
            st = mesh_stats(tmp, name, s)
            for fmt in ("msh", "inp", "vtu"):
                grainpack(tmp, name, s, fmt)
            vtu = meshio.read(os.path.join(tmp, name + ".vtu"))
            regions = np.concatenate(vtu.cell_data["region"])
            grains = sorted({int(r) for r in regions if r < regions.max() or second is None})
            gmsh_check(os.path.join(tmp, name + ".msh"), st, order, grains, second)
            meshio_check(tmp, name, st, order, strain)
            vtk_check(os.path.join(tmp, name + ".vtu"), st)
            if "periodic" in s["domain"]:
                periodic_check(tmp, name, s, st)
            if name == "layers":
                check(st["elements"]["quadrilaterals"] > 0, "band_layers made no quadrilaterals")
                again = grainpack(tmp, name + "_again", s, "msh")
                check(open(again, "rb").read() == open(os.path.join(tmp, name + ".msh"), "rb").read(),
                      "the same spec gave a different .msh")

        # without a mesh: .vtu of the grains (polygons with cells, vertices without)
        for name, s, kind in (("cells_only", spec(laguerre={"shrink": "offset"}), "polygon"),
                              ("disks_only", spec(), "vertex")):
            path = grainpack(tmp, name, s, "vtu")
            count = len(open(grainpack(tmp, name, s, "csv")).read().splitlines()) - 1
            m = meshio.read(path)
            got = sum(len(c.data) for c in m.cells if c.type.startswith(kind))
            check(got == count, f"{name}.vtu: meshio reads {got} {kind} cells for {count} grains")
            data = m.cell_data if kind == "polygon" else m.point_data
            for array in ("grain_id", "radius", "packing_radius") + (("area", "neighbours") if kind == "polygon" else ()):
                check(array in data, f"{name}.vtu: meshio finds no array {array}")
            grid = vtk_read(path)
            check(grid.GetNumberOfCells() == count, f"{name}.vtu: VTK reads {grid.GetNumberOfCells()} cells")
            arrays = grid.GetCellData() if kind == "polygon" else grid.GetPointData()
            check(arrays.GetArray("radius") is not None and arrays.GetArray("radius").GetNumberOfTuples() == count,
                  f"{name}.vtu: VTK reads no radius per grain")
            radii = vtk_to_numpy(arrays.GetArray("radius"))
            check(2.0 <= radii.min() and radii.max() <= 8.0, f"{name}.vtu: radii outside the law")
            # msh and inp need a mesh
            with open(os.path.join(tmp, name + ".json"), "w") as f:
                json.dump({"inputs": s}, f)
            r = subprocess.run([GRAINPACK, "run", os.path.join(tmp, name + ".json"), "-f", "msh"],
                               capture_output=True, text=True)
            check(r.returncode == 2 and "needs a mesh" in r.stderr, f"msh without a mesh: {r.returncode} {r.stderr}")

        # the example: what the current build makes, and Gmsh opens it
        example = os.path.join(EXAMPLES, "iron_mesh.msh")
        made = grainpack(tmp, "iron_mesh", json.load(open(os.path.join(EXAMPLES, "iron_mesh.json")))["inputs"], "msh")
        check(open(made, "rb").read() == open(example, "rb").read(), "examples/iron_mesh.msh is not what the build makes")
        st = mesh_stats(tmp, "iron_mesh", json.load(open(os.path.join(EXAMPLES, "iron_mesh.json")))["inputs"])
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(example)
        types, tags, _ = gmsh.model.mesh.getElements(2)
        check(sum(len(t) for t in tags) == st["elements"]["total"], "Gmsh counts other elements in the example")
        check(len(gmsh.model.getPhysicalGroups(2)) > 900, "the example has too few grains")
        gmsh.finalize()

        # the periodic RVE example (balanced, offset cells, meshed on the torus): what the
        # current build makes, and Gmsh, meshio and the Abaqus sets read its periodicity
        rve = json.load(open(os.path.join(EXAMPLES, "iron_periodic.json")))["inputs"]
        for fmt in ("msh", "inp", "vtu"):
            grainpack(tmp, "iron_periodic", rve, fmt)
        check(open(os.path.join(tmp, "iron_periodic.msh"), "rb").read() ==
              open(os.path.join(EXAMPLES, "iron_periodic.msh"), "rb").read(),
              "examples/iron_periodic.msh is not what the build makes")
        st = mesh_stats(tmp, "iron_periodic", rve)
        check(st["periodic"]["node_pairs"]["x"] > 0 and st["periodic"]["node_pairs"]["y"] > 0,
              f"the RVE has no node pairs: {st['periodic']}")
        periodic_check(tmp, "iron_periodic", rve, st)
        regions = np.concatenate(meshio.read(os.path.join(tmp, "iron_periodic.vtu")).cell_data["region"])
        grains = sorted({int(r) for r in regions if r < regions.max()})
        check(len(grains) > 900, f"the RVE meshes {len(grains)} grains")
        gmsh_check(os.path.join(EXAMPLES, "iron_periodic.msh"), st, 1, grains, "grain_boundary")

    print(f"{checks[0] - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
