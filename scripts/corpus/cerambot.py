#!/usr/bin/env python3
"""Slices the corpus's bulging vase and ripple vase with a Cerambot
owner's own Cura settings (jerome3o/clay_3d_printing at commit 75dbe1c:
`cura/*.curaprofile` and the machine and extruder settings shown in its
`images/`), through Debian's CuraEngine: the blue 2.6 mm nozzle (1.8 mm
layers, one spiralized wall), the green 2 mm nozzle with one spiralized
wall, and with two walls layer by layer. Their flow of 42 % on a
2.85 mm "filament" makes E count 0.0658 units per mm³ of clay. Nothing
of theirs is kept in this repository: the settings are read from the
profiles in a checkout, the machine's from the pictures (written here).

    git clone https://github.com/jerome3o/clay_3d_printing cerambot
    git -C cerambot checkout 75dbe1c
    python3 scripts/corpus/cerambot.py cerambot OUT
"""
import configparser
import io
import os
import subprocess
import sys
import tempfile
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make  # noqa: E402

SRC, OUT = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
os.makedirs(OUT, exist_ok=True)

# The machine, from images/blue_nozzle_machine_settings.jpg.
MACHINE = [
    "machine_width=170", "machine_depth=170", "machine_height=289",
    "machine_shape=elliptic", "machine_center_is_zero=true", "machine_gcode_flavor=RepRap (Marlin/Sprinter)",
    "machine_start_gcode=G28 ;Home\nG1 Z5.25 F0 ; Z0 releates to 5mm offset\nG92 Z0 E0\nM302 S0 ; always allow extrusion (disable temp checking)\nM163 S0 P0.5 ; Set Mix Factor\nM163 S1 P0.5 ; Set Mix Factor",
    "machine_end_gcode=;M104 S0\nG92 E1\nG28\nM82",
    "material_diameter=2.85",
]
# The nozzle each profile was made for, from images/*_extruder_settings.jpg.
NOZZLE = {"blue_nozzle": 2.6, "green_nozzle_1_wall": 2.0, "green_nozzle_2_wall": 2.0}


def profile(name):
    """The profile's settings: the global values, then the first
    extruder's."""
    data = open(os.path.join(SRC, "cura", name + ".curaprofile"), "rb").read()
    values = {}
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        names = sorted(z.namelist(), key=lambda n: ("extruder" in n, n))
        for n in names:
            if "extruder" in n and "extruder_1_" not in n:
                continue
            c = configparser.ConfigParser(interpolation=None)
            c.read_string(z.read(n).decode())
            values.update(c["values"])
    return values


defs = make.cura_definitions(tempfile.mkdtemp())
with tempfile.TemporaryDirectory() as tmp:
    shapes = {"vase": os.path.join(tmp, "vase.stl"), "ripple": os.path.join(tmp, "ripple.stl")}
    make.write_stl(shapes["vase"], make.vase_r, 50, 40, 48)
    make.write_stl(shapes["ripple"], make.ripple_r, 45, 36, 64)
    for name, nozzle in NOZZLE.items():
        v = profile(name)
        sets = MACHINE + [f"machine_nozzle_size={nozzle}"] + [f"{k}={x}" for k, x in v.items()]
        # Stated as Cura's front end derives them from the profile.
        width = float(v.get("line_width", nozzle))
        sets += [f"wall_line_width_0={width}", f"wall_line_width_x={width}",
                 f"skin_line_width={v.get('skin_line_width', width)}", f"infill_line_width={width}",
                 f"line_width={width}"]
        for shape, stl in shapes.items():
            out = os.path.join(OUT, f"cerambot-{name.replace('_', '-')}-{shape}.gcode")
            cmd = ["CuraEngine", "slice", "-j", os.path.join(defs, "fdmprinter.def.json")]
            for part in (["-e0"], ["-l", stl]):
                for s in sets:
                    cmd += ["-s", s]
                cmd += part
            for s in sets:
                cmd += ["-s", s]
            cmd += ["-o", out]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            print(out, os.path.getsize(out))
