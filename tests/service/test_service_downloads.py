#!/usr/bin/env python3
"""test_service_downloads.py - a job balanced and with Laguerre cells (some 12 000 grains:
seconds even under the sanitizers; bench/downloads.sh measures the 10^6 case) served from
what the worker stored:

- downloads of every format, plain and gzip, HEAD and 304 answers, run no pipeline (the
  daemon's grainpack_pipeline_runs_total stays where it was);
- their bytes (decompressed) are the very bytes `grainpack run` writes for the same spec;
- gzip only when Accept-Encoding allows it, with Vary; a strong ETag per result, format and
  encoding, 304 on If-None-Match (weak comparison, lists, *), Content-Disposition
  job-<id>.<format>;
- 20 downloads at once keep the daemon's peak RSS within RSS_BOUND of what it was idle
  (checked in the optimised build; under AddressSanitizer, whose quarantine keeps freed
  memory, the figure is only printed);
- a download paused mid-stream by its client holds no read transaction: a WAL checkpoint
  then completes;
- ?color= recolours the streamed SVG (the command line's bytes for that picture.color) and
  its ETag names the colouring, so a copy of one colouring is never taken for the other.

Usage: test_service_downloads.py GRAINPACKD GRAINPACK"""

import gzip
import http.client
import os
import sqlite3
import subprocess
import threading
import time

import gpd

FORMATS = ("json", "csv", "svg", "vtk")
# The job: the Bagi law on 56 x 56 (about 11 600 grains), two sweeps of relocation,
# offset cells, coloured by F: every section a result can have.
SPEC = {"inputs": {"domain": {"width": 56, "height": 56},
                   "distribution": {"kind": "uniform", "min": 0.06, "max": 0.42},
                   "joint": {"law": "constant", "value": 0.01},
                   "balance": {"method": "relocation", "max_iterations": 2},
                   "laguerre": {"shrink": "offset"}, "picture": {"color": "quality"}}}
CONCURRENT = 20
# Peak RSS 20 concurrent downloads may add to the idle daemon: a download holds about a
# megabyte (a window of the result, a chunk per section, zlib's state, libmicrohttpd's
# 128 KB block), so 20 take some 20 MB; rendering each in memory, as before, took tens of
# megabytes each at this size (gigabytes at 10^6 grains).
RSS_BOUND = 48 << 20


def pipeline_runs(client):
    return gpd.metric(client.get("/metrics").body.decode(), "grainpack_pipeline_runs_total")


def sanitized(binary):
    with open(binary, "rb") as f:
        return b"AddressSanitizer" in f.read()


def rss(pid, field):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) * 1024
    return None


def check_formats(c, api, client, job, cli_bytes):
    for fmt in FORMATS:
        plain = client.get(f"/jobs/{job}/results?f={fmt}")
        # (the bodies' schema: test_service_e2e, on smaller results; here it would take seconds)
        api.check(c, "GET", "/jobs/{jobId}/results", plain, body_schema=False)
        c.check(plain.status == 200 and plain.body == cli_bytes[fmt],
                f"{fmt}: {len(plain.body)} bytes served, the command line writes {len(cli_bytes[fmt])}")
        c.check("content-encoding" not in plain.headers, f"{fmt}: encoded without Accept-Encoding")
        c.check(plain.headers.get("content-disposition") == f'attachment; filename="job-{job}.{fmt}"',
                f"{fmt}: Content-Disposition {plain.headers.get('content-disposition')}")
        vary = [v.strip() for v in plain.headers.get("vary", "").split(",")]
        c.check("Accept-Encoding" in vary and "Accept" in vary, f"{fmt}: Vary {vary}")
        etag = plain.headers.get("etag", "")
        c.check(etag.startswith('"') and etag.endswith('"'), f"{fmt}: a strong ETag, got {etag!r}")

        packed = client.get(f"/jobs/{job}/results?f={fmt}", headers={"Accept-Encoding": "gzip, br"})
        api.check(c, "GET", "/jobs/{jobId}/results", packed, body_schema=False)
        c.check(packed.headers.get("content-encoding") == "gzip", f"{fmt}: not gzip: {packed.headers}")
        c.check(gzip.decompress(packed.body) == cli_bytes[fmt], f"{fmt}: gzip body differs once decompressed")
        c.check(len(packed.body) < len(plain.body) / 2,
                f"{fmt}: gzip {len(packed.body)} bytes for {len(plain.body)}")
        gz_etag = packed.headers.get("etag", "")
        c.check(gz_etag and gz_etag != etag, f"{fmt}: gzip and identity share the ETag {etag}")

        for header, encoded in (("gzip;q=0", False), ("identity", False), ("*", True),
                                ("x-gzip", True), ("*, gzip;q=0", False), ("deflate", False)):
            r = client.request("HEAD", f"/jobs/{job}/results?f={fmt}", headers={"Accept-Encoding": header})
            c.check(r.status == 200 and r.body == b"" and
                    (r.headers.get("content-encoding") == "gzip") == encoded,
                    f"{fmt}: HEAD with Accept-Encoding {header!r}: {r.status} {r.headers.get('content-encoding')}")

        # 304: the tag itself, in a list, weakly compared, *; another tag gets the body
        for inm in (etag, f'"x", {etag}', f"W/{etag}", "*"):
            r = client.get(f"/jobs/{job}/results?f={fmt}", headers={"If-None-Match": inm})
            api.check(c, "GET", "/jobs/{jobId}/results", r)
            c.check(r.status == 304 and r.body == b"" and r.headers.get("etag") == etag,
                    f"{fmt}: If-None-Match {inm}: {r.status} {r.headers.get('etag')}")
        r = client.get(f"/jobs/{job}/results?f={fmt}", headers={"If-None-Match": gz_etag})
        c.check(r.status == 200 and r.body == cli_bytes[fmt], f"{fmt}: the gzip tag matched identity")
        r = client.get(f"/jobs/{job}/results?f={fmt}",
                       headers={"If-None-Match": gz_etag, "Accept-Encoding": "gzip"})
        c.check(r.status == 304, f"{fmt}: gzip If-None-Match: {r.status}")


