#!/usr/bin/env python3
"""test_service_concurrency.py - 50 clients at once, each on its own connection,
submitting jobs, long-polling them, listing jobs and fetching results: no error, no lost
job, no duplicate. Usage: test_service_concurrency.py GRAINPACKD"""

import threading

import gpd

CLIENTS = 50
JOBS_PER_CLIENT = 3


def test(c, binary):
    daemon = gpd.Daemon(binary)
    try:
        daemon.start()
        errors, accepted = [], []
        lock = threading.Lock()
        start = threading.Barrier(CLIENTS)

        def client_main(k):
            client = daemon.client()
            try:
                start.wait()
                mine = []
                for j in range(JOBS_PER_CLIENT):
                    r = client.submit(gpd.small_spec(seed=k * 100 + j, side=20))
                    if r.status != 201:
                        raise AssertionError(f"submit: {r}")
                    mine.append(r.json()["jobID"])
                    if client.get("/jobs?limit=5").status != 200:
                        raise AssertionError("list")
                for job in mine:
                    info = client.wait_final(job)
                    if info["status"] != "successful":
                        raise AssertionError(f"{job}: {info}")
                    r = client.get(f"/jobs/{job}/results?f=csv")
                    if r.status != 200 or not r.body.startswith(b"x,y,r,R\n"):
                        raise AssertionError(f"results: {r}")
                with lock:
                    accepted.extend(mine)
            except Exception as e:  # reported below, with the others
                with lock:
                    errors.append(f"client {k}: {e!r}")
            finally:
                client.close()

        threads = [threading.Thread(target=client_main, args=(k,)) for k in range(CLIENTS)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        c.check(not errors, f"{len(errors)} clients failed: {errors[:3]}")
        c.check(len(accepted) == len(set(accepted)) == CLIENTS * JOBS_PER_CLIENT,
                f"{len(accepted)} jobs accepted ({len(set(accepted))} distinct)")
        client = daemon.client()
        listed = [j["jobID"] for j in client.get("/jobs?limit=1000").json()["jobs"]]
        c.check(sorted(listed) == sorted(accepted), f"{len(listed)} jobs listed")
        metrics = client.get("/metrics").body.decode()
        c.check(gpd.metric(metrics, "grainpack_jobs", 'status="successful"') == len(accepted), "jobs gauge")
        for code in range(500, 600):
            c.check(gpd.metric(metrics, "grainpack_http_requests_total", f'code="{code}"') is None, f"{code} answered")
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        with daemon.db() as db:
            c.check(db.execute("PRAGMA integrity_check").fetchone()[0] == "ok", "integrity_check")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
