#!/usr/bin/env python3
"""test_service_slow_clients.py - connections held for ever, over raw sockets.

- Slowloris: connections that trickle their request head (a byte of the request line, or
  of a header, now and then, never silent for --connection-timeout) are closed once the
  head is --connection-timeout late, with a 408 problem+json first when the request line
  had come; so is a kept-alive connection that starts a second request and trickles it,
  and one that stays idle after its response is closed without a 408 (its client would
  take it for the answer to its next request). A head sent in a few pieces but in time
  is answered; /health is answered all along.
- Abandoned long-polls: `?wait=` requests whose clients close their sockets give back
  their places at once: as many new long-polls as --max-connections-per-ip from the same
  address are not refused, and --max-connections in all from several loopback addresses
  (127.0.0.2-5) leave room for more; /metrics counts the hang-ups. A long-poll whose
  client stays gets its answer when the job ends.
Usage: test_service_slow_clients.py GRAINPACKD"""

import json
import socket
import time

import gpd

TIMEOUT = 2  # --connection-timeout of the slowloris daemon


def connect(port, source="127.0.0.1"):
    s = socket.socket()
    s.bind((source, 0))
    s.connect(("127.0.0.1", port))
    return s


def read_until_closed(s, limit):
    """What the daemon sends until it closes s, and when it closed (None: not within limit)."""
    s.settimeout(0.05)
    out, end = b"", time.monotonic() + limit
    while time.monotonic() < end:
        try:
            piece = s.recv(65536)
        except socket.timeout:
            continue
        except ConnectionResetError:
            return out, time.monotonic()
        if not piece:
            return out, time.monotonic()
        out += piece
    return out, None


def read_response(s, limit):
    """(status, body) of the first whole response on s, or (None, what came) after limit."""
    s.settimeout(limit)
    data = b""
    try:
        while True:
            status, headers, body = gpd.parse_raw(data)
            if status is not None and len(body) >= int(headers.get("content-length", 0)):
                return status, body
            piece = s.recv(65536)
            if not piece:
                break
            data += piece
    except OSError:
        pass
    return None, data


def test_slowloris(c, binary):
    daemon = gpd.Daemon(binary, "--connection-timeout", str(TIMEOUT))
    try:
        daemon.start()
        port = daemon.port
        client = daemon.client()
        # tricklers: in the request line, in a header, and a kept-alive connection's
        # second request
        prefixes = [b"GET /hea", b"GET /health HTTP/1.1\r\nHost: x\r\nX-Slow: a"] * 5
        socks, started = [], time.monotonic()
        for prefix in prefixes:
            s = connect(port)
            s.sendall(prefix)
            socks.append(s)
        kept = connect(port)
        kept.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
        first = b""
        while b"}" not in first:
            first += kept.recv(65536)
        c.check(first.startswith(b"HTTP/1.1 200"), f"the kept-alive connection's first answer: {first[:100]!r}")
        kept.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n")
        kept_at = time.monotonic()
        socks.append(kept)
        # trickle a byte every 0.3 s (never silent for TIMEOUT), and ask /health meanwhile
        closed = {}
        answers = {}
        while len(closed) < len(socks) and time.monotonic() - started < 4 * TIMEOUT + 5:
            for i, s in enumerate(socks):
                if i in closed:
                    continue
                s.setblocking(False)
                try:
                    data = s.recv(65536)
                    if data:
                        answers[i] = answers.get(i, b"") + data
                    else:
                        closed[i] = time.monotonic()
                        continue
                except BlockingIOError:
                    pass
                except ConnectionResetError:
                    closed[i] = time.monotonic()
                    continue
                try:
                    s.send(b"b")
                except OSError:
                    closed[i] = time.monotonic()
            r = client.get("/health")
            c.check(r.status == 200, f"/health during the slowloris: {r}")
            time.sleep(0.3)
        c.check(len(closed) == len(socks), f"{len(socks) - len(closed)} trickling connections still open "
                f"after {4 * TIMEOUT + 5} s")
        for i, s in enumerate(socks):
            since = kept_at if s is kept else started
            if i in closed:
                late = closed[i] - since
                c.check(TIMEOUT - 0.1 <= late <= 2 * TIMEOUT + 1, f"trickler {i} closed after {late:.2f} s")
            status, headers, body = gpd.parse_raw(answers.get(i, b""))
            if s is not kept and prefixes[i].startswith(b"GET /hea") and b" " not in prefixes[i][4:]:
                c.check(not answers.get(i), f"trickler {i} in its request line got an answer: {answers.get(i)!r}")
            else:
                c.check(status == 408 and headers.get("content-type") == "application/problem+json"
                        and json.loads(body)["type"] == "urn:grainpack:problem:request-timeout",
                        f"trickler {i}'s answer: {answers.get(i, b'')[:200]!r}")
            s.close()
        # idle after its response: closed, without an answer
        idle = connect(port)
        idle.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
        status, _ = read_response(idle, 10)
        c.check(status == 200, "the idle connection's one request")
        data, when = read_until_closed(idle, 3 * TIMEOUT + 2)
        c.check(when is not None and data == b"", f"an idle kept-alive connection: {data[:100]!r}, closed: {when}")
        idle.close()
        # a head in a few pieces, all in time: answered
        s = connect(port)
        for piece in (b"GET /hea", b"lth HTTP/1.1\r\n", b"Host: x\r\n", b"\r\n"):
            s.sendall(piece)
            time.sleep(TIMEOUT / 8)
        data, _ = read_until_closed(s, 1)
        c.check(data.startswith(b"HTTP/1.1 200"), f"a head in pieces: {data[:100]!r}")
        s.close()
        metrics = client.get("/metrics").body.decode()
        # (the idle one may be closed by libmicrohttpd's own silence timeout first)
        c.check(gpd.metric(metrics, "grainpack_http_slow_heads_total") in (len(socks), len(socks) + 1),
                f"slow heads counted: {gpd.metric(metrics, 'grainpack_http_slow_heads_total')} of {len(socks) + 1}")
        client.close()
        c.check(daemon.stop() == 0, "slowloris daemon stop")
    finally:
        daemon.cleanup()


