#!/usr/bin/env python3
"""test_service_access.py - access control with API keys: the README's command makes a
working key; without a key the jobs and the metrics are 401 (problem+json, with
WWW-Authenticate) while what the service is stays public; a job is seen only by the key
that submitted it (others get 404, and do not see it in /jobs) and by admins, who also
dismiss it; /metrics is admin-only (403); the per-key limit answers 429; SIGHUP reads
the key file again (a rotated key keeps its jobs, a revoked one is refused, a broken file
keeps the old keys); /jobs page cursors are opaque tokens of one viewer; a daemon
without keys refuses a non-loopback address unless told.
Usage: test_service_access.py GRAINPACKD"""

import os
import re
import signal
import subprocess
import tempfile
import time

import gpd

PROTECTED = [("GET", "/jobs", "/jobs"), ("GET", "/metrics", "/metrics"),
             ("GET", "/jobs/00000000-0000-4000-8000-000000000000", "/jobs/{jobId}")]
PUBLIC = ["/", "/conformance", "/processes", "/processes/pack2d", "/health", "/openapi.yaml"]


def readme_key(directory):
    """Runs the README's key block in directory; returns the key it made."""
    with open(os.path.join(gpd.ROOT, "README.md")) as f:
        block = re.search(r"<!-- keys:begin -->\s*```sh\n(.*?)```\s*<!-- keys:end -->", f.read(), re.S)
    assert block, "README.md has no keys block"
    out = subprocess.run(["bash", "-euo", "pipefail", "-c", block.group(1) + 'printf %s "$key"'],
                         cwd=directory, capture_output=True, text=True, check=True)
    return out.stdout


def append_keys(path, users):
    """Appends fresh keys for {name: role} to the key file; returns {name: key}."""
    tmp = path + ".more"
    keys = gpd.write_keys(tmp, users)
    with open(tmp) as f, open(path, "a") as out:
        out.write(f.read())
    os.unlink(tmp)
    return keys


def check_unauthorized(c, api, what, r, method, template, error=None):
    c.check(r.status == 401 and r.content_type == "application/problem+json",
            f"{what}: {r}")
    if r.status == 401:
        c.check(r.json()["type"] == "urn:grainpack:problem:unauthorized", f"{what}: type")
        auth = r.headers.get("www-authenticate", "")
        c.check(auth.startswith('Bearer realm="grainpack"'), f"{what}: WWW-Authenticate {auth!r}")
        if error:
            c.check(f'error="{error}"' in auth, f"{what}: {auth!r} has no error={error}")
        api.check(c, method, template, r)


