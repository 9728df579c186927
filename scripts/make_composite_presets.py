#!/usr/bin/env python3
"""Writes the generated composite presets of examples/ (a folded annulus; a curved-crease column; a curved box;
a pleated sheet with normal splines).
The scenes are plain JSON (proto/schemas/scene.schema.json); this script only saves typing their
numbers. The column is shaped the way a designer would shape it: its handles are dragged in small
steps, each solved by the devsurf binary (build it first: scripts/setup.sh), and the last state is
saved with its development. Run from anywhere: python3 scripts/make_composite_presets.py [annulus|column|curved-box|pleated-sheet ...]"""
import json
import math
import os
import subprocess
import tempfile

from preset_summaries import with_summary

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
EXAMPLES = os.path.join(ROOT, "examples")
DEVSURF = os.environ.get("DEVSURF_BIN", os.path.join(ROOT, "build", "server", "devsurf"))


def insert_knot(knots, points, degree, u):
    """Boehm's knot insertion (NURBS Book A5.1, one insertion) on a clamped curve."""
    k = max(i for i in range(len(knots) - 1) if knots[i] <= u < knots[i + 1])
    new = []
    for i in range(len(points) + 1):
        if i <= k - degree:
            new.append(points[i])
        elif i > k:
            new.append(points[i - 1])
        else:
            a = (u - knots[i]) / (knots[i + degree] - knots[i])
            new.append([(1 - a) * p + a * q for p, q in zip(points[i - 1], points[i])])
    return knots[: k + 1] + [u] + knots[k + 1:], new


def cubic_uniform(bezier, spans):
    """A cubic Bézier refined to a clamped uniform cubic B-spline with `spans` spans."""
    knots, pts = [0.0] * 4 + [1.0] * 4, [list(p) for p in bezier]
    for s in range(1, spans):
        knots, pts = insert_knot(knots, pts, 3, s / spans)
    return pts


def arc(radius, t0, t1, z0, z1, spans=2):
    """Cubic approximation of the circular arc at `radius` from angle t0 to t1 (radians), with
    heights blended linearly from z0 to z1 (a circular helix piece; z0 = z1 for a planar arc)."""
    k = 4.0 / 3.0 * math.tan((t1 - t0) / 4.0) * radius
    p0 = [radius * math.cos(t0), radius * math.sin(t0)]
    p3 = [radius * math.cos(t1), radius * math.sin(t1)]
    p1 = [p0[0] - k * math.sin(t0), p0[1] + k * math.cos(t0)]
    p2 = [p3[0] + k * math.sin(t1), p3[1] - k * math.cos(t1)]
    bez = [[p0[0], p0[1], z0], [p1[0], p1[1], z0 + (z1 - z0) / 3], [p2[0], p2[1], z0 + 2 * (z1 - z0) / 3],
           [p3[0], p3[1], z1]]
    return cubic_uniform(bez, spans)


def segment(p, q, spans=2):
    """A straight cubic from p to q (control points evenly spaced)."""
    return cubic_uniform([[p[i] + (q[i] - p[i]) * s / 3 for i in range(3)] for s in range(4)], spans)


def r(x, digits=9):
    return [round(v, digits) + 0.0 for v in x]


def s_edge(v0, v1, points, crease=None):
    e = {"v": [v0, v1], "type": "S", "degree": 3, "points": [r(p) for p in points[1:-1]]}
    if crease:
        e["crease"] = crease
    return e


def r_edge(v0, v1, crease=None):
    e = {"v": [v0, v1], "type": "R"}
    if crease:
        e["crease"] = crease
    return e


def write(name, scene):
    with open(os.path.join(EXAMPLES, name), "w") as f:
        json.dump(with_summary(name, scene), f, indent=1)
        f.write("\n")


def solved(scene, iterations):
    """The scene after `iterations` guided-projection iterations of the devsurf binary."""
    with tempfile.TemporaryDirectory() as tmp:
        src, out = os.path.join(tmp, "in.json"), os.path.join(tmp, "out.json")
        with open(src, "w") as f:
            json.dump(scene, f)
        subprocess.run([DEVSURF, "solve", src, "--iterations", str(iterations), "--out", out], check=True,
                       capture_output=True)
        with open(out) as f:
            result = json.load(f)["scene"]
    for key in ("name", "description", "format", "version"):
        if key in scene:
            result[key] = scene[key]
    return result


