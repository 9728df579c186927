// Issue 18: the web app behind HAProxy in front of three daemons on one PostgreSQL
// (scripts/cluster_local.py). The editor's socket names its session (/ws?session=ID), so HAProxy
// routes it to the daemon that holds the session; that daemon is SIGKILLed mid-design and the page
// reconnects to the daemon that takes the session over, with every acknowledged edit, and edits on.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';
import * as h from './lib/harness.mjs';

const CLUSTER = path.join(h.ROOT, 'scripts', 'cluster_local.py');
const ctx = { dir: null, cluster: null, browser: null };

function psql(uri, sql) {
  return execFileSync('psql', [uri, '-X', '-q', '-t', '-A', '-c', sql], { encoding: 'utf8' }).trim();
}

async function api(method, route, { body, token } = {}) {
  const headers = {};
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  if (token) headers.Authorization = `Bearer ${token}`;
  const r = await fetch(`http://127.0.0.1:${ctx.cluster.port}${route}`, {
    method, headers, body: body === undefined ? undefined : JSON.stringify(body),
  });
  const text = await r.text();
  return { status: r.status, body: text ? JSON.parse(text) : null };
}

before(async () => {
  ctx.dir = fs.mkdtempSync(path.join(os.tmpdir(), 'devsurf-web-cluster-'));
  fs.chmodSync(ctx.dir, 0o755);  // the PostgreSQL server (account postgres when run as root) enters it
  execFileSync('/usr/bin/python3', [CLUSTER, 'start', ctx.dir, '--nodes', '3', '--port', '0', '--lease-ms', '2000',
    '--fast', '--', '--web', h.WEB], { env: { ...process.env, DEVSURF_BIN: h.BIN }, stdio: ['ignore', 'ignore', 'inherit'] });
  ctx.cluster = JSON.parse(fs.readFileSync(path.join(ctx.dir, 'cluster.json'), 'utf8'));
  ctx.browser = await h.launchBrowser();
});

after(async () => {
  if (ctx.browser) await ctx.browser.close();
  if (ctx.dir) execFileSync('/usr/bin/python3', [CLUSTER, 'destroy', ctx.dir], { stdio: 'ignore' });
});

test('behind HAProxy the editor keeps its session when the daemon holding it is killed', { timeout: 240000 }, async () => {
  const s = (await api('POST', '/api/sessions', { body: h.freeStrip() })).body;
  const page = await h.newPage(ctx.browser);
  try {
    await h.openEditor(page, `http://127.0.0.1:${ctx.cluster.port}/?session=${encodeURIComponent(s.id)}&token=${encodeURIComponent(s.edit_token)}`);
    const shown = await api('GET', `/api/sessions/${s.id}`, { token: s.edit_token });
    const idx = shown.body.scene.model.b.points.length - 1;
    await h.dragBy(page, await h.controlPointPagePosition(page, 'b', idx), { dy: -50, steps: 10, pauseMs: 40 });
    await h.waitQuiet(page);
    const before = await h.poll(async () => {
      const st = await h.state(page);
      const server = (await api('GET', `/api/sessions/${s.id}`, { token: s.edit_token })).body;
      return { st, server, ok: server && st.seq === server.seq && st.seq > 0 };
    });
    assert.ok(before.ok, 'the drag was acknowledged and shown');
    const holder = psql(ctx.cluster.postgres, `SELECT lease_owner FROM sessions WHERE id = '${s.id}'`);
    const node = ctx.cluster.nodes.find((n) => n.id === holder);
    assert.ok(node, `the session is held by a node of the cluster (${holder})`);

    process.kill(node.pid, 'SIGKILL');
    const killedAt = Date.now();
    await h.waitState(page, (st) => st.connection !== 'connected', undefined, { timeout: 20000, what: 'the drop' });
    await h.waitForConnected(page, 30000);
    const back = await h.poll(async () => {
      const st = await h.state(page);
      const r = await api('GET', `/api/sessions/${s.id}`, { token: s.edit_token });
      return { st, r, ok: r.status === 200 && st.seq === r.body.seq };
    }, { timeout: 30000 });
    const newHolder = psql(ctx.cluster.postgres, `SELECT lease_owner FROM sessions WHERE id = '${s.id}'`);
    console.log(`${holder} killed: the page was connected to ${newHolder} again after ${Date.now() - killedAt} ms, seq ${back.st.seq}`);
    assert.notEqual(newHolder, holder);
    assert.equal(back.r.body.seq, before.server.seq, 'every acknowledged edit is there');
    assert.equal(back.st.seq, back.r.body.seq);
    await h.screenshotPage(page, '18-cluster-taken-over');

    const c0 = back.st.iterateCount;
    await h.dragBy(page, await h.controlPointPagePosition(page, 'b', idx), { dy: 40, steps: 8, pauseMs: 40 });
    await h.waitState(page, (st, n) => st.iterateCount > n, c0, { what: 'iterates from the new daemon' });
    await h.waitQuiet(page);
    const again = await h.poll(async () => {
      const st = await h.state(page);
      const server = (await api('GET', `/api/sessions/${s.id}`, { token: s.edit_token })).body;
      return { st, server, ok: server.seq > before.server.seq && st.seq === server.seq };
    });
    assert.ok(again.ok, 'edits after the takeover are applied and shown');
  } finally {
    await page.context().close().catch(() => {});
  }
});
