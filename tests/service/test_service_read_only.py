#!/usr/bin/env python3
"""test_service_read_only.py - the database becomes read-only under the running daemon,
for real: its files are made immutable (chattr +i), so that even the descriptors the
daemon holds open can no longer write. Submissions then get 503 storage-unwritable,
/health says degraded and unwritable, a job in flight keeps its outcome and nothing
crashes; once the files are writable again (chattr -i) the job is stored, new jobs are
accepted and run, and the database is sound.
Needs root and a file system with the immutable attribute that checks it on every write
(ext4, xfs, btrfs; not tmpfs); exits 77 (skipped) otherwise.
Usage: test_service_read_only.py GRAINPACKD"""

import os
import subprocess
import sys
import tempfile

import gpd

SKIP = 77
SUBMISSIONS = 50

# About 17000 disks: its result is written well after the files became read-only.
MEDIUM = {"inputs": {"domain": {"width": 250, "height": 250},
                     "distribution": {"kind": "constant", "radius": 0.9},
                     "joint": {"law": "constant", "value": 0.1}}}


def chattr(flag, *paths):
    return subprocess.run(["chattr", flag] + list(paths), capture_output=True, text=True)


def immutable_blocks_open_writers(directory):
    """Whether making a file immutable here stops a descriptor opened before from writing."""
    probe = os.path.join(directory, "probe")
    with open(probe, "wb", buffering=0) as f:
        f.write(b"a")
        if chattr("+i", probe).returncode != 0:
            return False
        try:
            f.write(b"b")
            blocked = False
        except OSError:
            blocked = True
        finally:
            chattr("-i", probe)
    os.unlink(probe)
    return blocked


def test(c, binary):
    directory = tempfile.mkdtemp(prefix="grainpackd-ro-")
    if not immutable_blocks_open_writers(directory):
        print("SKIP: cannot make a file immutable here (needs root, and ext4, xfs or btrfs)")
        os.rmdir(directory)
        sys.exit(SKIP)
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--workers", "1", data_dir=directory)
    files = [daemon.db_path, daemon.db_path + "-wal"]
    try:
        daemon.start()
        client = daemon.client()
        before = client.submit(gpd.small_spec(seed=1)).json()["jobID"]
        c.check(client.wait_final(before)["status"] == "successful", "a job before")

        medium = client.submit(MEDIUM).json()["jobID"]
        c.check(chattr("+i", *files).returncode == 0, "chattr +i")
        refused = None
        for s in range(SUBMISSIONS):
            r = client.submit(gpd.small_spec(seed=10 + s))
            if r.status != 201:
                refused = r
                break
        if gpd.check_problem(c, refused, 503, "urn:grainpack:problem:storage-unwritable", "cannot be written",
                             "a submission to a read-only database", retry_after=True):
            api.check(c, "POST", "/processes/{processId}/execution", refused)
        health = client.get("/health").json()
        c.check(health["status"] == "degraded" and health["database"] == "unwritable", f"health: {health}")
        c.check(client.get(f"/jobs/{before}/results?f=csv").status == 200, "results are still served")
        info = client.get(f"/jobs/{medium}").json()
        c.check(info["status"] in ("accepted", "running"), f"the medium job while read-only: {info}")
        c.check(daemon.proc.poll() is None, "grainpackd died on a read-only database")

        c.check(chattr("-i", *files).returncode == 0, "chattr -i")
        c.check(client.wait_final(medium)["status"] == "successful", "the medium job once writable")
        after = client.submit(gpd.small_spec(seed=999))
        c.check(after.status == 201, f"a submission once writable: {after}")
        c.check(client.wait_final(after.json()["jobID"])["status"] == "successful", "a job once writable")
        c.check(client.get("/health").json()["status"] == "ok", "health once writable")
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        final = gpd.check_store(c, daemon, "after the database was read-only")
        c.check(all(s == "successful" for s in final.values()), f"jobs: {final}")
    finally:
        chattr("-i", *[f for f in files if os.path.exists(f)])
        daemon.cleanup()
        gpd.remove_tree(directory)


if __name__ == "__main__":
    gpd.main(test)
