#!/usr/bin/env python3
"""Writes the developable-spline presets examples/spline-*.json (issue 14; Jiang et al. 2020 §4).

Each file is a devsurf scene of model kind "quad_mesh" with a control net ("control"): the scene
loader writes the mesh S^k(M) and its faces from it, both meshes are variable (Algorithm 2), and
handles on control points hold the corners. Plain Python, deterministic.

  spline-single-patch  one 7 × 7 bicubic patch of a doubly curved surface whose control net is
                       deliberately not fair (Fig. 13: the net need not be fair for S^k(M) to be)
  spline-watertight    a 2 × 2 arrangement of 6 × 6 patches sharing their sides (Fig. 15): a
                       roof-like shape kinked along the middle, asked for smoothness across the
                       patch boundaries (G1)

usage: scripts/make_spline_presets.py [--out examples]
"""
import argparse
import importlib.util
import math
import os

from preset_summaries import with_summary

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_spec = importlib.util.spec_from_file_location("make_quad_presets", os.path.join(ROOT, "scripts", "make_quad_presets.py"))
_quad = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_quad)
dump = _quad.dump

SCHEDULE = {"energy_min": 1e-12, "isometry_min": 1e-12, "round_iterations": 20, "rounds": 10,
            "fairness_divisor": 10}


def scene(name, description, control, handles, fairness):
    # E_map at 10 rather than 1: the two lattices of eq. 1 drift less, and the spline itself ends
    # flatter. Fairness (Algorithm 1's round-0 weight) low: at 0.1 it acts as a tension that
    # shrinks the free boundary toward the held corners (both meshes are variable, so nothing
    # keeps the size) — the surface moved 4.7 cm of 25; at 0.01 1.1 cm (docs/architecture.md).
    # No mesh and no unfolding: the loader refines the control net; M′ is planar (the default).
    model = {"kind": "quad_mesh", "control": control, "variables": "both",
             "handles": handles,
             "weights": {"mapping": 10, "position": 10, "fairness_mesh": fairness, "fairness_unfolding": fairness},
             "schedule": SCHEDULE}
    return {"format": "devsurf-scene", "version": 1, "name": name, "description": description,
            "units": "cm", "model": model, "solver": {"iterations": 200}}


def r6(v):
    return round(v, 6)


def hold(index, point):
    return {"on": "control", "vertex": index, "position": [r6(c) for c in point], "weight": 1}


def single_patch():
    n = 7
    points = []
    for r in range(n):
        for c in range(n):
            x, y = -10.0 + 20.0 * c / (n - 1), -10.0 + 20.0 * r / (n - 1)
            z = 0.04 * x * x + 0.012 * y * y + 0.005 * x * y
            # An unfair net: interior points pushed up and down in a checkerboard.
            if 0 < r < n - 1 and 0 < c < n - 1:
                z += 0.4 * (1 if (r + c) % 2 == 0 else -1)
            points.append([r6(x), r6(y), r6(z)])
    corners = [0, n - 1, n * (n - 1), n * n - 1]
    return scene("Developable spline surface (one patch)",
                 "A bicubic B-spline patch (7 × 7 control points, deliberately unfair) made developable by "
                 "Algorithm 2 of Jiang et al. 2020: its refinement S²(M) is held isometric to a flat M′ while "
                 "the four corners stay. Drag control points; the rulings of the limit surface follow.",
                 {"rounds": 2, "points": points, "rows": n, "columns": n},
                 [hold(i, points[i]) for i in corners], 0.001)


def watertight(size=6, shape="roof"):
    # One grid of points, cut into 2 × 2 patches of size × size along its middle row and column.
    R = C = 2 * size - 1
    points = []
    for r in range(R):
        for c in range(C):
            x, y = -12.0 + 24.0 * c / (C - 1), -8.0 + 16.0 * r / (R - 1)
            if shape == "roof":
                z = 0.35 * abs(x) + 0.012 * y * y - 0.004 * x * y  # kinked along x = 0 (the patch boundary)
            else:
                z = 0.2 * abs(x) + 0.015 * x * x + 0.01 * y * y
            points.append([r6(x), r6(y), r6(z)])
    patches = []
    for pr in (0, size - 1):
        for pc in (0, size - 1):
            patches.append({"rows": size, "columns": size,
                            "indices": [(pr + r) * C + pc + c for r in range(size) for c in range(size)]})
    corners = [0, C - 1, C * (R - 1), C * R - 1]
    return scene("Watertight developable spline model (2 × 2 patches)",
                 "Four bicubic patches sharing their sides, so the model is watertight by construction "
                 "(Jiang et al. 2020, Fig. 15). It starts kinked along the middle and doubly curved; "
                 "Algorithm 2 with smoothness across the patch boundaries makes it developable and G1.",
                 {"rounds": 2, "points": points, "patches": patches, "smoothness": 1},
                 [hold(i, points[i]) for i in corners], 0.01)


def presets():
    return {"spline-single-patch": single_patch(), "spline-watertight": watertight()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join(ROOT, "examples"))
    args = parser.parse_args()
    for name, doc in presets().items():
        path = os.path.join(args.out, name + ".json")
        with open(path, "w") as f:
            f.write(dump(with_summary(name + ".json", doc)) + "\n")
        print("%s: %d control points" % (path, len(doc["model"]["control"]["points"])))


if __name__ == "__main__":
    main()
