#!/usr/bin/env python3
"""Writes the quad-mesh presets examples/quad-*.json (issue 13; Jiang et al. 2020).

Each file is a devsurf scene of model kind "quad_mesh" (format in notes/issue13.md): M (3D), the
unfolding M′ (planar, or omitted when the model computes it), faces (quads, triangles with 3
indices) counter-clockwise in M′, glue pairs, handles, weights (Fig. 22 of the paper) and the
Algorithm 1 schedule. Plain Python (no numpy), deterministic: running it twice writes the same
bytes. Sizes are kept at a few hundred to ~1500 vertices so the presets load and solve fast; the
paper's examples (Fig. 22) are larger.

usage: scripts/make_quad_presets.py [--out examples]
"""
import argparse
import math
import os

from preset_summaries import with_summary

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# --- JSON with one point per line ------------------------------------------------------------

def _number(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if v == 0.0:
        return "0"
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return repr(v)


def _flat(v):
    return isinstance(v, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)


def dump(value, indent=0):
    pad = "  " * indent
    inner = "  " * (indent + 1)
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = ['%s"%s": %s' % (inner, k, dump(v, indent + 1)) for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list):
        if not value:
            return "[]"
        if _flat(value):
            return "[" + ", ".join(_number(x) for x in value) + "]"
        return "[\n" + ",\n".join(inner + dump(v, indent + 1) for v in value) + "\n" + pad + "]"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if value is None:
        return "null"
    return _number(value)


# --- scene -----------------------------------------------------------------------------------

# isometry 10 (Algorithm 1 has w_iso = 1; our energies are unscaled, in cm², and against the
# constant E_map and the fairness 10 measured better on every preset but the non-convex D-form:
# bent sheet L-Err 0.018 % → 0.0021 %, cut and glue 0.20 % → 0.0038 %, cones 0.0011 % → 0.0001 %,
# convex D-form 0.035 % → 0.021 %; non-convex D-form 0.067 % → 0.076 %);
# position 10: glue pairs and handles well above the regularizers; mapping (E_map) 10 where it
# measured best (bent sheet L-Err 0.065 % → 0.018 %, curved fold 0.09 % → 0.043 %).
WEIGHTS = {"isometry": 10, "conformality": 1, "conformal_factor": 0.1, "position": 10,
           "fairness_mesh": 0.1, "fairness_unfolding": 0.1, "proximity_point": 0,
           "proximity_plane": 0, "mapping": 1, "normals": 1, "symmetry": 1}
SCHEDULE = {"energy_min": 1e-12, "isometry_min": 1e-12, "round_iterations": 20, "rounds": 10,
            "fairness_divisor": 10}
ITERATIONS = 200  # the scene's solver.iterations: all rounds of Algorithm 1 together


def scene(name, description, faces, mesh, variables, unfolding=None, units=None, conformal=False,
          handles=(), fixed=(), glue=(), reference=None, weights=None, schedule=None):
    """fixed: vertices of M (integers) or {"vertex", "on"} objects for M′; glue: pairs [i, j] of M;
    reference: {"vertices", "faces"} (triangles). M′ is planar: "planar" is written only when false."""
    model = {"kind": "quad_mesh", "mesh": {"vertices": mesh, "faces": faces}}
    if unfolding is not None:
        model["unfolding"] = {"vertices": unfolding}
    model["variables"] = variables
    model["conformal"] = conformal
    model["gauss_image"] = False
    model["handles"] = list(handles)
    model["fixed"] = list(fixed)
    model["glue"] = list(glue)
    if reference is not None:
        model["reference"] = reference
    model["weights"] = dict(WEIGHTS, **(weights or {}))
    model["schedule"] = dict(SCHEDULE, **(schedule or {}))
    doc = {"format": "devsurf-scene", "version": 1, "name": name, "description": description}
    if units:
        doc["units"] = units
    doc["model"] = model
    doc["solver"] = {"iterations": ITERATIONS}
    return doc


def handle(vertex, position, on="mesh", weight=1):
    h = {"vertex": vertex, "position": list(position), "weight": weight}
    if on != "mesh":
        h["on"] = on
    return h


# --- meshes ----------------------------------------------------------------------------------

def grid(nx, ny, width, height, x0=0.0, y0=0.0):
    """(nx+1)(ny+1) points of a width × height rectangle, row by row; quads counter-clockwise."""
    pts = [[x0 + width * i / nx, y0 + height * j / ny] for j in range(ny + 1) for i in range(nx + 1)]

    def idx(i, j):
        return j * (nx + 1) + i
    faces = [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]
             for j in range(ny) for i in range(nx)]
    return pts, faces, idx


