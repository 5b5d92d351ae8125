#!/usr/bin/env python3
"""test_service_limits.py - the limits that protect the service, each with its problem:
a job running past --max-job-seconds fails with a message saying so (and the worker goes
on); more connections from one address than --max-connections-per-ip get 429 and are
closed (far more are dropped by libmicrohttpd), and the count goes down as they close; a
request line or headers over --max-header-bytes get 414/431 (far over: libmicrohttpd's
own 431); more histogram bins than --max-bins get 422; a silent client is disconnected
after --connection-timeout while a long-poll outlives it.
Usage: test_service_limits.py GRAINPACKD"""

import socket
import time

import gpd

PER_IP = 4
HARD_MARGIN = 16  # server/http.c, PER_IP_HARD_MARGIN
HEADER_CAP = 2048


def problem(c, r, status, ptype, word, what):
    return gpd.check_problem(c, r, status, ptype, word, what)


def closed_by_daemon(sock, limit=gpd.STARTUP_LIMIT):
    """Whether the daemon closes sock (reads EOF or a reset) within the limit, having sent
    nothing."""
    sock.settimeout(limit)
    try:
        return sock.recv(100) == b""
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False


def closed_after_408_or_nothing(sock, limit=gpd.STARTUP_LIMIT):
    """Whether the daemon closes sock within the limit having sent nothing or a 408."""
    sock.settimeout(limit)
    data = b""
    try:
        while piece := sock.recv(4096):
            data += piece
    except ConnectionResetError:
        pass
    except socket.timeout:
        return False
    return data == b"" or data.startswith(b"HTTP/1.1 408")


def test_job_time_limit(c, api, binary):
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-job-seconds", "0.2", "--max-disks", "10000000")
    try:
        daemon.start()
        client = daemon.client()
        slow = client.submit(gpd.big_spec()).json()["jobID"]
        after = client.submit(gpd.small_spec()).json()["jobID"]
        info = client.wait_final(slow)
        c.check(info["status"] == "failed" and "--max-job-seconds" in info["message"]
                and "stopped after" in info["message"], f"the slow job: {info}")
        r = client.get(f"/jobs/{slow}/results")
        problem(c, r, 404, "urn:grainpack:problem:job-failed", "--max-job-seconds", "results of the stopped job")
        api.check(c, "GET", "/jobs/{jobId}/results", r)
        c.check(client.wait_final(after)["status"] == "successful", "the next job runs")
        metrics = client.get("/metrics").body.decode()
        c.check(gpd.metric(metrics, "grainpack_job_runs_total", 'outcome="timed_out"') == 1, "timed_out counted")
        with daemon.db() as db:
            row = db.execute("SELECT error FROM jobs WHERE id = ?", (slow,)).fetchone()
        c.check(row == ("time limit",), f"error column: {row}")
        client.close()
        c.check(daemon.stop() == 0, "stop")
    finally:
        daemon.cleanup()


def test_connections_and_headers(c, api, binary):
    daemon = gpd.Daemon(binary, "--max-connections-per-ip", str(PER_IP), "--max-header-bytes", str(HEADER_CAP),
                        "--max-bins", "100")
    try:
        daemon.start()
        idle = [socket.create_connection(("127.0.0.1", daemon.port)) for _ in range(PER_IP)]
        extra = daemon.client()
        r = extra.get("/health")
        problem(c, r, 429, "urn:grainpack:problem:too-many-connections", "--max-connections-per-ip",
                "a connection over the limit")
        c.check(int(r.headers.get("retry-after", 0)) > 0 and r.headers.get("connection") == "close",
                f"429 headers: {r.headers}")
        api.check(c, "GET", "/health", r)
        extra.close()
        # far over the limit, libmicrohttpd drops new connections without a word
        flood = [socket.create_connection(("127.0.0.1", daemon.port)) for _ in range(HARD_MARGIN + 4)]
        dropped = sum(closed_by_daemon(s, 5) for s in flood[HARD_MARGIN - 1:])
        c.check(dropped >= 4, f"{dropped} of the connections beyond the hard limit dropped")
        for s in flood + idle:
            s.close()
        deadline = time.monotonic() + gpd.STARTUP_LIMIT
        status = None
        while True:  # the daemon counts the closed connections out as it notices them
            fresh = daemon.client()
            try:
                status = fresh.get("/health").status
            except ConnectionError:
                status = None  # libmicrohttpd's hard limit has not seen them close yet
            fresh.close()
            if status == 200 or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        c.check(status == 200, f"after the connections closed: {status}")

        client = daemon.client()
        r = client.get("/health", headers={"X-Padding": "a" * (HEADER_CAP + 100)})
        problem(c, r, 431, "urn:grainpack:problem:headers-too-large", "--max-header-bytes", "a large header")
        api.check(c, "GET", "/health", r)
        client.close()
        r = client.get("/jobs?status=" + "x" * (HEADER_CAP + 100))
        problem(c, r, 414, "urn:grainpack:problem:uri-too-long", "--max-header-bytes", "a long query")
        api.check(c, "GET", "/jobs", r)
        client.close()
        status, headers, body = gpd.parse_raw(gpd.raw_exchange(
            daemon.port, b"GET /health HTTP/1.1\r\nHost: x\r\nX-Huge: " + b"a" * 60000 + b"\r\n\r\n"))
        c.check(status == 431 and "content-type" not in headers, f"libmicrohttpd's own 431: {status} {headers}")
        bins = [{"min": 0.5 + i * 0.001, "max": 0.5 + (i + 1) * 0.001, "p": 1 / 101} for i in range(101)]
        spec = {"inputs": {"domain": {"width": 100, "height": 100}, "distribution": {"kind": "histogram", "bins": bins}}}
        r = client.submit(spec)
        problem(c, r, 422, "urn:grainpack:problem:job-too-big", "100", "more bins than --max-bins")
        c.check(client.get("/health").json()["status"] == "ok", "healthy after the limits")
        client.close()
        c.check(daemon.stop() == 0, "stop")
    finally:
        daemon.cleanup()


def test_slow_clients(c, binary):
    daemon = gpd.Daemon(binary, "--connection-timeout", "1", "--workers", "1", "--max-disks", "10000000")
    try:
        daemon.start()
        silent = socket.create_connection(("127.0.0.1", daemon.port))
        c.check(closed_by_daemon(silent), "a silent client is disconnected")
        silent.close()
        half = socket.create_connection(("127.0.0.1", daemon.port))
        half.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n")  # and never the end of the headers
        # closed by libmicrohttpd's idle timeout (nothing sent) or by the head deadline,
        # whichever comes first: the latter answers 408 first, as its request line came
        c.check(closed_after_408_or_nothing(half), "a client that stops mid-headers is disconnected")
        half.close()
        # a long-poll waits longer than the timeout (the big job packs for seconds): it is
        # answered, not cut off, because suspended connections are not timed out
        client = daemon.client()
        job = client.submit(gpd.big_spec()).json()["jobID"]
        r = client.get(f"/jobs/{job}?wait=30")
        c.check(r.status == 200 and r.json()["jobID"] == job, f"the long-poll: {r}")
        client.close()
        c.check(daemon.stop() == 0, "stop")
    finally:
        daemon.cleanup()


def test(c, binary):
    api = gpd.OpenAPI()
    test_job_time_limit(c, api, binary)
    test_connections_and_headers(c, api, binary)
    test_slow_clients(c, binary)


if __name__ == "__main__":
    gpd.main(test)
