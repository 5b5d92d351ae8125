#!/usr/bin/env python3
"""test_service_runaway.py - a job that will not end does not keep its worker, does not
hold up a stop, and is not run again at every start.

- A real job with balancing and cells, dismissed while it runs: its worker is free for the
  next job (the stages read their cancel flag), and the pool gives up on no worker.
- The same job past --max-job-seconds: failed with the limit's message.
- A worker that ignores its flag (the test-only fault GRAINPACKD_TEST_STALL_SECONDS makes
  the first job's stage sleep for an hour without reading it), timed out or dismissed:
  the pool gives up on it and another worker runs the next job; the job is failed or
  dismissed, /metrics counts the abandoned worker.
- SIGTERM while that worker sleeps: the daemon stops after its bound (not an hour), the
  job stays running in the store, and the next start runs it again.
- --max-job-attempts 2: a job the daemon died running twice is failed at the next start
  with a message that says so, instead of being claimed again.
Usage: test_service_runaway.py GRAINPACKD"""

import time

import gpd

STALL = {"GRAINPACKD_TEST_STALL_SECONDS": "3600"}
# About 290 000 disks, balanced and with cells: seconds of work even on a quiet machine
# (the balancing's steady stop ends it after some 8 sweeps), so that it is caught running
# in more than one stage.
STAGED = {"inputs": {"domain": {"width": 1000, "height": 1000},
                     "distribution": {"kind": "constant", "radius": 1.0},
                     "balance": {"method": "relocation", "max_iterations": 50},
                     "laguerre": {"shrink": "offset"}}}
# About 1.1 million disks, balanced: far more than the 3 s limit of the test.
TIMED = {"inputs": dict(gpd.big_spec(side=2000)["inputs"], balance={"method": "relocation"})}


def job_row(daemon, job):
    db = daemon.db()
    try:
        return db.execute("SELECT status, claims, error, message FROM jobs WHERE id = ?", (job,)).fetchone()
    finally:
        db.close()


def submit(c, client, spec):
    r = client.submit(spec)
    c.check(r.status == 201, f"submit: {r}")
    return r.json()["jobID"]


def test_real_stages_stop(c, binary):
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-job-seconds", "3")
    try:
        daemon.start()
        client = daemon.client()
        # dismissed at moments spread over its run: the next small job runs on the
        # same worker, which stopped by itself
        for delay in (0.0, 0.5, 1.5):
            job = submit(c, client, STAGED)
            client.wait_status(job, ("running",))
            time.sleep(delay)
            r = client.request("DELETE", f"/jobs/{job}")
            # a job that ended before the DELETE arrived is deleted with its results (status
            # "dismissed", that message): no worker had anything to stop
            finished = r.status == 200 and r.json().get("message") == "deleted with its results"
            if r.status == 200 and r.json()["status"] == "dismissed" and not finished:
                daemon.wait_log(f"job {job} dismissed: worker stopped")
            else:
                c.check(finished, f"DELETE after {delay} s: {r}")
            small = submit(c, client, gpd.small_spec())
            c.check(client.wait_final(small)["status"] == "successful", f"small job after a dismissal at {delay} s")
        # past its time limit: failed with the limit's message, by the worker itself
        slow = submit(c, client, TIMED)
        info = client.wait_final(slow)
        c.check(info["status"] == "failed" and "--max-job-seconds" in info["message"], f"timed out: {info}")
        metrics = client.get("/metrics").body.decode()
        c.check(gpd.metric(metrics, "grainpack_job_runs_total", 'outcome="abandoned"') == 0,
                "a worker was given up on although every stage reads its flag")
        c.check(gpd.metric(metrics, "grainpack_job_runs_total", 'outcome="timed_out"') == 1, "timed_out count")
        client.close()
        c.check(daemon.stop() == 0, "SIGTERM stop")
    finally:
        daemon.cleanup()


