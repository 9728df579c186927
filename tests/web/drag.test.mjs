// 2. Dragging a control point with real pointer events streams iterates, the release solve makes
//    the strip developable again, and the picture changes.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

// One demo: the test makes its own session (a daemon with all demos takes ~20 s to start).
const ctx = h.useDaemonAndBrowser('drag', { demos: [path.join(h.EXAMPLES, 'strip-twisted.json')] });

test('dragging the last control point of b streams iterates and ends developable', { timeout: 180000 }, () =>
  ctx.guard('drag', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.freeStrip());
    const idx = await daemon.lastIndex(s.id, s.edit_token, 'b');
    const initial = (await daemon.session(s.id, s.edit_token)).scene.model.b.points[idx];

    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    const before = await h.screenshotViewport(page, '02-before-drag');
    const st0 = await h.state(page);
    const from = await h.controlPointPagePosition(page, 'b', idx);
    assert.ok(from.local.x >= 0 && from.local.y >= 0 && from.local.x <= from.box.width && from.local.y <= from.box.height,
      `b[${idx}] is inside the viewport: ${JSON.stringify(from.local)} in ${from.box.width}x${from.box.height}`);

    await h.dragAndSettle(page, from, { dy: -60, steps: 12, pauseMs: 40 });

    // After the drag_end solve: the page's metrics are the server's latest, and developable.
    const done = await h.poll(async () => {
      const st = await h.state(page);
      const server = await daemon.session(s.id, s.edit_token);
      return { st, server, ok: st.seq === server.seq && st.metrics.warp_angle_max_deg < 0.05 };
    });
    const { st, server } = done;
    console.log(`after drag: ${st.iterateCount - st0.iterateCount} iterates, seq ${st0.seq} → ${st.seq}, `
      + `warp max ${st.metrics.warp_angle_max_deg}°`);
    assert.ok(st.iterateCount > st0.iterateCount, 'iterates were applied');
    assert.ok(st.seq > st0.seq, 'the drag was applied as edits');
    assert.equal(st.seq, server.seq, 'the page has seen every edit');
    assert.ok(st.metrics.warp_angle_max_deg < 0.05, `warp angle ${st.metrics.warp_angle_max_deg}° after the release solve`);
    assert.ok(server.metrics.warp_angle_max_deg < 0.05, `server warp angle ${server.metrics.warp_angle_max_deg}°`);
    assert.equal(st.lastError, null);
    const warpShown = await h.numberIn(page, 'status-warp');
    assert.ok(warpShown.value < 0.05, `status-warp shows ${JSON.stringify(warpShown.text)}`);
    const iterShown = await h.numberIn(page, 'status-iteration');
    assert.ok(Number.isFinite(iterShown.value), `status-iteration shows ${JSON.stringify(iterShown.text)}`);

    const moved = server.scene.model.b.points[idx];
    const dist = Math.hypot(...moved.map((v, k) => v - initial[k]));
    assert.ok(dist > 0.05, `b[${idx}] moved by ${dist} (from ${initial} to ${moved})`);

    await h.settleFrames(page);
    const after = await h.screenshotViewport(page, '02-after-drag');
    const changed = h.diffFraction(before.image, after.image);
    console.log(`viewport pixels changed by the drag: ${(100 * changed).toFixed(2)} %`);
    assert.ok(changed > 0.01, `only ${(100 * changed).toFixed(2)} % of the viewport changed`);
  }));
