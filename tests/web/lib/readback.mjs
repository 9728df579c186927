// Independent readers of the fabrication exports the browser tests download (issue 16): code that
// shares nothing with devsurf's writers.
//   stlMesh      — STL parsed here (ASCII or binary, detected): triangles, their total area, bbox.
//   stepProbe    — OpenCascade's STEPControl_Reader (tests/tools/step_probe.cpp, DEVSURF_STEP_PROBE).
//   dxfReadback  — Debian's python3 ezdxf: units, layers, the CUT outline's closed loops and the
//                  area they enclose, the MOUNTAIN/VALLEY score lines (as tests/server/e2e/
//                  test_fabrication.py reads them).
//   svgReadback  — python3's xml.etree: the page size in mm, the viewBox, and per group of the
//                  fold pattern (boundary, mountain, valley, …) its polylines and stroke colours.
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { ROOT } from './harness.mjs';

export const PYTHON = '/usr/bin/python3';
export const STEP_PROBE = process.env.DEVSURF_STEP_PROBE || path.join(ROOT, 'build', 'tests', 'step_probe');

function triangleArea(a, b, c) {
  const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
  const v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
  return 0.5 * Math.hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]);
}

/**
 * An STL file: binary when its size is exactly 84 + 50·n for the n in its header (an ASCII STL
 * starts "solid" and has no such size), else ASCII. → {binary, triangles, area, bbox: [min, max]}.
 */
export function stlMesh(buf) {
  const tris = [];
  const binary = buf.length >= 84 && buf.length === 84 + 50 * buf.readUInt32LE(80);
  if (binary) {
    const n = buf.readUInt32LE(80);
    for (let t = 0; t < n; t++) {
      const o = 84 + 50 * t + 12;
      const v = [0, 1, 2].map((k) => [0, 1, 2].map((c) => buf.readFloatLE(o + 12 * k + 4 * c)));
      tris.push(v);
    }
  } else {
    const text = buf.toString('latin1');
    if (!/^\s*solid\b/.test(text)) throw new Error('neither a binary STL nor an ASCII STL ("solid …")');
    let current = null;
    for (const line of text.split(/\r?\n/)) {
      const p = line.trim().split(/\s+/);
      if (p[0] === 'facet') current = [];
      else if (p[0] === 'vertex') current.push(p.slice(1, 4).map(Number));
      else if (p[0] === 'endfacet') {
        if (!current || current.length !== 3) throw new Error(`a facet with ${current && current.length} vertices`);
        tris.push(current);
        current = null;
      }
    }
  }
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  let area = 0;
  for (const t of tris) {
    area += triangleArea(...t);
    for (const p of t) for (let c = 0; c < 3; c++) { lo[c] = Math.min(lo[c], p[c]); hi[c] = Math.max(hi[c], p[c]); }
  }
  return { binary, triangles: tris.length, area, bbox: [lo, hi] };
}

/** Runs the OpenCascade probe on a STEP file → {roots, faces, area, bbox: [[x0,y0,z0],[x1,y1,z1]]} (mm). */
export function stepProbe(file) {
  if (!fs.existsSync(STEP_PROBE)) throw new Error(`no STEP probe at ${STEP_PROBE} (set DEVSURF_STEP_PROBE; cmake --build build builds step_probe)`);
  const r = spawnSync(STEP_PROBE, [file], { encoding: 'utf8', timeout: 60000 });
  if (r.status !== 0) throw new Error(`step_probe ${file} exited ${r.status ?? r.signal}: ${r.stderr}`);
  return JSON.parse(r.stdout.trim().split('\n').pop());
}

function python(script, file) {
  const r = spawnSync(PYTHON, ['-c', script, file], { encoding: 'utf8', timeout: 60000 });
  if (r.status !== 0) throw new Error(`${PYTHON} reading ${file} exited ${r.status ?? r.signal}: ${r.stderr}`);
  return JSON.parse(r.stdout.trim().split('\n').pop());
}

// Loops of undirected segments whose ends meet within tol (None when a chain stays open) and the
// area they enclose (a loop inside an odd number of others is a hole): as test_fabrication.py.
const PY_LOOPS = String.raw`
def loops_from_segments(segments, tol):
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
            a, b = key(segments[s][0]), key(segments[s][1])
            loop.append(points[v])
            v = b if a == v else a
            if v == start:
                break
            nxt = [t for t in at[v] if not used[t]]
            if not nxt:
                return None
            s = nxt[0]
        loops.append(loop)
    return loops

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
    total = 0.0
    for i, loop in enumerate(loops):
        depth = sum(1 for j, other in enumerate(loops) if j != i and inside(loop[0], other))
        total += (-1 if depth % 2 else 1) * abs(shoelace(loop))
    return total

def polyline_length(pts):
    return sum(((pts[i][0] - pts[i - 1][0]) ** 2 + (pts[i][1] - pts[i - 1][1]) ** 2) ** 0.5 for i in range(1, len(pts)))
`;

