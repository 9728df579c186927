// 13. Drawing the crease pattern (issue 16, item 3): a blank sheet made on the start page opens
//     as a flat composite with its drawing; on the crease-pattern board a curved valley crease is
//     drawn from the left edge to the right edge (its ends snapped onto the outline), which splits
//     the sheet into faces (2 sides, split again by proposed rulings) along folding S edges; relabelled mountain, undone back to valley;
//     its fold angle typed and entered (one edit, one undo step), undone; a
//     straight crease ending in the middle of the sheet is refused by the server (said on the board,
//     the drawing unchanged); the Fold slider then folds the design to 100 %, and the FOLD export
//     (read with npm fold) has the curved valley folded by about 90°.
//     Screenshots: test-artifacts/web/13-draw-creases-board.png (the board) and
//     13-draw-creases.png (the folded design) — look at them.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import fold from 'fold';
import * as h from './lib/harness.mjs';
import * as rb from './lib/readback.mjs';

const ctx = h.useDaemonAndBrowser('draw-creases', { demos: [] });

const strokesOf = (s) => s.scene.model.drawing.strokes;

/** Client px of a sheet point on the open board. */
async function boardPoint(page, p) {
  const q = await page.evaluate((pt) => window.__devsurf.creaseBoardPoint(pt), p);
  if (!q || !Number.isFinite(q.x) || !Number.isFinite(q.y)) throw new Error(`no board position for ${p}: ${JSON.stringify(q)}`);
  return q;
}

async function boardAttr(page, name) {
  return page.getByTestId('crease-board').getAttribute(name);
}

