#!/usr/bin/env python3
"""test_service_pack3d.py - the second process, pack3d (spheres in a box), through the real
daemon: /processes lists both processes and /processes/pack3d describes its inputs; an
unknown process is 404 on every route; bad 3D specs are 422 with the field's JSON pointer
(and a 2D spec with a depth is refused by pack2d the same way); a pack3d job is accepted,
run and stored like a 2D one, its status says processID pack3d and links only the formats
it serves, and its CSV download, read back by Python's csv module, has spheres that
overlap no other (relative 1e-9, the engine's tolerance), lie in the box, and give the
statistics' count, packing density and bin counts; the JSON download holds the same
spheres and statistics, the gzip download the same bytes, and none of the downloads runs
the pipeline again; a format it does not serve (msh) is 400 (its balanced, tessellated
jobs: test_service_pack3d_cells.py). A pack3d job too large for
--max-disks is refused before it is stored, one past --max-job-seconds fails with a time
limit, a dismissed one stops, and a finished one is deleted with its results. Responses
are checked against openapi.yaml. The JSON and CSV downloads are byte for byte what
`grainpack run` writes for the same spec. A job in a periodic cube (docs/3d.md §11) runs
the same way: its spheres overlap no image of another, their centres lie in [0, side),
some cross a side, and its CSV is the command line's; "periodic" of the wrong shape, a
periodic side under 12 R_max and balance/laguerre on a periodic box are 422.
Usage: test_service_pack3d.py GRAINPACKD GRAINPACK"""

import csv
import gzip
import io
import json
import math
import os
import subprocess
import tempfile

import gpd

RESULTS_REL = "http://www.opengis.net/def/rel/ogc/1.0/results"
INVALID = "urn:grainpack:problem:invalid-spec"
NO_PROCESS = "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/no-such-process"
CONTACT_RTOL = 1e-9
# A cap on the spheres a job may be expected to make: the jobs below expect a few hundred,
# the slow one (a box of side 100, radius 0.5) 1.2 million, which takes seconds to pack,
# the refused one (side 200) 9.8 million.
MAX_SPHERES = 2000000
BOX = {"width": 12, "height": 10, "depth": 8}
LAW = {"kind": "uniform", "min": 0.4, "max": 0.8}
# a cube periodic along all three axes: each side at least 12 R_max (R_max = 0.85)
PERIODIC_BOX = {"width": 11, "height": 11, "depth": 11, "periodic": True}


def spec3d(**inputs):
    base = {"domain": dict(BOX), "distribution": LAW, "joint": {"law": "constant", "value": 0.05},
            "seed": 7}
    base.update(inputs)
    return {"inputs": base}


def bad_specs():
    """(what, process, spec, JSON pointer) of specs the service must refuse with 422."""
    negative = spec3d()
    negative["inputs"]["domain"]["depth"] = -1
    flat = spec3d()
    del flat["inputs"]["domain"]["depth"]
    deep2d = gpd.small_spec()
    deep2d["inputs"]["domain"]["depth"] = 5
    big = spec3d(distribution={"kind": "constant", "radius": 4.5})  # 2 R = 9.1: above the depth only
    return [
        ("a negative depth", "pack3d", negative, "/inputs/domain/depth"),
        ("a box without depth", "pack3d", flat, "/inputs/domain/depth"),
        ("an unknown balance method", "pack3d", spec3d(balance={"method": "stir"}), "/inputs/balance/method"),
        ("a shrink that is not one", "pack3d", spec3d(laguerre={"shrink": 2}), "/inputs/laguerre/shrink"),
        ("a sphere larger than the box", "pack3d", big, "/inputs/domain/depth"),
        ("a depth given to pack2d", "pack2d", deep2d, "/inputs/domain/depth"),
        ("a periodic axis named w", "pack3d", spec3d(domain=dict(BOX, periodic=["x", "w"])),
         "/inputs/domain/periodic/1"),
        ("a periodic side under 12 R_max", "pack3d", spec3d(domain=dict(BOX, periodic=["y"])),
         "/inputs/domain/periodic"),
        ("balancing on a periodic box", "pack3d",
         spec3d(domain=dict(PERIODIC_BOX), balance={"method": "relocation"}), "/inputs/balance"),
        ("polyhedra on a periodic box", "pack3d",
         spec3d(domain=dict(PERIODIC_BOX), laguerre={"shrink": "offset"}), "/inputs/laguerre"),
    ]


