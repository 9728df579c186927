#!/usr/bin/env node
// Page load of the editor (issue 16, item 8): navigation start → first drawn surface, in headless
// chromium on loopback, against a real daemon with one demo session.
//
//   node bench/page_load.mjs [--runs 10] [--parallel 8 (0: none)] [--demo examples/strip-lifted-corner.json]
//
// 1. `--runs` loads one after another, each in a fresh browser context (empty cache): the time
//    from navigation start to the `devsurf:first-surface` performance mark (web/CONTRACT.md; the
//    app sets it right after the first surface geometry was rendered). An app without that mark
//    (older builds) is measured by polling, every animation frame, for `editor.viewport.hasFit`
//    (set just before that first render). Median, min, max and the bytes transferred.
// 2. The server's share: `--parallel` clients fetch the page and every file the browser fetched,
//    all at once over plain HTTP (no browser), `--runs` times, while GET /api/health is sampled
//    every 20 ms (on a worker thread).
// 3. `--parallel` loads at once in one browser (fresh contexts), each timed as in 1, with
//    /api/health sampled the same way. On a small machine with software WebGL (SwiftShader) this
//    measures mostly the browser: its pages share one GPU process and the cores.
// 4. `--parallel` loads at once in as many browsers (one each, as that many users would have:
//    each its own GPU process), launched and warmed by one load beforehand; timed and sampled as
//    in 3. All of them still share this machine's cores with the daemon.
// With every health sampling, a control thread sleeps 10 ms at a time and reports how late it
// woke: a late health answer beside an equally late wake-up is the machine stalling (on a small
// VM, eight software-rendering browsers stall even a sleeping thread by ~0.5 s), not the daemon.
//
// Environment (as tests/web): DEVSURF_BIN (default build/server/devsurf), DEVSURF_WEB (default
// web/dist), DEVSURF_CHROMIUM (default /usr/bin/chromium). playwright-core comes from
// tests/web/node_modules or web/node_modules.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import readline from 'node:readline';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { Worker } from 'node:worker_threads';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const BIN = process.env.DEVSURF_BIN || path.join(ROOT, 'build', 'server', 'devsurf');
const WEB = process.env.DEVSURF_WEB || path.join(ROOT, 'web', 'dist');
const CHROMIUM = process.env.DEVSURF_CHROMIUM || '/usr/bin/chromium';
// As tests/web/lib/harness.mjs: software WebGL, nothing in the background.
const LAUNCH_ARGS = ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader', '--disable-background-networking', '--disable-component-update',
  '--disable-sync', '--no-first-run', '--disable-quic'];
const VIEWPORT = { width: 1280, height: 720 };

function option(name, fallback) {
  const i = process.argv.indexOf(`--${name}`);
  return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
}
const RUNS = Number(option('runs', 10));
const PARALLEL = Number(option('parallel', 8));
const DEMO = path.resolve(option('demo', path.join(ROOT, 'examples', 'strip-lifted-corner.json')));

function loadPlaywright() {
  for (const dir of [path.join(ROOT, 'tests', 'web'), path.join(ROOT, 'web')]) {
    try {
      return createRequire(path.join(dir, 'package.json'))('playwright-core');
    } catch { /* next */ }
  }
  throw new Error('playwright-core not found: npm ci --prefix tests/web (or --prefix web)');
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const quantile = (xs, q) => {
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * s.length))];
};
const fmt = (ms) => `${(ms / 1000).toFixed(3)} s`;