def test_keys(c, api, binary):
    directory = tempfile.mkdtemp(prefix="grainpackd-keys-")
    key_file = os.path.join(directory, "keys")
    keys = {"alice": readme_key(directory)}
    c.check(re.fullmatch(r"[A-Za-z0-9_-]{43}", keys["alice"]), f"README key {keys['alice']!r}")
    with open(key_file) as f:
        c.check(f.read().endswith(" alice user\n"), "README line")
    keys.update(append_keys(key_file, {"bob": "user", "root": "admin"}))
    daemon = gpd.Daemon(binary, "--workers", "1", "--key-file", key_file, "--max-jobs-per-key", "2",
                        "--max-disks", "10000000", data_dir=directory)
    try:
        daemon.start()
        c.check("3 API keys read from" in daemon.log(), "start-up log counts the keys")
        anon = daemon.client()
        for path in PUBLIC:
            r = anon.get(path)
            c.check(r.status == 200, f"public {path} without a key: {r}")
        c.check(anon.get("/health").json()["access"] == "keys", "health says keys")
        for method, path, template in PROTECTED:
            check_unauthorized(c, api, f"{method} {path} without a key", anon.request(method, path), method,
                               template)
        r = anon.submit(gpd.small_spec())
        check_unauthorized(c, api, "submission without a key", r, "POST", "/processes/{processId}/execution")
        r = anon.get("/jobs", headers={"Authorization": "Bearer not-a-key-of-ours"})
        check_unauthorized(c, api, "unknown key", r, "GET", "/jobs", "invalid_token")
        r = anon.get("/jobs", headers={"Authorization": f"Basic {keys['alice']}"})
        check_unauthorized(c, api, "Basic instead of Bearer", r, "GET", "/jobs", "invalid_request")
        r = anon.get("/jobs", headers={"Authorization": f"Bearer {keys['alice']}x"})
        check_unauthorized(c, api, "a key one character off", r, "GET", "/jobs", "invalid_token")

        alice, bob, root = (daemon.client(keys[u]) for u in ("alice", "bob", "root"))
        r = alice.submit(gpd.small_spec(seed=3))
        c.check(r.status == 201, f"alice submits: {r}")
        job = r.json()["jobID"]
        c.check(alice.wait_final(job)["status"] == "successful", "alice's job runs")
        for path in (f"/jobs/{job}", f"/jobs/{job}/results", f"/jobs/{job}/statistics"):
            r = bob.get(path)
            c.check(r.status == 404 and r.json()["type"].endswith("no-such-job"), f"bob GET {path}: {r}")
            c.check(alice.get(path).status == 200, f"alice GET {path}")
            c.check(root.get(path).status == 200, f"root GET {path}")
        c.check(bob.request("DELETE", f"/jobs/{job}").status == 404, "bob cannot delete alice's job")
        c.check(job not in [j["jobID"] for j in bob.get("/jobs").json()["jobs"]], "bob's list")
        c.check(job in [j["jobID"] for j in alice.get("/jobs").json()["jobs"]], "alice's list")
        c.check(job in [j["jobID"] for j in root.get("/jobs").json()["jobs"]], "root's list")
        r = alice.get("/metrics")
        c.check(r.status == 403 and r.json()["type"] == "urn:grainpack:problem:forbidden"
                and "admin" in r.json()["detail"], f"alice on /metrics: {r}")
        api.check(c, "GET", "/metrics", r)
        c.check(root.get("/metrics").status == 200, "root on /metrics")
        with daemon.db() as db:
            owner = db.execute("SELECT owner FROM jobs WHERE id = ?", (job,)).fetchone()
        c.check(owner == ("alice",), f"owner in the database: {owner}")
        c.check(f"alice POST /processes/pack2d/execution 201" in daemon.log(), "the log names the user")

        # the per-key limit: a running and a queued job are two, the third is refused
        big = alice.submit(gpd.big_spec()).json()["jobID"]
        alice.wait_status(big, ("running",))
        c.check(alice.submit(gpd.small_spec(seed=4)).status == 201, "alice's second active job")
        r = alice.submit(gpd.small_spec(seed=5))
        c.check(r.status == 429 and r.json()["type"] == "urn:grainpack:problem:too-many-jobs"
                and "--max-jobs-per-key" in r.json()["detail"] and int(r.headers.get("retry-after", 0)) > 0,
                f"alice's third active job: {r}")
        api.check(c, "POST", "/processes/{processId}/execution", r)
        c.check(bob.submit(gpd.small_spec(seed=6)).status == 201, "bob is not limited by alice")
        r = root.request("DELETE", f"/jobs/{big}")
        c.check(r.status == 200 and r.json()["status"] == "dismissed", f"root dismisses alice's job: {r}")
        c.check(alice.submit(gpd.small_spec(seed=7)).status == 201, "alice after the dismissal")

        # SIGHUP: bob's key rotated, carol added, root kept; alice removed
        bob_jobs = [j["jobID"] for j in bob.get("/jobs").json()["jobs"]]
        os.rename(key_file, key_file + ".old")
        with open(key_file + ".old") as f:
            root_line = [line for line in f if line.endswith(" root admin\n")]
        new = gpd.write_keys(key_file, {"bob": "user", "carol": "user"})
        with open(key_file, "a") as f:
            f.writelines(root_line)
        daemon.proc.send_signal(signal.SIGHUP)
        daemon.wait_log("3 API keys read again")
        bob_old, bob_new, carol = daemon.client(keys["bob"]), daemon.client(new["bob"]), daemon.client(new["carol"])
        check_unauthorized(c, api, "bob's old key after rotation", bob_old.get("/jobs"), "GET", "/jobs")
        check_unauthorized(c, api, "alice's revoked key", alice.get("/jobs"), "GET", "/jobs")
        c.check([j["jobID"] for j in bob_new.get("/jobs").json()["jobs"]] == bob_jobs,
                "bob's new key sees bob's jobs")
        c.check(carol.get("/jobs").json()["jobs"] == [], "carol sees no job")
        c.check(root.get("/metrics").status == 200, "root kept")
        with open(key_file, "a") as f:
            f.write("sha256:nothex dave user\n")
        daemon.proc.send_signal(signal.SIGHUP)
        daemon.wait_log("the previous keys stay in use")
        c.check(f"{key_file}:4: " in daemon.log(), "the reload error names the line")
        c.check(carol.get("/jobs").status == 200, "carol after a broken reload")
        for client in (anon, alice, bob, root, bob_old, bob_new, carol):
            client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")

        # a bad key file at start-up: the daemon does not start, and says where
        broken = gpd.Daemon(binary, "--key-file", key_file)
        try:
            broken.start()
            c.check(False, "grainpackd started with a broken key file")
        except AssertionError as e:
            c.check(f"{key_file}:4: " in str(e) and "hex" in str(e), f"broken key file: {e}")
        finally:
            broken.cleanup()
    finally:
        daemon.cleanup()
        gpd.remove_tree(directory)


