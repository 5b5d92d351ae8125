#!/usr/bin/env python3
"""test_service_nodes.py - three grainpackd nodes on one PostgreSQL database (the real
server of tests/pg/pg_server.sh, a new database for this test): jobs submitted round-robin
to the three, one node SIGKILLed while it holds a running job; every job accepted ends
successful, its outcome stored exactly once (one "successful" in all the logs together),
the dead node's job run again by another after its lease, with its claim counted; every
node answers for every job (status, results); a long-poll on one node wakes when another
node finishes the job; a job of Alice's submitted to one node is 404 to Bob on another;
the per-key limit counts a key's jobs on every node; a listing's next page made by one
node is served by another; a DELETE on one node stops the job
running on another within about a second (its lease renewal sees it); /health names the
store and the node; no log shows the password.
Usage: test_service_nodes.py GRAINPACKD PG_STATE (PGPASSWORD in the environment)"""

import os
import subprocess
import threading
import time

import gpd

JOBS = 300  # the figure; each packs in milliseconds
LEASE = 2   # seconds: a dead node's job runs again soon after


def pg_uri(state):
    with open(state) as f:
        for line in f:
            if line.startswith("uri="):
                return line[4:].strip()
    raise AssertionError(f"no server URI in {state}")


def psql(uri, sql):
    out = subprocess.run(["psql", "-XAtq", "-d", uri, "-c", sql], check=True,
                         capture_output=True, text=True)
    return out.stdout.strip()


def new_database(admin_uri):
    name = f"nodes_{os.getpid()}"
    psql(admin_uri, f"DROP DATABASE IF EXISTS {name}")
    psql(admin_uri, f"CREATE DATABASE {name}")
    return name, admin_uri.replace("/postgres?", f"/{name}?")


def spec(seed, side=24):
    return gpd.small_spec(seed=seed, side=side)


def successes(nodes, job):
    """How many times a log says the job succeeded, all nodes counted."""
    return sum(n.log().count(f"job {job} successful") for n in nodes)


