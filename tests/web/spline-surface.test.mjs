// 14. Developable spline surfaces (issue 14, Jiang et al. 2020 Algorithm 2): a quad_mesh demo with
//     a control net shows the control mesh M (points and edges), the limit surface M^∞ coloured by
//     its scale-free Gauss curvature K·d², its rulings, and the unfolding M′ beside it (judged from
//     screenshots); the refined mesh S^k(M) is one switch away, and there a press on a vertex of
//     S^k(M) under a control point picks the control point. A control point dragged with a real
//     pointer sends drags addressed {vertex, on: 'control'} that the server acks; the control point
//     and M^∞ follow in the streamed geometry, and after the release the single patch has rulings
//     (drawn wide, seen in the pixels); the patches export as STEP and IGES. The watertight 2 × 2
//     model shows its normal jump across the shared patch sides, live while a control point is
//     dragged; F then fixes that control point.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

// The spline demos are built (and the watertight one solved) before the daemon listens: more
// than the default 20 s on a slow machine.
const ctx = h.useDaemonAndBrowser('spline-surface', {
  demos: ['spline-single-patch.json', 'spline-watertight.json'].map((f) => path.join(h.EXAMPLES, f)),
  startTimeoutMs: 120000,
});

/** sRGB of the rulings of M^∞ (QUAD_COLORS.splineRulings, 0x3b0764). */
const RULING_RGB = [0x3b, 0x07, 0x64];

/** The spline as the page holds it (SplineBuffers, the layer's objects, the drawn points). */
const spline = (page) => page.evaluate(() => {
  const { quad: q, viewport: v } = window.__devsurf.editor;
  const s = q.spline;
  const L = v.quadLayer;
  return {
    present: s.present, display: q.display, colorMode: q.colorMode, version: s.version,
    controls: s.controlCount, edges: s.controlEdges.length / 2, patches: s.patchCount, samples: s.sampleCount,
    rulings: s.rulingCount, rulingSegments: s.rulingSegments, drawnRulingSegments: L.splineRulingGeometry.instanceCount,
    gaussMax: s.gaussMaxScaled, gaussMean: s.gaussMeanScaled, sharedSides: s.sharedSides, normalJump: s.normalJumpMaxDeg,
    control: Array.from(s.control), samplesXYZ: Array.from(s.surface.getAttribute('position').array),
    netDrawn: s.controlLines.drawRange.count / 2, points: v.points.count, meshVertices: q.vertexCount,
    visible: {
      layer: L.group.visible, limit: L.splineSurface.visible, rulings: L.splineRulings.visible, net: L.controlNet.visible,
      mesh: L.surface.visible, meshEdges: L.edges.visible,
    },
  };
});

const distance = (a, b) => Math.hypot(...a.map((v, i) => v - b[i]));
const controlPoint = (s, i) => s.control.slice(3 * i, 3 * i + 3);
const maxDelta = (a, b) => a.reduce((m, v, i) => Math.max(m, Math.abs(v - b[i])), 0);

/** Pixels within `tolerance` of an sRGB colour in any channel. */
function countColor(img, rgb, tolerance = 24) {
  let n = 0;
  for (let i = 0; i < img.width * img.height; i++) {
    if (Math.abs(img.data[4 * i] - rgb[0]) <= tolerance && Math.abs(img.data[4 * i + 1] - rgb[1]) <= tolerance
      && Math.abs(img.data[4 * i + 2] - rgb[2]) <= tolerance) n++;
  }
  return n;
}

/** The first number of a metric cell. */
async function metric(page, testid) {
  return (await h.numberIn(page, testid)).value;
}

/** Waits until the page has seen the server's last edit and its solve is over. */
async function caughtUp(page, daemon, demo, after) {
  await h.waitQuiet(page, { quietMs: 1500, timeout: 60000 });
  return h.poll(async () => {
    const st = await h.state(page);
    const server = await daemon.session(demo.id, demo.view_token);
    return { st, server, ok: server.seq > after && st.seq === server.seq };
  }, { timeout: 30000 });
}