test('a design from a blank sheet', { timeout: 240000 }, () =>
  ctx.guard('draw-creases', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    // A blank sheet, 200 × 150 mm, from the start page.
    const { x0, x1, y0, y1, outline } = await openBlankSheet(page, daemon);
    const start = await h.state(page);
    assert.equal(start.scene.model.fold_amount ?? 0, 0);
    assert.ok(outline.length >= 1 && outline.every((s) => s.assignment === 'B'), `a blank sheet's drawing is its outline: ${JSON.stringify(outline)}`);
    assert.equal(start.scene.model.faces.length, 1);
    // Nothing to fold yet: the slider and Play are off and say what to do (a tryout's Play on a
    // blank sheet sent a refused fold every frame and covered the panel with errors).
    await page.waitForFunction(() => document.querySelector('[data-testid="fold-play"]').disabled, null, { timeout: 15000 });
    assert.ok(await page.getByTestId('fold-slider').isDisabled(), 'the slider is off on a blank sheet');
    assert.match(await page.getByTestId('fold-nothing').textContent(), /Nothing to fold yet: draw a mountain or valley crease/);

    // The board, over the 3D view.
    await page.getByTestId('draw-creases').click();
    await page.getByTestId('crease-board').waitFor({ state: 'visible' });
    assert.equal(await boardAttr(page, 'data-strokes'), String(outline.length));
    const box = await page.getByTestId('crease-board').boundingBox();
    assert.ok(box.width > 800 && box.height > 500, `a large drawing area: ${box.width} × ${box.height}`);

    // A curved valley (the default) from the left edge to the right edge: 5 clicks, the last a
    // double-click; the ends are clicked 1.2 mm inside the sheet and snap onto the outline.
    await page.getByTestId('crease-tool-curve').click();
    assert.equal(await page.getByTestId('crease-assignment-V').getAttribute('aria-pressed'), 'true');
    const ym = (y0 + y1) / 2;
    const arc = [[x0 + 1.2, ym], [x0 + 50, ym + 11], [x0 + 100, ym + 15], [x0 + 150, ym + 11], [x1 - 1.2, ym]];
    for (const [k, p] of arc.entries()) {
      const q = await boardPoint(page, p);
      await page.mouse.move(q.x, q.y, { steps: 3 });
      if (k === 0 || k === arc.length - 1) {
        const snap = await page.locator('[data-testid="crease-board"] [data-snap]').getAttribute('data-snap');
        assert.equal(snap, 'stroke', `the end ${k} snaps onto the outline`);
      }
      if (k < arc.length - 1) await page.mouse.click(q.x, q.y);
      else await page.mouse.dblclick(q.x, q.y);
    }
    await h.waitState(page, (s, n) => s.scene.model.drawing.strokes.length === n + 1, outline.length, { what: 'the crease drawn' });
    await page.waitForFunction((n) => document.querySelector('[data-testid="crease-board"]').dataset.strokes === String(n), outline.length + 1);
    const drawn = await h.state(page);
    const index = strokesOf(drawn).findIndex((s) => s.assignment !== 'B');
    const crease = strokesOf(drawn)[index];
    assert.equal(crease.assignment, 'V');
    assert.equal(crease.curved, true);
    assert.equal(crease.points.length, 5, `the 5 points clicked: ${JSON.stringify(crease.points)}`);
    assert.ok(Math.abs(crease.points[0][0] - x0) < 1e-6 && Math.abs(crease.points[4][0] - x1) < 1e-6,
      `the ends on the left and right edges: ${JSON.stringify(crease.points)}`);
    assert.equal(crease.fold_angle, 90, 'a valley of 90° (the board\'s default)');
    const model = drawn.scene.model;
    // The sheet is split in two by the crease (the server may split each side further along
    // the rulings it proposes to the crease's points: 4 faces for this arc).
    assert.ok(model.faces.length >= 2, `the sheet split in two: ${model.faces.length} faces`);
    assert.ok(model.edges.some((e) => e.type === 'S' && e.crease === 'fold'), `the curved crease is a folding S edge: ${JSON.stringify(model.edges.map((e) => [e.type, e.crease]))}`);
    assert.equal(drawn.lastError, null);

    // Select it (a click on one of its points: the curve passes through them) and relabel it mountain.
    await page.getByTestId('crease-tool-select').click();
    const mid = await boardPoint(page, arc[2]);
    await page.mouse.click(mid.x, mid.y);
    await page.waitForFunction((i) => document.querySelector('[data-testid="crease-board"]').dataset.selected === String(i), index);
    assert.equal(await page.getByTestId('crease-angle').inputValue(), '90');
    await page.getByTestId('crease-assignment-M').click();
    await h.waitState(page, (s, i) => s.scene.model.drawing.strokes[i].assignment === 'M', index, { what: 'the crease relabelled mountain' });
    const mountain = strokesOf(await h.state(page))[index];
    assert.equal(mountain.fold_angle, -90, 'a mountain of the same 90°');
    assert.equal(await page.getByTestId('crease-assignment-M').getAttribute('aria-pressed'), 'true');

    // Undo: a valley again.
    await page.getByTestId('undo').click();
    await h.waitState(page, (s, i) => s.scene.model.drawing.strokes[i].assignment === 'V', index, { what: 'a valley again after undo' });
    assert.equal((await h.state(page)).scene.model.drawing.strokes.length, outline.length + 1);

    // A fold angle typed and entered is one edit and one undo step (Enter and the field's change
    // both sent it: seq went up by two and the first undo seemed to do nothing); undone, 90° again.
    const typedFrom = await h.state(page);
    await page.getByTestId('crease-angle').fill('60');
    await page.getByTestId('crease-angle').press('Enter');
    await h.waitState(page, (s, i) => s.scene.model.drawing.strokes[i].fold_angle === 60, index, { what: 'the valley at 60°' });
    await page.getByTestId('crease-angle').blur();
    await h.sleep(500);
    const typed = await h.state(page);
    assert.equal(typed.seq, typedFrom.seq + 1, `one edit for the typed angle: seq ${typedFrom.seq} → ${typed.seq}`);
    assert.equal(typed.undo.available, typedFrom.undo.available + 1, `one undo step: ${JSON.stringify(typedFrom.undo)} → ${JSON.stringify(typed.undo)}`);
    await page.getByTestId('undo').click();
    await h.waitState(page, (s, i) => s.scene.model.drawing.strokes[i].fold_angle === 90, index, { what: 'the valley at 90° after one undo' });

    // A straight crease ending in the middle of the sheet: the server refuses it (a toast), the
    // drawing stays.
    await page.getByTestId('crease-tool-line').click();
    const seqBefore = (await h.state(page)).seq;
    for (const p of [[x0 + 1, y0 + 30], [x0 + 100, y0 + 30]]) {
      const q = await boardPoint(page, p);
      await page.mouse.click(q.x, q.y);
    }
    // Said once, on the board beside the drawing (a tryout saw it twice: there and in a toast).
    const boardError = page.locator('.field-error[data-source="crease-board"]');
    await boardError.waitFor({ state: 'visible', timeout: 15000 });
    const boardText = await boardError.textContent();
    assert.match(boardText, /points|end|crease/i, `the board says why: ${boardText}`);
    const toast = page.getByTestId('error-message');
    assert.equal(await toast.isVisible(), false, 'no toast repeats what the board says');
    const afterError = await h.state(page);
    assert.equal(afterError.lastError && afterError.lastError.path, 'points', `the error names points: ${JSON.stringify(afterError.lastError)}`);
    await h.sleep(500);
    const still = await h.state(page);
    assert.equal(strokesOf(still).length, outline.length + 1, 'the drawing unchanged');
    assert.equal(still.seq, seqBefore, 'no edit applied');
    assert.equal(await boardAttr(page, 'data-strokes'), String(outline.length + 1));
    assert.equal(await page.locator('[data-testid="crease-board"] .crease-pending').count(), 0, 'nothing left pending');
    // A curve with a loose end: refused too, but its points come back as a draft (a tryout's curve
    // vanished whole), to finish on the outline; Esc drops it.
    if (await toast.isVisible()) await page.locator('.toast-error .toast-close').click();
    await page.getByTestId('crease-tool-curve').click();
    const loose = [[x0 + 1, y0 + 20], [x0 + 40, y0 + 35], [x0 + 80, y0 + 38]];
    for (const [k, p] of loose.entries()) {
      const q = await boardPoint(page, p);
      if (k < loose.length - 1) await page.mouse.click(q.x, q.y);
      else await page.mouse.dblclick(q.x, q.y);
    }
    await page.waitForFunction(() => document.querySelectorAll('[data-testid="crease-board"] .crease-draft-point').length === 3, null, { timeout: 15000 });
    assert.match(await page.getByTestId('crease-board-hint').textContent(), /Not drawn — its points are kept/);
    assert.equal((await h.state(page)).seq, seqBefore, 'still no edit applied');
    await page.keyboard.press('Escape');
    await page.waitForFunction(() => document.querySelectorAll('[data-testid="crease-board"] .crease-draft-point').length === 0);

    // The board with the valley selected.
    await page.getByTestId('crease-tool-select').click();
    await page.mouse.click(mid.x, mid.y);
    await page.waitForFunction((i) => document.querySelector('[data-testid="crease-board"]').dataset.selected === String(i), index);
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, '13-draw-creases-board.png') });

    // Back to 3D. A drawn design's crease kinds are the board's: the Crease panel's type cannot be
    // set here (the next board edit would drop it).
    await page.getByTestId('crease-board-close').click();
    await page.getByTestId('crease-board').waitFor({ state: 'hidden' });
    assert.ok(await page.getByTestId('crease-type').isDisabled(), 'the crease type is set on the board');
    // Folded by the slider to 100 % (a valley drawn: something to fold).
    assert.ok(await page.getByTestId('fold-nothing').isHidden(), 'the hint is gone once a valley is drawn');
    await page.getByTestId('fold-slider').fill('100');
    await h.waitState(page, (s) => s.metrics && Math.abs(s.metrics.fold_amount - 1) < 1e-9, undefined, { what: 'fold amount 100 %' });
    await h.waitQuiet(page, { quietMs: 1500 });
    const m = (await h.state(page)).metrics;
    assert.ok(m.development_length_error < 5e-3, `the folded sheet keeps its lengths: ${m.development_length_error}`);
    const url = new URL(page.url());
    const { key, folded } = await rb.exportedFold(daemon, url.searchParams.get('session'), url.searchParams.get('token'));
    const valleys = key.edges_assignment.map((a, e) => (a === 'V' ? key.edges_foldAngle[e] : null)).filter((a) => a !== null);
    assert.ok(valleys.length >= 2, `the curved valley, sampled: ${valleys.length} edges`);
    assert.ok(!key.edges_assignment.includes('M'), 'no mountain after undo');
    const mean = valleys.reduce((a, b) => a + b, 0) / valleys.length;
    assert.ok(Math.abs(mean - 90) < 18, `the valley folds about 90°: ${mean}°`);
    // The folded form leaves the plane: its vertices span a third dimension.
    const zs = folded.vertices_coords.map((p) => p[2] || 0);
    const [zx, zy] = [folded.vertices_coords.map((p) => p[0]), folded.vertices_coords.map((p) => p[1])];
    const spans = [zx, zy, zs].map((v) => Math.max(...v) - Math.min(...v)).sort((a, b) => a - b);
    assert.ok(spans[0] > 20, `folded: the smallest extent is ${spans[0]} mm`);
    assert.ok(fold.filter.numType(key, 'faces') >= 2);
    // The scene file saved now reopens where it is: folded, at 100 % (a tryout's file saved
    // after a slider gesture said 0 %, and reopened folded with the slider at "the flat sheet").
    const [download] = await Promise.all([page.waitForEvent('download'), page.getByTestId('save-scene').click()]);
    const saved = JSON.parse(fs.readFileSync(await download.path(), 'utf8'));
    assert.equal(saved.model.fold_amount, 1, `the saved fold amount: ${saved.model.fold_amount}`);

    // The refused crease's toast has been read: dismissed for the picture of the folded design.
    if (await toast.isVisible()) await page.locator('.toast-error .toast-close').click();
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, '13-draw-creases.png') });
    // The crease pattern's line key has a band of its own: no paper under "mountain – valley" (a
    // sheet as wide as the panel ran under it). Judged from the pixels of the development view.
    const dev = h.decodePNG(await page.getByTestId('development-view').screenshot());
    let paperInKey = 0;
    for (let y = 0; y < 24; y++) {
      for (let x = Math.floor(dev.width / 2); x < dev.width; x++) {
        const i = 4 * (y * dev.width + x);
        paperInKey += Math.abs(dev.data[i] - 0xf3) < 12 && Math.abs(dev.data[i + 1] - 0xee) < 12 && Math.abs(dev.data[i + 2] - 0xe3) < 12;
      }
    }
    assert.equal(paperInKey, 0, `paper pixels in the key's band: ${paperInKey}`);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));

