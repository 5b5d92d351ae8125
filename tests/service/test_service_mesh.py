#!/usr/bin/env python3
"""test_service_mesh.py - the mesh stage through the service: a spec with "mesh" is
checked (validation writes the mesh options out, a fixed point; bad options and a mesh
larger than --max-elements are 422 with the field's pointer, before anything is stored),
runs in a worker, and its results download as msh, inp and vtu: byte for byte what
`grainpack run` writes for the same spec, read back by meshio with the counts of the
job's statistics, and listed as links only for a job that has a mesh (msh and inp of a
job without one are 400; its vtu is the grains, which meshio reads). The downloads
(msh, inp, vtu plain and gzip, svg, json, statistics) render the stored sections: the
daemon's grainpack_pipeline_runs_total does not move. Responses are checked against
openapi.yaml.
A periodic spec with a mesh is accepted and its .msh carries the $Periodic section.
The mesh formats are rendered from windows on the stored mesh: a walled mesh of triangles
only and the periodic one download msh, inp and vtu (plain and gzip) byte for byte as the
command line writes them, the .msh opened by Gmsh itself; a result stored before the
elements' qualities were (the section deleted from the store) still downloads its vtu.
Usage: test_service_mesh.py GRAINPACKD GRAINPACK"""

import gzip
import json
import os
import sqlite3
import subprocess
import tempfile

import gmsh
import meshio
import numpy as np

import gpd

RESULTS_REL = "http://www.opengis.net/def/rel/ogc/1.0/results"
# A cap low enough that a small spec can exceed it, high enough for the job below
# (about 3,000 elements).
MAX_ELEMENTS = 50000
IRON_LAW = {"kind": "histogram", "bins": [
    {"min": 2.0, "max": 3.0, "p": 0.37}, {"min": 3.0, "max": 4.0, "p": 0.38},
    {"min": 4.0, "max": 6.0, "p": 0.23}, {"min": 6.0, "max": 8.0, "p": 0.02}]}
MEDIA = {"msh": "text/x-gmsh", "inp": "text/x-abaqus-input", "vtu": "application/x-vtu+xml"}


def mesh_spec(**mesh):
    return {"inputs": {"domain": {"width": 40, "height": 30}, "distribution": IRON_LAW,
                       "joint": {"law": "inverse", "k": 2.0}, "seed": 5,
                       "laguerre": {"shrink": "offset"}, "mesh": mesh}}


def periodic_spec(**mesh):
    """A torus of a period of 12 largest packing radii at least (iron: 8.25)."""
    spec = mesh_spec(**mesh)
    spec["inputs"]["domain"] = {"width": 100, "height": 100, "periodic": True}
    return spec


def same_as_cli(c, client, cli, tmp, job, spec, label, formats=("msh", "inp", "vtu")):
    """Each format's download, plain and gzip, is the command line's bytes for the spec;
    returns the downloads."""
    path = os.path.join(tmp, label + ".json")
    with open(path, "w") as f:
        json.dump(spec, f)
    got = {}
    for fmt in formats:
        made = subprocess.run([cli, "run", path, "-f", fmt], capture_output=True, check=True).stdout
        r = client.get(f"/jobs/{job}/results?f={fmt}")
        c.check(r.status == 200 and r.body == made,
                f"{label} {fmt}: the download ({r.status}, {len(r.body)} bytes) is not the command line's ({len(made)})")
        z = client.get(f"/jobs/{job}/results?f={fmt}", headers={"Accept-Encoding": "gzip"})
        c.check(z.status == 200 and z.headers.get("content-encoding") == "gzip" and gzip.decompress(z.body) == made,
                f"{label} {fmt} gzip: {z.status}, {len(z.body)} bytes")
        got[fmt] = r.body
    return got