def circle(radius, n=720):
    return [r([radius * math.cos(2 * math.pi * i / n), radius * math.sin(2 * math.pi * i / n)]) for i in range(n)]


def annulus():
    """Tang et al. 2016 Fig. 1 and 12: an annulus folded along concentric creases. Starts from the
    rotationally symmetric pleat of cone frusta (each crease an exact planar fold by reflection,
    eq. 7 at round-off) whose development misses a sector; solving with the development held to
    the full annulus (boundary on both circles, §5) closes the gap: the creases leave their
    circles a little and the folds relax."""
    radii = [1.0, 1.5, 2.0, 2.5, 3.0]
    pleat = 0.15                     # circles 1 and 3 raised: alternating mountain and valley
    sectors, J = 8, len(radii)
    vid = lambda j, k: j * sectors + (k % sectors)
    height = lambda j: pleat if j % 2 == 1 else 0.0
    vertices = []
    for j in range(J):
        for k in range(sectors):
            t = 2 * math.pi * k / sectors
            vertices.append(r([radii[j] * math.cos(t), radii[j] * math.sin(t), height(j)]))
    edges, arc_id, radial_id = [], {}, {}
    for j in range(J):
        for k in range(sectors):
            t0, t1 = 2 * math.pi * k / sectors, 2 * math.pi * (k + 1) / sectors
            arc_id[j, k] = len(edges)
            crease = "fold" if 0 < j < J - 1 else None
            edges.append(s_edge(vid(j, k), vid(j, k + 1), arc(radii[j], t0, t1, height(j), height(j)), crease))
    for j in range(J - 1):
        for k in range(sectors):
            radial_id[j, k] = len(edges)
            edges.append(r_edge(vid(j, k), vid(j + 1, k), "smooth"))
    faces = []
    for j in range(J - 1):
        for k in range(sectors):
            faces.append([radial_id[j, k], arc_id[j + 1, k], radial_id[j, (k + 1) % sectors], arc_id[j, k]])
    scene = {
        "format": "devsurf-scene", "version": 1,
        "name": "folded annulus, concentric creases",
        "description": "An annulus (radii 1 to 3) folded along three concentric creases, after Tang et al. 2016 "
                       "Fig. 1 and 12: 8 sectors x 4 rings of developable strips, joined smoothly along the radial "
                       "rulings and by curved folds (eq. 7) along the creases. It was solved from a pleat of cone "
                       "frusta, whose development misses a sector, with the development held isometric to the full "
                       "flat annulus (inner and outer boundary on their circles, §5): the creases leave their "
                       "circles slightly to close the gap, as the paper recommends (exact circles do not fold, "
                       "Demaine et al.). Iterating on lets the folds relax further towards flat.",
        "model": {"kind": "composite", "vertices": vertices, "edges": edges, "faces": faces,
                  "development": {"samples": 4, "domain": {"boundary": [
                      {"points": circle(radii[0]), "closed": True},
                      {"points": circle(radii[-1]), "closed": True}]}}},
        "solver": {"iterations": 10, "regularization": 0.1}}
    scene = solved(scene, 150)
    scene["solver"] = {"iterations": 10, "regularization": 0.1}
    write("composite-folded-annulus.json", scene)


def dragged(scene, stages, iterations):
    """Moves every handle from its point's position to its target in `stages` equal steps, solving
    `iterations` guided-projection iterations after each (as a drag in a session does), and
    returns the solved scene of the last step (geometry and development)."""
    model = scene["model"]

    def position(h):
        if "vertex" in h:
            return model["vertices"][h["vertex"]]
        return model["edges"][h["edge"]]["points"][h["index"] - 1]

    origin = [list(position(h)) for h in model["handles"]]
    targets = [list(h["position"]) for h in model["handles"]]
    for step in range(1, stages + 1):
        for h, o, t in zip(scene["model"]["handles"], origin, targets):
            h["position"] = [o[i] + (t[i] - o[i]) * step / stages for i in range(3)]
        scene = solved(scene, iterations)
    for h, t in zip(scene["model"]["handles"], targets):
        h["position"] = r(t)
    return scene