// 15. Issue 16's design from a blank sheet, end to end: a blank 200 × 150 mm sheet from the start
//     page; on the board two curved creases, a valley and a mountain, each from the left edge to
//     the right edge (5 clicks, ends snapped onto the outline), roughly parallel arcs bulging up
//     (crossing straight creases cannot fold both at once: the editor says so, test 15c);
//     folded by the slider to 100 %, then by dragging a free corner of the sheet in the 3D view;
//     exported from the export menu as SVG, STL, STEP and DXF (downloads), each read back by an
//     independent reader (lib/readback.mjs): the STL parsed here, its triangles summing to the
//     sheet's 30 000 mm²; the STEP by OpenCascade (step_probe); the DXF by python3 ezdxf (the CUT
//     outline encloses the sheet, the creases are on MOUNTAIN and VALLEY); the SVG by python3
//     xml.etree (true size in mm, mountain red, valley blue).
//     Screenshots: test-artifacts/web/15-blank-sheet-board.png (the two creases on the board),
//     15-blank-sheet-slider.png (folded by the slider), 15-blank-sheet-dragged.png and
//     15-blank-sheet-dragged-3d.png (after the drag), 15-blank-sheet-orbit.png (the same, the
//     camera turned to show the folds' profile); the exports are kept as 15-blank-sheet.*.
const SHEET_AREA = 200 * 150;

/** A blank 200 × 150 mm sheet opened from the start page: {x0, x1, y0, y1, outline}. */
async function openBlankSheet(page, daemon) {
  await page.goto(daemon.url);
  await page.getByTestId('start-page').waitFor();
  await page.getByTestId('blank-width').fill('200');
  await page.getByTestId('blank-height').fill('150');
  await page.getByTestId('blank-units').selectOption('mm');
  await page.getByTestId('blank-sheet').click();
  await page.getByTestId('editor').waitFor({ timeout: 30000 });
  await h.waitForConnected(page);
  await h.waitState(page, (s) => s.kind === 'composite' && !!(s.scene && s.scene.model.drawing), undefined, { what: 'a composite with a drawing' });
  const start = await h.state(page);
  assert.equal(start.scene.units ?? 'mm', 'mm', 'the blank sheet is drawn in millimetres');
  // The drag grid follows the sheet from the start: a fiftieth of its 250 mm diagonal.
  assert.equal(await page.evaluate(() => document.querySelector('[data-testid="snap-step"]').value), '5', 'grid step of a 200 × 150 mm sheet');
  const outline = strokesOf(start);
  const xs = outline.flatMap((s) => s.points.map((p) => p[0]));
  const ys = outline.flatMap((s) => s.points.map((p) => p[1]));
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  assert.ok(Math.abs(x1 - x0 - 200) < 1e-6 && Math.abs(y1 - y0 - 150) < 1e-6, `the sheet is 200 × 150 mm: ${x1 - x0} × ${y1 - y0}`);
  const url = new URL(page.url());
  return { x0, x1, y0, y1, outline, id: url.searchParams.get('session'), token: url.searchParams.get('token') };
}

/**
 * On the board: a curved valley low on the sheet and a curved mountain above it, each 5 clicks
 * (the last a double-click) from the left edge to the right edge, the ends clicked 1.2 mm inside
 * the sheet and snapping onto the outline. Checks the drawing and the faces it makes; leaves the
 * board open. → {designs (the clicked points), flat (the model as drawn, flat)}.
 */