def open_polls(port, job, sources, count):
    socks = []
    for i in range(count):
        s = connect(port, sources[i % len(sources)])
        s.sendall(f"GET /jobs/{job}?wait=60 HTTP/1.1\r\nHost: x\r\n\r\n".encode())
        socks.append(s)
    return socks


def test_abandoned_polls(c, binary):
    per_ip, total = 20, 60
    # the first job stalls for an hour (the test-only fault): the waits never end by
    # themselves during the test
    daemon = gpd.Daemon(binary, "--workers", "1", "--max-connections-per-ip", str(per_ip),
                        "--max-connections", str(total), env={"GRAINPACKD_TEST_STALL_SECONDS": "3600"})
    try:
        daemon.start()
        port = daemon.port
        client = daemon.client()
        job = client.submit(gpd.small_spec()).json()["jobID"]
        client.wait_status(job, ("running",))
        client.close()
        # as many as one address may hold, abandoned, then as many again, and again: each
        # time every one waits (none refused, none answered), and every hang-up is seen
        hung_up = 0
        rounds = [(["127.0.0.2"], per_ip)] * 4 + [([f"127.0.0.{k}" for k in range(2, 6)], total - 5)] * 2
        for sources, count in rounds:
            socks = open_polls(port, job, sources, count)
            time.sleep(0.5)
            answered = 0
            for s in socks:
                s.setblocking(False)
                try:
                    answered += len(s.recv(64)) > 0
                except BlockingIOError:
                    pass  # still waiting: as it should
                s.close()
            c.check(answered == 0, f"{answered} of {count} long-polls from {len(sources)} addresses answered "
                    f"(429) instead of waiting, after {hung_up} others were abandoned")
            hung_up += count
            deadline = time.monotonic() + 30
            # counted when the wait is released; the place is given back once libmicrohttpd
            # closes the connection (on a loaded machine, a little later): both awaited,
            # the probe's own connection the only one left
            while time.monotonic() < deadline:
                probe = daemon.client()
                metrics = probe.get("/metrics").body.decode()
                probe.close()
                seen = gpd.metric(metrics, "grainpack_http_long_polls_hung_up_total")
                still = gpd.metric(metrics, "grainpack_http_connections")
                if seen == hung_up and still == 1:
                    break
                time.sleep(0.05)
            c.check(seen == hung_up, f"hang-ups counted: {seen} of {hung_up}")
            c.check(still == 1, f"{still} connections open after the hang-ups (the probe's only expected)")
        # as many connections at once as the hang-ups gave back, from other addresses
        fresh = [connect(port, f"127.0.0.{6 + k % 4}") for k in range(total - 5)]
        for f in fresh:
            f.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
        ok = sum(read_response(f, 10)[0] == 200 for f in fresh)
        c.check(ok == total - 5, f"only {ok} of {total - 5} clients answered after the hang-ups")
        for f in fresh:
            f.close()
        # a client that stays gets its answer when the job ends (dismissed here)
        stay = connect(port)
        stay.sendall(f"GET /jobs/{job}?wait=60 HTTP/1.1\r\nHost: x\r\n\r\n".encode())
        time.sleep(0.3)
        admin = daemon.client()
        c.check(admin.request("DELETE", f"/jobs/{job}").status == 200, "dismiss")
        status, body = read_response(stay, 10)
        c.check(status == 200 and json.loads(body)["status"] == "dismissed", f"the staying long-poll: {status} {body[:200]!r}")
        stay.close()
        admin.close()
        c.check(daemon.stop() == 0, "long-poll daemon stop")
    finally:
        daemon.cleanup()


def test(c, binary):
    test_slowloris(c, binary)
    test_abandoned_polls(c, binary)


if __name__ == "__main__":
    gpd.main(test)