def check_processes(c, api, client):
    r = client.get("/processes")
    api.check(c, "GET", "/processes", r)
    ids = [p["id"] for p in r.json()["processes"]]
    c.check(ids == ["pack2d", "pack3d"], f"/processes lists {ids}")
    r = client.get("/processes/pack3d")
    api.check(c, "GET", "/processes/{processId}", r)
    desc = r.json()
    c.check(desc["id"] == "pack3d" and "depth" in desc["inputs"]["domain"]["schema"]["required"],
            f"/processes/pack3d: {desc.get('id')}")
    for method, path in (("GET", "/processes/pack4d"), ("POST", "/processes/pack4d/execution"),
                         ("POST", "/processes/pack4d/validation")):
        r = client.get(path) if method == "GET" else client.post_json(path, spec3d())
        gpd.check_problem(c, r, 404, NO_PROCESS, "'pack3d'", f"{method} {path}")


def check_refusals(c, api, client):
    for what, process, spec, pointer in bad_specs():
        for route in ("execution", "validation"):
            r = client.post_json(f"/processes/{process}/{route}", spec)
            if gpd.check_problem(c, r, 422, INVALID, "", f"{what} ({route})"):
                c.check(r.json().get("pointer") == pointer, f"{what}: pointer {r.json().get('pointer')}")
            api.check(c, "POST", f"/processes/{{processId}}/{route}", r)
    # more spheres than --max-disks, before anything is stored
    huge = spec3d(domain={"width": 200, "height": 200, "depth": 200},
                  distribution={"kind": "constant", "radius": 0.5}, joint={"law": "none"})
    r = client.post_json("/processes/pack3d/execution", huge)
    c.check(r.status in (413, 422) and r.json().get("pointer") == "/inputs/domain",
            f"a box of 9.8 million spheres against --max-disks {MAX_SPHERES}: {r}")
    c.check(client.get("/jobs").json()["jobs"] == [], "a refused spec was stored")


def check_validation(c, api, client):
    r = client.post_json("/processes/pack3d/validation", spec3d())
    api.check(c, "POST", "/processes/{processId}/validation", r)
    v = r.json()
    volume = BOX["width"] * BOX["height"] * BOX["depth"]
    c.check(v.get("valid") is True and 0 < v.get("expected_spheres", 0) < volume,
            f"validation: {v}")
    c.check(v["inputs"]["domain"] == BOX and v["inputs"]["seed"] == 7, f"validation inputs: {v['inputs']}")


def read_csv(body):
    rows = list(csv.reader(io.StringIO(body.decode())))
    return rows[0], [tuple(float(v) for v in row) for row in rows[1:]]


