#!/usr/bin/env python3
"""Regenerates the checker's corpus of real-world clay G-code.

Small clay designs (a bulging vase and a ripple vase as STL meshes, an open
wall) are sliced by the tools potters use today, with clay settings
(1.25 mm layers, 3 mm beads; a leaning bowl with 1.8 mm layers and
4.5 mm beads):

- CuraEngine (Debian `cura-engine`, spiralize; its setting definitions come
  from Debian's `cura` package, unpacked, never installed),
- PrusaSlicer and Slic3r (Debian `prusa-slicer`, `slic3r`, spiral vase),
- FullControl (PyPI `fullcontrol`, its WASP 2040 Clay profile),
- a plain Python loop, as people script clay G-code by hand.

Also a 54° cone, 4.5 mm lines on 1.25 mm layers, from each slicer, and a
square vase whose first turn is four 63 mm moves. Then hand-made edits
of the valid files, each with one real fault, and a seam jog on the
cone that is short enough to print. Writes
`crates/sweepclay-check/tests/corpus/*.gcode` (each at most 200 KB) and
`printers/*.json`; `tests/corpus.rs` holds each file's verdict and report
snapshot. Run from anywhere: `python3 scripts/corpus/make.py`.
"""

import glob
import math
import re
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "crates", "sweepclay-check", "tests", "corpus")
LAYER = 1.25  # mm, clay layers
WIDTH = 3.0  # mm, clay beads
# A "filament" diameter that makes E count 0.13 units per mm³ of clay (the
# calibration of the paper's sample G-code): 4 / (pi d^2) = 0.13.
FEED_DIA = 3.13
MAX_BYTES = 200_000


def vase_r(z, t):
    """The bulging vase: 50 mm tall, radius 20 mm with a 6 mm bulge."""
    return 20 + 6 * math.sin(math.pi * z / 50)


def ripple_r(z, t):
    """The ripple vase: eight lobes of 2.5 mm, 45 mm tall."""
    return 18 + 2.5 * math.cos(8 * t) + 3 * math.sin(math.pi * z / 45)


def write_stl(path, rfun, height, nz, nt):
    """A closed solid of revolution (side, bottom and top caps), ASCII STL."""
    rings = []
    for k in range(nz + 1):
        z = height * k / nz
        ring = []
        for j in range(nt):
            t = 2 * math.pi * j / nt
            r = rfun(z, t)
            ring.append((r * math.cos(t), r * math.sin(t), z))
        rings.append(ring)
    tris = []
    for k in range(nz):
        a, b = rings[k], rings[k + 1]
        for j in range(nt):
            j2 = (j + 1) % nt
            tris += [(a[j], a[j2], b[j2]), (a[j], b[j2], b[j])]
    c0, c1 = (0.0, 0.0, 0.0), (0.0, 0.0, height)
    for j in range(nt):
        j2 = (j + 1) % nt
        tris += [(c0, rings[0][j2], rings[0][j]), (c1, rings[-1][j], rings[-1][j2])]
    with open(path, "w") as f:
        f.write("solid m\n")
        for t in tris:
            f.write(" facet normal 0 0 0\n  outer loop\n")
            for p in t:
                f.write("   vertex %.4f %.4f %.4f\n" % p)
            f.write("  endloop\n endfacet\n")
        f.write("endsolid m\n")


