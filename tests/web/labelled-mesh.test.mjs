// 16. Editing a composite's labelled mesh in the browser (issue 16 item 3, 000_… §4.1): on the
//     curved box (three strips and two planar flaps), Shift-click two opposite corners of a flap
//     and "Split the face" adds a ruling between them (two triangles); picking that edge and
//     "Join its faces" takes it out again; "Make S" on a flap's side, with the opposite side,
//     turns the planar flap into a strip (S R S R) that has not moved; "Make S" on the side the
//     flap shares with a strip, alone, is refused (S R R R) and the error under the panel names
//     the face, the scene unchanged; undo brings the rulings back. Each edit is checked on the server's scene.
//     Screenshot: test-artifacts/web/16-labelled-mesh.png (the flap as a strip, its edge picked).
//     16b below: a chain of strips cut across (16-cut-across.png); 16c: a vertex added and removed.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('labelled-mesh', { demos: [] });

/** Corner k of face f of a scene model (where loop edges k − 1 and k meet). */
function cornersOf(model, f) {
  const loop = model.faces[f];
  return loop.map((e, k) => {
    const a = model.edges[loop[(k + loop.length - 1) % loop.length]].v;
    const b = model.edges[e].v;
    return a[0] === b[0] || a[0] === b[1] ? a[0] : a[1];
  });
}

async function serverModel(daemon, s) {
  return (await daemon.session(s.id, s.edit_token)).scene.model;
}

