#!/usr/bin/env python3
"""test_demo_refusal.py - the README's main command (scripts/demo.sh) refuses clearly, at
once and before building anything, when its port is taken or its database is in use by
another grainpackd: exit status 1, a message on standard error that says which and how to
stop it, nothing written. The script runs from a copy in an empty directory, so that a
failure to refuse could not build anything here (it would fail at once, without .ci/ and
CMakeLists.txt). (Its normal run builds the project: that is not done here.)
Usage: test_demo_refusal.py GRAINPACKD"""

import os
import shutil
import socket
import subprocess
import tempfile

import gpd

DEMO = os.path.join(gpd.ROOT, "scripts", "demo.sh")


def run_demo(root, port, data_dir):
    env = dict(os.environ, GRAINPACKD_PORT=str(port), GRAINPACKD_DATA_DIR=data_dir)
    return subprocess.run(["bash", os.path.join(root, "scripts", "demo.sh")], env=env, capture_output=True,
                          text=True, timeout=60, stdin=subprocess.DEVNULL)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test(c, binary):
    with tempfile.TemporaryDirectory() as work:
        root = os.path.join(work, "root")
        os.makedirs(os.path.join(root, "scripts"))
        shutil.copy(DEMO, os.path.join(root, "scripts"))
        # the port taken by something else
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            s.listen()
            port = s.getsockname()[1]
            r = run_demo(root, port, os.path.join(work, "data"))
        c.check(r.returncode == 1, f"port taken: exit {r.returncode}")
        c.check(f"port {port} on 127.0.0.1 is already in use" in r.stderr and "Nothing was built" in r.stderr,
                f"port taken: {r.stderr!r}")
        c.check(r.stdout == "", f"port taken: printed {r.stdout!r}")
        c.check(not os.path.exists(os.path.join(work, "data")), "port taken: the data directory was made")

        # the database held by a running daemon (on another port)
        daemon = gpd.Daemon(binary, data_dir=work)
        try:
            daemon.start()
            r = run_demo(root, free_port(), work)
            c.check(r.returncode == 1, f"database in use: exit {r.returncode}")
            c.check("is in use by another grainpackd" in r.stderr and f"kill {daemon.proc.pid}" in r.stderr,
                    f"database in use: {r.stderr!r}")
            # the daemon on its port: the message names it and its pid (found with ss)
            r = run_demo(root, daemon.port, work)
            named = f"pid {daemon.proc.pid} (grainpackd)" in r.stderr and f"kill {daemon.proc.pid}" in r.stderr
            c.check(r.returncode == 1 and "already in use" in r.stderr and (named or not shutil.which("ss")),
                    f"daemon on the port: {r.stderr!r}")
            c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        finally:
            daemon.cleanup()
        c.check(os.listdir(root) == ["scripts"], f"a refused run wrote {os.listdir(root)}")


if __name__ == "__main__":
    gpd.main(test)
