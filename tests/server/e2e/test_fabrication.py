"""Fabrication exports and thumbnails of every shipped preset (issue 16 items 5 and 6), read back by
independent readers.

Every preset in examples/ (discovered) is opened as a demo session of one daemon, exported through
the session route as the web app's export menu asks for it, and checked with code that shares
nothing with the writers: ezdxf (Debian's python3-ezdxf) reads the DXF, the STL, OBJ and SVG are
parsed here. The check that matters is geometric: a flat pattern is the surface unrolled, so the
area its cut outline encloses must equal the area of the 3D surface (the OBJ export) — for a quad
mesh, the area of its unfolding M′ (the unfolding_obj export). Thumbnails are PNGs decoded here
with zlib (no image library).
"""
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest
import struct
import xml.etree.ElementTree as ET
import zlib

import ezdxf

from daemon import ROOT, Daemon

# Run against SQLite alone (tests/CMakeLists.txt): exports and thumbnails read the session, never the store.
ONE_STORE_IS_ENOUGH = True

EXAMPLES = sorted(os.path.join(ROOT, "examples", f) for f in os.listdir(os.path.join(ROOT, "examples"))
                  if f.endswith(".json"))
MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}


def auth(token):
    return {"Authorization": f"Bearer {token}"}


def triangle_area(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    x = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * math.sqrt(sum(t * t for t in x))


def obj_area(text):
    """Area of an OBJ's faces as fans (z = 0 for 2D vertices)."""
    vs, area = [], 0.0
    for line in text.splitlines():
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            xyz = [float(t) for t in p[1:4]] + [0.0] * (4 - len(p))
            vs.append(xyz[:3])
        elif p[0] == "f":
            ids = [int(t.split("/")[0]) - 1 for t in p[1:]]
            for k in range(1, len(ids) - 1):
                area += triangle_area(vs[ids[0]], vs[ids[k]], vs[ids[k + 1]])
    return area


def polygon_area(vs, faces):
    area = 0.0
    for ids in faces:
        for k in range(1, len(ids) - 1):
            area += triangle_area(vs[ids[0]], vs[ids[k]], vs[ids[k + 1]])
    return area


def off_mesh(text):
    """(vertices, faces) of an ASCII OFF file: "OFF", then "V F E", V lines "x y z", F lines "n i…"."""
    words = [w for line in text.splitlines() if not line.lstrip().startswith("#") for w in line.split()]
    if not words or words[0] != "OFF":
        raise ValueError("not an OFF file: " + text[:40])
    nv, nf = int(words[1]), int(words[2])
    at = 4
    vs = []
    for _ in range(nv):
        vs.append([float(t) for t in words[at:at + 3]])
        at += 3
    faces = []
    for _ in range(nf):
        n = int(words[at])
        faces.append([int(t) for t in words[at + 1:at + 1 + n]])
        at += 1 + n
    return vs, faces


def ply_mesh(text):
    """(vertices, faces) of an ASCII PLY file, read from its header's elements and properties."""
    lines = text.splitlines()
    if not lines or lines[0] != "ply" or lines[1] != "format ascii 1.0":
        raise ValueError("not an ASCII PLY file: " + text[:40])
    elements, at = [], 2
    while lines[at] != "end_header":
        p = lines[at].split()
        if p[0] == "element":
            elements.append((p[1], int(p[2]), []))
        elif p[0] == "property":
            elements[-1][2].append(p[-1] if p[1] != "list" else "list:" + p[-1])
        at += 1
    at += 1
    vs, faces = [], []
    for name, count, props in elements:
        for _ in range(count):
            values = lines[at].split()
            at += 1
            if name == "vertex":
                vs.append([float(values[props.index(axis)]) for axis in ("x", "y", "z")])
            elif name == "face":
                n = int(values[0])
                faces.append([int(t) for t in values[1:1 + n]])
    return vs, faces


def stl_facets(text):
    """(normal, [three vertices]) of every facet of an ASCII STL."""
    facets, current, normal = [], None, None
    for line in text.splitlines():
        p = line.split()
        if not p:
            continue
        if p[0] == "facet":
            normal, current = [float(t) for t in p[2:5]], []
        elif p[0] == "vertex":
            current.append([float(t) for t in p[1:4]])
        elif p[0] == "endfacet":
            facets.append((normal, current))
    return facets


def loops_from_segments(segments, tol):
    """Closed loops of undirected segments whose ends meet within tol, as point lists."""
    def key(p):
        return (round(p[0] / tol), round(p[1] / tol))
    at, points = {}, {}
    for k, (a, b) in enumerate(segments):
        for p in (a, b):
            at.setdefault(key(p), []).append(k)
            points[key(p)] = p
    used, loops = [False] * len(segments), []
    for k in range(len(segments)):
        if used[k]:
            continue
        loop, start = [], key(segments[k][0])
        v, s = start, k
        while True:
            used[s] = True
            a, b = (key(segments[s][0]), key(segments[s][1]))
            loop.append(points[v])
            v = b if a == v else a
            if v == start:
                break
            nxt = [t for t in at[v] if not used[t]]
            if not nxt:
                return None  # an open chain: the outline is not closed
            s = nxt[0]
        loops.append(loop)
    return loops


def decode_png(data):
    """(width, height, rows of RGBA bytes) of an 8-bit RGBA, non-interlaced PNG."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "PNG signature"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]
        assert zlib.crc32(kind + body) & 0xFFFFFFFF == crc, f"CRC of {kind}"
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert (depth, colour, interlace) == (8, 6, 0), "8-bit RGBA, not interlaced"
    raw, stride, rows, prev = zlib.decompress(idat), width * 4, [], bytearray(width * 4)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 4] if i >= 4 else 0
            b, c = prev[i], (prev[i - 4] if i >= 4 else 0)
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, rows


def shoelace(loop):
    return 0.5 * sum(loop[i][0] * loop[i - 1][1] - loop[i - 1][0] * loop[i][1] for i in range(len(loop)))


def inside(point, loop):
    x, y, hit = point[0], point[1], False
    for i in range(len(loop)):
        (x0, y0), (x1, y1) = loop[i - 1], loop[i]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            hit = not hit
    return hit


def enclosed_area(loops):
    """Area enclosed by simple, disjoint loops: a loop inside an odd number of others is a hole."""
    total = 0.0
    for i, loop in enumerate(loops):
        depth = sum(1 for j, other in enumerate(loops) if j != i and inside(loop[0], other))
        total += (-1 if depth % 2 else 1) * abs(shoelace(loop))
    return total


class FabricationExportsOfEveryPreset(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        args = []
        for path in EXAMPLES:
            args += ["--demo", path]
        cls.daemon = Daemon(cls.tmp.name, *args).start()
        sessions = cls.daemon.json("GET", "/api/sessions")[2]["sessions"]
        cls.demos = {s["id"]: s for s in sessions}

    @classmethod
    def tearDownClass(cls):
        cls.daemon.stop()
        cls.tmp.cleanup()

    def export(self, demo, fmt):
        status, headers, raw = self.daemon.request("GET", f"/api/sessions/{demo['id']}/export?format={fmt}",
                                                   headers=auth(demo["view_token"]))
        return status, raw

    def each_preset(self):
        for path in EXAMPLES:
            name = os.path.splitext(os.path.basename(path))[0]
            demo = self.demos.get("demo-" + name)
            self.assertIsNotNone(demo, f"the demo of {name} is listed")
            status, raw = self.export(demo, "json")
            self.assertEqual(status, 200, name)
            scene = json.loads(raw)
            yield name, demo, scene

    def test_every_preset_exports_an_stl_whose_facets_are_triangles_covering_the_obj_area(self):
        for name, demo, scene in self.each_preset():
            with self.subTest(preset=name):
                status, raw = self.export(demo, "stl")
                self.assertEqual(status, 200, raw[:200])
                facets = stl_facets(raw.decode())
                self.assertGreater(len(facets), 0)
                area = 0.0
                for normal, vertices in facets:
                    self.assertEqual(len(vertices), 3, "every facet has three vertices")
                    a = triangle_area(*vertices)
                    self.assertGreater(a, 0.0, "no facet of zero area")
                    area += a
                status, obj = self.export(demo, "obj")
                self.assertEqual(status, 200)
                # The STL in millimetres (what slicers read), the OBJ in the scene's units.
                mm = MM[scene.get("units", "mm")]
                reference = obj_area(obj.decode()) * mm * mm
                self.assertAlmostEqual(area / reference, 1.0, delta=1e-6)

    def test_every_preset_exports_a_dxf_whose_cut_outline_encloses_the_surfaces_area(self):
        for name, demo, scene in self.each_preset():
            with self.subTest(preset=name):
                model = scene["model"]
                mm = MM[scene.get("units", "mm")]
                if model["kind"] == "quad_mesh" and model["unfolding"].get("planar", True) is False:
                    status, raw = self.export(demo, "dxf")
                    self.assertEqual(status, 400, "a second surface has no flat pattern")
                    continue
                status, raw = self.export(demo, "dxf")
                self.assertEqual(status, 200, raw[:300])
                with tempfile.NamedTemporaryFile(suffix=".dxf") as f:
                    f.write(raw)
                    f.flush()
                    doc = ezdxf.readfile(f.name)
                self.assertEqual(doc.header.get("$INSUNITS"), 4, "millimetres")
                layers = {layer.dxf.name: layer for layer in doc.layers}
                entities = list(doc.modelspace())
                self.assertGreater(len(entities), 0)
                for e in entities:
                    self.assertIn(e.dxf.layer, layers, "every entity's layer is declared")
                for off in ("RULINGS", "MESH"):
                    if off in layers:
                        self.assertTrue(layers[off].is_off(), f"{off} is reference only, off")
                # The outline: every CUT and GLUE segment (both are cut through).
                segments = []
                for e in entities:
                    if e.dxftype() != "LWPOLYLINE" or e.dxf.layer not in ("CUT", "GLUE"):
                        continue
                    pts = [(p[0], p[1]) for p in e.get_points("xy")]
                    if e.closed:
                        pts.append(pts[0])
                    segments += list(zip(pts[:-1], pts[1:]))
                self.assertGreater(len(segments), 2)
                xs = [p[0] for s in segments for p in s]
                ys = [p[1] for s in segments for p in s]
                size = max(max(xs) - min(xs), max(ys) - min(ys))
                loops = loops_from_segments(segments, 1e-6 * size)
                self.assertIsNotNone(loops, "the cut outline closes")
                flat = enclosed_area(loops)
                if model["kind"] == "quad_mesh":
                    status, obj = self.export(demo, "unfolding_obj")
                    reference = obj_area(obj.decode()) * mm * mm
                    tolerance = 1e-6
                elif model["kind"] == "composite":
                    status, obj = self.export(demo, "obj")
                    reference = obj_area(obj.decode()) * mm * mm
                    tolerance = 0.005  # the pattern and the obj sample the surface differently
                else:
                    status, obj = self.export(demo, "obj")
                    reference = obj_area(obj.decode()) * mm * mm
                    tolerance = 1e-6  # the obj's own quads, unrolled
                self.assertEqual(status, 200)
                self.assertAlmostEqual(flat / reference, 1.0, delta=tolerance,
                                       msg=f"flat {flat:.6g} mm² against the surface's {reference:.6g} mm²")
                # Creases are scored, not cut: a crease pattern's folds are on MOUNTAIN/VALLEY.
                if model["kind"] == "composite" and model.get("development"):
                    folds = [e for e in entities if e.dxf.layer in ("MOUNTAIN", "VALLEY")]
                    creased = any(edge.get("crease", "none") != "none" for edge in model["edges"])
                    self.assertEqual(bool(folds), creased, "folds are drawn exactly when the design has creases")
                # Seam numbers come in pairs.
                labels = [e.dxf.text for e in entities if e.dxftype() == "TEXT" and e.dxf.layer == "LABEL"]
                for text in set(labels):
                    self.assertEqual(labels.count(text), 2, f"seam {text} is numbered on both sides")

    def test_every_strip_kind_exports_an_svg_flat_pattern_at_true_size(self):
        kinds = {"strip", "quasi_strip", "conical_strip"}
        seen = set()
        for name, demo, scene in self.each_preset():
            kind = scene["model"]["kind"]
            if kind not in kinds:
                continue
            seen.add(kind)
            with self.subTest(preset=name):
                status, raw = self.export(demo, "svg")
                self.assertEqual(status, 200, raw[:300])
                root = ET.fromstring(raw)
                ns = "{http://www.w3.org/2000/svg}"
                self.assertTrue(root.get("width").endswith("mm"))
                cuts = root.find(f".//{ns}g[@id='cuts']")
                segments = [((float(l.get("x1")), float(l.get("y1"))), (float(l.get("x2")), float(l.get("y2"))))
                            for l in cuts.iter(f"{ns}line")]
                loops = loops_from_segments(segments, 1e-3)
                self.assertIsNotNone(loops)
                status, obj = self.export(demo, "obj")
                mm = MM[scene.get("units", "mm")]
                reference = obj_area(obj.decode()) * mm * mm
                # SVG coordinates carry 4 decimals of a millimetre.
                self.assertAlmostEqual(enclosed_area(loops) / reference, 1.0, delta=1e-4)
        self.assertEqual(seen, kinds, "every strip kind has a preset")

    @unittest.skipUnless(shutil.which("node"), "node is needed to ask the web app's export menu")
    def test_the_web_menu_offers_exactly_the_formats_the_server_exports(self):
        # The menu's own rule (web/src/ui/exportFormats.js), evaluated by node on every preset.
        scenes = {name: scene for name, demo, scene in self.each_preset()}
        module = "file://" + os.path.join(ROOT, "web", "src", "ui", "exportFormats.js")
        script = ("import { EXPORT_FORMATS, exportFormats } from '" + module + "';\n"
                  "let text = ''; process.stdin.on('data', (d) => { text += d; });\n"
                  "process.stdin.on('end', () => { const scenes = JSON.parse(text); const out = {};\n"
                  "  for (const [n, s] of Object.entries(scenes)) out[n] = exportFormats(s.model.kind, s.model);\n"
                  "  console.log(JSON.stringify({ all: EXPORT_FORMATS, offered: out })); });\n")
        run = subprocess.run(["node", "--input-type=module", "-e", script], input=json.dumps(scenes),
                             capture_output=True, text=True, timeout=60, check=True)
        menu = json.loads(run.stdout)
        for name, scene in scenes.items():
            demo = self.demos["demo-" + name]
            offered = set(menu["offered"][name])
            for fmt in menu["all"]:
                with self.subTest(preset=name, format=fmt):
                    status, raw = self.export(demo, fmt)
                    if fmt in offered:
                        self.assertEqual(status, 200, f"the menu offers {fmt}: {raw[:300]!r}")
                        self.assertGreater(len(raw), 0)
                    else:
                        self.assertEqual(status, 400, f"the menu hides {fmt}, so the server refuses it")
                        self.assertIn("format", raw.decode())
        # The REST contract (OpenAPI) lists the menu's formats and the picture, which every kind
        # exports; it listed no png, which the server answered (a tryout compared the lists).
        with open(os.path.join(ROOT, "proto", "schemas", "openapi.json")) as f:
            api = json.load(f)
        for route in ("/api/sessions/{id}/export", "/api/jobs/{id}/result"):
            enums = [p["schema"]["enum"] for p in api["paths"][route]["get"]["parameters"] if p["name"] == "format"]
            # The menu's, the picture and the two mesh formats REST offers besides (off, ply).
            self.assertEqual(set(enums[0]), set(menu["all"]) | {"png", "off", "ply"}, route)
        for name in scenes:
            status, headers, raw = self.daemon.request("GET", f"/api/sessions/{self.demos['demo-' + name]['id']}/export?format=png",
                                                       headers=auth(self.demos["demo-" + name]["view_token"]))
            self.assertEqual(status, 200, name)
            self.assertEqual(raw[:8], b"\x89PNG\r\n\x1a\n", name)

    def test_every_preset_but_quad_meshes_exports_off_and_ply_read_back_as_its_obj(self):
        # Read by the parsers above, not by OpenMesh, which wrote them: the same vertices, faces
        # and area as the OBJ export. A quad mesh is refused, naming the format (as by the CLI).
        for name, demo, scene in self.each_preset():
            for fmt, read in (("off", off_mesh), ("ply", ply_mesh)):
                with self.subTest(preset=name, format=fmt):
                    status, raw = self.export(demo, fmt)
                    if scene["model"]["kind"] == "quad_mesh":
                        self.assertEqual(status, 400, raw[:300])
                        self.assertIn("format", raw.decode())
                        continue
                    self.assertEqual(status, 200, raw[:300])
                    vs, faces = read(raw.decode())
                    status, obj = self.export(demo, "obj")
                    self.assertEqual(status, 200)
                    obj_vs = [l for l in obj.decode().splitlines() if l.startswith("v ")]
                    obj_faces = [l for l in obj.decode().splitlines() if l.startswith("f ")]
                    self.assertEqual(len(vs), len(obj_vs))
                    self.assertEqual(len(faces), len(obj_faces))
                    self.assertGreater(len(faces), 0)
                    # Quads; a quad with a repeated corner (a composite's non-convex face) is a triangle.
                    self.assertTrue(all(len(f) in (3, 4) for f in faces), "the sampled surface's quads")
                    area = polygon_area(vs, faces)
                    self.assertAlmostEqual(area, obj_area(obj.decode()), delta=1e-6 * max(1.0, area))

    def test_every_demo_has_a_thumbnail_of_its_surface(self):
        for name, demo, scene in self.each_preset():
            with self.subTest(preset=name):
                status, headers, raw = self.daemon.request("GET", f"/api/sessions/{demo['id']}/thumbnail",
                                                           headers=auth(demo["view_token"]))
                self.assertEqual(status, 200, raw[:200])
                self.assertEqual(headers.get("Content-Type"), "image/png")
                width, height, rows = decode_png(raw)
                self.assertEqual((width, height), (320, 240))
                alpha = [row[x * 4 + 3] for row in rows for x in range(width)]
                opaque = sum(1 for a in alpha if a == 255) / len(alpha)
                self.assertGreater(opaque, 0.03, "the surface is drawn")
                self.assertLess(opaque, 0.95, "on a transparent background")
                self.assertEqual(rows[0][3], 0, "a corner is background")
                # Every fully covered pixel is a shade of the front blue (0.31, 0.66, 1) or the back
                # orange (1, 0.62, 0.26), but for pixels on a fold that mix both.
                def shade_of(rgb, base):
                    k = max(rgb) / 255 / max(base)
                    return all(abs(c - 255 * k * b) <= 2.5 for c, b in zip(rgb, base))
                pixels = [row[x * 4:x * 4 + 3] for row in rows for x in range(width) if row[x * 4 + 3] == 255]
                shaded = sum(1 for p in pixels if shade_of(p, (0.31, 0.66, 1.0)) or shade_of(p, (1.0, 0.62, 0.26)))
                self.assertGreater(shaded / len(pixels), 0.95, "drawn in the app's two surface colours")
                again = self.daemon.request("GET", f"/api/sessions/{demo['id']}/thumbnail", headers=auth(demo["view_token"]))
                self.assertEqual(again[2], raw, "kept for the revision")
                self.assertEqual(again[1].get("ETag"), headers.get("ETag"))
        status, _, _ = self.daemon.request("GET", f"/api/sessions/{demo['id']}/thumbnail", headers=auth("nope"))
        self.assertIn(status, (401, 403, 404))

    def test_unknown_formats_are_refused_naming_the_field(self):
        demo = next(iter(self.demos.values()))
        status, raw = self.export(demo, "dwg")
        self.assertEqual(status, 400)
        self.assertIn("format", raw.decode())


if __name__ == "__main__":
    unittest.main()
