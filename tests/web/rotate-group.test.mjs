// 14. Rotate a selected group (issue 16, item 3; 000_… §4.1 Fig. 8 bottom row): in a composite,
//     Shift-click picks vertices of an outer flap into a group (drawn as white rings); the
//     Selection panel counts them, shows their centroid, and turns them about the vertical axis
//     through it by the typed angle (rotate_points), then solves; undo takes the turn back.
//     First with "solve" 0 (the turn alone: exactly 20° about the vertical through the centroid),
//     then with the session's solve (R key): the solve makes the composite developable again; a
//     handle on a turned point turns with it, so that point keeps the turn, while a free point of
//     the flap is partly turned back (turning a flap about a vertical axis would stretch it). Plain click and Esc leave a single selection / none.
//     Screenshot: test-artifacts/web/14-rotate-group.png.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('rotate-group', { demos: [path.join(h.EXAMPLES, 'composite-two-creases.json')] });

// The right outer flap of composite-two-creases: vertices 1 2 3 4; 1 and 4 are fixed (they hold
// the middle piece), 3 has a handle (target [2.7, 2, 0.8]); 2 is free.
const GROUP = [2, 3, 4];

const sub = (a, b) => a.map((x, k) => x - b[k]);
const centroidOf = (points) => [0, 1, 2].map((k) => points.reduce((s, p) => s + p[k], 0) / points.length);
/** Signed turn (degrees, counter-clockwise seen from +z) of p → q about the vertical through c. */
function turnAboutZ(p, q, c) {
  const a = sub(p, c);
  const b = sub(q, c);
  return (Math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1]) * 180) / Math.PI;
}

async function vertices(daemon, s) {
  return (await daemon.session(s.id, s.edit_token)).scene.model.vertices;
}

/** Waits until the page has seen the server's latest edit and its `solved`, after `seq0`. */
async function waitSolvedAfter(page, daemon, s, seq0, what) {
  await h.waitState(page, (st, n) => st.lastSolved && st.lastSolved.seq > n, seq0, { what: `solved after ${what}` });
  await h.waitQuiet(page, { quietMs: 800 });
  const done = await h.poll(async () => {
    const st = await h.state(page);
    const server = await daemon.session(s.id, s.edit_token);
    return { st, server, ok: st.seq === server.seq && st.lastSolved && st.lastSolved.seq === server.seq };
  });
  assert.ok(done.ok, `${what}: the page caught up with the server (page seq ${done.st.seq}, solved ${done.st.lastSolved && done.st.lastSolved.seq}, server ${done.server.seq})`);
  return done;
}

/** Waits until the server's vertices are `expected` again (an undo). */
async function waitRestored(daemon, s, expected, what) {
  const r = await h.poll(async () => {
    const v = await vertices(daemon, s);
    const err = Math.max(...GROUP.map((i) => Math.hypot(...sub(v[i], expected[i]))));
    return { v, err, ok: err < 1e-6 };
  });
  assert.ok(r.ok, `${what}: the group is back where it was (max distance ${r.err})`);
}

