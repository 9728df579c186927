// A fitted strip (issue 15) as a demo: its reference points drawn, the fit watched in the status
// line while it solves, the points hidden on request. The lampshade scene is test data, not a
// shipped preset: after some drags its release ends above the presets' warp threshold (see
// docs/architecture.md).
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('fit', {
  demos: [path.join(h.ROOT, 'tests', 'data', 'fit', 'strip-fit-lampshade.json')],
});

test('a demo strip that approximates a scan shows its reference points, fits them when solved, and hides them on request',
  { timeout: 120000 }, () => ctx.guard('fit', async () => {
    const { daemon } = ctx;
    const listed = (await daemon.api('GET', '/api/sessions')).body.sessions;
    // Discovered: every demo whose scene carries model.approximation.
    const fitted = [];
    for (const s of listed) {
      const session = await daemon.session(s.id, s.view_token);
      if (session.scene.model.approximation) fitted.push({ ...s, points: session.scene.model.approximation.points.length });
    }
    assert.ok(fitted.length >= 1, 'the lampshade demo approximates reference points');
    for (const demo of fitted) {
      const page = await ctx.page();
      await h.openEditor(page, daemon.editorUrl(demo.id, demo.edit_token));
      await h.waitForConnected(page);
      await page.getByTestId('reference-toggle').waitFor();
      const shown = await page.evaluate(() => window.__devsurf.editor.viewport.referenceCount);
      assert.equal(shown, demo.points, `${demo.id}: every reference point is drawn`);
      // Solve from the toolbar and watch the fit arrive in the status line.
      await page.getByTestId('solve').click();
      await h.waitState(page, (s) => s.lastSolved && s.metrics && typeof s.metrics.approximation_distance_rms_relative === 'number',
        undefined, { what: 'a solved fit with approximation metrics' });
      const st = await h.state(page);
      const rms = st.metrics.approximation_distance_rms_relative;
      console.log(`${demo.id}: ${shown} reference points, after Solve RMS ${(100 * rms).toFixed(3)} % of their diagonal, `
        + `max ${(100 * st.metrics.approximation_distance_max_relative).toFixed(2)} %, warp ${st.metrics.warp_angle_max_deg}°`);
      assert.ok(rms < 0.005, `${demo.id}: the strip lies on its scan (RMS ${rms} of the diagonal)`);
      assert.match(await page.getByTestId('status-fit').textContent(), /^RMS [\d.]+ % · max [\d.]+ % · [\d.]+ % covered$/);
      await h.settleFrames(page);
      const withPoints = await h.screenshotViewport(page, `09-${demo.id}-reference-points`);
      await page.getByTestId('reference-toggle').locator('input').uncheck();
      await h.settleFrames(page);
      const without = await h.screenshotViewport(page, `09-${demo.id}-reference-hidden`);
      assert.ok(h.diffFraction(withPoints.image, without.image) > 0.001, 'hiding the reference points changes the picture');
      assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');
    }
  }));
