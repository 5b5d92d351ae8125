#!/usr/bin/env python3
"""hostile.py - /health latency while hostile clients hold connections, on this machine:
slowloris (connections that trickle request-head bytes and never finish), abandoned
long-polls (hundreds of `?wait=` requests from several loopback addresses whose clients
then vanish), and large downloads (clients fetching big results at once). Prints
markdown. Not a test: wall-clock figures, read with the load average.

Usage: hostile.py GRAINPACKD [slowloris|polls|downloads|cancel ...]
  slowloris: 50 connections, one header byte each every second, --connection-timeout 5;
             /health timed over 12 s; when and how each trickler was closed.
  polls:     1000 long-polls (wait=60) from 10 addresses 127.0.0.2-11 on a job that runs
             for minutes, all closed by their clients; /health timed before, while they
             wait, and after they hang up; the slots they held, free again or not.
  downloads: a job of GP_BIG_SIDE (default 980: ~290 000 disks) with Laguerre cells,
             its JSON result fetched by 4 clients at once, over and over, for 15 s;
             /health timed meanwhile.
  cancel:    how soon a worker is free again after DELETE or the time limit of the issue's
             endless histogram job, and after DELETE of a real job in each stage."""

import http.client
import json
import os
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

HEALTH = b"GET /health HTTP/1.1\r\nHost: bench\r\n\r\n"


def start(binary, *args, env=None):
    d = tempfile.mkdtemp(prefix="grainpackd-hostile-")
    ready = os.path.join(d, "ready")
    proc = subprocess.Popen([binary, "--port", "0", "--data-dir", d, "--ready-file", ready] + list(args),
                            stderr=open(os.path.join(d, "log"), "w"), env=dict(os.environ, **(env or {})))
    while not os.path.exists(ready):
        time.sleep(0.01)
    return proc, int(open(ready).read()), d


def stop(proc, d):
    proc.send_signal(signal.SIGTERM)
    proc.wait()
    shutil.rmtree(d)


def health_once(port, timeout=5.0):
    """Seconds for one /health on a new connection (connect, request, whole answer)."""
    t = time.monotonic()
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    try:
        s.sendall(HEALTH)
        data = b""
        while b"\r\n\r\n" not in data or len(data) < data.index(b"\r\n\r\n") + 4 + int(
                data.split(b"Content-Length: ")[1].split(b"\r\n")[0]):
            piece = s.recv(65536)
            if not piece:
                break
            data += piece
        assert data.startswith(b"HTTP/1.1 200"), data[:100]
    finally:
        s.close()
    return time.monotonic() - t


def sample_health(port, seconds, period=0.05):
    out = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            out.append(health_once(port))
        except (OSError, AssertionError):
            out.append(float("inf"))
        time.sleep(period)
    return out


def summary(times):
    ok = sorted(t for t in times if t != float("inf"))
    failed = len(times) - len(ok)
    if not ok:
        return f"{len(times)} requests, all failed"
    p99 = ok[min(len(ok) - 1, int(0.99 * len(ok)))]
    return (f"{len(times)} requests: median {1e3 * statistics.median(ok):.1f} ms, p99 {1e3 * p99:.1f} ms, "
            f"max {1e3 * ok[-1]:.1f} ms" + (f", {failed} failed" if failed else ""))


def load():
    return os.getloadavg()[0]


def slowloris(binary):
    timeout = 5
    proc, port, d = start(binary, "--connection-timeout", str(timeout))
    try:
        socks, closed, answers = [], {}, {}
        t0 = time.monotonic()
        for i in range(50):
            s = socket.create_connection(("127.0.0.1", port))
            s.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\nX-Slow: ")
            s.setblocking(False)
            socks.append(s)

        def trickle():
            while len(closed) < len(socks) and time.monotonic() - t0 < 4 * timeout + 2:
                for i, s in enumerate(socks):
                    if i in closed:
                        continue
                    try:
                        data = s.recv(4096)
                        if data:
                            answers[i] = answers.get(i, b"") + data
                            continue
                        closed[i] = time.monotonic() - t0
                    except BlockingIOError:
                        try:
                            s.send(b"a")
                        except OSError:
                            closed[i] = time.monotonic() - t0
                    except OSError:
                        closed[i] = time.monotonic() - t0
                time.sleep(1.0)

        th = threading.Thread(target=trickle)
        th.start()
        times = sample_health(port, 12)
        th.join()
        for s in socks:
            s.close()
        got408 = sum(1 for a in answers.values() if a.startswith(b"HTTP/1.1 408"))
        when = sorted(closed.values())
        print(f"| slowloris: 50 connections trickling a header byte a second, --connection-timeout {timeout} "
              f"| {summary(times)} | {len(closed)} of 50 closed, after {when[0]:.1f}-{when[-1]:.1f} s; "
              f"{got408} got a 408 first | {load():.2f} |" if when else
              f"| slowloris | {summary(times)} | none closed within {4 * timeout + 2} s | {load():.2f} |")
    finally:
        stop(proc, d)