/** `devsurf serve --port 0 --data <tmp> --web WEB --demo DEMO`; resolves with {proc, url, dataDir}. */
function startDaemon() {
  const dataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'devsurf-page-load-'));
  const proc = spawn(BIN, ['serve', '--port', '0', '--data', dataDir, '--web', WEB, '--demo', DEMO,
    '--log-level', 'warn'], { stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((resolve, reject) => {
    const lines = readline.createInterface({ input: proc.stdout });
    const timer = setTimeout(() => { proc.kill('SIGKILL'); reject(new Error('devsurf serve: no first line in 60 s')); }, 60000);
    lines.once('line', (line) => {
      clearTimeout(timer);
      const m = /^devsurf serving on (http:\/\/[^/]+\/)/.exec(line);
      if (!m) { proc.kill('SIGKILL'); reject(new Error(`unexpected first line ${JSON.stringify(line)}`)); return; }
      resolve({ proc, url: m[1], dataDir });
    });
    proc.on('exit', (code, signal) => reject(new Error(`devsurf serve exited (${code ?? signal})`)));
  });
}

async function stopDaemon({ proc, dataDir }) {
  if (proc.exitCode === null && proc.signalCode === null) {
    const gone = new Promise((r) => proc.once('exit', r));
    proc.kill('SIGTERM');
    const t = setTimeout(() => proc.kill('SIGKILL'), 20000);
    await gone;
    clearTimeout(t);
  }
  fs.rmSync(dataDir, { recursive: true, force: true });
}

/** One load in a fresh context: ms from navigation start to the first drawn surface. */
async function loadOnce(browser, link) {
  const context = await browser.newContext({ viewport: VIEWPORT });
  try {
    const page = await context.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(link, { waitUntil: 'commit' });
    const handle = await page.waitForFunction(() => {
      const mark = performance.getEntriesByName('devsurf:first-surface')[0];
      if (mark) return { ms: mark.startTime, how: 'mark' };
      const d = window.__devsurf;
      if (d && d.editor && d.editor.viewport && d.editor.viewport.hasFit) return { ms: performance.now(), how: 'poll' };
      return null;
    }, undefined, { polling: 'raf', timeout: 60000 });
    const result = await handle.jsonValue();
    Object.assign(result, await page.evaluate(() => {
      const nav = performance.getEntriesByType('navigation')[0];
      const resources = performance.getEntriesByType('resource');
      return {
        bytes: (nav ? nav.transferSize : 0) + resources.reduce((s, r) => s + (r.transferSize || 0), 0),
        // The app's own files (what the HTTP-only phase fetches).
        assets: resources.map((r) => r.name).filter((u) => new URL(u).origin === location.origin && !new URL(u).pathname.startsWith('/api/')),
      };
    }));
    if (errors.length) throw new Error(`page errors: ${errors.join('; ')}`);
    return result;
  } finally {
    await context.close();
  }
}

/**
 * GET /api/health every `everyMs` until stop(); stop() resolves with {latencies, late} (ms): the
 * health round trips, sampled on a worker thread of its own so the browser's traffic on the main
 * event loop does not delay them, and the control's late wake-ups (below).
 */
function sampleHealth(base, everyMs) {
  const worker = new Worker(`
    const { parentPort, workerData } = require('node:worker_threads');
    const latencies = [];
    let running = true;
    parentPort.on('message', () => { running = false; });
    (async () => {
      while (running) {
        const t0 = performance.now();
        const r = await fetch(new URL('api/health', workerData.base));
        await r.arrayBuffer();
        if (r.status !== 200) throw new Error('/api/health: ' + r.status);
        const dt = performance.now() - t0;
        latencies.push(dt);
        await new Promise((res) => setTimeout(res, Math.max(0, workerData.everyMs - dt)));
      }
      parentPort.postMessage(latencies);
    })();
  `, { eval: true, workerData: { base, everyMs } });
  // The control: a thread of its own that only sleeps 10 ms at a time and records how late it
  // wakes. It shares the machine with the browsers but not the daemon, so a late health answer
  // that comes with a late wake-up here is the machine's stall (scheduling, the VM's vCPUs), not
  // the daemon's.
  const control = new Worker(`
    const { parentPort } = require('node:worker_threads');
    const late = [];
    let running = true;
    parentPort.on('message', () => { running = false; });
    (async () => {
      while (running) {
        const t0 = performance.now();
        await new Promise((res) => setTimeout(res, 10));
        late.push(Math.max(0, performance.now() - t0 - 10));
      }
      parentPort.postMessage(late);
    })();
  `, { eval: true });
  const collect = (w) => new Promise((resolve, reject) => {
    w.once('message', (values) => { w.terminate(); resolve(values); });
    w.once('error', reject);
  });
  const done = Promise.all([collect(worker), collect(control)]);
  return {
    stop: async () => {
      worker.postMessage('stop');
      control.postMessage('stop');
      const [latencies, late] = await done;
      return { latencies, late };
    },
  };
}

/** Prints the health samples and, beside them, how late the control's 10 ms sleeps woke. */
function reportHealth({ latencies, late }) {
  console.log(`  /api/health every 20 ms (${latencies.length} samples): p50 ${median(latencies).toFixed(1)} ms, `
    + `p95 ${quantile(latencies, 0.95).toFixed(1)} ms, max ${Math.max(...latencies).toFixed(1)} ms`);
  console.log(`  control, a 10 ms sleep on another thread (${late.length} samples): woke late by p95 `
    + `${quantile(late, 0.95).toFixed(1)} ms, max ${Math.max(...late).toFixed(1)} ms`);
}

async function main() {
  const { chromium } = loadPlaywright();
  const daemon = await startDaemon();
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: LAUNCH_ARGS });
  try {
    const sessions = (await (await fetch(new URL('api/sessions', daemon.url))).json()).sessions;
    const demo = sessions[0];
    const link = new URL(`?session=${encodeURIComponent(demo.id)}&token=${encodeURIComponent(demo.edit_token)}`, daemon.url).href;
    console.log(`daemon ${BIN}\nweb ${WEB}\ndemo ${demo.id}`);

    // Warm-up (not counted): the browser's own first start, the daemon's first requests.
    await loadOnce(browser, link);

    const sequential = [];
    for (let i = 0; i < RUNS; ++i) sequential.push(await loadOnce(browser, link));
    const ms = sequential.map((r) => r.ms);
    console.log(`\n${RUNS} loads one after another (fresh context each; measured by ${sequential[0].how}):`);
    console.log(`  first surface: median ${fmt(median(ms))}, min ${fmt(Math.min(...ms))}, max ${fmt(Math.max(...ms))}`);
    console.log(`  transferred: ${(sequential[0].bytes / 1024).toFixed(0)} KiB per load`);

    if (PARALLEL <= 0) return;
    // The server's share alone: PARALLEL clients fetch the page and every file the browser
    // fetched (Accept-Encoding: br, gzip), all at once, without a browser competing for the CPU.
    {
      const urls = [link, ...sequential[0].assets];
      const health = sampleHealth(daemon.url, 20);
      await sleep(200);
      const fetchAll = async () => {
        const t0 = performance.now();
        // node:http, not fetch: the bodies are read as sent, not decompressed on this thread.
        await Promise.all(urls.map((u) => new Promise((resolve, reject) => {
          http.get(u, { headers: { 'Accept-Encoding': 'br, gzip' } }, (r) => {
            r.on('data', () => {});
            r.on('end', () => (r.statusCode === 200 ? resolve() : reject(new Error(`${u}: ${r.statusCode}`))));
          }).on('error', reject);
        })));
        return performance.now() - t0;
      };
      const times = [];
      for (let round = 0; round < RUNS; ++round) {
        times.push(...await Promise.all(Array.from({ length: PARALLEL }, fetchAll)));
        await sleep(50);
      }
      await sleep(200);
      const samples = await health.stop();
      console.log(`\n${PARALLEL} page loads at once over HTTP only, ${RUNS} times (${urls.length} files each, no browser):`);
      console.log(`  all files of a load: median ${fmt(median(times))}, max ${fmt(Math.max(...times))}`);
      reportHealth(samples);
    }

    const health = sampleHealth(daemon.url, 20);
    await sleep(200);
    const t0 = performance.now();
    const parallel = await Promise.all(Array.from({ length: PARALLEL }, () => loadOnce(browser, link)));
    const wall = performance.now() - t0;
    await sleep(200);
    const samples = await health.stop();
    const pms = parallel.map((r) => r.ms);
    console.log(`\n${PARALLEL} loads at once in one browser (wall ${fmt(wall)}):`);
    console.log(`  first surface: median ${fmt(median(pms))}, max ${fmt(Math.max(...pms))}`);
    reportHealth(samples);

    // As eight users would: a browser each (its own GPU process), already open and warmed by one
    // load, all loading at once — still on this machine's cores, beside the daemon.
    const browsers = await Promise.all(Array.from({ length: PARALLEL },
      () => chromium.launch({ executablePath: CHROMIUM, headless: true, args: LAUNCH_ARGS })));
    try {
      for (const b of browsers) await loadOnce(b, link);
      const health2 = sampleHealth(daemon.url, 20);
      await sleep(200);
      const t1 = performance.now();
      const separate = await Promise.all(browsers.map((b) => loadOnce(b, link)));
      const wall2 = performance.now() - t1;
      await sleep(200);
      const samples2 = await health2.stop();
      const sms = separate.map((r) => r.ms);
      console.log(`\n${PARALLEL} loads at once, a browser each (wall ${fmt(wall2)}):`);
      console.log(`  first surface: median ${fmt(median(sms))}, max ${fmt(Math.max(...sms))}`);
      reportHealth(samples2);
    } finally {
      await Promise.all(browsers.map((b) => b.close()));
    }
  } finally {
    await browser.close();
    await stopDaemon(daemon);
  }
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
