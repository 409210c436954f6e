#!/usr/bin/env python3
"""Writes three hand-made floor fixtures for the checker's corpus
(docs/CHECKER.md, "Under-extruded moves"; docs/ALGORITHMS.md §8): a round
pot 60 mm across, two floor layers and a short spiral wall, relative E,
3 mm beads on 1.25 mm layers, as a script would write it.

- floor-rings-joins: concentric rings 2.55 mm apart, each closed on its
  start, the step from one ring to the next laid at 5 % of a bead (the
  "join" sweepclay once wrote): fails, under-extruded.
- floor-ring-seam: one flat ring closed on its start under the same wall
  (a bottomless pot as sweepclay once laid it): its last bead ends on its
  first, a seam, as slicers lay perimeters; reported (beads pressed on
  clay), printable.
- floor-spiral: one Archimedean spiral a layer, inward then outward, and
  the wall starting a layer above the floor: printable, nothing on clay
  at its own height.

Run from anywhere: `python3 scripts/corpus/floors.py`."""

import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "crates", "sweepclay-check", "tests", "corpus")
LAYER = 1.25
WIDTH = 3.0
PITCH = WIDTH * 0.85
E_MM3 = 4 / (math.pi * 3.13 ** 2)
C = (100.0, 100.0)
R = 30.0


class Path:
    def __init__(self):
        self.lines = ["; hand-made floor fixture (scripts/corpus/floors.py)", "G21", "G90",
                      "M83", "G28", "G1 Z10 F3000"]
        self.at = None

    def go(self, p):
        self.lines.append(f"G1 X{p[0]:.3f} Y{p[1]:.3f} Z{p[2]:.3f} F3000")
        self.at = p

    def bead(self, p, width=WIDTH, height=LAYER, share=1.0):
        d = math.dist(p[:2], self.at[:2])
        e = d * width * height * E_MM3 * share
        if d < 1e-9:
            # A step straight up: the clay of a half disc.
            e = math.pi / 8 * width * width * abs(p[2] - self.at[2]) * E_MM3
        self.lines.append(f"G1 X{p[0]:.3f} Y{p[1]:.3f} Z{p[2]:.3f} E{e:.5f} F1500")
        self.at = p

    def save(self, name):
        self.lines += ["G1 Z80 F3000", "M84"]
        with open(os.path.join(OUT, name + ".gcode"), "w") as f:
            f.write("\n".join(self.lines) + "\n")


def on(r, t, z):
    return (C[0] + r * math.cos(t), C[1] + r * math.sin(t), z)


def wall(path, z0, turns=6):
    """A helix on the wall's radius from z0 (the floor's top) up, its
    first turn a layer up and rising to two."""
    seg = 96
    path.bead(on(R, 0.0, z0 + LAYER))
    for i in range(1, turns * seg + 1):
        t = 2 * math.pi * i / seg
        path.bead(on(R, t, z0 + LAYER + LAYER * i / seg), height=LAYER * (1 + min(1.0, i / seg)))


def rings(share_join):
    p = Path()
    radii = [R]
    while radii[-1] - PITCH > PITCH / 2:
        radii.append(radii[-1] - PITCH)
    p.go(on(R, 0.0, LAYER))
    for layer in (1, 2):
        z = LAYER * layer
        order = radii if layer == 1 else radii[::-1]
        for k, r in enumerate(order):
            if k > 0 or layer > 1:
                # The step to this ring: a join at share_join of a bead.
                if layer > 1 and k == 0:
                    p.bead(on(r, 0.0, z))
                else:
                    p.bead(on(r, 0.0, z), share=share_join)
            seg = max(12, int(2 * math.pi * r / 1.5))
            for i in range(1, seg + 1):
                p.bead(on(r, 2 * math.pi * i / seg, z))
    wall(p, 2 * LAYER)
    return p


def ring_seam():
    p = Path()
    p.go(on(R, 0.0, LAYER))
    seg = int(2 * math.pi * R / 1.5)
    for i in range(1, seg + 1):
        p.bead(on(R, 2 * math.pi * i / seg, LAYER))
    # The ring closes over its start: its last bead runs on over the first.
    p.bead(on(R, 2 * math.pi * 1.5 / (2 * math.pi * R), LAYER))
    wall(p, LAYER)
    return p


def spiral():
    p = Path()
    turns = int((R + 0.1 * PITCH) / PITCH)
    q = (R + 0.1 * PITCH) / turns
    pts = []
    n = 96
    for i in range(turns * n + 1):
        s = -0.75 * PITCH + q * i / n
        t = -2 * math.pi * i / n
        pts.append((R - s, t))
    p.go(on(pts[0][0], pts[0][1], LAYER))
    for r, t in pts[1:]:
        p.bead(on(r, t, LAYER))
    p.bead(on(pts[-1][0], pts[-1][1], 2 * LAYER))
    for r, t in pts[-2::-1]:
        p.bead(on(r, t, 2 * LAYER))
    # Straight up where the floor ended, then onto the wall.
    end = pts[0]
    p.bead(on(end[0], end[1], 3 * LAYER))
    wall(p, 2 * LAYER)
    return p


def main():
    rings(0.05).save("floor-rings-joins")
    ring_seam().save("floor-ring-seam")
    spiral().save("floor-spiral")


if __name__ == "__main__":
    main()