def overlaps(spheres):
    """Pairs of spheres whose packing spheres overlap beyond the engine's tolerance, by
    a bucket grid of side 2 R_max."""
    cell = 2 * max(s[4] for s in spheres)
    grid = {}
    for i, s in enumerate(spheres):
        grid.setdefault(tuple(int(s[k] // cell) for k in range(3)), []).append(i)
    bad = []
    for i, a in enumerate(spheres):
        cx, cy, cz = (int(a[k] // cell) for k in range(3))
        for key in ((x, y, z) for x in (cx - 1, cx, cx + 1) for y in (cy - 1, cy, cy + 1)
                    for z in (cz - 1, cz, cz + 1)):
            for j in grid.get(key, ()):
                b = spheres[j]
                reach = (a[4] + b[4]) * (1 - CONTACT_RTOL)
                if j > i and sum((a[k] - b[k]) ** 2 for k in range(3)) < reach * reach:
                    bad.append((i, j))
    return bad


def outside(spheres):
    sides = (BOX["width"], BOX["height"], BOX["depth"])
    tol = CONTACT_RTOL * max(sides)
    return [s for s in spheres
            if any(s[k] - s[4] < -tol or s[k] + s[4] > sides[k] + tol for k in range(3))]


def image_overlaps(spheres, sides):
    """Pairs overlapping under the minimum image (all pairs: a few hundred spheres)."""
    bad = []
    for i, a in enumerate(spheres):
        for j in range(i + 1, len(spheres)):
            b = spheres[j]
            d = [a[k] - b[k] for k in range(3)]
            d = [v - sides[k] * round(v / sides[k]) for k, v in enumerate(d)]
            reach = (a[4] + b[4]) * (1 - CONTACT_RTOL)
            if sum(v * v for v in d) < reach * reach:
                bad.append((i, j))
    return bad


def check_periodic_job(c, api, client, cli):
    spec = spec3d(domain=dict(PERIODIC_BOX))
    r = client.submit(spec, "pack3d")
    api.check(c, "POST", "/processes/{processId}/execution", r)
    job = r.json()["jobID"]
    info = client.wait_final(job)
    if not c.check(info["status"] == "successful", f"the periodic pack3d job: {info}"):
        return
    st = client.get(f"/jobs/{job}/statistics").json()
    r = client.get(f"/jobs/{job}/results?f=csv")
    header, spheres = read_csv(r.body)
    sides = (PERIODIC_BOX["width"], PERIODIC_BOX["height"], PERIODIC_BOX["depth"])
    c.check(len(spheres) == st["count"] > 100, f"periodic csv: {len(spheres)} spheres, {st['count']}")
    c.check(not image_overlaps(spheres, sides), f"periodic: overlapping images {image_overlaps(spheres, sides)[:5]}")
    c.check(all(0 <= s[k] < sides[k] for s in spheres for k in range(3)), "a periodic centre outside [0, side)")
    c.check(any(s[k] < s[4] or s[k] > sides[k] - s[4] for s in spheres for k in range(3)),
            "no sphere crosses a periodic side")
    density = sum(4 / 3 * math.pi * s[4] ** 3 for s in spheres) / (sides[0] * sides[1] * sides[2])
    c.check(abs(density - st["packing_density"]) < 1e-12, f"periodic density {density}, {st['packing_density']}")
    doc = client.get(f"/jobs/{job}/results?f=json").json()
    c.check(doc["inputs"]["domain"] == dict(PERIODIC_BOX, periodic=["x", "y", "z"]),
            f"the JSON download's domain: {doc['inputs']['domain']}")
    for fmt, mark in (("svg", b"<svg"), ("vtu", b"<VTKFile")):
        r = client.get(f"/jobs/{job}/results?f={fmt}")
        c.check(r.status == 200 and mark in r.body[:400], f"the periodic job's {fmt}: {r.status}")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cube.json")
        with open(path, "w") as f:
            json.dump(spec, f)
        made = subprocess.run([cli, "run", path, "-f", "csv"], capture_output=True, check=True).stdout
        c.check(made == plain_csv(client, job), "the periodic CSV download is not grainpack run's")


def pipeline_runs(client):
    return gpd.metric(client.get("/metrics").body.decode(), "grainpack_pipeline_runs_total")


def plain_csv(client, job):
    return client.get(f"/jobs/{job}/results?f=csv").body


def check_job(c, api, client, cli):
    r = client.submit(spec3d(), "pack3d")
    api.check(c, "POST", "/processes/{processId}/execution", r)
    c.check(r.status == 201 and r.json()["processID"] == "pack3d", f"submission: {r}")
    job = r.json()["jobID"]
    info = client.wait_final(job)
    if not c.check(info["status"] == "successful", f"the pack3d job: {info}"):
        return
    api.check(c, "GET", "/jobs/{jobId}", client.get(f"/jobs/{job}"))
    formats = {lk["href"].split("f=")[1] for lk in info["links"]
               if lk["rel"] == RESULTS_REL and "f=" in lk["href"]}
    c.check(info["processID"] == "pack3d" and formats == {"csv", "svg", "vtu"}, f"status links {sorted(formats)}")
    listed = {j["jobID"]: j["processID"] for j in client.get("/jobs").json()["jobs"]}
    c.check(listed.get(job) == "pack3d", f"/jobs says {listed.get(job)}")

    runs = pipeline_runs(client)
    r = client.get(f"/jobs/{job}/statistics")
    api.check(c, "GET", "/jobs/{jobId}/statistics", r)
    st = r.json()
    r = client.get(f"/jobs/{job}/results?f=csv")
    api.check(c, "GET", "/jobs/{jobId}/results", r, body_schema=False)
    header, spheres = read_csv(r.body)
    c.check(header == ["x", "y", "z", "r", "R"] and len(spheres) == st["count"] > 100,
            f"csv: {header}, {len(spheres)} spheres, statistics {st['count']}")
    c.check(not overlaps(spheres), f"overlapping spheres: {overlaps(spheres)[:5]}")
    c.check(not outside(spheres), f"spheres outside the box: {outside(spheres)[:3]}")
    c.check(all(LAW["min"] <= s[3] <= LAW["max"] and abs(s[4] - s[3] - 0.05) < 1e-12 for s in spheres),
            "a radius outside the law, or a joint other than 0.05")
    volume = BOX["width"] * BOX["height"] * BOX["depth"]
    density = sum(4 / 3 * math.pi * s[4] ** 3 for s in spheres) / volume
    c.check(abs(density - st["packing_density"]) < 1e-12 and st["box_volume"] == volume,
            f"density {density} against the statistics' {st['packing_density']}")
    bins = st["distribution"]["bins"]
    c.check(sum(b["count"] for b in bins) == len(spheres) and
            all(b["count"] == sum(1 for s in spheres if b["min"] <= s[3] < b["max"] or
                                  (b is bins[-1] and s[3] == b["max"])) for b in bins),
            "the statistics' bin counts are not the CSV's")
    c.check([t["stage"] for t in st["timings"]] == ["pack", "stats"],
            f"statistics: {st['timings']}")

    r = client.get(f"/jobs/{job}/results?f=json")
    api.check(c, "GET", "/jobs/{jobId}/results", r)
    doc = r.json()
    c.check([(s["x"], s["y"], s["z"], s["r"], s["R"]) for s in doc["spheres"]] == spheres and
            [s["id"] for s in doc["spheres"]] == list(range(len(spheres))) and
            doc["process"] == "pack3d" and doc["inputs"]["domain"] == BOX,
            "the JSON download's spheres differ from the CSV's")
    # the very bytes the command line writes for the same spec
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "box.json")
        with open(path, "w") as f:
            json.dump(spec3d(), f)
        for fmt, body in (("json", r.body), ("csv", plain_csv(client, job))):
            made = subprocess.run([cli, "run", path, "-f", fmt], capture_output=True, check=True).stdout
            c.check(body == made, f"{fmt}: the download ({len(body)} bytes) is not what grainpack run "
                                  f"writes ({len(made)} bytes)")
    stats = {k: v for k, v in st.items() if k not in ("jobID", "timings", "total_seconds")}
    c.check(doc["statistics"] == stats, "the JSON download's statistics differ from /statistics")
    plain = client.get(f"/jobs/{job}/results?f=csv").body
    z = client.get(f"/jobs/{job}/results?f=csv", headers={"Accept-Encoding": "gzip"})
    c.check(z.headers.get("content-encoding") == "gzip" and gzip.decompress(z.body) == plain,
            "the gzip download is not the CSV")
    etag = z.headers.get("etag")
    again = client.get(f"/jobs/{job}/results?f=csv", headers={"Accept-Encoding": "gzip", "If-None-Match": etag})
    c.check(again.status == 304, f"If-None-Match of the gzip CSV: {again.status}")
    r = client.get(f"/jobs/{job}/results?f=msh")
    gpd.check_problem(c, r, 400, "urn:grainpack:problem:bad-parameter", "pack3d", "msh of a pack3d job")
    api.check(c, "GET", "/jobs/{jobId}/results", r)
    c.check(pipeline_runs(client) == runs, "a download ran the pipeline again")

    r = client.request("DELETE", f"/jobs/{job}")
    c.check(r.status == 200 and client.get(f"/jobs/{job}").status == 404, f"delete: {r}")
    # one kept for the store's check at the end
    kept = client.submit(spec3d(seed=8), "pack3d").json()["jobID"]
    c.check(client.wait_final(kept)["status"] == "successful", "the second pack3d job")


def check_limits(c, client):
    """A job past --max-job-seconds fails with the time limit; a dismissed one stops."""
    slow = spec3d(domain={"width": 100, "height": 100, "depth": 100},
                  distribution={"kind": "constant", "radius": 0.5}, joint={"law": "none"})
    job = client.submit(slow, "pack3d").json()["jobID"]
    info = client.wait_final(job)
    c.check(info["status"] == "failed" and "max-job-seconds" in info["message"],
            f"a job past the time limit: {info['status']}, {info['message']}")
    job = client.submit(slow, "pack3d").json()["jobID"]
    client.wait_status(job, ("running",))
    r = client.request("DELETE", f"/jobs/{job}")
    c.check(r.status == 200 and r.json()["status"] == "dismissed", f"dismiss: {r}")
    c.check(client.wait_final(job)["status"] == "dismissed", "the dismissed job did not stay dismissed")


def test(c, binary, cli):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--max-disks", str(MAX_SPHERES), "--max-job-seconds", "1",
                        "--workers", "1")
    try:
        daemon.start()
        client = daemon.client()
        check_processes(c, api, client)
        check_refusals(c, api, client)
        check_validation(c, api, client)
        check_job(c, api, client, cli)
        check_periodic_job(c, api, client, cli)
        check_limits(c, client)
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        gpd.check_store(c, daemon, "after the pack3d jobs")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
