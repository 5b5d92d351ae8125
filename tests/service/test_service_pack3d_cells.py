#!/usr/bin/env python3
"""test_service_pack3d_cells.py - a pack3d job that balances and makes offset Laguerre
polyhedra, through the real daemon: its downloads in every format (json, csv, vtu, tess,
svg) are byte for byte what `grainpack run -f X` writes for the same spec, and each is
read back by the field's own tools: the VTU by meshio (its polyhedra's volumes by the
divergence theorem against the cells' statistics) and VTK's XML reader, the .tess by
tests/tess_reader.py (Neper's documented format: a valid tessellation of the box, one
polyhedron per sphere, volumes summing to the box), the SVG by Python's XML parser, the
JSON by Python's json. /statistics holds the balancing (F_max not risen) and the cells'
statistics, consistent with the JSON download's; gzip and If-None-Match work on the new
formats; a job that only packed refuses f=tess with 400; bad balance and shrink blocks
are 422 with their JSON pointers. Responses are checked against openapi.yaml.
Usage: test_service_pack3d_cells.py GRAINPACKD GRAINPACK"""

import gzip
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import gpd

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import tess_reader  # noqa: E402

INVALID = "urn:grainpack:problem:invalid-spec"
BAD_PARAMETER = "urn:grainpack:problem:bad-parameter"
SVG = "{http://www.w3.org/2000/svg}"
BOX = {"width": 8, "height": 7, "depth": 6}
VOLUME = BOX["width"] * BOX["height"] * BOX["depth"]


def spec3d(**inputs):
    base = {"domain": dict(BOX), "distribution": {"kind": "uniform", "min": 0.4, "max": 0.8},
            "joint": {"law": "constant", "value": 0.05}, "seed": 3,
            "balance": {"method": "relocation"}, "laguerre": {"shrink": "offset"},
            "picture": {"section": {"axis": "y", "at": 0.4}}}
    base.update(inputs)
    return {"inputs": base}


def check_refusals(c, api, client):
    for what, spec, pointer in (
            ("an unknown balance method", spec3d(balance={"method": "shake"}), "/inputs/balance/method"),
            ("an unknown shrink", spec3d(laguerre={"shrink": "melt"}), "/inputs/laguerre/shrink")):
        r = client.post_json("/processes/pack3d/execution", spec)
        if gpd.check_problem(c, r, 422, INVALID, "", what):
            c.check(r.json().get("pointer") == pointer, f"{what}: pointer {r.json().get('pointer')}")
        api.check(c, "POST", "/processes/{processId}/execution", r)


def meshio_volumes(path):
    """{grain: (volume by the divergence theorem, the cell data's volume)} as meshio reads
    the polyhedra (see tests/test_writers3d.py for meshio 5.0's blocks)."""
    from meshio.vtu._vtu import VtuReader
    r = VtuReader(path)
    sizes = sorted(int(b.type[len("polyhedron"):]) for b in r.cells)
    out = {}
    for block in r.cells:
        group = sizes.index(int(block.type[len("polyhedron"):]))
        for k, cell in enumerate(block.data):
            vol = 0.0
            for face in cell:
                pts = [r.points[v] for v in face]
                for m in range(1, len(pts) - 1):
                    a, b, d = pts[0], pts[m], pts[m + 1]
                    vol += (a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) +
                            a[2] * (b[0] * d[1] - b[1] * d[0])) / 6.0
            grain = int(r.cell_data["grain"][group][k])
            out[grain] = (vol, float(r.cell_data["volume"][group][k]))
    return out


def vtk_cells(path):
    import vtk
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    return grid.GetNumberOfCells(), grid.GetCellType(0) if grid.GetNumberOfCells() else None