const PY_DXF = `${PY_LOOPS}
import json, sys
import ezdxf
doc = ezdxf.readfile(sys.argv[1])
layers = {l.dxf.name: {"off": l.is_off(), "color": l.dxf.color} for l in doc.layers}
entities = list(doc.modelspace())
counts = {}
polylines = {}
segments = []
for e in entities:
    counts[e.dxf.layer + ":" + e.dxftype()] = counts.get(e.dxf.layer + ":" + e.dxftype(), 0) + 1
    if e.dxftype() != "LWPOLYLINE":
        continue
    pts = [(p[0], p[1]) for p in e.get_points("xy")]
    if e.closed:
        pts.append(pts[0])
    if e.dxf.layer in ("CUT", "GLUE"):
        segments += list(zip(pts[:-1], pts[1:]))
    if e.dxf.layer in ("CUT", "MOUNTAIN", "VALLEY"):
        polylines.setdefault(e.dxf.layer, []).append({"points": pts, "length": polyline_length(pts)})
xs = [p[0] for s in segments for p in s] or [0.0]
ys = [p[1] for s in segments for p in s] or [0.0]
size = max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)
loops = loops_from_segments(segments, 1e-6 * size) if segments else None
print(json.dumps({
    "version": ezdxf.__version__,
    "insunits": doc.header.get("$INSUNITS"),
    "layers": layers,
    "counts": counts,
    "cut_segments": len(segments),
    "cut_bbox": [[min(xs), min(ys)], [max(xs), max(ys)]],
    "loops": None if loops is None else len(loops),
    "area": None if loops is None else enclosed_area(loops),
    "polylines": polylines,
}))
`;

const PY_SVG = `${PY_LOOPS}
import json, re, sys
import xml.etree.ElementTree as ET
NS = "{http://www.w3.org/2000/svg}"
root = ET.parse(sys.argv[1]).getroot()
def points_of(el):
    tag = el.tag[len(NS):] if el.tag.startswith(NS) else el.tag
    if tag in ("polyline", "polygon"):
        nums = [float(t) for t in re.split(r"[\\s,]+", el.get("points").strip()) if t]
        pts = list(zip(nums[0::2], nums[1::2]))
        return pts + [pts[0]] if tag == "polygon" else pts
    if tag == "line":
        return [(float(el.get("x1")), float(el.get("y1"))), (float(el.get("x2")), float(el.get("y2")))]
    return None
groups = {}
for g in root.iter(NS + "g"):
    gid = g.get("id")
    if gid in (None, "legend", "rulings"):
        continue
    items = []
    for el in g:
        pts = points_of(el)
        if pts is None:
            continue
        items.append({"tag": el.tag[len(NS):], "stroke": el.get("stroke"), "class": el.get("class"),
                      "dasharray": el.get("stroke-dasharray"), "points": pts, "length": polyline_length(pts)})
    groups[gid] = items
segments = [s for it in groups.get("boundary", []) for s in zip(it["points"][:-1], it["points"][1:])]
xs = [p[0] for s in segments for p in s] or [0.0]
ys = [p[1] for s in segments for p in s] or [0.0]
size = max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)
loops = loops_from_segments(segments, 1e-6 * size) if segments else None
print(json.dumps({
    "width": root.get("width"), "height": root.get("height"), "viewBox": root.get("viewBox"),
    "title": (root.findtext(NS + "title") or ""),
    "groups": groups,
    "rulings": len(list(root.iter(NS + "path"))),
    "boundary_bbox": [[min(xs), min(ys)], [max(xs), max(ys)]],
    "loops": None if loops is None else len(loops),
    "area": None if loops is None else enclosed_area(loops),
}))
`;

/** The DXF read with ezdxf (see PY_DXF for what it reports). */
export function dxfReadback(file) {
  return python(PY_DXF, file);
}

/** The SVG read with xml.etree (see PY_SVG for what it reports). */
export function svgReadback(file) {
  return python(PY_SVG, file);
}

/**
 * Chains polylines (lists of [x, y]) that share end points within tol into curves; returns each
 * curve as one point list (for crease lines split into several polylines where faces meet).
 */
export function chainPolylines(polylines, tol = 1e-3) {
  const rest = polylines.map((p) => p.slice());
  const near = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]) <= tol;
  const chains = [];
  while (rest.length) {
    let chain = rest.shift();
    for (let grown = true; grown;) {
      grown = false;
      for (let i = 0; i < rest.length; i++) {
        const p = rest[i];
        const [a, b] = [chain[0], chain[chain.length - 1]];
        let joined = null;
        if (near(b, p[0])) joined = chain.concat(p.slice(1));
        else if (near(b, p[p.length - 1])) joined = chain.concat(p.slice(0, -1).reverse());
        else if (near(a, p[p.length - 1])) joined = p.concat(chain.slice(1));
        else if (near(a, p[0])) joined = p.slice().reverse().concat(chain.slice(1));
        if (joined) { chain = joined; rest.splice(i, 1); grown = true; break; }
      }
    }
    chains.push(chain);
  }
  return chains;
}

/** Distance from point q to a polyline. */
export function distanceToPolyline(q, pts) {
  let best = Infinity;
  for (let i = 1; i < pts.length; i++) {
    const [a, b] = [pts[i - 1], pts[i]];
    const d = [b[0] - a[0], b[1] - a[1]];
    const l2 = d[0] * d[0] + d[1] * d[1];
    const t = l2 > 0 ? Math.max(0, Math.min(1, ((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / l2)) : 0;
    best = Math.min(best, Math.hypot(q[0] - a[0] - t * d[0], q[1] - a[1] - t * d[1]));
  }
  return best;
}

/**
 * A session's FOLD export read back: {key (the file's key frame, file_* keys left out), folded
 * (the key frame with the first of file_frames over it)}.
 */
export async function exportedFold(daemon, id, token) {
  const r = await fetch(`http://127.0.0.1:${daemon.port}/api/sessions/${encodeURIComponent(id)}/export?format=fold`,
    { headers: { Authorization: `Bearer ${token}` } });
  if (r.status !== 200) throw new Error(`FOLD export of ${id}: HTTP ${r.status} ${await r.text()}`);
  const doc = JSON.parse(await r.text());
  const key = {};
  for (const [k, v] of Object.entries(doc)) if (!k.startsWith('file_')) key[k] = v;
  return { key, folded: { ...key, ...doc.file_frames[0] } };
}