async function drawTwoCreases(page, sheet, { shot } = {}) {
  const { x0, x1, y0, outline } = sheet;
  await page.getByTestId('draw-creases').click();
  await page.getByTestId('crease-board').waitFor({ state: 'visible' });
  const at = (u, v) => [x0 + u, y0 + v];
  const designs = [
    { assignment: 'V', points: [at(1.2, 45), at(50, 56), at(100, 60), at(150, 56), at(200 - 1.2, 45)] },
    { assignment: 'M', points: [at(1.2, 95), at(50, 106), at(100, 110), at(150, 106), at(200 - 1.2, 95)] },
  ];
  for (const [c, design] of designs.entries()) {
    await page.getByTestId('crease-tool-curve').click();
    await page.getByTestId(`crease-assignment-${design.assignment}`).click();
    assert.equal(await page.getByTestId(`crease-assignment-${design.assignment}`).getAttribute('aria-pressed'), 'true');
    for (const [k, p] of design.points.entries()) {
      const q = await boardPoint(page, p);
      await page.mouse.move(q.x, q.y, { steps: 3 });
      if (k === 0 || k === design.points.length - 1) {
        const snap = await page.locator('[data-testid="crease-board"] [data-snap]').getAttribute('data-snap');
        assert.equal(snap, 'stroke', `crease ${c}: the end ${k} snaps onto the outline`);
      }
      if (k < design.points.length - 1) await page.mouse.click(q.x, q.y);
      else await page.mouse.dblclick(q.x, q.y);
    }
    await h.waitState(page, (s, n) => s.scene.model.drawing.strokes.length === n, outline.length + c + 1, { what: `crease ${c} drawn` });
    await page.waitForFunction((n) => document.querySelector('[data-testid="crease-board"]').dataset.strokes === String(n), outline.length + c + 1);
  }
  const drawn = await h.state(page);
  assert.equal(drawn.lastError, null, `no refusal: ${JSON.stringify(drawn.lastError)}`);
  const creases = strokesOf(drawn).filter((s) => s.assignment !== 'B');
  assert.equal(creases.length, 2, `2 drawn creases: ${JSON.stringify(creases)}`);
  for (const [c, design] of designs.entries()) {
    const s = creases[c];
    assert.equal(s.assignment, design.assignment, `crease ${c} is ${design.assignment}`);
    assert.equal(s.curved, true, `crease ${c} is curved`);
    assert.equal(s.points.length, 5, `crease ${c}: the 5 points clicked`);
    assert.ok(Math.abs(s.points[0][0] - x0) < 1e-6 && Math.abs(s.points[4][0] - x1) < 1e-6,
      `crease ${c}: the ends on the left and right edges: ${JSON.stringify(s.points)}`);
    assert.equal(s.fold_angle, design.assignment === 'V' ? 90 : -90, `crease ${c}: a ${design.assignment} of 90°`);
  }
  const flat = drawn.scene.model;
  const folding = flat.edges.filter((e) => e.type === 'S' && e.crease === 'fold');
  console.log(`blank sheet, 2 creases: ${flat.faces.length} faces, ${flat.edges.length} edges `
    + `(${folding.length} S edges folding), vertices ${JSON.stringify(flat.vertices.map((v) => v.slice(0, 2).map((x) => +x.toFixed(2))))}, `
    + `fixed ${JSON.stringify(flat.fixed)}`);
  assert.ok(flat.faces.length >= 3, `two creases across the sheet make at least 3 faces: ${flat.faces.length}`);
  assert.ok(folding.length >= 2, `both curved creases are folding S edges: ${JSON.stringify(flat.edges.map((e) => [e.type, e.crease]))}`);
  if (shot) {
    await page.getByTestId('crease-tool-select').click();
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, `${shot}.png`) });
  }
  return { designs, flat };
}

/** The page's state and the server's session once the page has the solve of the last edit. */
async function solvedState(page, daemon, sheet) {
  const r = await h.poll(async () => {
    const st = await h.state(page);
    const server = await daemon.session(sheet.id, sheet.token);
    return { st, server, ok: !!(st.lastSolved && st.lastSolved.seq === server.seq && st.seq === server.seq) };
  });
  assert.ok(r.ok, `the page has the solve of seq ${r.server.seq}: ${JSON.stringify(h.summary(r.st))}`);
  return r;
}

const zMaxOf = (model) => Math.max(...model.vertices.map((v) => Math.abs(v[2])));

/** Closes the board and folds by the slider to 100 %; checks that the sheet folded. */
async function foldBySlider(page, daemon, sheet, { shot } = {}) {
  await page.getByTestId('crease-board-close').click();
  await page.getByTestId('crease-board').waitFor({ state: 'hidden' });
  await page.getByTestId('fold-slider').fill('100');
  await h.waitState(page, (s) => s.metrics && Math.abs(s.metrics.fold_amount - 1) < 1e-9, undefined, { what: 'fold amount 100 %' });
  await h.waitQuiet(page, { quietMs: 1500 });
  let slid = await solvedState(page, daemon, sheet);
  if (slid.st.lastSolved.reason === 'time_budget' && slid.st.lastSolved.quality && !slid.st.lastSolved.quality.met) {
    // The release polish ran out of its time budget before the quality was met (seen on a loaded
    // machine: 8° short of the drawn fold). The status bar says so; a user presses Solve.
    console.log(`slider 100 %: the release stopped on its time budget, quality not met: Solve continues it`);
    const seq = slid.server.seq;
    await page.getByTestId('solve').click();
    await h.waitState(page, (s, n) => s.lastSolved && s.lastSolved.seq > n, seq, { what: 'the solve after the slider' });
    await h.waitQuiet(page, { quietMs: 1500 });
    slid = await solvedState(page, daemon, sheet);
  }
  const m = slid.server.metrics;
  const zMax = zMaxOf(slid.server.scene.model);
  console.log(`slider 100 %: max |z| of the vertices ${zMax.toFixed(2)} mm, fold angle max ${m.crease_fold_angle_max_deg?.toFixed(2)}°, `
    + `fold angle error ${m.fold_angle_error_max_deg?.toExponential(2)}°, development error ${m.development_length_error?.toExponential(2)}, `
    + `solved ${slid.st.lastSolved.reason}, quality met ${slid.st.lastSolved.quality?.met}`);
  assert.ok(zMax > 10, `a real fold: the vertices leave the plane by ${zMax} mm`);
  assert.ok(m.crease_fold_angle_max_deg > 45, `the creases fold: ${m.crease_fold_angle_max_deg}°`);
  if (m.fold_angle_error_max_deg !== undefined)
    assert.ok(m.fold_angle_error_max_deg < 5, `the creases reach the drawn 90°: off by ${m.fold_angle_error_max_deg}°`);
  assert.ok(m.development_length_error < 5e-3, `the folded sheet keeps its lengths: ${m.development_length_error}`);
  if (shot) {
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, `${shot}.png`) });
  }
  return slid;
}

/** The free corner (not fixed) of the flat sheet farthest from every fixed vertex. */
function freeCorner(sheet, flat) {
  const { x0, x1, y0, y1 } = sheet;
  const fixedIds = new Set((flat.fixed || []).map((f) => f.vertex));
  const corners = flat.vertices.map((v, i) => ({ i, v }))
    .filter(({ v }) => [x0, x1].some((x) => Math.abs(v[0] - x) < 1e-3) && [y0, y1].some((y) => Math.abs(v[1] - y) < 1e-3));
  assert.equal(corners.length, 4, `the sheet's 4 corners are vertices: ${JSON.stringify(corners)}`);
  const free = corners.filter(({ i }) => !fixedIds.has(i));
  assert.ok(free.length >= 1, `a corner is free to drag: fixed ${JSON.stringify([...fixedIds])}`);
  const far = ({ v }) => Math.min(...[...fixedIds].map((j) => Math.hypot(v[0] - flat.vertices[j][0], v[1] - flat.vertices[j][1])));
  return free.sort((a, b) => far(b) - far(a))[0].i;
}

