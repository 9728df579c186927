// 12. Exact input (issue 16, item 4): coordinates typed for the selected point move it there
//     (a drag and its release, one undo step); a drag held to the z axis moves along z only and
//     snaps to the grid; the units setting relabels the design and the exports follow (FOLD's
//     frame_unit, read back with npm fold). An editor opened by the edit link knows the view link
//     (item 6). Typed text that is not a value (a coordinate, a solver setting) is refused naming
//     the field and nothing is sent (item 7); so are a fixed point's typed coordinates and drags.
//     Screenshot: test-artifacts/web/12-exact-input.png.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import fold from 'fold';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('exact-input', { demos: [path.join(h.EXAMPLES, 'composite-two-creases.json')] });

async function vertexOnServer(daemon, s, v) {
  return (await daemon.session(s.id, s.edit_token)).scene.model.vertices[v];
}

test('typed coordinates, an axis-held snapped drag and the units setting', { timeout: 180000 }, () =>
  ctx.guard('exact-input', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.readScene('composite-two-creases.json'));
    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.waitState(page, (st) => st.kind === 'composite', undefined, { what: 'a composite session' });

    // Opened by its edit link, the editor is told the view link too (the Share panel shows it).
    await page.waitForFunction((t) => {
      const el = document.querySelector('[data-testid="share-view"]');
      return el && el.value.includes(`token=${t}`);
    }, s.view_token, { timeout: 10000 });

    // Select vertex 6 (a free top corner) by clicking it.
    const at = await h.pointPagePosition(page, { vertex: 6 });
    await page.mouse.click(at.x, at.y);
    await page.getByTestId('coord-z').waitFor({ state: 'visible' });
    const start = await vertexOnServer(daemon, s, 6);
    for (const [k, axis] of ['x', 'y', 'z'].entries()) {
      const shown = Number(await page.getByTestId(`coord-${axis}`).inputValue());
      assert.ok(Math.abs(shown - start[k]) < 1e-3, `${axis}: the input shows ${shown}, the vertex is at ${start[k]}`);
    }

    // Typed: z up by 0.25, Enter.
    const seq0 = (await h.state(page)).seq;
    const target = start[2] + 0.25;
    await page.getByTestId('coord-z').fill(String(target));
    await page.getByTestId('coord-z').press('Enter');
    await h.waitState(page, (st, n) => st.seq > n, seq0, { what: 'the typed move applied' });
    await h.waitQuiet(page, { quietMs: 1000 });
    const moved = await vertexOnServer(daemon, s, 6);
    assert.ok(Math.abs(moved[2] - target) < 0.03, `z after the typed move: ${moved[2]}, typed ${target}`);
    assert.equal((await h.state(page)).lastError, null);

    // Undone, the fields follow the point back (they kept the undone move's values, and Move would
    // have sent it again); redone, forward again.
    for (const [button, want] of [['undo', start], ['redo', moved]]) {
      await page.getByTestId(button).click();
      await h.waitQuiet(page, { quietMs: 1000 });
      const now = await vertexOnServer(daemon, s, 6);
      assert.ok(Math.abs(now[2] - want[2]) < 1e-6, `${button}: the vertex at z ${now[2]}, expected ${want[2]}`);
      const shown = Number(await page.getByTestId('coord-z').inputValue());
      assert.ok(Math.abs(shown - now[2]) < 1e-3, `${button}: the z field shows ${shown}, the vertex is at ${now[2]}`);
    }

    // Text a coordinate field cannot read ("1e999" hands over '') is refused naming the axis and
    // nothing is sent; a valid value clears the message.
    const moveError = page.locator('[data-source="selection:move"]');
    const seq1 = (await h.state(page)).seq;
    await page.getByTestId('coord-x').click();
    await page.keyboard.press('Control+A');
    await page.keyboard.type('1e999');
    await page.keyboard.press('Enter');
    await moveError.waitFor({ state: 'visible', timeout: 5000 });
    assert.equal(await moveError.textContent(), 'x: enter a number');
    await new Promise((r) => setTimeout(r, 500));
    assert.equal((await h.state(page)).seq, seq1, 'nothing sent for a coordinate that is not a number');
    await page.getByTestId('coord-x').fill(String(moved[0]));
    await page.getByTestId('coord-x').press('Enter');
    await moveError.waitFor({ state: 'hidden', timeout: 5000 });
    await h.waitQuiet(page, { quietMs: 1000 });

    // A number the server refuses (far outside the model), sent with the Move button: the message
    // names the position, the field keeps the refused text to correct, the vertex stays.
    const beforeRefused = await vertexOnServer(daemon, s, 6);
    await page.getByTestId('coord-x').fill('1e6');
    await page.getByTestId('move-to').click();
    await moveError.waitFor({ state: 'visible', timeout: 5000 });
    assert.match(await moveError.textContent(), /position is .* from the model's centre/);
    await new Promise((r) => setTimeout(r, 500));
    assert.equal(await page.getByTestId('coord-x').inputValue(), '1e6', 'the refused text stays in the field');
    const stayed = await vertexOnServer(daemon, s, 6);
    assert.deepEqual(stayed, beforeRefused, 'the vertex stays where it was');
    // Corrected and sent again, the field follows the point once more.
    await page.getByTestId('coord-x').fill(String(stayed[0] + 0.05));
    await page.getByTestId('move-to').click();
    await moveError.waitFor({ state: 'hidden', timeout: 5000 });
    await h.waitQuiet(page, { quietMs: 1000 });
    const corrected = await vertexOnServer(daemon, s, 6);
    assert.ok(Math.abs(corrected[0] - (stayed[0] + 0.05)) < 0.03, `x after the corrected move: ${corrected[0]}`);
    assert.ok(Math.abs(Number(await page.getByTestId('coord-x').inputValue()) - corrected[0]) < 1e-5, 'the field shows the point again');

    // A solver setting typed as text, out of its range or infinite: refused under the field, the
    // server's value stays; a valid one clears the message and reaches the scene.
    const fairness = page.locator('[data-setting="fairness"] input');
    const fairnessError = page.locator('[data-source="solver:fairness"]');
    const fairness0 = (await daemon.session(s.id, s.edit_token)).scene.solver.fairness;
    for (const [typed, why] of [['abc', 'enter a number'], ['-1', 'at least 0'], ['1e999', 'enter a finite number']]) {
      await fairness.fill(typed);
      await fairness.press('Enter');
      await fairnessError.waitFor({ state: 'visible', timeout: 5000 });
      assert.equal(await fairnessError.textContent(), `fairness: ${why}`, `typed ${typed}`);
      assert.equal(Number(await fairness.inputValue()), fairness0, `the field shows the server's value again after ${typed}`);
    }
    await new Promise((r) => setTimeout(r, 500));
    assert.equal((await daemon.session(s.id, s.edit_token)).scene.solver.fairness, fairness0, 'nothing refused was sent');
    await fairness.fill('0.02');
    await fairness.press('Enter');
    await fairnessError.waitFor({ state: 'hidden', timeout: 5000 });
    const fairnessSet = await h.poll(async () => {
      const scene = (await daemon.session(s.id, s.edit_token)).scene;
      return { ok: scene.solver.fairness === 0.02 };
    });
    assert.ok(fairnessSet.ok, 'a valid fairness reaches the scene');

    // A drag held to the z axis with the grid on: every position sent keeps x and y, z on the grid.
    await page.getByTestId('drag-constraint').selectOption('z');
    await page.getByTestId('snap-grid').check();
    await page.getByTestId('snap-step').fill('0.05');
    await page.getByTestId('snap-step').dispatchEvent('change');
    const from = await h.pointPagePosition(page, { vertex: 6 });
    const before = await vertexOnServer(daemon, s, 6);
    await page.mouse.move(from.x, from.y);
    await page.mouse.down();
    const positions = [];
    for (let k = 1; k <= 10; k++) {
      await page.mouse.move(from.x + 4 * k, from.y - 6 * k);
      await new Promise((r) => setTimeout(r, 40));
      const p = await page.evaluate(() => {
        const d = window.__devsurf.editor.viewport.drag;
        return d && d.position ? d.position.toArray() : null;
      });
      if (p) positions.push(p);
    }
    await page.mouse.up();
    assert.ok(positions.length >= 5, `drag positions seen: ${positions.length}`);
    for (const p of positions) {
      // x and y exactly those where the drag began (the drawn point: float32 of the server's).
      assert.ok(p[0] === positions[0][0] && p[1] === positions[0][1], `held to z: ${p} after ${positions[0]}`);
      assert.ok(Math.abs(p[0] - before[0]) < 1e-5 && Math.abs(p[1] - before[1]) < 1e-5, `held to z: ${p} from ${before}`);
      assert.ok(Math.abs(p[2] / 0.05 - Math.round(p[2] / 0.05)) < 1e-6, `z on the 0.05 grid: ${p[2]}`);
    }
    assert.ok(positions[positions.length - 1][2] > before[2] + 0.04, `the drag went up: ${positions.map((p) => p[2])}`);
    await h.waitQuiet(page, { quietMs: 1000 });

    // A fixed vertex (4) does not move: coordinates typed for it are refused saying how to move
    // it, and a press-drag on it selects it, says so and sends nothing (a drag would only pull
    // against it; a new user's drag of a fixed point of a folded sheet changed the fold targets).
    await page.getByTestId('drag-constraint').selectOption('free');
    const fixedAt = await h.pointPagePosition(page, { vertex: 4 });
    await page.mouse.click(fixedAt.x, fixedAt.y);
    await h.waitState(page, (st) => st.selection && st.selection.vertex === 4, undefined, { what: 'vertex 4 selected' });
    const seqFixed = (await h.state(page)).seq;
    const fixedStart = await vertexOnServer(daemon, s, 4);
    await page.getByTestId('coord-z').fill(String(fixedStart[2] + 0.3));
    await page.getByTestId('coord-z').press('Enter');
    await moveError.waitFor({ state: 'visible', timeout: 5000 });
    assert.equal(await moveError.textContent(), 'this point is fixed: unfix it (F) to move it');
    const notice = page.getByText('This point is fixed: unfix it (F) to drag it.');
    assert.equal(await notice.count(), 0, 'a click to select a fixed point says nothing');
    await page.mouse.move(fixedAt.x, fixedAt.y);
    await page.mouse.down();
    for (let k = 1; k <= 8; k++) await page.mouse.move(fixedAt.x + 5 * k, fixedAt.y - 5 * k);
    await page.mouse.up();
    await notice.waitFor({ timeout: 5000 });
    await new Promise((r) => setTimeout(r, 500));
    assert.equal((await h.state(page)).seq, seqFixed, 'nothing sent for the fixed vertex');
    assert.deepEqual(await vertexOnServer(daemon, s, 4), fixedStart, 'the fixed vertex stays');

    // Units: centimetres; the scene says so and the FOLD export names them.
    await page.getByTestId('units-select').selectOption('cm');
    await h.waitState(page, (st) => st.scene && st.scene.units === 'cm', undefined, { what: 'units cm' });
    const r = await fetch(`http://127.0.0.1:${daemon.port}/api/sessions/${encodeURIComponent(s.id)}/export?format=fold`,
      { headers: { Authorization: `Bearer ${s.edit_token}` } });
    assert.equal(r.status, 200);
    const doc = JSON.parse(await r.text());
    assert.equal(doc.frame_unit, 'cm');
    assert.ok(fold.filter.numType(doc, 'faces') > 0);
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, '12-exact-input.png') });

    // A phone's width: one column — the view wide and tall, the toolbar within the screen, the side
    // panel below the view (reached by scrolling), its fields usable.
    await page.setViewportSize({ width: 390, height: 844 });
    await h.settleFrames(page);
    const phoneView = await page.getByTestId('viewport').boundingBox();
    assert.ok(phoneView.width >= 380 && phoneView.height >= 400, `3D view ${phoneView.width} × ${phoneView.height} px`);
    for (const id of ['undo', 'redo']) {
      const b = await page.getByTestId(id).boundingBox();
      assert.ok(b && b.x >= 0 && b.x + b.width <= 390, `${id} within the screen: ${JSON.stringify(b)}`);
    }
    const phonePanel = await page.getByTestId('sidebar').boundingBox();
    assert.ok(phonePanel.y >= phoneView.y + phoneView.height - 1 && phonePanel.width >= 380, `side panel ${JSON.stringify(phonePanel)}`);
    // The page scrolls by hand (the wheel over the side panel), not only by script.
    await page.mouse.move(195, 835);
    await page.mouse.wheel(0, 600);
    await page.waitForFunction(() => window.scrollY > 100, null, { timeout: 5000, polling: 50 });
    await page.getByTestId('coord-z').scrollIntoViewIfNeeded();
    const field = await page.getByTestId('coord-z').boundingBox();
    assert.ok(field && field.x + field.width <= 390, `coordinate field ${JSON.stringify(field)}`);
    await page.evaluate(() => window.scrollTo(0, 0));
    await h.settleFrames(page);
    await page.screenshot({ path: path.join(h.ARTIFACTS, '12-exact-input-phone.png'), fullPage: true });
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), []);
  }));
