// 7. Crease-pattern exports read back by independent tools: every composite example with a
//    development is solved by `devsurf solve … --export fold:F --export svg:F`; the FOLD file is
//    read with FOLD's reference library (npm `fold`) and compared with the crease pattern the
//    daemon streams to the editor for the same solved scene; the SVG is rasterized by chromium.
//    The PNGs land in test-artifacts/web/07-fold-*.png (look at them: mountain red dash-dot,
//    valley blue dashed, boundary black solid, rulings light grey).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';
import fold from 'fold';
import * as h from './lib/harness.mjs';

const ASSIGNMENTS = ['M', 'V', 'B', 'F'];
const COMPOSITES = fs.readdirSync(h.EXAMPLES).filter((f) => /^composite-.*\.json$/.test(f)).sort()
  .filter((f) => {
    const model = h.readScene(f).model;
    return model.kind === 'composite' && model.development;
  });

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'devsurf-fold-'));
let daemon = null;
let browser = null;
before(async () => {
  daemon = await new h.Daemon({ name: 'fold-export', demos: [] }).start();
  browser = await h.launchBrowser();
});
after(async () => {
  if (browser) await browser.close();
  if (daemon) await daemon.stop();
  fs.rmSync(work, { recursive: true, force: true });
});

/** `devsurf solve EXAMPLE --out R --export fold:F --export svg:S`; the report and both files. */
function solveAndExport(example) {
  const stem = path.join(work, path.basename(example, '.json'));
  const files = { report: `${stem}.report.json`, fold: `${stem}.fold`, svg: `${stem}.svg` };
  try {
    execFileSync(h.BIN, ['solve', path.join(h.EXAMPLES, example), '--out', files.report,
      '--export', `fold:${files.fold}`, '--export', `svg:${files.svg}`], { stdio: ['ignore', 'ignore', 'pipe'] });
  } catch (e) {
    assert.fail(`devsurf solve ${example} with fold/svg exports exited ${e.status}: ${String(e.stderr).trim()}`);
  }
  return {
    report: JSON.parse(fs.readFileSync(files.report, 'utf8')),
    foldText: fs.readFileSync(files.fold, 'utf8'),
    svg: fs.readFileSync(files.svg, 'utf8'),
  };
}

/**
 * The frames of a FOLD document as the spec defines them: frame 0 is the top level without the
 * file_ keys; file_frames[i] is frame i + 1, and with frame_inherit it takes every key of its
 * frame_parent that it does not set itself.
 */
function frames(doc) {
  const key = {};
  for (const [k, v] of Object.entries(doc)) if (!k.startsWith('file_')) key[k] = v;
  const list = [key];
  for (const f of doc.file_frames || []) {
    const parent = f.frame_parent === undefined ? null : list[f.frame_parent];
    list.push(f.frame_inherit && parent ? { ...parent, ...f } : { ...f });
  }
  return list;
}

/** Every per-element array of a frame (vertices_*, edges_*, faces_*) has its type's length. */
function assertConsistentLengths(frame, label) {
  for (const type of ['vertices', 'edges', 'faces']) {
    const n = fold.filter.numType(frame, type);
    for (const k of fold.filter.keysStartingWith(frame, `${type}_`)) {
      assert.ok(Array.isArray(frame[k]), `${label}: ${k} is an array`);
      assert.equal(frame[k].length, n, `${label}: ${k} has ${frame[k].length} entries, ${type} ${n}`);
    }
  }
}

/** Decodes one of the daemon's binary arrays ({dtype, shape, data: base64}). */
function decodeArray(a) {
  const buf = Buffer.from(a.data, 'base64');
  const view = a.dtype === 'int32' ? new Int32Array(buf.buffer, buf.byteOffset, buf.length / 4)
    : new Float32Array(buf.buffer, buf.byteOffset, buf.length / 4);
  return { shape: a.shape, values: Array.from(view) };
}

/** The crease pattern the editor gets: `state.geometry.development` of a new session on `scene`. */
async function streamedDevelopment(scene) {
  const s = await daemon.createSession(scene);
  const page = await browser.newPage();
  try {
    return await page.evaluate(({ url, id, token }) => new Promise((resolve, reject) => {
      const ws = new WebSocket(url);
      const timer = setTimeout(() => reject(new Error('no state message in 20 s')), 20000);
      ws.onopen = () => ws.send(JSON.stringify({ type: 'join', session: id, token, name: 'fold test' }));
      ws.onerror = () => reject(new Error('WebSocket error'));
      ws.onmessage = (m) => {
        const msg = JSON.parse(m.data);
        if (msg.type === 'error') { clearTimeout(timer); ws.close(); reject(new Error(m.data)); }
        if (msg.type !== 'state') return;
        clearTimeout(timer);
        ws.close();
        resolve(msg.geometry.development);
      };
    }), { url: `ws://127.0.0.1:${daemon.port}/ws`, id: s.id, token: s.view_token });
  } finally {
    await page.close();
  }
}

