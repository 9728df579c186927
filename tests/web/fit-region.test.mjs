// Fit strips to your own shape (issue 15): the start page reads CGAL's bunny (a mesh nobody here
// made) through POST /api/references and draws its points; a click on the shape centres the
// region (the ball brush) and the radius slider sizes it; "one strip" opens a strip session that
// grows onto the region while Solve streams iterates (the reference points drawn, the fit in the
// status line), and "strips side by side" opens the composite covering the bunny's back.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('fit-region', { demos: [path.join(h.EXAMPLES, 'strip-twisted.json')] });

function cgalFile(member) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'devsurf-cgal-'));
  execFileSync('tar', ['-xzf', '/usr/share/doc/libcgal-dev/data.tar.gz', '-C', dir, member]);
  return path.join(dir, member);
}

/** An OFF triangle mesh: {vertices: [[x, y, z]…], triangles: [[i, j, k]…]}. */
function readOff(file) {
  const words = fs.readFileSync(file, 'utf8').split(/\s+/).filter(Boolean);
  assert.equal(words[0], 'OFF');
  const [nv, nf] = [Number(words[1]), Number(words[2])];
  let at = 4;
  const vertices = [], triangles = [];
  for (let i = 0; i < nv; ++i, at += 3) vertices.push([Number(words[at]), Number(words[at + 1]), Number(words[at + 2])]);
  for (let f = 0; f < nf; ++f) {
    const n = Number(words[at]);
    const ids = words.slice(at + 1, at + 1 + n).map(Number);
    for (let k = 1; k + 1 < n; ++k) triangles.push([ids[0], ids[k], ids[k + 1]]);
    at += 1 + n;
  }
  return { vertices, triangles };
}

/** Whether a triangle of the mesh crosses the segment from `eye` to `p` short of p by more than `margin` (Möller–Trumbore). */
function occluded(mesh, eye, p, margin) {
  const d = [p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]];
  const length = Math.hypot(...d);
  const u = d.map((c) => c / length);
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  for (const [i, j, k] of mesh.triangles) {
    const a = mesh.vertices[i], e1 = sub(mesh.vertices[j], a), e2 = sub(mesh.vertices[k], a);
    const q = cross(u, e2), det = dot(e1, q);
    if (Math.abs(det) < 1e-14) continue;
    const s = sub(eye, a), bu = dot(s, q) / det;
    if (bu < 0 || bu > 1) continue;
    const r = cross(s, e1), bv = dot(u, r) / det;
    if (bv < 0 || bu + bv > 1) continue;
    const t = dot(e2, r) / det;
    if (t > 0 && t < length - margin) return true;
  }
  return false;
}

async function loadShape(page, daemon, file) {
  await page.goto(daemon.url);
  await page.getByTestId('start-page').waitFor();
  await page.getByTestId('shape-file').setInputFiles(file);
  await page.getByTestId('region-view').waitFor();
  await h.poll(async () => /37,706 points, 75,408 triangles/.test(await page.getByTestId('shape-info').textContent()));
}

/** Clicks Fit and waits for the editor: the state it opened and the server's session. */
async function fitAndOpen(page, daemon) {
  await page.getByTestId('fit-region').click();
  await page.getByTestId('editor').waitFor({ timeout: 60000 });
  await h.waitForConnected(page);
  const opened = await h.state(page);
  const server = await daemon.session(opened.session, new URL(page.url()).searchParams.get('token'));
  return { opened, server };
}

/** The daemon, CGAL's bunny extracted, and a start page that has read it. */
async function bunnyOnTheStartPage() {
  const { daemon } = ctx;
  const bunny = cgalFile('data/meshes/bunny00.off');
  const page = await ctx.page();
  await loadShape(page, daemon, bunny);
  return { daemon, bunny, page };
}

