"""test_writers_round_trip.py - every writer's numbers read back, by other programs'
parsers, to the very doubles that were written: Python's csv and json modules, VTK's own
legacy reader (vtkPolyDataReader), and for the SVG picture, whose coordinates are rounded on
purpose, Python's XML parser within half a unit of the last decimal. The numbers come
from write_synthetic (random bit patterns, subnormals, integers, huge and tiny magnitudes,
both zeros, NaN for F).

Usage: test_writers_round_trip.py WRITE_SYNTHETIC EXAMPLES_DIR"""
import csv
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def same(a, b):
    """Same double, bit for bit (so 0.0 and -0.0 differ, NaN equals NaN)."""
    return struct.pack("<d", float(a)) == struct.pack("<d", float(b))


def read_expected(path):
    data = open(path, "rb").read()
    n, m, q = struct.unpack_from("<3Q", data, 0)
    off = 24
    grains = [struct.unpack_from("<6d", data, off + 48 * i) for i in range(n)]
    off += 48 * n
    start = struct.unpack_from("<%dQ" % (n + 1), data, off)
    off += 8 * (n + 1)
    nstart = struct.unpack_from("<%dQ" % (n + 1), data, off)
    off += 8 * (n + 1)
    xy = struct.unpack_from("<%dd" % (2 * m), data, off)
    off += 16 * m
    neighbours = struct.unpack_from("<%di" % q, data, off)
    return grains, start, nstart, xy, neighbours


def check_csv(path, grains):
    rows = list(csv.reader(open(path, newline="")))
    check(rows[0] == ["x", "y", "r", "R"], "csv header")
    bad = [i for i, (row, g) in enumerate(zip(rows[1:], grains))
           if not all(same(float(v), e) for v, e in zip(row, g[:4]))]
    check(len(rows) - 1 == len(grains) and not bad,
          "csv: %d rows for %d grains, rows %s differ" % (len(rows) - 1, len(grains), bad[:5]))


def check_json(path, grains, start, nstart, xy, neighbours):
    # JSON has one number type; "-0" is the double -0, which Python's int cannot hold
    doc = json.load(open(path), parse_int=lambda s: -0.0 if s == "-0" else int(s))
    disks = doc["disks"]
    check(len(disks) == len(grains), "json: %d disks" % len(disks))
    bad = []
    for i, (d, g) in enumerate(zip(disks, grains)):
        ok = all(same(d[k], g[j]) for j, k in enumerate("xyrR"))
        ok &= d["F"] is None if math.isnan(g[4]) else same(d["F"], g[4])
        if not ok:
            bad.append(i)
    check(not bad, "json disks %s differ" % bad[:5])
    cells = doc["cells"]
    bad = []
    for i, (c, g) in enumerate(zip(cells, grains)):
        poly = [v for k in range(start[i], start[i + 1]) for v in (xy[2 * k], xy[2 * k + 1])]
        got = [v for p in c["polygon"] for v in p]
        ok = c["id"] == i and same(c["x"], g[0]) and same(c["y"], g[1]) and same(c["r"], g[2])
        ok &= same(c["area"], g[5]) and len(got) == len(poly)
        ok &= all(same(a, b) for a, b in zip(got, poly))
        ok &= c["neighbours"] == list(neighbours[nstart[i]:nstart[i + 1]])
        if not ok:
            bad.append(i)
    check(len(cells) == len(grains) and not bad, "json cells %s differ" % bad[:5])


