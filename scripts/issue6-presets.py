#!/usr/bin/env python3
"""Writes the issue-6 presets examples/{quasi,conical}-strip-{hull,brim,twisted}.json.

The same curve pair goes into both models' scenes, so that their reports compare
(scripts/compare-bo-chu.py). Each curve is a clamped uniform cubic B-spline fitted by least
squares to a closed-form curve (pure Python: no numpy on the target machine).
"""
import json
import math
import os

from preset_summaries import with_summary

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def basis(knots, p, i, u):
    """N_{i,p}(u) by Cox-de Boor (right end included in the last span)."""
    if p == 0:
        if knots[i] <= u < knots[i + 1]:
            return 1.0
        if u == knots[-1] and knots[i] < knots[i + 1] == knots[-1]:
            return 1.0
        return 0.0
    out = 0.0
    if knots[i + p] > knots[i]:
        out += (u - knots[i]) / (knots[i + p] - knots[i]) * basis(knots, p - 1, i, u)
    if knots[i + p + 1] > knots[i + 1]:
        out += (knots[i + p + 1] - u) / (knots[i + p + 1] - knots[i + 1]) * basis(knots, p - 1, i + 1, u)
    return out


def clamped_uniform(p, n):
    inner = n - p - 1
    return [0.0] * (p + 1) + [(k + 1) / (inner + 1) for k in range(inner)] + [1.0] * (p + 1)


def solve(a, b):
    """Gaussian elimination with partial pivoting; a is n×n, b is n×m."""
    n = len(a)
    a = [row[:] + bb[:] for row, bb in zip(a, b)]
    for c in range(n):
        piv = max(range(c, n), key=lambda r: abs(a[r][c]))
        a[c], a[piv] = a[piv], a[c]
        for r in range(n):
            if r != c and a[r][c] != 0.0:
                f = a[r][c] / a[c][c]
                a[r] = [x - f * y for x, y in zip(a[r], a[c])]
    return [[x / a[r][r] for x in a[r][n:]] for r in range(n)]


def fit(f, n, p=3, samples=400):
    """Cubic B-spline with n control points fitted to f on [0, 1]; the ends interpolate."""
    knots = clamped_uniform(p, n)
    us = [k / (samples - 1) for k in range(samples)]
    rows = [[basis(knots, p, i, u) for i in range(n)] for u in us]
    w = [100.0 if k in (0, samples - 1) else 1.0 for k in range(samples)]  # ends held closely
    ata = [[sum(w[k] * rows[k][i] * rows[k][j] for k in range(samples)) for j in range(n)] for i in range(n)]
    atb = [[sum(w[k] * rows[k][i] * f(us[k])[d] for k in range(samples)) for d in range(3)] for i in range(n)]
    pts = solve(ata, atb)
    pts[0], pts[-1] = list(f(0.0)), list(f(1.0))
    return {"degree": p, "points": [[round(x, 9) for x in pt] for pt in pts]}


def bezier(points, t):
    n = len(points) - 1
    return [sum(math.comb(n, i) * (1 - t) ** (n - i) * t ** i * points[i][d] for i in range(n + 1)) for d in range(3)]


# (a) A hard-chine hull's side panel (metres): the sheer line above the chine, bow at x = 0 where
# both curves close in, a transom at x = 9. Half-breadths grow from the stem to about 1.6 m.
def sheer(u):
    x = 9.0 * u
    return (x, 1.65 * math.sin(min(1.0, 0.25 + 0.9 * u) * math.pi / 2) ** 1.5, 1.55 - 0.35 * u + 0.25 * (1 - u) ** 3)


def chine(u):
    x = 0.4 + 8.6 * u
    return (x, 1.45 * math.sin(min(1.0, 0.12 + 1.0 * u) * math.pi / 2) ** 1.2, 0.35 + 0.55 * (1 - u) ** 2.5)


# (b) A hat brim (centimetres) around a crown of radius 9: the inner edge a level open arc of
# 300°, the outer edge (radius 16) sloping down 2 cm and tilted: 0.8 cm lower at the front (θ = 0) and higher at the back, like a snap brim.
SPAN = 300.0 / 180.0 * math.pi


def brim_inner(u):
    t = -SPAN / 2 + SPAN * u
    return (9.0 * math.cos(t), 9.0 * math.sin(t), 0.0)


