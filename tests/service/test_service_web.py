#!/usr/bin/env python3
"""test_service_web.py - what the web page needs from the service, over plain HTTP: / is
the page for a browser and the JSON landing page for API clients (Vary: Accept, ?f=);
every file the page loads is served from the binary, byte for byte the repository's,
with its media type, a strong ETag (304 on If-None-Match) and the page's security headers,
and refers to no other host; the check of a spec without running it (POST
/processes/pack2d/validation: expected disks, the spec with its defaults written out,
the same 422 as a submission, nothing stored); the picture coloured by radius or by F on
request (?color=); one results link per format in a successful job's status; the
standard error of each bin. Responses are checked against openapi.yaml.
Usage: test_service_web.py GRAINPACKD"""

import math
import os
import re
import tempfile

import gpd

WEB = os.path.join(gpd.ROOT, "server", "web")
# What a browser sends (Chromium's Accept for a page).
BROWSER = "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,*/*;q=0.8"
# The page's aim (issue 14): under 200 KB before any result is fetched.
PAGE_BUDGET = 200 * 1024
# Absolute URLs the page's files may hold: names, never fetched (the SVG namespace, the
# OGC link relation of results).
IDENTIFIERS = {"http://www.w3.org/2000/svg", "http://www.opengis.net/def/rel/ogc/1.0/results"}
MEDIA = {".html": "text/html", ".js": "text/javascript", ".css": "text/css", ".svg": "image/svg+xml",
         ".json": "application/json"}
IRON_BAD_BIN = 3  # the bin the invalid spec breaks


def web_files():
    return sorted(os.listdir(WEB))


def check_negotiation(c, api, client):
    r = client.get("/")
    c.check(r.status == 200 and r.content_type == "application/json", f"/ without Accept: {r}")
    c.check(r.headers.get("vary") == "Accept", f"/: Vary {r.headers.get('vary')!r}")
    api.check(c, "GET", "/", r)
    links = {link["rel"]: link for link in r.json()["links"]}
    c.check(links.get("alternate", {}).get("type") == "text/html", f"/: no link to the page: {links.keys()}")
    for accept in ("*/*", "application/json", "text/html;q=0.5, application/json", "image/png"):
        r = client.get("/", headers={"Accept": accept})
        c.check(r.status == 200 and r.content_type == "application/json", f"/ with Accept {accept}: {r}")
    page = client.get("/", headers={"Accept": BROWSER})
    c.check(page.status == 200 and page.content_type == "text/html", f"/ from a browser: {page}")
    api.check(c, "GET", "/", page)
    c.check(b'<script type="module" src="/ui/app.js">' in page.body, "the page does not load app.js")
    c.check(page.body == open(os.path.join(WEB, "index.html"), "rb").read(), "the page is not server/web/index.html")
    c.check(page.headers.get("vary") == "Accept", f"the page: Vary {page.headers.get('vary')!r}")
    csp = page.headers.get("content-security-policy", "")
    c.check("default-src 'none'" in csp and "script-src 'self'" in csp and "frame-ancestors 'none'" in csp,
            f"the page's CSP: {csp!r}")
    c.check(page.headers.get("x-content-type-options") == "nosniff", "the page: no nosniff")
    for query, expected in (("?f=html", "text/html"), ("?f=json", "application/json")):
        r = client.get("/" + query, headers={"Accept": BROWSER if expected == "application/json" else "*/*"})
        c.check(r.status == 200 and r.content_type == expected, f"/{query}: {r}")
    r = client.get("/?f=xml")
    gpd.check_problem(c, r, 400, "urn:grainpack:problem:bad-parameter", "html or json", "/?f=xml")
    api.check(c, "GET", "/", r)
    etag = page.headers.get("etag", "")
    c.check(re.fullmatch(r'"[0-9a-f]{16}"', etag) is not None, f"the page's ETag {etag!r}")
    r = client.get("/", headers={"Accept": BROWSER, "If-None-Match": etag})
    c.check(r.status == 304 and r.body == b"" and r.headers.get("etag") == etag, f"/ revalidated: {r}")
    api.check(c, "GET", "/", r)
    r = client.get("/", headers={"Accept": BROWSER, "If-None-Match": '"0000000000000000"'})
    c.check(r.status == 200 and r.body == page.body, f"/ with a stale ETag: {r}")
    r = client.request("HEAD", "/", headers={"Accept": BROWSER})
    c.check(r.status == 200 and r.body == b"" and r.content_type == "text/html", f"HEAD / from a browser: {r}")


