#!/usr/bin/env python3
"""test_service_jobs.py - following and managing jobs: progress of a running job,
dismissing a running large job (its worker stops: the run ends as 'dismissed', not as a
finished run whose result is thrown away), dismissing a queued job (it never runs), deleting finished jobs, the
long-poll woken by a dismissal, the job list's pagination and status filter, the queue
cap (503 + Retry-After) and CORS. Usage: test_service_jobs.py GRAINPACKD"""

import threading

import gpd

ORIGIN = "https://lab.example"


def runs(client, outcome):
    return gpd.metric(client.get("/metrics").body.decode(), "grainpack_job_runs_total", f'outcome="{outcome}"')


def test_dismissal(c, api, daemon, client):
    big = client.submit(gpd.big_spec())
    c.check(big.status == 201, f"big job: {big}")
    big_id = big.json()["jobID"]
    queued = client.submit(gpd.small_spec(seed=3))  # behind the big one: one worker
    queued_id = queued.json()["jobID"]
    client.wait_status(big_id, ("running",))
    # progress is published while it packs
    for _ in range(3000):
        info = client.get(f"/jobs/{big_id}").json()
        if info["progress"] > 0 or info["status"] != "running":
            break
        threading.Event().wait(0.02)
    c.check(info["status"] == "running" and 0 < info["progress"] < 100
            and info["message"].startswith("running: pack"), f"progress of the big job: {info}")

    # a long-poll on the running job, answered by the dismissal (not by its 60 s deadline)
    polled = {}

    def long_poll():
        polled["r"] = daemon.client().get(f"/jobs/{big_id}?wait=60")
    poller = threading.Thread(target=long_poll)
    poller.start()

    r = client.request("DELETE", f"/jobs/{queued_id}")
    api.check(c, "DELETE", "/jobs/{jobId}", r)
    c.check(r.status == 200 and r.json()["status"] == "dismissed", f"dismiss queued: {r}")
    r = client.request("DELETE", f"/jobs/{big_id}")
    api.check(c, "DELETE", "/jobs/{jobId}", r)
    c.check(r.status == 200 and r.json()["status"] == "dismissed", f"dismiss running: {r}")
    poller.join(120)
    c.check("r" in polled and polled["r"].json()["status"] == "dismissed",
            f"long-poll answered with {polled.get('r')}")

    # the worker stopped the job rather than finishing it: its run ends as dismissed
    for _ in range(6000):
        if runs(client, "dismissed") == 1:
            break
        threading.Event().wait(0.02)
    c.check(runs(client, "dismissed") == 1, "the big job's run did not end as dismissed")
    c.check(runs(client, "discarded") == 0, "the big job ran to its end after the dismissal")
    info = client.get(f"/jobs/{big_id}").json()
    c.check(info["status"] == "dismissed" and info["progress"] < 100, f"dismissed job: {info}")
    r = client.get(f"/jobs/{big_id}/results")
    api.check(c, "GET", "/jobs/{jobId}/results", r)
    c.check(r.status == 404 and r.json()["type"] == "urn:grainpack:problem:job-dismissed",
            f"results of a dismissed job: {r}")
    # the worker is free: a new job runs
    after = client.submit(gpd.small_spec(seed=4)).json()["jobID"]
    c.check(client.wait_final(after)["status"] == "successful", "a job after the dismissal")
    with daemon.db() as db:
        row = db.execute("SELECT status, started, claims FROM jobs WHERE id = ?", (queued_id,)).fetchone()
        c.check(row == ("dismissed", None, 0), f"the dismissed queued job ran: {row}")
        row = db.execute("SELECT status, count, claims FROM jobs WHERE id = ?", (big_id,)).fetchone()
        c.check(row == ("dismissed", None, 1), f"the dismissed running job: {row}")
        c.check(db.execute("SELECT count(*) FROM result_sections WHERE job_id = ?", (big_id,)).fetchone()[0] == 0,
                "a dismissed job has a result")

    # deleting finished jobs: gone with their rows
    for job in (big_id, after):
        r = client.request("DELETE", f"/jobs/{job}")
        c.check(r.status == 200 and r.json()["status"] == "dismissed", f"delete {job}: {r}")
        r = client.get(f"/jobs/{job}")
        c.check(r.status == 404, f"GET a deleted job: {r}")
        with daemon.db() as db:
            for table, key in (("jobs", "id"), ("result_sections", "job_id"), ("bin_stats", "job_id"),
                               ("stage_timings", "job_id")):
                n = db.execute(f"SELECT count(*) FROM {table} WHERE {key} = ?", (job,)).fetchone()[0]
                c.check(n == 0, f"{table} keeps {n} rows of deleted job {job}")
            n = db.execute("SELECT count(*) FROM result_chunks WHERE section NOT IN"
                           " (SELECT id FROM result_sections)").fetchone()[0]
            c.check(n == 0, f"{n} chunks of deleted results are left")
    return queued_id