def gmsh_reads(c, tmp, name, body, st):
    """Gmsh itself opens a downloaded .msh: its nodes and elements are the statistics'."""
    path = os.path.join(tmp, name)
    with open(path, "wb") as f:
        f.write(body)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(path)
        nodes, _, _ = gmsh.model.mesh.getNodes()
        _, tags, _ = gmsh.model.mesh.getElements(2)
        _, lines, _ = gmsh.model.mesh.getElements(1)
        c.check(len(nodes) == st["nodes"] and sum(len(t) for t in tags) == st["elements"]["total"]
                and sum(len(t) for t in lines) == st["boundary_edges"],
                f"Gmsh reads {len(nodes)} nodes, {sum(len(t) for t in tags)} elements in {name}; "
                f"the statistics say {st['nodes']}, {st['elements']['total']}")
    finally:
        gmsh.finalize()


def check_walled_triangles(c, client, cli, tmp):
    """A walled mesh of triangles only (no band layers), downloaded from its windows."""
    spec = mesh_spec(element_size=3)
    job = client.submit(spec).json()["jobID"]
    info = client.wait_final(job)
    if not c.check(info["status"] == "successful", f"the walled mesh job: {info}"):
        return
    st = client.get(f"/jobs/{job}/statistics").json()["mesh"]
    c.check(st["elements"]["quadrilaterals"] == 0, f"quads without band_layers: {st['elements']}")
    got = same_as_cli(c, client, cli, tmp, job, spec, "walled")
    gmsh_reads(c, tmp, "walled.msh", got["msh"], st)
    return job, spec


def edit_store(c, daemon, sql, job):
    """Runs one statement on the stopped daemon's store; its row count."""
    c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    db = sqlite3.connect(daemon.db_path)
    count = db.execute(sql, (job,)).rowcount
    db.commit()
    db.close()
    daemon.start()
    return count


def check_stored_without_quality(c, daemon, cli, tmp, job, spec):
    """The vtu download reads the elements' qualities stored with the mesh (section
    mesh_quality, announced by the mesh section's version 2): without that section it is
    cut short. A result stored before them (mesh version 1, no mesh_quality: what an older
    grainpackd left) downloads its vtu from the mesh read whole, still the command line's
    bytes; msh and inp read it window by window."""
    gone = edit_store(c, daemon, "DELETE FROM result_sections WHERE job_id = ? AND tag = 'mesh_quality'", job)
    c.check(gone == 1, f"the stored result had {gone} mesh_quality sections")
    try:
        r = daemon.client().get(f"/jobs/{job}/results?f=vtu")
        whole = r.status == 200 and r.body.endswith(b"</VTKFile>\n")
    except Exception:  # the connection closed before the end: what a cut-short download is
        whole = False
    c.check(not whole, "a vtu download without the stored qualities was not cut short: it did not read them")
    older = edit_store(c, daemon, "UPDATE result_sections SET version = 1 WHERE job_id = ? AND tag = 'mesh'", job)
    c.check(older == 1, f"the stored result had {older} mesh sections")
    same_as_cli(c, daemon.client(), cli, tmp, job, spec, "old")