def referenced_files():
    """The names of the files index.html and the modules load (links, scripts, imports)."""
    names = set()
    html = open(os.path.join(WEB, "index.html")).read()
    names.update(re.findall(r'(?:href|src)="/ui/([^"]+)"', html))
    for name in web_files():
        if name.endswith(".js"):
            names.update(re.findall(r"from '\./([^']+)'", open(os.path.join(WEB, name)).read()))
    return names


def check_files(c, api, client):
    total = 0
    etags = set()
    for name in web_files():
        r = client.get(f"/ui/{name}")
        want = MEDIA[os.path.splitext(name)[1]]
        c.check(r.status == 200 and r.content_type == want, f"/ui/{name}: {r}")
        api.check(c, "GET", "/ui/{file}", r)
        with open(os.path.join(WEB, name), "rb") as f:
            c.check(r.body == f.read(), f"/ui/{name} differs from server/web/{name}")
        etag = r.headers.get("etag")
        etags.add(etag)
        c.check(r.headers.get("cache-control") == "no-cache", f"/ui/{name}: Cache-Control")
        c.check("content-security-policy" in r.headers, f"/ui/{name}: no CSP")
        r304 = client.get(f"/ui/{name}", headers={"If-None-Match": f'"x", W/{etag}'})
        c.check(r304.status == 304 and r304.body == b"", f"/ui/{name} revalidated with its ETag: {r304}")
        total += len(r.body)
        text = r.body.decode()
        for url in set(re.findall(r"""https?://[^\s"'`)<>]+""", text)):
            c.check(url in IDENTIFIERS, f"/ui/{name} refers to another host: {url}")
        c.check("@import" not in text and "//cdn" not in text, f"/ui/{name} imports from elsewhere")
    c.check(len(etags) == len(web_files()), "two files share an ETag")
    c.check(total < PAGE_BUDGET, f"the page's files weigh {total} bytes, over {PAGE_BUDGET}")
    print(f"the page's {len(web_files())} files: {total} bytes")
    missing = referenced_files() - set(web_files())
    c.check(not missing, f"the page loads files the service does not have: {missing}")
    for example in ("fixed", "variable", "iron", "bagi", "iron3d"):
        r = client.get(f"/ui/example-{example}.json")
        c.check(r.status == 200 and r.body == open(os.path.join(gpd.EXAMPLES, f"{example}.json"), "rb").read(),
                f"/ui/example-{example}.json: {r}")
    for path in ("/ui/nope.js", "/ui/..", "/ui/", "/ui/index.html/x"):
        r = client.get(path)
        c.check(r.status == 404 and r.content_type == "application/problem+json", f"{path}: {r}")
    r = client.post_json("/ui/app.js", {})
    c.check(r.status == 405, f"POST /ui/app.js: {r}")


def normalised_keys_cover(c, process, spec):
    """The spec uses every input of the process description, and the normalised spec
    keeps each one: an input the service gains must be written out by gp_spec_json too."""
    c.check(set(spec["inputs"]) == set(process["inputs"]),
            f"the full spec of this test lacks inputs {set(process['inputs']) - set(spec['inputs'])}: add them")


def full_spec():
    spec = gpd.load_example("iron")
    spec["inputs"].update({"front": {"level_band": 1}, "balance": {"method": "relocation", "max_iterations": 30},
                           "laguerre": {"shrink": "offset"}, "picture": {"color": "radius", "disks": True},
                           "mesh": {"element_size": 4, "band_layers": 1},
                           "seed": 7})
    return spec


