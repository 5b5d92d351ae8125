#!/usr/bin/env python3
"""test_service_hostile.py - hostile requests, sent as raw bytes on their own connection:
truncated and deeply nested JSON, duplicate keys, numbers out of range, NaN, negatives and
zeros everywhere, a grain larger than the domain, a histogram of 10^6 bins, probabilities
that do not sum to 1, unknown fields, wrong types, bytes that are not UTF-8, huge headers,
path traversal in ids, methods not allowed, bad keys, bad framing. Each gets the right
status and a problem+json whose detail says what is wrong -- or, for the few that
libmicrohttpd answers itself, exactly the answer the README documents. The daemon stays
healthy, keeps every job, answers no 500, and stops cleanly.
Usage: test_service_hostile.py GRAINPACKD"""

import json
import os
import tempfile

import gpd

OGC = "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/"
P = "urn:grainpack:problem:"
EXEC = "/processes/pack2d/execution"
MHD = "libmicrohttpd"  # an answer of the HTTP library itself: HTML, no Content-Type
NONE = "no answer"     # the connection is closed without one


def request(method, path, headers=(), body=None, content_type="application/json", key="alice",
            version=b"HTTP/1.1", length=None):
    """The bytes of a request; `key` names whose API key goes in (None: no key)."""
    if isinstance(path, str):
        path = path.encode()
    lines = [method.encode() + b" " + path + b" " + version, b"Host: localhost"]
    if key:
        lines.append(b"Authorization: Bearer " + KEYS[key].encode())
    if body is not None:
        if isinstance(body, (dict, list)):
            body = json.dumps(body).encode()
        elif isinstance(body, str):
            body = body.encode()
        if content_type:
            lines.append(b"Content-Type: " + content_type.encode())
        lines.append(b"Content-Length: " + str(len(body) if length is None else length).encode())
    lines += [h if isinstance(h, bytes) else h.encode() for h in headers]
    return b"\r\n".join(lines) + b"\r\n\r\n" + (body or b"")


def submit(body, **kw):
    return request("POST", EXEC, body=body, **kw)


def spec(**inputs):
    base = {"domain": {"width": 30, "height": 30}, "distribution": {"kind": "constant", "radius": 0.9}}
    for k, v in inputs.items():
        if v is None:
            base.pop(k, None)
        else:
            base[k] = v
    return {"inputs": base}


def hist(*bins):
    return {"kind": "histogram", "bins": [{"min": a, "max": b, "p": p} for a, b, p in bins]}


def nested(depth, leaf="1"):
    return ("[" * depth + leaf + "]" * depth)


KEYS = {}
ALICE_JOB = "{alice}"  # filled in once the daemon runs
BOB_JOB = "{bob}"
MANY_BINS = 10 ** 6


def million_bins():
    """A histogram of 10^6 bins: about 40 MB of JSON. Only the head is sent (the daemon
    answers from Content-Length before reading the body)."""
    width = 1.0 / MANY_BINS
    head = '{"inputs": {"domain": {"width": 1000, "height": 1000}, "distribution": {"kind": "histogram", "bins": ['
    one = '{"min": %.9f, "max": %.9f, "p": 0.000001},'
    sample = head + "".join(one % (1 + i * width, 1 + (i + 1) * width) for i in range(1000))
    total = len(head) + MANY_BINS * len(one % (1.5, 1.5)) + 4
    return sample.encode(), total