def check_periodic(c, client, cli, tmp):
    """A periodic spec with a mesh is accepted; its .msh download, the command line's
    bytes, has the $Periodic section that meshio reads (test_mesh_readers has Gmsh's
    reading of it)."""
    spec = periodic_spec(element_size=4)
    # the service's reading of the spec keeps the periodic sides (it dropped them)
    echoed = client.post_json("/processes/pack2d/validation", spec).json().get("inputs", {})
    c.check(echoed.get("domain", {}).get("periodic") == ["x", "y"],
            f"validation's normalised domain of a periodic spec: {echoed.get('domain')}")
    r = client.submit(spec)
    c.check(r.status == 201, f"a periodic spec with a mesh: {r}")
    info = client.wait_final(r.json()["jobID"])
    if not c.check(info["status"] == "successful", f"the periodic mesh job: {info}"):
        return
    st = client.get(f"/jobs/{info['jobID']}/statistics").json()["mesh"]
    c.check(st["periodic"]["axes"] == ["x", "y"] and st["periodic"]["node_pairs"]["x"] > 2,
            f"periodic mesh statistics: {st['periodic']}")
    r = client.get(f"/jobs/{info['jobID']}/results?f=msh")
    path = os.path.join(tmp, "periodic.json")
    with open(path, "w") as f:
        json.dump(spec, f)
    made = subprocess.run([cli, "run", path, "-f", "msh"], capture_output=True, check=True).stdout
    c.check(r.status == 200 and r.body == made and b"$Periodic" in r.body,
            f"periodic msh: {r.status}, {len(r.body)} bytes, the command line's {len(made)}")
    links = read_mesh(tmp, "periodic.msh", r.body).gmsh_periodic or []
    c.check(len(links) == 2 and [len(lk[3]) for lk in links] == [st["periodic"]["node_pairs"]["x"],
                                                                 st["periodic"]["node_pairs"]["y"]],
            f"meshio reads {len(links)} periodic links")
    same_as_cli(c, client, cli, tmp, info["jobID"], spec, "periodic", ("inp", "vtu"))


def bad_specs():
    """(what, spec, problem type, pointer) of meshing options the service must refuse."""
    no_cells = mesh_spec(band_layers=2)
    del no_cells["inputs"]["laguerre"]
    homothetic = mesh_spec(band_layers=1)
    homothetic["inputs"]["laguerre"] = {"shrink": "homothetic"}
    not_object = mesh_spec()
    not_object["inputs"]["mesh"] = 3
    no_band_size = mesh_spec(band_size=0.5)
    periodic_layers = periodic_spec(band_layers=2)
    no_band_size["inputs"]["laguerre"] = {"shrink": "none"}
    invalid = "urn:grainpack:problem:invalid-spec"
    return [
        ("zero size", mesh_spec(element_size=0), invalid, "/inputs/mesh/element_size"),
        ("negative size", mesh_spec(element_size=-1), invalid, "/inputs/mesh/element_size"),
        ("angle CGAL cannot guarantee", mesh_spec(min_angle=30), invalid, "/inputs/mesh/min_angle"),
        ("order 3", mesh_spec(order=3), invalid, "/inputs/mesh/order"),
        ("negative layers", mesh_spec(band_layers=-1), invalid, "/inputs/mesh/band_layers"),
        ("layers without cells", no_cells, invalid, "/inputs/mesh/band_layers"),
        ("layers with homothetic cells", homothetic, invalid, "/inputs/mesh/band_layers"),
        ("band_size sizing nothing", mesh_spec(band_size=0.5, grading=False), invalid, "/inputs/mesh/band_size"),
        ("band_size without a band", no_band_size, invalid, "/inputs/mesh/band_size"),
        ("grading not a boolean", mesh_spec(grading=1), invalid, "/inputs/mesh/grading"),
        ("unknown option", mesh_spec(size=1), invalid, "/inputs/mesh/size"),
        ("unknown plane", mesh_spec(abaqus={"plane": "axisymmetric"}), invalid, "/inputs/mesh/abaqus/plane"),
        ("not an object", not_object, invalid, "/inputs/mesh"),
        ("layers on a periodic domain", periodic_layers, invalid, "/inputs/mesh/band_layers"),
        ("beyond --max-elements", mesh_spec(element_size=0.05), "urn:grainpack:problem:job-too-big",
         "/inputs/mesh/element_size"),
    ]


def check_refusals(c, api, client):
    for what, spec, ptype, pointer in bad_specs():
        for path in ("/processes/pack2d/validation", "/processes/pack2d/execution"):
            r = client.post_json(path, spec)
            ok = gpd.check_problem(c, r, 422, ptype, "", f"{what} at {path}")
            if ok:
                c.check(r.json().get("pointer") == pointer, f"{what}: pointer {r.json().get('pointer')}, not {pointer}")
            api.check(c, "POST", path.replace("pack2d", "{processId}"), r)
    c.check(not client.get("/jobs").json()["jobs"], "a refused mesh spec was stored")


