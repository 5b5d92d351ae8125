#!/usr/bin/env python3
"""test_web_browser.py - the web page in a real browser: starts grainpackd twice (open,
and with API keys for alice and bob) and runs tests/browser/page_test.mjs, which drives
Debian's chromium headless through the page (playwright-core and axe-core from npm,
pinned in tests/browser/package-lock.json). Then checks what the browser left: the CSV
files it downloaded parse, hold the job's disks (as many as its statistics say, none
overlapping) and equal the service's own CSV; the 3D job's .tess is the service's and a
valid tessellation of its box (tests/tess_reader.py); the long job is dismissed and the one deleted
from My jobs is gone from the database; alice's job is hers. Screenshots, the downloads
and outcome.json (first paint, transfer size, axe counts) are left in OUT_DIR.
Usage: test_web_browser.py GRAINPACKD NODE CHROMIUM OUT_DIR"""

import json
import os
import subprocess
import sys
import tempfile

import gpd

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import tess_reader  # noqa: E402

BROWSER_DIR = os.path.join(gpd.ROOT, "tests", "browser")
# The long job: a square of this side filled with disks of radius 0.5 (about 1.9 million
# expected, under the default --max-disks) and balanced: it runs for many seconds.
LONG_SIDE = 1300
# The whole browser run must end within this (s); it takes about a minute.
BROWSER_LIMIT = 600


def check_csv(c, client, job, path, what):
    with open(path) as f:
        text = f.read()
    header, disks = gpd.parse_csv(text)
    c.check(header == "x,y,r,R", f"{what}: CSV header {header!r}")
    stats = client.get(f"/jobs/{job}/statistics").json()
    c.check(len(disks) == stats["count"], f"{what}: {len(disks)} disks in the CSV, {stats['count']} in the statistics")
    c.check(not gpd.find_overlaps(disks), f"{what}: overlapping disks in the downloaded CSV")
    c.check(text == client.get(f"/jobs/{job}/results?f=csv").body.decode(), f"{what}: the download is not the service's CSV")


def check_tess(c, client, job, path):
    """The .tess the browser saved (the 3D job of page_test.mjs, a box of 6 x 5 x 4): the
    service's bytes, and for the independent reader a valid tessellation of the box with a
    polyhedron a sphere."""
    with open(path, "rb") as f:
        body = f.read()
    c.check(body == client.get(f"/jobs/{job}/results?f=tess").body, "the 3D job's .tess is not the service's")
    count = client.get(f"/jobs/{job}/statistics").json()["count"]
    t = tess_reader.read(path)
    bad = tess_reader.check(t, (6, 5, 4))
    c.check(not bad and t.ncells == count, f".tess: {t.ncells} cells for {count} spheres; {bad[:3]}")


def test(c, binary, node, chromium, out_dir):
    if not os.path.exists(chromium):
        c.check(False, f"{chromium} is missing: bash .ci/setup installs Debian's chromium")
        return
    if not os.path.isdir(os.path.join(BROWSER_DIR, "node_modules", "playwright-core")):
        c.check(False, "tests/browser/node_modules is missing: bash .ci/setup installs it (npm ci)")
        return
    os.makedirs(out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory() as work:
        key_file = os.path.join(work, "keys")
        keys = gpd.write_keys(key_file, {"alice": "user", "bob": "user"})
        open_daemon = gpd.Daemon(binary)
        keys_daemon = gpd.Daemon(binary, "--key-file", key_file)
        try:
            open_daemon.start()
            keys_daemon.start()
            config = {"open": f"http://127.0.0.1:{open_daemon.port}", "keys": f"http://127.0.0.1:{keys_daemon.port}",
                      "alice": keys["alice"], "bob": keys["bob"], "chromium": chromium, "out": out_dir,
                      "examples": gpd.EXAMPLES, "long_side": LONG_SIDE}
            config_path = os.path.join(work, "config.json")
            with open(config_path, "w") as f:
                json.dump(config, f)
            run = subprocess.run([node, os.path.join(BROWSER_DIR, "page_test.mjs"), config_path], cwd=BROWSER_DIR,
                                 capture_output=True, text=True, timeout=BROWSER_LIMIT)
            print(run.stdout)
            c.check(run.returncode == 0, f"the browser scenarios failed ({run.returncode}):\n{run.stderr[-4000:]}")
            with open(os.path.join(out_dir, "outcome.json")) as f:
                outcome = json.load(f)
            print(json.dumps(outcome["metrics"], indent=1))
            opened, keyed = outcome.get("open", {}), outcome.get("keys", {})
            client = open_daemon.client()
            if opened:
                check_csv(c, client, opened["iron"], opened["csv"], "the iron job's CSV")
                check_tess(c, client, opened["box"], opened["tess"])
                c.check(client.get(f"/jobs/{opened['long']}").status == 404, "the dismissed job deleted from My jobs is still there")
                statuses = gpd.check_store(c, open_daemon, "after the browser")
                c.check(opened["long"] not in statuses, "the deleted job is still in the database")
                c.check(list(statuses.values()).count("successful") >= 2, f"jobs in the database: {statuses}")
            if keyed:
                alice, bob = keys_daemon.client(keys["alice"]), keys_daemon.client(keys["bob"])
                check_csv(c, alice, keyed["id"], keyed["csv"], "alice's CSV, downloaded with her key")
                c.check(bob.get(f"/jobs/{keyed['id']}").status == 404, "bob sees alice's job")
            for name in ("design", "design-invalid-bin", "running", "result", "jobs", "narrow-design", "keys-bob",
                         "design-3d", "result-3d"):
                png = os.path.join(out_dir, f"{name}.png")
                c.check(os.path.exists(png) and os.path.getsize(png) > 10000, f"screenshot {name}.png is missing")
            c.check(open_daemon.stop() == 0, "the open grainpackd did not stop cleanly")
            c.check(keys_daemon.stop() == 0, "grainpackd with keys did not stop cleanly")
        finally:
            open_daemon.cleanup()
            keys_daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