/** Frames the page sends and receives on its WebSocket. */
function recordFrames(page) {
  const frames = { sent: [], received: [] };
  page.on('websocket', (ws) => {
    ws.on('framesent', (f) => { try { frames.sent.push(JSON.parse(f.payload)); } catch { /* binary */ } });
    ws.on('framereceived', (f) => {
      try {
        const m = JSON.parse(f.payload);
        if (m.type !== 'iterate') frames.received.push(m);
      } catch { /* binary */ }
    });
  });
  return frames;
}

async function openDemo(page, daemon, id) {
  const demo = await h.openQuadMeshDemo(page, daemon, id, { spline: true });
  await h.settleFrames(page);
  return demo;
}

/**
 * A real pointer drag of control point i by (dx, dy) px in `steps` moves; before the release it
 * waits for an iterate of the drag and takes a screenshot of the view (`shot`).
 */
async function dragControlPoint(page, i, { dx = 0, dy = -40, steps = 12, shot }) {
  const from = await h.pointPagePosition(page, { vertex: i, on: 'control' });
  const st0 = await h.state(page);
  await page.mouse.move(from.x, from.y);
  await h.sleep(50);
  await page.mouse.down();
  for (let k = 1; k <= steps; k++) {
    await page.mouse.move(from.x + (dx * k) / steps, from.y + (dy * k) / steps);
    await h.sleep(40);
  }
  await h.waitState(page, (st, n) => st.iterateCount > n, st0.iterateCount, { what: 'iterates while dragging' });
  await h.settleFrames(page);
  const during = await h.screenshotViewport(page, shot);
  await page.mouse.up();
  return { st0, during };
}

/** Every drag / drag_end sent was acked (matched by op), and no error came back. */
function assertAcked(frames, target) {
  const mine = frames.sent.filter((m) => m.type === 'drag' || m.type === 'drag_end');
  const acked = new Set(frames.received.filter((m) => m.type === 'ack').map((m) => m.op));
  assert.ok(mine.length > 0, 'drag messages were sent');
  for (const m of mine) {
    assert.deepEqual(m.target, target, `${m.type} addresses the control point`);
    assert.ok(acked.has(m.op), `${m.type} op ${m.op} was acked`);
  }
  const errors = frames.received.filter((m) => m.type === 'error');
  assert.deepEqual(errors, [], 'no error from the server');
}