def download(port, job, fmt, encoding, out, pause=0.0):
    """One download on its own connection, read in 64 KB pieces; its byte count in out."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
    try:
        conn.request("GET", f"/jobs/{job}/results?f={fmt}", headers={"Accept-Encoding": encoding})
        r = conn.getresponse()
        n = 0
        while True:
            piece = r.read(65536)
            if not piece:
                break
            n += len(piece)
            if pause:
                time.sleep(pause)
        out.append((r.status, n))
    finally:
        conn.close()


def check_concurrent_memory(c, daemon, client, job, binary):
    pid = daemon.proc.pid
    for fmt in FORMATS:  # every code path once, so the first use's one-off costs are in the idle figure
        for enc in ("identity", "gzip"):
            client.get(f"/jobs/{job}/results?f={fmt}", headers={"Accept-Encoding": enc})
    idle = rss(pid, "VmRSS")
    try:  # the peak from now on
        with open(f"/proc/{pid}/clear_refs", "w") as f:
            f.write("5")
        peak_field = "VmHWM"
    except OSError:
        peak_field = None
    sampled = [idle]
    stop = threading.Event()

    def sample():
        while not stop.is_set():
            sampled.append(rss(pid, "VmRSS") or 0)
            time.sleep(0.005)

    sampler = threading.Thread(target=sample)
    sampler.start()
    results = []
    threads = [threading.Thread(target=download, args=(daemon.port, job, FORMATS[k % 4],
                                                       "gzip" if k % 2 else "identity", results, 0.002))
               for k in range(CONCURRENT)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    stop.set()
    sampler.join()
    peak = max(max(sampled), rss(pid, peak_field) if peak_field else 0)
    grew = peak - idle
    c.check(len(results) == CONCURRENT and all(s == 200 and n > 0 for s, n in results),
            f"concurrent downloads: {results}")
    print(f"     {CONCURRENT} concurrent downloads: idle RSS {idle / 2**20:.1f} MB, peak "
          f"{peak / 2**20:.1f} MB (+{grew / 2**20:.1f} MB; bound +{RSS_BOUND / 2**20:.0f} MB)")
    if sanitized(binary):
        print("     (AddressSanitizer build: its quarantine keeps freed memory, the bound is not checked)")
    else:
        c.check(grew < RSS_BOUND, f"peak RSS grew by {grew / 2**20:.1f} MB during {CONCURRENT} downloads")


def check_paused_download_holds_no_transaction(c, daemon, client, job):
    """A client that stops reading mid-download: the daemon waits on the socket with no
    read transaction open, so a checkpoint copies every frame of the WAL back."""
    conn = http.client.HTTPConnection("127.0.0.1", daemon.port, timeout=120)
    conn.request("GET", f"/jobs/{job}/results?f=json")
    r = conn.getresponse()
    first = r.read(65536)
    # writes while the download waits: a job finishing appends its result to the WAL
    other = client.submit(gpd.small_spec(seed=7)).json()["jobID"]
    c.check(client.wait_final(other)["status"] == "successful", "a job during a paused download")
    db = sqlite3.connect(daemon.db_path, timeout=30)
    try:
        # busy: another checkpoint (the daemon's own, after its commit) runs right now
        for _ in range(200):
            busy, log, done = db.execute("PRAGMA wal_checkpoint(PASSIVE)").fetchone()
            if not busy:
                break
            time.sleep(0.05)
    finally:
        db.close()
    c.check(busy == 0 and log == done and log >= 0,
            f"checkpoint during a paused download: busy {busy}, {done} of {log} frames")
    rest = r.read()
    conn.close()
    c.check(len(first) + len(rest) > 0 and r.status == 200, "the paused download completes")


def check_picture_colors(c, client, job, cli_bytes, cli):
    """The job's spec colours by F (quality): ?color=quality is that very picture and tag,
    ?color=radius another picture under another tag."""
    default = client.get(f"/jobs/{job}/results?f=svg")
    spec = {"inputs": dict(SPEC["inputs"], picture={"color": "radius"})}
    by_radius = subprocess.run([cli, "run", "-", "--format", "svg"], input=gpd.json.dumps(spec).encode(),
                               capture_output=True, check=True).stdout
    c.check(by_radius != cli_bytes["svg"], "colouring by radius gave the same picture as by F")
    quality = client.get(f"/jobs/{job}/results?f=svg&color=quality")
    c.check(quality.status == 200 and quality.body == cli_bytes["svg"] and
            quality.headers.get("etag") == default.headers.get("etag"),
            f"color=quality: {quality.status}, ETag {quality.headers.get('etag')} for {default.headers.get('etag')}")
    radius = client.get(f"/jobs/{job}/results?f=svg&color=radius")
    c.check(radius.status == 200 and radius.body == by_radius,
            f"color=radius: {radius.status}, {len(radius.body)} bytes, the command line writes {len(by_radius)}")
    c.check(radius.headers.get("etag") not in (None, default.headers.get("etag")),
            f"color=radius shares the ETag {radius.headers.get('etag')} of the picture coloured by F")
    r = client.get(f"/jobs/{job}/results?f=svg&color=radius",
                   headers={"If-None-Match": default.headers.get("etag", "")})
    c.check(r.status == 200 and r.body == by_radius, f"color=radius answered {r.status} to the F picture's tag")
    r = client.get(f"/jobs/{job}/results?f=svg&color=radius",
                   headers={"If-None-Match": radius.headers.get("etag", "")})
    c.check(r.status == 304, f"color=radius, its own tag: {r.status}")
    r = client.get(f"/jobs/{job}/results?f=csv&color=radius")
    c.check(r.status == 200 and r.body == cli_bytes["csv"], f"color= changed the CSV: {r.status}")


def test(c, binary, cli):
    api = gpd.OpenAPI()
    daemon = gpd.Daemon(binary, "--workers", "1")
    try:
        daemon.start()
        client = daemon.client()
        job = client.submit(SPEC).json()["jobID"]
        info = client.wait_final(job)
        if not c.check(info["status"] == "successful", f"job: {info}"):
            return
        cli_bytes = {fmt: subprocess.run([cli, "run", "-", "--format", fmt], input=gpd.json.dumps(SPEC).encode(),
                                         capture_output=True, check=True).stdout for fmt in FORMATS}
        runs = pipeline_runs(client)
        c.check(runs == 1, f"grainpack_pipeline_runs_total is {runs} after one job")
        check_formats(c, api, client, job, cli_bytes)
        check_picture_colors(c, client, job, cli_bytes, cli)
        st = client.get(f"/jobs/{job}/statistics")
        api.check(c, "GET", "/jobs/{jobId}/statistics", st)
        c.check(st.status == 200 and st.json()["balance"]["sweeps"] == 2, f"statistics: {st}")
        check_concurrent_memory(c, daemon, client, job, binary)
        c.check(pipeline_runs(client) == runs,
                f"downloads ran the pipeline: {pipeline_runs(client)} runs, {runs} before")
        check_paused_download_holds_no_transaction(c, daemon, client, job)
        client.close()
        c.check(daemon.stop() == 0, "grainpackd did not stop cleanly")
        c.check("download:" not in daemon.log(), "a download failed: " +
                "".join(line for line in daemon.log().splitlines(True) if "download:" in line)[:500])
    finally:
        daemon.cleanup()


if __name__ == "__main__":
    gpd.main(test)
