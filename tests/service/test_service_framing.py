#!/usr/bin/env python3
"""test_service_framing.py - requests whose body framing a proxy could read otherwise
(RFC 9112), over raw sockets to the real daemon: Content-Length with Transfer-Encoding,
Content-Length twice, every Transfer-Encoding but exactly `chunked`, Transfer-Encoding
in HTTP/1.0, no Host in HTTP/1.1 or two of them, a header name with a space before its
colon, a query of more parameters than any route takes. Each is sent to several routes
(public and protected, the daemon having keys) with a second request smuggled after it
on the same connection, and each gets exactly one answer: 400 (501 for a coding other
than chunked) problem+json, `Connection: close`, the connection closed, the smuggled
request never run (no job created), before any route (a request without a key gets its
400, not a 401). Well-framed requests still work. The two that libmicrohttpd answers by
itself (a Content-Length that is not a number, or overflows 64 bits) are closed without
running the smuggled request either.
Usage: test_service_framing.py GRAINPACKD"""

import json
import os
import re
import socket
import tempfile

import gpd

P = "urn:grainpack:problem:"
SPEC = json.dumps(gpd.small_spec()).encode()
KEYS = {}


def smuggled():
    """A request that, if it ever ran, would create a job."""
    return (b"POST /processes/pack2d/execution HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer "
            + KEYS["alice"].encode() + b"\r\nContent-Type: application/json\r\nContent-Length: "
            + str(len(SPEC)).encode() + b"\r\n\r\n" + SPEC)


def chunked(body):
    return b"%x\r\n%s\r\n0\r\n\r\n" % (len(body), body)


def head(method, path, headers, version=b"HTTP/1.1", host=True, key=True):
    lines = [method + b" " + path + b" " + version]
    if host:
        lines.append(b"Host: localhost")
    if key:
        lines.append(b"Authorization: Bearer " + KEYS["alice"].encode())
    return b"\r\n".join(lines + headers) + b"\r\n\r\n"


