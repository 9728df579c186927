"""Structural checks of the quad-mesh presets examples/quad-*.json (discovered, not listed):
scene format, indices in range, faces counter-clockwise in a planar unfolding, glue pairs joining
boundary vertices, D-form pieces of equal perimeter, the cylinder's unrolling exactly isometric.

The presets are written in issue 13's spelling: "mesh": {"vertices", "faces"}, "unfolding":
{"vertices", "planar" (only when false)}, "variables", "fixed" (integers for vertices of M),
"glue" (pairs [i, j] on M, then one {"on": "unfolding", "pairs"} object), "reference": {"vertices",
"faces"}. The legacy spelling the loader still accepts is not used here.
"""
import glob
import json
import math
import os
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
PRESETS = sorted(glob.glob(os.path.join(ROOT, "examples", "quad-*.json")))
KINDS = {"mesh", "unfolding", "both"}
WEIGHTS = {"isometry", "conformality", "conformal_factor", "position", "fairness_mesh",
           "fairness_unfolding", "proximity_point", "proximity_plane", "mapping", "normals",
           "symmetry"}


def load(path):
    with open(path) as f:
        return json.load(f)


def vertices(m):
    """The vertices of M."""
    return m["mesh"]["vertices"]


def faces(m):
    return m["mesh"]["faces"]


def unfolding(m):
    """The vertices of M′, or None when the scene leaves M′ to the model."""
    return m["unfolding"]["vertices"] if "unfolding" in m else None


def planar(m):
    return m["unfolding"].get("planar", True) if "unfolding" in m else True


def glue_pairs(m):
    """Every glue pair, (on, [i, j]): plain pairs are on M, then an {"on": "unfolding"} object."""
    out = []
    for g in m["glue"]:
        if isinstance(g, list):
            out.append(("mesh", g))
        else:
            assert set(g) == {"on", "pairs"} and g["on"] == "unfolding", g
            out += [("unfolding", pair) for pair in g["pairs"]]
    return out


def edges_of(faces):
    count = {}
    for f in faces:
        for k in range(len(f)):
            e = frozenset((f[k], f[(k + 1) % len(f)]))
            count[e] = count.get(e, 0) + 1
    return count


def signed_area(pts, face):
    return 0.5 * sum(pts[face[k]][0] * pts[face[(k + 1) % len(face)]][1]
                     - pts[face[(k + 1) % len(face)]][0] * pts[face[k]][1] for k in range(len(face)))


def dist(p, q):
    return math.sqrt(sum((a - b) ** 2 for a, b in zip(p, q)))


def components(n, faces):
    parent = list(range(n))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    for f in faces:
        for v in f[1:]:
            parent[find(v)] = find(f[0])
    return [find(i) for i in range(n)]