def polar_sector(sectors, total, rings, radius, first=0):
    """A polar grid of `sectors` of the `total` sectors of a full disc (spokes 0 … sectors), with
    `rings` rings: the apex first, triangles round it, quads outside. Returns points (2D, in the
    disc's own frame), faces, and id(ring, spoke) (ring 0 is the apex)."""
    pts = [[0.0, 0.0]]
    ids = {}
    for r in range(1, rings + 1):
        for k in range(sectors + 1):
            t = 2 * math.pi * k / total
            ids[(r, k)] = first + len(pts)
            pts.append([radius * r / rings * math.cos(t), radius * r / rings * math.sin(t)])

    def idx(r, k):
        return first if r == 0 else ids[(r, k)]
    faces = [[idx(0, 0), idx(1, k), idx(1, k + 1)] for k in range(sectors)]
    for r in range(1, rings):
        for k in range(sectors):
            faces.append([idx(r, k), idx(r + 1, k), idx(r + 1, k + 1), idx(r, k + 1)])
    return pts, faces, idx


def coons_rect(boundary, n1, n2, start=0):
    """Transfinite (Coons) quad grid of a closed boundary of 2(n1 + n2) points (counter-clockwise)
    split into four sides from point `start`: bottom n1 edges, right n2, top n1, left n2.
    Returns the (n1 + 1)(n2 + 1) grid points row by row (boundary points exactly as given), the
    faces and the grid index of boundary point k. The grid's corners sit on a smooth boundary:
    their quads have an angle near 180°, which the checkerboard (diagonals only) leaves free to
    fold, so each is split into two triangles through the corner, held by all their edges."""
    m = 2 * (n1 + n2)
    b = lambda k: boundary[(start + k) % m]
    bottom = [b(k) for k in range(0, n1 + 1)]
    right = [b(k) for k in range(n1, n1 + n2 + 1)]
    top = [b(2 * n1 + n2 - i) for i in range(0, n1 + 1)]
    left = [b(m - j) for j in range(0, n2 + 1)]
    c00, c10, c11, c01 = bottom[0], bottom[n1], top[n1], top[0]
    pts = []
    for j in range(n2 + 1):
        v = j / n2
        for i in range(n1 + 1):
            u = i / n1
            if j == 0:
                p = bottom[i]
            elif j == n2:
                p = top[i]
            elif i == 0:
                p = left[j]
            elif i == n1:
                p = right[j]
            else:
                p = [(1 - v) * bottom[i][d] + v * top[i][d] + (1 - u) * left[j][d] + u * right[j][d]
                     - ((1 - u) * (1 - v) * c00[d] + u * (1 - v) * c10[d] + u * v * c11[d]
                        + (1 - u) * v * c01[d]) for d in range(len(c00))]
            pts.append(list(p))

    def idx(i, j):
        return j * (n1 + 1) + i
    corners = {idx(0, 0), idx(n1, 0), idx(n1, n2), idx(0, n2)}
    faces = []
    for j in range(n2):
        for i in range(n1):
            f = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]
            c = [k for k in range(4) if f[k] in corners]
            if c:
                k = c[0]
                faces.append([f[k], f[(k + 1) % 4], f[(k + 2) % 4]])
                faces.append([f[k], f[(k + 2) % 4], f[(k + 3) % 4]])
            else:
                faces.append(f)
    grid_of = {}
    for k in range(m):
        q = (k - start) % m
        if q <= n1:
            grid_of[k] = idx(q, 0)
        elif q <= n1 + n2:
            grid_of[k] = idx(n1, q - n1)
        elif q <= 2 * n1 + n2:
            grid_of[k] = idx(2 * n1 + n2 - q, n2)
        else:
            grid_of[k] = idx(0, m - q)
    return pts, faces, grid_of


def coons_disc(boundary, n):
    """coons_rect of a boundary of 4n points with four sides of n edges from point 0."""
    return coons_rect(boundary, n, n, 0)


def equal_chords(curve, count, t0=0.0):
    """`count` points on a closed curve γ(t), t ∈ [t0, t0 + 2π), counter-clockwise, with all
    `count` chords (the closing one too) of one length c: an equilateral inscribed polygon, the
    discrete arc-length sampling. Returns (points, c)."""
    def dist(s, t):
        p, q = curve(s), curve(t)
        return math.hypot(p[0] - q[0], p[1] - q[1])

    def next_t(s, c):
        lo, hi = s, s + 2 * math.pi / count
        while dist(s, hi) < c:
            lo, hi = hi, hi + 2 * math.pi / count
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if dist(s, mid) < c:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    def walk(c):
        ts = [t0]
        for _ in range(count):
            ts.append(next_t(ts[-1], c))
        return ts

    perimeter = sum(dist(t0 + 2 * math.pi * k / 4096, t0 + 2 * math.pi * (k + 1) / 4096) for k in range(4096))
    lo, hi = 0.5 * perimeter / count, perimeter / count
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if walk(mid)[-1] < t0 + 2 * math.pi:
            lo = mid
        else:
            hi = mid
    c = 0.5 * (lo + hi)
    ts = walk(c)[:count]
    return [list(curve(t)) for t in ts], c