def test_batch_and_kill(c, binary, uri, keys, key_file, tmp):
    # C's one worker sleeps at its first job without reading its flag (the test fault): C
    # surely holds that job running when it is killed
    common = ["--db", uri, "--lease-seconds", str(LEASE), "--key-file", key_file,
              "--max-jobs-per-key", "0"]
    a = gpd.Daemon(binary, *common, "--workers", "2", "--node", "node-a")
    b = gpd.Daemon(binary, *common, "--workers", "2", "--node", "node-b")
    cc = gpd.Daemon(binary, *common, "--workers", "1", "--node", "node-c",
                    env={"GRAINPACKD_TEST_STALL_SECONDS": "60"})
    nodes = [a, b, cc]
    try:
        for n in nodes:
            n.start()
        for n, name in zip(nodes, ["node-a", "node-b", "node-c"]):
            h = n.client().get("/health").json()
            c.check(h.get("store") == "postgresql" and h.get("node") == name,
                    f"/health names the store and the node: {h}")
            # every series of /metrics carries the node's label: three nodes' figures stay
            # apart in one query
            text = n.client(key=keys["ops"]).get("/metrics").body.decode()
            series = [line for line in text.splitlines() if line and not line.startswith("#")]
            c.check(series and all(f'node="{name}"' in line for line in series),
                    f"{name}: a series of /metrics without its node label")
            c.check(gpd.metric(text, "grainpack_workers", f'node="{name}"') == (1 if name == "node-c" else 2)
                    and gpd.metric(text, "grainpack_node_info", f'node="{name}",store="postgresql"') == 1,
                    f"{name}: the node's workers and info series")
        clients = [n.client(key=keys["batch"]) for n in nodes]
        ids = []
        for i in range(JOBS):
            r = clients[i % 3].submit(spec(i + 1))
            if c.check(r.status == 201, f"job {i} accepted: {r}"):
                ids.append(r.json()["jobID"])
        # the job C runs, held by the fault, then C dies
        deadline = time.monotonic() + gpd.JOB_LIMIT
        held = ""
        while not held and time.monotonic() < deadline:
            held = psql(uri, "SELECT id FROM jobs WHERE status = 'running' AND node LIKE 'node-c/%'")
            time.sleep(0.05)
        c.check(held, "node C runs a job")
        cc.kill()
        killed = time.monotonic()
        # every job accepted ends successful, on the nodes alive; any node answers
        for i, job in enumerate(ids):
            info = clients[i % 2].wait_final(job)
            c.check(info["status"] == "successful", f"job {job}: {info['status']} {info.get('message')}")
            if job == held:
                print(f"the dead node's job was taken over and done {time.monotonic() - killed:.2f} s "
                      f"after the kill (lease {LEASE} s)")
        once = [job for job in ids if successes(nodes, job) != 1]
        c.check(not once, f"jobs whose outcome was not stored exactly once: {once[:5]}")
        claims = psql(uri, f"SELECT claims FROM jobs WHERE id = '{held}'")
        # twice: C's claim, then a live node's (more only if a loaded machine delayed a
        # live node's renewals past its lease: then that node's result was refused)
        c.check(claims.isdigit() and int(claims) >= 2, f"the dead node's job was claimed again: {claims}")
        c.check(f"job {held} successful" not in cc.log(), "the dead node did not finish it")
        counted = psql(uri, "SELECT count(*) FROM jobs WHERE status = 'successful'")
        c.check(counted == str(len(ids)), f"{counted} successful jobs of {len(ids)}")
        # any node serves any result, whole: B serves what A ran and the reverse
        for job in ids[:6]:
            r = clients[1].get(f"/jobs/{job}/results?f=csv")
            status = clients[0].get(f"/jobs/{job}").json()
            n = int(status["message"].split()[0])
            c.check(r.status == 200 and r.body.count(b"\n") == n + 1,
                    f"job {job}: its CSV from node B has {n} disks: {r.status}")
        # a pack3d job (spheres in a box) in the shared store: its process read back from
        # the stored spec, its spheres served by the other node
        box = {"inputs": {"domain": {"width": 8, "height": 8, "depth": 8},
                          "distribution": {"kind": "constant", "radius": 0.5}}}
        job = clients[0].submit(box, "pack3d").json()["jobID"]
        info = clients[1].wait_final(job)
        r = clients[1].get(f"/jobs/{job}/results?f=csv")
        n = int(info["message"].split()[0]) if info["status"] == "successful" else -1
        c.check(info["processID"] == "pack3d" and r.status == 200 and
                r.body.startswith(b"x,y,z,r,R\n") and r.body.count(b"\n") == n + 1,
                f"a pack3d job through node B: {info['status']}, {info['processID']}, {r.status}")
        ids.append(job)
        # a listing's next page, made by A, asked of B (the nodes share the cursors' keys)
        page = clients[0].get("/jobs?limit=5").json()
        nxt = [link["href"] for link in page["links"] if link["rel"] == "next"]
        second = clients[1].get(nxt[0]) if nxt else None
        c.check(second is not None and second.status == 200 and
                [j["jobID"] for j in second.json()["jobs"]][:1] == [ids[-6]],
                f"A's next page on B: {second}")
        # a long-poll on one node wakes when the other finishes the job: which node claims a
        # job is a race (both hear of it), so the poll goes to the node that does not run it,
        # parked while the job (some tenths of a second of packing) still runs there. A
        # wait ends only by its job's end or its deadline: an answer "successful" before the
        # deadline is the other node's notification (however slow a loaded machine makes
        # the job itself)
        woke = False
        for attempt in range(5):
            job = clients[1].submit(gpd.big_spec(side=600)).json()["jobID"]
            runner = ""
            deadline = time.monotonic() + gpd.JOB_LIMIT
            while not runner and time.monotonic() < deadline:
                runner = psql(uri, f"SELECT node FROM jobs WHERE id = '{job}' AND status = 'running'")
                time.sleep(0.01)
            running_on, other = (b, clients[0]) if runner.startswith("node-b/") else (a, clients[1])
            t0 = time.monotonic()
            if f"job {job} successful" in running_on.log():
                continue  # it ended before the poll began: that proves nothing, again
            info = other.get(f"/jobs/{job}?wait=60").json()
            waited = time.monotonic() - t0
            if info["status"] == "successful" and f"job {job} successful" in running_on.log():
                c.check(waited < 55, f"the long-poll ran to its deadline ({waited:.2f} s)")
                print(f"a long-poll parked on one node woke {waited:.2f} s after it began, the job "
                      f"run by {runner.split('/')[0]}")
                woke = True
                break
        c.check(woke, "a long-poll parked on one node woke when the other node finished the job")
        for n in (a, b):
            c.check(n.stop() == 0, "a node stops cleanly")
        for n in nodes:
            c.check(os.environ["PGPASSWORD"] not in n.log(), "no log shows the password")
    finally:
        for n in nodes:
            n.cleanup()