def check_validation(c, api, client, daemon):
    process = client.get("/processes/pack2d").json()
    spec = full_spec()
    normalised_keys_cover(c, process, spec)
    r = client.post_json("/processes/pack2d/validation", spec)
    c.check(r.status == 200, f"validation of the full spec: {r}")
    api.check(c, "POST", "/processes/{processId}/validation", r)
    answer = r.json()
    inputs = answer["inputs"]
    c.check(set(spec["inputs"]) <= set(inputs), f"normalised inputs lost {set(spec['inputs']) - set(inputs)}")
    c.check(inputs["balance"] == {"method": "relocation", "max_iterations": 30, "max_step": 1.0}, f"balance {inputs['balance']}")
    c.check(inputs["laguerre"] == {"shrink": "offset", "flush_boundary": False}, f"laguerre {inputs['laguerre']}")
    c.check(inputs["mesh"] == {"element_size": 4, "min_angle": 20.7048, "order": 1, "band_layers": 1,
                               "grading": True, "abaqus": {"plane": "stress", "reduced_integration": False}}, f"mesh {inputs['mesh']}")
    c.check(inputs["distribution"] == spec["inputs"]["distribution"], "the bins are not given back as sent")
    c.check(answer["limits"]["max_disks"] == 2000000 and answer["limits"]["max_bins"] == 10000, f"limits {answer['limits']}")
    # the defaults written out, and the normalised spec a fixed point of validation
    r = client.post_json("/processes/pack2d/validation", {"inputs": {"domain": {"width": 30, "height": 30},
                                                                      "distribution": {"kind": "constant", "radius": 0.9}}})
    bare = r.json()["inputs"]
    c.check(bare["seed"] == 1 and bare["joint"] == {"law": "none"} and bare["front"] == {"rule": "densest"}
            and bare["picture"] == {"color": "radius", "disks": False} and "balance" not in bare,
            f"defaults of a bare spec: {bare}")
    again = client.post_json("/processes/pack2d/validation", {"inputs": inputs}).json()
    c.check(again == answer, "validating the normalised spec gives another answer")
    c.check(not client.get("/jobs").json()["jobs"], "a validation stored a job")
    # the estimate is the one the submission records (and caps)
    job = client.submit({"inputs": inputs}).json()["jobID"]
    db = daemon.db()
    try:
        recorded = db.execute("SELECT expected_disks FROM jobs WHERE id = ?", (job,)).fetchone()[0]
    finally:
        db.close()
    c.check(answer["expected_disks"] == round(recorded), f"expected disks {answer['expected_disks']} vs {recorded}")
    final = client.wait_final(job)
    c.check(final["status"] == "successful", f"the normalised spec's job: {final}")
    # an invalid spec: the very problem a submission gets
    bad = gpd.load_example("iron")
    bad["inputs"]["distribution"]["bins"][IRON_BAD_BIN]["max"] = 1.0
    r = client.post_json("/processes/pack2d/validation", bad)
    pointer = f"/inputs/distribution/bins/{IRON_BAD_BIN}/max"
    gpd.check_problem(c, r, 422, "urn:grainpack:problem:invalid-spec", pointer, "validation of a bad bin")
    api.check(c, "POST", "/processes/{processId}/validation", r)
    submitted = client.submit(bad)
    strip = lambda p: {k: v for k, v in p.items() if k != "instance"}  # noqa: E731
    c.check(r.status == submitted.status and strip(r.json()) == strip(submitted.json()),
            f"validation and submission disagree: {r.json()} vs {submitted.json()}")
    c.check(r.json().get("pointer") == pointer, f"pointer {r.json().get('pointer')}")
    big = {"domain": {"width": 1e5, "height": 1e5}, "distribution": {"kind": "constant", "radius": 0.5}}
    gpd.check_problem(c, client.post_json("/processes/pack2d/validation", big), 422,
                      "urn:grainpack:problem:job-too-big", "limit", "validation of a huge spec")
    for what, r, status in (
            ("malformed", client.post_json("/processes/pack2d/validation", b"{"), 400),
            ("not JSON", client.post_json("/processes/pack2d/validation", spec, content_type="text/plain"), 415),
            ("no such process", client.post_json("/processes/nope/validation", spec), 404),
            ("GET", client.get("/processes/pack2d/validation"), 405)):
        c.check(r.status == status and r.content_type == "application/problem+json", f"validation, {what}: {r}")
        if status != 405:
            api.check(c, "POST", "/processes/{processId}/validation", r)
    jobs = client.get("/jobs").json()["jobs"]
    c.check(len(jobs) == 1, f"validations stored jobs: {len(jobs)} jobs")


