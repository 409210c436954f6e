#!/usr/bin/env python3
"""Makes the CODA ExperienceLab's three clay shapes as their own notebook
does: xmenage/print_with_clay_at_CODA (pinned at commit 4a06629), their
`generative_printing.py` and their FullControl printer `lutum.py` for a
Vormvrij Lutum 5M (4 mm beads, 1.3 mm layers, a loop a layer, 300 mm³
purged in the air first). Nothing of theirs is kept in this repository:
the script reads their files from a checkout, runs them with PyPI's
`fullcontrol`, and writes gzipped G-code into the checker's corpus.

    python3 -m venv v && v/bin/pip install fullcontrol==0.1.2 numpy
    git clone https://github.com/xmenage/print_with_clay_at_CODA coda
    git -C coda checkout 4a06629
    v/bin/python scripts/corpus/coda.py coda
"""
import gzip
import os
import shutil
import sys
from math import pi, tau

CODA = os.path.abspath(sys.argv[1])
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                   "crates", "sweepclay-check", "tests", "corpus")

import fullcontrol as fc  # noqa: E402
import numpy as np  # noqa: E402

# Their README: copy lutum.py among FullControl 0.1.2's printers.
lib = os.path.join(os.path.dirname(fc.__file__), "devices", "community", "singletool")
shutil.copy(os.path.join(CODA, "lutum.py"), os.path.join(lib, "lutum.py"))
sys.path.insert(0, CODA)
from generative_printing import GenerativeShape  # noqa: E402


class Shell(GenerativeShape):
    """The notebook's three polar curves, as written there."""

    def polar_curve_bumpy(self, layer_index, h):
        t = np.linspace(0, tau, 1000)
        p1 = 0.2 - 0.8 * (h + 0.2) * (h + 1.4) * (h - 1.2)
        rho = self.horizontal_scale * (1 + 0.05 * np.sin(12 * t) * np.sin(12 * pi * h)) * p1
        return rho, t

    def polar_curve_twisted(self, layer_index, h):
        t = np.linspace(0, tau, 5 * 200)
        p1 = 0.2 - 0.8 * (h + 0.2) * (h + 1.4) * (h - 1.2)
        rho = self.horizontal_scale * (1 + 0.05 * np.sin(12 * t + 6 * pi * h)) * p1
        return rho, t

    def polar_curve_deep_sea_shell(self, layer_index, h):
        t = np.linspace(0, tau, 5 * 200)
        p3 = 0.9 * (h - 1.4) * (h + 0.2) * (h - 1.8)
        rho = self.horizontal_scale * (1 + 0.3 * np.cos(5 * t)) * p3
        p2 = 0.28 - 0.3 * (h + 0.1) * (h + 1) * (h - 1)
        return rho, t + np.sin(10 * t) * p2


for name in ("bumpy", "twisted", "deep_sea_shell"):
    # The notebook's parameters.
    shell = Shell(vertical_scale=140.0, horizontal_scale=70.0, layer_height=1.3,
                  first_layer_height=1.0, extrusion_width=4.0)
    shell.polar_curve = getattr(shell, "polar_curve_" + name)
    shell.print_polar()
    steps = shell.move_to_positive_quadrant()
    controls = fc.GcodeControls(printer_name="lutum", initialization_data={
        "print_speed": 2400, "travel_speed": 6000,
        "extrusion_width": 4.0, "extrusion_height": 1.3})
    gcode = fc.transform(steps, "gcode", controls, show_tips=False)
    path = os.path.join(OUT, f"coda-{name.replace('_', '-')}.gcode.gz")
    with gzip.open(path, "wt", compresslevel=9) as f:
        f.write(gcode)
    print(path, os.path.getsize(path))
