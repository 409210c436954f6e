#!/usr/bin/env python3
"""Closed-form vessel meshes written by trimesh (PyPI), for the mesh tests
(crates/sweepclay-core/tests/meshes.rs, docs/MESHES.md "Closed forms").

    pip install trimesh numpy shapely mapbox_earcut manifold3d
    python3 scripts/mesh-fixtures.py [NAME…]

writes small binary STLs to crates/sweepclay-core/tests/fixtures/meshes/.
Each is a form whose sweep is known: the tests read what trimesh wrote,
not what our own code would write.
"""

import os
import sys

import numpy as np
import trimesh
from shapely.geometry import Polygon

OUT = os.path.join(
    os.path.dirname(os.path.abspath(__file__)),
    "..", "crates", "sweepclay-core", "tests", "fixtures", "meshes",
)


def revolved(profile, sections):
    """A solid of revolution from (r, z) points, axis to axis."""
    pts = [(0.0, profile[0][1])] + list(profile) + [(0.0, profile[-1][1])]
    return trimesh.creation.revolve(np.array(pts), sections=sections)


def lofted_oval(a, b, h, rings, around, radius=None):
    """An oval whose half-axes a(z) and b(z) change with height, capped;
    or, given `radius(t, z)`, the loop of that radius round the axis."""
    verts, faces = [], []
    for i in range(rings + 1):
        z = h * i / rings
        for j in range(around):
            t = 2 * np.pi * j / around
            if radius is not None:
                r = radius(t, z)
                verts.append((r * np.cos(t), r * np.sin(t), z))
            else:
                verts.append((a(z) * np.cos(t), b(z) * np.sin(t), z))
    for i in range(rings):
        for j in range(around):
            p, q = i * around + j, i * around + (j + 1) % around
            faces += [(p, q, q + around), (p, q + around, p + around)]
    bottom, top = len(verts), len(verts) + 1
    verts += [(0, 0, 0), (0, 0, h)]
    for j in range(around):
        faces.append((bottom, (j + 1) % around, j))
        top_ring = rings * around
        faces.append((top, top_ring + j, top_ring + (j + 1) % around))
    return trimesh.Trimesh(np.array(verts), np.array(faces))


