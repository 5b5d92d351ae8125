#!/usr/bin/env python3
"""test_service_crash.py - SIGKILL during writes under load, then restart, several rounds
on one database: clients submit, poll and download while two workers store results;
the daemon is killed after a number of accepted jobs that differs each round. After
each kill the database passes integrity_check and holds no half-written result; after
the restart every job that got its 201 is there and reaches successful, and every
result served is complete (as many CSV lines as the job's disk count) and the same as
before the kill. Usage: test_service_crash.py GRAINPACKD [ROUNDS]"""

import http.client
import random
import threading

import gpd

CLIENTS = 6
ROUNDS = 3
BURST = 4  # jobs a client submits before it waits for the last: the queue never drains


def small(seed):
    """A job of a few thousand disks: packed in milliseconds, a result of tens of KB to
    store."""
    side = 40 + seed % 37
    return {"inputs": {"domain": {"width": side, "height": side},
                       "distribution": {"kind": "uniform", "min": 0.4, "max": 0.9},
                       "joint": {"law": "inverse", "k": 0.05}, "seed": seed}}


def csv_lines(client, job):
    r = client.get(f"/jobs/{job}/results?f=csv")
    return r.body.count(b"\n") if r.status == 200 else None


class Load:
    """Clients submitting, polling and downloading until the daemon dies."""

    def __init__(self, port, seed_base):
        self.port = port
        self.seed_base = seed_base
        self.lock = threading.Lock()
        self.accepted = []
        self.served = {}  # job -> CSV lines of a result downloaded while the daemon ran
        self.problems = []
        self.stop = threading.Event()

    def client(self, k):
        client = gpd.Client(self.port, timeout=60)
        seed = self.seed_base + k * 100000
        try:
            while not self.stop.is_set():
                job = None
                for _ in range(BURST):
                    seed += 1
                    r = client.submit(small(seed))
                    if r.status != 201:
                        self.problems.append(f"submit: {r}")
                        continue
                    job = r.json()["jobID"]
                    with self.lock:
                        self.accepted.append(job)
                if job is None:
                    continue
                info = client.get(f"/jobs/{job}?wait=5").json()
                if info["status"] == "successful":
                    lines = csv_lines(client, job)
                    with self.lock:
                        self.served[job] = lines
        except (OSError, http.client.HTTPException, ValueError):
            pass  # the daemon was killed
        finally:
            client.close()

    def count(self):
        with self.lock:
            return len(self.accepted)


def test(c, binary, rounds=ROUNDS):
    rng = random.Random(6)
    daemon = gpd.Daemon(binary, "--workers", "2")
    accepted, served = [], {}
    try:
        for rnd in range(int(rounds)):
            daemon.start()
            load = Load(daemon.port, rnd * 10 ** 7)
            threads = [threading.Thread(target=load.client, args=(k,)) for k in range(CLIENTS)]
            for t in threads:
                t.start()
            kill_at = rng.randint(30, 90)  # accepted jobs, not seconds: no timing
            while load.count() < kill_at and all(t.is_alive() for t in threads):
                threading.Event().wait(0.005)
            daemon.kill()
            load.stop.set()
            for t in threads:
                t.join()
            c.check(not load.problems, f"round {rnd}: errors under load: {load.problems[:3]}")
            accepted += load.accepted
            served.update({j: n for j, n in load.served.items() if n is not None})
            after_kill = gpd.check_store(c, daemon, f"round {rnd} after SIGKILL")
            lost = [j for j in accepted if j not in after_kill]
            c.check(not lost, f"round {rnd}: {len(lost)} accepted jobs lost by the kill: {lost[:3]}")
            print(f"     round {rnd}: killed after {load.count()} accepted jobs "
                  f"({sum(s == 'running' for s in after_kill.values())} running, "
                  f"{sum(s == 'accepted' for s in after_kill.values())} queued)")

        daemon.start()
        client = daemon.client()
        for job in accepted:
            c.check(client.wait_final(job)["status"] == "successful", f"job {job} after the restarts")
        # and those stored when a kill cut their 201 short: they run too
        for job in gpd.check_store(c, daemon, "after the last restart, before the last jobs end"):
            client.wait_final(job)
        final = gpd.check_store(c, daemon, "after the last restart")
        c.check(all(s == "successful" for s in final.values()),
                f"jobs not successful: {[j for j, s in final.items() if s != 'successful'][:5]}")
        with daemon.db() as db:
            counts = dict(db.execute("SELECT id, count FROM jobs").fetchall())
        for job in accepted:
            lines = csv_lines(client, job)
            c.check(lines == counts[job] + 1, f"job {job}: {lines} CSV lines for {counts[job]} disks")
            if job in served:
                c.check(served[job] == lines, f"job {job}: served {served[job]} lines before, {lines} after")
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        print(f"     {len(accepted)} accepted jobs over {rounds} kills, none lost; {len(served)} results "
              "served before a kill, unchanged after")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
