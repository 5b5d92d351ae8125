#!/usr/bin/env python3
"""periodic_table.py - the table of bench/PERIODIC.md: the four reference cases of
examples/ packed walled, on the torus and on strips periodic along x or y, seeds 1-5, by
the command line; prints one Markdown row per case and domain (density, max |z|, time).
Usage: python3 bench/periodic_table.py [path/to/grainpack] (default build/cli/grainpack)."""
import json
import os
import subprocess
import sys
import tempfile
import time

SEEDS = range(1, 6)
MODES = {"walled": None, "torus": True, "periodic x": ["x"], "periodic y": ["y"]}


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else "build/cli/grainpack"
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
