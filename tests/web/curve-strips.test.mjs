// 7. Strips between two given curves (issue 6): a quasi_strip demo (Bo et al., twisted pair) shows
//    the strip coloured by warp angle and the σ plot (initial identity and solved mapping); dragging
//    a control point of c1 re-solves the strip (the warp metric updates, σ is redrawn). A
//    conical_strip demo (Chu et al., hull panel) shows its patches and the unfolded patches in the
//    development view; colouring by patch type switches the legend.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('curve-strips', {
  demos: ['quasi-strip-twisted.json', 'conical-strip-hull.json'].map((f) => path.join(h.EXAMPLES, f)),
});

test('a quasi_strip demo drags a control point of c1, the warp metric updates and σ is plotted; a conical_strip demo unfolds its patches',
  { timeout: 240000 }, () => ctx.guard('curve-strips', async () => {
    const { daemon } = ctx;
    const listed = (await daemon.api('GET', '/api/sessions')).body.sessions;
    const quasi = listed.find((s) => s.id === 'demo-quasi-strip-twisted');
    const conical = listed.find((s) => s.id === 'demo-conical-strip-hull');
    assert.ok(quasi && conical, `both demos are listed: ${listed.map((s) => s.id).join(', ')}`);

    // ---- quasi_strip ----
    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(quasi.id, quasi.edit_token));
    await h.waitState(page, (st) => st.kind === 'quasi_strip' && st.metrics && typeof st.metrics.warp_angle_max_deg === 'number',
      undefined, { what: 'a solved quasi_strip session' });
    assert.equal((await page.getByTestId('legend-title').textContent()).trim(), 'warp angle');
    const plot = page.getByTestId('mapping-plot');
    await page.waitForFunction(() => Number(document.querySelector('[data-testid="mapping-plot"]').dataset.points) > 10);
    assert.equal(await plot.locator('canvas').count(), 1, 'the σ plot is drawn on a canvas');
    await page.getByTestId('params-panel').waitFor();
    const warp0 = (await h.numberIn(page, 'status-warp')).value;
    await h.screenshotPage(page, '07-quasi-strip-editor');
    const before = await h.screenshotViewport(page, '07-quasi-strip-before-drag');
    const stats = h.pixelStats(before.image);
    assert.ok(stats.distinct >= 64 && stats.dominantShare < 0.97, `the 3D view is drawn: ${JSON.stringify(stats)}`);

    const server0 = await daemon.session(quasi.id, quasi.view_token);
    const p0 = server0.scene.model.c1.points[12];
    const st0 = await h.state(page);
    const from = await h.pointPagePosition(page, { curve: 'c1', index: 12 });
    await h.dragBy(page, from, { dy: -70, steps: 8, pauseMs: 60 });
    const done = await h.poll(async () => {
      const st = await h.state(page);
      const server = await daemon.session(quasi.id, quasi.view_token);
      return { st, server, ok: st.seq === server.seq && server.seq > server0.seq && st.lastSolved && st.lastSolved.seq === server.seq };
    }, { timeout: 30000 });
    const { st, server } = done;
    assert.ok(done.ok, `the page caught up with the server's solve of the drag (page seq ${st.seq}, solved ${st.lastSolved && st.lastSolved.seq}, server seq ${server.seq})`);
    const p1 = server.scene.model.c1.points[12];
    const warp1 = (await h.numberIn(page, 'status-warp')).value;
    console.log(`quasi_strip drag: ${st.iterateCount - st0.iterateCount} iterates, c1[12] ${p0} → ${p1}, `
      + `max warp ${server0.metrics.warp_angle_max_deg} → ${server.metrics.warp_angle_max_deg} (shown ${warp0} → ${warp1})`);
    assert.equal(st.lastError, null);
    assert.ok(Math.hypot(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]) > 1e-3, 'c1[12] moved');
    assert.ok(st.iterateCount > st0.iterateCount, 'iterates arrived');
    assert.ok(Math.abs(warp1 - server.metrics.warp_angle_max_deg) < 1e-3 * Math.max(1, warp1),
      `the status shows the server's warp metric (${warp1} vs ${server.metrics.warp_angle_max_deg})`);
    assert.notEqual(server.metrics.warp_angle_max_deg, server0.metrics.warp_angle_max_deg, 'the warp metric changed');
    assert.ok(Number(await plot.getAttribute('data-points')) > 10, 'σ is still plotted');
    await h.settleFrames(page);
    const after = await h.screenshotViewport(page, '07-quasi-strip-after-drag');
    assert.ok(h.diffFraction(before.image, after.image) > 0.002, 'the picture changed');
    await h.screenshotPage(page, '07-quasi-strip-after-drag-page');

    // ---- conical_strip ----
    const page2 = await ctx.page();
    await h.openEditor(page2, daemon.editorUrl(conical.id, conical.edit_token));
    await h.waitState(page2, (s) => s.kind === 'conical_strip' && s.metrics && typeof s.metrics.n3 === 'number',
      undefined, { what: 'a conical_strip session' });
    await page2.waitForFunction(() => Number(document.querySelector('[data-testid="development-view"]').dataset.polygons) > 0);
    const patches = Number(await page2.getByTestId('development-view').getAttribute('data-polygons'));
    const metrics = (await h.state(page2)).metrics;
    assert.equal(patches, metrics.n3 + metrics.n4, `the development view unfolded every patch (${patches})`);
    assert.equal((await page2.getByTestId('legend-title').textContent()).trim(), 'normal jump');
    assert.equal(await page2.getByTestId('mapping-panel').isHidden(), true, 'no σ plot for conical strips');
    await page2.getByTestId('strip-color-mode').selectOption('patch_type');
    assert.equal((await page2.getByTestId('legend-title').textContent()).trim(), 'patch type');
    await h.settleFrames(page2);
    await h.screenshotPage(page2, '07-conical-strip-editor');
    const dev = await page2.getByTestId('development-view').screenshot({ path: path.join(h.ARTIFACTS, '07-conical-strip-development.png') });
    const devStats = h.pixelStats(h.decodePNG(dev));
    assert.ok(devStats.distinct >= 16 && devStats.dominantShare < 0.97, `the development view has content: ${JSON.stringify(devStats)}`);

    // A value typed below a parameter's range is refused with the reason, not clamped and sent
    // (a new user's "1" sample on P became 2 without a word, and the strip was rebuilt).
    const seqBefore = (await daemon.session(conical.id, conical.view_token)).seq;
    const np = page2.locator('[data-param="np"] input');
    await np.fill('1');
    await np.press('Enter');
    const slot = page2.locator('.field-error[data-source="params:np"]');
    await slot.waitFor({ state: 'visible', timeout: 5000 });
    assert.match(await slot.textContent(), /samples on P: at least 2/);
    await h.sleep(500);
    assert.equal((await daemon.session(conical.id, conical.view_token)).seq, seqBefore, 'nothing was sent');
    assert.equal(await np.inputValue(), String(metrics.np ?? (await daemon.session(conical.id, conical.view_token)).scene.model.np),
      'the field shows the server\'s value again');
  }));