def run(cmd):
    print("  $", " ".join(cmd[:3]), "...", file=sys.stderr)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def cura_definitions(tmp):
    """fdmprinter.def.json from Debian's `cura` package (downloaded and
    unpacked into `tmp`; CuraEngine needs it and Debian ships it there)."""
    found = glob.glob("/usr/share/cura/resources/definitions/fdmprinter.def.json")
    if found:
        return os.path.dirname(found[0])
    subprocess.run(["apt-get", "download", "cura"], cwd=tmp, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deb = glob.glob(os.path.join(tmp, "cura_*.deb"))[0]
    subprocess.run(["dpkg-deb", "-x", deb, os.path.join(tmp, "cura")], check=True)
    return os.path.join(tmp, "cura", "usr", "share", "cura", "resources", "definitions")


def cura_settings(layer=LAYER, width=WIDTH):
    """CuraEngine's clay settings for a spiralized vase."""
    return [
        "magic_spiralize=true", f"layer_height={layer}", f"layer_height_0={layer}",
        f"line_width={width}", f"machine_nozzle_size={width}",
        f"material_diameter={FEED_DIA}", "bottom_layers=0", "top_layers=0",
        "wall_line_count=1", "infill_sparse_density=0", "adhesion_type=skirt",
        "skirt_line_count=1", "skirt_gap=6", "speed_print=30", "speed_wall_0=30",
        "machine_width=200", "machine_depth=200", "machine_height=200",
        "retraction_amount=2", "smooth_spiralized_contours=true",
        "meshfix_maximum_resolution=1.5",
        # CuraEngine's command line takes the definitions' default values,
        # not their formulas: the settings derived from the above, stated.
        f"wall_line_width_0={width}", f"wall_line_width_x={width}",
        f"skirt_brim_line_width={width}", f"skin_line_width={width}",
        f"infill_line_width={width}", "top_thickness=0", "bottom_thickness=0",
        "top_bottom_thickness=0", "initial_bottom_layers=0", "infill_line_distance=0",
        "roofing_layer_count=0", "speed_layer_0=30", "speed_print_layer_0=30",
        "speed_travel=60", "retraction_hop_enabled=false",
    ]


def cura(stl, out, defs, layer=LAYER, width=WIDTH):
    clay = cura_settings(layer, width)
    cmd = ["CuraEngine", "slice", "-j", os.path.join(defs, "fdmprinter.def.json")]
    for s in clay:
        cmd += ["-s", s]
    cmd += ["-e0"]
    for s in clay:
        cmd += ["-s", s]
    cmd += ["-l", stl]
    for s in clay:
        cmd += ["-s", s]
    cmd += ["-o", out]
    run(cmd)


PRUSA_START = (
    "G28 ; home all axes\\nG1 Z5 F5000 ; lift nozzle\\nG21\\nG90\\nM82\\n"
    "G92 E0\\nG1 X20 Y10 Z1.25 F3000 ; to the purge line\\n"
    "G1 X60 Y10 E15 F1000 ; purge line on the bed, off the part\\nG92 E0\\n"
)


def prusa(tool, stl, out, tmp, layer=LAYER, width=WIDTH, first_width=None, retract=2):
    """`tool`'s spiral vase of `stl`: `width` beads on `layer` layers, the
    first layer's beads `first_width` wide (default `width`), retracting
    `retract` mm where the slicer travels."""
    first_width = width if first_width is None else first_width
    cmd = [
        tool, "--export-gcode" if tool == "prusa-slicer" else "--gcode-comments",
        "--spiral-vase", "--perimeters", "1", "--layer-height", str(layer),
        "--first-layer-height", str(layer), "--nozzle-diameter", str(width),
        "--extrusion-width", str(width), "--first-layer-extrusion-width", str(first_width),
        "--filament-diameter", str(FEED_DIA), "--bottom-solid-layers", "0",
        "--top-solid-layers", "0", "--skirts", "0", "--fill-density", "0",
        "--center" if tool == "prusa-slicer" else "--print-center", "100,100", "--bed-shape", "0x0,200x0,200x200,0x200",
        "--perimeter-speed", "30", "--first-layer-speed", "30",
        "--retract-length", str(retract), "-o", out, stl,
    ]
    if tool == "prusa-slicer":
        cmd[1:1] = ["--max-print-height", "200", "--start-gcode", PRUSA_START.replace("\\n", "\n")]
    else:
        # Slic3r: its own start code, plus a stationary prime as clay
        # printers do it (an ini file: its command line mangles newlines).
        ini = os.path.join(tmp, "slic3r.ini")
        with open(ini, "w") as f:
            f.write("start_gcode = G28 ; home\\nG1 Z5 F5000\\nG92 E0\\nG1 F200 E3 ; prime\\nG92 E0\n")
        cmd[1:1] = ["--load", ini]
    run(cmd)


def bowl_r(z, t):
    """The leaning bowl: 36 mm tall, radius 25 mm at the foot, its wall
    leaning 35° out from the vertical."""
    return 25 + z * math.tan(math.radians(35))


BOWL_LAYER = 1.8  # mm: wide, thick clay lines, as potters print bowls
BOWL_WIDTH = 4.5


def lean_files(tmp, defs):
    """Leaning vase starts: the 35° bowl with 4.5 mm lines on 1.8 mm
    layers, spiralized by each slicer. Their first turn rises from the
    flat first loop over a wall that leans out."""
    bowl = os.path.join(tmp, "bowl.stl")
    write_stl(bowl, bowl_r, 36, 20, 64)
    lw = dict(layer=BOWL_LAYER, width=BOWL_WIDTH)
    cura(bowl, os.path.join(OUT, "cura-bowl.gcode"), defs, **lw)
    prusa("prusa-slicer", bowl, os.path.join(OUT, "prusa-bowl.gcode"), tmp, **lw)
    prusa("slic3r", bowl, os.path.join(OUT, "slic3r-bowl.gcode"), tmp, **lw)


def cone_r(z, t):
    """The steep cone: 30 mm tall, radius 20 mm at the foot, its wall
    leaning 54° out from the vertical, 3° inside the overhang limit."""
    return 20 + z * math.tan(math.radians(54))


CONE_WIDTH = 4.5  # mm: wide beads on thin layers, as steep walls need


def cone_files(tmp, defs):
    """The 54° cone spiralized by each slicer with 4.5 mm lines on 1.25 mm
    layers: every turn leans 1.72 mm out over the one below."""
    cone = os.path.join(tmp, "cone.stl")
    write_stl(cone, cone_r, 30, 20, 96)
    lw = dict(layer=LAYER, width=CONE_WIDTH)
    cura(cone, os.path.join(OUT, "cura-cone.gcode"), defs, **lw)
    prusa("prusa-slicer", cone, os.path.join(OUT, "prusa-cone.gcode"), tmp, **lw)
    prusa("slic3r", cone, os.path.join(OUT, "slic3r-cone.gcode"), tmp, **lw)


def square_file():
    """A square spiral vase as people script it, whose flat first loop and
    rising first turn are each four straight 63 mm moves (one bead a
    side), the turns above cut into 2 mm moves: a first bead as long as a
    side must be judged as the same path cut short would be."""
    e_mm3 = 4 / (math.pi * FEED_DIA ** 2)
    side, c = 63.0, 100.0
    corners = [(c - side / 2, c - side / 2), (c + side / 2, c - side / 2),
               (c + side / 2, c + side / 2), (c - side / 2, c + side / 2)]
    lines = ["; a plain Python loop: a square vase", "G21", "G90", "M83", "G28", "G1 Z10 F3000",
             f"G1 X{corners[0][0]:.3f} Y{corners[0][1]:.3f} Z{LAYER:.3f} F3000"]
    prev = (corners[0][0], corners[0][1], LAYER)
    turns = 16
    for turn in range(turns + 1):
        cut = 1 if turn < 2 else int(side / 2.0)
        for k in range(4):
            a, b = corners[k], corners[(k + 1) % 4]
            for j in range(1, cut + 1):
                u = (k + j / cut) / 4  # share of the turn
                z = LAYER + (0.0 if turn == 0 else LAYER * (turn - 1 + u))
                p = (a[0] + (b[0] - a[0]) * j / cut, a[1] + (b[1] - a[1]) * j / cut, z)
                d = math.dist(p, prev)
                lines.append(f"G1 X{p[0]:.3f} Y{p[1]:.3f} Z{p[2]:.3f} E{d * WIDTH * LAYER * e_mm3:.5f} F1500")
                prev = p
    lines += ["G1 E-1.5 F1200 ; end retraction", "G1 Z80 F3000", "G28 X Y", "M84"]
    with open(os.path.join(OUT, "python-square.gcode"), "w") as f:
        f.write("\n".join(lines) + "\n")


def jog_edits():
    """A jog on the real 54° cone (PrusaSlicer): at 15.6 mm the path
    steps 0.3 mm out, runs along the wall and steps back, as a seam or a
    scripted lip does. Its outer bead leans 59° over the turn below (the
    limit is 57°; the overlap is still half the bead): one 2.6 mm move
    long, shorter than the narrowest bead is wide, it cannot sag on its
    own and the file prints (`overhang-jog`); four moves, 10.4 mm, it
    sags (`fault-overhang-run`)."""
    with open(os.path.join(OUT, "prusa-cone.gcode")) as f:
        lines = f.read().split("\n")
    e_per_mm = CONE_WIDTH * LAYER * 4 / (math.pi * FEED_DIA ** 2)

    def xyze(line):
        v = {}
        for w in line.split(";")[0].split()[1:]:
            if w[0] in "XYZE":
                v[w[0]] = float(w[1:])
        return v

    def jogged(moves):
        out = list(lines)
        # The first extruding move at or above 15.6 mm: from its end the
        # next `moves` moves are laid 0.3 mm farther out (from the cone's
        # axis, the bed's middle), with their own clay; a short move out
        # and one back in join them to the wall.
        i = next(k for k, l in enumerate(out) if l.startswith("G1 Z") and " E" in l
                 and xyze(l).get("Z", 0) >= 15.6)
        out_mm = 0.3
        added = 0.0
        e_prev = xyze(out[i])["E"]
        p = xyze(out[i])
        first = True
        for k in range(i + 1, i + 1 + moves):
            v = xyze(out[k])
            de = v["E"] - e_prev
            e_prev = v["E"]
            rn = math.hypot(v["X"] - 100.0, v["Y"] - 100.0)
            x = v["X"] + out_mm * (v["X"] - 100.0) / rn
            y = v["Y"] + out_mm * (v["Y"] - 100.0) / rn
            jog = []
            if first:
                # Out from the wall at the jog's start.
                qn = math.hypot(p["X"] - 100.0, p["Y"] - 100.0)
                ox = p["X"] + out_mm * (p["X"] - 100.0) / qn
                oy = p["Y"] + out_mm * (p["Y"] - 100.0) / qn
                added += out_mm * e_per_mm
                jog.append(f"G1 X{ox:.3f} Y{oy:.3f} E{p['E'] + added:.5f} ; jog out")
                first = False
            jog.append(f"G1 Z{v['Z']:.3f} X{x:.3f} Y{y:.3f} E{v['E'] + added:.5f} ; jog")
            out[k] = "\n".join(jog)
            last = v
        # Back in to the wall where the jog ends.
        added += out_mm * e_per_mm
        out[i + moves] += f"\nG1 X{last['X']:.3f} Y{last['Y']:.3f} E{last['E'] + added:.5f} ; jog in"
        # Absolute E: every later E grows by the jog's own clay.
        for k in range(i + 1 + moves, len(out)):
            m = re.search(r"E(-?[0-9.]+)", out[k].split(";")[0])
            if m and out[k].startswith("G1"):
                out[k] = out[k].replace(m.group(0), f"E{float(m.group(1)) + added:.5f}", 1)
        return "\n".join(out).split("\n")

    with open(os.path.join(OUT, "overhang-jog.gcode"), "w") as f:
        f.write("\n".join(jogged(1)))
    with open(os.path.join(OUT, "fault-overhang-run.gcode"), "w") as f:
        f.write("\n".join(jogged(4)))


# Cura 5's Eazao Zero start and end code (Ultimaker/Cura,
# resources/definitions/eazao_zero.def.json at commit 07076dc): the end
# code lifts the nozzle by declaring a new origin (`G92 Z0`, then
# `G1 Z10`). Debian's CuraEngine 4.13 ships the older definition.
EAZAO_START = ("G21 \nG90 ;absolute positioning\nM82 ;set extruder to absolute mode\nG28 ;Home \n"
               "G1 Z15.0 F1500 ;move the platform down 15mm\nG92 E0 \nG1 F1500 E2\nG92 E0\nM302\n"
               "M163 S0 P0.8; Set Mix Factor\nM163 S1 P0.2; Set Mix Factor\nM164 S0\n")
EAZAO_END = "G92 Z0 E0\nG1 F1500 E-2\nG1 F1500 Z10\nG28 X0;move X Y to min endstops\nM82\nM84 ;steppers off\n"


def cura_machine(defs, definition, stl, name, machine=()):
    """CuraEngine with a printer's own definition (its start and end
    code) and the clay settings, `machine` overriding its machine
    settings, slicing `stl` into the corpus's `name`.gcode."""
    clay = cura_settings()
    cmd = ["CuraEngine", "slice", "-j", os.path.join(defs, definition + ".def.json")]
    for s in clay + list(machine):
        cmd += ["-s", s]
    cmd += ["-e0"]
    for s in clay:
        cmd += ["-s", s]
    cmd += ["-l", stl, "-o", os.path.join(OUT, name + ".gcode")]
    run(cmd)


def firmware_files(tmp, defs, vase):
    """Files whose firmware commands the checker must read as firmware
    does (docs/CHECKER.md, "Firmwares"), made by the slicers themselves:
    CuraEngine with the Eazao Zero's definition and Cura 5's Eazao start
    and end code (`G92 Z0` before the lift); PrusaSlicer with firmware
    retraction (`G10`/`G11`); PrusaSlicer's layer-change G-code writing
    `G4 P0` (a planner sync) at every layer, then `G4 S5` (a 5 s pause) at
    one layer, then `M221 S10` (10 % flow) from one layer on."""
    cura_machine(defs, "eazao_zero", vase, "cura-eazao",
                 [f"machine_start_gcode={EAZAO_START}", f"machine_end_gcode={EAZAO_END}",
                  "machine_width=150", "machine_depth=150", "machine_height=240"])
    # Debian's Cura definition of the Structur3D Discov3ry, a paste
    # extruder on an Ultimaker 2+: its own start code sets the paste's
    # steps (`M92 E2589`), its end code sets them back for plastic
    # (`M92 E282`), as a paste printer's file does (issue 55, class 3).
    cura_machine(defs, "structur3d_discov3ry1_complete_um2plus", vase, "cura-discov3ry")

    def prusa_with(name, *more):
        # PrusaSlicer's vase with the extra options.
        run(vase_call(vase, os.path.join(OUT, name + ".gcode"), LAYER, WIDTH, LAYER, *more))

    prusa_with("prusa-fwretract", "--use-firmware-retraction")
    prusa_with("prusa-g4p0", "--layer-gcode", "G4 P0 ; planner sync")
    prusa_with("fault-dwell", "--layer-gcode", "{if layer_num==12}G4 S5 ; pause for a photo{endif}")
    prusa_with("fault-m221", "--layer-gcode", "{if layer_num==12}M221 S10 ; flow to 10 %{endif}")


def vase_call(stl, path, layer, width, first, *more):
    """PrusaSlicer's spiral vase of `stl` with clay beads `width` wide on
    `layer` layers, the first `first` high."""
    return ["prusa-slicer", "--max-print-height", "200", "--start-gcode",
            PRUSA_START.replace("\\n", "\n"), "--export-gcode", "--spiral-vase",
            "--perimeters", "1", "--layer-height", str(layer), "--first-layer-height", str(first),
            "--nozzle-diameter", str(width), "--extrusion-width", str(width),
            "--first-layer-extrusion-width", str(width), "--filament-diameter", str(FEED_DIA),
            "--bottom-solid-layers", "0", "--top-solid-layers", "0", "--skirts", "0",
            "--fill-density", "0", "--center", "100,100", "--bed-shape", "0x0,200x0,200x200,0x200",
            "--perimeter-speed", "30", "--first-layer-speed", "30", "--retract-length", "2",
            *more, "-o", path, stl]


def wide_first_files(tmp):
    """Issue 55, class 1: vases whose first layer is laid wider than the
    wall (a first-layer width of 9.5 mm under 4 mm beads: a setting for a
    footing that holds on the board), retraction off as clay needs. The
    wall's first turn rises from that loop's top, 2.75 mm in from its
    outer edge, from a short move across the loop just laid."""
    cyl = os.path.join(tmp, "wide-cylinder.stl")
    write_stl(cyl, lambda z, t: 30.0, 24, 16, 128)
    prusa("prusa-slicer", cyl, os.path.join(OUT, "prusa-wide-first.gcode"), tmp,
          layer=1.5, width=4.0, first_width=9.5, retract=0)
    bowl = os.path.join(tmp, "bowl.stl")
    write_stl(bowl, bowl_r, 36, 20, 64)
    lw = dict(layer=BOWL_LAYER, width=BOWL_WIDTH, first_width=9.5, retract=0)
    prusa("prusa-slicer", bowl, os.path.join(OUT, "prusa-wide-bowl.gcode"), tmp, **lw)
    prusa("slic3r", bowl, os.path.join(OUT, "slic3r-wide-bowl.gcode"), tmp, **lw)


def round5_files(tmp, vase):
    """Issue 55: PrusaSlicer's vase of a plain cylinder whose first layer
    is 3.0 mm, the tallest first layer the checker takes (class 1: its
    ramp starts 0.005 mm above that loop, where the loop ends); the bulging
    vase in 3.7 mm beads on 1.5 mm layers with `M221 S25` from layer 12
    (class 4: a 0.92 mm coil, narrower than it is tall)."""
    cyl = os.path.join(tmp, "cylinder.stl")
    write_stl(cyl, lambda z, t: 30.0, 45, 30, 128)
    run(vase_call(cyl, os.path.join(OUT, "prusa-first3.gcode"), 1.5, 4.0, 3.0))
    run(vase_call(vase, os.path.join(OUT, "fault-m221-25.gcode"), 1.5, 3.7, 1.5,
                  "--layer-gcode", "{if layer_num==12}M221 S25 ; flow to 25 %{endif}"))


def main():
    os.makedirs(OUT, exist_ok=True)
    for f in glob.glob(os.path.join(OUT, "*.gcode")):
        os.remove(f)
    with tempfile.TemporaryDirectory() as tmp:
        vase = os.path.join(tmp, "vase.stl")
        ripple = os.path.join(tmp, "ripple.stl")
        write_stl(vase, vase_r, 50, 40, 48)
        write_stl(ripple, ripple_r, 45, 36, 64)
        defs = cura_definitions(tmp)
        cura(vase, os.path.join(OUT, "cura-vase.gcode"), defs)
        cura(ripple, os.path.join(OUT, "cura-ripple.gcode"), defs)
        lean_files(tmp, defs)
        cone_files(tmp, defs)
        firmware_files(tmp, defs, vase)
        round5_files(tmp, vase)
        wide_first_files(tmp)
        prusa("prusa-slicer", vase, os.path.join(OUT, "prusa-vase.gcode"), tmp)
        prusa("prusa-slicer", ripple, os.path.join(OUT, "prusa-ripple.gcode"), tmp)
        prusa("slic3r", vase, os.path.join(OUT, "slic3r-vase.gcode"), tmp)
        prusa("slic3r", ripple, os.path.join(OUT, "slic3r-ripple.gcode"), tmp)
    fullcontrol_files()
    python_loop_files()
    square_file()
    edits()
    jog_edits()
    big = False
    for f in sorted(glob.glob(os.path.join(OUT, "*.gcode"))):
        size = os.path.getsize(f)
        print(f"{os.path.basename(f):28} {size:>8} bytes")
        big = big or size > MAX_BYTES
    if big:
        sys.exit(f"a file is over {MAX_BYTES} bytes")


if __name__ == "__main__":
    main()