def polls(binary, count=1000, addresses=10):
    # a job that runs for minutes: the first job stalls an hour (the test-only fault), or,
    # for a build without it, GP_POLL_SIDE makes the job big (4000: ~4.6 million disks)
    side = int(os.environ.get("GP_POLL_SIDE", "100"))
    proc, port, d = start(binary, "--workers", "1", "--max-disks", "100000000",
                          env={"GRAINPACKD_TEST_STALL_SECONDS": "3600"})
    try:
        spec = json.dumps({"inputs": {"domain": {"width": side, "height": side},
                                      "distribution": {"kind": "constant", "radius": 1}}}).encode()
        req = urllib.request.Request(f"http://127.0.0.1:{port}/processes/pack2d/execution", data=spec,
                                     headers={"Content-Type": "application/json"})
        job = urllib.request.urlopen(req).headers["Location"]
        before = sample_health(port, 3)
        socks = []
        for i in range(count):
            s = socket.socket()
            s.bind((f"127.0.0.{2 + i % addresses}", 0))
            s.connect(("127.0.0.1", port))
            s.sendall(f"GET {job}?wait=60 HTTP/1.1\r\nHost: x\r\n\r\n".encode())
            socks.append(s)
        time.sleep(1)
        waiting = sample_health(port, 3)
        t = time.monotonic()
        for s in socks:
            s.close()
        after = sample_health(port, 3)
        # the per-address slots: 100 new waits from one address, while the old ones'
        # 60 s are far from over
        fresh, refused = [], 0
        for i in range(100):
            s = socket.socket()
            s.bind(("127.0.0.2", 0))
            s.connect(("127.0.0.1", port))
            s.sendall(f"GET {job}?wait=1 HTTP/1.1\r\nHost: x\r\n\r\n".encode())
            fresh.append(s)
        for s in fresh:
            s.settimeout(10)
            refused += s.recv(64).startswith(b"HTTP/1.1 429")
            s.close()
        metrics = urllib.request.urlopen(f"http://127.0.0.1:{port}/metrics").read().decode()
        hung = [line for line in metrics.splitlines() if line.startswith("grainpack_http_long_polls_hung_up_total")]
        print(f"| {count} long-polls from {addresses} addresses: before | {summary(before)} | | {load():.2f} |")
        print(f"| ... while they wait | {summary(waiting)} | | |")
        print(f"| ... after their clients hung up | {summary(after)} | {hung[0] if hung else '?'} "
              f"{time.monotonic() - t:.1f} s after; 100 new waits from one address: {refused} refused (429) | |")
    finally:
        stop(proc, d)


def downloads(binary, seconds=15):
    # 980: ~290 000 disks, the 287 704-disk job (148 MiB as JSON with its cells)
    side = int(os.environ.get("GP_BIG_SIDE", "980"))
    proc, port, d = start(binary, "--workers", "1")
    try:
        spec = json.dumps({"inputs": {"domain": {"width": side, "height": side},
                                      "distribution": {"kind": "constant", "radius": 1},
                                      "laguerre": {"shrink": "offset"}}}).encode()
        req = urllib.request.Request(f"http://127.0.0.1:{port}/processes/pack2d/execution", data=spec,
                                     headers={"Content-Type": "application/json"})
        job = urllib.request.urlopen(req).headers["Location"]
        while json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}{job}?wait=60"))["status"] != "successful":
            pass
        size = len(urllib.request.urlopen(f"http://127.0.0.1:{port}{job}/results?f=json").read())
        disks = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}{job}/statistics"))["count"]
        stop_at = time.monotonic() + seconds
        fetched, failed = [0], [0]

        def fetch():
            while time.monotonic() < stop_at:
                try:
                    urllib.request.urlopen(f"http://127.0.0.1:{port}{job}/results?f=json", timeout=120).read()
                    fetched[0] += 1
                except (OSError, http.client.HTTPException):  # refused or cut off: counted
                    failed[0] += 1

        threads = [threading.Thread(target=fetch) for _ in range(4)]
        for th in threads:
            th.start()
        times = sample_health(port, seconds)
        for th in threads:
            th.join()
        print(f"| 4 clients downloading a {disks}-disk result with its cells as JSON, {size / 2**20:.0f} MiB, "
              f"over and over ({fetched[0]} downloads in {seconds} s) | {summary(times)} | "
              f"{failed[0]} downloads failed | {load():.2f} |")
    finally:
        stop(proc, d)


def submit(port, spec):
    req = urllib.request.Request(f"http://127.0.0.1:{port}/processes/pack2d/execution",
                                 data=json.dumps(spec).encode(), headers={"Content-Type": "application/json"})
    return urllib.request.urlopen(req).headers["Location"]