def column():
    """Tang et al. 2016 Fig. 14 (after Huffman's hexagonal column): a hexagonal tube whose six
    vertical creases are curved folds. Dragged from the straight prism: the middle of every other
    crease out, of the others in; the development is cut open along crease 0 and kept periodic,
    so the column unfolds onto a cylinder."""
    k, R, H, spans = 6, 1.0, 3.0, 4
    vertices, edges, faces = [], [], []
    for level in (0.0, H):
        for i in range(k):
            t = 2 * math.pi * i / k
            vertices.append(r([R * math.cos(t), R * math.sin(t), level]))
    crease_id, bottom_id, top_id = [], [], []
    for i in range(k):
        crease_id.append(len(edges))
        edges.append(s_edge(i, k + i, segment(vertices[i], vertices[k + i], spans=spans), "fold"))
    for i in range(k):
        bottom_id.append(len(edges))
        edges.append(r_edge(i, (i + 1) % k))
    for i in range(k):
        top_id.append(len(edges))
        edges.append(r_edge(k + (i + 1) % k, k + i))
    for i in range(k):
        faces.append([bottom_id[i], crease_id[(i + 1) % k], top_id[i], crease_id[i]])
    handles = []
    for i in range(k):
        t = 2 * math.pi * i / k
        rad = R + 0.2 if i % 2 == 0 else R - 0.15
        handles.append({"edge": crease_id[i], "index": (spans + 3) // 2, "weight": 0.2,
                        "position": r([rad * math.cos(t), rad * math.sin(t), H / 2])})
    scene = {
        "format": "devsurf-scene", "version": 1,
        "name": "curved-crease column on a cylinder",
        "description": "A hexagonal tube (radius 1, height 3) of six developable strips between six vertical "
                       "creases that are curved folds (eq. 7), after Huffman's hexagonal column as in Tang et al. "
                       "2016 Fig. 14. Shaped from the straight prism by dragging the middle of every other crease "
                       "out and of the others in (weak handles, 10 steps). The development is cut open along "
                       "crease 0 and kept periodic (§6): the column unfolds onto a cylinder whose circumference "
                       "is the period.",
        "model": {"kind": "composite", "vertices": vertices, "edges": edges, "faces": faces, "handles": handles,
                  "development": {"samples": 4, "seam": [crease_id[0]]}},
        "solver": {"iterations": 5}}
    scene = dragged(scene, 10, 5)
    scene["solver"] = {"iterations": 10}
    write("composite-column.json", scene)


def curved_box():
    """A box-like composite (after Mundilova 2017 Fig. 6.4-6.9): a tray whose long walls fold up
    along curved creases and whose end walls fold along straight ones; corners are cut."""
    L, W, H = 4.0, 2.0, 0.8  # bottom length, width, wall height
    bow = 0.25               # the long creases bow inwards by this much at the middle
    # bottom corners 0..3 (counterclockwise from (0,0)), wall tops 4..7 (long walls), 8..11 (end walls)
    v = [[0, 0, 0], [L, 0, 0], [L, W, 0], [0, W, 0],
         [0, -H, 0], [L, -H, 0], [L, W + H, 0], [0, W + H, 0],
         [L + H, 0, 0], [L + H, W, 0], [-H, W, 0], [-H, 0, 0]]
    vertices = [r(p) for p in v]

    def bowed(p, q, inward):
        bez = [p, [p[0] + (q[0] - p[0]) / 3, p[1] + inward * bow * 4 / 3, 0], [p[0] + 2 * (q[0] - p[0]) / 3, p[1] + inward * bow * 4 / 3, 0], q]
        return cubic_uniform(bez, 2)

    edges = []
    e_front = len(edges); edges.append(s_edge(0, 1, bowed(v[0], v[1], 1), "fold"))      # bottom/front wall
    e_back = len(edges); edges.append(s_edge(2, 3, bowed(v[2], v[3], -1), "fold"))      # bottom/back wall
    e_right = len(edges); edges.append(r_edge(1, 2))                                     # bottom/right wall (straight)
    e_left = len(edges); edges.append(r_edge(3, 0))                                      # bottom/left wall
    e_front_top = len(edges); edges.append(s_edge(4, 5, segment(v[4], v[5])))
    e_front_l = len(edges); edges.append(r_edge(0, 4))
    e_front_r = len(edges); edges.append(r_edge(5, 1))
    e_back_top = len(edges); edges.append(s_edge(6, 7, segment(v[6], v[7])))
    e_back_r = len(edges); edges.append(r_edge(2, 6))
    e_back_l = len(edges); edges.append(r_edge(7, 3))
    e_right_out = len(edges); edges.append(r_edge(8, 9))
    e_right_b = len(edges); edges.append(r_edge(1, 8))
    e_right_t = len(edges); edges.append(r_edge(9, 2))
    e_left_out = len(edges); edges.append(r_edge(10, 11))
    e_left_t = len(edges); edges.append(r_edge(3, 10))
    e_left_b = len(edges); edges.append(r_edge(11, 0))
    faces = [
        [e_front, e_right, e_back, e_left],                 # bottom: S R S R, counterclockwise from +z
        [e_front_top, e_front_r, e_front, e_front_l],       # front wall: 4->5->1->0->4
        [e_back_top, e_back_l, e_back, e_back_r],           # back wall: 6->7->3->2->6
        [e_right_b, e_right_out, e_right_t, e_right],       # right wall (planar): 1->8->9->2->1
        [e_left_t, e_left_out, e_left_b, e_left],           # left wall (planar): 3->10->11->0->3
    ]
    for e in (e_right, e_left):
        edges[e]["crease"] = None
        del edges[e]["crease"]
    fixed = [{"vertex": 0}, {"vertex": 1}]
    handles = [
        {"vertex": 4, "position": [0.3, 0.1, H * 0.9]}, {"vertex": 5, "position": [L - 0.3, 0.1, H * 0.9]},
        {"vertex": 6, "position": [L - 0.3, W - 0.1, H * 0.9]}, {"vertex": 7, "position": [0.3, W - 0.1, H * 0.9]},
    ]
    write("composite-curved-box.json", {
        "format": "devsurf-scene", "version": 1,
        "name": "curved box",
        "description": "A box-like composite after Mundilova 2017 Fig. 6.4-6.9, simplified to a tray: the bottom is "
                       "a developable strip between two curved creases (curved folds, eq. 7) that join it to the "
                       "long walls; the end walls are planar and fold along straight creases; the corners are cut. "
                       "Handles raise the long walls' top corners; the bottom bends as the walls fold up. Export "
                       "its fold pattern with --export svg:FILE or fold:FILE.",
        "model": {"kind": "composite", "vertices": vertices, "edges": edges, "faces": faces, "fixed": fixed,
                  "handles": handles, "development": {"samples": 4}},
        "solver": {"iterations": 40}})