test('split a flap between two corners, join it again, make it a strip, a refusal names the face, undo', { timeout: 240000 }, () =>
  ctx.guard('labelled-mesh', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.readScene('composite-curved-box.json'));
    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });
    let st0 = await h.state(page);
    await page.getByTestId('solve').click();
    await h.waitState(page, (st, n) => st.lastSolved && st.lastSolved.seq > n, st0.seq, { what: 'the first solve' });
    await h.waitQuiet(page, { quietMs: 800 });
    await page.evaluate(() => window.__devsurf.editor.viewport.fit());
    await h.settleFrames(page);
    await page.getByTestId('labelled-mesh-edits').waitFor();

    const model0 = await serverModel(daemon, s);
    const flap = model0.faces.findIndex((l) => l.every((e) => model0.edges[e].type === 'R'));
    assert.ok(flap >= 0, 'the box has a planar flap');
    const corners = cornersOf(model0, flap);
    const [a, b] = [corners[0], corners[2]];

    // Split: click corner a, Shift-click corner b.
    let p = await h.pointPagePosition(page, { vertex: a });
    await page.mouse.click(p.x, p.y);
    await h.waitState(page, (st, v) => st.selection && st.selection.vertex === v, a, { what: `vertex ${a} selected` });
    p = await h.pointPagePosition(page, { vertex: b });
    await page.keyboard.down('Shift');
    await page.mouse.click(p.x, p.y);
    await page.keyboard.up('Shift');
    await h.waitState(page, (st) => st.group.length === 2, undefined, { what: 'two corners in the group' });
    assert.match(await page.getByTestId('split-face-hint').textContent(), new RegExp(`face ${flap}: a ruling from vertex ${a} to ${b}`));
    await page.getByTestId('split-face').click();
    await h.waitState(page, (st, n) => st.scene.model.faces.length === n + 1, model0.faces.length, { what: 'the flap split' });
    const split = await serverModel(daemon, s);
    assert.equal(split.faces.length, model0.faces.length + 1);
    const ruling = split.edges.length - 1;
    assert.deepEqual([...split.edges[ruling].v].sort(), [a, b].sort(), 'the new edge joins the two corners');
    assert.equal(split.edges[ruling].type, 'R');
    assert.ok(split.faces[flap].length === 3 && split.faces.at(-1).length === 3, 'two triangles');

    // Join: pick the new edge, "Join its faces".
    await page.getByTestId('crease-edge').selectOption(String(ruling));
    await page.getByTestId('merge-faces').click();
    await h.waitState(page, (st, n) => st.scene.model.faces.length === n, model0.faces.length, { what: 'the faces joined' });
    const joined = await serverModel(daemon, s);
    assert.equal(joined.edges.length, model0.edges.length);
    assert.deepEqual([...joined.faces[flap]].sort(), [...model0.faces[flap]].sort(), 'the flap as it was');

    // Make S without the opposite side: no face type (S R R R, or three S in the strip beside):
    // the button is disabled, and the hint says in words which face and why; nothing is sent.
    const side = model0.faces[flap].find((e) => model0.faces.filter((l) => l.includes(e)).length === 2);
    assert.ok(side !== undefined, 'the flap has an interior side');
    await page.getByTestId('crease-edge').selectOption(String(side));
    await page.getByTestId('relabel-opposite').uncheck();
    const relabel = page.getByTestId('relabel-edge');
    await page.waitForFunction(() => document.querySelector('[data-testid="relabel-edge"]').disabled, null, { timeout: 15000 });
    const hint = page.getByTestId('labelled-mesh-hint');
    assert.match(await hint.textContent(), /^Make S: face \d+: it would have .* curved \(S\) side/, 'the hint names the face');
    assert.match(await relabel.getAttribute('title'), new RegExp(`^Edge ${side} cannot be made S: face \\d+`));
    await h.screenshotPage(page, '16-labelled-mesh-refused');
    // A strip, where the flap was: its two sides next to that edge (boundary edges) made S together.
    const loop = model0.faces[flap];
    const boundarySide = loop[(loop.indexOf(side) + 1) % 4];
    await h.waitQuiet(page, { quietMs: 800 });
    const flat = await serverModel(daemon, s);
    await page.getByTestId('crease-edge').selectOption(String(boundarySide));
    await page.getByTestId('relabel-opposite').check();
    await page.getByTestId('relabel-edge').click();
    await h.waitState(page, (st, e) => st.scene.model.edges[e].type === 'S', boundarySide, { what: 'the sides made S' });
    const strip = await serverModel(daemon, s);
    const opposite = loop[(loop.indexOf(boundarySide) + 2) % 4];
    assert.equal(strip.edges[opposite].type, 'S', 'the opposite side too');
    const moved = Math.max(...strip.vertices.map((v, i) => Math.hypot(...v.map((x, k) => x - flat.vertices[i][k]))));
    assert.ok(moved < 1e-6, `nothing moved: ${moved}`);
    assert.equal(await page.getByTestId('relabel-edge').textContent(), 'Make R');
    await h.settleFrames(page);
    await h.screenshotPage(page, '16-labelled-mesh');

    // Undo: rulings again.
    await page.getByTestId('undo').click();
    await h.waitState(page, (st, e) => st.scene.model.edges[e].type === 'R', boundarySide, { what: 'undo: a ruling again' });
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));