class QuadPresetsTest(unittest.TestCase):
    def test_there_are_presets_for_every_task_of_the_issue(self):
        names = {os.path.basename(p)[:-5] for p in PRESETS}
        for name in ("quad-bend-sheet", "quad-developable-approx", "quad-cut-glue", "quad-cut-glue-diagonal",
                     "quad-cone-deficit", "quad-cone-excess", "quad-dform-convex",
                     "quad-dform-nonconvex", "quad-curved-fold", "quad-conformal-flatten",
                     "quad-cylinder-exact"):
            self.assertIn(name, names)

    def test_every_preset_is_a_well_formed_quad_mesh_scene(self):
        for path in PRESETS:
            with self.subTest(preset=os.path.basename(path)):
                doc = load(path)
                self.assertEqual(doc["format"], "devsurf-scene")
                self.assertEqual(doc["version"], 1)
                self.assertTrue(doc["name"])
                self.assertRegex(doc["description"], r"Fig\. \d+|issue 13", "says what it reproduces")
                m = doc["model"]
                self.assertEqual(m["kind"], "quad_mesh")
                for legacy in ("faces", "unfolding_planar", "variable"):
                    self.assertNotIn(legacy, m, "issue 13's spelling, not the legacy one")
                self.assertEqual(set(m["mesh"]), {"vertices", "faces"})
                self.assertIn(m["variables"], KINDS)
                self.assertEqual(set(m["weights"]), WEIGHTS)
                n = len(vertices(m))
                self.assertLessEqual(n, 3000, "small enough to load fast")
                self.assertTrue(all(len(p) == 3 and all(math.isfinite(c) for c in p) for p in vertices(m)))
                if "unfolding" in m:
                    self.assertLessEqual(set(m["unfolding"]), {"vertices", "planar"})
                    self.assertNotEqual(m["unfolding"].get("planar"), True, "planar is written only when false")
                    self.assertEqual(len(unfolding(m)), n)
                    self.assertTrue(all(len(p) == (2 if planar(m) else 3) for p in unfolding(m)))
                else:
                    self.assertIn(m["variables"], ("unfolding", "both"), "M′ may be omitted only when variable")
                used = set()
                for f in faces(m):
                    self.assertIn(len(f), (3, 4))
                    self.assertEqual(len(set(f)), len(f))
                    self.assertTrue(all(0 <= v < n for v in f))
                    used.update(f)
                self.assertEqual(used, set(range(n)), "every vertex is in a face")
                self.assertTrue(all(c <= 2 for c in edges_of(faces(m)).values()), "manifold")
                for h in m.get("handles", []):
                    self.assertIn(h.get("on", "mesh"), ("mesh", "unfolding"))
                    self.assertTrue(0 <= h["vertex"] < n)
                    self.assertEqual(len(h["position"]), 3)
                for fx in m.get("fixed", []):
                    if isinstance(fx, int):  # a vertex of M
                        self.assertTrue(0 <= fx < n)
                    else:
                        self.assertEqual(fx["on"], "unfolding", "vertices of M are plain integers")
                        self.assertTrue(0 <= fx["vertex"] < n)
                glue_pairs(m)
                if "reference" in m:
                    self.assertEqual(set(m["reference"]), {"vertices", "faces"})
                    rv = m["reference"]["vertices"]
                    for t in m["reference"]["faces"]:
                        self.assertEqual(len(t), 3)
                        self.assertTrue(all(0 <= v < len(rv) for v in t))

    def test_faces_are_counter_clockwise_in_a_planar_unfolding(self):
        for path in PRESETS:
            m = load(path)["model"]
            if "unfolding" not in m or not planar(m):
                continue
            with self.subTest(preset=os.path.basename(path)):
                for k, f in enumerate(faces(m)):
                    self.assertGreater(signed_area(unfolding(m), f), 0, "face %d" % k)

    def test_glue_pairs_join_boundary_vertices(self):
        for path in PRESETS:
            m = load(path)["model"]
            if not m["glue"]:
                continue
            with self.subTest(preset=os.path.basename(path)):
                boundary = set()
                for e, c in edges_of(faces(m)).items():
                    if c == 1:
                        boundary |= e
                for on, (i, j) in glue_pairs(m):
                    self.assertNotEqual(i, j)
                    self.assertIn(i, boundary)
                    self.assertIn(j, boundary)

    def test_the_diagonal_cut_runs_along_quad_diagonals_and_every_edge_of_it_is_glued(self):
        """Fig. 16: features may follow diagonals. Every edge of the hole in M′ is the diagonal of
        a grid cell (|dx| = |dy|), and every vertex on it is glued, except the seam's two tips."""
        m = load(os.path.join(ROOT, "examples", "quad-cut-glue-diagonal.json"))["model"]
        u = unfolding(m)
        xs, ys = [p[0] for p in u], [p[1] for p in u]
        outer = lambda v: u[v][0] in (min(xs), max(xs)) or u[v][1] in (min(ys), max(ys))
        hole = [tuple(e) for e, c in edges_of(faces(m)).items() if c == 1 and not all(outer(v) for v in e)]
        self.assertEqual(len(hole), 16)
        for a, b in hole:
            dx, dy = abs(u[a][0] - u[b][0]), abs(u[a][1] - u[b][1])
            self.assertGreater(dx, 0)
            self.assertAlmostEqual(dx, dy, delta=1e-12)
        glued = {v for _, pair in glue_pairs(m) for v in pair}
        on_hole = {v for e in hole for v in e}
        self.assertEqual(len(on_hole - glued), 2, "only the two tips of the seam are unglued")
        self.assertTrue(any(len(f) == 3 for f in faces(m)), "the cut splits the quads it crosses")

    def test_glued_boundary_edges_have_equal_lengths_in_the_unfolding(self):
        """An arc-length preserving gluing: a boundary edge whose ends are glued to the ends of
        another boundary edge has that edge's length in M′."""
        for path in PRESETS:
            m = load(path)["model"]
            if not m["glue"] or "unfolding" not in m:
                continue
            with self.subTest(preset=os.path.basename(path)):
                partner = {}
                for _, (i, j) in glue_pairs(m):
                    partner.setdefault(i, set()).add(j)
                    partner.setdefault(j, set()).add(i)
                boundary = [tuple(e) for e, c in edges_of(faces(m)).items() if c == 1]
                lookup = {frozenset(e) for e in boundary}
                glued = 0
                for a, b in boundary:
                    for a2 in partner.get(a, ()):
                        for b2 in partner.get(b, ()):
                            if frozenset((a2, b2)) in lookup:
                                glued += 1
                                u = unfolding(m)
                                # Built presets are exact; an approximation ships its solved state,
                                # whose unfoldings keep glued lengths within its L-Err (max 1.2e-4 here).
                                tolerance = 1e-3 if "reference" in m else 1e-9
                                self.assertAlmostEqual(dist(u[a], u[b]), dist(u[a2], u[b2]),
                                                       delta=tolerance * dist(u[a], u[b]))
                self.assertGreater(glued, 0)

    def test_d_form_pieces_have_equal_perimeters_and_meet_on_their_glued_boundary(self):
        for path in [p for p in PRESETS if "dform" in os.path.basename(p)]:
            with self.subTest(preset=os.path.basename(path)):
                m = load(path)["model"]
                u = unfolding(m)
                comp = components(len(u), faces(m))
                pieces = sorted(set(comp))
                self.assertEqual(len(pieces), 2)
                perimeter = {c: 0.0 for c in pieces}
                for e, count in edges_of(faces(m)).items():
                    if count == 1:
                        a, b = tuple(e)
                        perimeter[comp[a]] += dist(u[a], u[b])
                p0, p1 = (perimeter[c] for c in pieces)
                self.assertAlmostEqual(p0, p1, delta=1e-9 * p0)
                pairs = [pair for _, pair in glue_pairs(m)]
                boundary = {v for e, c in edges_of(faces(m)).items() if c == 1 for v in e}
                self.assertEqual({v for pair in pairs for v in pair}, boundary,
                                 "the whole boundaries are glued")
                for i, j in pairs:
                    self.assertNotEqual(comp[i], comp[j])
                    self.assertLess(dist(vertices(m)[i], vertices(m)[j]), 1e-12 * max(1.0, p0),
                                    "M starts with glued vertices at one point")

    def test_the_cylinder_unrolling_is_exactly_isometric(self):
        m = load(os.path.join(ROOT, "examples", "quad-cylinder-exact.json"))["model"]
        M, U = vertices(m), [p + [0.0] for p in unfolding(m)]
        for f in faces(m):
            pairs = [(f[k], f[(k + 1) % len(f)]) for k in range(len(f))] + [(f[0], f[2]), (f[1], f[3])]
            for a, b in pairs:  # edges and diagonals
                self.assertAlmostEqual(dist(M[a], M[b]), dist(U[a], U[b]), delta=1e-12 * dist(U[a], U[b]))
        radius = {round(math.hypot(p[0], p[1]), 12) for p in M}
        self.assertEqual(radius, {1.0}, "M lies on the unit cylinder")


if __name__ == "__main__":
    unittest.main()
