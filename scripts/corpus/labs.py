#!/usr/bin/env python3
"""Real clay G-code from two labs' public repositories, checked against
verdicts written down before the checker ran (issue 55; the table in
docs/CHECKER.md, "Files from other people's tools").

- Hand and Machine lab (UNM), Hand-and-Machine/extruder-turtle-Rhino at
  commit 89977ea: `ceramics/*.gcode`, written by their Extruder Turtle
  library (and one by Cura 4.13) for a 3D Potter with a 3 mm nozzle.
  Their files' own header gives the bead: "extrued width = 3.5",
  "extrued rate = 3.0" (E a mm of path), "layer height = 2.2", so
  E counts 3.0 / (3.5 × 2.2) = 0.39 units per mm³; the 3D Potter's box
  is their start code's `M208 X415 Y405 Z500`.
- Digital Design Unit (TU Darmstadt), digitaldesignunit/clayprinting-slicer
  at commit 90515b1: `resources/SampleGcode.gcode`, their Grasshopper
  slicer's sample for a WASP 40100 (centred origin, 1 m box). Its header:
  EXTRUSIONRATE=0.16 (E a mm of path), LINEWIDTH=4, LAYERHEIGHT=1.9, so
  0.16 / (4 × 1.9) = 0.0211 units per mm³.

Nothing of theirs is kept in this repository: the files are read from
checkouts at the pinned commits.

    git clone https://github.com/Hand-and-Machine/extruder-turtle-Rhino turtle
    git clone https://github.com/digitaldesignunit/clayprinting-slicer ddu
    cargo build --release
    python3 scripts/corpus/labs.py turtle ddu

Prints each file's verdict beside the one expected and the fraction
right per source; exits 1 when any verdict differs from its expectation
(a difference is read by hand and written into docs/CHECKER.md).
"""
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BIN = os.path.join(ROOT, "target", "release", "sweepclay")

TURTLE_COMMIT = "89977ea178d676ad03f82010f6767f9c4841fb80"
DDU_COMMIT = "90515b1470c6bb17f62182c80b2e7bd6dd6f0018"

POTTER = {"name": "3d-potter", "build_volume": [415, 405, 500],
          "bed_min": [0, 0, 0], "e_per_mm3": 3.0 / (3.5 * 2.2), "nozzle_radius": 1.5}
WASP_40100 = {"name": "wasp-40100", "build_volume": [1000, 1000, 1000],
              "bed_min": [-500, -500, 0], "e_per_mm3": 0.16 / (4 * 1.9), "nozzle_radius": 2}
# Cura's E is a 1.75 mm filament's length (its `;Filament used` over the
# path: 1.27 E a mm for 2 mm lines on 1.5 mm layers).
POTTER_CURA = dict(POTTER, e_per_mm3=1 / (3.141592653589793 * 0.875 ** 2))

# The 3D Potter runs RepRapFirmware: their start code sets its axes with
# `M208`, RepRapFirmware's command (read after the first run, where
# Marlin's reading of `Y4e-05` was reported; see docs/CHECKER.md).
POTTER_FLAGS = ["--width-min", "3", "--firmware", "reprap"]

# (source, path, printer, flags, expected printable, findings that must be
# among the failures, why) -- written before the checker ran.
FIRST_35 = "its first bead is at Z 3.5 (start at Z 1.5, then `G1 Z2` relative): above the 3 mm first-layer limit"
EXPECTED = [
    ("turtle", "ceramics/cup.gcode", POTTER, POTTER_FLAGS, False, ["first_layer_high"],
     FIRST_35 + "; the cup itself is one continuous spiral, straight walls"),
    ("turtle", "ceramics/cup_woven.gcode", POTTER, POTTER_FLAGS, False, ["first_layer_high"],
     FIRST_35 + "; its weave leans at most 31 degrees from layer to layer"),
    ("turtle", "ceramics/flower_pot.gcode", POTTER, POTTER_FLAGS, False, ["first_layer_high"],
     FIRST_35 + "; planar layers joined by dry 2 mm rises (shorter than a bead)"),
    ("turtle", "ceramics/random_bumps.gcode", POTTER, POTTER_FLAGS, True, [],
     "one continuous spiral from Z 1.5, bumps of 1.2 mm on 3.5 mm beads"),
    ("turtle", "ceramics/tall_spiral_cup.gcode", POTTER, POTTER_FLAGS, True, [],
     "one continuous spiral from Z 1.5, a straight 125 mm cup"),
    ("turtle", "ceramics/square_wave_vase.gcode", POTTER, POTTER_FLAGS, True, [],
     "planar layers from Z 2.6 joined by dry 2 mm rises; the lab prints it"),
    ("turtle", "ceramics/wavy_bowl_small.gcode", POTTER, POTTER_FLAGS, True, [],
     "a spiral bowl from Z 1.0 leaning at most a few degrees layer to layer"),
    ("turtle", "ceramics/z_osciallations_cup.gcode", POTTER, POTTER_FLAGS, True, [],
     "a spiral cup from Z 1.0 whose height oscillates within a turn; the lab prints it"),
    ("turtle", "ceramics/tall_cup_one_droop.gcode", POTTER, POTTER_FLAGS, False, ["travel_move"],
     "a droop: the nozzle lifts 20 mm dry (`G1 Z20`), lays clay in the air for 60 moves, comes down: "
     "a travel and beads with nothing below, on purpose"),
    ("turtle", "ceramics/cup_2droops.gcode", POTTER, POTTER_FLAGS, False, ["travel_move"],
     "two droops, as above"),
    ("turtle", "ceramics/Jeff_Suina1.gcode", POTTER_CURA, POTTER_FLAGS, False, ["travel_move"],
     "Cura 4.13 spiralized with 3 bottom layers: travels between the bottom's lines"),
    ("ddu", "resources/SampleGcode.gcode", WASP_40100, ["--width-min", "4", "--width-max", "8"], False,
     ["retraction"],
     "12 retractions with 1 mm Z-hops: the first outline apart from the spiral, and 11 top layers each its own loop"),
]


def main():
    checkouts = {"turtle": (sys.argv[1], TURTLE_COMMIT), "ddu": (sys.argv[2], DDU_COMMIT)}
    tally = {}
    wrong = 0
    with tempfile.TemporaryDirectory() as tmp:
        for source, path, printer, flags, printable, must, why in EXPECTED:
            repo, commit = checkouts[source]
            text = subprocess.run(["git", "-C", repo, "show", f"{commit}:{path}"],
                                  check=True, capture_output=True).stdout
            gcode = os.path.join(tmp, os.path.basename(path))
            with open(gcode, "wb") as f:
                f.write(text)
            pjson = os.path.join(tmp, printer["name"] + ".json")
            with open(pjson, "w") as f:
                json.dump(printer, f)
            out = subprocess.run([BIN, "check", "--json", "--printer", pjson, *flags, gcode],
                                 capture_output=True, text=True)
            r = json.loads(out.stdout)
            got_ok = r["printable"] == printable and all(r["findings"][k]["count"] for k in must)
            right, n = tally.get(source, (0, 0))
            tally[source] = (right + got_ok, n + 1)
            wrong += not got_ok
            mark = "right" if got_ok else "DIFFERS"
            print(f"{mark:8} {source}/{path}: expected {'printable' if printable else 'not printable'}"
                  f" ({why})")
            print(f"         got {'printable' if r['printable'] else 'not printable'}: "
                  + ("; ".join(r["failures"]) or "no failures"))
    for source, (right, n) in tally.items():
        print(f"{source}: {right} of {n} as expected")
    sys.exit(1 if wrong else 0)


if __name__ == "__main__":
    main()