def exchange(port, data, timeout=15):
    """Sends data, reads until the daemon closes; returns everything it sent."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    out = b""
    try:
        s.sendall(data)
        while True:
            try:
                piece = s.recv(65536)
            except ConnectionResetError:
                break
            except socket.timeout:
                out += b"<not closed>"
                break
            if not piece:
                break
            out += piece
    finally:
        s.close()
    return out


# (what, head headers, body, version, host, expected status, problem type)
CL = b"Content-Length: %d" % len(SPEC)
JSON = b"Content-Type: application/json"
CASES = [
    ("Content-Length and Transfer-Encoding", [JSON, CL, b"Transfer-Encoding: chunked"], chunked(SPEC), 400, "bad-framing"),
    ("Transfer-Encoding then Content-Length", [JSON, b"Transfer-Encoding: chunked", CL], chunked(SPEC), 400, "bad-framing"),
    ("Content-Length with a lower-case Transfer-Encoding", [JSON, CL, b"transfer-encoding: CHUNKED"], chunked(SPEC), 400, "bad-framing"),
    ("two different Content-Length", [JSON, CL, b"Content-Length: 5"], SPEC, 400, "bad-framing"),
    ("the same Content-Length twice", [JSON, CL, CL], SPEC, 400, "bad-framing"),
    ("Transfer-Encoding: identity, chunked", [JSON, b"Transfer-Encoding: identity, chunked"], chunked(SPEC), 501, "unsupported-transfer-coding"),
    ("Transfer-Encoding: gzip, chunked", [JSON, b"Transfer-Encoding: gzip, chunked"], chunked(SPEC), 501, "unsupported-transfer-coding"),
    ("Transfer-Encoding: gzip", [JSON, b"Transfer-Encoding: gzip"], SPEC, 400, "bad-framing"),
    ("Transfer-Encoding: chunked, gzip", [JSON, b"Transfer-Encoding: chunked, gzip"], chunked(SPEC), 400, "bad-framing"),
    ("Transfer-Encoding: chunked, chunked", [JSON, b"Transfer-Encoding: chunked, chunked"], chunked(SPEC), 400, "bad-framing"),
    ("Transfer-Encoding: , chunked", [JSON, b"Transfer-Encoding: , chunked"], chunked(SPEC), 400, "bad-framing"),
    ("Transfer-Encoding: deflate", [JSON, b"Transfer-Encoding: deflate"], SPEC, 400, "bad-framing"),
    ("two Transfer-Encoding: chunked", [JSON, b"Transfer-Encoding: chunked", b"Transfer-Encoding: chunked"], chunked(SPEC), 400, "bad-framing"),
    ("a space before the colon of Content-Length", [JSON, b"Content-Length : %d" % len(SPEC)], SPEC, 400, "bad-framing"),
    ("a tab before the colon of Transfer-Encoding", [JSON, b"Transfer-Encoding\t: chunked"], chunked(SPEC), 400, "bad-framing"),
    ("a header name with a separator", [b"X(y): 1"], b"", 400, "bad-framing"),
    ("two Host headers", [b"Host: other"], b"", 400, "bad-framing"),
    ("a Host with a space", [b"Host: a b"], b"", 400, "bad-framing"),
    ("a Host with a path", [b"Host: a/b"], b"", 400, "bad-framing"),
]


def answers(raw):
    """The number of status lines in what the daemon sent."""
    return len(re.findall(rb"(?:^|\r\n)HTTP/1\.[01] \d{3} ", raw))


def check_refused(c, what, raw, status, ptype):
    got, headers, body = gpd.parse_raw(raw)
    ok = c.check(got == status and headers.get("content-type") == "application/problem+json"
                 and headers.get("connection", "").lower() == "close", f"{what}: {raw[:300]!r}")
    if ok:
        p = json.loads(body)
        c.check(p["type"] == P + ptype and p["status"] == status and p["detail"], f"{what}: {p}")
    # exactly one answer, and the connection closed after it
    c.check(answers(raw) == 1 and not raw.endswith(b"<not closed>"), f"{what}: not one answer then close: {raw[:400]!r}")


def test(c, binary):
    directory = tempfile.mkdtemp(prefix="grainpackd-framing-")
    KEYS.update(gpd.write_keys(os.path.join(directory, "keys"), {"alice": "user", "root": "admin"}))
    daemon = gpd.Daemon(binary, "--key-file", os.path.join(directory, "keys"), data_dir=directory)
    try:
        daemon.start()
        root = daemon.client(KEYS["root"])
        jobs_before = len(root.get("/jobs?limit=1000").json()["jobs"])
        routes = [(b"POST", b"/processes/pack2d/execution"), (b"GET", b"/health"),
                  (b"GET", b"/jobs"), (b"DELETE", b"/jobs/00000000-0000-4000-8000-000000000000")]
        n = 0
        for what, headers, body, status, ptype in CASES:
            for method, path in routes:
                for key in (True, False):
                    host = not any(h.startswith(b"Host: ") for h in headers) or what == "two Host headers"
                    data = head(method, path, headers, key=key, host=host) + body + smuggled()
                    check_refused(c, f"{what}, {method.decode()} {path.decode()}{'' if key else ', no key'}",
                                  exchange(daemon.port, data), status, ptype)
                    n += 1
        # the version and Host rules
        for what, data, status in (
                ("HTTP/1.1 without Host", head(b"GET", b"/health", [], host=False), 400),
                ("HTTP/1.1 without Host, a job", head(b"POST", b"/processes/pack2d/execution", [JSON, CL], host=False) + SPEC, 400),
                ("HTTP/1.0 with Transfer-Encoding", head(b"POST", b"/processes/pack2d/execution",
                                                          [JSON, b"Transfer-Encoding: chunked"], version=b"HTTP/1.0") + chunked(SPEC), 400)):
            check_refused(c, what, exchange(daemon.port, data + smuggled()), status, "bad-framing")
            n += 1
        raw = exchange(daemon.port, head(b"GET", b"/health", [], version=b"HTTP/1.0", host=False))
        c.check(gpd.parse_raw(raw)[0] == 200, f"HTTP/1.0 without Host is fine: {raw[:200]!r}")
        # more query parameters than any route takes: refused, whatever they are
        for count in (65, 300, 1000, 3000):
            query = "&".join(f"p{i}=1" for i in range(count))
            raw = exchange(daemon.port, head(b"GET", b"/jobs?" + query.encode(), []) + smuggled(), timeout=15)
            got, headers, body = gpd.parse_raw(raw)
            c.check(got == 400 and json.loads(body)["type"] == P + "bad-parameter"
                    and f"{count} parameters" in json.loads(body)["detail"] and answers(raw) == 1,
                    f"{count} query parameters: {raw[:300]!r}")
            n += 1
        query = "&".join(["limit=3"] + [f"p{i}=1" for i in range(63)])
        r = root.get("/jobs?" + query)
        c.check(r.status == 200, f"64 query parameters are fine: {r}")
        # libmicrohttpd's own answers: closed too, nothing smuggled runs
        for what, length, status in (("Content-Length not a number", b"ten", 400),
                                     ("Content-Length over 64 bits", b"99999999999999999999999", 413)):
            raw = exchange(daemon.port, head(b"POST", b"/processes/pack2d/execution",
                                             [JSON, b"Content-Length: " + length]) + SPEC + smuggled())
            c.check(gpd.parse_raw(raw)[0] == status and not raw.endswith(b"<not closed>"), f"{what}: {raw[:300]!r}")
            n += 1
        print(f"     {n} badly framed requests refused")
        # nothing smuggled ran: no job was created
        c.check(len(root.get("/jobs?limit=1000").json()["jobs"]) == jobs_before, "a smuggled request created a job")
        # well-framed requests work: Content-Length, chunked (any case), keep-alive
        for what, data in (("Content-Length", head(b"POST", b"/processes/pack2d/execution", [JSON, CL]) + SPEC),
                           ("chunked", head(b"POST", b"/processes/pack2d/execution",
                                            [JSON, b"Transfer-Encoding: chunked"]) + chunked(SPEC)),
                           ("Chunked", head(b"POST", b"/processes/pack2d/execution",
                                            [JSON, b"Transfer-Encoding: Chunked"]) + chunked(SPEC))):
            raw = gpd.raw_exchange(daemon.port, data)
            c.check(gpd.parse_raw(raw)[0] == 201, f"a well-framed POST ({what}): {raw[:300]!r}")
        alice = daemon.client(KEYS["alice"])
        for i in range(3):
            c.check(alice.get("/jobs").status == 200 and alice.conn is not None, "keep-alive after the refusals")
        alice.close()
        root.close()
        c.check(daemon.stop() == 0, "stop")
    finally:
        daemon.cleanup()
        gpd.remove_tree(directory)


if __name__ == "__main__":
    gpd.main(test)
