// Iterate apply + render time in the page (moved from tests/web: timings belong in bench/):
// main-thread time to apply and render one iterate of a strip of ~10 000 unknowns (370 spans:
// 373 + 373 control points) while a pointer drags it for 8 s, from the performance.measure entries
// 'iterate-apply' exposed as window.__devsurf.iterateApplyTimes(), and the frame intervals.
//
//   node --test bench/iterate_apply.mjs
//
// Environment as tests/web (DEVSURF_BIN, DEVSURF_WEB, DEVSURF_CHROMIUM; npm ci --prefix tests/web).
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from '../tests/web/lib/harness.mjs';

// One demo: the test makes its own session (a daemon with all demos takes ~20 s to start).
const ctx = h.useDaemonAndBrowser('measure', { demos: [path.join(h.EXAMPLES, 'strip-twisted.json')] });
const SPANS = 370;
const SECONDS = 8;

test('measure: iterate apply + render time on a 10 000-unknown strip', { timeout: 240000 }, () =>
  ctx.guard('measure', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.stripScene(SPANS));
    const info = await daemon.session(s.id, s.edit_token);
    const idx = info.scene.model.b.points.length - 1;
    const unknowns = info.metrics?.unknowns;

    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    await h.screenshotViewport(page, '06-large-strip-before');
    const st0 = await h.state(page);
    const before = await page.evaluate(() => window.__devsurf.iterateApplyTimes().length);

    // Frame intervals (rAF) while dragging: with software GL (SwiftShader) the raster work of a
    // frame happens off the main thread and is not part of 'iterate-apply'; the frame rate shows it.
    await page.evaluate(() => {
      window.__e2eFrames = [];
      window.__e2eFramesOn = true;
      let last = performance.now();
      const tick = (t) => {
        window.__e2eFrames.push(t - last);
        last = t;
        if (window.__e2eFramesOn) requestAnimationFrame(tick);
      };
      requestAnimationFrame(tick);
    });

    // Drag back and forth for SECONDS, one pointer move per ~16 ms (or slower: each move waits
    // until the page has handled it).
    const from = await h.controlPointPagePosition(page, 'b', idx);
    await page.mouse.move(from.x, from.y);
    await page.mouse.down();
    const t0 = Date.now();
    let k = 0;
    while (Date.now() - t0 < SECONDS * 1000) {
      k++;
      await page.mouse.move(from.x + 10 * Math.sin(k / 15), from.y - 60 * Math.sin(k / 30));
      await h.sleep(16);
    }
    await page.mouse.up();
    const moves = k;
    const frames = await page.evaluate(() => { window.__e2eFramesOn = false; return window.__e2eFrames.slice(1); });
    await h.waitQuiet(page, { quietMs: 1500, timeout: 60000 });

    const all = await page.evaluate(() => window.__devsurf.iterateApplyTimes());
    const st = await h.state(page);
    await h.screenshotViewport(page, '06-large-strip-after');
    const times = all.filter((t) => Number.isFinite(t));
    const iterates = st.iterateCount - st0.iterateCount;
    const line = (label, xs) => `${label}: n=${xs.length} median ${h.median(xs).toFixed(2)} ms, p95 ${h.percentile(xs, 95).toFixed(2)} ms, `
      + `max ${Math.max(...xs).toFixed(2)} ms`;
    console.log(`[measure] strip of ${SPANS} spans (${2 * (SPANS + 3)} control points, ${unknowns} unknowns), `
      + `${moves} pointer moves in ${SECONDS} s → ${iterates} iterates applied in the page`);
    console.log(`[measure] iterate-apply (main thread: decode + geometry update + render) ${line('all', times)}`);
    console.log(`[measure] frame interval while dragging (rAF): ${line('frames', frames)}, `
      + `${frames.filter((f) => f > 100).length} frames over 100 ms`);
    console.log(`[measure] iterateApplyTimes() held ${all.length} entries (${before} before the drag)`);
    assert.ok(iterates > 0, 'iterates arrived while dragging');
    assert.ok(times.length > 0, 'iterateApplyTimes() recorded durations');
  }));