def status(port, job):
    return json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}{job}"))


def until(predicate, limit=600, period=0.005):
    t = time.monotonic()
    while not predicate():
        if time.monotonic() - t > limit:
            return None
        time.sleep(period)
    return time.monotonic() - t


PATHOLOGICAL = {"inputs": {"domain": {"width": 100, "height": 100},
                           "distribution": {"kind": "histogram", "bins": [{"min": 1e-06, "max": 2e-06, "p": 0.5},
                                                                          {"min": 1, "max": 1.1, "p": 0.5}]}}}
STAGED = {"inputs": {"domain": {"width": 2280, "height": 2280}, "distribution": {"kind": "constant", "radius": 1},
                     "joint": {"law": "constant", "value": 0.1},
                     "balance": {"method": "relocation", "max_iterations": 5}, "laguerre": {"shrink": "offset"}}}
TINY = {"inputs": {"domain": {"width": 10, "height": 10}, "distribution": {"kind": "constant", "radius": 0.9}}}


def busy(port):
    return json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/health"))["workers_busy"]


def cancel(binary):
    """How soon a worker is free again: after DELETE of the issue's endless histogram job,
    after its time limit, and after DELETE of a real 1.2-million-disk job in each stage."""
    proc, port, d = start(binary, "--workers", "1", "--max-job-seconds", "5", "--max-disks", "10000000")
    try:
        rows = []
        job = submit(port, PATHOLOGICAL)
        until(lambda: status(port, job)["status"] == "running")
        time.sleep(1)
        t = time.monotonic()
        urllib.request.urlopen(urllib.request.Request(f"http://127.0.0.1:{port}{job}", method="DELETE"))
        free = until(lambda: busy(port) == 0)
        tiny = submit(port, TINY)
        until(lambda: status(port, tiny)["status"] == "successful")
        rows.append(("the issue's histogram job, DELETE 1 s after it started", free, time.monotonic() - t))
        job = submit(port, PATHOLOGICAL)
        until(lambda: status(port, job)["status"] == "running")
        t = time.monotonic()
        until(lambda: status(port, job)["status"] == "failed")
        failed = time.monotonic() - t
        free = until(lambda: busy(port) == 0)
        tiny = submit(port, TINY)
        until(lambda: status(port, tiny)["status"] == "successful")
        rows.append((f"the same, left to its 5 s limit (failed {failed:.2f} s after it started)", failed + free,
                     time.monotonic() - t))
        metrics = urllib.request.urlopen(f"http://127.0.0.1:{port}/metrics").read().decode()
        abandoned = [line for line in metrics.splitlines() if line.startswith('grainpack_job_runs_total{outcome="abandoned",')]
        stop(proc, d)
        proc, port, d = start(binary, "--workers", "1", "--max-disks", "10000000")
        for stage in ("pack", "triangulation", "balance", "laguerre"):
            job = submit(port, STAGED)
            if until(lambda: stage in status(port, job).get("message", ""), limit=900, period=0.02) is None:
                rows.append((f"1.2 million disks, DELETE in {stage}: stage not seen in 900 s", None, None))
                urllib.request.urlopen(urllib.request.Request(f"http://127.0.0.1:{port}{job}", method="DELETE"))
                until(lambda: busy(port) == 0)
                continue
            t = time.monotonic()
            urllib.request.urlopen(urllib.request.Request(f"http://127.0.0.1:{port}{job}", method="DELETE"))
            free = until(lambda: busy(port) == 0)
            tiny = submit(port, TINY)
            until(lambda: status(port, tiny)["status"] == "successful")
            rows.append((f"1.2 million disks (relocation, cells), DELETE in {stage}", free, time.monotonic() - t))
        for what, free, tiny in rows:
            print(f"| {what} | {'-' if free is None else f'{1e3 * free:.0f} ms'} | "
                  f"{'-' if tiny is None else f'{1e3 * tiny:.0f} ms'} | {load():.2f} |")
        print(f"\nworkers given up on with the histogram job: {abandoned[0] if abandoned else '?'}")
    finally:
        stop(proc, d)


def main():
    binary, modes = sys.argv[1], sys.argv[2:] or ["slowloris", "polls", "downloads", "cancel"]
    print(f"Load average {load():.2f} at the start; 2 cores shared.\n")
    attacks = [m for m in modes if m != "cancel"]
    if attacks:
        print("| attack | /health on a new connection | what became of the attackers | load |\n|---|---|---|---|")
    for mode in attacks:
        {"slowloris": slowloris, "polls": polls, "downloads": downloads}[mode](binary)
    if "cancel" in modes:
        print("\n| job stopped | worker free (workers_busy 0) after | a tiny job done after | load |\n|---|---|---|---|")
        cancel(binary)


if __name__ == "__main__":
    main()
