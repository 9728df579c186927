// 1. A demo session opened from the start page: editor, connected, a 3D view that is not blank.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('open-demo');

test('a demo opened from the start page shows the editor, connected, with a rendered strip', { timeout: 120000 }, () =>
  ctx.guard('open-demo', async () => {
    const { daemon } = ctx;
    const listed = (await daemon.api('GET', '/api/sessions')).body.sessions;
    assert.equal(listed.length, h.DEMOS.length, 'one demo session per example scene');

    const page = await ctx.page();
    await page.goto(daemon.url);
    await page.getByTestId('start-page').waitFor();
    const demos = page.getByTestId('demo-session');
    await demos.first().waitFor();
    assert.equal(await demos.count(), listed.length, 'the start page lists every demo session');
    const ids = await demos.evaluateAll((els) => els.map((e) => e.getAttribute('data-session-id')));
    assert.deepEqual([...ids].sort(), listed.map((s) => s.id).sort());
    // The tagline speaks of every kind the demos show, not of strips alone.
    const tagline = await page.getByTestId('tagline').textContent();
    for (const kind of [/strips/, /curved-crease/, /quad-mesh/, /spline surfaces/]) assert.match(tagline, kind);
    // Every demo card shows a picture of its surface, drawn by the server and decoded by the page.
    assert.equal(await page.getByTestId('my-sessions').isVisible(), false, 'a new browser has no sessions of its own');
    await page.waitForFunction((n) => {
      const imgs = [...document.querySelectorAll('[data-testid="demo-session"] img[data-testid="session-thumbnail"]')];
      return imgs.length === n && imgs.every((img) => img.dataset.state === 'loaded' && img.complete && img.naturalWidth === 320);
    }, listed.length, { timeout: 90000 });
    await h.screenshotPage(page, '01-start-page');

    const demo = listed.find((s) => /lifted/.test(s.id)) || listed[0];
    await page.locator(`[data-testid="demo-session"][data-session-id="${demo.id}"]`).click();
    await page.getByTestId('editor').waitFor({ timeout: 30000 });
    await h.waitForConnected(page);

    const s = await h.state(page);
    assert.equal(s.session, demo.id);
    assert.equal(s.role, 'edit', 'a demo opens with its (public) edit token');
    assert.equal(s.lastError, null);
    assert.match((await page.getByTestId('status-connection').textContent()).trim(), /^connected$/i);
    const server = await daemon.session(demo.id, demo.view_token);
    assert.equal(s.seq, server.seq, 'the page has seen the server seq');
    assert.ok(Number.isFinite(s.metrics?.warp_angle_max_deg), 'metrics arrived with the state');
    // A strip's view options are its own: the quad-mesh colouring and Gauss image stay hidden.
    assert.equal(await page.getByTestId('quad-color-mode').isVisible(), false, 'no quad-mesh colouring on a strip');
    assert.equal(await page.getByText('Gauss image', { exact: true }).isVisible(), false, 'no Gauss image toggle on a strip');
    assert.equal(await page.getByText('Rulings', { exact: true }).isVisible(), true, 'a strip shows its rulings toggle');

    // The 3D view: many colours, no single colour covering (nearly) all of it.
    const shot = await h.poll(async () => {
      await h.settleFrames(page);
      const sh = await h.screenshotViewport(page, '01-viewport');
      const st = h.pixelStats(sh.image);
      return { ...sh, st, ok: st.distinct >= 64 && st.dominantShare < 0.97 && st.lumaStd > 4 };
    });
    console.log(`viewport ${shot.image.width}x${shot.image.height}: ${shot.st.distinct} colours, `
      + `dominant ${(100 * shot.st.dominantShare).toFixed(1)} %, luma σ ${shot.st.lumaStd.toFixed(1)}`);
    assert.ok(shot.image.width >= 300 && shot.image.height >= 200, 'the viewport has a usable size');
    assert.ok(shot.st.distinct >= 64, `the 3D canvas has ${shot.st.distinct} distinct colours`);
    assert.ok(shot.st.dominantShare < 0.97, `one colour covers ${(100 * shot.st.dominantShare).toFixed(1)} % of the canvas`);
    assert.ok(shot.st.lumaStd > 4, `luminance σ ${shot.st.lumaStd}`);

    await page.getByTestId('development-view').waitFor();
    await h.screenshotPage(page, '01-editor');

    // Back on the start page, the demo just opened is listed under "Your sessions", with its
    // picture and its links; Forget removes it from the list.
    await page.goto(daemon.url);
    const mine = page.getByTestId('my-session');
    await mine.first().waitFor();
    assert.equal(await mine.count(), 1);
    assert.equal(await mine.first().getAttribute('data-session-id'), demo.id);
    const editLink = await mine.first().getByTestId('my-session-edit').getAttribute('href');
    assert.equal(new URL(editLink).searchParams.get('token'), demo.edit_token);
    await page.waitForFunction(() => {
      const img = document.querySelector('[data-testid="my-session"] img[data-testid="session-thumbnail"]');
      return img && img.dataset.state === 'loaded' && img.naturalWidth === 320;
    }, undefined, { timeout: 30000 });
    await h.screenshotPage(page, '01-start-page-your-sessions');
    // With sessions listed, the ways to start are still above the fold at 1280 × 720, unscrolled.
    assert.equal(await page.evaluate(() => window.scrollY), 0);
    for (const [what, locator] of [['Start drawing', page.getByTestId('blank-sheet')], ['New session', page.getByTestId('new-session')],
      ['the file drop zone', page.locator('.drop-zone')]]) {
      const box = await locator.boundingBox();
      assert.ok(box && box.y >= 0 && box.y + box.height <= h.VIEWPORT.height,
        `${what} is in view at ${h.VIEWPORT.width} × ${h.VIEWPORT.height}: ${JSON.stringify(box)}`);
    }
    await mine.first().getByTestId('forget-session').click();
    assert.equal(await page.getByTestId('my-sessions').isVisible(), false, 'forgotten');
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
  }));
