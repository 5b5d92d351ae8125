#!/usr/bin/env python3
"""test_service_errors.py - bad requests: each gets the right status and an RFC 9457
problem+json body with a useful detail (a 422 also names the field by JSON pointer and
says what was expected), documented in openapi.yaml; the daemon stays healthy, loses
nothing, and still stops cleanly. Usage: test_service_errors.py GRAINPACKD"""

import json

import gpd

MAX_BODY = 4096
MAX_DISKS = 200000
OGC = "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/"


def spec_with(**changes):
    """The fixed example with inputs changed: value None deletes the member."""
    spec = gpd.small_spec()
    for key, value in changes.items():
        if value is None:
            del spec["inputs"][key]
        else:
            spec["inputs"][key] = value
    return spec


HIST = {"kind": "histogram", "bins": [{"min": 0.5, "max": 0.7, "p": 0.5}, {"min": 0.7, "max": 0.9, "p": 0.5}]}


def bins(*triples):
    return {"kind": "histogram", "bins": [{"min": a, "max": b, "p": p} for a, b, p in triples]}


# (what, body, status, problem type, JSON pointer or None, a word the detail must hold)
SPEC_CASES = [
    ("not JSON at all", b"{\"inputs\": ", 400, "urn:grainpack:problem:malformed-json", None, "line"),
    ("an empty body", b"", 400, "urn:grainpack:problem:malformed-json", None, "JSON"),
    ("duplicate keys", b'{"inputs": {"seed": 1, "seed": 2}}', 400, "urn:grainpack:problem:malformed-json", None, "duplicate"),
    ("a JSON array", b"[1, 2]", 422, "urn:grainpack:problem:invalid-spec", "", "object"),
    ("JSON null", b"null", 422, "urn:grainpack:problem:invalid-spec", "", "got null"),
    ("inputs not an object", {"inputs": 5}, 422, "urn:grainpack:problem:invalid-spec", "/inputs", "object"),
    ("an unknown top-level member", {"inputs": gpd.small_spec()["inputs"], "extra": 1}, 422,
     "urn:grainpack:problem:invalid-spec", "/extra", "unknown"),
    ("no domain", spec_with(domain=None), 422, "urn:grainpack:problem:invalid-spec", "/inputs/domain", "missing"),
    ("a negative width", spec_with(domain={"width": -3, "height": 10}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/domain/width", "> 0"),
    ("a width as a string", spec_with(domain={"width": "ten", "height": 10}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/domain/width", "a string"),
    ("an unknown input", spec_with(colour="red"), 422, "urn:grainpack:problem:invalid-spec", "/inputs/colour", "unknown"),
    ("an unknown distribution kind", spec_with(distribution={"kind": "lognormal"}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/kind", "histogram"),
    ("no bins", spec_with(distribution={"kind": "histogram", "bins": []}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/bins", "at least one"),
    ("a negative probability", spec_with(distribution=bins((0.5, 0.7, 1.1), (0.7, 0.9, -0.1))), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/bins/0/p", "<= 1"),
    ("probabilities not summing to 1", spec_with(distribution=bins((0.5, 0.7, 0.5), (0.7, 0.9, 0.4))), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/bins", "sum to 1"),
    ("overlapping bins", spec_with(distribution=bins((0.5, 0.8, 0.5), (0.7, 0.9, 0.5))), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/bins/1/min", "previous bin"),
    ("a bin with max below min", spec_with(distribution=bins((0.5, 0.4, 1.0))), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/bins/0/max", "must be >"),
    ("a uniform law with max below min", spec_with(distribution={"kind": "uniform", "min": 0.5, "max": 0.2}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/max", "must be >"),
    ("a constant radius of zero", spec_with(distribution={"kind": "constant", "radius": 0}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution/radius", "> 0"),
    ("an unknown joint law", spec_with(joint={"law": "quadratic"}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/joint/law", "inverse"),
    ("a power law without exponent", spec_with(joint={"law": "power", "k": 1}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/joint/exponent", "missing"),
    ("a negative joint", spec_with(joint={"law": "constant", "value": -1}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/joint/value", ">= 0"),
    ("level_band above 16", spec_with(front={"level_band": 17}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/front/level_band", "0 to 16"),
    ("level_band as a number", spec_with(front={"level_band": 1.5}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/front/level_band", "integer"),
    ("a negative seed", spec_with(seed=-1), 422, "urn:grainpack:problem:invalid-spec", "/inputs/seed", ">= 0"),
    ("a fractional seed", spec_with(seed=1.5), 422, "urn:grainpack:problem:invalid-spec", "/inputs/seed", "integer"),
    ("a grain larger than the domain", spec_with(domain={"width": 1, "height": 1}), 422,
     "urn:grainpack:problem:invalid-spec", "/inputs/distribution", "fit"),
    ("more disks than --max-disks", spec_with(domain={"width": 3000, "height": 3000}), 422,
     "urn:grainpack:problem:job-too-big", "/inputs/domain", str(MAX_DISKS)),
    ("bare inputs with an error", {"domain": {"width": 0, "height": 5}, "distribution": HIST}, 422,
     "urn:grainpack:problem:invalid-spec", "/domain/width", "> 0"),
]


def check_problem(c, api, what, r, status, ptype, method, template):
    ok = c.check(r.status == status, f"{what}: status {r.status}, expected {status}: {r}")
    ok &= c.check(r.content_type == "application/problem+json", f"{what}: content type {r.content_type}")
    try:
        p = r.json()
    except ValueError:
        return c.check(False, f"{what}: body is not JSON: {r.body[:200]!r}")
    ok &= c.check(p.get("status") == status and p.get("type") == ptype,
                  f"{what}: problem {p.get('status')} {p.get('type')}, expected {status} {ptype}")
    ok &= c.check(isinstance(p.get("detail"), str) and len(p["detail"]) > 10, f"{what}: detail {p.get('detail')!r}")
    if template is not None:
        ok &= api.check(c, method, template, r)
    else:  # a path the API does not have: still a problem as openapi.yaml defines it
        errors = api.validate(api.schema("Problem"), p)
        ok &= c.check(not errors, f"{what}: not a Problem: {errors}")
    return ok, p


def test(c, binary):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-body", str(MAX_BODY), "--max-disks", str(MAX_DISKS),
                        "--max-wait", "30")
    count = 0
    try:
        daemon.start()
        client = daemon.client()
        good = client.submit(gpd.small_spec(seed=7))
        c.check(good.status == 201, f"a good job: {good}")
        job = good.json()["jobID"]
        client.wait_final(job)

        # the job spec: 400 and 422, with pointer and expectation
        for what, body, status, ptype, pointer, word in SPEC_CASES:
            data = body if isinstance(body, bytes) else json.dumps(body).encode()
            r = client.post_json("/processes/pack2d/execution", data)
            count += 1
            ok, p = check_problem(c, api, what, r, status, ptype, "POST", "/processes/{processId}/execution")
            if pointer is not None:
                c.check(p.get("pointer") == pointer, f"{what}: pointer {p.get('pointer')!r}, expected {pointer!r}")
                c.check(isinstance(p.get("expected"), str) and p["expected"] in p.get("detail", ""),
                        f"{what}: expected {p.get('expected')!r} not in detail {p.get('detail')!r}")
                if pointer:
                    c.check(p.get("detail", "").startswith(pointer + ": "), f"{what}: detail {p.get('detail')!r}")
            c.check(word in p.get("detail", ""), f"{what}: detail {p.get('detail')!r} does not say {word!r}")

        # the body: media type and size
        spec = json.dumps(gpd.small_spec()).encode()
        transport = [
            ("text/plain", lambda: client.post_json("/processes/pack2d/execution", spec, "text/plain"), 415,
             "urn:grainpack:problem:unsupported-media-type"),
            ("no Content-Type", lambda: client.post_json("/processes/pack2d/execution", spec, None), 415,
             "urn:grainpack:problem:unsupported-media-type"),
            ("a form", lambda: client.post_json("/processes/pack2d/execution", spec,
                                                "application/x-www-form-urlencoded"), 415,
             "urn:grainpack:problem:unsupported-media-type"),
            ("a body over the cap", lambda: client.post_json("/processes/pack2d/execution",
                                                             b" " * (MAX_BODY + 1) + spec), 413,
             "urn:grainpack:problem:body-too-large"),
            ("a chunked body over the cap", lambda: client.request(
                "POST", "/processes/pack2d/execution", body=b" " * (MAX_BODY + 2048),
                headers={"Content-Type": "application/json"}, chunked=True), 413,
             "urn:grainpack:problem:body-too-large"),
        ]
        for what, call, status, ptype in transport:
            count += 1
            check_problem(c, api, what, call(), status, ptype, "POST", "/processes/{processId}/execution")

        # paths, methods, parameters
        unknown = "00000000-0000-4000-8000-000000000000"
        requests = [
            ("an unknown process (execute)", "POST", "/processes/nope/execution", 404, OGC + "no-such-process",
             "/processes/{processId}/execution"),
            ("an unknown process", "GET", "/processes/nope", 404, OGC + "no-such-process", "/processes/{processId}"),
            ("an unknown job", "GET", f"/jobs/{unknown}", 404, OGC + "no-such-job", "/jobs/{jobId}"),
            ("a job id with odd characters", "GET", "/jobs/%3Cscript%3E", 404, "urn:grainpack:problem:not-found", None),
            ("results of an unknown job", "GET", f"/jobs/{unknown}/results", 404, OGC + "no-such-job",
             "/jobs/{jobId}/results"),
            ("statistics of an unknown job", "GET", f"/jobs/{unknown}/statistics", 404, OGC + "no-such-job",
             "/jobs/{jobId}/statistics"),
            ("deleting an unknown job", "DELETE", f"/jobs/{unknown}", 404, OGC + "no-such-job", "/jobs/{jobId}"),
            ("an unknown path", "GET", "/nowhere", 404, "urn:grainpack:problem:not-found", None),
            ("DELETE on /processes", "DELETE", "/processes", 405, "urn:grainpack:problem:method-not-allowed", None),
            ("PUT on /jobs", "PUT", "/jobs", 405, "urn:grainpack:problem:method-not-allowed", None),
            ("POST on /jobs", "POST", "/jobs", 405, "urn:grainpack:problem:method-not-allowed", None),
            ("GET on the execution", "GET", "/processes/pack2d/execution", 405,
             "urn:grainpack:problem:method-not-allowed", None),
            ("POST on a job", "POST", f"/jobs/{job}", 405, "urn:grainpack:problem:method-not-allowed", None),
            ("limit=0", "GET", "/jobs?limit=0", 400, "urn:grainpack:problem:bad-parameter", "/jobs"),
            ("limit=abc", "GET", "/jobs?limit=abc", 400, "urn:grainpack:problem:bad-parameter", "/jobs"),
            ("limit=100000", "GET", "/jobs?limit=100000", 400, "urn:grainpack:problem:bad-parameter", "/jobs"),
            ("an unknown status", "GET", "/jobs?status=finished", 400, "urn:grainpack:problem:bad-parameter", "/jobs"),
            ("a negative cursor", "GET", "/jobs?cursor=-3", 400, "urn:grainpack:problem:bad-parameter", "/jobs"),
            ("wait=-1", "GET", f"/jobs/{job}?wait=-1", 400, "urn:grainpack:problem:bad-parameter", "/jobs/{jobId}"),
            ("wait over --max-wait", "GET", f"/jobs/{job}?wait=31", 400, "urn:grainpack:problem:bad-parameter",
             "/jobs/{jobId}"),
            ("an unknown format", "GET", f"/jobs/{job}/results?f=xml", 400, "urn:grainpack:problem:bad-parameter",
             "/jobs/{jobId}/results"),
        ]
        for what, method, path, status, ptype, template in requests:
            count += 1
            r = client.request(method, path)
            ok, p = check_problem(c, api, what, r, status, ptype, method, template)
            if status == 405:
                c.check("allow" in r.headers and "OPTIONS" in r.headers["allow"], f"{what}: Allow {r.headers.get('allow')}")
        count += 1
        r = client.get(f"/jobs/{job}/results", headers={"Accept": "application/xml"})
        check_problem(c, api, "an Accept nothing matches", r, 406, "urn:grainpack:problem:not-acceptable",
                      "GET", "/jobs/{jobId}/results")
        c.check("text/csv" in r.json().get("detail", ""), "406 detail lists the formats")

        # the daemon is healthy and lost nothing: the good job is intact, a new one runs
        r = client.get("/health")
        c.check(r.status == 200 and r.json()["status"] == "ok", f"health after bad requests: {r}")
        after = client.submit(gpd.small_spec(seed=8))
        c.check(after.status == 201 and client.wait_final(after.json()["jobID"])["status"] == "successful",
                "a job after the bad requests")
        jobs = client.get("/jobs?limit=100").json()["jobs"]
        c.check(sorted(j["jobID"] for j in jobs) == sorted([job, after.json()["jobID"]]),
                f"bad requests created jobs: {[j['jobID'] for j in jobs]}")
        c.check(client.get(f"/jobs/{job}/results?f=csv").status == 200, "the good job's result")
        metrics = client.get("/metrics").body.decode()
        c.check(gpd.metric(metrics, "grainpack_http_requests_total", 'code="422"') ==
                sum(1 for case in SPEC_CASES if case[2] == 422), "422s counted in /metrics")
        c.check(gpd.metric(metrics, "grainpack_http_requests_total", 'code="500"') is None, "no 500 in /metrics")
        client.close()
        c.check(count >= 30, f"only {count} bad requests")
        print(f"     {count} bad requests answered with the right problem")
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
