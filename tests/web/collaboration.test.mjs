// 3. Two browser contexts share a session through the edit link; 4. a view link cannot edit: a
//    press on a point selects it and starts no drag (nothing is sent, no error comes back).
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

// One demo: its sessions are made by the test; one demo lists (a daemon with all demos takes ~20 s to start).
const ctx = h.useDaemonAndBrowser('collaboration', { demos: [path.join(h.EXAMPLES, 'strip-twisted.json')] });

const participantIds = (st) => (st.participants || []).map((p) => String(p.id)).sort();

test('two contexts on the edit link see each other and each other\'s edits', { timeout: 180000 }, () =>
  ctx.guard('collab', async () => {
    const { daemon } = ctx;
    const s = await daemon.createSession(h.freeStrip());
    const idx = await daemon.lastIndex(s.id, s.edit_token, 'b');

    const a = await ctx.page();
    await h.openEditor(a, daemon.editorUrl(s.id, s.edit_token));
    const link = await h.inputValueWhenSet(a, 'share-edit');
    const url = new URL(link, daemon.url);
    assert.equal(url.searchParams.get('session'), s.id, `share-edit link ${link}`);
    assert.equal(url.searchParams.get('token'), s.edit_token, 'share-edit carries the edit token');

    const b = await ctx.page();
    await h.openEditor(b, new URL(`/?session=${url.searchParams.get('session')}&token=${url.searchParams.get('token')}`, daemon.url).href);
    assert.equal((await h.state(b)).role, 'edit');

    for (const p of [a, b]) {
      await h.waitState(p, (st) => (st.participants || []).length === 2, undefined, { what: 'two participants' });
      await p.waitForFunction(() => document.querySelectorAll('[data-testid="participants"] [data-testid="participant"]').length === 2);
    }
    const [sa, sb] = [await h.state(a), await h.state(b)];
    assert.deepEqual(participantIds(sa), participantIds(sb), 'both list the same participants');
    const domIds = await b.locator('[data-testid="participant"]').evaluateAll((els) => els.map((e) => e.getAttribute('data-participant-id')).sort());
    assert.deepEqual(domIds, participantIds(sb), 'the participant list shows the presence ids');
    const server = await daemon.session(s.id, s.view_token);
    assert.equal(server.participants.length ?? server.participants, 2);

    const beforeB = await h.screenshotViewport(b, '03-b-before');
    const from = await h.controlPointPagePosition(a, 'b', idx);
    await h.dragBy(a, from, { dy: -60, steps: 12, pauseMs: 40 });
    await h.waitState(b, (st, n) => st.seq > n.seq && st.iterateCount > n.iterateCount, sb, { what: 'B sees A\'s edit' });
    await h.waitQuiet(b);
    const done = await h.poll(async () => {
      const [ea, eb] = [await h.state(a), await h.state(b)];
      const srv = await daemon.session(s.id, s.view_token);
      return { ea, eb, srv, ok: ea.seq === srv.seq && eb.seq === srv.seq };
    });
    console.log(`B: seq ${sb.seq} → ${done.eb.seq}, iterates ${sb.iterateCount} → ${done.eb.iterateCount}; A: iterates ${done.ea.iterateCount}`);
    assert.ok(done.eb.seq > sb.seq, 'B\'s seq advanced');
    assert.ok(done.eb.iterateCount > sb.iterateCount, 'B applied iterates');
    assert.equal(done.eb.seq, done.srv.seq, 'B has seen every edit');
    assert.equal(done.ea.seq, done.srv.seq, 'A has seen every edit');
    assert.ok(Math.abs(done.eb.metrics.warp_angle_max_deg - done.ea.metrics.warp_angle_max_deg) < 1e-9, 'same metrics on both');
    // B's activity list says in words what A did (a drag is one line, at its release).
    const activity = await b.getByTestId('activity').locator('li').allTextContents();
    assert.ok(activity.length === 1 && activity[0].endsWith(` moved b[${idx}]`), `B's activity list: ${JSON.stringify(activity)}`);

    await h.settleFrames(b);
    const afterB = await h.screenshotViewport(b, '03-b-after');
    await h.screenshotViewport(a, '03-a-after');
    const changed = h.diffFraction(beforeB.image, afterB.image);
    console.log(`B's viewport pixels changed by A's drag: ${(100 * changed).toFixed(2)} %`);
    assert.ok(changed > 0.01, `B's picture changed by ${(100 * changed).toFixed(2)} %`);
    await h.screenshotPage(b, '03-b-editor');
  }));