def signed_area(pts, face):
    f = [v for v in face]
    return 0.5 * sum(pts[f[k]][0] * pts[f[(k + 1) % len(f)]][1] - pts[f[(k + 1) % len(f)]][0] * pts[f[k]][1]
                     for k in range(len(f)))


def triangulate(faces):
    tris = []
    for f in faces:
        tris.append([f[0], f[1], f[2]])
        if len(f) == 4:
            tris.append([f[0], f[2], f[3]])
    return tris


# --- presets ---------------------------------------------------------------------------------

def bend_sheet():
    nx, ny, w, h = 24, 16, 24.0, 16.0
    pts, faces, idx = grid(nx, ny, w, h)
    # M: M′ with a tiny cylindrical bend (sag 0.2 cm), so that the first solve is not degenerate.
    mesh = [[x, y, 0.2 * (1 - ((x - w / 2) / (w / 2)) ** 2)] for x, y in pts]
    handles = [handle(idx(0, 0), [4.0, 0.0, 6.0]), handle(idx(0, ny), [4.0, h, 6.0]),
               handle(idx(nx, 0), [w - 4.0, 0.0, 6.0]), handle(idx(nx, ny), [w - 4.0, h, 6.0])]
    return scene(
        "quad: isometric bending of a flat sheet",
        "Handle-based isometric bending of a given flat unfolding (Jiang et al. 2020, Fig. 7 and "
        "Fig. 26): M′ is a flat 24 × 16 cm sheet of 24 × 16 quads, held fixed; M starts as M′ "
        "with a 2 mm sag and is the variable. The four corners are handles pulled 4 cm towards "
        "each other across the sheet and 6 cm up, so the sheet rolls into a developable arch. "
        "Weights: isometry 10, handles 10, E_map 10, fairness 0.1 lowered by Algorithm 1 (Fig. 22 "
        "row 7 has isometry 1 and position 1; ours measured better in our units of cm²). "
        "Drag the handles to bend it further; export the SVG to cut it out of paper. Fig. 7 has "
        "1.9k vertices (here 425).",
        faces, mesh, "mesh", unfolding=pts, units="cm", handles=handles,
        weights={"fairness_mesh": 0.1, "fairness_unfolding": 0, "mapping": 10})


def developable_approx():
    n = 20
    pts, faces, idx = grid(n, n, 2.0, 2.0, -1.0, -1.0)
    mesh = [[x, y, 0.35 * (x * x - y * y) + 0.15 * x * y * y] for x, y in pts]
    return scene(
        "quad: make a doubly curved patch developable",
        "Approximation with a developable (Jiang et al. 2020, Fig. 8 and Sec. 5): M is a doubly "
        "curved patch of 20 × 20 quads over 2 × 2 units (the saddle z = 0.35(x² − y²) + "
        "0.15xy², Gauss curvature negative throughout). Both M and its unfolding M′ are "
        "variable; M′ is not given — the model flattens M (least squares conformal map) to start "
        "it. Proximity to the original surface Φ (the reference: M triangulated) with weights "
        "0.001 / 0.001 as Fig. 22 row 10 keeps M near its design while isometry to a flat M′ "
        "makes it developable; watch K go to zero and the rulings appear. Fig. 8 has up to 50k "
        "vertices (here 441).",
        faces, mesh, "both", reference={"vertices": mesh, "faces": triangulate(faces)},
        weights={"proximity_point": 0.001, "proximity_plane": 0.001, "fairness_mesh": 0.1,
                 "fairness_unfolding": 0.1})


