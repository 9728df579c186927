// 6. A composite demo (curved fold, lifted corner): the editor shows the folded sheet coloured by
//    face flatness and its crease pattern; dragging a vertex streams iterates and the release
//    solve keeps every face developable; switching the crease type of the fold edge is an
//    undoable edit; the development view has content and follows.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

// One demo: the demo it opens (a daemon with all demos takes ~20 s to start).
const ctx = h.useDaemonAndBrowser('composite', { demos: [path.join(h.EXAMPLES, 'composite-curved-fold.json')] });

test('a composite demo opens, a vertex drags, a crease type switches and undoes, the development follows', { timeout: 240000 }, () =>
  ctx.guard('composite', async () => {
    const { daemon } = ctx;
    const listed = (await daemon.api('GET', '/api/sessions')).body.sessions;
    const demo = listed.find((s) => s.id === 'demo-composite-curved-fold');
    assert.ok(demo, `the composite example is a demo session: ${listed.map((s) => s.id).join(', ')}`);

    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(demo.id, demo.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });
    await page.getByTestId('crease-panel').waitFor();
    const dev = page.getByTestId('development-view');
    await page.waitForFunction(() => Number(document.querySelector('[data-testid="development-view"]').dataset.polygons) > 0);
    const polygons0 = Number(await dev.getAttribute('data-polygons'));
    assert.ok(polygons0 > 0, `the development view drew ${polygons0} polygons`);
    assert.equal((await page.getByTestId('legend-title').textContent()).trim(), 'face flatness δ');
    await h.screenshotPage(page, '06-composite-editor');
    const before = await h.screenshotViewport(page, '06-composite-before-drag');
    const stats = h.pixelStats(before.image);
    assert.ok(stats.distinct >= 64 && stats.dominantShare < 0.97, `the 3D view is drawn: ${JSON.stringify(stats)}`);

    // Drag vertex 3 (the lifted corner) upwards on screen.
    const server0 = await daemon.session(demo.id, demo.view_token);
    const z0 = server0.scene.model.vertices[3][2];
    const from = await h.pointPagePosition(page, { vertex: 3 });
    const st0 = await h.dragAndSettle(page, from, { dy: -50, steps: 10, pauseMs: 50 });
    const done = await h.poll(async () => {
      const st = await h.state(page);
      const server = await daemon.session(demo.id, demo.view_token);
      return { st, server, ok: st.seq === server.seq && server.seq > server0.seq && st.lastSolved && st.lastSolved.seq === server.seq };
    });
    const { st, server } = done;
    assert.ok(done.ok, `the page caught up with the server's solve of the drag (page seq ${st.seq}, solved ${st.lastSolved && st.lastSolved.seq}, server seq ${server.seq})`);
    console.log(`composite drag: ${st.iterateCount - st0.iterateCount} iterates, vertex 3 z ${z0} → ${server.scene.model.vertices[3][2]}, `
      + `face flatness max ${server.metrics.face_flatness_max}, crease residual ${server.metrics.crease_fold_residual_max}`);
    assert.equal(st.lastError, null);
    assert.ok(Math.abs(server.scene.model.vertices[3][2] - z0) > 0.02, 'vertex 3 moved');
    assert.ok(server.metrics.face_flatness_max < 1e-2, `faces stay developable: δ = ${server.metrics.face_flatness_max}`);
    await h.settleFrames(page);
    const after = await h.screenshotViewport(page, '06-composite-after-drag');
    assert.ok(h.diffFraction(before.image, after.image) > 0.005, 'the picture changed');

    // Select the fold edge by its diamond in the 3D view, switch it to smooth, then undo.
    const mid = await page.evaluate(() => window.__devsurf.edgeScreenPosition(0));
    const box = await page.getByTestId('viewport').boundingBox();
    await page.mouse.click(box.x + mid.x, box.y + mid.y);
    await h.waitState(page, (s) => s.selectedEdge === 0, undefined, { what: 'edge 0 selected' });
    assert.equal(await page.getByTestId('crease-edge').inputValue(), '0');
    assert.equal(await page.getByTestId('crease-type').inputValue(), 'fold');
    await page.getByTestId('crease-type').selectOption('smooth');
    await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { ok: s.scene.model.edges[0].crease === 'smooth' };
    });
    await page.waitForFunction(() => document.querySelector('[data-testid="crease-type"]').value === 'smooth');
    await page.getByTestId('solve').click();
    await h.waitQuiet(page);
    await h.screenshotPage(page, '06-composite-smooth');
    // Solve is an edit of its own: the first undo takes the solve back, the second the switch.
    const beforeUndo = await daemon.session(demo.id, demo.view_token);
    await page.getByTestId('undo').click();
    await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { ok: s.seq > beforeUndo.seq && s.scene.model.edges[0].crease === 'smooth' };
    });
    await h.waitQuiet(page);
    await page.getByTestId('undo').click();
    await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { ok: s.scene.model.edges[0].crease === 'fold' };
    });
    await page.waitForFunction(() => document.querySelector('[data-testid="crease-type"]').value === 'fold');

    // The development view still has content after all that; colour by vertex curvature.
    const polygons1 = Number(await dev.getAttribute('data-polygons'));
    assert.ok(polygons1 > 0, `the development view drew ${polygons1} polygons`);
    const devShot = await page.screenshot({ path: `${h.ARTIFACTS}/06-composite-development.png`, clip: await dev.boundingBox() });
    const devStats = h.pixelStats(h.decodePNG(devShot));
    assert.ok(devStats.distinct >= 16 && devStats.dominantShare < 0.95, `the development is drawn: ${JSON.stringify(devStats)}`);
    await page.getByTestId('color-mode').selectOption('curvature');
    assert.equal((await page.getByTestId('legend-title').textContent()).trim(), 'vertex curvature');
    await h.screenshotPage(page, '06-composite-curvature');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

