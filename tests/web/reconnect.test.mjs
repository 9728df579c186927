// 5. The page reconnects after the daemon is killed and restarted on the same port and data dir.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

// One demo: the test makes its own session (a daemon with all demos takes ~20 s to start).
const ctx = h.useDaemonAndBrowser('reconnect', { demos: [path.join(h.EXAMPLES, 'strip-twisted.json')] });

const statusText = (page) => page.getByTestId('status-connection').textContent().then((t) => t.trim().toLowerCase());

test('after SIGKILL and a restart the page reconnects and catches up with the server', { timeout: 240000 }, () =>
  ctx.guard('reconnect', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.freeStrip());
    const idx = await daemon.lastIndex(s.id, s.edit_token, 'b');

    const page = await ctx.page();
    await h.openEditor(page, daemon.editorUrl(s.id, s.edit_token));
    // Some edits first, so that the restarted daemon has a journal to replay.
    await h.dragBy(page, await h.controlPointPagePosition(page, 'b', idx), { dy: -50, steps: 10, pauseMs: 40 });
    await h.waitQuiet(page);
    const seqBefore = (await daemon.session(s.id, s.edit_token)).seq;
    await h.poll(async () => ({ ok: (await h.state(page)).seq === seqBefore }));
    assert.equal((await h.state(page)).seq, seqBefore);
    assert.ok(seqBefore > 0, 'the drag was journalled');
    const port = daemon.port;

    // A drag in progress when the daemon dies: it ends there, nothing more is sent and no error
    // is raised for every pointer move (before, each frame's drag came back as "not sent").
    const grab = await h.controlPointPagePosition(page, 'b', idx);
    await page.mouse.move(grab.x, grab.y);
    await page.mouse.down();
    await page.mouse.move(grab.x, grab.y - 10, { steps: 3 });
    // Its first frames are journalled before the daemon dies (the restart replays them).
    const atKill = await h.poll(async () => {
      const [st, server] = [await h.state(page), await daemon.session(s.id, s.edit_token)];
      return { seq: server.seq, ok: server.seq > seqBefore && st.seq === server.seq };
    });
    const seqAtKill = atKill.seq;
    await daemon.kill();
    await h.waitState(page, (st) => st.connection === 'reconnecting' || st.connection === 'offline', undefined,
      { timeout: 20000, what: 'reconnecting/offline after SIGKILL' });
    await page.waitForFunction(() => /reconnecting|offline/i.test(document.querySelector('[data-testid="status-connection"]').textContent),
      null, { timeout: 20000 });
    for (let k = 1; k <= 5; k++) await page.mouse.move(grab.x, grab.y - 10 - 6 * k);
    await page.mouse.up();
    await h.sleep(300);
    assert.ok(await page.getByTestId('error-message').isHidden(), 'the drag cut by the dead connection raised no error');
    const down = await statusText(page);
    console.log(`daemon killed: status shows ${JSON.stringify(down)}`);
    await h.screenshotPage(page, '05-daemon-down');
    // Nothing that edits can be used while the page is not connected: the toolbar and the
    // Solver panel are disabled, and a drag of a point starts nothing (no "not sent" error).
    const disabled = (id) => page.getByTestId(id).isDisabled();
    for (const id of ['undo', 'solve', 'reset']) assert.ok(await disabled(id), `${id} is disabled while offline`);
    const solverInputs = await page.locator('.panel-gui input, .panel-gui select').evaluateAll(
      (els) => els.filter((e) => e.offsetParent !== null).map((e) => e.disabled));
    assert.ok(solverInputs.length > 0 && solverInputs.every(Boolean), `the Solver panel's ${solverInputs.length} controls are disabled while offline`);
    await h.dragBy(page, await h.controlPointPagePosition(page, 'b', idx), { dy: 30, steps: 5, pauseMs: 30 });
    assert.ok(await page.getByTestId('error-message').isHidden(), 'a drag while offline raises no error: it does not start');
    await h.sleep(1500);   // a few failed reconnect attempts

    await daemon.restart();
    assert.equal(daemon.port, port, 'restarted on the same port');
    await h.waitForConnected(page, 90000);
    const done = await h.poll(async () => {
      const st = await h.state(page);
      const server = await daemon.session(s.id, s.edit_token);
      return { st, server, ok: st.seq === server.seq };
    });
    console.log(`reconnected: status ${JSON.stringify(await statusText(page))}, page seq ${done.st.seq}, server seq ${done.server.seq}`);
    assert.equal(done.server.seq, seqAtKill, 'the restarted daemon replayed the journal');
    assert.equal(done.st.seq, done.server.seq, 'the page seq matches the server\'s');
    assert.equal(done.st.session, s.id);
    assert.equal(done.st.connection, 'connected');
    // (Undo stays disabled: a restarted daemon has no history to undo.)
    for (const id of ['solve', 'reset']) assert.ok(!(await disabled(id)), `${id} is enabled again once connected`);
    await h.screenshotPage(page, '05-reconnected');

    // And editing works again.
    const c0 = done.st.iterateCount;
    await h.dragBy(page, await h.controlPointPagePosition(page, 'b', idx), { dy: 40, steps: 8, pauseMs: 40 });
    await h.waitState(page, (st, n) => st.iterateCount > n, c0, { what: 'iterates after reconnecting' });
    await h.waitQuiet(page);
    const again = await h.poll(async () => {
      const st = await h.state(page);
      const server = await daemon.session(s.id, s.edit_token);
      return { st, server, ok: st.seq === server.seq && server.seq > seqAtKill };
    });
    assert.ok(again.server.seq > seqAtKill, 'edits after the reconnect are applied');
    assert.equal(again.st.seq, again.server.seq);
  }));