def cut_glue():
    nx, ny, w, h = 24, 16, 24.0, 16.0
    hx0, hx1, hy0, hy1 = 8, 16, 6, 10  # the hole: quads [8, 16) × [6, 10), glued shut
    full, _, full_idx = grid(nx, ny, w, h)
    keep = [(i, j) for j in range(ny) for i in range(nx) if not (hx0 <= i < hx1 and hy0 <= j < hy1)]
    used = sorted({full_idx(i + di, j + dj) for i, j in keep for di in (0, 1) for dj in (0, 1)})
    new = {old: k for k, old in enumerate(used)}
    pts = [full[old] for old in used]
    vid = lambda i, j: new[full_idx(i, j)]
    faces = [[vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)] for i, j in keep]
    # Glue the hole's boundary folded in half along its middle row: bottom to top, and each side
    # to itself mirrored; the side midpoints (0, 8) … are the ends of the seam.
    ym = (hy0 + hy1) // 2
    glue = [[vid(i, hy0), vid(i, hy1)] for i in range(hx0, hx1 + 1)]
    glue += [[vid(i, j), vid(i, hy0 + hy1 - j)] for i in (hx0, hx1) for j in range(hy0 + 1, ym)]
    # M starts with the hole closed: columns over the hole pulled together towards the middle
    # row (falling off linearly 4 cm beyond the hole's ends), the sheet arched up a little.
    half = (hy1 - hy0) / 2.0

    def phi(x):
        if hx0 <= x <= hx1:
            return 1.0
        d = hx0 - x if x < hx0 else x - hx1
        return max(0.0, 1.0 - d / 4.0)
    mesh = []
    for x, y in pts:
        s = y - ym
        if abs(s) <= half:
            dy = -s
        else:
            far = (h - ym) if s > 0 else ym
            dy = -math.copysign(half * (far - abs(s)) / (far - half), s)
        mesh.append([x, y + phi(x) * dy, 1.5 * phi(x) * math.cos(math.pi * s / h)])
    return scene(
        "quad: cut and glue — a hole glued shut",
        "Cutting and gluing (Jiang et al. 2020, Fig. 16 and Fig. 18): a 24 × 16 cm sheet with an "
        "8 × 4 cm rectangular hole in the middle. The glue pairs close the hole by folding its "
        "boundary in half along the hole's middle row (bottom edge onto top edge, each side onto "
        "itself), an arc-length preserving correspondence, so the glued shape is developable "
        "away from the seam's two ends. M′ (the sheet with the hole) is fixed; M starts with the "
        "hole pulled shut and the sheet arched, and the solve makes it isometric with the glued "
        "vertices coinciding. Export the SVG: the hole's edges are numbered glue edges; cut, "
        "glue, and compare with the solved shape. Fig. 18 has 8.4k vertices (here 404).",
        faces, mesh, "mesh", unfolding=pts, units="cm", glue=glue,
        weights={"fairness_mesh": 0.1, "fairness_unfolding": 0, "mapping": 10})


def cut_glue_diagonal():
    nx, ny, w, h = 24, 16, 24.0, 16.0
    cx, cy, a = 12, 8, 4  # the hole: the diamond |x − 12| + |y − 8| < 4, edges on quad diagonals
    full, _, full_idx = grid(nx, ny, w, h)
    level = lambda i, j: abs(i - cx) + abs(j - cy)
    kept = []
    for j in range(ny):
        for i in range(nx):
            quad = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            low = min(level(*c) for c in quad)
            if low >= a:
                kept.append(quad)  # outside the hole
            elif low == a - 1:
                # Cut along the diagonal through the two corners on the diamond: keep the
                # triangle outside (the corner inside the hole drops, the order stays ccw).
                kept.append([c for c in quad if level(*c) != a - 1])
    used = sorted({full_idx(*c) for f in kept for c in f})
    new = {old: k for k, old in enumerate(used)}
    pts = [full[old] for old in used]
    vid = lambda i, j: new[full_idx(i, j)]
    faces = [[vid(*c) for c in f] for f in kept]
    # Glue the diamond shut by folding it in half along its horizontal diagonal: the upper V onto
    # the lower V, (cx + d, cy + e) with (cx + d, cy − e); the left and right tips end the seam.
    glue = [[vid(cx + d, cy + a - abs(d)), vid(cx + d, cy - a + abs(d))] for d in range(-a + 1, a)]

    def phi(x):
        return max(0.0, min(1.0, 1.0 - (abs(x - cx) - a) / 4.0))
    mesh = []
    for x, y in pts:
        s = y - cy
        half = max(0.0, a - abs(x - cx))  # the hole's half-height over x
        far = (h - cy) if s > 0 else cy
        dy = -math.copysign(half * (far - abs(s)) / (far - half), s) if half > 0 else 0.0
        mesh.append([x, y + dy, 1.5 * phi(x) * math.cos(math.pi * s / h)])
    return scene(
        "quad: cut and glue along diagonals — a diamond hole glued shut",
        "Cutting and gluing along diagonals (Jiang et al. 2020, Fig. 16: features may follow the "
        "diagonals of the quad mesh): a 24 × 16 cm sheet of 1 cm quads with a diamond-shaped "
        "hole |x − 12| + |y − 8| < 4 cm whose edges run along quad diagonals; the quads the cut "
        "crosses keep their outer triangle. The glue pairs fold the diamond in half along its "
        "horizontal diagonal (upper V onto lower V, an arc-length preserving correspondence), so "
        "the seam is a straight line with a cone point at each tip and one where the top and "
        "bottom corners meet. M′ (the sheet with the hole) is fixed; M starts with the hole "
        "pulled shut and the sheet arched, and the solve makes it isometric with the glued "
        "vertices coinciding. Export the SVG: the diamond's edges are numbered glue edges.",
        faces, mesh, "mesh", unfolding=pts, units="cm", glue=glue,
        weights={"fairness_mesh": 0.1, "fairness_unfolding": 0, "mapping": 10})