test('a click on an uploaded shape centres the region, and one strip fitted there grows onto it while Solve streams',
  { timeout: 180000 }, () => ctx.guard('fit-region-strip', async () => {
    const { daemon, bunny, page } = await bunnyOnTheStartPage();
    assert.equal(await page.getByTestId('fit-region').isDisabled(), true, 'no region yet');
    // A click in the middle of the view lands on the bunny and fills the centre.
    await page.getByTestId('region-view').scrollIntoViewIfNeeded();
    const box = await page.getByTestId('region-view').boundingBox();
    await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
    const picked = await h.inputValueWhenSet(page, 'region-centre');
    const centre = picked.split(/[\s,]+/).map(Number);
    assert.equal(centre.length, 3);
    assert.ok(centre.every((v) => Math.abs(v) <= 0.5), `the picked point ${picked} lies on the bunny`);
    await h.settleFrames(page);
    await h.screenshotPage(page, '11-start-page-region');
    // The bunny's back, a ball of 8 % of its diagonal, one strip (doubly curved: one strip stays
    // ~1.6 % of the region away; eight side by side come to 0.65 %, CoverCommandTest).
    await page.getByTestId('region-centre').fill('0.187, 0.119, 0.014');
    await page.getByTestId('region-centre').dispatchEvent('change');
    await page.getByTestId('region-radius').fill('8');
    assert.equal(await page.getByTestId('region-radius-label').textContent(), '0.128 (8 %)');
    const { opened, server } = await fitAndOpen(page, daemon);
    assert.equal(server.scene.model.kind, 'strip');
    assert.equal(server.scene.name, 'bunny00: fitted strip');
    assert.ok(server.scene.model.approximation.points.length > 20, 'the region thinned as the target');
    // "keep over the region" is on by default: the strip carries the overhang rows.
    assert.equal(server.scene.model.approximation.weights.overhang, 0.001);
    await h.waitState(page, (s) => s.metrics && typeof s.metrics.approximation_distance_rms_relative === 'number',
      undefined, { what: 'the placed strip measured against the region' });
    const before = (await h.state(page)).metrics.approximation_distance_rms_relative;
    await page.getByTestId('solve').click();
    await h.waitState(page, (s) => s.lastSolved && s.metrics && typeof s.metrics.approximation_distance_rms_relative === 'number',
      undefined, { what: 'a solved fit with approximation metrics', timeout: 90000 });
    const st = await h.state(page);
    console.log(`bunny back, one strip: RMS ${(100 * st.metrics.approximation_distance_rms_relative).toFixed(3)} % of the region `
      + `(placed: ${(100 * before).toFixed(3)} %), covered ${(100 * st.metrics.approximation_coverage).toFixed(1)} %, warp ${st.metrics.warp_angle_max_deg.toExponential(2)}°`);
    assert.ok(st.metrics.approximation_distance_rms_relative < 0.04, 'the strip lies on the region');
    assert.ok(st.metrics.approximation_coverage > 0.15, 'the strip covers part of the region');
    assert.ok(st.metrics.approximation_distance_rms_relative < 0.5 * before, 'the strip grew onto the region');
    assert.match(await page.getByTestId('status-fit').textContent(), /^RMS [\d.]+ % · max [\d.]+ % · [\d.]+ % covered$/);
    // The reference points are coloured by their distance to the strip.
    const coloured = await page.evaluate(() => {
      const v = window.__devsurf && window.__devsurf.editor && window.__devsurf.editor.viewport;
      const c = v && v.referenceGeometry.getAttribute('color');
      return c ? { count: c.count, vertexColors: v.referenceCloud.material.vertexColors } : null;
    });
    assert.deepEqual(coloured, { count: server.scene.model.approximation.points.length, vertexColors: true });
    await h.settleFrames(page);
    await h.screenshotViewport(page, '11-fit-region-strip');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

test('strips side by side over the bunny\'s back open as one composite that solves developable',
  { timeout: 180000 }, () => ctx.guard('fit-region-cover', async () => {
    const { daemon, bunny, page } = await bunnyOnTheStartPage();
    await page.getByTestId('region-centre').fill('0.187,0.119,0.014');
    await page.getByTestId('region-centre').dispatchEvent('change');
    await page.getByTestId('region-radius').fill('22');
    await page.getByTestId('region-mode').selectOption('cover');
    await page.getByTestId('region-strips').fill('8');
    const { opened, server } = await fitAndOpen(page, daemon);
    assert.equal(server.scene.model.kind, 'composite');
    assert.equal(server.scene.model.faces.length, 8);
    await page.getByTestId('solve').click();
    await h.waitState(page, (s) => s.lastSolved && s.metrics && s.metrics.warp_angle_max_deg < 0.05,
      undefined, { what: 'a developable composite', timeout: 90000 });
    await h.settleFrames(page);
    const shot = await h.screenshotViewport(page, '11-fit-region-cover');
    const s = h.pixelStats(shot.image);
    assert.ok(s.distinct >= 32 && s.dominantShare < 0.97, `the composite is drawn (${s.distinct} colours)`);
    // Pieces cut along seams: the export menu offers their flat patterns (SVG, DXF and FOLD).
    assert.equal(await page.getByTestId('export-fold').isVisible(), true);
    assert.match(await page.getByTestId('export-fold').getAttribute('title'), /flat pieces/);
    assert.equal(await page.getByTestId('export-svg').isVisible(), true);
    assert.match(await page.getByTestId('export-svg').getAttribute('title'), /flat pieces/);
    const token = new URL(page.url()).searchParams.get('token');
    const res = await fetch(`${daemon.url}api/sessions/${opened.session}/export?format=svg`, { headers: { Authorization: `Bearer ${token}` } });
    assert.equal(res.status, 200);
    const svg = await res.text();
    assert.match(svg, /<title>bunny00: 8 strips: 8 pieces, cut along the seams<\/title>/);
    assert.equal(new Set([...svg.matchAll(/data-seam="(\d+)"/g)].map((m) => m[1])).size, 7, 'seven seams numbered');
    // The fabrication files from the menu's buttons, as a user downloads them: the pieces as DXF
    // (cut and glue layers, each seam numbered on both pieces) and the surface as STL.
    const exported = async (testid) => {
      const [download] = await Promise.all([page.waitForEvent('download'), page.getByTestId(testid).click()]);
      return { name: download.suggestedFilename(), text: fs.readFileSync(await download.path(), 'latin1') };
    };
    const dxf = await exported('export-dxf');
    assert.match(dxf.name, /\.dxf$/);
    assert.match(dxf.text, /\$INSUNITS\r?\n 70\r?\n4\r?\n/, 'millimetres');
    const labels = [...dxf.text.matchAll(/\nTEXT\r?\n[\s\S]*?\n  1\r?\n(\d+)\r?\n/g)].map((m) => m[1]);
    assert.equal(labels.length, 14, 'seven seams, each numbered on both of its pieces');
    // FOLD: the pieces as one crease pattern with joins, the surface as its folded frame; read
    // here: every join's two copies meet in the folded frame, and the flat pieces keep the
    // folded frame's edge lengths.
    const foldFile = await exported('export-fold');
    assert.match(foldFile.name, /\.fold$/);
    const fold = JSON.parse(foldFile.text);
    const flatXY = fold.vertices_coords, folded = fold.file_frames[0].vertices_coords;
    assert.equal(folded.length, flatXY.length);
    const joins = fold.edges_assignment.filter((a) => a === 'J').length;
    assert.ok(joins > 50, `the seams are joins: ${joins}`);
    const pairs = fold['devsurf:gluePairs'];
    const gapMax = Math.max(...pairs.map(([a, b]) => Math.hypot(...folded[a].map((v, k) => v - folded[b][k]))));
    assert.ok(gapMax < 1e-9, `the copies of a seam point meet in the folded frame: ${gapMax}`);
    let stretch = 0;
    for (const [a, b] of fold.edges_vertices) {
      const l2 = Math.hypot(flatXY[a][0] - flatXY[b][0], flatXY[a][1] - flatXY[b][1]);
      const l3 = Math.hypot(...folded[a].map((v, k) => v - folded[b][k]));
      stretch = Math.max(stretch, Math.abs(l2 - l3) / l3);
    }
    assert.ok(stretch < 1e-3, `flat pieces keep the surface's edge lengths: ${stretch}`);
    console.log(`cover FOLD: ${flatXY.length} vertices, ${joins} join edges, ${pairs.length} glue pairs, gap ${gapMax}, stretch ${stretch}`);
    const stl = await exported('export-stl');
    assert.match(stl.name, /\.stl$/);
    assert.ok((stl.text.match(/\n\s*facet normal /g) || []).length > 1000, 'the cover as triangles');

    // A region that wraps around the shape (the ear): the warning is shown and the composite
    // opens only on a second click.
    const ear = await ctx.page();
    await loadShape(ear, daemon, bunny);
    await ear.getByTestId('region-centre').fill('-0.005, 0.494, -0.12');
    await ear.getByTestId('region-centre').dispatchEvent('change');
    await ear.getByTestId('region-radius').fill('10');
    await ear.getByTestId('region-mode').selectOption('cover');
    await ear.getByTestId('region-strips').fill('6');
    await ear.getByTestId('fit-region').click();
    const warning = ear.locator('.start-status .field-error');
    await warning.waitFor({ state: 'visible', timeout: 60000 });
    assert.match(await warning.textContent(), /cover a region of bunny00\.off: \d+ % of the region's normals are more than 75°/);
    assert.equal(await ear.getByTestId('fit-region').textContent(), 'Open anyway');
    assert.equal(await ear.getByTestId('start-page').isVisible(), true, 'still on the start page');
    await ear.getByTestId('fit-region').click();
    await ear.getByTestId('editor').waitFor({ timeout: 60000 });

    // A region with no points: refused on the start page, naming the field; the page stays usable.
    const start = await ctx.page();
    await loadShape(start, daemon, bunny);
    await start.getByTestId('region-centre').fill('5, 5, 5');
    await start.getByTestId('region-centre').dispatchEvent('change');
    await start.getByTestId('fit-region').click();
    const error = start.locator('.start-status .field-error');
    await error.waitFor({ state: 'visible' });
    assert.match(await error.textContent(), /fit a strip to bunny00\.off: radius: the region holds 0 points/);
    assert.equal(await start.getByTestId('fit-region').isDisabled(), false);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

test('the whole bunny covered region by region opens as one composite of developable parts (Fig. 10e)',
  { timeout: 180000 }, () => ctx.guard('fit-region-whole', async () => {
    const { daemon, page } = await bunnyOnTheStartPage();
    // No region to mark: the whole shape is cut into regions by the server.
    await page.getByTestId('region-mode').selectOption('whole');
    assert.equal(await page.getByTestId('shape-regions').isVisible(), true);
    assert.equal(await page.getByTestId('region-strips').inputValue(), '4', 'four strips a region by default');
    await page.getByTestId('shape-regions').fill('16');
    assert.equal(await page.getByTestId('fit-region').isDisabled(), false, 'nothing to mark first');
    await page.getByTestId('fit-region').click();
    // Some regions are left out as a rule: the page says how many were covered, and opens on a
    // second click.
    const warning = page.locator('.start-status .field-error');
    await warning.waitFor({ state: 'visible', timeout: 90000 });
    const said = await warning.textContent();
    const m = /^cover bunny00\.off: (\d+) of (\d+) regions covered; \d+ warnings?, e\.g\. region \d+/.exec(said);
    assert.ok(m, said);
    const covered = Number(m[1]);
    assert.ok(covered >= 8 && covered <= Number(m[2]), said);
    assert.equal(await page.getByTestId('fit-region').textContent(), 'Open anyway');
    await page.getByTestId('fit-region').click();
    await page.getByTestId('editor').waitFor({ timeout: 60000 });
    await h.waitForConnected(page);
    const opened = await h.state(page);
    const server = await daemon.session(opened.session, new URL(page.url()).searchParams.get('token'));
    assert.equal(server.scene.model.kind, 'composite');
    assert.equal(server.scene.model.faces.length, 4 * covered, 'four faces a covered region');
    assert.match(server.scene.name, /bunny00: covered in 16 regions/);
    await page.getByTestId('solve').click();
    await h.waitState(page, (s) => s.lastSolved && s.metrics && s.metrics.warp_angle_max_deg < 0.05,
      undefined, { what: 'developable parts', timeout: 90000 });
    await h.settleFrames(page);
    const shot = await h.screenshotViewport(page, '11-fit-region-whole');
    const s = h.pixelStats(shot.image);
    assert.ok(s.distinct >= 32 && s.dominantShare < 0.97, `the parts are drawn (${s.distinct} colours)`);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

test('a lasso drawn over the bunny takes only the side facing the viewer, a brush paints and Shift erases, and the marked points fit one strip',
  { timeout: 180000 }, () => ctx.guard('fit-region-lasso', async () => {
    const { daemon, bunny, page } = await bunnyOnTheStartPage();
    await page.getByTestId('region-view').scrollIntoViewIfNeeded();
    const box = await page.getByTestId('region-view').boundingBox();
    const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
    const marked = async () => Number((await page.getByTestId('region-count').textContent()).replace(/[^\d]/g, ''));

    // Brush: a stroke across the middle paints; the same stroke with Shift erases it all.
    await page.getByTestId('region-tool').selectOption('brush');
    assert.equal(await page.getByTestId('region-view').getAttribute('data-tool'), 'brush');
    assert.equal(await page.getByTestId('fit-region').isDisabled(), true, 'nothing painted yet');
    await page.getByTestId('region-radius').fill('4');
    const stroke = async (shift) => {
      if (shift) await page.keyboard.down('Shift');
      await page.mouse.move(cx - 40, cy);
      await page.mouse.down();
      for (let k = 1; k <= 16; ++k) await page.mouse.move(cx - 40 + 5 * k, cy + (k % 2), { steps: 1 });
      await page.mouse.up();
      if (shift) await page.keyboard.up('Shift');
    };
    await stroke(false);
    const painted = await marked();
    assert.ok(painted > 50, `the stroke painted points (${painted})`);
    assert.equal(await page.getByTestId('fit-region').isDisabled(), false);
    await stroke(true);
    assert.equal(await marked(), 0, 'Shift and the same stroke erase what it painted');

    // Lasso: a loop round the middle of the view. The bunny is seen from the front-right; a loop
    // over its body encloses points of its far side too, which must not be taken.
    await page.getByTestId('region-tool').selectOption('lasso');
    assert.equal(await page.getByTestId('region-radius').isVisible(), false, 'the lasso has no radius');
    await page.mouse.move(cx + 45, cy);
    await page.mouse.down();
    for (let k = 1; k <= 36; ++k) {
      const a = (2 * Math.PI * k) / 36;
      await page.mouse.move(cx + 45 * Math.cos(a), cy + 35 * Math.sin(a));
    }
    await page.mouse.up();
    const lassoed = await marked();
    assert.ok(lassoed > 100, `the loop took points (${lassoed})`);
    // Independent check of "only the near side": rays from the camera to the points, cast
    // against the bunny's own triangles (read from the file here, not from the app). A point
    // some triangle hides is on the far side.
    const view = await page.evaluate(([w, hgt]) => {
      const picker = window.__devsurf.startPage.regionPicker;
      const p = picker.points.geometry.getAttribute('position');
      const v = picker.camera.position.clone();
      const enclosed = [];
      for (let i = 0; i < p.count; ++i) {
        v.set(p.getX(i), p.getY(i), p.getZ(i)).project(picker.camera);
        const x = ((v.x + 1) / 2) * w, y = ((1 - v.y) / 2) * hgt;
        if (((x - w / 2) / 45) ** 2 + ((y - hgt / 2) / 35) ** 2 < 0.8) enclosed.push(p.getX(i), p.getY(i), p.getZ(i));
      }
      const c = picker.camera.position;
      return { camera: [c.x, c.y, c.z], taken: picker.selectedPositions(), enclosed, diagonal: picker.diagonal };
    }, [box.width, box.height]);
    const mesh = readOff(bunny);
    const hiddenOf = (flat) => {
      let hidden = 0;
      for (let i = 0; i < flat.length; i += 3) if (occluded(mesh, view.camera, flat.slice(i, i + 3), 1e-3 * view.diagonal)) ++hidden;
      return hidden;
    };
    const takenHidden = hiddenOf(view.taken), enclosedHidden = hiddenOf(view.enclosed);
    console.log(`lasso: ${lassoed} points taken, ${takenHidden} of them hidden by the mesh; `
      + `${view.enclosed.length / 3} drawn inside the loop, ${enclosedHidden} of those hidden`);
    assert.ok(enclosedHidden > 0.3 * (view.enclosed.length / 3), 'the loop encloses much of the far side as well');
    assert.ok(takenHidden <= 0.02 * lassoed, `only the near side is taken (${takenHidden} hidden points of ${lassoed})`);
    await h.settleFrames(page);
    await h.screenshotPage(page, '11-start-page-lasso');

    // The marked points become the strip's region.
    const positions = await page.evaluate(() => window.__devsurf.startPage.regionPicker.selectedPositions());
    const { opened, server } = await fitAndOpen(page, daemon);
    assert.equal(server.scene.model.kind, 'strip');
    const target = server.scene.model.approximation.points;
    assert.ok(target.length > 20, `the region thinned as the target (${target.length} points)`);
    const marks = [];
    for (let i = 0; i < positions.length; i += 3) marks.push(positions.slice(i, i + 3));
    for (const q of target) {
      const nearest = Math.min(...marks.map((m) => Math.hypot(m[0] - q[0], m[1] - q[1], m[2] - q[2])));
      assert.ok(nearest < 1e-6, `target point ${q} is one of the lassoed points (${nearest})`);
    }
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));