test('single patch: control net, limit surface and rulings; a control point drags, M^∞ follows', { timeout: 300000 }, () =>
  ctx.guard('spline-single-patch', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    const frames = recordFrames(page);
    const demo = await openDemo(page, daemon, 'demo-spline-single-patch');
    const server0 = await daemon.session(demo.id, demo.view_token);
    const net = server0.scene.model.control;

    // What is drawn: the 7 × 7 net (84 edges), one patch sampled 25 × 25, only the control points
    // as sprites (the limit surface is the surface shown), coloured by K·d².
    const s0 = await spline(page);
    assert.equal(s0.present, true);
    assert.equal(s0.display, 'limit');
    assert.equal(s0.colorMode, 'spline_gauss');
    assert.equal(s0.controls, net.points.length);
    assert.ok(distance(controlPoint(s0, 3), net.points[3]) < 1e-4, 'the control points are the scene\'s');
    assert.equal(s0.edges, 84);
    assert.equal(s0.netDrawn, 84);
    assert.equal(s0.patches, 1);
    assert.equal(s0.samples, 25 * 25);
    assert.equal(s0.points, s0.controls, 'the control points are the points of the view');
    assert.deepEqual(s0.visible, { layer: true, limit: true, rulings: true, net: true, mesh: false, meshEdges: false });
    assert.equal((await page.getByTestId('legend-title').textContent()).trim(), 'K·d² of the limit surface');
    assert.equal(await page.locator('.legend').getAttribute('data-scale'), 'diverging');
    assert.equal(await page.getByTestId('quad-display').inputValue(), 'limit');
    assert.equal(await page.getByTestId('quad-color-mode').inputValue(), 'spline_gauss');
    assert.ok(Math.abs(await metric(page, 'metric-spline-gauss-max') - s0.gaussMax) <= 0.01 * s0.gaussMax, 'the panel shows max |K|·d²');
    assert.ok(Math.abs(await metric(page, 'metric-spline-gauss-mean') - s0.gaussMean) <= 0.01 * s0.gaussMean, 'the panel shows mean |K|·d²');
    assert.equal(s0.sharedSides, 0);
    assert.equal(await page.getByTestId('metric-spline-normal-jump').isVisible(), false, 'no normal jump on one patch');
    assert.match(await page.getByTestId('metric-control-net').textContent(), /^49 points · 1 patch · k = 2$/);
    console.log(`single patch: ${s0.controls} control points, ${s0.samples} samples, |K|·d² max ${s0.gaussMax.toFixed(4)} mean ${s0.gaussMean.toFixed(4)}, `
      + `${s0.rulings} rulings`);

    await h.screenshotPage(page, '14-spline-editor');
    const before = await h.screenshotViewport(page, '14-spline-limit-before');
    const stats = h.pixelStats(before.image);
    assert.ok(stats.distinct >= 64 && stats.dominantShare < 0.85, `M^∞ and the net are drawn: ${JSON.stringify(stats)}`);
    // M′ (S^2(M) unfolded: 18 × 18 faces) is drawn beside it as before.
    assert.equal(Number(await page.getByTestId('unfolding-view').getAttribute('data-faces')), 324);
    const flatClip = await page.getByTestId('unfolding-view').boundingBox();
    const flat = h.pixelStats(h.decodePNG(await page.screenshot({ path: `${h.ARTIFACTS}/14-spline-unfolding.png`, clip: flatClip })));
    assert.ok(flat.distinct >= 16 && flat.dominantShare < 0.8, `M′ is drawn: ${JSON.stringify(flat)}`);

    // The refined mesh S^k(M): its faces, edges and vertices, the control points still first.
    await page.getByTestId('quad-display').selectOption('refined');
    await h.settleFrames(page);
    const refined = await spline(page);
    assert.deepEqual(refined.visible, { layer: true, limit: false, rulings: false, net: true, mesh: true, meshEdges: true });
    assert.equal(refined.points, refined.controls + refined.meshVertices);
    await h.screenshotViewport(page, '14-spline-refined');
    // A press on the vertex of S^k(M) nearest a control point (on screen) picks the control point.
    const pair = await page.evaluate(() => {
      const { quad: q, viewport: v } = window.__devsurf.editor;
      let best = null;
      for (let c = 0; c < q.spline.controlCount; c++) {
        const pc = v.pointScreenPosition({ vertex: c, on: 'control' });
        for (let i = 0; i < q.vertexCount; i++) {
          const pv = v.pointScreenPosition({ vertex: i });
          const d = Math.hypot(pc.x - pv.x, pc.y - pv.y);
          if (!best || d < best.d) best = { c, i, d };
        }
      }
      return best;
    });
    assert.ok(pair.d < 4, `a vertex of S^k(M) lies under control point ${pair.c}: ${JSON.stringify(pair)}`);
    const under = await h.pointPagePosition(page, { vertex: pair.i });
    await page.mouse.click(under.x, under.y);
    await h.waitState(page, (st, c) => st.selection && st.selection.on === 'control' && st.selection.vertex === c, pair.c,
      { what: `control point ${pair.c} selected` });
    await page.getByTestId('quad-display').selectOption('limit');
    await h.settleFrames(page);
    assert.equal((await spline(page)).visible.limit, true);

    // Drag control point 3 (middle of the first row) up the screen with a real pointer.
    const target = { vertex: 3, on: 'control' };
    frames.sent.length = 0;
    frames.received.length = 0;
    const { st0 } = await dragControlPoint(page, 3, { dy: -40, shot: '14-spline-limit-dragging' });
    await h.waitState(page, (st, n) => st.iterateCount > n, st0.iterateCount, { what: 'iterates after the release' });
    const { st, server } = await caughtUp(page, daemon, demo, server0.seq);
    const s1 = await spline(page);
    const drags = frames.sent.filter((m) => m.type === 'drag');
    const moved = distance(controlPoint(s1, 3), controlPoint(s0, 3));
    const surfaceMoved = maxDelta(s1.samplesXYZ, s0.samplesXYZ);
    console.log(`single patch drag: ${drags.length} drags, control point 3 moved ${moved.toFixed(3)}, M^∞ moved up to ${surfaceMoved.toFixed(3)}, `
      + `|K|·d² max ${s0.gaussMax.toFixed(4)} → ${s1.gaussMax.toFixed(4)}, rulings ${s0.rulings} → ${s1.rulings} (${s1.rulingSegments} segments), `
      + `solved ${st.lastSolved && st.lastSolved.reason}`);
    assert.ok(drags.length >= 5, `${drags.length} drag messages for 12 moves`);
    assert.ok(frames.sent.some((m) => m.type === 'drag_end'), 'drag_end on release');
    assertAcked(frames, target);
    assert.equal(st.lastError, null);
    assert.deepEqual(st.selection, target);
    assert.ok(moved > 0.2, `the control point followed the pointer (moved ${moved})`);
    assert.ok(distance(controlPoint(s1, 3), server.scene.model.control.points[3]) < 1e-3, 'the streamed control point is the scene\'s');
    assert.ok(s1.version > s0.version, 'new spline geometry arrived');
    assert.ok(surfaceMoved > 0.05, `the limit surface changed (by up to ${surfaceMoved})`);
    assert.ok(s1.rulings >= 1 && s1.rulingSegments > 0, `M^∞ has rulings after the release: ${s1.rulings}`);
    assert.equal(s1.drawnRulingSegments, s1.rulingSegments, 'every ruling segment is drawn');
    assert.equal(Number(await metric(page, 'metric-spline-rulings')), s1.rulings);
    assert.ok(Math.abs(await metric(page, 'metric-spline-gauss-max') - s1.gaussMax) <= 0.01 * s1.gaussMax, 'the panel follows the iterates');

    await h.settleFrames(page);
    const after = await h.screenshotViewport(page, '14-spline-limit-after');
    assert.ok(h.diffFraction(before.image, after.image) > 0.005, 'the picture of M^∞ changed');
    await h.screenshotPage(page, '14-spline-after-drag');
    // The rulings are on screen: their colour is there, and goes with the Rulings switch.
    const rulingPixels = countColor(after.image, RULING_RGB);
    await page.locator('.view-options label', { hasText: 'Rulings' }).locator('input').uncheck();
    await h.settleFrames(page);
    const noRulings = countColor((await h.screenshotViewport(page, '14-spline-limit-no-rulings')).image, RULING_RGB);
    console.log(`ruling pixels: ${rulingPixels} drawn, ${noRulings} with the rulings off`);
    assert.ok(rulingPixels >= 15 && noRulings < rulingPixels / 4, `the rulings are visible: ${rulingPixels} px (${noRulings} without them)`);
    await page.locator('.view-options label', { hasText: 'Rulings' }).locator('input').check();

    // The spline's B-spline patches export for CAD: STEP and IGES, from the export panel.
    const exported = async (testid) => {
      const [download] = await Promise.all([page.waitForEvent('download'), page.getByTestId(testid).click()]);
      return { name: download.suggestedFilename(), text: fs.readFileSync(await download.path(), 'latin1') };
    };
    const step = await exported('export-step');
    assert.match(step.name, /\.step$/);
    assert.match(step.text, /^ISO-10303-21;/);
    assert.match(step.text, /B_SPLINE_SURFACE/);
    const iges = await exported('export-iges');
    assert.match(iges.name, /\.igs$/);
    const lines = iges.text.split(/\r?\n/).filter((l) => l.length > 0);
    assert.ok(lines.every((l) => l.length === 80), 'IGES lines are 80 columns');
    assert.ok(lines.some((l) => l[72] === 'D' && /^ +128 /.test(l)), 'IGES has a rational B-spline surface (entity 128)');
    console.log(`exports: ${step.name} ${step.text.length} bytes, ${iges.name} ${lines.length} lines`);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

test('watertight 2 × 2 patches: the normal jump across shared sides is shown, live while dragging', { timeout: 300000 }, () =>
  ctx.guard('spline-watertight', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    const frames = recordFrames(page);
    const demo = await openDemo(page, daemon, 'demo-spline-watertight');
    const server0 = await daemon.session(demo.id, demo.view_token);
    const s0 = await spline(page);
    assert.equal(s0.patches, 4);
    assert.equal(s0.controls, server0.scene.model.control.points.length);
    assert.ok(s0.sharedSides >= 4, `2 × 2 patches share their inner sides: ${s0.sharedSides}`);
    assert.equal(s0.samples, 4 * 19 * 19);
    assert.equal(s0.points, s0.controls);
    assert.deepEqual(s0.visible, { layer: true, limit: true, rulings: true, net: true, mesh: false, meshEdges: false });
    assert.equal(await page.getByTestId('metric-spline-normal-jump').isVisible(), true);
    assert.match(await page.getByTestId('metric-spline-normal-jump').textContent(), new RegExp(`° \\(${s0.sharedSides} shared sides\\)$`));
    assert.ok(Math.abs(await metric(page, 'metric-spline-normal-jump') - s0.normalJump) <= 0.01 * s0.normalJump + 1e-9);
    assert.match(await page.getByTestId('metric-control-net').textContent(), /^121 points · 4 patches · k = 2$/);
    await h.screenshotPage(page, '14-spline-watertight-editor');
    const before = await h.screenshotViewport(page, '14-spline-watertight-before');
    // A long, thin model seen at an angle: it covers less of the view than the square patch.
    const stats = h.pixelStats(before.image);
    assert.ok(stats.distinct >= 64 && stats.dominantShare < 0.95, `the four patches are drawn: ${JSON.stringify(stats)}`);

    // Control point 38 lies inside a patch, off the shared sides (row 3, column 5 of 11 × 11).
    const target = { vertex: 38, on: 'control' };
    frames.sent.length = 0;
    frames.received.length = 0;
    const seen = [];
    await page.exposeFunction('__noteJump', (text) => seen.push(text));
    await page.evaluate(() => {
      const cell = document.querySelector('[data-testid="metric-spline-normal-jump"]');
      new MutationObserver(() => window.__noteJump(cell.textContent)).observe(cell, { childList: true, characterData: true, subtree: true });
    });
    const { st0 } = await dragControlPoint(page, 38, { dx: 0, dy: -30, steps: 10, shot: '14-spline-watertight-dragging' });
    await h.waitState(page, (st, n) => st.iterateCount > n, st0.iterateCount, { what: 'iterates after the release' });
    const { st, server } = await caughtUp(page, daemon, demo, server0.seq);
    const s1 = await spline(page);
    const moved = distance(controlPoint(s1, 38), controlPoint(s0, 38));
    console.log(`watertight drag: control point 38 moved ${moved.toFixed(3)}, normal jump ${s0.normalJump.toExponential(2)}° → ${s1.normalJump.toExponential(2)}°, `
      + `|K|·d² max ${s0.gaussMax.toFixed(4)} → ${s1.gaussMax.toFixed(4)}, ${seen.length} updates of the normal-jump cell, solved ${st.lastSolved && st.lastSolved.reason}`);
    assertAcked(frames, target);
    assert.equal(st.lastError, null);
    assert.ok(moved > 0.2, `the control point followed the pointer (moved ${moved})`);
    assert.ok(distance(controlPoint(s1, 38), server.scene.model.control.points[38]) < 1e-3);
    assert.ok(maxDelta(s1.samplesXYZ, s0.samplesXYZ) > 0.05, 'the limit surface changed');
    assert.ok(seen.length >= 2, `the normal jump was redrawn with the iterates (${seen.length} times)`);
    assert.ok(Math.abs(await metric(page, 'metric-spline-normal-jump') - s1.normalJump) <= 0.01 * s1.normalJump + 1e-9);
    await h.settleFrames(page);
    const after = await h.screenshotViewport(page, '14-spline-watertight-after');
    assert.ok(h.diffFraction(before.image, after.image) > 0.005, 'the picture changed');
    await h.screenshotPage(page, '14-spline-watertight-after-drag');

    // F fixes the selected control point: the scene lists it as {on: 'control', vertex}.
    assert.deepEqual(st.selection, target);
    await page.keyboard.press('f');
    const fixed = await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { s, ok: (s.scene.model.fixed || []).some((f) => f.on === 'control' && f.vertex === 38) };
    });
    assert.ok(fixed.ok, `control point 38 is fixed: ${JSON.stringify(fixed.s.scene.model.fixed)}`);
    await page.waitForFunction(() => /Control point 38 — fixed/.test(document.querySelector('.sel-title').textContent));
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));