def cases():
    """(what, request bytes, status, problem type or MHD/NONE, a word the detail holds)."""
    big_body, big_len = million_bins()
    long_name = "\u00e9" * 400  # 800 bytes of UTF-8: a message cut inside a character
    c = [
        # JSON that is not JSON
        ("truncated JSON", submit('{"inputs": {"domain": {"width": 10,'), 400, P + "malformed-json", "line 1"),
        ("truncated inside a string", submit('{"inputs": {"dom'), 400, P + "malformed-json", "line 1"),
        ("an empty body", submit(b""), 400, P + "malformed-json", "line"),
        ("only whitespace", submit(b"  \n\t "), 400, P + "malformed-json", "line"),
        ("arrays nested 100000 deep", submit(nested(100000)), 400, P + "malformed-json", "depth"),
        ("objects nested 5000 deep", submit('{"a":' * 5000 + "1" + "}" * 5000), 400, P + "malformed-json", "depth"),
        ("duplicate keys at the top", submit('{"inputs": {}, "inputs": {}}'), 400, P + "malformed-json", "duplicate"),
        ("duplicate keys deep inside", submit('{"inputs": {"domain": {"width": 1, "width": 2, "height": 3}}}'), 400,
         P + "malformed-json", "duplicate"),
        ("1e309", submit('{"inputs": {"domain": {"width": 1e309, "height": 10}}}'), 400, P + "malformed-json",
         "overflow"),
        ("-1e309", submit('{"inputs": {"domain": {"width": 10, "height": -1e309}}}'), 400, P + "malformed-json",
         "overflow"),
        ("NaN", submit('{"inputs": {"domain": {"width": NaN, "height": 10}}}'), 400, P + "malformed-json", "line 1"),
        ("Infinity", submit('{"inputs": {"domain": {"width": Infinity, "height": 10}}}'), 400, P + "malformed-json",
         "line 1"),
        ("a hexadecimal number", submit('{"inputs": {"seed": 0x10}}'), 400, P + "malformed-json", "line 1"),
        ("a leading zero", submit('{"inputs": {"seed": 010}}'), 400, P + "malformed-json", "line 1"),
        ("a trailing comma", submit('{"inputs": {"seed": 1,}}'), 400, P + "malformed-json", "line 1"),
        ("two documents", submit('{"inputs": {}} {"inputs": {}}'), 400, P + "malformed-json", "end of file"),
        ("a byte that is not UTF-8 in a string", submit(b'{"inputs": {"seed": "\xff\xfe"}}'), 400,
         P + "malformed-json", "decode byte 0xff"),
        ("a byte that is not UTF-8 in a key", submit(b'{"inputs": {"se\xc3ed": 1}}'), 400, P + "malformed-json",
         "decode byte 0xc3"),
        ("a UTF-16 body", submit('{"inputs": {}}'.encode("utf-16")), 400, P + "malformed-json", "NUL byte"),
        ("a NUL byte in the body", submit(b'{"inputs": {"seed": 1\x00}}'), 400, P + "malformed-json", "NUL byte"),
        ("an escaped NUL in a key", submit('{"inputs": {"se\\u0000ed": 1}}'), 400, P + "malformed-json", "NUL"),
        # JSON that is not a job
        ("JSON null", submit("null"), 422, P + "invalid-spec", "got null"),
        ("a string", submit('"pack me"'), 422, P + "invalid-spec", "got a string"),
        ("a number", submit("42"), 422, P + "invalid-spec", "got an integer"),
        ("an empty object", submit("{}"), 422, P + "invalid-spec", "missing"),
        ("inputs null", submit({"inputs": None}), 422, P + "invalid-spec", "null"),
        ("inputs an array", submit({"inputs": [1, 2]}), 422, P + "invalid-spec", "array"),
        ("domain nested in arrays", submit(spec(domain=[[[1]]])), 422, P + "invalid-spec", "object"),
        ("width 0", submit(spec(domain={"width": 0, "height": 10})), 422, P + "invalid-spec", "> 0"),
        ("width -0.0", submit(spec(domain={"width": -0.0, "height": 10})), 422, P + "invalid-spec", "> 0"),
        ("height negative", submit(spec(domain={"width": 10, "height": -5})), 422, P + "invalid-spec", "> 0"),
        ("width 1e-400 (0 once read)", submit('{"inputs": {"domain": {"width": 1e-400, "height": 10}, '
                                               '"distribution": {"kind": "constant", "radius": 1}}}'), 422,
         P + "invalid-spec", "> 0"),
        ("width a string", submit(spec(domain={"width": "10", "height": 10})), 422, P + "invalid-spec", "a string"),
        ("width true", submit(spec(domain={"width": True, "height": 10})), 422, P + "invalid-spec", "true"),
        ("radius 0", submit(spec(distribution={"kind": "constant", "radius": 0})), 422, P + "invalid-spec", "> 0"),
        ("radius negative", submit(spec(distribution={"kind": "constant", "radius": -1})), 422, P + "invalid-spec",
         "> 0"),
        ("uniform min 0", submit(spec(distribution={"kind": "uniform", "min": 0, "max": 1})), 422,
         P + "invalid-spec", "> 0"),
        ("uniform min negative", submit(spec(distribution={"kind": "uniform", "min": -1, "max": 1})), 422,
         P + "invalid-spec", "> 0"),
        ("a radius larger than the domain", submit(spec(distribution={"kind": "constant", "radius": 20})), 422,
         P + "invalid-spec", "fit"),
        ("kind a number", submit(spec(distribution={"kind": 3})), 422, P + "invalid-spec", "got an integer"),
        ("bins an object", submit(spec(distribution={"kind": "histogram", "bins": {"min": 1}})), 422,
         P + "invalid-spec", "array"),
        ("probabilities summing to 0.9", submit(spec(distribution=hist((0.5, 0.7, 0.5), (0.7, 0.9, 0.4)))), 422,
         P + "invalid-spec", "sum to 1"),
        ("probabilities summing to 1.1", submit(spec(distribution=hist((0.5, 0.7, 0.5), (0.7, 0.9, 0.6)))), 422,
         P + "invalid-spec", "sum to 1"),
        ("a negative probability", submit(spec(distribution=hist((0.5, 0.7, -0.2), (0.7, 0.9, 1.2)))), 422,
         P + "invalid-spec", ">= 0"),
        ("all probabilities 0", submit(spec(distribution=hist((0.5, 0.7, 0), (0.7, 0.9, 0)))), 422,
         P + "invalid-spec", "sum to 1"),
        ("a bin of zero width", submit(spec(distribution=hist((0.5, 0.5, 1)))), 422, P + "invalid-spec", "> "),
        ("20000 bins (more than --max-bins)", submit(spec(domain={"width": 1000, "height": 1000}, distribution=hist(
            *[(1 + i * 1e-5, 1 + (i + 1) * 1e-5, 1 / 20000) for i in range(20000)]))), 422, P + "job-too-big",
         "10000"),
        ("a histogram of 10^6 bins", submit(big_body, length=big_len), 413, P + "body-too-large", "--max-body"),
        ("joint negative", submit(spec(joint={"law": "constant", "value": -0.1})), 422, P + "invalid-spec", ">= 0"),
        ("joint power exponent a string", submit(spec(joint={"law": "power", "k": 1, "exponent": "2"})), 422,
         P + "invalid-spec", "a string"),
        ("seed negative", submit(spec(seed=-1)), 422, P + "invalid-spec", ">= 0"),
        ("seed 1e30", submit(spec(seed=1e30)), 422, P + "invalid-spec", "integer"),
        ("seed 2^64", submit('{"inputs": {"domain": {"width": 30, "height": 30}, "distribution": {"kind": '
                             '"constant", "radius": 0.9}, "seed": 18446744073709551616}}'), 400,
         P + "malformed-json", "too big integer"),
        ("level_band -1", submit(spec(front={"level_band": -1})), 422, P + "invalid-spec", "0 to 16"),
        ("more disks than --max-disks", submit(spec(domain={"width": 5000, "height": 5000})), 422,
         P + "job-too-big", "limit of 200000"),
        ("an unknown top-level field", submit({"inputs": spec()["inputs"], "priority": "high"}), 422,
         P + "invalid-spec", "unknown"),
        ("an unknown field in domain", submit(spec(domain={"width": 10, "height": 10, "depth": 3})), 422,
         P + "invalid-spec", "unknown"),
        ("an unknown field with a long non-ASCII name", submit(spec(**{long_name: 1})), 422, P + "invalid-spec",
         "unknown"),
        # the body as sent
        ("Content-Type text/plain", submit(spec(), content_type="text/plain"), 415, P + "unsupported-media-type",
         "application/json"),
        ("no Content-Type", submit(spec(), content_type=None), 415, P + "unsupported-media-type", "Content-Type"),
        ("Content-Type application/json-patch+json", submit(spec(), content_type="application/json-patch+json"),
         415, P + "unsupported-media-type", "json-patch"),
        ("Content-Length over --max-body", submit(b"{}", length=(1 << 20) + 1), 413, P + "body-too-large",
         "--max-body"),
        ("a chunked body over --max-body", b"POST " + EXEC.encode() + b" HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer "
         + b"%s\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n" + b"".join(
             b"10000\r\n" + b" " * 0x10000 + b"\r\n" for _ in range(20)) + b"0\r\n\r\n", 413, P + "body-too-large",
         "--max-body"),
        ("a body shorter than its Content-Length", submit(b'{"inputs": {}}', length=100), NONE, None, None),
        ("Content-Length not a number", submit(b"{}", length="ten"), MHD, 400, None),
        ("a chunk size that is not hex", b"POST " + EXEC.encode() + b" HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer "
         b"%s\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n{}\r\n0\r\n\r\n",
         MHD, 400, None),
        # paths and ids
        ("path traversal in an id", request("GET", "/jobs/../../etc/passwd"), 404, P + "not-found", "no resource"),
        ("an id of ..", request("GET", "/jobs/.."), 404, P + "not-found", "no resource"),
        ("escaped traversal", request("GET", "/jobs/%2e%2e%2f%2e%2e%2fetc%2fpasswd"), 404, P + "not-found",
         "no resource"),
        ("an escaped NUL as the id", request("GET", "/jobs/%00"), 404, P + "not-found", "no resource"),
        ("an escaped NUL after a real id", request("GET", f"/jobs/{ALICE_JOB}%00"), 404, P + "not-found",
         "no resource"),
        ("an id of 65 characters", request("GET", "/jobs/" + "a" * 65), 404, P + "not-found", "no resource"),
        ("raw bytes that are not UTF-8 in the path", request("GET", b"/jobs/\xff\xfe\xfd"), 404, P + "not-found",
         "no resource"),
        ("escaped bytes that are not UTF-8", request("GET", "/jobs/%ff%c3%28"), 404, P + "not-found", "no resource"),
        ("a control character in the path", request("GET", "/jobs/%0a%0dX-Injected:%20yes"), 404, P + "not-found",
         "no resource"),
        ("another owner's job", request("GET", f"/jobs/{BOB_JOB}"), 404, OGC + "no-such-job", "no job"),
        ("another owner's results", request("GET", f"/jobs/{BOB_JOB}/results?f=csv"), 404, OGC + "no-such-job",
         "no job"),
        ("deleting another owner's job", request("DELETE", f"/jobs/{BOB_JOB}"), 404, OGC + "no-such-job", "no job"),
        ("a path below the results", request("GET", f"/jobs/{ALICE_JOB}/results/x"), 404, P + "not-found",
         "no resource"),
        ("a double slash", request("GET", "//jobs"), 404, P + "not-found", "no resource"),
        # methods
        ("PUT on /jobs", request("PUT", "/jobs"), 405, P + "method-not-allowed", "allowed: GET, HEAD, OPTIONS"),
        ("PATCH on a job", request("PATCH", f"/jobs/{ALICE_JOB}"), 405, P + "method-not-allowed", "DELETE"),
        ("DELETE on a process", request("DELETE", "/processes/pack2d"), 405, P + "method-not-allowed", "allowed"),
        ("TRACE on /", request("TRACE", "/"), 405, P + "method-not-allowed", "allowed"),
        ("a lower-case method", request("get", "/health"), 405, P + "method-not-allowed", "get is not allowed"),
        ("POST on results", request("POST", f"/jobs/{ALICE_JOB}/results", body=b"{}"), 405,
         P + "method-not-allowed", "allowed"),
        ("GET on the execution", request("GET", EXEC), 405, P + "method-not-allowed", "POST"),
        # keys
        ("no key", request("GET", "/jobs", key=None), 401, P + "unauthorized", "Authorization: Bearer"),
        ("an unknown key", request("GET", "/jobs", key=None, headers=["Authorization: Bearer 0123456789abcdef"]),
         401, P + "unauthorized", "not valid"),
        ("Basic credentials", request("GET", "/jobs", key=None, headers=["Authorization: Basic YWxpY2U6eA=="]),
         401, P + "unauthorized", "Bearer KEY"),
        ("a key of 600 characters", request("GET", "/jobs", key=None, headers=["Authorization: Bearer " + "k" * 600]),
         401, P + "unauthorized", "at most 512"),
        ("a key that is not UTF-8", request("GET", "/jobs", key=None, headers=[b"Authorization: Bearer \xff\xfe"]),
         401, P + "unauthorized", "Bearer KEY"),
        ("a user key on /metrics", request("GET", "/metrics"), 403, P + "forbidden", "admin"),
        # headers and the request line
        ("a header of 9000 bytes", request("GET", "/health", headers=["X-Pad: " + "a" * 9000]), 431,
         P + "headers-too-large", "--max-header-bytes"),
        ("a query of 9000 bytes", request("GET", "/jobs?status=" + "s" * 9000), 414, P + "uri-too-long",
         "--max-header-bytes"),
        ("200 headers", request("GET", "/health", headers=[f"X-H{i}: {'v' * 40}" for i in range(200)]), 431,
         P + "headers-too-large", "--max-header-bytes"),
        ("a header of 100 KB", request("GET", "/health", headers=["X-Pad: " + "a" * 100000]), MHD, 431, None),
        ("a path of 100 KB", request("GET", "/" + "a" * 100000), MHD, 414, None),
        ("a header line without a colon", request("GET", "/health", headers=["NoColonHere"]), MHD, 400, None),
        ("HTTP/2.0 in the request line", request("GET", "/health", version=b"HTTP/2.0"), MHD, 505, None),
        ("a request line of garbage", b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03\r\n\r\n", NONE, None, None),
        ("an Accept no format matches", request("GET", f"/jobs/{ALICE_JOB}/results", headers=[b"Accept: \xff/\xfe"]),
         406, P + "not-acceptable", "text/csv"),
        # query parameters
        ("f=../../etc/passwd", request("GET", f"/jobs/{ALICE_JOB}/results?f=../../etc/passwd"), 400,
         P + "bad-parameter", "unknown format"),
        ("limit=1e3", request("GET", "/jobs?limit=1e3"), 400, P + "bad-parameter", "limit must be"),
        ("limit of 30 digits", request("GET", "/jobs?limit=" + "9" * 30), 400, P + "bad-parameter", "limit must be"),
        ("cursor=-1", request("GET", "/jobs?cursor=-1"), 400, P + "bad-parameter", "cursor must be"),
        ("wait=NaN", request("GET", f"/jobs/{ALICE_JOB}?wait=NaN"), 400, P + "bad-parameter", "wait must be"),
        ("status with an escaped NUL", request("GET", "/jobs?status=successful%00"), 400, P + "bad-parameter",
         "status must be"),
        ("status empty", request("GET", "/jobs?status="), 400, P + "bad-parameter", "status must be"),
        ("status not UTF-8", request("GET", "/jobs?status=%ff%fe"), 400, P + "bad-parameter", "status must be"),
    ]
    return c


def fill(data):
    """Puts the real job ids and alice's key into a case's bytes."""
    data = data.replace(ALICE_JOB.encode(), IDS["alice"].encode()).replace(BOB_JOB.encode(), IDS["bob"].encode())
    return data.replace(b"Bearer %s", b"Bearer " + KEYS["alice"].encode())


IDS = {}


def test(c, binary):
    api_doc = gpd.OpenAPI()
    directory = tempfile.mkdtemp(prefix="grainpackd-hostile-")
    KEYS.update(gpd.write_keys(os.path.join(directory, "keys"), {"alice": "user", "bob": "user", "root": "admin"}))
    # a short connection timeout: the requests that never end are closed sooner
    daemon = gpd.Daemon(binary, "--workers", "1", "--key-file", os.path.join(directory, "keys"),
                        "--max-disks", "200000", "--connection-timeout", "3", data_dir=directory)
    table = cases()
    try:
        daemon.start()
        for user in ("alice", "bob"):
            client = daemon.client(KEYS[user])
            IDS[user] = client.submit(gpd.small_spec(seed=len(user))).json()["jobID"]
            c.check(client.wait_final(IDS[user])["status"] == "successful", f"{user}'s job")
            client.close()
        answered = {}
        for what, data, status, ptype, word in table:
            try:
                raw = gpd.raw_exchange(daemon.port, fill(data))
            except OSError as e:
                c.check(False, f"{what}: {e!r}")
                continue
            got, headers, body = gpd.parse_raw(raw)
            if status == NONE:
                c.check(got is None, f"{what}: expected no answer, got {raw[:200]!r}")
                continue
            if status == MHD:
                c.check(got == ptype and "content-type" not in headers,
                        f"{what}: expected libmicrohttpd's own {ptype}, got {got} {headers}")
                continue
            answered[got] = answered.get(got, 0) + 1
            if not c.check(got == status and headers.get("content-type") == "application/problem+json",
                           f"{what}: expected {status} problem+json, got {raw[:300]!r}"):
                continue
            try:
                p = json.loads(body)
            except ValueError:
                c.check(False, f"{what}: body is not JSON: {body[:200]!r}")
                continue
            c.check(p.get("status") == status and p.get("type") == ptype,
                    f"{what}: problem {p.get('status')} {p.get('type')}, expected {status} {ptype}")
            c.check(word in p.get("detail", ""), f"{what}: detail {p.get('detail')!r} does not say {word!r}")
            errors = api_doc.validate(api_doc.schema("Problem"), p)
            c.check(not errors, f"{what}: not a Problem: {errors}")
        c.check(len(table) >= 60, f"only {len(table)} hostile cases")
        print(f"     {len(table)} hostile requests: answered {dict(sorted(answered.items()))}")

        client = daemon.client(KEYS["alice"])
        r = client.get("/health")
        c.check(r.status == 200 and r.json()["status"] == "ok", f"health after the hostile requests: {r}")
        r = client.get(f"/jobs/{IDS['alice']}/results?f=csv")
        c.check(r.status == 200 and r.body.startswith(b"x,y,r,R"), "alice's result intact")
        fresh = client.submit(gpd.small_spec(seed=99))
        c.check(fresh.status == 201 and client.wait_final(fresh.json()["jobID"])["status"] == "successful",
                "a job after the hostile requests")
        root = daemon.client(KEYS["root"])
        jobs = root.get("/jobs?limit=100").json()["jobs"]
        c.check(sorted(j["jobID"] for j in jobs) == sorted([IDS["alice"], IDS["bob"], fresh.json()["jobID"]]),
                f"hostile requests created or lost jobs: {[j['jobID'] for j in jobs]}")
        metrics = root.get("/metrics").body.decode()
        c.check(gpd.metric(metrics, "grainpack_http_requests_total", 'code="500"') is None, "no 500 in /metrics")
        client.close()
        root.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    finally:
        daemon.cleanup()
        gpd.remove_tree(directory)


if __name__ == "__main__":
    gpd.main(test)