test('Shift-click a group of vertices, turn it about z, solve, undo', { timeout: 240000 }, () =>
  ctx.guard('rotate-group', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.readScene('composite-two-creases.json'));
    const page = await ctx.page();
    const sent = [];
    page.on('websocket', (ws) => ws.on('framesent', (f) => { try { sent.push(JSON.parse(f.payload)); } catch { /* binary */ } }));
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });

    // Solve first: the handles lift the outer flaps (the scene starts flat).
    let st0 = await h.state(page);
    await page.getByTestId('solve').click();
    await waitSolvedAfter(page, daemon, s, st0.seq, 'the first solve');
    await page.evaluate(() => window.__devsurf.editor.viewport.fit());
    await h.settleFrames(page);

    // A plain click selects vertex 2 alone; Shift-click adds 3 and 4: a group of three.
    await page.getByTestId('group-rotate').waitFor({ state: 'hidden' });
    const at = async (v) => h.pointPagePosition(page, { vertex: v });
    let p = await at(GROUP[0]);
    await page.mouse.click(p.x, p.y);
    await h.waitState(page, (st) => st.selection && st.selection.vertex === 2 && st.group.length === 0, undefined, { what: 'vertex 2 selected' });
    assert.equal((await page.getByTestId('group-count').textContent()).trim(), '1 point selected');
    await page.keyboard.down('Shift');
    for (const v of GROUP.slice(1)) {
      p = await at(v);
      await page.mouse.click(p.x, p.y);
    }
    await page.keyboard.up('Shift');
    await h.waitState(page, (st, want) => JSON.stringify(st.group.map((t) => t.vertex)) === JSON.stringify(want), GROUP,
      { what: `the group ${GROUP}` });
    assert.equal((await page.getByTestId('group-count').textContent()).trim(), `${GROUP.length} points selected`);
    // Shift-click toggles: 3 out and in again.
    p = await at(3);
    await page.keyboard.down('Shift');
    await page.mouse.click(p.x, p.y);
    await h.waitState(page, (st) => st.group.length === 2, undefined, { what: 'vertex 3 out of the group' });
    await page.mouse.click(p.x, p.y);
    await page.keyboard.up('Shift');
    await h.waitState(page, (st) => st.group.length === 3, undefined, { what: 'vertex 3 back in the group' });

    // The panel shows the group's centroid.
    const v0 = await vertices(daemon, s);
    const c0 = centroidOf(GROUP.map((i) => v0[i]));
    for (const [k, axis] of ['x', 'y', 'z'].entries()) {
      const shown = Number(await page.getByTestId(`rotate-centre-${axis}`).inputValue());
      assert.ok(Math.abs(shown - c0[k]) < 1e-3, `centre ${axis}: shown ${shown}, centroid ${c0[k]}`);
    }

    // 1. The turn alone (solve: 0 iterations): exactly 20° about the vertical through the centroid.
    await page.getByTestId('rotate-axis-z').click();
    assert.equal(await page.getByTestId('rotate-axis-z').getAttribute('aria-pressed'), 'true');
    await page.getByTestId('rotate-angle').fill('20');
    await page.getByTestId('rotate-iterations').fill('0');
    st0 = await h.state(page);
    await page.getByTestId('rotate-group').click();
    await waitSolvedAfter(page, daemon, s, st0.seq, 'the turn alone');
    const message = sent.filter((m) => m.type === 'rotate_points').pop();
    const { op, targets, ...rest } = message;
    assert.ok(op !== undefined, 'the message has an op id');
    assert.deepEqual(targets.map((t) => t.vertex).sort(), GROUP, `the group sent: ${JSON.stringify(targets)}`);
    assert.deepEqual(targets.map((t) => Object.keys(t)), GROUP.map(() => ['vertex']));
    assert.deepEqual(rest, { type: 'rotate_points', axis: [0, 0, 1], angle: 20, iterations: 0 });
    const v1 = await vertices(daemon, s);
    for (const i of GROUP) {
      const turned = turnAboutZ(v0[i], v1[i], c0);
      const r0 = Math.hypot(v0[i][0] - c0[0], v0[i][1] - c0[1]);
      const r1 = Math.hypot(v1[i][0] - c0[0], v1[i][1] - c0[1]);
      console.log(`turn alone: vertex ${i} turned ${turned.toFixed(3)}° (radius ${r0.toFixed(4)} → ${r1.toFixed(4)}, z ${v0[i][2].toFixed(4)} → ${v1[i][2].toFixed(4)})`);
      assert.ok(Math.abs(turned - 20) < 0.5, `vertex ${i} turned by ${turned}° about the vertical through the centroid, not 20°`);
      assert.ok(Math.abs(r1 - r0) < 1e-6 && Math.abs(v1[i][2] - v0[i][2]) < 1e-6, `vertex ${i} kept its distance to the axis and its height`);
    }
    // Undo (the toolbar button) takes it back: one step.
    await page.getByTestId('undo').click();
    await waitRestored(daemon, s, v0, 'undo of the turn alone');

    // 2. With the session's solve (blank: the release iterations), by the R key.
    await page.getByTestId('rotate-iterations').fill('');
    await page.evaluate(() => document.activeElement && document.activeElement.blur());
    st0 = await h.state(page);
    const iterates0 = st0.iterateCount;
    await page.keyboard.press('r');
    const { st, server } = await waitSolvedAfter(page, daemon, s, st0.seq, 'the turn and its solve');
    const message2 = sent.filter((m) => m.type === 'rotate_points').pop();
    assert.equal(message2.angle, 20);
    assert.equal(message2.iterations, undefined);
    assert.ok(st.lastSolved.iterations > 0 && st.iterateCount > iterates0, `the turn was solved: ${JSON.stringify(st.lastSolved)}, ${st.iterateCount - iterates0} iterates`);
    const v2 = server.scene.model.vertices;
    const turns = Object.fromEntries(GROUP.map((i) => [i, turnAboutZ(v0[i], v2[i], c0)]));
    console.log(`turn and solve: ${JSON.stringify(Object.fromEntries(Object.entries(turns).map(([i, a]) => [i, Number(a.toFixed(2))])))}°, `
      + `solved ${st.lastSolved.reason} after ${st.lastSolved.iterations} iterations, face flatness ${server.metrics.face_flatness_max}`);
    // Vertex 4 is fixed: it stays where the turn put it. Vertex 2 (free) keeps part of the turn;
    // vertex 3 goes back to its handle's target.
    assert.ok(Math.abs(turns[4] - 20) < 0.5, `fixed vertex 4 turned ${turns[4]}°`);
    assert.ok(turns[2] > 1 && turns[2] < 21, `free vertex 2 turned ${turns[2]}° (part of 20°)`);
    const handle = server.scene.model.handles.find((x) => x.vertex === 3);
    assert.ok(Math.hypot(...sub(v2[3], handle.position)) < 0.05, `vertex 3 is at its handle's target: ${v2[3]} vs ${handle.position}`);
    assert.ok(server.metrics.face_flatness_max < 1e-2, `faces developable after the solve: δ = ${server.metrics.face_flatness_max}`);
    assert.equal(st.lastError, null);

    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, '14-rotate-group.png') });

    // Undo (Ctrl+Z) takes the turn and its solve back in one step.
    await page.keyboard.press('Control+z');
    await waitRestored(daemon, s, v0, 'undo of the turn and its solve');

    // Esc clears the group and the selection; a plain click selects one point again.
    await page.keyboard.press('Escape');
    await h.waitState(page, (x) => x.group.length === 0 && !x.selection, undefined, { what: 'nothing selected after Esc' });
    await page.getByTestId('group-rotate').waitFor({ state: 'hidden' });
    p = await at(2);
    await page.keyboard.down('Shift');
    await page.mouse.click(p.x, p.y);
    p = await at(3);
    await page.mouse.click(p.x, p.y);
    await page.keyboard.up('Shift');
    await h.waitState(page, (x) => x.group.length === 2, undefined, { what: 'a group of two' });
    p = await at(4);
    await page.mouse.click(p.x, p.y);
    await h.waitState(page, (x) => x.group.length === 0 && x.selection && x.selection.vertex === 4, undefined, { what: 'a plain click: vertex 4 alone' });
    assert.equal((await page.getByTestId('group-count').textContent()).trim(), '1 point selected');
    assert.equal((await h.state(page)).lastError, null);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));

