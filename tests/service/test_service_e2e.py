#!/usr/bin/env python3
"""test_service_e2e.py - the report's four reference cases through the real daemon:
submit, wait, fetch every format (by ?f= and by Accept), check the CSV for overlaps,
compare the result with the command line's for the same spec, and check that the
statistics in the database equal the API's; then a job that balances and builds
Laguerre cells, whose cells and F the service rebuilds from the stored disks exactly as
the command line wrote them. Every response is checked against openapi.yaml.
Usage: test_service_e2e.py GRAINPACKD GRAINPACK_CLI"""

import subprocess

import gpd

CASES = ["fixed", "variable", "iron", "bagi"]
FORMATS = {"json": "application/json", "csv": "text/csv", "svg": "image/svg+xml",
           "vtk": "application/x-vtk"}


def check_service_documents(c, api, client):
    for path in ["/", "/conformance", "/processes", "/processes/pack2d", "/health", "/jobs"]:
        r = client.get(path)
        c.check(r.status == 200, f"GET {path}: {r}")
        api.check(c, "GET", path.replace("/processes/pack2d", "/processes/{processId}"), r)
    landing = client.get("/").json()
    hrefs = {link["href"] for link in landing["links"]}
    c.check({"/conformance", "/processes", "/jobs", "/openapi.yaml"} <= hrefs, f"landing links {hrefs}")
    conf = client.get("/conformance").json()["conformsTo"]
    c.check("http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/core" in conf, f"conformance {conf}")
    processes = client.get("/processes").json()["processes"]
    c.check([p["id"] for p in processes] == ["pack2d", "pack3d"], f"processes {processes}")
    desc = client.get("/processes/pack2d").json()
    c.check(set(desc["inputs"]) == {"domain", "distribution", "joint", "front", "seed", "balance",
                                    "laguerre", "mesh", "picture"},
            f"process inputs {list(desc['inputs'])}")
    served = client.get("/openapi.yaml")
    api.check(c, "GET", "/openapi.yaml", served)
    with open(gpd.os.path.join(gpd.ROOT, "openapi.yaml"), "rb") as f:
        c.check(served.body == f.read(), "GET /openapi.yaml is not the repository's openapi.yaml")
    metrics = client.get("/metrics")
    api.check(c, "GET", "/metrics", metrics)
    c.check(b"# TYPE grainpack_http_requests_total counter" in metrics.body, "metrics text")
    head = client.request("HEAD", "/")
    c.check(head.status == 200 and head.body == b"", f"HEAD /: {head}")