def main():
    os.makedirs(OUT, exist_ok=True)
    forms = {}
    # A cylinder, 70 mm across and 80 tall, standing on the bed.
    c = trimesh.creation.cylinder(radius=35.0, height=80.0, sections=64)
    c.apply_translation((0, 0, 40.0))
    forms["cylinder"] = c
    # A cone's frustum flaring from 30 to 45 mm radius over 70 mm.
    forms["frustum"] = revolved([(30.0, 0.0), (45.0, 70.0)], 64)
    # A bellied profile revolved: r = 30 + 10 sin(pi z / 90).
    zs = np.linspace(0.0, 90.0, 21)
    forms["revolved"] = revolved([(30 + 10 * np.sin(np.pi * z / 90), z) for z in zs], 64)
    # A lofted oval: its long axis flares, its short one leans in.
    forms["lofted-oval"] = lofted_oval(
        lambda z: 40.0 + 6.0 * z / 70.0,
        lambda z: 28.0 - 4.0 * (z / 70.0) ** 2,
        70.0, 20, 96,
    )
    # Twelve flutes 1.5 mm deep on a flaring round pot, rising from a
    # plain foot between 2.5 and 12.5 mm (half a cosine), their sine
    # starting at 30°: r = 35 + 0.08 z + 1.5 e(z) sin(12 t + 30°).
    def rise(z):
        return 0.0 if z <= 2.5 else 1.0 if z >= 12.5 else 0.5 - 0.5 * np.cos(np.pi * (z - 2.5) / 10.0)
    forms["fluted"] = lofted_oval(
        lambda z: 1.0, lambda z: 1.0, 70.0, 20, 120,
        radius=lambda t, z: 35.0 + 0.08 * z + 1.5 * rise(z) * np.sin(12 * t + np.radians(30.0)),
    )
    # A pentagon (rounded by nothing: its corners are vertices) swept
    # straight up 70 mm, turning 0.6 rad from its foot.
    pent = Polygon([(34 * np.cos(a), 34 * np.sin(a))
                    for a in np.linspace(0, 2 * np.pi, 6)[:-1] + np.pi / 2])
    path = np.column_stack([np.zeros(71), np.zeros(71), np.linspace(0, 70, 71)])
    forms["twisted-pentagon"] = trimesh.creation.sweep_polygon(
        pent, path, angles=np.linspace(0.0, 0.6, 71))
    # A cylinder cut by a plane rising 12 mm across it: a solid whose rim
    # slants (its top a cap, not a wall).
    s = trimesh.creation.cylinder(radius=35.0, height=100.0, sections=64)
    s.apply_translation((0, 0, 50.0))
    below = trimesh.creation.box(extents=(400.0, 400.0, 200.0))
    below.apply_translation((0, 0, -100.0))
    below.apply_transform(trimesh.transformations.rotation_matrix(
        -np.arctan2(12.0, 70.0), (0, 1, 0)))
    below.apply_translation((0, 0, 70.0))
    forms["slanted-solid"] = s.intersection(below)
    # The same cylinder under a dome (a sphere of 75 mm round a point
    # 10 mm off its axis): a top that closes over, no opening.
    d = trimesh.creation.cylinder(radius=35.0, height=100.0, sections=64)
    d.apply_translation((0, 0, 50.0))
    ball = trimesh.creation.icosphere(subdivisions=3, radius=75.0)
    ball.apply_translation((10.0, 0, 0))
    forms["domed-solid"] = d.intersection(ball)
    # A cup as potters model it: a cylinder less a cylinder, a wall 4 mm
    # thick on a floor 5 mm thick (a shell).
    outer = trimesh.creation.cylinder(radius=36.0, height=70.0, sections=64)
    outer.apply_translation((0, 0, 35.0))
    inner = trimesh.creation.cylinder(radius=32.0, height=70.0, sections=64)
    inner.apply_translation((0, 0, 40.0))
    forms["cup-shell"] = outer.difference(inner)
    # Walls thicker than a bead, as potters model them (issue 56, point
    # 1): a cylinder 10 mm thick on an 8 mm floor; a wide bowl flaring
    # from 40 to 70 mm radius over 45 mm, 6 mm thick on a 6 mm floor.
    outer = trimesh.creation.cylinder(radius=40.0, height=70.0, sections=96)
    outer.apply_translation((0, 0, 35.0))
    inner = trimesh.creation.cylinder(radius=30.0, height=70.0, sections=96)
    inner.apply_translation((0, 0, 43.0))
    forms["thick-cylinder"] = outer.difference(inner)
    bowl = revolved([(40.0, 0.0), (70.0, 45.0)], 96)
    hollow = revolved([(34.0 + 30.0 * 6.0 / 45.0, 6.0), (64.0 + 30.0 * 6.0 / 45.0, 51.0)], 96)
    forms["wide-bowl"] = bowl.difference(hollow)
    # A pot on a ring foot (issue 56, point 3): a cylinder 80 mm across,
    # its wall 5 mm thick on a 6 mm floor, standing on a ring 10 mm wide
    # round a recess 4 mm deep under its floor.
    pot = trimesh.creation.cylinder(radius=40.0, height=70.0, sections=96)
    pot.apply_translation((0, 0, 35.0))
    cavity = trimesh.creation.cylinder(radius=35.0, height=70.0, sections=96)
    cavity.apply_translation((0, 0, 45.0))
    recess = trimesh.creation.cylinder(radius=30.0, height=8.0, sections=96)
    forms["ring-foot"] = pot.difference(cavity).difference(recess)
    # An eight-point star, its points 45 mm out and its notches 35, swept
    # straight up 60 mm: a solid whose spikes are sharp.
    star = Polygon([((45.0 if k % 2 == 0 else 35.0) * np.cos(np.pi * k / 8),
                     (45.0 if k % 2 == 0 else 35.0) * np.sin(np.pi * k / 8)) for k in range(16)])
    forms["star"] = trimesh.creation.extrude_polygon(star, 60.0)
    # Issue 56, point 2: what potters' meshes carry besides one wall.
    def cup(r=36.0, h=70.0, wall=4.0, floor=5.0, n=96):
        o = trimesh.creation.cylinder(radius=r, height=h, sections=n)
        o.apply_translation((0, 0, h / 2))
        i = trimesh.creation.cylinder(radius=r - wall, height=h, sections=n)
        i.apply_translation((0, 0, h / 2 + floor))
        return o.difference(i)
    # Four drainage holes 6 mm across through a cup's floor.
    holes = [trimesh.creation.cylinder(radius=3.0, height=20.0, sections=24) for _ in range(4)]
    for k, hole in enumerate(holes):
        hole.apply_translation((15.0 * np.cos(k * np.pi / 2), 15.0 * np.sin(k * np.pi / 2), 0.0))
    forms["drained-cup"] = cup().difference(trimesh.util.concatenate(holes))
    # A groove 3 mm wide and 1.5 mm deep round the floor's top, at its edge.
    groove = trimesh.creation.annulus(r_min=29.0, r_max=32.0, height=3.0, sections=96)
    groove.apply_translation((0, 0, 5.0))
    forms["grooved-floor"] = cup().difference(groove)
    # A mug: the cup and a handle (a bar 10 × 8 mm bent round, its ends
    # in the wall at 15 and 55 mm).
    handle = trimesh.creation.box(extents=(8.0, 10.0, 48.0))
    handle.apply_translation((52.0, 0, 35.0))
    top = trimesh.creation.box(extents=(22.0, 10.0, 8.0))
    top.apply_translation((43.0, 0, 55.0))
    low = top.copy()
    low.apply_translation((0, 0, -40.0))
    forms["mug"] = cup().union(handle).union(top).union(low)
    # A bowl on three feet 10 mm tall.
    feet = [trimesh.creation.cylinder(radius=4.0, height=10.0, sections=24) for _ in range(3)]
    for k, foot in enumerate(feet):
        foot.apply_translation((25.0 * np.cos(2 * k * np.pi / 3), 25.0 * np.sin(2 * k * np.pi / 3), 5.0))
    bowl = cup(r=40.0, h=50.0)
    bowl.apply_translation((0, 0, 10.0))
    forms["footed"] = bowl.union(trimesh.util.concatenate(feet))
    # A cup tilted 1.5° (an export turned a little): its foot meets the
    # bed on one side.
    t = cup()
    t.apply_transform(trimesh.transformations.rotation_matrix(np.radians(1.5), (1, 0, 0)))
    forms["tilted-cup"] = t
    # Six windows 12 mm wide through the wall from 25 to 45 mm.
    windows = []
    for k in range(6):
        w = trimesh.creation.box(extents=(20.0, 12.0, 20.0))
        w.apply_translation((36.0, 0, 35.0))
        w.apply_transform(trimesh.transformations.rotation_matrix(k * np.pi / 3, (0, 0, 1)))
        windows.append(w)
    forms["windowed"] = cup().difference(trimesh.util.concatenate(windows))
    # Twelve creases 0.6 mm wide cut 3 mm deep into a solid's outside,
    # slanting 45° to its rays (a faceted vase's folds).
    creases = []
    for k in range(12):
        c2 = trimesh.creation.box(extents=(6.0, 0.6, 100.0))
        c2.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 4, (0, 0, 1)))
        c2.apply_translation((36.0, 0, 40.0))
        c2.apply_transform(trimesh.transformations.rotation_matrix(k * np.pi / 6, (0, 0, 1)))
        creases.append(c2)
    body = trimesh.creation.cylinder(radius=36.0, height=70.0, sections=96)
    body.apply_translation((0, 0, 35.0))
    forms["creased"] = body.difference(trimesh.util.concatenate(creases))
    # A collar inside the cup's wall from 40 to 50 mm, 12.5 mm wide, its
    # underside rising 0.6 mm to the wall (brianfoshee's vase at its
    # neck): sections just under the join cut the underside alone, a
    # ring apart from the wall.
    collar = trimesh.creation.revolve(
        np.array([(20.0, 39.2), (32.5, 39.8), (32.5, 50.0), (20.0, 50.0), (20.0, 39.2)]), sections=96)
    forms["collared-cup"] = cup().union(collar)
    # A post 10 mm across standing 25 mm up from the floor: a part inside.
    post = trimesh.creation.cylinder(radius=5.0, height=25.0, sections=48)
    post.apply_translation((0, 0, 5.0 + 12.5))
    forms["post-cup"] = cup().union(post)
    # `python3 scripts/mesh-fixtures.py NAME…` writes only those (a
    # newer trimesh or manifold may triangulate the others differently).
    only = sys.argv[1:]
    for name, m in forms.items():
        if only and name not in only:
            continue
        if not m.is_watertight:
            sys.exit(f"{name}: trimesh wrote a mesh that is not watertight")
        path = os.path.join(OUT, f"{name}.stl")
        m.export(path)
        print(f"{name}: {len(m.faces)} triangles, {os.path.getsize(path)} bytes, "
              f"{m.bounds[1][2] - m.bounds[0][2]:.1f} mm tall")


if __name__ == "__main__":
    main()