def check_downloads(c, api, client, cli, job, st, tmp):
    n = st["count"]
    bodies = {}
    for fmt in ("json", "csv", "vtu", "tess", "svg"):
        r = client.get(f"/jobs/{job}/results?f={fmt}")
        api.check(c, "GET", "/jobs/{jobId}/results", r, body_schema=fmt == "json")
        c.check(r.status == 200, f"f={fmt}: {r}")
        bodies[fmt] = r.body
        with open(os.path.join(tmp, f"job.{fmt}"), "wb") as f:
            f.write(r.body)
    spec_path = os.path.join(tmp, "spec.json")
    with open(spec_path, "w") as f:
        json.dump(spec3d(), f)
    for fmt, body in bodies.items():
        made = subprocess.run([cli, "run", spec_path, "-f", fmt], capture_output=True, check=True).stdout
        c.check(body == made, f"{fmt}: the download ({len(body)} bytes) is not what grainpack run "
                              f"writes ({len(made)} bytes)")

    doc = json.loads(bodies["json"])
    # the inputs a result carries are the whole job: run again, they give the same document
    c.check(doc["inputs"]["balance"]["method"] == "relocation" and doc["inputs"]["laguerre"]["shrink"] == "offset",
            f"json: the result's inputs lost a stage: {sorted(doc['inputs'])}")
    again_path = os.path.join(tmp, "again.json")
    with open(again_path, "w") as f:
        json.dump({"inputs": doc["inputs"]}, f)
    again = subprocess.run([cli, "run", again_path, "-f", "json"], capture_output=True, check=True).stdout
    c.check(again == bodies["json"], "json: the result's own inputs do not run to the same result")
    c.check(len(doc["spheres"]) == n and len(doc["polyhedra"]) == n and
            all("F" in s for s in doc["spheres"]), "json: spheres, F, polyhedra")
    stats = {k: v for k, v in st.items() if k not in ("jobID", "timings", "total_seconds", "balance", "cells")}
    c.check(doc["statistics"] == stats and doc["balance"] == st["balance"] and doc["cells"] == st["cells"],
            "the JSON download's statistics, balance or cells differ from /statistics")

    vols = meshio_volumes(os.path.join(tmp, "job.vtu"))
    c.check(sorted(vols) == list(range(n)), f"vtu: {len(vols)} polyhedra for {n} spheres")
    c.check(all(abs(a - b) <= 1e-9 * max(1.0, abs(b)) for a, b in vols.values()),
            "vtu: a polyhedron's volume is not its cell data's")
    shrunk = sum(b for _, b in vols.values())
    c.check(abs(shrunk / VOLUME - (1 - st["cells"]["boundary_fraction"])) < 1e-9,
            f"vtu: cells fill {shrunk / VOLUME}, the statistics say {1 - st['cells']['boundary_fraction']}")
    ncells, kind = vtk_cells(os.path.join(tmp, "job.vtu"))
    c.check(ncells == n and kind == 42, f"VTK reads {ncells} cells of type {kind} (42: polyhedron)")

    t = tess_reader.read(os.path.join(tmp, "job.tess"))
    bad = tess_reader.check(t, (BOX["width"], BOX["height"], BOX["depth"]))
    c.check(not bad and t.ncells == n, f"tess: {t.ncells} cells for {n}; {bad[:3]}")
    total = sum(tess_reader.poly_volume(t, p) for p in t.polys)
    c.check(abs(total - VOLUME) <= 1e-12 * VOLUME * 10, f"tess: volumes sum to {total}, box {VOLUME}")

    root = ET.fromstring(bodies["svg"])
    circles = list(root.iter(SVG + "circle"))
    polygons = list(root.iter(SVG + "polygon"))
    c.check(root.tag == SVG + "svg" and circles and polygons and
            all(0 <= int(e.get("data-grain")) < n for e in circles + polygons),
            f"svg: {len(circles)} circles, {len(polygons)} polygons")

    for fmt in ("vtu", "tess", "svg"):
        z = client.get(f"/jobs/{job}/results?f={fmt}", headers={"Accept-Encoding": "gzip"})
        c.check(z.headers.get("content-encoding") == "gzip" and gzip.decompress(z.body) == bodies[fmt],
                f"the gzip {fmt} is not the plain one")
        again = client.get(f"/jobs/{job}/results?f={fmt}",
                           headers={"Accept-Encoding": "gzip", "If-None-Match": z.headers.get("etag")})
        c.check(again.status == 304, f"If-None-Match of the gzip {fmt}: {again.status}")