def test_stalled_worker_is_replaced(c, binary, how):
    args = ["--workers", "1"] + (["--max-job-seconds", "1"] if how == "timeout" else [])
    daemon = gpd.Daemon(binary, *args, env=STALL)
    try:
        daemon.start()
        client = daemon.client()
        stuck = submit(c, client, gpd.big_spec(side=300))
        client.wait_status(stuck, ("running",))
        if how == "dismissed":
            r = client.request("DELETE", f"/jobs/{stuck}")
            c.check(r.status == 200 and r.json()["status"] == "dismissed", f"DELETE: {r}")
        # the only worker sleeps for an hour: the next job runs only if it was replaced
        small = submit(c, client, gpd.small_spec())
        c.check(client.wait_final(small, limit=120)["status"] == "successful", f"{how}: the next job")
        info = client.get(f"/jobs/{stuck}").json()
        if how == "timeout":
            c.check(info["status"] == "failed" and "--max-job-seconds" in info["message"], f"stuck job: {info}")
        else:
            c.check(info["status"] == "dismissed", f"stuck job: {info}")
        metrics = client.get("/metrics").body.decode()
        c.check(gpd.metric(metrics, "grainpack_job_runs_total", 'outcome="abandoned"') == 1, f"{how}: abandoned count")
        c.check(gpd.metric(metrics, "grainpack_workers_abandoned") == 1, f"{how}: abandoned gauge")
        c.check(gpd.metric(metrics, "grainpack_workers_busy") == 0, f"{how}: busy gauge")
        c.check(f"job {stuck}: its worker did not stop" in daemon.log(), f"{how}: log")
        client.close()
        # the stop does not wait for a worker already given up on
        t0 = time.monotonic()
        c.check(daemon.stop() == 0, f"{how}: SIGTERM stop")
        c.check(time.monotonic() - t0 < 60, f"{how}: the stop waited for the stalled worker")
    finally:
        daemon.cleanup()


def test_stop_is_bounded_and_attempts_are_counted(c, binary):
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-job-attempts", "2", env=STALL)
    try:
        daemon.start()
        client = daemon.client()
        stuck = submit(c, client, gpd.big_spec(side=300))
        client.wait_status(stuck, ("running",))
        client.close()
        # SIGTERM while the worker ignores its flag: the daemon stops (in seconds, not in
        # the hour the worker sleeps), the job stays running, with its claim
        c.check(daemon.stop() == 0, "SIGTERM with a stalled worker")
        c.check("worker threads did not stop within" in daemon.log(), "the stop's log")
        c.check(job_row(daemon, stuck)[:2] == ("running", 1), f"after the bounded stop: {job_row(daemon, stuck)}")
        # the next start queues it again and runs it: the first job again, it stalls again
        daemon.start()
        c.check("1 of them queued again" in daemon.log(), "second start: requeued")
        client = daemon.client()
        client.wait_status(stuck, ("running",))
        client.close()
        daemon.kill()
        c.check(job_row(daemon, stuck)[:2] == ("running", 2), f"after SIGKILL: {job_row(daemon, stuck)}")
        # died running it twice (--max-job-attempts 2): failed, not claimed again
        del daemon.env["GRAINPACKD_TEST_STALL_SECONDS"]
        daemon.start()
        c.check("1 jobs the daemon died running 2 times failed" in daemon.log(), "third start's log")
        row = job_row(daemon, stuck)
        c.check(row[0] == "failed" and row[2] == "gave up" and "stopped 2 times" in row[3]
                and "--max-job-attempts 2" in row[3], f"the job at the third start: {row}")
        client = daemon.client()
        info = client.get(f"/jobs/{stuck}").json()
        c.check(info["status"] == "failed" and "not run again" in info["message"], f"its status: {info}")
        small = submit(c, client, gpd.small_spec())
        c.check(client.wait_final(small)["status"] == "successful", "a job after the given-up one")
        client.close()
        c.check(daemon.stop() == 0, "last SIGTERM stop")
    finally:
        daemon.cleanup()


def test(c, binary):
    test_real_stages_stop(c, binary)
    test_stalled_worker_is_replaced(c, binary, "timeout")
    test_stalled_worker_is_replaced(c, binary, "dismissed")
    test_stop_is_bounded_and_attempts_are_counted(c, binary)


if __name__ == "__main__":
    gpd.main(test)
