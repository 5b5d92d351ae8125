"""gpd.py - what the service tests share: the real grainpackd started on a free loopback
port with a real sqlite file in a temporary directory, a plain HTTP client, the checks
that a response matches its schema in openapi.yaml, and a few assertions.

Only Debian's python3 with python3-yaml and python3-jsonschema (see .ci/setup)."""

import gzip
import hashlib
import http.client
import json
import os
import re
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

import jsonschema
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLES = os.path.join(ROOT, "examples")

# How long a test waits for something that must happen (a daemon to start, a job to
# finish). These bound a broken run; no assertion depends on them.
STARTUP_LIMIT = 60.0
JOB_LIMIT = 300.0

# Contact tolerance of the engine (include/grainpack/disk.h, GP_CONTACT_RTOL).
CONTACT_RTOL = 1e-9


class Checks:
    """Counts failed checks; a test goes on after a failure so that one run shows all."""

    def __init__(self, name):
        self.name = name
        self.failures = 0

    def check(self, cond, what):
        if not cond:
            self.failures += 1
            print(f"FAIL {self.name}: {what}", file=sys.stderr, flush=True)
        return bool(cond)

    def done(self):
        if self.failures:
            print(f"{self.failures} check(s) failed in {self.name}", file=sys.stderr)
            return 1
        print(f"ok   {self.name}")
        return 0


class Response:
    def __init__(self, status, headers, body):
        self.status = status
        self.headers = {k.lower(): v for k, v in headers}
        self.body = body

    @property
    def content_type(self):
        return self.headers.get("content-type", "").split(";")[0].strip()

    def json(self):
        return json.loads(self.body)

    def __repr__(self):
        return f"<{self.status} {self.content_type} {self.body[:300]!r}>"


class Client:
    """One keep-alive HTTP/1.1 connection to the daemon (one per thread); with `key`,
    every request carries it as a Bearer key."""

    def __init__(self, port, timeout=120, key=None):
        self.port = port
        self.timeout = timeout
        self.conn = None
        self.key = key

    def request(self, method, path, body=None, headers=None, chunked=False):
        headers = dict(headers or {})
        if self.key and "Authorization" not in headers:
            headers["Authorization"] = f"Bearer {self.key}"
        for attempt in range(2):
            reused = self.conn is not None
            if self.conn is None:
                self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=self.timeout)
            try:
                if chunked:
                    # chunks without a length up front; with chunked="partial" the last
                    # chunk is never sent, so that the answer must come before the end
                    self.conn.putrequest(method, path)
                    for k, v in headers.items():
                        self.conn.putheader(k, v)
                    self.conn.putheader("Transfer-Encoding", "chunked")
                    self.conn.endheaders()
                    for i in range(0, len(body), 1024):
                        piece = body[i:i + 1024]
                        self.conn.send(b"%x\r\n%s\r\n" % (len(piece), piece))
                    if chunked != "partial":
                        self.conn.send(b"0\r\n\r\n")
                else:
                    self.conn.request(method, path, body=body, headers=headers)
                r = self.conn.getresponse()
                data = r.read()
                resp = Response(r.status, r.getheaders(), data)
                if resp.headers.get("connection", "").lower() == "close":
                    self.close()
                return resp
            except (ConnectionError, http.client.RemoteDisconnected, BrokenPipeError):
                # a kept-alive connection the daemon closed meanwhile: once more on a new
                # one (never for a fresh connection, so a POST is never sent twice)
                self.close()
                if attempt or not reused:
                    raise
        raise AssertionError("unreachable")

    def close(self):
        if self.conn is not None:
            self.conn.close()
            self.conn = None

    def get(self, path, headers=None):
        return self.request("GET", path, headers=headers)

    def post_json(self, path, body, content_type="application/json"):
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        headers = {"Content-Type": content_type} if content_type else {}
        return self.request("POST", path, body=data, headers=headers)

    def submit(self, spec, process="pack2d"):
        return self.post_json(f"/processes/{process}/execution", spec)

    def wait_final(self, job_id, limit=JOB_LIMIT):
        """Long-polls GET /jobs/{id}?wait=.. until the job is finished; its statusInfo."""
        deadline = time.monotonic() + limit
        while True:
            r = self.get(f"/jobs/{job_id}?wait=30")
            if r.status != 200:
                raise AssertionError(f"GET /jobs/{job_id}: {r}")
            info = r.json()
            if info["status"] in ("successful", "failed", "dismissed"):
                return info
            if time.monotonic() > deadline:
                raise AssertionError(f"job {job_id} not finished after {limit} s: {info}")

    def wait_status(self, job_id, statuses, limit=JOB_LIMIT):
        """Polls until the job's status is one of `statuses` (for running, which has no
        long-poll); returns its statusInfo."""
        deadline = time.monotonic() + limit
        while True:
            info = self.get(f"/jobs/{job_id}").json()
            if info["status"] in statuses:
                return info
            if time.monotonic() > deadline:
                raise AssertionError(f"job {job_id} never reached {statuses}: {info}")
            time.sleep(0.02)