def cone_deficit():
    total, removed, rings, radius = 24, 6, 8, 8.0
    sectors = total - removed
    pts, faces, idx = polar_sector(sectors, total, rings, radius)
    glue = [[idx(r, 0), idx(r, sectors)] for r in range(1, rings + 1)]
    # M: the exact smooth cone of angle sum α = 270°: polar (ρ, θ) → radius ρα/2π, angle 2πθ/α.
    alpha = 2 * math.pi * sectors / total
    k = alpha / (2 * math.pi)
    mesh = []
    for x, y in pts:
        rho, theta = math.hypot(x, y), math.atan2(y, x) % (2 * math.pi)
        if rho > 0 and abs(theta - alpha) < 1e-9:
            theta = alpha
        phi = theta / k
        mesh.append([rho * k * math.cos(phi), rho * k * math.sin(phi), rho * math.sqrt(1 - k * k)])
    return scene(
        "quad: cone point, angle sum below 2π",
        "A cone point with angle sum 270° < 360° (Jiang et al. 2020, Fig. 17): a disc of radius "
        "8 cm (polar grid, 24 sectors × 8 rings, triangles round the centre) with a 90° wedge "
        "cut out; the wedge's two sides are glued. M′ is fixed; M starts as the smooth cone the "
        "gluing makes (a cone of half-angle asin(3/4)). Developable everywhere except at the "
        "apex, where the Gauss curvature 2π − 270° = 90° is concentrated. Export the SVG and "
        "glue seam 1 to get a paper cone; drag the rim to see the cone point stay.",
        faces, mesh, "mesh", unfolding=pts, units="cm", glue=glue,
        weights={"fairness_mesh": 0.1, "fairness_unfolding": 0})


def ruffle_height(alpha, waves):
    """h such that the curve normalize(cos φ, sin φ, h sin(waves·φ)), φ ∈ [0, 2π), has length α."""
    def length(h):
        steps, total, prev = 4096, 0.0, None
        for s in range(steps + 1):
            f = 2 * math.pi * s / steps
            p = (math.cos(f), math.sin(f), h * math.sin(waves * f))
            n = math.sqrt(sum(c * c for c in p))
            p = tuple(c / n for c in p)
            if prev is not None:
                total += math.sqrt(sum((a - b) ** 2 for a, b in zip(p, prev)))
            prev = p
        return total
    lo, hi = 0.0, 10.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if length(mid) < alpha:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def cone_excess():
    total, rings, radius = 24, 8, 8.0
    sa, sb = 18, 12  # 270° and 180° sectors: angle sum 450° round the cone point
    a_pts, a_faces, a_idx = polar_sector(sa, total, rings, radius)
    b_local, b_faces, b_idx = polar_sector(sb, total, rings, radius, first=len(a_pts))
    # Lay B apart, to the right of A.
    dx = 2 * radius + 3.0
    b_pts = [[x + dx, y] for x, y in b_local]
    pts = a_pts + b_pts
    faces = a_faces + b_faces
    # Round the cone point: A's sectors (0 … 270°), then B's (270° … 450°).
    glue = [[a_idx(0, 0), b_idx(0, 0)]]
    glue += [[a_idx(r, sa), b_idx(r, 0)] for r in range(1, rings + 1)]
    glue += [[b_idx(r, sb), a_idx(r, 0)] for r in range(1, rings + 1)]
    # M: the radial lines kept straight and of their length, the rings ruffled into two waves
    # so that the ring through the unit sphere has length 450° (a saddle-like cone point).
    alpha = 2 * math.pi * (sa + sb) / total
    h = ruffle_height(alpha, 2)
    mesh = []
    for piece, local, offset in (("a", a_pts, 0.0), ("b", b_local, 2 * math.pi * sa / total)):
        for x, y in local:
            rho, theta = math.hypot(x, y), math.atan2(y, x) % (2 * math.pi)
            if rho > 0 and theta > 2 * math.pi - 1e-9:
                theta = 0.0
            if rho > 0 and piece == "b" and abs(theta - 2 * math.pi * sb / total) < 1e-9:
                theta = 2 * math.pi * sb / total
            phi = (offset + theta) * 2 * math.pi / alpha
            d = (math.cos(phi), math.sin(phi), h * math.sin(2 * phi))
            n = math.sqrt(sum(c * c for c in d))
            mesh.append([rho * c / n for c in d])
    return scene(
        "quad: cone point, angle sum above 2π",
        "A cone point with angle sum 450° > 360° (Jiang et al. 2020, Fig. 17): two flat pieces "
        "of radius 8 cm, a 270° sector (left in M′) and a 180° sector (laid apart to the right), "
        "glued along two seams so that 270° + 180° meet round the glued apex. The negative "
        "Gauss curvature 360° − 450° = −90° is concentrated in that point; elsewhere the surface "
        "is developable and ruffles like a saddle. M′ is fixed; M starts with straight radial "
        "lines and rings waved twice round the apex to the right length. Export the SVG and glue "
        "seams 1 and 2 to build it.",
        faces, mesh, "mesh", unfolding=pts, units="cm", glue=glue,
        weights={"fairness_mesh": 0.1, "fairness_unfolding": 0})