def check_case(c, api, client, daemon, cli, name):
    spec = gpd.load_example(name)
    r = client.submit(spec)
    if not c.check(r.status == 201, f"{name}: submit: {r}"):
        return
    api.check(c, "POST", "/processes/{processId}/execution", r)
    info = r.json()
    job = info["jobID"]
    c.check(r.headers.get("location") == f"/jobs/{job}", f"{name}: Location {r.headers.get('location')}")
    c.check(info["status"] in ("accepted", "running", "successful"), f"{name}: status {info}")
    c.check(gpd.RFC3339.match(info["created"]), f"{name}: created {info['created']}")

    final = client.wait_final(job)
    if not c.check(final["status"] == "successful", f"{name}: finished {final}"):
        print(daemon.log())
        return
    r = client.get(f"/jobs/{job}")
    api.check(c, "GET", "/jobs/{jobId}", r)
    c.check(final["progress"] == 100, f"{name}: progress {final['progress']}")
    for key in ("created", "started", "finished", "updated"):
        c.check(gpd.RFC3339.match(final.get(key, "")), f"{name}: {key} {final.get(key)}")
    c.check(final["created"] <= final["started"] <= final["finished"], f"{name}: timestamps {final}")
    rels = {link["rel"] for link in final["links"]}
    c.check("http://www.opengis.net/def/rel/ogc/1.0/results" in rels, f"{name}: links {rels}")

    # every format, by ?f= and by Accept; each byte-identical to the command line's
    bodies = {}
    for fmt, media in FORMATS.items():
        by_f = client.get(f"/jobs/{job}/results?f={fmt}")
        by_accept = client.get(f"/jobs/{job}/results", headers={"Accept": f"{media}, */*;q=0.1"})
        c.check(by_f.status == 200 and by_f.content_type == media, f"{name} ?f={fmt}: {by_f}")
        c.check(by_accept.status == 200 and by_accept.content_type == media,
                f"{name} Accept {media}: {by_accept}")
        c.check(by_f.body == by_accept.body, f"{name}: {fmt} differs between ?f= and Accept")
        api.check(c, "GET", "/jobs/{jobId}/results", by_f)
        cli_out = subprocess.run([cli, "run", "-", "--format", fmt], input=gpd.json.dumps(spec).encode(),
                                 capture_output=True, check=True).stdout
        c.check(by_f.body == cli_out, f"{name}: service {fmt} differs from `grainpack run` ({len(by_f.body)} vs {len(cli_out)} bytes)")
        bodies[fmt] = by_f.body
    default = client.get(f"/jobs/{job}/results")
    c.check(default.content_type == "application/json" and default.body == bodies["json"],
            f"{name}: default format is not JSON")

    header, disks = gpd.parse_csv(bodies["csv"].decode())
    c.check(header == "x,y,r,R", f"{name}: CSV header {header!r}")
    result = gpd.json.loads(bodies["json"])
    stats = result["statistics"]
    c.check(len(disks) == stats["count"] == len(result["disks"]) > 0,
            f"{name}: {len(disks)} CSV lines, count {stats['count']}")
    overlaps = gpd.find_overlaps(disks)
    c.check(not overlaps, f"{name}: overlapping disks {overlaps[:3]}")
    W, H = spec["inputs"]["domain"]["width"], spec["inputs"]["domain"]["height"]
    slack = 1e-9 * max(W, H)
    outside = [d for d in disks if d[0] - d[3] < -slack or d[0] + d[3] > W + slack
               or d[1] - d[3] < -slack or d[1] + d[3] > H + slack]
    c.check(not outside, f"{name}: disks outside the domain {outside[:3]}")
    svg = bodies["svg"].decode()
    c.check(svg.startswith("<?xml") and svg.rstrip().endswith("</svg>"), f"{name}: SVG not whole")
    c.check(svg.count("<circle") >= len(disks), f"{name}: SVG has {svg.count('<circle')} circles")

    # statistics: schema, content, and the database's rows
    r = client.get(f"/jobs/{job}/statistics")
    api.check(c, "GET", "/jobs/{jobId}/statistics", r)
    st = r.json()
    c.check(st["jobID"] == job, f"{name}: statistics jobID")
    c.check({t["stage"] for t in st["timings"]} >= {"pack", "stats"}, f"{name}: timings {st['timings']}")
    c.check(abs(st["total_seconds"] - sum(t["seconds"] for t in st["timings"])) < 1e-9,
            f"{name}: total_seconds")
    for key in ("count", "packing_density", "grain_fraction", "distribution", "radius", "front"):
        c.check(st[key] == stats[key], f"{name}: statistics {key} differs from the result's")
    with daemon.db() as db:
        row = db.execute("SELECT status, count, packing_density, grain_fraction, chi2, dof, p_value,"
                         " max_abs_z, seed, distribution, domain_width, domain_height, spec"
                         " FROM jobs WHERE id = ?", (job,)).fetchone()
        bins = db.execute("SELECT bin, min, max, target, achieved, count, z FROM bin_stats"
                          " WHERE job_id = ? ORDER BY bin", (job,)).fetchall()
        timings = db.execute("SELECT stage, seconds FROM stage_timings WHERE job_id = ?"
                             " ORDER BY position", (job,)).fetchall()
        blob = db.execute("SELECT s.bytes, (SELECT sum(length(data)) FROM result_chunks c"
                          " WHERE c.section = s.id) FROM result_sections s"
                          " WHERE s.job_id = ? AND s.tag = 'disks'", (job,)).fetchone()
    d = st["distribution"]
    c.check(row is not None and row[:9] == ("successful", st["count"], st["packing_density"],
                                            st["grain_fraction"], d["chi2"], d["dof"], d["p_value"],
                                            d["max_abs_z"], spec["inputs"].get("seed", 1)),
            f"{name}: jobs row {row and row[:9]} differs from the API")
    c.check(row is not None and row[9] == spec["inputs"]["distribution"]["kind"]
            and (row[10], row[11]) == (W, H), f"{name}: jobs summary columns {row and row[9:12]}")
    c.check(row is not None and gpd.json.loads(row[12]) == spec, f"{name}: stored spec differs")
    api_bins = [(i, b["min"], b["max"], b["target"], b["achieved"], b["count"], b["z"])
                for i, b in enumerate(d["bins"])]
    c.check(len(bins) > 0 and bins == api_bins, f"{name}: bin_stats rows {bins[:2]} vs API {api_bins[:2]}")
    c.check([(t["stage"], t["seconds"]) for t in st["timings"]] == timings,
            f"{name}: stage_timings rows {timings} vs API {st['timings']}")
    c.check(blob == (32 * st["count"], 32 * st["count"]), f"{name}: disks section {blob}")


def check_staged(c, api, client, cli):
    """A balanced job with Laguerre cells (the report's Figure 47): the service stores what
    every stage produced, and serves the very bytes the command line writes, in every format
    (F before balancing and the sweeps included)."""
    spec = gpd.load_example("figure47")
    r = client.submit(spec)
    if not c.check(r.status == 201, f"staged: submit: {r}"):
        return
    job = r.json()["jobID"]
    if not c.check(client.wait_final(job)["status"] == "successful", "staged: not successful"):
        return
    for fmt in ("json", "csv", "svg", "vtk"):
        cli_out = subprocess.run([cli, "run", "-", "--format", fmt], input=gpd.json.dumps(spec).encode(),
                                 capture_output=True, check=True).stdout
        r = client.get(f"/jobs/{job}/results?f={fmt}")
        api.check(c, "GET", "/jobs/{jobId}/results", r)
        c.check(r.status == 200 and r.body == cli_out,
                f"staged: the service's {fmt} differs from the command line's")
    ours = client.get(f"/jobs/{job}/results?f=json").json()
    c.check("before" in ours["statistics"]["balance"] and "sweeps" in ours["statistics"]["balance"],
            "staged: F before balancing and the sweeps are kept")
    st = client.get(f"/jobs/{job}/statistics")
    api.check(c, "GET", "/jobs/{jobId}/statistics", st)
    stages = [t["stage"] for t in st.json()["timings"]]
    c.check(stages == ["pack", "triangulation", "balance", "laguerre", "stats"], f"staged: timings {stages}")


def test(c, binary, cli):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--workers", "2")
    try:
        daemon.start()
        client = daemon.client()
        check_service_documents(c, api, client)
        for name in CASES:
            check_case(c, api, client, daemon, cli, name)
        check_staged(c, api, client, cli)
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly on SIGTERM")
        log = daemon.log()
        c.check(log.count(" successful: ") == len(CASES) + 1, "log: one 'successful' line per job")
        c.check("POST /processes/pack2d/execution 201" in log, "log: request lines")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