// 16b. Cut across: on the two-crease sheet (three strips side by side between its curves), pick
//      a curve, type 30 % and "Cut across": every curve of the chain is cut there and every strip
//      becomes two, nothing moves (the server's vertices before and after), the new rulings are
//      drawn (screenshot 16-cut-across.png), and undo takes the cut back.
test('cut a chain of strips across along a new ruling at 30 % of a curve, nothing moves, undo', { timeout: 240000 }, () =>
  ctx.guard('cut-across', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.readScene('composite-two-creases.json'));
    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });
    await page.getByTestId('labelled-mesh-edits').waitFor();
    const model0 = await serverModel(daemon, s);
    const curve = model0.edges.findIndex((e) => e.type === 'S');
    assert.ok(curve >= 0, 'the sheet has a curve');
    const ruling = model0.edges.findIndex((e) => e.type === 'R');
    await page.getByTestId('crease-edge').selectOption(String(ruling));
    assert.equal(await page.getByTestId('split-along-ruling').isDisabled(), true, 'a ruling cannot be cut across');
    await page.getByTestId('crease-edge').selectOption(String(curve));
    assert.equal(await page.getByTestId('split-along-ruling').isDisabled(), false);
    await page.getByTestId('split-along-ruling-at').fill('30');
    await page.getByTestId('split-along-ruling').click();
    await h.waitState(page, (st, n) => st.scene.model.faces.length > n, model0.faces.length, { what: 'the strips cut' });
    const cut = await serverModel(daemon, s);
    const curves = model0.edges.filter((e) => e.type === 'S').length;
    assert.equal(cut.vertices.length, model0.vertices.length + curves, 'every curve of the chain cut once');
    assert.equal(cut.faces.length, model0.faces.length + curves - 1, 'every strip between them cut in two');
    const moved = Math.max(...model0.vertices.map((v, i) => Math.hypot(...v.map((x, k) => x - cut.vertices[i][k]))));
    assert.ok(moved < 1e-9, `nothing moved: ${moved}`);
    const added = cut.edges.slice(model0.edges.length + curves);
    assert.ok(added.length === curves - 1 && added.every((e) => e.type === 'R'), 'one new ruling per strip');
    // The cut point of the picked curve is 30 % along it (its parameter), near 30 % of its length.
    const polyline = (pts) => pts.reduce((sum, p, k) => (k ? sum + Math.hypot(...p.map((x, i) => x - pts[k - 1][i])) : 0), 0);
    const first = polyline(cut.edges[curve].points), whole = polyline(model0.edges[curve].points);
    console.log(`cut across: ${curves} curves cut, ${cut.faces.length - model0.faces.length} faces added; control polygon of the first piece ${(100 * first / whole).toFixed(1)} % of the curve's`);
    assert.ok(first / whole > 0.05 && first / whole < 0.5, 'the first piece is the shorter one');
    await h.waitQuiet(page, { quietMs: 800 });
    await page.evaluate(() => window.__devsurf.editor.viewport.fit());
    await h.settleFrames(page);
    await h.screenshotPage(page, '16-cut-across');
    await page.getByTestId('undo').click();
    await h.waitState(page, (st, n) => st.scene.model.faces.length === n, model0.faces.length, { what: 'undo: the strips whole again' });
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));

// 16c. A vertex added at the middle of a flap's side ("Add a vertex" on the picked ruling), then
//      clicked and removed ("Remove vertex"): the server's faces are the flap's again.
test('a vertex added on a flap side and removed again', { timeout: 240000 }, () =>
  ctx.guard('vertex-add-remove', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.readScene('composite-curved-box.json'));
    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });
    await page.getByTestId('labelled-mesh-edits').waitFor();
    const model0 = await serverModel(daemon, s);
    const flap = model0.faces.findIndex((l) => l.every((e) => model0.edges[e].type === 'R'));
    const side = model0.faces[flap].find((e) => model0.faces.filter((l) => l.includes(e)).length === 1);
    assert.ok(side !== undefined, 'the flap has a boundary side');
    await page.getByTestId('crease-edge').selectOption(String(side));
    await page.getByTestId('split-edge').click();
    await h.waitState(page, (st, n) => st.scene.model.vertices.length === n + 1, model0.vertices.length, { what: 'a vertex added' });
    const added = await serverModel(daemon, s);
    const w = model0.vertices.length;
    const [p0, p1] = model0.edges[side].v.map((v) => model0.vertices[v]);
    const mid = p0.map((x, i) => 0.5 * (x + p1[i]));
    assert.ok(Math.hypot(...added.vertices[w].map((x, i) => x - mid[i])) < 1e-9, 'at the middle of the side');
    assert.equal(added.faces[flap].length, model0.faces[flap].length + 1, 'the flap has a corner more');
    await h.waitQuiet(page, { quietMs: 500 });
    const p = await h.pointPagePosition(page, { vertex: w });
    await page.mouse.click(p.x, p.y);
    await h.waitState(page, (st, v) => st.selection && st.selection.vertex === v, w, { what: `vertex ${w} selected` });
    await page.getByTestId('remove-vertex').click();
    await h.waitState(page, (st, n) => st.scene.model.vertices.length === n, model0.vertices.length, { what: 'the vertex removed' });
    const removed = await serverModel(daemon, s);
    assert.deepEqual(removed.faces, model0.faces, 'the faces as they were');
    assert.deepEqual(removed.edges.map((e) => e.v), model0.edges.map((e) => e.v), 'the edges as they were');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));