/** Drags vertex `corner` by (dx, dy) px with the mouse, releases, waits for the release solve. */
async function dragCorner(page, daemon, sheet, corner, before, { dx, dy }) {
  const c0 = before.server.scene.model.vertices[corner];
  const st0 = await h.state(page);
  const from = await h.pointPagePosition(page, { vertex: corner });
  assert.ok(from.local.x + dx > 10 && from.local.y + dy > 10 && from.local.x < from.box.width - 10 && from.local.y < from.box.height - 10,
    `corner ${corner} and where it is dragged to are in the viewport: ${JSON.stringify(from.local)} + (${dx}, ${dy}) in ${from.box.width}x${from.box.height}`);
  // The fold angle the page shows, sampled through the drag and the release solve.
  const trace = [];
  let tracing = true;
  const tracer = (async () => {
    while (tracing) {
      trace.push(await page.evaluate(() => window.__devsurf.state.metrics?.crease_fold_angle_max_deg));
      await h.sleep(200);
    }
  })();
  await h.dragBy(page, from, { dx, dy, steps: 16, pauseMs: 40 });
  const released = trace.length;
  await h.waitState(page, (s, n) => s.iterateCount > n, st0.iterateCount, { what: 'iterates after the drag' });
  await h.waitQuiet(page, { quietMs: 1500 });
  const after = await solvedState(page, daemon, sheet);
  tracing = false;
  await tracer;
  const m = after.server.metrics;
  const c1 = after.server.scene.model.vertices[corner];
  const moved = Math.hypot(...c1.map((x, k) => x - c0[k]));
  const zMax = zMaxOf(after.server.scene.model);
  const deg = (a) => (typeof a === 'number' ? a.toFixed(1) : String(a));
  console.log(`drag of corner ${corner} by (${dx}, ${dy}) px: ${c0.map((x) => x.toFixed(2))} → ${c1.map((x) => x.toFixed(2))} (moved ${moved.toFixed(2)} mm), `
    + `seq ${st0.seq} → ${after.st.seq}; fold angle max (°) while dragging ${trace.slice(0, released).map(deg).join(' ')} | after the release ${trace.slice(released).map(deg).join(' ')}; `
    + `after the solve: fold angle max ${deg(m.crease_fold_angle_max_deg)}°, fold angle error ${deg(m.fold_angle_error_max_deg)}°, δ_max ${m.face_flatness_max}, `
    + `K ${m.vertex_curvature_max}, development error ${m.development_length_error}, flipped ${m.development_flipped_faces}, `
    + `max |z| ${zMax.toFixed(2)} mm, solved ${after.st.lastSolved.reason}, quality met ${after.st.lastSolved.quality?.met}`);
  return { ...after, m, moved, zMax, st0 };
}

/** What a drag must leave: the corner moved, a developable sheet, the creases still folded. */
function assertDraggedAndFolded(d) {
  assert.equal(d.st.lastError, null);
  assert.ok(d.st.seq > d.st0.seq, 'the drag was applied as edits');
  assert.ok(d.moved > 3, `the corner followed the pointer: moved ${d.moved} mm`);
  // Within 2 %: the known stretch a drag leaves on a slide-folded drawn sheet (0.07–0.8 % measured,
  // more under load; docs/architecture.md "Drags of a design folded by its targets").
  assert.ok(d.m.development_length_error < 2e-2, `the dragged sheet keeps its lengths within 2 %: ${d.m.development_length_error}`);
  assert.equal(d.m.development_flipped_faces, 0, 'no flipped face in the development');
  assert.ok(d.m.face_flatness_max <= 1e-3, `the faces stay developable: δ_max ${d.m.face_flatness_max}`);
  // The verdict is shown, not asserted: after a large drag of a curved fold the sheet's lengths
  // rest at 0.3–0.7 % (the development threshold is tighter), a known limit (docs/architecture.md).
  assert.ok(d.st.lastSolved.quality, 'the page got a quality verdict');
  console.log(`quality after the drag: ${JSON.stringify(d.st.lastSolved.quality).slice(0, 300)}`);
  // The creases are 90° folds: a drag may bend them, not undo them.
  assert.ok(d.zMax > 10 && d.m.crease_fold_angle_max_deg > 45,
    `still folded after the release: max |z| ${d.zMax} mm, fold angle max ${d.m.crease_fold_angle_max_deg}° (drawn 90°)`);
  if (d.m.fold_angle_error_max_deg !== undefined)
    assert.ok(d.m.fold_angle_error_max_deg < 45, `the creases stay near their drawn 90°: off by ${d.m.fold_angle_error_max_deg}°`);
}

