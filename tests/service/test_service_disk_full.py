#!/usr/bin/env python3
"""test_service_disk_full.py - the database's disk fills up, for real: the data directory
is a small tmpfs (mounted in a private mount namespace, so nothing outside sees it or is
left behind) that a ballast file fills. Submissions then get 503 storage-full with
Retry-After, /health says degraded and full, a job that finished meanwhile keeps its
result (the worker retries) and nothing crashes; once the ballast is gone, the job's
result is stored, new jobs are accepted and run, and the database is sound.
Needs root or unprivileged user namespaces (unshare); exits 77 (skipped) without them.
Usage: test_service_disk_full.py GRAINPACKD"""

import os
import shutil
import subprocess
import sys
import tempfile

import gpd

INNER = "GRAINPACKD_TEST_IN_NAMESPACE"
SKIP = 77
TMPFS_BYTES = 4 << 20
ROOM = 150 << 10  # left free by the ballast: small writes fit, a result of 500 KB does not
SUBMISSIONS = 3000  # a bound on the submissions it takes to exhaust the room

# About 17000 disks: a result blob of about 550 KB.
MEDIUM = {"inputs": {"domain": {"width": 250, "height": 250},
                     "distribution": {"kind": "constant", "radius": 0.9},
                     "joint": {"law": "constant", "value": 0.1}}}


def reexec_in_namespace():
    """Runs this test again in a private mount namespace; returns its exit status."""
    unshare = shutil.which("unshare")
    if not unshare:
        print("SKIP: no unshare(1)")
        return SKIP
    flags = ["--mount", "--propagation", "private"]
    if os.geteuid() != 0:
        flags = ["--user", "--map-root-user"] + flags
    env = dict(os.environ, **{INNER: "1"})
    probe = subprocess.run([unshare] + flags + ["true"], capture_output=True, text=True)
    if probe.returncode != 0:
        print(f"SKIP: cannot make a mount namespace here: {probe.stderr.strip()}")
        return SKIP
    return subprocess.run([unshare] + flags + [sys.executable] + sys.argv, env=env).returncode


def fill(path, room):
    """Writes a ballast file leaving about `room` bytes free on path's file system."""
    st = os.statvfs(os.path.dirname(path))
    size = st.f_bavail * st.f_frsize - room
    with open(path, "wb") as f:
        chunk = b"\0" * (1 << 16)
        while size > 0:
            size -= f.write(chunk[:min(size, len(chunk))])


def test(c, binary):
    base = tempfile.mkdtemp(prefix="grainpackd-full-")
    data = os.path.join(base, "data")
    os.mkdir(data)
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={TMPFS_BYTES}", "tmpfs", data],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        print(f"SKIP: cannot mount a tmpfs: {mounted.stderr.strip()}")
        os.rmdir(data)
        os.rmdir(base)
        sys.exit(SKIP)
    api = gpd.OpenAPI()
    ballast = os.path.join(data, "ballast")
    daemon = gpd.Daemon(binary, "--workers", "1", data_dir=data, log_dir=base)
    try:
        daemon.start()
        client = daemon.client()
        before = [client.submit(gpd.small_spec(seed=s)).json()["jobID"] for s in range(3)]
        for job in before:
            c.check(client.wait_final(job)["status"] == "successful", "a job before the disk fills")

        fill(ballast, ROOM)
        r = client.submit(MEDIUM)
        c.check(r.status == 201, f"the medium job fits (its spec is small): {r}")
        medium = r.json()["jobID"]
        daemon.wait_log(f"job {medium}: cannot store its outcome (the disk is full)")
        accepted, full = [], None
        for s in range(SUBMISSIONS):
            r = client.submit(gpd.small_spec(seed=100 + s))
            if r.status == 201:
                accepted.append(r.json()["jobID"])
                continue
            full = r
            break
        if gpd.check_problem(c, full, 503, "urn:grainpack:problem:storage-full", "disk is full",
                             f"after {len(accepted)} submissions on a full disk", retry_after=True):
            api.check(c, "POST", "/processes/{processId}/execution", full)
        health = client.get("/health")
        c.check(health.status == 200 and health.json()["status"] == "degraded"
                and health.json()["database"] == "full", f"health while full: {health}")
        api.check(c, "GET", "/health", health)
        info = client.get(f"/jobs/{medium}").json()
        c.check(info["status"] == "running", f"the medium job while full: {info}")
        c.check(daemon.proc.poll() is None, "grainpackd died on a full disk")

        os.unlink(ballast)  # space returns
        info = client.wait_final(medium)
        c.check(info["status"] == "successful", f"the medium job once there is room: {info}")
        lines = client.get(f"/jobs/{medium}/results?f=csv").body.count(b"\n")
        c.check(lines > 10000, f"the medium job's result has {lines} lines")
        after = client.submit(gpd.small_spec(seed=99999))
        c.check(after.status == 201, f"a submission once there is room: {after}")
        for job in before + accepted + [after.json()["jobID"]]:
            c.check(client.wait_final(job)["status"] == "successful", f"job {job} after the disk was full")
        c.check(client.get("/health").json()["status"] == "ok", "health once there is room")
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        final = gpd.check_store(c, daemon, "after the disk was full")
        c.check(len(final) == len(before) + len(accepted) + 2 and all(s == "successful" for s in final.values()),
                f"jobs in the database: {final}")
        print(f"     {len(accepted)} small jobs accepted before the disk was full, then 503; all run")
    finally:
        daemon.cleanup()
        subprocess.run(["umount", data])  # the tmpfs and all on it goes
        os.rmdir(data)
        for name in os.listdir(base):
            os.unlink(os.path.join(base, name))
        os.rmdir(base)


if __name__ == "__main__":
    if os.environ.get(INNER) != "1":
        sys.exit(reexec_in_namespace())
    gpd.main(test)
