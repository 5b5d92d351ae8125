#!/usr/bin/env python3
"""test_openapi_client.py - openapi.yaml is usable, not only valid: a typed client is
generated from it (openapi-typescript), the client script tests/openapi/client/
contract_client.ts is type-checked against those types by tsc (strict; its deliberate type
errors must be caught), then run with node against the real grainpackd on a free port:
submit, wait, results in JSON and CSV, statistics, the job list, a 400, a 422, a 404, delete.
The document's maximum for ?wait= must be what a daemon with default options accepts.
Usage: test_openapi_client.py GRAINPACKD NODE"""

import os
import shutil
import subprocess
import tempfile

import gpd

TOOLS = os.path.join(gpd.ROOT, "tests", "openapi")
CLIENT = os.path.join(TOOLS, "client")


def run(c, what, argv, cwd):
    """Runs a step; a failed step is a failed check with its output."""
    r = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=300)
    out = (r.stdout + r.stderr).strip()
    c.check(r.returncode == 0, f"{what} exited {r.returncode}:\n{out[-3000:]}")
    return r.returncode == 0, out


def wait_maximum():
    """The maximum openapi.yaml gives for GET /jobs/{jobId}?wait=."""
    api = gpd.OpenAPI()
    params = api.doc["paths"]["/jobs/{jobId}"]["get"]["parameters"]
    return next(p for p in params if p.get("name") == "wait")["schema"]["maximum"]


def test(c, binary, node):
    with tempfile.TemporaryDirectory() as work:
        os.symlink(os.path.join(TOOLS, "node_modules"), os.path.join(work, "node_modules"))
        for name in ("contract_client.ts", "tsconfig.json"):
            shutil.copy(os.path.join(CLIENT, name), work)
        with open(os.path.join(work, "package.json"), "w") as f:
            f.write('{"type": "module", "private": true}\n')
        bin_dir = os.path.join(TOOLS, "node_modules", ".bin")
        # properties with a default stay optional in the types: a client may leave them out
        ok, _ = run(c, "openapi-typescript", [node, os.path.join(bin_dir, "openapi-typescript"),
                    os.path.join(gpd.ROOT, "openapi.yaml"), "--default-non-nullable", "false",
                    "-o", "api.d.ts"], work)
        ok = ok and run(c, "tsc", [node, os.path.join(bin_dir, "tsc"), "-p", "tsconfig.json"], work)[0]
        if not ok:
            return
        max_wait = wait_maximum()
        daemon = gpd.Daemon(binary)
        try:
            daemon.start()
            ok, out = run(c, "the contract client", [node, os.path.join("out", "contract_client.js"),
                          f"http://127.0.0.1:{daemon.port}", str(max_wait)], work)
            print(out)
            c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        finally:
            daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