def brim_outer(u):
    t = -SPAN / 2 + SPAN * u
    return (16.0 * math.cos(t), 16.0 * math.sin(t), -2.0 - 0.8 * math.cos(t))


# (c) A strongly twisted pair like Bo et al. Fig. 2 (the quasi_strip tests' twistedConeDesign): a
# cone with apex A through a wavy quintic Bézier q; C2 = q, C1 = A + 1.8 (q∘ψ − A) with ψ a cubic
# far from the identity, so that the rulings C1(t)C2(t) cross the cone.
Q = [[0, 0, 0], [1, 1.2, 0.4], [2, -0.8, 1.0], [3, 1.0, -0.6], [4, -0.6, 0.3], [5, 0.4, 0.0]]
PSI = [0.0, 0.08, 0.33, 1.0]
APEX = [2.5, 0.2, -3.0]


def twisted_c1(u):
    psi = sum(math.comb(3, i) * (1 - u) ** (3 - i) * u ** i * PSI[i] for i in range(4))
    q = bezier(Q, psi)
    return tuple(APEX[d] + 1.8 * (q[d] - APEX[d]) for d in range(3))


PAIRS = {
    "hull": {
        "units": "m",
        "name": "hull side panel",
        "what": "a hard-chine hull's side panel between the chine (c1/p) and the sheer line (c2/q), 9 m long",
        "c1": fit(chine, 10), "c2": fit(sheer, 10),
        "conical": {"np": 40, "nq": 44, "h3": 1.8, "h4": 0.5, "ra": 1.2},
    },
    "brim": {
        "units": "cm",
        "name": "hat brim",
        "what": "a hat brim around a crown of radius 9 cm: a level inner edge (c1/p) and a wavy outer edge of radius 16 cm (c2/q), open arcs of 300°",
        "c1": fit(brim_inner, 14), "c2": fit(brim_outer, 14),
        # h3 ≈ 1.08 × the strip width, h4 = 0.5 cm: at 9 / 1.0 (until stop 54) fans ran on until the
        # greedy strip folded back by 165° and quadrilateral corners stood 0.9 cm off the curves.
        "conical": {"np": 40, "nq": 60, "h3": 7.8, "h4": 0.5, "ra": 2.0},
    },
    "twisted": {
        "units": "mm",
        "name": "twisted pair",
        "what": "a strongly twisted pair like Bo et al. Fig. 2: curves on a cone whose rulings at T = t cross it (more than 30° of warp before solving)",
        "c1": fit(twisted_c1, 24), "c2": {"degree": 5, "points": Q},
        "conical": {"np": 60, "nq": 40, "h3": 5.0, "h4": 0.6, "ra": 2.0},
    },
}


def write(path, scene):
    with open(os.path.join(ROOT, "examples", path), "w") as out:
        json.dump(with_summary(path, scene), out, indent=1)
        out.write("\n")


for key, pair in PAIRS.items():
    write(f"quasi-strip-{key}.json", {
        "format": "devsurf-scene", "version": 1, "name": f"{pair['name']} (Bo et al.)",
        "description": f"A developable strip between two given curves by Bo et al.'s method: {pair['what']}. "
                       "The rulings come from a smooth mapping between the curves, optimized until the strip "
                       "is as developable as the curves allow. Compare with conical-strip-" + key
                       + ".json, Chu et al.'s method on the same curves.",
        "units": pair["units"],
        "model": {"kind": "quasi_strip", "c1": pair["c1"], "c2": pair["c2"],
                  "mapping": {"degree": 2, "coefficients": 50}, "samples": 100,
                  "method": "bspline", "optimizer": "lbfgs"}})
    c = pair["conical"]
    write(f"conical-strip-{key}.json", {
        "format": "devsurf-scene", "version": 1, "name": f"{pair['name']} (Chu et al.)",
        "description": f"A developable strip between two given curves by Chu et al.'s method: {pair['what']}. "
                       "Cone patches are laid one after another along the curves and joined smoothly. "
                       "Compare with quasi-strip-" + key + ".json, Bo et al.'s method on the same curves.",
        "units": pair["units"],
        "model": {"kind": "conical_strip", "p": pair["c1"], "q": pair["c2"], **c,
                  "objective": "normal_variation", "g1": True}})