/** Vertex 3 dragged 40 px up in ten steps; the page's and the server's state once it is solved. */
async function dragVertexThreeUp(page, daemon, demo, afterSeq) {
  await h.dragAndSettle(page, await h.pointPagePosition(page, { vertex: 3 }), { dy: -40, steps: 10, pauseMs: 50 });
  const done = await h.poll(async () => {
    const st = await h.state(page);
    const server = await daemon.session(demo.id, demo.view_token);
    return { st, server, ok: st.lastSolved && st.lastSolved.seq === server.seq && server.seq > afterSeq };
  });
  assert.ok(done.ok, 'the drag was solved');
  return done;
}

/** The shared curved-fold demo in an editor: its session entry, the page and the session's state. */
async function openCurvedFoldDemo(daemon) {
  const demo = (await daemon.api('GET', '/api/sessions')).body.sessions.find((s) => s.id === 'demo-composite-curved-fold');
  const page = await ctx.page();
  await h.openEditor(page, daemon.editorUrl(demo.id, demo.edit_token));
  await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });
  return { demo, page, before: await daemon.session(demo.id, demo.view_token) };
}

test('the Solver panel solves a composite\'s development apart, and a drag keeps the development isometric', { timeout: 240000 }, () =>
  ctx.guard('composite-development-apart', async () => {
    const { daemon } = ctx;
    const { demo, page, before } = await openCurvedFoldDemo(daemon);
    assert.ok(before.scene.model.development, 'the demo has a development');
    assert.equal(before.scene.solver.development_solve, 'coupled', 'the demo solves its development with the surface');
    const control = page.locator('[data-setting="development_solve"] select');
    assert.ok(await control.isVisible(), 'a composite with a development offers the choice');
    await control.selectOption({ label: 'apart (faster)' });
    const switched = await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { s, ok: s.scene.solver.development_solve === 'alternating' };
    });
    assert.ok(switched.ok, 'the server solves the development apart');
    await page.waitForFunction(() => window.__devsurf.state.scene.solver.development_solve === 'alternating');

    const done = await dragVertexThreeUp(page, daemon, demo, switched.s.seq);
    const m = done.server.metrics;
    console.log(`development apart: after the drag development length error ${m.development_length_error}, `
      + `flatness ${m.face_flatness_max}, warp ${m.warp_angle_max_deg}°`);
    assert.ok(m.development_length_error < 5e-3, `development length error ${m.development_length_error}`);
    assert.ok(m.face_flatness_max < 1e-3, `face flatness ${m.face_flatness_max}`);
    assert.equal(done.st.lastError, null);
    assert.equal(await control.evaluate((el) => el.options[el.selectedIndex].text), 'apart (faster)');
    await h.screenshotPage(page, '06-composite-development-apart');
    // Back with the surface: the demo is shared with the tests that follow.
    await control.selectOption({ label: 'with the surface' });
    const back = await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { s, ok: s.scene.solver.development_solve === 'coupled' };
    });
    assert.ok(back.ok, 'the demo solves its development with the surface again');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