def check_validation(c, api, client):
    r = client.post_json("/processes/pack2d/validation", mesh_spec(band_layers=2))
    c.check(r.status == 200, f"validation of a mesh spec: {r}")
    api.check(c, "POST", "/processes/{processId}/validation", r)
    answer = r.json()
    mesh = answer["inputs"].get("mesh", {})
    c.check(mesh.get("band_layers") == 2 and mesh.get("order") == 1 and mesh.get("element_size", 0) > 0
            and abs(mesh.get("min_angle", 0) - 20.7) < 0.01
            and mesh.get("abaqus") == {"plane": "stress", "reduced_integration": False},
            f"the mesh's defaults are not written out: {mesh}")
    c.check(answer["limits"].get("max_elements") == MAX_ELEMENTS, f"limits {answer['limits']}")
    again = client.post_json("/processes/pack2d/validation", {"inputs": answer["inputs"]}).json()
    c.check(again == answer, "the normalised mesh spec is not a fixed point of validation")


def read_mesh(tmp, name, body):
    path = os.path.join(tmp, name)
    with open(path, "wb") as f:
        f.write(body)
    return meshio.read(path)


def check_downloads(c, api, client, cli, tmp):
    spec = mesh_spec(band_layers=2)
    job = client.submit(spec).json()["jobID"]
    info = client.wait_final(job)
    c.check(info["status"] == "successful", f"the mesh job: {info}")
    api.check(c, "GET", "/jobs/{jobId}", client.get(f"/jobs/{job}"))
    links = {lk["href"].split("f=")[1] if "f=" in lk["href"] else "json": lk
             for lk in info["links"] if lk["rel"] == RESULTS_REL}
    c.check({"msh", "inp", "vtu"} <= set(links), f"the mesh job's result links: {sorted(links)}")
    r = client.get(f"/jobs/{job}/statistics")
    api.check(c, "GET", "/jobs/{jobId}/statistics", r)
    st = r.json().get("mesh")
    if not c.check(st is not None, "the statistics have no mesh"):
        return
    c.check(any(t["stage"] == "mesh" for t in r.json()["timings"]), "no timing of the mesh stage")
    c.check(st["elements"]["quadrilaterals"] > 0 and st["band_strips"]["count"] > 0, f"band_layers made no quads: {st}")
    spec_path = os.path.join(tmp, "spec.json")
    with open(spec_path, "w") as f:
        json.dump(spec, f)
    runs = pipeline_runs(client)
    for fmt in ("msh", "inp", "vtu"):
        r = client.get(links[fmt]["href"])
        c.check(r.status == 200 and r.content_type == MEDIA[fmt] == links[fmt]["type"].split(";")[0],
                f"{fmt}: {r}, link type {links[fmt]['type']}")
        api.check(c, "GET", "/jobs/{jobId}/results", r)
        made = subprocess.run([cli, "run", spec_path, "-f", fmt], capture_output=True, check=True).stdout
        c.check(r.body == made, f"{fmt}: the download ({len(r.body)} bytes) is not what grainpack run writes ({len(made)})")
        m = read_mesh(tmp, "job." + fmt, r.body)
        tri = sum(len(b.data) for b in m.cells if b.type == "triangle")
        quad = sum(len(b.data) for b in m.cells if b.type == "quad")
        c.check(len(m.points) == st["nodes"] and (tri, quad) == (st["elements"]["triangles"], st["elements"]["quadrilaterals"]),
                f"{fmt}: meshio reads {len(m.points)} nodes, {tri} triangles, {quad} quads; the statistics say {st['nodes']}, {st['elements']}")
        if fmt == "msh":
            names = set(m.field_data)
            c.check({"grain_boundary", "left", "right", "bottom", "top"} <= names
                    and sum(n.startswith("grain_") for n in names) > 10, f"msh groups: {sorted(names)[:8]}")
        if fmt == "vtu":
            phase = np.concatenate(m.cell_data["phase"])
            c.check(set(np.unique(phase)) == {0, 1}, f"vtu phases {np.unique(phase)}")
        # text: gzip on the wire when accepted, the same bytes once decompressed
        z = client.get(links[fmt]["href"], headers={"Accept-Encoding": "gzip"})
        c.check(z.status == 200 and z.headers.get("content-encoding") == "gzip"
                and gzip.decompress(z.body) == made and len(z.body) < len(made),
                f"{fmt} gzip: {z.status} {z.headers.get('content-encoding')}, {len(z.body)} bytes")
    # the picture draws the stored mesh: the command line's bytes
    r = client.get(f"/jobs/{job}/results?f=svg")
    made = subprocess.run([cli, "run", spec_path, "-f", "svg"], capture_output=True, check=True).stdout
    c.check(r.status == 200 and r.body == made and b"mesh:" in made,
            f"svg: the download ({len(r.body)} bytes) is not what grainpack run writes ({len(made)})")
    r = client.get(f"/jobs/{job}/results?f=json")
    c.check(r.status == 200 and r.json()["statistics"]["mesh"]["nodes"] == st["nodes"], f"json: {r}")
    # every download above rendered the stored sections: no pipeline ran for them
    c.check(pipeline_runs(client) == runs, f"downloads ran the pipeline: {runs} runs before, "
            f"{pipeline_runs(client)} after")
    # the same job through Accept instead of ?f=
    r = client.get(f"/jobs/{job}/results", headers={"Accept": "text/x-gmsh"})
    c.check(r.status == 200 and r.content_type == "text/x-gmsh", f"Accept: text/x-gmsh: {r}")