def page_through(client, path):
    """Follows the next links from path; returns (job ids in order, the cursors seen)."""
    ids, cursors = [], []
    while path:
        r = client.get(path)
        assert r.status == 200, f"GET {path}: {r}"
        ids += [j["jobID"] for j in r.json()["jobs"]]
        nxt = [link["href"] for link in r.json()["links"] if link["rel"] == "next"]
        path = nxt[0] if nxt else None
        if path:
            cursors.append(re.search(r"[?&]cursor=([^&]*)", path).group(1))
    return ids, cursors


def test_cursors(c, api, binary):
    """/jobs cursors are opaque and per viewer: alice's pages hold her jobs only, in order;
    her cursor is a token that shows no sequence number, is refused to bob and to an admin,
    refused when altered, and refused after a restart (it is valid until the daemon stops)."""
    directory = tempfile.mkdtemp(prefix="grainpackd-cursors-")
    key_file = os.path.join(directory, "keys")
    keys = gpd.write_keys(key_file, {"alice": "user", "bob": "user", "root": "admin"})
    daemon = gpd.Daemon(binary, "--workers", "1", "--key-file", key_file, data_dir=directory)
    try:
        daemon.start()
        alice, bob, root = (daemon.client(keys[u]) for u in ("alice", "bob", "root"))
        mine = []
        for i in range(4):  # bob submits between alice's jobs
            mine.append(alice.submit(gpd.small_spec(seed=i)).json()["jobID"])
            for k in range(2):
                bob.submit(gpd.small_spec(seed=10 + 2 * i + k))
        ids, cursors = page_through(alice, "/jobs?limit=1")
        c.check(ids == mine[::-1], f"alice's pages: {ids}")
        c.check(len(cursors) == 3 and all(re.fullmatch(r"[0-9a-f]{32}", t) for t in cursors),
                f"alice's cursors are not 32-hex tokens: {cursors}")
        with daemon.db() as db:
            seqs = [str(s) for (s,) in db.execute("SELECT seq FROM jobs WHERE owner = 'alice'")]
        c.check(not any(t in seqs for t in cursors), "a cursor is a sequence number")
        r = alice.get(f"/jobs?limit=1&cursor={cursors[0]}")
        c.check(r.status == 200 and [j["jobID"] for j in r.json()["jobs"]] == [mine[2]], f"alice reuses her cursor: {r}")
        altered = cursors[0][:-1] + ("0" if cursors[0][-1] != "0" else "1")
        for who, client, token in (("bob", bob, cursors[0]), ("root", root, cursors[0]),
                                   ("alice, altered", alice, altered), ("alice, a number", alice, "7")):
            r = client.get(f"/jobs?limit=1&cursor={token}")
            c.check(r.status == 400 and r.json()["type"] == "urn:grainpack:problem:bad-parameter"
                    and "next link" in r.json()["detail"], f"{who} with alice's cursor: {r}")
            api.check(c, "GET", "/jobs", r)
        # root sees every job, a page at a time, with cursors of its own
        ids, root_cursors = page_through(root, "/jobs?limit=5")
        c.check(len(ids) == 12 and len(set(ids)) == 12 and set(mine) <= set(ids), f"root's pages: {ids}")
        c.check(not set(root_cursors) & set(cursors), "root and alice share cursors")
        for client in (alice, bob, root):
            client.close()
        c.check(daemon.stop() == 0, "stop")
        daemon.start()
        alice = daemon.client(keys["alice"])
        r = alice.get(f"/jobs?limit=1&cursor={cursors[0]}")
        c.check(r.status == 400 and "restarts" in r.json()["detail"], f"a cursor after a restart: {r}")
        ids, again = page_through(alice, "/jobs?limit=1")
        c.check(ids == mine[::-1] and not set(again) & set(cursors), "new cursors after a restart")
        alice.close()
        c.check(daemon.stop() == 0, "second stop")
    finally:
        daemon.cleanup()
        gpd.remove_tree(directory)


def test_open_mode(c, binary):
    # without keys: loopback only, unless --insecure-open
    r = subprocess.run([binary, "--host", "0.0.0.0", "--port", "0"], capture_output=True, text=True, timeout=60)
    c.check(r.returncode == 2 and "refusing to listen on 0.0.0.0 without a key file" in r.stderr
            and "--insecure-open" in r.stderr, f"open on 0.0.0.0: {r.returncode} {r.stderr}")
    daemon = gpd.Daemon(binary, "--host", "0.0.0.0", "--insecure-open")
    try:
        daemon.start()
        c.check(daemon.client().get("/health").json()["access"] == "open", "open daemon's health")
        c.check("the service is open to anyone" in daemon.log(), "open daemon's log")
        c.check(daemon.stop() == 0, "open daemon stop")
    finally:
        daemon.cleanup()


def test(c, binary):
    api = gpd.OpenAPI()
    test_keys(c, api, binary)
    test_cursors(c, api, binary)
    test_open_mode(c, binary)


if __name__ == "__main__":
    gpd.main(test)