/** Rasterizes SVG text with chromium at `widthPx` (height from its aspect ratio) into a PNG. */
async function rasterize(svg, name, widthPx = 1000) {
  const page = await browser.newPage({ viewport: { width: widthPx + 40, height: 800 } });
  try {
    const src = `data:image/svg+xml;base64,${Buffer.from(svg).toString('base64')}`;
    await page.setContent(`<html><body style="margin:0;background:#ffffff">
      <img id="svg" style="display:block;width:${widthPx}px" src="${src}"></body></html>`);
    await page.waitForFunction(() => {
      const img = document.getElementById('svg');
      return img.complete && img.naturalWidth > 0;
    });
    const file = path.join(h.ARTIFACTS, `${name}.png`);
    const buf = await page.locator('#svg').screenshot({ path: file });
    return { file, image: h.decodePNG(buf) };
  } finally {
    await page.close();
  }
}

/** Pixels of a colour family: red (mountain), blue (valley), black (boundary). */
function colourCounts(img) {
  const c = { red: 0, blue: 0, black: 0, white: 0 };
  for (let i = 0; i < img.width * img.height; i++) {
    const r = img.data[4 * i]; const g = img.data[4 * i + 1]; const b = img.data[4 * i + 2];
    if (r > 180 && g < 90 && b < 90) c.red++;
    else if (b > 180 && r < 90 && g < 90) c.blue++;
    else if (r < 60 && g < 60 && b < 60) c.black++;
    else if (r > 245 && g > 245 && b > 245) c.white++;
  }
  return c;
}