def pipeline_runs(client):
    return gpd.metric(client.get("/metrics").body.decode(), "grainpack_pipeline_runs_total")


def check_without_mesh(c, api, client, tmp):
    job = client.submit(gpd.small_spec()).json()["jobID"]
    info = client.wait_final(job)
    formats = {lk["href"].split("f=")[1] for lk in info["links"] if lk["rel"] == RESULTS_REL and "f=" in lk["href"]}
    c.check(formats == {"csv", "svg", "vtk", "vtu"}, f"a job without a mesh lists {sorted(formats)}")
    for fmt in ("msh", "inp"):
        r = client.get(f"/jobs/{job}/results?f={fmt}")
        gpd.check_problem(c, r, 400, "urn:grainpack:problem:bad-parameter", "mesh", f"{fmt} without a mesh")
        api.check(c, "GET", "/jobs/{jobId}/results", r)
    # vtu of the disks (issue 15 item 6): one vertex per disk, read by meshio
    r = client.get(f"/jobs/{job}/results?f=vtu")
    api.check(c, "GET", "/jobs/{jobId}/results", r)
    count = client.get(f"/jobs/{job}/statistics").json()["count"]
    m = read_mesh(tmp, "disks.vtu", r.body)
    got = sum(len(b.data) for b in m.cells if b.type == "vertex")
    c.check(got == count and "radius" in m.point_data, f"disks.vtu: meshio reads {got} vertices for {count} disks")


def test(c, binary, cli):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--max-elements", str(MAX_ELEMENTS))
    try:
        daemon.start()
        client = daemon.client()
        with tempfile.TemporaryDirectory() as tmp:
            check_refusals(c, api, client)
            check_validation(c, api, client)
            check_downloads(c, api, client, cli, tmp)
            check_without_mesh(c, api, client, tmp)
            check_periodic(c, client, cli, tmp)
            walled = check_walled_triangles(c, client, cli, tmp)
            if walled:
                check_stored_without_quality(c, daemon, cli, tmp, *walled)
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