class Daemon:
    """grainpackd in a temporary data directory, on a port it picks itself."""

    def __init__(self, binary, *args, data_dir=None, env=None, log_dir=None, wrapper=()):
        self.binary = binary
        self.args = list(args)
        self.own_dir = data_dir is None
        self.dir = data_dir or tempfile.mkdtemp(prefix="grainpackd-test-")
        self.log_dir = log_dir or self.dir  # elsewhere when the data directory may fill up
        self.wrapper = list(wrapper)
        self.db_path = os.path.join(self.dir, "grainpack.db")
        self.env = dict(os.environ, **(env or {}))
        self.proc = None
        self.port = None
        self.log_path = None
        self.runs = 0

    def start(self):
        ready = os.path.join(self.dir, "ready")
        if os.path.exists(ready):
            os.unlink(ready)
        self.runs += 1
        self.log_path = os.path.join(self.log_dir, f"daemon-{self.runs}.log")
        log = open(self.log_path, "w")
        self.proc = subprocess.Popen(
            self.wrapper + [self.binary, "--port", "0", "--data-dir", self.dir, "--ready-file", ready] + self.args,
            stdout=log, stderr=log, env=self.env)
        log.close()
        deadline = time.monotonic() + STARTUP_LIMIT
        while not os.path.exists(ready):
            if self.proc.poll() is not None:
                raise AssertionError(f"grainpackd exited with {self.proc.returncode}:\n{self.log()}")
            if time.monotonic() > deadline:
                raise AssertionError(f"grainpackd did not start:\n{self.log()}")
            time.sleep(0.01)
        self.port = int(open(ready).read())
        return self

    def client(self, key=None):
        return Client(self.port, key=key)

    def log(self):
        try:
            return open(self.log_path).read()
        except OSError:
            return ""

    def stop(self):
        """SIGTERM; returns the exit status (0 for a clean stop, and under AddressSanitizer
        also no leak)."""
        if self.proc is None:
            return None
        self.proc.send_signal(signal.SIGTERM)
        try:
            rc = self.proc.wait(timeout=STARTUP_LIMIT)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            rc = self.proc.wait()
        self.proc = None
        return rc

    def kill(self):
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait()
        self.proc = None

    def db(self):
        """A read-only connection to the daemon's database file."""
        return sqlite3.connect(f"file:{self.db_path}?mode=ro", uri=True, timeout=30)

    def wait_log(self, text, count=1, limit=JOB_LIMIT):
        """Waits until the log holds text (count times); a broken run fails after limit."""
        deadline = time.monotonic() + limit
        while self.log().count(text) < count:
            if self.proc is not None and self.proc.poll() is not None:
                raise AssertionError(f"grainpackd exited with {self.proc.returncode}:\n{self.log()[-3000:]}")
            if time.monotonic() > deadline:
                raise AssertionError(f"the log never said {text!r}:\n{self.log()[-3000:]}")
            time.sleep(0.02)

    def cleanup(self):
        if self.proc is not None:
            self.kill()
        if self.own_dir:
            remove_tree(self.dir)


def check_store(checks, daemon, what):
    """The database file is sound and holds no half-written result: integrity_check is
    ok; every successful job has its summary and its grains (a pack2d job's disks, 32
    bytes each, or a pack3d job's spheres, 40 bytes each, as many as its count, in chunks
    adding up to the section), its per-bin statistics and its stage timings; no other job
    has a result, and no chunk is left of a deleted one. Returns the {id: status} of every
    job."""
    db = daemon.db()
    try:
        checks.check(db.execute("PRAGMA integrity_check").fetchone()[0] == "ok", f"{what}: integrity_check")
        bad = db.execute(
            "SELECT j.id, j.status, j.count, d.bytes,"
            " (SELECT sum(length(c.data)) FROM result_chunks c WHERE c.section = d.id)"
            " FROM jobs j LEFT JOIN result_sections d ON d.job_id = j.id AND d.tag IN ('disks', 'spheres')"
            " WHERE (j.status = 'successful' AND (d.bytes IS NULL"
            "   OR d.bytes != (CASE d.tag WHEN 'disks' THEN 32 ELSE 40 END) * j.count"
            "   OR (j.count > 0 AND (SELECT sum(length(c.data)) FROM result_chunks c"
            "                        WHERE c.section = d.id) != d.bytes)"
            "   OR NOT EXISTS (SELECT 1 FROM result_sections p WHERE p.job_id = j.id"
            "                  AND p.tag = (CASE d.tag WHEN 'disks' THEN 'pack' ELSE 'pack3d' END))"
            "   OR NOT EXISTS (SELECT 1 FROM bin_stats b WHERE b.job_id = j.id)"
            "   OR NOT EXISTS (SELECT 1 FROM stage_timings t WHERE t.job_id = j.id)))"
            " OR (j.status != 'successful' AND EXISTS"
            "   (SELECT 1 FROM result_sections s WHERE s.job_id = j.id))").fetchall()
        checks.check(not bad, f"{what}: jobs with a half-written or stray result: {bad[:5]}")
        orphans = db.execute("SELECT count(*) FROM result_chunks WHERE section NOT IN"
                             " (SELECT id FROM result_sections)").fetchone()[0]
        checks.check(orphans == 0, f"{what}: {orphans} result chunks belong to no result")
        return dict(db.execute("SELECT id, status FROM jobs").fetchall())
    finally:
        db.close()  # (a `with` block would leave it open)


