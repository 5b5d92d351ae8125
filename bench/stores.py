#!/usr/bin/env python3
"""stores.py - the two job stores compared on this machine, in a markdown table: iron jobs
(examples/iron.json) completed per second, from the first submission to the last result
stored, by one node on sqlite and by 1, 2 and 3 nodes on one PostgreSQL database (the
jobs submitted round-robin to the nodes, each node with --workers 2); then the time a dead
node's job takes to be taken over: two nodes, one SIGKILLed while it holds a running job,
the time from the kill until another node claims the job and until it is done, against
the lease. Not a test: run by hand (bench/stores.sh builds and starts the server).
Usage: stores.py GRAINPACKD PG_STATE [JOBS] (PGPASSWORD in the environment)"""

import json
import os
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "service"))
import gpd  # noqa: E402

LEASE = 10.0  # the default


def psql(uri, sql):
    return subprocess.run(["psql", "-XAtq", "-d", uri, "-c", sql], check=True,
                          capture_output=True, text=True).stdout.strip()


def fresh_db(admin, name):
    psql(admin, f"DROP DATABASE IF EXISTS {name} WITH (FORCE)")
    psql(admin, f"CREATE DATABASE {name}")
    return admin.replace("/postgres?", f"/{name}?")


def throughput(binary, db_args, nodes, jobs):
    spec = gpd.load_example("iron")
    daemons = [gpd.Daemon(binary, *db_args, "--workers", "2", "--node", f"n{i}",
                          "--max-queued", "1000000") for i in range(nodes)]
    try:
        for d in daemons:
            d.start()
        clients = [d.client() for d in daemons]
        ids = []
        lock = threading.Lock()

        def submit(k):
            mine = [d.client() for d in daemons]  # one connection per node and thread
            for i in range(k, jobs, 4):
                r = mine[i % nodes].submit(spec)
                with lock:
                    ids.append(r.json()["jobID"])

        t0 = time.monotonic()
        threads = [threading.Thread(target=submit, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for i, job in enumerate(ids):
            info = clients[i % nodes].wait_final(job)
            assert info["status"] == "successful", info
        seconds = time.monotonic() - t0
        ran = [d.log().count(" successful: ") for d in daemons]
        return len(ids) / seconds, ran
    finally:
        for d in daemons:
            d.stop()
            d.cleanup()


def takeover(binary, uri):
    args = ["--db", uri, "--workers", "2", "--lease-seconds", str(LEASE)]
    a = gpd.Daemon(binary, *args, "--node", "alive")
    b = gpd.Daemon(binary, *args, "--node", "dying", env={"GRAINPACKD_TEST_STALL_SECONDS": "600"})
    try:
        b.start()
        job = b.client().submit(gpd.load_example("iron")).json()["jobID"]
        b.client().wait_status(job, ("running",))
        a.start()
        time.sleep(2)  # a few renewals: the lease is at its full length at the kill
        b.kill()
        t0 = time.monotonic()
        claimed = None
        while True:
            node = psql(uri, f"SELECT node FROM jobs WHERE id = '{job}'")
            if claimed is None and node.startswith("alive/"):
                claimed = time.monotonic() - t0
            info = a.client().get(f"/jobs/{job}").json()
            if info["status"] == "successful":
                return claimed, time.monotonic() - t0
            time.sleep(0.02)
    finally:
        a.stop()
        a.cleanup()
        b.cleanup()


def main():
    binary, state = sys.argv[1], sys.argv[2]
    jobs = int(sys.argv[3]) if len(sys.argv) > 3 else 1000
    admin = next(line[4:].strip() for line in open(state) if line.startswith("uri="))
    rows = []
    rate, ran = throughput(binary, [], 1, jobs)
    rows.append(("sqlite", 1, rate, ran))
    for nodes in (1, 2, 3):
        uri = fresh_db(admin, f"bench_{nodes}")
        rate, ran = throughput(binary, ["--db", uri], nodes, jobs)
        rows.append(("PostgreSQL", nodes, rate, ran))
    print(f"| store | nodes (2 workers each) | iron jobs per second | jobs run by each node |")
    print("| --- | --- | --- | --- |")
    for store, nodes, rate, ran in rows:
        print(f"| {store} | {nodes} | {rate:.0f} | {' / '.join(map(str, ran))} |")
    uri = fresh_db(admin, "bench_takeover")
    claimed, done = takeover(binary, uri)
    print()
    print(f"A dead node's job (lease {LEASE:g} s, renewed every second): claimed by the "
          f"other node {claimed:.2f} s after the SIGKILL ({claimed / LEASE:.2f} lease periods), "
          f"done {done:.2f} s after it.")
    print()
    print(f"{os.cpu_count()} cores")


if __name__ == "__main__":
    main()
