#!/usr/bin/env python3
"""The same vessel meshes through sweepclay and through the vase modes
potters use today (PrusaSlicer's spiral vase, CuraEngine's spiralize),
each with two floor layers and clay settings (1.25 mm layers, 3 mm beads,
as scripts/corpus/make.py), and every G-code judged by `sweepclay check`.
Prints the table in docs/MESHES.md: extrusion runs, travel moves,
retractions, whether the floor and the wall are one run, the verdict.

    python3 scripts/mesh-compare.py   # after `cargo build --release`;
                                      # needs Debian's prusa-slicer and cura-engine
"""
import json
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "corpus"))
import make  # noqa: E402  (its STL writer, Cura and Prusa clay settings)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "sweepclay")


def tall_vase_r(z, t):
    """A 90 mm vase bulging to 32 mm and necking in to 22 mm."""
    return 26 + 6 * math.sin(math.pi * z / 60) - 4 * (z / 90) ** 2


def oval_r(z, t):
    """An oval pot, 60 × 40 mm at the foot, flaring 6 mm by its 50 mm rim."""
    return 30 / math.sqrt(math.cos(t) ** 2 + (1.5 * math.sin(t)) ** 2) + 6 * z / 50


def with_floor(cmd_settings):
    """Two floor layers instead of make.py's none."""
    return [s.replace("bottom_layers=0", "bottom_layers=2").replace("initial_bottom_layers=0", "initial_bottom_layers=2")
            .replace("bottom_thickness=0", "bottom_thickness=2.5") for s in cmd_settings]


make_cura_settings = make.cura_settings
make.cura_settings = lambda layer=make.LAYER, width=make.WIDTH: with_floor(make_cura_settings(layer, width))
make_prusa = make.prusa


def prusa_with_floor(tool, stl, out, tmp, layer=make.LAYER, width=make.WIDTH):
    """make.prusa with two bottom solid layers."""
    real_run = make.run

    def run(cmd):
        cmd = [("2" if c == "0" and cmd[i - 1] == "--bottom-solid-layers" else c) for i, c in enumerate(cmd)]
        real_run(cmd)
    make.run = run
    try:
        make_prusa(tool, stl, out, tmp, layer, width)
    finally:
        make.run = real_run


make.prusa = prusa_with_floor


def verdict(gcode):
    r = subprocess.run([BIN, "check", "--json", "--printer", "generic", gcode],
                       capture_output=True, text=True)
    rep = json.loads(r.stdout)
    f = rep["findings"]
    why = "printable" if rep["printable"] else "NOT printable: " + "; ".join(rep["failures"])
    return rep["extrusion_runs"], f["travel_move"]["count"], f["retraction"]["count"], why


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        defs = make.cura_definitions(tmp)
        meshes = []
        for name, r, h in [("bulging vase (50 mm)", make.vase_r, 50.0),
                           ("tall vase (90 mm)", tall_vase_r, 90.0),
                           ("oval pot (50 mm)", oval_r, 50.0),
                           ("leaning bowl (35°, 36 mm)", make.bowl_r, 36.0)]:
            path = os.path.join(tmp, f"{len(meshes)}.stl")
            make.write_stl(path, r, h, 60, 96)
            meshes.append((name, path))
        for name, stl in meshes:
            ours = os.path.join(tmp, "ours.gcode")
            r = subprocess.run([BIN, "slice", stl, "--printer", "generic", "-o", ours],
                               capture_output=True, text=True)
            if r.returncode == 0:
                rows.append((name, "sweepclay", *verdict(ours)))
            else:
                rows.append((name, "sweepclay", "-", "-", "-", "refused: " + r.stderr.strip().splitlines()[-1][:120]))
            prusa = os.path.join(tmp, "prusa.gcode")
            try:
                make.prusa("prusa-slicer", stl, prusa, tmp)
                rows.append((name, "PrusaSlicer spiral vase", *verdict(prusa)))
            except subprocess.CalledProcessError as e:
                rows.append((name, "PrusaSlicer spiral vase", "-", "-", "-", f"failed ({e.returncode})"))
            cura = os.path.join(tmp, "cura.gcode")
            try:
                make.cura(stl, cura, defs)
                rows.append((name, "CuraEngine spiralize", *verdict(cura)))
            except subprocess.CalledProcessError as e:
                rows.append((name, "CuraEngine spiralize", "-", "-", "-", f"failed ({e.returncode})"))
    print("| mesh | tool | extrusion runs | travels | retractions | check |")
    print("|---|---|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(str(c) for c in row) + " |")


if __name__ == "__main__":
    sys.exit(main())