class OpenAPI:
    """The responses of openapi.yaml, to check real responses against."""

    def __init__(self, path=os.path.join(ROOT, "openapi.yaml")):
        with open(path) as f:
            self.doc = yaml.safe_load(f)
        self.resolver = jsonschema.RefResolver(base_uri="", referrer=self.doc)

    def _deref(self, node):
        while isinstance(node, dict) and "$ref" in node:
            node = self.resolver.resolve(node["$ref"])[1]
        return node

    def validate(self, schema, instance):
        """The list of error messages of instance against a schema of the document."""
        cls = jsonschema.Draft202012Validator
        validator = cls(schema, resolver=self.resolver, format_checker=cls.FORMAT_CHECKER)
        return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
                for e in validator.iter_errors(instance)]

    def schema(self, name):
        return self.doc["components"]["schemas"][name]

    def check(self, checks, method, template, resp, body_schema=True):
        """Checks that resp is documented for (method, template), with its required
        headers, and that its body matches the documented schema (unless body_schema is
        false: a large body another test checks); returns whether it did."""
        what = f"{method} {template} -> {resp.status}"
        op = self.doc["paths"].get(template, {}).get(method.lower())
        if not checks.check(op is not None, f"{what}: not in openapi.yaml"):
            return False
        documented = op["responses"].get(str(resp.status))
        if not checks.check(documented is not None, f"{what}: status not documented; {resp}"):
            return False
        documented = self._deref(documented)
        ok = True
        for header, spec in documented.get("headers", {}).items():
            spec = self._deref(spec)
            present = header.lower() in resp.headers
            if spec.get("required"):
                ok &= checks.check(present, f"{what}: no {header} header")
            if present:
                value = resp.headers[header.lower()]
                schema = self._deref(spec.get("schema", {}))
                if schema.get("type") == "integer" and value.isdigit():
                    value = int(value)
                errors = self.validate(schema, value)
                ok &= checks.check(not errors, f"{what}: header {header}: {errors[:2]}")
        content = documented.get("content")
        if not content:  # 304: no body
            return checks.check(resp.body == b"", f"{what}: a body where none is documented") and ok
        body = resp.body
        if resp.headers.get("content-encoding") == "gzip":
            body = gzip.decompress(body)
        media = content.get(resp.content_type)
        if not checks.check(media is not None,
                            f"{what}: content type {resp.content_type!r} not documented"):
            return False
        schema = media.get("schema", {})
        if not body_schema:
            return ok
        if resp.content_type.endswith("json"):
            try:
                body = json.loads(body)
            except ValueError as e:
                return checks.check(False, f"{what}: body is not JSON: {e}")
        else:
            body = body.decode("utf-8", "replace")
        errors = self.validate(schema, body)
        return checks.check(not errors, f"{what}: body does not match its schema: {errors[:3]}") and ok


RFC3339 = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z$")


def check_problem(checks, r, status, ptype, word, what, retry_after=False):
    """Checks that r is a problem+json of this status and type whose detail says `word`
    (and that has a Retry-After, when asked); returns whether it is."""
    ok = checks.check(r is not None and r.status == status and r.content_type == "application/problem+json",
                      f"{what}: {r}")
    if ok:
        p = r.json()
        ok = checks.check(p.get("type") == ptype and p.get("status") == status and word in p.get("detail", ""),
                          f"{what}: {p}")
        if retry_after:
            ok &= checks.check(int(r.headers.get("retry-after", 0)) > 0, f"{what}: no Retry-After")
    return ok


def remove_tree(directory):
    """Removes a test's temporary directory and the files in it."""
    for name in os.listdir(directory):
        os.unlink(os.path.join(directory, name))
    os.rmdir(directory)


