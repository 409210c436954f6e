#!/usr/bin/env python3
"""How far a printed pot's outside lies from its mesh's outside (issue 56,
point 1; docs/MESHES.md, "The outside is the pot").

Each mesh is sliced by the release CLI with `--stl`, which writes the
surface the G-code prints thickened to its beads' widths. Both meshes are
cut at five heights (10, 30, 50, 70 and 90 % of the pot's height); along
72 rays from the mesh section's centroid, the outside is where a ray leaves
the section last. Prints, per mesh, the print's outside less the mesh's
(mm, + outward) at each height, as the mean over the rays and the worst
ray. Reads binary or ASCII STL with nothing but the standard library.

    cargo build --release
    python3 scripts/mesh-outside.py MESH.stl [MESH.stl ...]
"""
import math
import os
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
BIN = os.path.join(ROOT, "target", "release", "sweepclay")
RAYS = 72
HEIGHTS = (0.1, 0.3, 0.5, 0.7, 0.9)


def read_stl(path):
    """The triangles of an STL file, as three (x, y, z) each."""
    data = open(path, "rb").read()
    if len(data) >= 84:
        n = struct.unpack_from("<I", data, 80)[0]
        if 84 + 50 * n == len(data):
            return [tuple(struct.unpack_from("<9f", data, 84 + 50 * i + 12)[k:k + 3]
                          for k in (0, 3, 6)) for i in range(n)]
    tris, cur = [], []
    for line in data.decode("ascii", "replace").splitlines():
        w = line.split()
        if w and w[0] == "vertex":
            cur.append(tuple(float(v) for v in w[1:4]))
            if len(cur) == 3:
                tris.append(tuple(cur))
                cur = []
    return tris


def section(tris, z):
    """The segments where the plane at height z cuts the triangles."""
    segs = []
    for t in tris:
        pts = []
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            if (a[2] - z) * (b[2] - z) < 0:
                s = (z - a[2]) / (b[2] - a[2])
                pts.append((a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])))
        if len(pts) == 2:
            segs.append(pts)
    return segs


def outside(segs, c, a):
    """Where the ray from c at angle a leaves the section last (its
    distance from c), or None."""
    d = (math.cos(a), math.sin(a))
    far = None
    for p, q in segs:
        ex, ey = q[0] - p[0], q[1] - p[1]
        den = d[0] * ey - d[1] * ex
        if abs(den) < 1e-12:
            continue
        u = ((p[0] - c[0]) * ey - (p[1] - c[1]) * ex) / den
        s = ((p[0] - c[0]) * d[1] - (p[1] - c[1]) * d[0]) / den
        if u > 0 and 0 <= s <= 1:
            far = u if far is None else max(far, u)
    return far


def bounds(tris):
    zs = [v[2] for t in tris for v in t]
    return min(zs), max(zs)


def compare(mesh, printed, cut=0.0):
    """Per height: (z, mean, worst) of the print's outside less the mesh's;
    `cut`: the mm of the mesh's bottom the print leaves out (a tilted or
    round foot cut level), so the print's bed is that high on the mesh."""
    m, p = read_stl(mesh), read_stl(printed)
    (mz0, mz1), (pz0, _) = bounds(m), bounds(p)
    rows = []
    for f in HEIGHTS:
        # Off the heights a mesh's rings of vertices often sit at.
        h = f * (mz1 - mz0) + 0.0137
        sm, sp = section(m, mz0 + h), section(p, pz0 + h - cut)
        if not sm or not sp:
            rows.append((h, None, None))
            continue
        # The centroid of the mesh section's points, and the print's own
        # (the fit moves the foot's centre to the origin).
        cm = [sum(q[k] for s in sm for q in s) / (2 * len(sm)) for k in (0, 1)]
        cp = [sum(q[k] for s in sp for q in s) / (2 * len(sp)) for k in (0, 1)]
        diffs = []
        for i in range(RAYS):
            a = math.tau * i / RAYS
            rm, rp = outside(sm, cm, a), outside(sp, cp, a)
            if rm is not None and rp is not None:
                diffs.append(rp - rm)
        if diffs:
            rows.append((h, sum(diffs) / len(diffs), max(diffs, key=abs)))
        else:
            rows.append((h, None, None))
    return rows


def main():
    for mesh in sys.argv[1:]:
        with tempfile.TemporaryDirectory() as tmp:
            stl, gcode = os.path.join(tmp, "print.stl"), os.path.join(tmp, "print.gcode")
            r = subprocess.run([BIN, "slice", mesh, "-o", gcode, "--stl", stl],
                               capture_output=True, text=True)
            name = os.path.basename(mesh)
            if r.returncode != 0 or not os.path.exists(stl):
                why = (r.stdout + r.stderr).strip().splitlines()
                print(f"| {name} | refused: {why[-1] if why else r.returncode} |")
                continue
            rows = compare(mesh, stl)
            cells = " | ".join("–" if mean is None else f"{mean:+.1f} ({worst:+.1f})"
                               for _, mean, worst in rows)
            print(f"| {name} | {cells} |")


if __name__ == "__main__":
    main()