test('a view-only link cannot edit', { timeout: 180000 }, () =>
  ctx.guard('view-only', async () => {
    const { daemon } = ctx;
    // The creator of a session knows both links: make one from the start page's example list.
    const a = await ctx.page();
    await a.goto(daemon.url);
    await a.getByTestId('start-page').waitFor();
    const select = a.getByTestId('preset-select');
    const options = await select.locator('option').evaluateAll((els) => els.map((o) => ({ value: o.value, label: o.textContent })));
    const preset = options.find((o) => /^strip-lifted/.test(o.value)) || options.find((o) => /lifted/i.test(`${o.value} ${o.label}`)) || options[0];
    await select.selectOption(preset.value);
    // The example is introduced by its summary as the file has it, not its paper references.
    const shipped = h.readScene(`${preset.value}.json`);
    assert.equal((await a.getByTestId('preset-summary').textContent()).trim(), shipped.summary);
    await a.getByTestId('new-session').click();
    await a.getByTestId('editor').waitFor({ timeout: 30000 });
    await h.waitForConnected(a);
    const sa = await h.state(a);
    assert.equal(sa.role, 'edit', 'the creator edits');
    const listed = (await daemon.api('GET', '/api/sessions')).body.sessions.map((x) => x.id);
    assert.ok(!listed.includes(sa.session), 'a new session is not one of the public demos');

    const editLink = new URL(await h.inputValueWhenSet(a, 'share-edit'), daemon.url);
    const link = await h.inputValueWhenSet(a, 'share-view');
    const url = new URL(link, daemon.url);
    const viewToken = url.searchParams.get('token');
    assert.equal(url.searchParams.get('session'), sa.session, `share-view link ${link}`);
    assert.equal(editLink.searchParams.get('session'), sa.session);
    assert.ok(viewToken && viewToken !== editLink.searchParams.get('token'), 'the view link has its own token');
    const id = sa.session;
    const first = await daemon.session(id, viewToken);     // 200: the server accepts it as a token
    const idx = first.scene.model.b.points.length - 1;

    const v = await ctx.page();
    // Every message the view page sends: a view-only editor starts no drag, so sends none.
    const sent = [];
    v.on('websocket', (ws) => ws.on('framesent', ({ payload }) => sent.push(String(payload))));
    await h.openEditor(v, url.href);
    const sv = await h.state(v);
    assert.equal(sv.role, 'view');
    assert.equal(sv.session, id);
    // Its Selection panel does not tell it to drag points (a tryout's student read "drag it to
    // reshape the design" on a page that cannot).
    const selectionHint = await v.locator('.panel p.muted.small', { hasText: 'Click a point' }).first().textContent();
    assert.match(selectionHint, /view only/, `the view page's hint: ${selectionHint}`);
    const seqBefore = (await daemon.session(id, viewToken)).seq;
    const pointBefore = (await daemon.session(id, viewToken)).scene.model.b.points[idx];
    const aBefore = await h.state(a);

    const from = await h.controlPointPagePosition(v, 'b', idx);
    await h.dragBy(v, from, { dy: -60, steps: 12, pauseMs: 40 });
    await h.sleep(1000);
    const after = await h.state(v);
    const server = await daemon.session(id, viewToken);
    // The view page does not drag (a drag the server then refused ended in a "forbidden" toast):
    // the press selects the point, no drag message leaves the page, no error comes back.
    const drags = sent.filter((m) => /"type":"drag/.test(m));
    assert.deepEqual(drags, [], 'the view page sent no drag');
    assert.equal(after.lastError, null, `no error: ${JSON.stringify(after.lastError)}`);
    assert.equal(await v.getByTestId('error-message').first().isVisible(), false, 'no error toast');
    assert.ok(after.selection && after.selection.curve === 'b' && after.selection.index === idx, `the pressed point is selected: ${JSON.stringify(after.selection)}`);
    await h.screenshotPage(v, '04-view-only-after-drag');
    assert.equal(server.seq, seqBefore, 'the server applied no edit');
    assert.deepEqual(server.scene.model.b.points[idx], pointBefore, 'the control point did not move');
    assert.equal(after.seq, seqBefore, 'the view page saw no edit');
    assert.equal((await h.state(a)).seq, aBefore.seq, 'the editor saw no edit');

    // Keyboard shortcuts that edit (S solve, F fix, H handle, Ctrl+Z undo, Ctrl+Shift+Z redo) send
    // nothing from the view page (the pressed point still selected, so F and H have a target):
    // each is answered locally, "view only".
    const sentBefore = sent.length;
    for (const key of ['s', 'f', 'h', 'Control+z', 'Control+Shift+z']) {
      await v.evaluate(() => { window.__devsurf.state.lastError = null; });
      await v.keyboard.press(key);
      await h.sleep(150);
      const error = (await h.state(v)).lastError;
      assert.ok(error && error.code === 'forbidden' && /view only/.test(error.message), `${key}: ${JSON.stringify(error)}`);
    }
    const edits = sent.slice(sentBefore).filter((m) => !/"type":"(presence|ping)"/.test(m));
    assert.deepEqual(edits, [], 'no edit left the view page');
    // Said once, not once per refused control.
    const shown = await v.evaluate(() => [...document.querySelectorAll('.field-error')]
      .filter((el) => !el.hidden && /view only/.test(el.textContent)).length);
    assert.ok(shown <= 1, `the "view only" message shows in ${shown} places at once`);
    assert.equal((await daemon.session(id, viewToken)).seq, seqBefore, 'the server applied no edit');
  }));