def check_vtk(path, grains, start, xy):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkPolyDataReader()
    reader.SetFileName(path)
    reader.ReadAllScalarsOn()
    reader.Update()
    poly = reader.GetOutput()
    n, m = len(grains), start[-1]
    check(poly.GetNumberOfPoints() == m and poly.GetNumberOfPolys() == n,
          "vtk: %d points, %d polygons" % (poly.GetNumberOfPoints(), poly.GetNumberOfPolys()))
    points = vtk_to_numpy(poly.GetPoints().GetData())
    bad = [k for k in range(m)
           if not (same(points[k][0], xy[2 * k]) and same(points[k][1], xy[2 * k + 1]))]
    check(not bad, "vtk points %s differ" % bad[:5])
    offsets = vtk_to_numpy(poly.GetPolys().GetOffsetsArray())
    check(list(offsets) == list(start), "vtk polygon offsets")
    data = poly.GetCellData()
    expect = {"radius": [g[2] for g in grains], "packing_radius": [g[3] for g in grains],
              "area": [g[5] for g in grains],
              "F": [-1.0 if math.isnan(g[4]) else g[4] for g in grains]}
    for name, values in expect.items():
        array = data.GetArray(name)
        check(array is not None, "vtk array %s" % name)
        if array is None:
            continue
        got = vtk_to_numpy(array)
        bad = [i for i in range(n) if not same(got[i], values[i])]
        check(not bad, "vtk %s: grains %s differ (%s for %r)" % (
            name, bad[:5], [got[i] for i in bad[:2]], [values[i] for i in bad[:2]]))
    ids = vtk_to_numpy(data.GetArray("grain_id"))
    check(list(ids) == list(range(n)), "vtk grain ids")


def svg_decimals(spec):
    """The SVG writer's rounding (io_svg.c, svg_decimals), from the spec."""
    dom = spec["inputs"]["domain"]
    longest = max(dom["width"], dom["height"])
    r_lo = min(b["min"] for b in spec["inputs"]["distribution"]["bins"])
    return max(0, min(9, math.ceil(-math.log10(min(longest * 1e-4, r_lo / 50.0)))))


def check_sorted_close(what, got, expected, decimals):
    """Each number of `got` is one of `expected` rounded to `decimals`; comparing both lists
    sorted keeps that within the same bound (sorting moves no value further than that)."""
    check(len(got) == len(expected), "%s: %d numbers for %d" % (what, len(got), len(expected)))
    # half a unit of the last decimal, plus the rounding of x * 10^decimals in doubles and
    # of the decimal read back: a few ulps of the value
    half = 0.5 * 10.0 ** -decimals
    bad = [(g, e) for g, e in zip(sorted(got), sorted(expected))
           if not abs(g - e) <= half * (1 + 1e-9) + abs(e) * 1e-15]
    check(not bad, "%s: %d numbers off, e.g. %s" % (what, len(bad), bad[:3]))


def check_svg(path, spec, grains, start, xy):
    ns = "{http://www.w3.org/2000/svg}"
    root = ET.parse(path).getroot()
    dec = svg_decimals(spec)
    height = spec["inputs"]["domain"]["height"]
    polygons = root.iter(ns + "polygon")
    got = [float(v) for p in polygons for v in re.split(r"[ ,]", p.get("points"))]
    expected = [v for k in range(start[-1]) for v in (xy[2 * k], height - xy[2 * k + 1])]
    check_sorted_close("svg polygon points", got, expected, dec)
    circles = [c for c in root.iter(ns + "circle")]
    check_sorted_close("svg circle x", [float(c.get("cx")) for c in circles],
                       [g[0] for g in grains], dec)
    check_sorted_close("svg circle y", [float(c.get("cy")) for c in circles],
                       [height - g[1] for g in grains], dec)
    check_sorted_close("svg circle r", [float(c.get("r")) for c in circles],
                       [g[2] for g in grains], dec + 1)


def main():
    writer, examples = sys.argv[1], sys.argv[2]
    spec = json.load(open(os.path.join(examples, "iron.json")))
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([writer, d], check=True)
        grains, start, nstart, xy, neighbours = read_expected(os.path.join(d, "expected.bin"))
        check_csv(os.path.join(d, "result.csv"), grains)
        check_json(os.path.join(d, "result.json"), grains, start, nstart, xy, neighbours)
        check_vtk(os.path.join(d, "result.vtk"), grains, start, xy)
        check_svg(os.path.join(d, "result.svg"), spec, grains, start, xy)
    print("%d passed, %d failed" % (1 if not failures else 0, 1 if failures else 0))
    sys.exit(1 if failures else 0)


main()