def test_keys_limits_and_dismissal(c, binary, uri, keys, key_file):
    common = ["--db", uri, "--workers", "2", "--lease-seconds", str(LEASE), "--key-file", key_file,
              "--max-jobs-per-key", "2", "--max-disks", "5000000"]
    a = gpd.Daemon(binary, *common, "--node", "node-a")
    b = gpd.Daemon(binary, *common, "--node", "node-b")
    try:
        a.start()
        b.start()
        alice_a, alice_b = a.client(key=keys["alice"]), b.client(key=keys["alice"])
        bob_b = b.client(key=keys["bob"])
        r = alice_a.submit(spec(7))
        job = r.json()["jobID"]
        alice_a.wait_final(job)
        c.check(bob_b.get(f"/jobs/{job}").status == 404, "Alice's job is 404 to Bob on another node")
        c.check(bob_b.get(f"/jobs/{job}/results?f=csv").status == 404, "and its results")
        c.check(bob_b.request("DELETE", f"/jobs/{job}").status == 404, "and Bob cannot delete it")
        c.check(alice_b.get(f"/jobs/{job}").status == 200, "Alice sees it on the other node")
        # two long jobs of Alice's on A: a third on B is refused (the count is every node's)
        long_jobs = [alice_a.submit(gpd.big_spec(side=2000)).json()["jobID"] for _ in range(2)]
        r = alice_b.submit(spec(8))
        c.check(r.status == 429, f"a third active job of Alice's on node B: {r}")
        c.check(bob_b.submit(spec(9)).status == 201, "Bob has his own count")
        # dismissed on B while A (or B) runs them: the node running each stops it
        for job in long_jobs:
            alice_a.wait_status(job, ("running",))
        t0 = time.monotonic()
        for job in long_jobs:
            c.check(alice_b.request("DELETE", f"/jobs/{job}").status == 200, "DELETE on B")
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            busy = [n.client().get("/health").json()["workers_busy"] for n in (a, b)]
            if busy == [0, 0]:
                break
            time.sleep(0.05)
        print(f"both dismissed jobs stopped {time.monotonic() - t0:.2f} s after their DELETE")
        c.check(busy == [0, 0], f"the workers are free after the DELETE: {busy}")
        stopped = sum(n.log().count("dismissed: worker stopped") for n in (a, b))
        c.check(stopped == 2, f"both runs stopped by their flag: {stopped}")
        c.check(alice_b.submit(spec(10)).status == 201, "room again for Alice once dismissed")
        for n in (a, b):
            c.check(n.stop() == 0, "a node stops cleanly")
    finally:
        a.cleanup()
        b.cleanup()


def test(c, binary, state):
    admin = pg_uri(state)
    name, uri = new_database(admin)
    tmp = gpd.tempfile.mkdtemp(prefix="grainpackd-nodes-")
    key_file = os.path.join(tmp, "keys")
    keys = gpd.write_keys(key_file, {"batch": "user", "alice": "user", "bob": "user",
                                     "ops": "admin"})
    try:
        test_batch_and_kill(c, binary, uri, keys, key_file, tmp)
        test_keys_limits_and_dismissal(c, binary, uri, keys, key_file)
    finally:
        gpd.remove_tree(tmp)
        psql(admin, f"DROP DATABASE IF EXISTS {name} WITH (FORCE)")


if __name__ == "__main__":
    gpd.main(test)