def check_statistics(c, api, client, job):
    r = client.get(f"/jobs/{job}/statistics")
    api.check(c, "GET", "/jobs/{jobId}/statistics", r)
    st = r.json()
    b, cells = st.get("balance"), st.get("cells")
    if not c.check(b and cells, f"statistics without balance or cells: {sorted(st)}"):
        return st
    c.check(b["after"]["max"] <= b["before"]["max"] and b["sweeps"] >= 1 and b["method"] == "relocation",
            f"balance: {b}")
    n = st["count"]
    c.check(cells["count"] == n and cells["shrink"] == "offset", f"cells: {cells['count']} for {n} spheres")
    c.check(abs(cells["tiling_error"]) < 1e-12, f"power cells sum to the box within {cells['tiling_error']}")
    c.check(0 < cells["boundary_fraction"] < 1, f"boundary fraction {cells['boundary_fraction']}")
    c.check([t["stage"] for t in st["timings"]] == ["pack", "triangulation", "balance", "laguerre", "stats",
                                                   "tess"], f"timings: {st['timings']}")
    return st


def result_links(info):
    """The formats a job's status links its results in."""
    rel = "http://www.opengis.net/def/rel/ogc/1.0/results"
    return {lk["href"].split("f=")[1] for lk in info["links"] if lk["rel"] == rel and "f=" in lk["href"]}


def test(c, binary, cli):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--workers", "1")
    try:
        daemon.start()
        client = daemon.client()
        check_refusals(c, api, client)
        r = client.post_json("/processes/pack3d/validation", spec3d())
        echoed = r.json().get("inputs", {}) if r.status == 200 else {}
        c.check(echoed.get("balance", {}).get("method") == "relocation" and
                echoed.get("laguerre", {}).get("shrink") == "offset",
                f"validation: the normalised inputs lost a stage: {r.status} {sorted(echoed)}")
        r = client.submit(spec3d(), "pack3d")
        c.check(r.status == 201, f"submission: {r}")
        job = r.json()["jobID"]
        info = client.wait_final(job)
        if c.check(info["status"] == "successful", f"the pack3d job: {info}"):
            links = result_links(client.get(f"/jobs/{job}").json())
            c.check(links == {"csv", "svg", "vtu", "tess"}, f"status links of the cells job {sorted(links)}")
            st = check_statistics(c, api, client, job)
            with tempfile.TemporaryDirectory() as tmp:
                check_downloads(c, api, client, cli, job, st, tmp)
        # a job that only packed has no tessellation
        plain_spec = {"inputs": {k: v for k, v in spec3d()["inputs"].items() if k not in ("balance", "laguerre")}}
        plain = client.submit(plain_spec, "pack3d").json()["jobID"]
        if c.check(client.wait_final(plain)["status"] == "successful", "the packing-only job"):
            links = result_links(client.get(f"/jobs/{plain}").json())
            c.check(links == {"csv", "svg", "vtu"}, f"status links of the packing-only job {sorted(links)}")
            r = client.get(f"/jobs/{plain}/results?f=tess")
            gpd.check_problem(c, r, 400, BAD_PARAMETER, "laguerre", "tess of a job without cells")
            r = client.get(f"/jobs/{plain}/results?f=vtu")
            c.check(r.status == 200 and b"<UnstructuredGrid" in r.body, f"vtu of the spheres: {r}")
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        gpd.check_store(c, daemon, "after the pack3d cell jobs")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
