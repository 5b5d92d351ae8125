#!/usr/bin/env python3
"""test_readme_walkthrough.py - the README's curl walk-through runs as written against
the real daemon (only `base=` is pointed at the test's port), every command succeeds,
and what it prints is what the README says it prints.
Usage: test_readme_walkthrough.py GRAINPACKD"""

import os
import re
import subprocess
import tempfile

import gpd


def walkthrough():
    with open(os.path.join(gpd.ROOT, "README.md")) as f:
        text = f.read()
    block = re.search(r"<!-- walkthrough:begin -->\s*```sh\n(.*?)```\s*<!-- walkthrough:end -->", text, re.S)
    if not block:
        raise AssertionError("README.md has no walk-through block")
    return block.group(1)


def test(c, binary):
    script = walkthrough()
    c.check(script.startswith("base=http://127.0.0.1:8080\n"), "the walk-through does not start with base=")
    daemon = gpd.Daemon(binary)
    try:
        daemon.start()
        script = script.replace("base=http://127.0.0.1:8080", f"base=http://127.0.0.1:{daemon.port}", 1)
        with tempfile.TemporaryDirectory() as work:
            os.symlink(gpd.EXAMPLES, os.path.join(work, "examples"))
            run = subprocess.run(["bash", "-e", "-c", script], cwd=work, capture_output=True, text=True,
                                 timeout=300)
            out = run.stdout
            c.check(run.returncode == 0, f"walk-through exited {run.returncode}: {run.stderr[-500:]}")
            svg = open(os.path.join(work, "bagi.svg")).read() if os.path.exists(os.path.join(work, "bagi.svg")) else ""
            c.check(svg.rstrip().endswith("</svg>"), "bagi.svg is not a whole SVG")
            saved = [f for f in os.listdir(work) if re.fullmatch(r"job-[0-9a-f-]{36}\.csv", f)]
            c.check(len(saved) == 1 and open(os.path.join(work, saved[0])).read().startswith("x,y,r,R\n"),
                    f"the download was not saved as job-<id>.csv (decompressed): {os.listdir(work)}")
            for name, last in (("iron_mesh.msh", "$EndElements"), ("iron_mesh.inp", "*Nset, nset=top"),
                               ("iron_mesh.vtu", "</VTKFile>")):
                path = os.path.join(work, name)
                text = open(path).read() if os.path.exists(path) else ""
                c.check(last in text, f"{name} downloaded by the walk-through is not a whole file")
        for expected in ['"conformsTo"', '"id":"pack2d"', "job at http://", '"status":"successful"',
                         "<!doctype html>", '"valid":true,"expected_disks":',
                         "x,y,r,R", '"packing_density"', '"timings"', "\n304\n", '"status":"dismissed"', "\n404\n",
                         '"pointer":"/inputs/distribution/radius"', '"status":"ok"',
                         'grainpack_jobs{status="successful",node="', "openapi: 3.1.0", "$MeshFormat\n4.1 0 8",
                         '"processID":"pack3d"', "x,y,z,r,R\n", '"box_volume":1000']:
            c.check(expected in out, f"walk-through output lacks {expected!r}")
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