test('the Solver panel switches a composite to normal splines, and a drag keeps it developable', { timeout: 240000 }, () =>
  ctx.guard('composite-normal-splines', async () => {
    const { daemon } = ctx;
    const { demo, page, before } = await openCurvedFoldDemo(daemon);
    assert.equal(before.scene.solver.normal_splines, false, 'the demo ships with free normals');
    const unknowns0 = before.metrics.unknowns;

    // "normals: spline" in the Solver panel is the solver's normal_splines on a composite.
    await page.locator('[data-setting="normals"] select').selectOption('spline');
    const switched = await h.poll(async () => {
      const s = await daemon.session(demo.id, demo.view_token);
      return { s, ok: s.scene.solver.normal_splines === true };
    });
    assert.ok(switched.ok, 'the server has normal splines on');
    assert.ok(switched.s.metrics.unknowns < unknowns0, `fewer unknowns: ${switched.s.metrics.unknowns} < ${unknowns0}`);
    await page.waitForFunction(() => window.__devsurf.state.scene.solver.normal_splines === true);
    // The spline's control-point count belongs to strips; a composite's follows its curves.
    assert.equal(await page.locator('[data-setting="normals"] select').inputValue(), 'spline');

    const done = await dragVertexThreeUp(page, daemon, demo, switched.s.seq);
    const m = done.server.metrics;
    console.log(`normal splines: ${unknowns0} → ${m.unknowns} unknowns; after the drag warp ${m.warp_angle_max_deg}°, `
      + `flatness ${m.face_flatness_max}, crease residual ${m.crease_fold_residual_max}`);
    assert.ok(m.warp_angle_max_deg < 0.05, `warp ${m.warp_angle_max_deg}°`);
    assert.ok(m.face_flatness_max < 1e-3, `face flatness ${m.face_flatness_max}`);
    assert.equal(done.st.lastError, null);
    await h.screenshotPage(page, '06-composite-normal-splines');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

/** "New session from an example" on the start page: the curved fold, in a session of its own. */
async function openCurvedFoldExample(page, daemon) {
  await page.goto(daemon.url);
  await page.getByTestId('start-page').waitFor();
  await page.getByTestId('preset-select').selectOption('composite-curved-fold');
  await page.getByTestId('new-session').click();
  await page.getByTestId('editor').waitFor({ timeout: 30000 });
  await h.waitForConnected(page);
  await h.waitState(page, (st) => st.kind === 'composite' && st.scene, undefined, { what: 'the new composite session' });
}

test('an example opens as its picture shows it, and its first fold lets go of the handle and can be undone', { timeout: 240000 }, () =>
  ctx.guard('composite-example-fold', async () => {
    const { daemon } = ctx;
    // "New session from an example": the curved fold with its corner's handle, solved at opening.
    const page = await ctx.page();
    await openCurvedFoldExample(page, daemon);
    const url = new URL(page.url());
    const s = { id: url.searchParams.get('session'), token: url.searchParams.get('token') };
    const opened = await daemon.session(s.id, s.token);
    assert.ok(opened.scene.model.vertices[3][2] > 0.5, `the corner is lifted as the example's picture shows: z = ${opened.scene.model.vertices[3][2]}`);
    assert.equal(opened.scene.model.handles.length, 1);
    const undoButton = page.getByTestId('undo');
    assert.ok(await undoButton.isDisabled(), 'nothing to undo yet');

    // The first fold takes the design's folds as 100 % and lets go of the handle: the editor
    // learns it at once (no handle drawn) and can undo it.
    await page.getByTestId('fold-slider').fill('50');
    await h.waitState(page, (st) => st.constraints.handles.length === 0, undefined, { what: 'the handle let go in the editor' });
    await h.waitState(page, (st) => st.metrics && Math.abs(st.metrics.fold_amount - 0.5) < 1e-9, undefined, { what: 'fold 50 %' });
    await h.waitQuiet(page, { quietMs: 1000 });
    assert.ok(await undoButton.isEnabled(), `undo offered after the fold: ${await undoButton.getAttribute('title')}`);
    const folded = await daemon.session(s.id, s.token);
    assert.equal((folded.scene.model.handles || []).length, 0, 'the server let go of it too');
    assert.ok(folded.scene.model.vertices[3][2] < opened.scene.model.vertices[3][2], 'half folded, the corner is lower');

    // A second gesture is one more step; undoing both brings the handle and the lifted corner back.
    await page.getByTestId('fold-slider').fill('30');
    await h.waitState(page, (st) => st.metrics && Math.abs(st.metrics.fold_amount - 0.3) < 1e-9, undefined, { what: 'fold 30 %' });
    await h.waitQuiet(page, { quietMs: 1000 });
    await h.waitState(page, (st) => st.undo.available >= 2, undefined, { what: 'two undo steps known to the editor' });
    await undoButton.click();
    await h.waitState(page, (st) => st.metrics && Math.abs(st.metrics.fold_amount - 0.5) < 1e-9, undefined, { what: 'back to 50 %' });
    await undoButton.click();
    await h.waitState(page, (st) => st.constraints.handles.length === 1, undefined, { what: 'the handle back in the editor' });
    const back = await daemon.session(s.id, s.token);
    assert.equal(back.scene.model.handles.length, 1);
    assert.ok(Math.abs(back.scene.model.vertices[3][2] - opened.scene.model.vertices[3][2]) < 1e-6, 'the design as it opened');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

test('arrow keys on the fold slider are one gesture: one release when the keys rest, where the slider shows', { timeout: 240000 }, () =>
  ctx.guard('composite-fold-keys', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    const sent = [];
    page.on('websocket', (ws) => ws.on('framesent', ({ payload }) => sent.push(String(payload))));
    await openCurvedFoldExample(page, daemon);
    const ends = () => sent.filter((f) => f.includes('"fold_end"')).length;
    // To 0 % with a key, then up by twenty presses of → (a range input fires `change` at each one).
    const slider = page.getByTestId('fold-slider');
    await slider.focus();
    await page.keyboard.press('Home');
    for (let i = 0; i < 20; ++i) await page.keyboard.press('ArrowRight');
    await h.waitState(page, (st) => st.metrics && Math.abs(st.metrics.fold_amount - 0.2) < 1e-9, undefined, { what: 'fold 20 %' });
    await h.waitQuiet(page, { quietMs: 1500 });
    assert.equal(ends(), 1, `one fold_end for the whole key gesture, not one per key: ${ends()}`);
    assert.equal((await page.getByTestId('fold-amount').textContent()).trim(), '20 %');
    const url = new URL(page.url());
    const folded = await daemon.session(url.searchParams.get('session'), url.searchParams.get('token'));
    assert.ok(Math.abs(folded.scene.model.fold_amount - 0.2) < 1e-9, `the session rests at 20 %: ${folded.scene.model.fold_amount}`);
    // A mouse-like change (no key) still ends its gesture at once.
    await slider.fill('40');
    await h.waitState(page, (st) => st.metrics && Math.abs(st.metrics.fold_amount - 0.4) < 1e-9, undefined, { what: 'fold 40 %' });
    await h.waitQuiet(page, { quietMs: 1000 });
    assert.equal(ends(), 2);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));