def pleated_sheet():
    """A sheet of parallel curved creases (bench/composite_iteration's parallelCreaseSheet at a
    modest size), solved with normal splines (000_… §2.2, §7)."""
    strips, spans = 6, 12
    n = spans + 3
    vertices, edges = [], []
    for i in range(strips + 1):
        pts = [[0.6 * i + 0.12 * math.sin(2 * math.pi * k / (n - 1)), 3.0 * k / (n - 1), 0.0] for k in range(n)]
        vertices += [r(pts[0]), r(pts[-1])]
        edges.append(s_edge(2 * i, 2 * i + 1, pts, "fold" if 0 < i < strips else None))
    edges += [r_edge(2 * j, 2 * j + 2) for j in range(strips)]
    edges += [r_edge(2 * j + 3, 2 * j + 1) for j in range(strips)]
    faces = [[strips + 1 + j, j + 1, 2 * strips + 1 + j, j] for j in range(strips)]
    far0, far1 = 2 * strips, 2 * strips + 1
    handles = [{"vertex": far0, "position": r([vertices[far0][0] - 0.5, vertices[far0][1], 1.2])},
               {"vertex": far1, "position": r([vertices[far1][0] - 0.5, vertices[far1][1], 1.2])}]
    write("composite-pleated-sheet.json", {
        "format": "devsurf-scene", "version": 1,
        "name": "sheet of parallel curved creases",
        "description": "Seven wavy curves across a 3.6 x 3 sheet, the five inside ones curved folds: six strips side "
                       "by side. The left edge is held and handles lift the right edge, so every crease folds a "
                       "little. Each strip's normals are a cubic normal spline (solver setting normal_splines; "
                       "Tang et al. 2016 section 7): half the unknowns of free normals here, a fifth of the normals "
                       "alone.",
        "model": {"kind": "composite", "vertices": vertices, "edges": edges, "faces": faces,
                  "fixed": [{"vertex": 0}, {"vertex": 1}, {"edge": 0, "index": n // 2}],
                  "handles": handles, "development": {"samples": 4}},
        "solver": {"iterations": 40, "normal_splines": True}})


PRESETS = {"annulus": annulus, "column": column, "curved-box": curved_box, "pleated-sheet": pleated_sheet}

if __name__ == "__main__":
    import sys
    # Names (annulus, column, curved-box, pleated-sheet) write only those; none writes all.
    for name in sys.argv[1:] or list(PRESETS):
        PRESETS[name]()