test('two curved creases on a blank sheet: folded by the slider and by a drag, exported as SVG, STL, STEP and DXF and read back', { timeout: 300000 }, () =>
  ctx.guard('blank-sheet-two-creases', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    const sheet = await openBlankSheet(page, daemon);
    const { x0, y0 } = sheet;
    const { designs, flat } = await drawTwoCreases(page, sheet, { shot: '15-blank-sheet-board' });
    const slid = await foldBySlider(page, daemon, sheet, { shot: '15-blank-sheet-slider' });

    // Folded further by dragging: the free corner farthest from the fixed vertices, pulled
    // 70 px up the screen with the mouse.
    const corner = freeCorner(sheet, flat);
    const dragged = await dragCorner(page, daemon, sheet, corner, slid, { dx: 0, dy: -70 });
    assertDraggedAndFolded(dragged);
    await h.settleFrames(page);
    await h.screenshotPage(page, '15-blank-sheet-dragged');
    const view = await h.screenshotViewport(page, '15-blank-sheet-dragged-3d');
    const viewStats = h.pixelStats(view.image);
    assert.ok(viewStats.distinct >= 64 && viewStats.dominantShare < 0.97, `the 3D view is drawn: ${JSON.stringify(viewStats)}`);

    // The camera turned (orbit: a drag on empty background) to show the folds' profile.
    const box = await page.getByTestId('viewport').boundingBox();
    const seqBeforeOrbit = (await h.state(page)).seq;
    await h.dragBy(page, { x: box.x + box.width - 30, y: box.y + box.height / 2 }, { dx: 70, dy: -20, steps: 20, pauseMs: 20 });
    await h.sleep(300);
    await h.settleFrames(page);
    await h.screenshotPage(page, '15-blank-sheet-orbit');
    assert.equal((await h.state(page)).seq, seqBeforeOrbit, 'turning the camera edits nothing');

    // The exports, from the export menu (downloads), kept in test-artifacts/web/15-blank-sheet.*.
    const exported = async (format) => {
      const button = page.getByTestId(`export-${format}`);
      assert.equal(await button.isVisible(), true, `the export menu offers ${format}`);
      const [download] = await Promise.all([page.waitForEvent('download'), button.click()]);
      const file = path.join(h.ARTIFACTS, `15-blank-sheet.${format}`);
      await download.saveAs(file);
      return { name: download.suggestedFilename(), file, buf: fs.readFileSync(file) };
    };

    // STL: the folded surface; triangles parsed here. The scene is in mm and the STL is written
    // in the scene's units, so its area is in mm²: a developable sheet keeps the sheet's area.
    const stl = await exported('stl');
    assert.match(stl.name, /\.stl$/);
    const mesh = rb.stlMesh(stl.buf);
    const stlExtent = mesh.bbox[1].map((x, k) => x - mesh.bbox[0][k]);
    console.log(`STL ${stl.name}: ${mesh.binary ? 'binary' : 'ASCII'}, ${mesh.triangles} triangles, area ${mesh.area.toFixed(2)} mm² `
      + `(${(100 * (mesh.area / SHEET_AREA - 1)).toFixed(3)} % off 30 000), extent ${stlExtent.map((x) => x.toFixed(2)).join(' × ')} mm`);
    assert.ok(mesh.triangles > 0, 'the STL has triangles');
    // The sheet's area, within 2 % (the STL samples the surface) plus what the session itself
    // reports of a stretch: after a drag a slide-folded drawn sheet rests stretched by up to ~1 %
    // (issue 16's open point: the release holds the fold the drag left, measured on the dragged
    // sheet), 4× that in area at the crease ends. A face missing or doubled is off by 10 % or more.
    // The STEP's area below is the second, independent measure of the same surface.
    const stretch = dragged.m.development_length_error;
    const areaTolerance = 0.02 + 4 * stretch;
    assert.ok(Math.abs(mesh.area / SHEET_AREA - 1) < areaTolerance,
      `the STL's area ${mesh.area} mm² is the sheet's ${SHEET_AREA} mm² within ${(100 * areaTolerance).toFixed(2)} % (development error ${stretch})`);
    assert.ok(stlExtent[2] > 10, `the STL is folded: z extent ${stlExtent[2]} mm`);

    // STEP: read by OpenCascade (the probe converts to mm); the file's own length unit reported.
    const step = await exported('step');
    assert.match(step.name, /\.step$/);
    const stepText = step.buf.toString('latin1');
    assert.match(stepText, /^ISO-10303-21;/);
    const stepUnit = /LENGTH_UNIT\(\)\s*NAMED_UNIT\(\*\)\s*SI_UNIT\(([^)]*)\)/.exec(stepText);
    const probe = rb.stepProbe(step.file);
    const stepExtent = probe.bbox[1].map((x, k) => x - probe.bbox[0][k]);
    console.log(`STEP ${step.name}: length unit SI_UNIT(${stepUnit && stepUnit[1]}), step_probe ${JSON.stringify(probe)}, `
      + `area ${(100 * (probe.area / SHEET_AREA - 1)).toFixed(3)} % off 30 000, extent ${stepExtent.map((x) => x.toFixed(2)).join(' × ')} mm`);
    assert.ok(stepUnit && /\.MILLI\.\s*,\s*\.METRE\./.test(stepUnit[1]), `the STEP is in millimetres: ${stepUnit && stepUnit[1]}`);
    assert.ok(probe.roots >= 1, `OpenCascade transfers a root: ${probe.roots}`);
    assert.ok(probe.faces >= 2, `the STEP has the sheet's faces: ${probe.faces}`);
    assert.ok(Math.abs(probe.area / SHEET_AREA - 1) < areaTolerance, `the STEP's area ${probe.area} mm² is the sheet's ${SHEET_AREA} mm² within ${(100 * areaTolerance).toFixed(2)} %`);
    // Two readers, two exports, one surface: OpenCascade's area of the B-spline faces and the STL's
    // triangles agree (the STL samples it).
    assert.ok(Math.abs(probe.area / mesh.area - 1) < 0.01, `the STEP's area ${probe.area} mm² and the STL's ${mesh.area} mm² agree within 1 %`);
    assert.ok(stepExtent[2] > 10, `the STEP is folded: z extent ${stepExtent[2]} mm`);
    for (let k = 0; k < 3; k++) {
      for (const side of [0, 1])
        assert.ok(Math.abs(probe.bbox[side][k] - mesh.bbox[side][k]) < 3,
          `the STEP's box and the STL's agree (axis ${k}, ${side ? 'max' : 'min'}): ${probe.bbox[side][k]} vs ${mesh.bbox[side][k]}`);
    }

    // DXF: read by ezdxf — millimetres, the CUT outline closes around the sheet's area, the
    // creases are scored on MOUNTAIN and VALLEY (each one curve from the left edge to the right
    // edge, through the points clicked), the rulings on a layer that is off.
    const dxfFile = await exported('dxf');
    assert.match(dxfFile.name, /\.dxf$/);
    const dxf = rb.dxfReadback(dxfFile.file);
    const dxfChains = Object.fromEntries(['MOUNTAIN', 'VALLEY'].map((layer) =>
      [layer, rb.chainPolylines((dxf.polylines[layer] || []).map((p) => p.points), 1e-3)]));
    console.log(`DXF ${dxfFile.name} (ezdxf ${dxf.version}): $INSUNITS ${dxf.insunits}, entities ${JSON.stringify(dxf.counts)}, `
      + `CUT ${dxf.cut_segments} segments in ${dxf.loops} loop(s) enclosing ${dxf.area && dxf.area.toFixed(2)} mm² `
      + `(${dxf.area && (100 * (dxf.area / SHEET_AREA - 1)).toFixed(4)} %), CUT box ${JSON.stringify(dxf.cut_bbox)}, `
      + `creases ${Object.entries(dxfChains).map(([l, cs]) => `${l}: ${cs.length} curve(s) of ${cs.map((c) => c.length).join(', ')} points`).join('; ')}`);
    assert.equal(dxf.insunits, 4, 'the DXF is in millimetres ($INSUNITS 4)');
    assert.equal(dxf.loops, 1, 'the CUT outline is one closed loop');
    assert.ok(Math.abs(dxf.area / SHEET_AREA - 1) < 0.01, `the CUT outline encloses ${dxf.area} mm², the sheet's ${SHEET_AREA} within 1 %`);
    assert.ok(dxf.layers.RULINGS ? dxf.layers.RULINGS.off : true, 'rulings are reference only (layer off)');
    const [bx0, by0] = dxf.cut_bbox[0];
    for (const [layer, design] of [['VALLEY', designs[0]], ['MOUNTAIN', designs[1]]]) {
      const chains = dxfChains[layer];
      assert.equal(chains.length, 1, `one ${layer} crease in the DXF: ${chains.length} curves`);
      const curve = chains[0];
      const ends = [curve[0], curve[curve.length - 1]].sort((a, b) => a[0] - b[0]);
      assert.ok(Math.abs(ends[0][0] - bx0) < 0.5 && Math.abs(ends[1][0] - (bx0 + 200)) < 0.5,
        `the ${layer} crease runs from the left edge to the right edge: ${JSON.stringify(ends)}`);
      for (const p of design.points.slice(1, 4)) {
        const d = rb.distanceToPolyline([bx0 + p[0] - x0, by0 + p[1] - y0], curve);
        assert.ok(d < 2, `the ${layer} crease passes through the clicked point ${p}: ${d.toFixed(3)} mm away`);
      }
    }

    // SVG: read by xml.etree — the fold pattern at true size (the sheet plus the writer's margin
    // on each side; one user unit = 1 mm), its boundary closing around 200 × 150 mm, mountain
    // strokes red and valley strokes blue.
    const svgFile = await exported('svg');
    assert.match(svgFile.name, /\.svg$/);
    const svg = rb.svgReadback(svgFile.file);
    const [W, H] = [svg.width, svg.height].map((s) => (/^([\d.]+)mm$/.exec(s) || [])[1]).map(Number);
    const [[sx0, sy0], [sx1, sy1]] = svg.boundary_bbox;
    const stroked = (g) => (svg.groups[g] || []).map((it) => it.stroke);
    console.log(`SVG ${svgFile.name}: ${svg.width} × ${svg.height}, viewBox ${svg.viewBox}, boundary ${(sx1 - sx0).toFixed(3)} × ${(sy1 - sy0).toFixed(3)} mm `
      + `at (${sx0}, ${sy0}) in ${svg.loops} loop(s) enclosing ${svg.area && svg.area.toFixed(2)} mm², `
      + `groups ${Object.entries(svg.groups).map(([g, items]) => `${g}: ${items.length} × ${[...new Set(items.map((i) => i.stroke))].join('/')}`).join(', ')}`);
    assert.ok(Number.isFinite(W) && Number.isFinite(H), `the SVG's size is in mm: ${svg.width} × ${svg.height}`);
    assert.equal(svg.viewBox, `0 0 ${svg.width.replace('mm', '')} ${svg.height.replace('mm', '')}`, 'one user unit is a millimetre');
    assert.ok(Math.abs((sx1 - sx0) / 200 - 1) < 0.01 && Math.abs((sy1 - sy0) / 150 - 1) < 0.01,
      `the sheet at true size: ${sx1 - sx0} × ${sy1 - sy0} mm`);
    assert.ok(Math.abs(W - (sx1 - sx0) - 2 * sx0) < 0.01 && Math.abs(H - (sy1 - sy0) - 2 * sy0) < 0.01,
      `the page is the sheet and an even margin of ${sx0} mm: ${W} × ${H}`);
    assert.equal(svg.loops, 1, 'the boundary is one closed loop');
    assert.ok(Math.abs(svg.area / SHEET_AREA - 1) < 0.01, `the boundary encloses ${svg.area} mm²`);
    assert.ok(stroked('mountain').length >= 1 && stroked('mountain').every((c) => c === '#ff0000'), `mountain strokes red: ${stroked('mountain')}`);
    assert.ok(stroked('valley').length >= 1 && stroked('valley').every((c) => c === '#0000ff'), `valley strokes blue: ${stroked('valley')}`);
    for (const [g, design] of [['valley', designs[0]], ['mountain', designs[1]]]) {
      const chains = rb.chainPolylines(svg.groups[g].map((it) => it.points), 1e-3);
      assert.equal(chains.length, 1, `one ${g} crease in the SVG: ${chains.length} curves`);
      for (const p of design.points.slice(1, 4)) {
        const d = rb.distanceToPolyline([sx0 + p[0] - x0, sy1 - (p[1] - y0)], chains[0]);  // SVG's y points down
        assert.ok(d < 2, `the SVG's ${g} crease passes through the clicked point ${p}: ${d.toFixed(3)} mm away`);
      }
    }
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));

