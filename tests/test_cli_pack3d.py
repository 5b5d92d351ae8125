"""test_cli_pack3d.py - `grainpack run` and `validate` on 3D specs (docs/3d.md): the process
detected from the domain's "depth" or given by --process, the CSV read back by Python's csv
module and checked on its own (no overlap beyond 1e-9, inside the box, the header), the
same bytes from a file and from stdin, a box periodic along two axes checked under the
minimum image, and the refusals with their exit statuses and JSON pointers. Usage: test_cli_pack3d.py PATH/TO/grainpack EXAMPLES_DIR"""
import csv
import io
import json
import math
import subprocess
import sys
import tempfile
import os

BIN, EXAMPLES = sys.argv[1], sys.argv[2]
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what, file=sys.stderr)


def run(args, stdin=None):
    p = subprocess.run([BIN] + args, input=stdin, capture_output=True)
    return p.returncode, p.stdout, p.stderr.decode()


SPEC = {"inputs": {"domain": {"width": 6, "height": 5, "depth": 4},
                   "distribution": {"kind": "uniform", "min": 0.2, "max": 0.5},
                   "joint": {"law": "constant", "value": 0.05}, "seed": 3}}

with tempfile.TemporaryDirectory() as tmp:
    path = os.path.join(tmp, "box.json")
    with open(path, "w") as f:
        json.dump(SPEC, f)
    out = os.path.join(tmp, "box.csv")
    rc, _, err = run(["run", path, "-f", "csv", "-o", out])
    check(rc == 0, "run exited %d: %s" % (rc, err))
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    check(rows[0] == ["x", "y", "z", "r", "R"], "header %r" % rows[:1])
    s = [tuple(float(v) for v in row) for row in rows[1:]]
    check(len(s) > 100, "%d spheres" % len(s))
    W, H, D = 6.0, 5.0, 4.0
    for x, y, z, r, R in s:
        check(0.2 <= r <= 0.5 and abs(R - (r + 0.05)) <= 1e-12, "radii %g %g" % (r, R))
        for c, side in ((x, W), (y, H), (z, D)):
            check(c - R >= -1e-9 * R and c + R <= side + 1e-9 * R, "outside: %r" % ((x, y, z, R),))
    worst = -1.0
    for i in range(len(s)):
        for j in range(i):
            d = math.dist(s[i][:3], s[j][:3])
            worst = max(worst, 1.0 - d / (s[i][4] + s[j][4]))
    check(worst <= 1e-9, "worst overlap %g" % worst)
    # stdin gives the same bytes, --process pack3d changes nothing, validate agrees
    with open(out, "rb") as f:
        expected = f.read()
    rc, got, _ = run(["run", "-", "--format", "csv"], stdin=json.dumps(SPEC).encode())
    check(rc == 0 and got == expected, "stdin run differs")
    rc, got, _ = run(["run", path, "--process", "pack3d", "-f", "csv"])
    check(rc == 0 and got == expected, "--process pack3d differs")
    rc, got, _ = run(["validate", path])
    check(rc == 0 and b"pack3d" in got and b"spheres expected" in got, "validate: %r" % got)

    # refusals: 3 for an invalid spec (with the field's pointer), 2 for a usage error
    def refused(spec, status, pointer, args=()):
        rc, _, err = run(["run", "-"] + list(args), stdin=json.dumps(spec).encode())
        check(rc == status and pointer in err, "%r: exit %d, %s" % (spec, rc, err.strip()))

    box = {"width": 6, "height": 5, "depth": 4}
    law = {"kind": "constant", "radius": 0.3}
    refused({"domain": dict(box, depth=0.5), "distribution": law}, 3, "/domain/depth")
    refused({"domain": dict(box, depth=-1), "distribution": law}, 3, "/domain/depth")
    refused({"domain": box, "distribution": {"kind": "uniform", "min": 0.01, "max": 0.3}}, 3,
            "/distribution/min")
    # a periodic side under 12 R_max (3.6 here), a periodic axis that is not one, and the
    # stages not yet on periodic boxes
    refused({"domain": dict(box, depth=3, periodic=["z"]), "distribution": law}, 3, "/domain/periodic")
    refused({"domain": dict(box, periodic=["t"]), "distribution": law}, 3, "/domain/periodic/0")
    refused({"domain": dict(box, periodic=True), "distribution": law,
             "laguerre": {"shrink": "offset"}}, 3, "/laguerre")
    # periodic along x and z: centres in [0, side) there, spheres inside along y, no two
    # overlapping under the minimum image (the CSV's own positions)
    rc, got, err = run(["run", "-", "-f", "csv"],
                       stdin=json.dumps({"domain": dict(box, periodic=["x", "z"]), "distribution": law}).encode())
    check(rc == 0, "periodic run exited %d: %s" % (rc, err))
    p = [tuple(float(v) for v in row) for row in list(csv.reader(io.StringIO(got.decode())))[1:]]
    sides = (6.0, 5.0, 4.0)
    check(len(p) > 100 and all(0 <= c[0] < 6 and 0 <= c[2] < 4 and 0.3 - 1e-9 <= c[1] <= 4.7 + 1e-9 for c in p),
          "periodic: %d spheres, or one outside" % len(p))
    worst = -1.0
    for i in range(len(p)):
        for j in range(i):
            d = [p[i][k] - p[j][k] for k in range(3)]
            d = [v - sides[k] * round(v / sides[k]) if k != 1 else v for k, v in enumerate(d)]
            worst = max(worst, 1.0 - math.sqrt(sum(v * v for v in d)) / 0.6)
    check(worst <= 1e-9, "periodic: worst overlap %g" % worst)
    # balanced by relocation: F_max does not rise, the spheres stay apart and in the box
    # (the JSON's own positions, checked here), F is given where a centre is interior
    balanced = json.loads(json.dumps(SPEC))
    balanced["inputs"]["balance"] = {"method": "relocation"}
    rc, got, err = run(["run", "-", "-f", "json"], stdin=json.dumps(balanced).encode())
    check(rc == 0, "balanced run exited %d: %s" % (rc, err))
    doc = json.loads(got) if rc == 0 else {"balance": {"before": {}, "after": {}}, "spheres": []}
    b = doc["balance"]
    check(b.get("method") == "relocation" and b.get("sweeps", 0) >= 1 and
          b["after"].get("max", 9) <= b["before"].get("max", 0) and b["after"].get("interior", 0) > 10,
          "balance %r" % {k: b.get(k) for k in ("method", "sweeps", "before", "after")})
    bs = [(q["x"], q["y"], q["z"], q["R"]) for q in doc["spheres"]]
    check(len(bs) == len(s) and sum(q["F"] is not None for q in doc["spheres"]) == b["after"].get("interior"),
          "balanced spheres %d, with F %d" % (len(bs), sum(q["F"] is not None for q in doc["spheres"])))
    moved = sum(a[:3] != tuple(t[:3]) for a, t in zip(bs, s))
    check(moved > 0, "balancing moved no sphere")
    worst = -1.0
    for i in range(len(bs)):
        x, y, z, R = bs[i]
        for c, side in ((x, W), (y, H), (z, D)):
            check(c - R >= -1e-9 * R and c + R <= side + 1e-9 * R, "balanced outside: %r" % (bs[i],))
        for j in range(i):
            worst = max(worst, 1.0 - math.dist(bs[i][:3], bs[j][:3]) / (R + bs[j][3]))
    check(worst <= 1e-9, "balanced: worst overlap %g" % worst)
    refused({"inputs": {"domain": dict(box, depth="deep"), "distribution": law}}, 3,
            "/inputs/domain/depth")
    refused({"domain": box, "distribution": law}, 2, "unknown format 'vtk' for pack3d", ["-f", "vtk"])
    # JSON by default, as in 2D
    rc, got, _ = run(["run", path])
    check(rc == 0 and json.loads(got)["process"] == "pack3d", "default format: %d" % rc)
    # a 2D spec asked for as pack3d: the depth is missing; a 3D one as pack2d: depth unknown
    rc, _, err = run(["run", os.path.join(EXAMPLES, "iron.json"), "--process", "pack3d"])
    check(rc == 3 and "/inputs/domain/depth" in err, "2D spec as pack3d: %d %s" % (rc, err))
    rc, _, err = run(["run", path, "--process", "pack2d"])
    check(rc == 3 and "/inputs/domain/depth" in err, "3D spec as pack2d: %d %s" % (rc, err))
    rc, _, err = run(["run", path, "--process", "pack4d"])
    check(rc == 2, "unknown process: %d" % rc)
    # the cap on spheres
    rc, _, err = run(["run", path, "--max-disks", "50"])
    check(rc == 3 and "/inputs/domain" in err, "cap: %d %s" % (rc, err))

    # equal spheres against the walls sit in a lattice whose power cells meet four or more
    # along a line, and a vertex on such a line was in some of its faces and not in
    # others (6 x 5 x 4: 191 faults): the .tess must be conforming for its own reader
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import tess_reader
    for dims, radius in (((6, 5, 4), 0.5), ((8, 8, 8), 0.5), ((10, 7, 5), 0.37)):
        lattice = {"domain": dict(zip(("width", "height", "depth"), dims)),
                   "distribution": {"kind": "constant", "radius": radius},
                   "joint": {"law": "constant", "value": 0.05}, "laguerre": {"shrink": "offset"}}
        tess = os.path.join(tmp, "lattice.tess")
        rc, _, err = run(["run", "-", "-f", "tess", "-o", tess], stdin=json.dumps(lattice).encode())
        check(rc == 0, "lattice %r: tess exited %d: %s" % (dims, rc, err))
        if rc == 0:
            t = tess_reader.read(tess)
            bad = tess_reader.check(t, dims)
            check(not bad, "lattice %r: %d faults in the .tess, %s" % (dims, len(bad), bad[:2]))

print("%d failure(s)" % len(failures), file=sys.stderr)
sys.exit(1 if failures else 0)