for (const example of COMPOSITES) {
  const name = path.basename(example, '.json');

  test(`${name}: the FOLD export reads back with the fold package with consistent frames, counts and assignments`, { timeout: 120000 }, async () => {
    const { report, foldText } = solveAndExport(example);
    const doc = JSON.parse(fold.convert.convertFromTo(foldText, 'fold', 'fold'));
    assert.equal(doc.file_spec, 1.2);
    assert.equal(doc.frame_unit, 'mm', 'design units are millimetres by default');

    // Counts as the fold package derives them equal the file's own arrays.
    const nv = fold.filter.numVertices(doc);
    const ne = fold.filter.numEdges(doc);
    const nf = fold.filter.numFaces(doc);
    assert.equal(nv, doc.vertices_coords.length);
    assert.equal(ne, doc.edges_vertices.length);
    assert.equal(nf, doc.faces_vertices.length);
    assert.ok(nv > 0 && ne > 0 && nf > 0, `${nv} vertices, ${ne} edges, ${nf} faces`);

    // Assignments: only M, V, B, F; the package's filters count what the file says; fold angles
    // follow FOLD's sign (valley > 0, mountain < 0).
    assert.deepEqual([...new Set(doc.edges_assignment)].filter((a) => !ASSIGNMENTS.includes(a)), []);
    const count = (a) => doc.edges_assignment.filter((x) => x === a).length;
    assert.equal(fold.filter.mountainEdges(doc).length, count('M'));
    assert.equal(fold.filter.valleyEdges(doc).length, count('V'));
    assert.equal(fold.filter.boundaryEdges(doc).length, count('B'));
    assert.equal(fold.filter.flatEdges(doc).length, count('F'));
    assert.ok(count('M') + count('V') > 0, 'the solved example has folded creases');
    assert.ok(count('B') >= 3, 'the sheet has a boundary');
    for (const e of fold.filter.mountainEdges(doc)) assert.ok(doc.edges_foldAngle[e] < 0, `mountain edge ${e}`);
    for (const e of fold.filter.valleyEdges(doc)) assert.ok(doc.edges_foldAngle[e] > 0, `valley edge ${e}`);

    // Frames: the crease pattern (2D) and the folded form (3D) inheriting the structure.
    const list = frames(doc);
    assert.equal(list.length, 2, 'a crease-pattern frame and a folded frame');
    assert.deepEqual(list[0].frame_classes, ['creasePattern']);
    assert.deepEqual(list[1].frame_classes, ['foldedForm']);
    for (const [k, frame] of list.entries()) {
      assertConsistentLengths(frame, `frame ${k}`);
      assert.equal(fold.filter.numVertices(frame), nv, `frame ${k} vertices`);
      assert.equal(fold.filter.numEdges(frame), ne, `frame ${k} edges`);
      assert.equal(fold.filter.numFaces(frame), nf, `frame ${k} faces`);
      const dim = k === 0 ? 2 : 3;
      for (const c of frame.vertices_coords) {
        assert.equal(c.length, dim, `frame ${k}: ${dim}D coordinates`);
        assert.ok(c.every(Number.isFinite), `frame ${k}: finite coordinates`);
      }
    }

    // Faces reference valid vertices, run counter-clockwise in the crease pattern, and every side
    // of a face is an edge of the file (the package's faces_vertices_to_faces_edges finds it).
    for (const [f, face] of doc.faces_vertices.entries()) {
      assert.ok(face.length >= 3, `face ${f} has ${face.length} vertices`);
      for (const v of face) assert.ok(Number.isInteger(v) && v >= 0 && v < nv, `face ${f}: vertex ${v} of ${nv}`);
      assert.equal(fold.geom.polygonOrientation(face.map((v) => doc.vertices_coords[v])), 1, `face ${f} is counter-clockwise`);
    }
    for (const [e, [a, b]] of doc.edges_vertices.entries()) {
      assert.ok(a !== b && a >= 0 && b >= 0 && a < nv && b < nv, `edge ${e}: [${a}, ${b}]`);
    }
    const withEdges = fold.convert.deepCopy(doc);
    fold.convert.faces_vertices_to_faces_edges(withEdges);
    for (const [f, edges] of withEdges.faces_edges.entries()) {
      assert.ok(edges.every((e) => Number.isInteger(e)), `face ${f}: every side is an edge`);
    }

    // The crease pattern the daemon streams for the same solved scene has the same counts and
    // assignments (its polygons are fanned into triangles).
    const dev = await streamedDevelopment(report.scene);
    assert.ok(dev, 'the session streams a development');
    assert.equal(dev.vertices.shape[0], nv, 'streamed vertices');
    assert.equal(dev.edges.shape[0], ne, 'streamed edges');
    assert.equal(dev.assignment, doc.edges_assignment.join(''), 'streamed assignments, edge by edge');
    const fanned = doc.faces_vertices.reduce((n, face) => n + face.length - 2, 0);
    assert.equal(dev.triangles.shape[0], fanned, 'streamed triangles = faces fanned');
    assert.deepEqual(decodeArray(dev.edges).values, doc.edges_vertices.flat(), 'streamed edge endpoints');
    console.log(`${name}: ${nv} vertices, ${ne} edges (M ${count('M')}, V ${count('V')}, B ${count('B')}, F ${count('F')}), ${nf} faces`);
  });

  test(`${name}: the SVG fold pattern is sized in millimetres and renders mountains red and valleys blue`, { timeout: 120000 }, async () => {
    const { foldText, svg } = solveAndExport(example);
    const doc = JSON.parse(foldText);
    const root = /<svg\b[^>]*>/.exec(svg)[0];
    const attr = (k) => new RegExp(`\\b${k}="([^"]*)"`).exec(root)?.[1];
    assert.match(attr('width'), /^\d+(\.\d+)?mm$/);
    assert.match(attr('height'), /^\d+(\.\d+)?mm$/);
    assert.equal(attr('viewBox'), `0 0 ${parseFloat(attr('width'))} ${parseFloat(attr('height'))}`, 'one user unit is a millimetre');

    const full = await rasterize(svg, `07-fold-${name}`);
    // The drawing alone (legend removed): a colour shows exactly when the pattern has that kind.
    const drawing = await rasterize(svg.replace(/<g id="legend"[\s\S]*?<\/g>\n/, ''), `07-fold-${name}-drawing`);
    const all = colourCounts(full.image);
    const lines = colourCounts(drawing.image);
    const px = drawing.image.width * drawing.image.height;
    console.log(`${name}: ${full.file}: ${JSON.stringify(all)}; drawing only: ${JSON.stringify(lines)}`);
    assert.ok(all.red > 50 && all.blue > 50, `the legend shows both styles: ${JSON.stringify(all)}`);
    assert.ok(lines.black > 0.002 * px, `the boundary is drawn: ${JSON.stringify(lines)}`);
    assert.ok(lines.white > 0.5 * px, `the background stays white: ${JSON.stringify(lines)}`);
    const has = (a) => doc.edges_assignment.includes(a);
    assert.equal(lines.red > 50, has('M'), `mountain pixels iff mountain edges: ${lines.red} red pixels`);
    assert.equal(lines.blue > 50, has('V'), `valley pixels iff valley edges: ${lines.blue} blue pixels`);
  });
}

test('every composite example with a development is covered', () => {
  assert.ok(COMPOSITES.length >= 3, `composite examples with a development: ${COMPOSITES.join(', ')}`);
});