def check_results(c, api, client):
    balanced = gpd.load_example("iron")
    balanced["inputs"]["balance"] = {"method": "relocation", "max_iterations": 20}
    plain = gpd.small_spec()
    ids = {}
    for name, spec in (("balanced", balanced), ("plain", plain)):
        ids[name] = client.submit(spec).json()["jobID"]
    for name, job in ids.items():
        info = client.wait_final(job)
        c.check(info["status"] == "successful", f"{name}: {info}")
        results = [link for link in info["links"] if link["rel"] == "http://www.opengis.net/def/rel/ogc/1.0/results"]
        formats = {re.search(r"[?&]f=(\w+)", link["href"]).group(1) if "f=" in link["href"] else "json"
                   for link in results}
        # msh and inp only for a job with a mesh (test_service_mesh)
        c.check(formats == {"json", "csv", "svg", "vtk", "vtu"}, f"{name}: result links for {formats}")
        for link in results + [lk for lk in info["links"] if lk["rel"] == "statistics"]:
            r = client.get(link["href"])
            c.check(r.status == 200 and r.content_type == link["type"].split(";")[0],
                    f"{name}: {link['href']} answers {r.status} {r.content_type}, the link says {link['type']}")
    svg = {}
    for color in ("radius", "quality"):
        r = client.get(f"/jobs/{ids['balanced']}/results?f=svg&color={color}")
        c.check(r.status == 200 and r.content_type == "image/svg+xml", f"color={color}: {r}")
        api.check(c, "GET", "/jobs/{jobId}/results", r)
        svg[color] = r.body.decode()
    c.check("balance criterion F" in svg["quality"] and "balance criterion F" not in svg["radius"]
            and "grain radius" in svg["radius"], "?color= does not change what the picture is coloured by")
    c.check(svg["quality"] == client.get(f"/jobs/{ids['balanced']}/results?f=svg").body.decode(),
            "a balanced job's picture is not coloured by F by default")
    c.check(client.get(f"/jobs/{ids['balanced']}/results?f=csv&color=quality").status == 200, "color with CSV")
    r = client.get(f"/jobs/{ids['plain']}/results?f=svg&color=quality")
    gpd.check_problem(c, r, 400, "urn:grainpack:problem:bad-parameter", "balance", "color=quality without balance")
    api.check(c, "GET", "/jobs/{jobId}/results", r)
    r = client.get(f"/jobs/{ids['balanced']}/results?f=svg&color=red")
    gpd.check_problem(c, r, 400, "urn:grainpack:problem:bad-parameter", "radius or quality", "color=red")
    stats = client.get(f"/jobs/{ids['balanced']}/statistics").json()
    n = stats["count"]
    for b in stats["distribution"]["bins"]:
        se = math.sqrt(b["target"] * (1 - b["target"]) / n)
        c.check(abs(b["se"] - se) <= 1e-12 and abs(b["z"] * b["se"] - (b["achieved"] - b["target"])) <= 1e-12,
                f"bin {b}: se is not the standard error of z")


def check_keys(c, api, binary):
    with tempfile.TemporaryDirectory() as work:
        key_file = os.path.join(work, "keys")
        keys = gpd.write_keys(key_file, {"alice": "user"})
        daemon = gpd.Daemon(binary, "--key-file", key_file)
        try:
            daemon.start()
            anyone = daemon.client()
            page = anyone.get("/", headers={"Accept": BROWSER})
            c.check(page.status == 200 and page.content_type == "text/html", f"the page with keys, no key: {page}")
            for name in web_files():
                c.check(anyone.get(f"/ui/{name}").status == 200, f"/ui/{name} needs a key")
            spec = gpd.small_spec()
            r = anyone.post_json("/processes/pack2d/validation", spec)
            c.check(r.status == 401, f"validation without a key: {r}")
            api.check(c, "POST", "/processes/{processId}/validation", r)
            r = daemon.client(keys["alice"]).post_json("/processes/pack2d/validation", spec)
            c.check(r.status == 200, f"validation with a key: {r}")
            c.check(daemon.stop() == 0, "grainpackd with keys did not stop cleanly")
        finally:
            daemon.cleanup()


def test(c, binary):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary)
    try:
        daemon.start()
        client = daemon.client()
        check_negotiation(c, api, client)
        check_files(c, api, client)
        check_validation(c, api, client, daemon)
        check_results(c, api, client)
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    finally:
        daemon.cleanup()
    check_keys(c, api, binary)


if __name__ == "__main__":
    gpd.main(test)