// 15b. The same design, the same corner pulled up and out instead (40 px left, 70 px up). This
//      found a defect: the release's projections dropped the fold-angle targets and walked the
//      whole sheet back to flat (every crease 92° → 0°, the corner back at its flat position)
//      under a "quality met" verdict. Now the targets let go while the corner is pulled and take
//      the fold the drag left when it is released (Session::release): the sheet stays folded.
//      Screenshot: test-artifacts/web/15-blank-sheet-drag-out.png.
test('two curved creases on a blank sheet: a drag of the corner up and out leaves the sheet folded', { timeout: 240000 }, () =>
  ctx.guard('blank-sheet-drag-out', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    const sheet = await openBlankSheet(page, daemon);
    const { flat } = await drawTwoCreases(page, sheet);
    const slid = await foldBySlider(page, daemon, sheet);
    const corner = freeCorner(sheet, flat);
    const dragged = await dragCorner(page, daemon, sheet, corner, slid, { dx: -40, dy: -70 });
    await h.settleFrames(page);
    await h.screenshotPage(page, '15-blank-sheet-drag-out');
    assertDraggedAndFolded(dragged);
  }));

// 15c. Two straight creases drawn across each other (a mountain and a valley through the middle
//      of the sheet): the server accepts the drawing, but a flat sheet folds along one straight
//      line at a time, so the Fold panel says the crossing cannot fold (and why) and the board
//      marks it where the creases cross; erasing one of them clears both. The reason itself is
//      checked against the solver in CompositeFoldConflicts (C++): the crossing stays flat.
//      Screenshot: test-artifacts/web/15c-crossing-creases.png.
test('two straight creases drawn across each other: the editor says the crossing cannot fold, and erasing one clears it', { timeout: 180000 }, () =>
  ctx.guard('crossing-creases', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    const { x0, x1, y0, y1, outline } = await openBlankSheet(page, daemon);
    const [xm, ym] = [(x0 + x1) / 2, (y0 + y1) / 2];
    await page.getByTestId('draw-creases').click();
    await page.getByTestId('crease-board').waitFor({ state: 'visible' });
    const line = async (assignment, a, b, count) => {
      await page.getByTestId('crease-tool-line').click();
      await page.getByTestId(`crease-assignment-${assignment}`).click();
      for (const p of [a, b]) {
        const q = await boardPoint(page, p);
        await page.mouse.move(q.x, q.y, { steps: 3 });
        await page.mouse.click(q.x, q.y);
      }
      await h.waitState(page, (s, n) => s.scene.model.drawing.strokes.length === n, count, { what: `${assignment} line drawn` });
    };
    await line('M', [x0 + 1, ym], [x1 - 1, ym], outline.length + 1);
    await h.waitQuiet(page, { quietMs: 500 });
    assert.equal(await page.getByTestId('fold-conflicts').isVisible(), false, 'one straight crease folds');
    await line('V', [xm, y0 + 1], [xm, y1 - 1], outline.length + 2);
    assert.equal((await h.state(page)).lastError, null, 'the drawing is accepted');
    const panel = page.getByTestId('fold-conflicts');
    await panel.waitFor({ state: 'visible', timeout: 15000 });
    const text = await panel.textContent();
    assert.match(text, /One point cannot fold as drawn/, text);
    assert.match(text, /two straight creases cross here/, text);
    assert.match(text, /\(100, 75\)/, `where, on the sheet: ${text}`);
    const marks = page.locator('[data-testid="crease-board"] .crease-conflict');
    await marks.first().waitFor({ state: 'attached' });
    assert.equal(await marks.count(), 1);
    const box = await marks.first().boundingBox();
    const centre = await boardPoint(page, [xm, ym]);
    assert.ok(Math.abs(box.x + box.width / 2 - centre.x) < 2 && Math.abs(box.y + box.height / 2 - centre.y) < 2,
      `the mark sits on the crossing: ${JSON.stringify(box)} vs ${JSON.stringify(centre)}`);
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, '15c-crossing-creases.png') });

    // Erase the valley: the warning and the mark go.
    await page.getByTestId('crease-tool-select').click();
    const onValley = await boardPoint(page, [xm, y0 + 30]);
    await page.mouse.click(onValley.x, onValley.y);
    await page.waitForFunction(() => document.querySelector('[data-testid="crease-board"]').dataset.selected !== '');
    await page.getByTestId('crease-delete').click();
    await h.waitState(page, (s, n) => s.scene.model.drawing.strokes.length === n, outline.length + 1, { what: 'the valley erased' });
    await panel.waitFor({ state: 'hidden', timeout: 15000 });
    assert.equal(await marks.count(), 0, 'no mark left');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));