def test_list(c, api, client, kept):
    ids = []
    for seed in range(25):
        r = client.submit(gpd.small_spec(seed=100 + seed))
        c.check(r.status == 201, f"submit {seed}: {r}")
        ids.append(r.json()["jobID"])
    for job in ids:
        client.wait_final(job)
    expected = list(reversed(ids)) + [kept]  # newest first; the dismissed job is older
    seen, path, pages = [], "/jobs?limit=10", 0
    while path:
        r = client.get(path)
        api.check(c, "GET", "/jobs", r)
        page = r.json()
        c.check(len(page["jobs"]) <= 10, f"page of {len(page['jobs'])}")
        seen += [j["jobID"] for j in page["jobs"]]
        nxt = [link["href"] for link in page["links"] if link["rel"] == "next"]
        path = nxt[0] if nxt else None
        pages += 1
        if pages > 10:
            break
    c.check(seen == expected, f"paginated list {len(seen)} jobs, expected {len(expected)} newest first")
    c.check(pages == 3, f"{pages} pages of 10 for 26 jobs")

    r = client.get("/jobs?status=successful&limit=1000")
    jobs = r.json()["jobs"]
    c.check([j["jobID"] for j in jobs] == list(reversed(ids)), "status=successful lists the 25 jobs")
    c.check(all(j["status"] == "successful" for j in jobs), "status=successful lists other statuses")
    r = client.get("/jobs?status=dismissed")
    c.check([j["jobID"] for j in r.json()["jobs"]] == [kept], f"status=dismissed: {r}")
    r = client.get("/jobs?status=failed,dismissed,running")
    c.check([j["jobID"] for j in r.json()["jobs"]] == [kept], f"status=failed,dismissed,running: {r}")
    # the filter survives in the next link
    r = client.get("/jobs?status=successful&limit=20").json()
    nxt = [link["href"] for link in r["links"] if link["rel"] == "next"]
    c.check(nxt and "status=successful" in nxt[0], f"next link {nxt}")
    rest = client.get(nxt[0]).json()["jobs"] if nxt else []
    c.check([j["jobID"] for j in r["jobs"] + rest] == list(reversed(ids)), "filtered pages")


def test_queue_cap(c, api, binary):
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-queued", "2", "--cors-origins", ORIGIN,
                        "--max-disks", "10000000")
    try:
        daemon.start()
        client = daemon.client()
        running = client.submit(gpd.big_spec()).json()["jobID"]
        client.wait_status(running, ("running",))
        statuses = [client.submit(gpd.small_spec(seed=s)) for s in range(3)]
        c.check([r.status for r in statuses] == [201, 201, 503], f"queue cap: {[r.status for r in statuses]}")
        full = statuses[-1]
        api.check(c, "POST", "/processes/{processId}/execution", full)
        c.check(full.json()["type"] == "urn:grainpack:problem:queue-full" and int(full.headers["retry-after"]) > 0,
                f"queue full: {full}")
        c.check(client.get("/health").json()["queue_depth"] == 2, "queue depth")

        # CORS: the allowed origin gets the header, another does not; preflight
        r = client.get("/jobs", headers={"Origin": ORIGIN})
        c.check(r.headers.get("access-control-allow-origin") == ORIGIN, f"CORS allowed: {r.headers}")
        r = client.get("/jobs", headers={"Origin": "https://elsewhere.example"})
        c.check("access-control-allow-origin" not in r.headers, "CORS for another origin")
        r = client.request("OPTIONS", "/processes/pack2d/execution",
                           headers={"Origin": ORIGIN, "Access-Control-Request-Method": "POST"})
        c.check(r.status == 204 and "POST" in r.headers.get("access-control-allow-methods", ""),
                f"preflight: {r.status} {r.headers}")
        r = client.submit(gpd.small_spec())
        c.check(r.status == 503, "still full")

        client.request("DELETE", f"/jobs/{running}")
        for s in statuses[:2]:
            c.check(client.wait_final(s.json()["jobID"])["status"] == "successful", "queued jobs run")
        client.close()
        c.check(daemon.stop() == 0, "stop")
    finally:
        daemon.cleanup()


def test(c, binary):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-disks", "10000000")
    try:
        daemon.start()
        client = daemon.client()
        kept = test_dismissal(c, api, daemon, client)
        test_list(c, api, client, kept)
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
    finally:
        daemon.cleanup()
    test_queue_cap(c, api, binary)


if __name__ == "__main__":
    gpd.main(test)
