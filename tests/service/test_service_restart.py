#!/usr/bin/env python3
"""test_service_restart.py - nothing accepted is lost: a batch is submitted, the daemon
is killed with SIGKILL while a job runs, started again on the same database; every
accepted job reaches successful (the one that was running is queued again and run a
second time), and the database passes PRAGMA integrity_check. A second daemon on the
same database is refused. A clean SIGTERM stop in the middle of a job queues it again
too. Usage: test_service_restart.py GRAINPACKD"""

import gpd

# A job long enough to be caught running (about a million disks), then small ones.
LONG = gpd.big_spec(side=2000)
SMALL = 8


def submit_batch(c, client):
    ids = []
    for spec in [LONG] + [gpd.small_spec(seed=s) for s in range(SMALL)]:
        r = client.submit(spec)
        c.check(r.status == 201, f"submit: {r}")
        ids.append(r.json()["jobID"])
    return ids


def statuses(daemon, ids):
    with daemon.db() as db:
        return {row[0]: row[1:] for row in db.execute(
            "SELECT id, status, claims FROM jobs WHERE id IN (%s)" % ",".join("?" * len(ids)), ids)}


def test(c, binary):
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-disks", "10000000")
    try:
        # SIGKILL while the long job runs
        daemon.start()
        client = daemon.client()
        ids = submit_batch(c, client)
        client.wait_status(ids[0], ("running",))
        daemon.kill()
        client.close()
        before = statuses(daemon, ids)
        c.check(len(before) == len(ids), f"{len(before)} of {len(ids)} accepted jobs in the database after SIGKILL")
        c.check(before.get(ids[0], (None,))[0] == "running", f"the long job after SIGKILL: {before.get(ids[0])}")
        c.check(all(before[j][0] == "accepted" for j in ids[1:]), f"queued jobs after SIGKILL: {before}")

        daemon.start()
        c.check("1 of them queued again" in daemon.log(), "start-up log does not report the requeue")
        # a second daemon on the same database would queue the running jobs again: refused
        other = gpd.Daemon(binary, "--db", daemon.db_path)
        try:
            other.start()
            c.check(False, "a second grainpackd started on the same database")
        except AssertionError as e:
            c.check("another grainpackd is using" in str(e), f"second daemon: {e}")
        finally:
            other.cleanup()
        client = daemon.client()
        for job in ids:
            info = client.wait_final(job)
            c.check(info["status"] == "successful", f"job {job} after restart: {info}")
        after = statuses(daemon, ids)
        c.check(after[ids[0]] == ("successful", 2), f"the long job was not run again: {after[ids[0]]}")
        c.check(all(after[j] == ("successful", 1) for j in ids[1:]), f"the other jobs: {after}")
        c.check(client.get(f"/jobs/{ids[0]}/results?f=csv").status == 200, "the requeued job's result")

        # SIGTERM while a job runs: it is queued again, and runs after the next start
        term = client.submit(LONG).json()["jobID"]
        client.wait_status(term, ("running",))
        client.close()
        c.check(daemon.stop() == 0, "SIGTERM stop")
        c.check("queued again, the daemon is stopping" in daemon.log(), "SIGTERM log")
        # a clean stop gives the claim back: only the runs the daemon died in count
        # against --max-job-attempts
        c.check(statuses(daemon, [term])[term] == ("accepted", 0), f"after SIGTERM: {statuses(daemon, [term])}")
        daemon.start()
        client = daemon.client()
        c.check(client.wait_final(term)["status"] == "successful", "the job stopped by SIGTERM")
        client.close()
        c.check(daemon.stop() == 0, "second SIGTERM stop")

        with daemon.db() as db:
            c.check(db.execute("PRAGMA integrity_check").fetchone()[0] == "ok", "integrity_check")
            c.check(db.execute("PRAGMA user_version").fetchone()[0] == 3, "schema version")
            n = db.execute("SELECT count(*) FROM jobs WHERE status = 'successful'").fetchone()[0]
            c.check(n == len(ids) + 1, f"{n} successful jobs")
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