// 15d. The start page's blank-sheet button while its import runs (a busy daemon can take
//      seconds): it says "Creating…" and is disabled where the user clicked (the page's own busy
//      line is below the fold at 1280 × 720), and stays so while the editor opens, so a second
//      click or Enter in a size field makes no second sheet; an import that fails gives the button
//      back with the error shown. The sheet is made in cm (300 × 100): it opens in cm, its numbers
//      as typed, the drag grid a fiftieth of its diagonal. The import is answered by the test (a route): refused once, then
//      held back 1.5 s, so each state is seen, not raced.
test('the blank-sheet button says it is creating while the import runs, and a second click makes no second sheet', { timeout: 120000 }, () =>
  ctx.guard('blank-sheet-busy', async () => {
    const { daemon } = ctx;
    const page = await ctx.page();
    let imports = 0;
    let sessions = 0;
    let refuse = true;
    await page.route('**/api/imports*', async (route) => {
      imports += 1;
      if (refuse) {
        await route.fulfill({ status: 400, contentType: 'application/json', body: JSON.stringify({ error: { code: 'invalid', path: 'svg', message: 'refused by the test' } }) });
        return;
      }
      await new Promise((resolve) => setTimeout(resolve, 1500));
      await route.continue();
    });
    page.on('request', (r) => { if (r.method() === 'POST' && /\/api\/sessions(\?|$)/.test(r.url())) sessions += 1; });
    await page.goto(daemon.url);
    await page.getByTestId('start-page').waitFor();
    const button = page.getByTestId('blank-sheet');
    assert.equal(await button.textContent(), 'Start drawing');
    const buttonState = () => page.evaluate(() => {
      const b = document.querySelector('[data-testid="blank-sheet"]');
      return { disabled: b.disabled, text: b.textContent, busy: b.getAttribute('aria-busy') };
    });

    // Refused: the button comes back, the error is shown.
    await button.click();
    await page.getByText('refused by the test').first().waitFor();
    await page.waitForFunction(() => !document.querySelector('[data-testid="blank-sheet"]').disabled);
    assert.deepEqual(await buttonState(), { disabled: false, text: 'Start drawing', busy: null });
    assert.equal(imports, 1);
    assert.equal(sessions, 0);

    // Held back: busy from the click until the editor is open. This sheet is 300 × 100 cm: it
    // opens in cm, its numbers as typed, the drag grid a fiftieth of its diagonal (316 cm: 5).
    await page.getByTestId('blank-width').fill('300');
    await page.getByTestId('blank-height').fill('100');
    await page.getByTestId('blank-units').selectOption('cm');
    refuse = false;
    await button.click();
    await page.waitForFunction(() => {
      const b = document.querySelector('[data-testid="blank-sheet"]');
      return b.disabled && b.textContent === 'Creating…' && b.getAttribute('aria-busy') === 'true';
    });
    await button.click({ force: true });  // on the disabled button: nothing
    await page.getByTestId('blank-width').press('Enter');  // nor the size fields' Enter
    assert.equal(imports, 2, 'no import for the second click or Enter');
    await page.getByTestId('editor').waitFor({ timeout: 60000 });
    await h.waitForConnected(page);
    await h.waitState(page, (st) => st.kind === 'composite' && !!(st.scene && st.scene.model.drawing), undefined, { what: 'the blank sheet' });
    assert.equal(imports, 2, 'one import for the one sheet');
    assert.equal(sessions, 1, 'one session for the one sheet');
    await page.unroute('**/api/imports*');
    const sheet = await h.state(page);
    assert.equal(sheet.scene.units, 'cm', 'the sheet keeps the unit it was made in');
    const points = strokesOf(sheet).flatMap((s) => s.points);
    const extent = (k) => Math.max(...points.map((p) => p[k])) - Math.min(...points.map((p) => p[k]));
    assert.ok(Math.abs(extent(0) - 300) < 1e-6 && Math.abs(extent(1) - 100) < 1e-6, `300 × 100 in cm: ${extent(0)} × ${extent(1)}`);
    assert.equal(await page.getByTestId('units-select').inputValue(), 'cm');
    assert.equal(await page.evaluate(() => document.querySelector('[data-testid="snap-step"]').value), '5', 'grid step of a 300 × 100 cm sheet');
  }));