def write_keys(path, users):
    """Writes a key file for users {name: role} with fresh random keys, as the README
    says; returns {name: key}."""
    keys = {}
    with open(path, "w") as f:
        for name, role in users.items():
            keys[name] = os.urandom(24).hex()
            f.write(f"sha256:{hashlib.sha256(keys[name].encode()).hexdigest()} {name} {role}\n")
    return keys


def raw_exchange(port, data, timeout=30, half_close=True):
    """Sends raw bytes on a new connection (then, with half_close, says it has no more to
    send) and returns what the daemon answers: everything up to the end of its first
    response, or up to its closing the connection, or b"" when it closes without one.
    (libmicrohttpd does not always close a half-closed connection after answering, so the
    end of a response is found by its Content-Length, not by the close.)"""
    import socket
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    out = b""
    try:
        try:
            s.sendall(data)
            if half_close:
                s.shutdown(socket.SHUT_WR)
        except OSError:
            pass  # the daemon may close before all is sent (too large): read what it said
        while True:
            try:
                piece = s.recv(65536)
            except (ConnectionResetError, socket.timeout):
                break
            if not piece:
                break
            out += piece
            status, headers, body = parse_raw(out)
            if status is not None and "content-length" in headers and len(body) >= int(headers["content-length"]):
                break
    finally:
        s.close()
    return out


def parse_raw(data):
    """(status, headers with lower-case names, body) of the first response in data, or
    (None, {}, b"") when there is none."""
    if not data.startswith(b"HTTP/1."):
        return None, {}, b""
    head, complete, rest = data.partition(b"\r\n\r\n")
    if not complete:
        return None, {}, b""
    lines = head.decode("latin-1").split("\r\n")
    status = int(lines[0].split()[1])
    headers = {}
    for line in lines[1:]:
        name, _, value = line.partition(":")
        headers[name.strip().lower()] = value.strip()
    length = int(headers.get("content-length", len(rest)))
    return status, headers, rest[:length]


def load_example(name):
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        return json.load(f)


def small_spec(seed=1, side=30):
    """A job that packs in milliseconds even under AddressSanitizer."""
    return {"inputs": {"domain": {"width": side, "height": side},
                       "distribution": {"kind": "constant", "radius": 0.9},
                       "joint": {"law": "constant", "value": 0.1}, "seed": seed}}


def big_spec(side=4000):
    """A job that runs for seconds: ~4.6 million disks for the default side."""
    return {"inputs": {"domain": {"width": side, "height": side},
                       "distribution": {"kind": "constant", "radius": 1.0}}}


def parse_csv(text):
    lines = text.strip().split("\n")
    return lines[0], [tuple(float(v) for v in line.split(",")) for line in lines[1:]]


def find_overlaps(disks, limit=10):
    """Pairs of disks (x, y, r, R) whose packing disks overlap beyond the engine's
    tolerance, found through a bucket grid."""
    if not disks:
        return []
    cell = 2 * max(d[3] for d in disks)
    grid = {}
    for i, d in enumerate(disks):
        grid.setdefault((int(d[0] // cell), int(d[1] // cell)), []).append(i)
    bad = []
    for i, a in enumerate(disks):
        cx, cy = int(a[0] // cell), int(a[1] // cell)
        for gx in (cx - 1, cx, cx + 1):
            for gy in (cy - 1, cy, cy + 1):
                for j in grid.get((gx, gy), ()):
                    if j <= i:
                        continue
                    b = disks[j]
                    reach = (a[3] + b[3]) * (1 - CONTACT_RTOL)
                    if (a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 < reach * reach:
                        bad.append((i, j))
                        if len(bad) >= limit:
                            return bad
    return bad


def metric(text, name, labels=""):
    """The value of the Prometheus sample named `name` whose labels include every one of
    `labels` (as written in the text format: 'status="successful"'), or None. Every series
    carries its node's label too, so the labels asked for are a subset, in any order."""
    wanted = set(re.findall(r'\w+="(?:[^"\\]|\\.)*"', labels))
    for line in text.splitlines():
        m = re.match(r'([a-zA-Z_:][\w:]*)(?:\{(.*)\})? (\S+)$', line)
        if m and m.group(1) == name and wanted <= set(re.findall(r'\w+="(?:[^"\\]|\\.)*"', m.group(2) or "")):
            return float(m.group(3))
    return None


def main(test):
    """Runs test(checks, *argv[1:]) and exits with its status."""
    name = os.path.splitext(os.path.basename(sys.argv[0]))[0]
    checks = Checks(name)
    try:
        test(checks, *sys.argv[1:])
    except AssertionError as e:
        checks.check(False, str(e))
    sys.exit(checks.done())
