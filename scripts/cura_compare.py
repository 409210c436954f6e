#!/usr/bin/env python3
"""Our whole process against CuraEngine's on the same vessel (the bundled
`vase` example), for docs/PERFORMANCE.md.

The vase's shape is read back from our own G-code (the mean radius of each
layer), revolved into a closed STL, and sliced by CuraEngine (Debian
`cura-engine`) in spiralize mode with two bottom layers, clay settings as
in scripts/corpus/make.py. Both are timed (median of 5 runs of the whole
command) and both outputs are judged by `sweepclay check`.

    python3 scripts/cura_compare.py   # after `cargo build --release`
"""
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "corpus"))
import make  # noqa: E402  (the corpus script's STL writer and Cura settings)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "sweepclay")


def timed(cmd, runs=5):
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def radius_table(gcode):
    """Mean distance from the centre of each 1.25 mm band of wall moves."""
    pts = []
    for line in open(gcode):
        if line.startswith("G1") and " X" in line and " Z" in line:
            f = {w[0]: float(w[1:]) for w in line.split()[1:] if w[0] in "XYZ"}
            pts.append((f["X"], f["Y"], f["Z"]))
    cx = sum(p[0] for p in pts) / len(pts)
    cy = sum(p[1] for p in pts) / len(pts)
    bands = {}
    for x, y, z in pts:
        if z > 2.6:  # the wall, above the floor
            bands.setdefault(round(z / 1.25), []).append(math.hypot(x - cx, y - cy))
    return sorted((k * 1.25, max(v)) for k, v in bands.items())


def main():
    with tempfile.TemporaryDirectory() as tmp:
        ours = os.path.join(tmp, "vase.gcode")
        t_ours = timed([BIN, "slice", "vase", "-o", ours])
        table = radius_table(ours)
        height = table[-1][0]

        def r_at(z, _t):
            for (z0, r0), (z1, r1) in zip(table, table[1:]):
                if z0 <= z <= z1:
                    return r0 + (r1 - r0) * (z - z0) / (z1 - z0)
            return table[0][1] if z < table[0][0] else table[-1][1]

        stl = os.path.join(tmp, "vase.stl")
        make.write_stl(stl, r_at, height, 80, 120)
        defs = make.cura_definitions(tmp)
        theirs = os.path.join(tmp, "cura.gcode")
        settings = []
        # Two bottom layers: Cura's floor, then the spiral.
        base = [s for s in make.cura_settings() if not s.startswith(("bottom_layers", "initial_bottom_layers", "bottom_thickness", "top_bottom_thickness"))]
        base += ["bottom_layers=2", "initial_bottom_layers=2", "bottom_thickness=2.5", "infill_sparse_density=0"]
        cmd = ["CuraEngine", "slice", "-j", os.path.join(defs, "fdmprinter.def.json")]
        for part in (["-e0"], ["-l", stl], ["-o", theirs]):
            for s in base:
                settings += ["-s", s]
            cmd += settings + part
            settings = []
        t_cura = timed(cmd)
        for name, path, t in (("sweepclay", ours, t_ours), ("CuraEngine", theirs, t_cura)):
            out = subprocess.run([BIN, "check", path, "--json"], capture_output=True, text=True).stdout
            import json
            r = json.loads(out)
            f = {k: v for k, v in r.items() if not isinstance(v, (list, dict))}
            print(f"{name}: {t * 1000:.0f} ms median of 5; printable={f.get('printable')} "
                  f"moves={f.get('moves')} runs={f.get('extrusion_runs')} "
                  f"failures={r.get('failures')}")


if __name__ == "__main__":
    main()