def dform(name, curve_a, curve_b, t0, description, n=12):
    """Two square Coons-gridded domains of equal perimeter (4n boundary points each, both sampled
    from parameter t0), glued along their boundaries: dform_aligned with n × n cells from point 0."""
    assert n % 2 == 0, "the grids start at boundary point 0: n even"
    return dform_aligned(name, curve_a, curve_b, t0, t0, description, 4 * n, n, n, n // 2, n // 2)


def dform_aligned(name, curve_a, curve_b, ta, tb, description, m, a_cols, b_cols, a_centre, b_centre):
    """Two domains of equal perimeter glued point k of A to point −k of B, each a rectangular
    Coons grid (coons_rect) whose bottom and top sides (a_cols / b_cols edges) are centred on
    boundary points a_centre / b_centre, so that its columns run along the D-form's rulings
    (which cross each piece from side to side) and its cells are thin across them. Measured on
    the convex D-form (same weights, 2062 against 2178 vertices): L-Err .0022 % / A-Err .0021 %
    against the square Coons grids' .012 % / .042 %, whose grid lines cross the rulings."""
    a_boundary, c = equal_chords(curve_a, m, ta)
    b_unit, cb = equal_chords(curve_b, m, tb)
    b_boundary = [[p[0] * c / cb, p[1] * c / cb] for p in b_unit]  # same chord: same perimeter
    a_rows, b_rows = m // 2 - a_cols, m // 2 - b_cols
    a_start, b_start = (a_centre - a_cols // 2) % m, (b_centre - b_cols // 2) % m
    a_pts, a_faces, a_of = coons_rect(a_boundary, a_cols, a_rows, a_start)
    b_local, b_faces, b_of = coons_rect(b_boundary, b_cols, b_rows, b_start)
    width = lambda pts: max(p[0] for p in pts) - min(p[0] for p in pts)
    dx = max(p[0] for p in a_pts) - min(p[0] for p in b_local) + 0.15 * width(a_pts)
    b_pts = [[x + dx, y] for x, y in b_local]
    first_b = len(a_pts)
    pts = a_pts + b_pts
    faces = a_faces + [[v + first_b for v in f] for f in b_faces]
    partner = lambda k: (-k) % m  # A faces up, B is turned over: its boundary runs the other way
    glue = [[a_of[k], first_b + b_of[partner(k)]] for k in range(m)]
    # M: the common boundary halfway between A's boundary and B's mirrored (x, −y), the two
    # Coons sheets over it bulged apart (A up, B down) by 15% of the size.
    common = [[0.5 * (a_boundary[k][0] + b_boundary[partner(k)][0]),
               0.5 * (a_boundary[k][1] - b_boundary[partner(k)][1]), 0.0] for k in range(m)]
    lift = 0.15 * width(a_pts)
    mesh = []
    for sign, boundary_of, cols, rows, first in ((1.0, lambda k: common[k], a_cols, a_rows, a_start),
                                                 (-1.0, lambda k: common[partner(k)], b_cols, b_rows, b_start)):
        sheet, _, _ = coons_rect([boundary_of(k) for k in range(m)], cols, rows, first)
        for j in range(rows + 1):
            for i in range(cols + 1):
                p = sheet[j * (cols + 1) + i]
                bump = math.sin(math.pi * i / cols) * math.sin(math.pi * j / rows)
                mesh.append([p[0], p[1], sign * lift * bump])
    for f, face in enumerate(faces):
        assert signed_area(pts, face) > 0, "%s: face %d is not counter-clockwise" % (name, f)
    return scene(name, description, faces, mesh, "mesh", unfolding=pts, units="cm", glue=glue,
                 weights={"fairness_mesh": 0.1, "fairness_unfolding": 0})


def make_dforms():
    r = 5.0
    n = 24
    circle = lambda t: (r * math.cos(t), r * math.sin(t))
    ellipse = lambda t: (1.6 * r * math.cos(t), 0.75 * r * math.sin(t))
    peanut = lambda t: ((1 + 0.35 * math.cos(2 * t)) * r * math.cos(t),
                        (1 + 0.35 * math.cos(2 * t)) * r * math.sin(t))
    # The circle sampled from (−r, 0), the ellipse from the end of its minor axis (a polygon
    # symmetric about both axes); the grids' bottom sides centred on the circle's lowest point
    # (point m/4) and the ellipse's (point 0). The gluing differs from sampling both from one
    # parameter by a turn of the circle only: the same D-form.
    m = 160
    convex = dform_aligned(
        "quad: D-form of a circle and an ellipse", circle, ellipse, math.pi, -math.pi / 2,
        "A D-form (Jiang et al. 2020, Fig. 19a): two convex planar domains of equal perimeter — "
        "a circle of radius 5 cm and an ellipse (axes 1.6 : 0.75, scaled to the circle's "
        "perimeter) — glued along their whole boundaries, each sampled at 160 points of equal "
        "chord length (an equilateral polygon, the discrete arc-length correspondence). Each "
        "domain is a rectangular Coons-patch quad grid (circle 60 × 20, ellipse 70 × 10 cells; "
        "the corner quads split into triangles) whose columns run along the D-form's rulings, "
        "its cells thin across them: grid lines crossing the rulings cost accuracy (square "
        "grids: L-Err .012 %). The pieces lie side by side in M′, which is fixed. M starts as "
        "the two sheets bulged apart (circle up, ellipse down) over a common boundary. Since "
        "κ + κ′ ≥ 0 everywhere the glued surface is a unique convex D-form (Bobenko and "
        "Izmestiev); export the SVG (one seam, numbered 1 on both pieces) to build it. Fig. 19a "
        "has 2.5k vertices (here 2062).",
        m, 60, 70, m // 4, 0)
    nonconvex = dform(
        "quad: non-convex D-form (peanut and circle)", peanut, circle, -math.pi / 4,
        "A generalized, non-convex D-form (Jiang et al. 2020, Fig. 19b): a peanut-shaped domain "
        "r = 5(1 + 0.35 cos 2t) cm, concave at its waist (κ ≈ −1.8 / 5 cm), glued along its "
        "whole boundary to a circle of equal perimeter (κ′ ≈ 1 / 5.5 cm), so κ + κ′ < 0 at the "
        "waist and no convex surface exists: creases and singularities emerge there. Glue and "
        "start as in quad-dform-convex; each piece a square Coons grid of 24 × 24 cells (96 "
        "boundary points of equal chord length; finer, its creases cost accuracy: L-Err 0.089 % "
        "at 32 × 32), M′ fixed, pieces side by side, M bulged apart. Fig. 19b has 11k "
        "vertices (here 1250).", n=n)
    return convex, nonconvex


def curved_fold(i0=1, i1=23, fixed_frame=True):
    nx, ny, w, h = 24, 16, 24.0, 16.0
    crease_row = 8  # the zero-width hole: row 8 between vertices i0 and i1
    bend = lambda x: 2.0 * math.sin(math.pi * x / w)  # rows of the grid curve by this much
    base, _, idx = grid(nx, ny, w, h)
    pts = [[x, y + bend(x) * math.sin(math.pi * y / h)] for x, y in base]
    # Duplicate the hole's inner vertices: faces above the crease row use the copies.
    copy = {}
    for i in range(i0 + 1, i1):
        copy[i] = len(pts)
        pts.append(list(pts[idx(i, crease_row)]))
    faces = []
    for j in range(ny):
        for i in range(nx):
            f = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]
            if j == crease_row:
                f = [copy.get(i, f[0]), copy.get(i + 1, f[1]), f[2], f[3]]
            faces.append(f)
    glue = [[idx(i, crease_row), copy[i]] for i in range(i0 + 1, i1)]
    # M starts with the upper half turned 15° about the crease; handles fold it on to 80°.
    crease_y = lambda x: crease_row * h / ny + bend(x) * math.sin(math.pi * crease_row / ny)
    upper = set(copy.values()) | {idx(i, j) for j in range(crease_row + 1, ny + 1) for i in range(nx + 1)}

    def turned(v, angle):
        x, y = pts[v]
        if v not in upper:
            return [x, y, 0.0]
        d = y - crease_y(x)
        return [x, crease_y(x) + d * math.cos(angle), d * math.sin(angle)]
    mesh = [turned(v, math.radians(15)) for v in range(len(pts))]
    fold = math.radians(80)
    # One handle: the top edge's middle pulled to where an 80° turn about the crease would put it.
    # (A rigid turn of the whole upper half about a curved crease is no isometry: three such
    # targets measured L-Err 0.75 %, one 0.043 %.)
    handles = [handle(idx(nx // 2, ny), turned(idx(nx // 2, ny), fold))]
    if fixed_frame:
        # A small rigid frame at the bottom edge's middle: three fixed vertices close together
        # stop rigid motions without holding the bottom edge straight (three fixed points across
        # the edge did, against the bending of the lower half: L-Err 0.032 % → 0.0125 %).
        fixed = [idx(nx // 2, 0), idx(nx // 2 + 1, 0), idx(nx // 2, 1)]
    else:
        fixed = [idx(0, 0), idx(nx // 2, 0), idx(nx, 0)]
    return scene(
        "quad: curved fold by gluing a zero-width hole",
        "A curved fold (Jiang et al. 2020, Fig. 25): a 24 × 16 cm sheet whose grid rows bow by up "
        "to 2 cm, with a hole of zero width along the curved middle row (its 21 inner vertices "
        "duplicated; the hole ends one quad short of each side). Gluing the duplicates back "
        "together lets the mesh bend sharply along the curve: a curved crease. M′ is fixed; M "
        "starts with the upper half turned 15° about the crease; a handle at the top edge's middle "
        "pulls it on towards 80° while the bottom edge's corners and middle are fixed. Export "
        "the SVG (the slit is seam 1) and score the slit instead of cutting it for a paper "
        "model. Fig. 25 has 1.5k vertices (here 446).",
        faces, mesh, "mesh", unfolding=pts, units="cm", handles=handles, fixed=fixed,
        glue=glue,
        weights={"fairness_mesh": 0.1, "fairness_unfolding": 0, "mapping": 10})


def conformal_flatten():
    n, R, a = 24, 1.0, 0.6
    base, faces, idx = grid(n, n, 2 * a, 2 * a, -a, -a)
    mesh = [[x, y, math.sqrt(R * R - x * x - y * y)] for x, y in base]
    unfolding = [[x, y] for x, y in base]  # the orthographic view: a distorted start
    return scene(
        "quad: conformal flattening of a spherical patch",
        "A conformal map to a planar mesh (Jiang et al. 2020, Fig. 4): M is a patch of the unit "
        "sphere (the square [−0.6, 0.6]² lifted onto the sphere, 24 × 24 quads), held fixed; "
        "the planar unfolding M′ is the variable, starting from the orthographic projection "
        "(x, y), which shrinks the patch towards its rim. With conformal = true the checkerboard "
        "conformality of eq. 2 with per-face factors λ_f replaces isometry; weights as Fig. 22 "
        "row 4: conformality 1, conformal factor 0.1, fairness of M′ 0.01. The centre of M′ is "
        "fixed. The result is as isometric as a conformal map of a sphere can be, and starts an "
        "isometric solve of the same mesh. Fig. 4 has 1.1k vertices (here 625).",
        faces, mesh, "unfolding", unfolding=unfolding, conformal=True,
        fixed=[{"vertex": idx(n // 2, n // 2), "on": "unfolding"}],
        weights={"conformality": 1, "conformal_factor": 0.1, "fairness_unfolding": 0.01,
                 "fairness_mesh": 0})


def cylinder_exact():
    nu, nv, r, span, height = 16, 12, 1.0, 2 * math.pi / 3, 2.0
    chord = 2 * r * math.sin(span / nu / 2)
    unfolding, faces, idx = grid(nu, nv, nu * chord, height)
    mesh = []
    for j in range(nv + 1):
        for i in range(nu + 1):
            t = span * i / nu - span / 2
            mesh.append([r * math.sin(t), r * math.cos(t), height * j / nv])
    # The unrolling's columns at multiples of the chord length: every quad of M is a planar
    # rectangle chord × height/nv, congruent to its image — an exact (discrete) isometry.
    unfolding = [[chord * i, height * j / nv] for j in range(nv + 1) for i in range(nu + 1)]
    return scene(
        "quad: cylinder with its exact unrolling",
        "The exact case of issue 13: a 120° patch of the unit cylinder, 16 × 12 quads over "
        "height 2, and its exact unrolling — M′ columns spaced by the chord 2 sin(3.75°), so "
        "every quad of M is a flat rectangle congruent to its image in M′ and the checkerboard "
        "isometry holds exactly (L-Err at round-off). M is the variable, M′ fixed, fairness 0: "
        "the scene is a fixed point of the solver. Perturb M by 1% and solve: 10 iterations "
        "should bring L-Err back below 1e-4.",
        faces, mesh, "mesh", unfolding=unfolding,
        weights={"fairness_mesh": 0, "fairness_unfolding": 0})


def presets():
    convex, nonconvex = make_dforms()
    return {
        "quad-bend-sheet": bend_sheet(),
        "quad-developable-approx": developable_approx(),
        "quad-cut-glue": cut_glue(),
        "quad-cut-glue-diagonal": cut_glue_diagonal(),
        "quad-cone-deficit": cone_deficit(),
        "quad-cone-excess": cone_excess(),
        "quad-dform-convex": convex,
        "quad-dform-nonconvex": nonconvex,
        "quad-curved-fold": curved_fold(),
        "quad-conformal-flatten": conformal_flatten(),
        "quad-cylinder-exact": cylinder_exact(),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join(ROOT, "examples"))
    args = parser.parse_args()
    for name, doc in presets().items():
        model = doc["model"]
        faces = model["mesh"]["faces"]
        if model.get("unfolding") is not None:
            for f, face in enumerate(faces):
                assert signed_area(model["unfolding"]["vertices"], face) > 0, "%s: face %d is not ccw" % (name, f)
        path = os.path.join(args.out, name + ".json")
        with open(path, "w") as f:
            f.write(dump(with_summary(name + ".json", doc)) + "\n")
        print("%s: %d vertices, %d faces" % (path, len(model["mesh"]["vertices"]), len(faces)))


if __name__ == "__main__":
    main()
