#!/usr/bin/env python3
"""periodic_table.py - the tables of bench/PERIODIC.md: the four reference cases of
examples/ packed walled, on the torus and on strips periodic along x or y, seeds 1-5, by
the command line; prints one Markdown row per case and domain (density, max |z|, time).
With --mesh: the iron case meshed (offset cells, and the disks in a matrix; element size
3), walled, torus and strips, seeds 1-3: elements, node pairs, rounds, refused
refinements, smallest angle, and the mesh's CPU time (the run's CPU with the mesh less
the same run's without it, children's rusage).
Usage: python3 bench/periodic_table.py [--mesh] [path/to/grainpack] (default build/cli/grainpack)."""
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

SEEDS = range(1, 6)
MODES = {"walled": None, "torus": True, "periodic x": ["x"], "periodic y": ["y"]}


MESH_SEEDS = range(1, 4)


def cpu_run(exe, path):
    """The statistics of `grainpack run path` and the CPU seconds it took."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([exe, "run", path], capture_output=True, text=True, check=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return json.loads(out)["statistics"], cpu


def mesh_table(exe):
    print("| cells | domain | grains | elements | node pairs x / y | rounds | refused | min angle "
          "| mesh CPU s |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "spec.json")
        for cells in ("offset", "none (disks in a matrix)"):
            for mode, periodic in MODES.items():
                rows = []
                for seed in MESH_SEEDS:
                    spec = json.load(open("examples/iron.json"))
                    inputs = spec["inputs"]
                    inputs["seed"] = seed
                    if periodic is not None:
                        inputs["domain"]["periodic"] = periodic
                    if cells == "offset":
                        inputs["laguerre"] = {"shrink": "offset"}
                    with open(path, "w") as f:
                        json.dump(spec, f)
                    _, cpu_without = cpu_run(exe, path)
                    inputs["mesh"] = {"element_size": 3}
                    with open(path, "w") as f:
                        json.dump(spec, f)
                    st, cpu = cpu_run(exe, path)
                    rows.append((st["count"], st["mesh"], cpu - cpu_without))
                n = len(rows)
                m = [r[1] for r in rows]
                pairs = "/".join(f"{min(x['periodic']['node_pairs'][a] for x in m)}-"
                                 f"{max(x['periodic']['node_pairs'][a] for x in m)}" for a in "xy")
                print(f"| {cells} | {mode} | {min(r[0] for r in rows)}-{max(r[0] for r in rows)} | "
                      f"{sum(x['elements']['total'] for x in m) / n:.0f} | {pairs} | "
                      f"{max(x['periodic']['rounds'] for x in m)} | "
                      f"{min(x['refused_refinements'] for x in m)}-{max(x['refused_refinements'] for x in m)} | "
                      f"{min(x['angles']['min'] for x in m):.1f} | {sum(r[2] for r in rows) / n:.2f} |")
    print("load average:", " ".join(f"{x:.1f}" for x in os.getloadavg()))


def main():
    args = [a for a in sys.argv[1:] if a != "--mesh"]
    exe = args[0] if args else "build/cli/grainpack"
    if "--mesh" in sys.argv[1:]:
        mesh_table(exe)
        return
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "spec.json")
        for case in ["fixed", "variable", "iron", "bagi"]:
            for mode, periodic in MODES.items():
                dens, zs, times, counts = [], [], [], []
                for seed in SEEDS:
                    spec = json.load(open(f"examples/{case}.json"))
                    spec["inputs"]["seed"] = seed
                    if periodic is not None:
                        spec["inputs"]["domain"]["periodic"] = periodic
                    with open(path, "w") as f:
                        json.dump(spec, f)
                    t = time.time()
                    out = subprocess.run([exe, "run", path], capture_output=True, text=True, check=True).stdout
                    times.append(time.time() - t)
                    st = json.loads(out)["statistics"]
                    dens.append(st["packing_density"])
                    zs.append(st["distribution"]["max_abs_z"])
                    counts.append(st["count"])
                n = len(SEEDS)
                print(f"| {case} | {mode} | {min(counts)}-{max(counts)} | {sum(dens) / n:.4f} | "
                      f"{min(dens):.4f} | {max(zs):.2f} | {sum(times) / n:.2f} |")
    print("load average:", " ".join(f"{x:.1f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