test('a selected curve point: insert one after it, then remove one', { timeout: 180000 }, () =>
  ctx.guard('curve-points', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.readScene('composite-two-creases.json'));
    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });
    await page.evaluate(() => window.__devsurf.editor.viewport.fit());
    await h.settleFrames(page);
    const scene0 = (await daemon.session(s.id, s.edit_token)).scene;
    const edge = scene0.model.edges.findIndex((e) => e.type === 'S');
    const inner0 = scene0.model.edges[edge].points.length;
    await page.getByTestId('curve-points').waitFor({ state: 'hidden' });
    const p = await h.pointPagePosition(page, { edge, index: 1 });
    await page.mouse.click(p.x, p.y);
    await h.waitState(page, (st, e) => st.selection && st.selection.edge === e && st.selection.index === 1, edge, { what: `control point 1 of edge ${edge} selected` });
    await page.getByTestId('curve-points').waitFor({ state: 'visible' });

    await page.getByTestId('curve-point-add').click();
    const grown = await h.poll(async () => {
      const sc = (await daemon.session(s.id, s.edit_token)).scene;
      return { sc, ok: sc.model.edges[edge].points.length === inner0 + 1 };
    });
    assert.ok(grown.ok, `edge ${edge} has one more control point (${inner0} → ${grown.sc.model.edges[edge].points.length} interior)`);
    // The curve keeps its ends (that it does not move at all is checked exactly in
    // tests/server/SessionControlPointsTest.cpp).
    assert.deepEqual(grown.sc.model.edges[edge].v, scene0.model.edges[edge].v);

    await page.getByTestId('curve-point-remove').click();
    const shrunk = await h.poll(async () => {
      const sc = (await daemon.session(s.id, s.edit_token)).scene;
      return { sc, ok: sc.model.edges[edge].points.length === inner0 };
    });
    assert.ok(shrunk.ok, `one control point removed again (${shrunk.sc.model.edges[edge].points.length} interior)`);
    assert.equal((await h.state(page)).lastError, null);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));
