// Harness of the browser end-to-end tests: the daemon (start, SIGKILL, restart on the same port
// and data dir), Debian's chromium through playwright-core, REST helpers, pointer drags, and pixel
// checks on screenshots (a small PNG decoder on node:zlib).
//
// Environment: DEVSURF_BIN (daemon binary), DEVSURF_WEB (built web app), DEVSURF_CHROMIUM (browser).
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import readline from 'node:readline';
import { fileURLToPath } from 'node:url';
import zlib from 'node:zlib';
import { after, before } from 'node:test';
import { chromium } from 'playwright-core';

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..', '..');
export const BIN = process.env.DEVSURF_BIN || path.join(ROOT, 'build', 'server', 'devsurf');
export const WEB = process.env.DEVSURF_WEB || path.join(ROOT, 'web', 'dist');
export const CHROMIUM = process.env.DEVSURF_CHROMIUM || '/usr/bin/chromium';
export const ARTIFACTS = path.join(ROOT, 'test-artifacts', 'web');
export const EXAMPLES = path.join(ROOT, 'examples');
// The example scenes that open as demo sessions (strips and composites).
export const DEMOS = fs.readdirSync(EXAMPLES).filter((f) => f.endsWith('.json')).sort()
  .map((f) => path.join(EXAMPLES, f))
  .filter((f) => ['strip', 'composite'].includes(JSON.parse(fs.readFileSync(f, 'utf8')).model.kind));

fs.mkdirSync(ARTIFACTS, { recursive: true });

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
export { sleep };

// ---------------------------------------------------------------------------------------------
// Daemon

const live = new Set();
process.on('exit', () => {
  for (const p of live) {
    try { p.kill('SIGKILL'); } catch { /* already gone */ }
  }
});

/**
 * Spawns `devsurf serve` once; resolves with its port, or rejects if it exits before listening or
 * prints no first line within `startTimeoutMs` (demo sessions are built before it listens).
 */
function spawnDaemon({ port, dataDir, demos, extra, logName, append, startTimeoutMs = 20000 }) {
  const log = fs.openSync(path.join(ARTIFACTS, `daemon-${logName}.log`), append ? 'a' : 'w');
  const args = ['serve', '--port', String(port), '--data', dataDir, '--web', WEB,
    ...demos.flatMap((d) => ['--demo', d]), ...extra];
  const proc = spawn(BIN, args, { stdio: ['ignore', 'pipe', log] });
  fs.closeSync(log);
  live.add(proc);
  proc.on('exit', () => live.delete(proc));
  return new Promise((resolve, reject) => {
    const lines = readline.createInterface({ input: proc.stdout });
    let first = true;
    const timer = setTimeout(() => { proc.kill('SIGKILL'); reject(new Error(`devsurf serve: no first line in ${startTimeoutMs / 1000} s`)); }, startTimeoutMs);
    lines.on('line', (line) => {
      if (!first) return;       // keep draining stdout so the pipe never fills
      first = false;
      clearTimeout(timer);
      const m = /^devsurf serving on (http:\/\/127\.0\.0\.1:(\d+)\/)/.exec(line);
      if (!m) { proc.kill('SIGKILL'); reject(new Error(`devsurf serve: unexpected first line ${JSON.stringify(line)}`)); return; }
      resolve({ proc, port: Number(m[2]), url: m[1] });
    });
    proc.on('exit', (code, signal) => {
      if (first) { clearTimeout(timer); first = false; reject(new Error(`devsurf serve exited (${code ?? signal}) before listening`)); }
    });
  });
}

export class Daemon {
  constructor({ name = 'e2e', demos = DEMOS, extra = [], startTimeoutMs = 20000 } = {}) {
    this.name = name;
    this.demos = demos;
    this.extra = extra;
    this.startTimeoutMs = startTimeoutMs;
    this.dataDir = fs.mkdtempSync(path.join(os.tmpdir(), `devsurf-web-${name}-`));
    this.proc = null;
    this.port = null;
    this.url = null;
  }

  /** `devsurf serve --port 0 --data <fresh dir> --web <dist> --demo …` */
  async start() {
    Object.assign(this, await spawnDaemon({ port: 0, dataDir: this.dataDir, demos: this.demos,
      extra: this.extra, logName: this.name, startTimeoutMs: this.startTimeoutMs }));
    return this;
  }

  /** A new daemon on the same data dir and the same port; retries binding for up to `seconds`. */
  async restart({ seconds = 15 } = {}) {
    if (this.proc && this.proc.exitCode === null && this.proc.signalCode === null) await this.kill();
    const deadline = Date.now() + seconds * 1000;
    for (;;) {
      try {
        const d = await spawnDaemon({ port: this.port, dataDir: this.dataDir, demos: this.demos,
          extra: this.extra, logName: this.name, append: true, startTimeoutMs: this.startTimeoutMs });
        if (d.port !== this.port) throw new Error(`restarted on port ${d.port}, wanted ${this.port}`);
        Object.assign(this, d);
        return this;
      } catch (e) {
        if (Date.now() > deadline) throw e;
        await sleep(250);
      }
    }
  }

  /** SIGKILL, as a crash would. */
  async kill() {
    const p = this.proc;
    if (!p || p.exitCode !== null || p.signalCode !== null) return;
    const gone = new Promise((r) => p.once('exit', r));
    p.kill('SIGKILL');
    await gone;
  }

  /** SIGTERM (SIGKILL after 20 s) and remove the data dir. */
  async stop() {
    const p = this.proc;
    if (p && p.exitCode === null && p.signalCode === null) {
      const gone = new Promise((r) => p.once('exit', r));
      p.kill('SIGTERM');
      const t = setTimeout(() => p.kill('SIGKILL'), 20000);
      await gone;
      clearTimeout(t);
    }
    fs.rmSync(this.dataDir, { recursive: true, force: true });
  }

  async api(method, route, { body, token } = {}) {
    const headers = {};
    if (body !== undefined) headers['Content-Type'] = 'application/json';
    if (token) headers.Authorization = `Bearer ${token}`;
    const r = await fetch(`http://127.0.0.1:${this.port}${route}`, {
      method, headers, body: body === undefined ? undefined : JSON.stringify(body),
    });
    const text = await r.text();
    let json = null;
    try { json = text ? JSON.parse(text) : null; } catch { json = text; }
    return { status: r.status, body: json };
  }

  /** POST /api/sessions → {id, edit_token, view_token, links} */
  async createSession(scene) {
    const r = await this.api('POST', '/api/sessions', { body: scene });
    if (r.status !== 201) throw new Error(`POST /api/sessions: ${r.status} ${JSON.stringify(r.body)}`);
    return r.body;
  }

  /** GET /api/sessions/ID → {id, seq, scene, metrics, participants} */
  async session(id, token) {
    const r = await this.api('GET', `/api/sessions/${id}`, { token });
    if (r.status !== 200) throw new Error(`GET /api/sessions/${id}: ${r.status} ${JSON.stringify(r.body)}`);
    return r.body;
  }

  /** Index of the last control point of a curve of the session's current scene. */
  async lastIndex(id, token, curve = 'b') {
    return (await this.session(id, token)).scene.model[curve].points.length - 1;
  }

  editorUrl(id, token) {
    return `${this.url}?session=${encodeURIComponent(id)}&token=${encodeURIComponent(token)}`;
  }
}

export function readScene(name) {
  return JSON.parse(fs.readFileSync(path.join(EXAMPLES, name), 'utf8'));
}

/** The lifted-corner strip without its handle: the last control point of b is free to drag. */
export function freeStrip() {
  const scene = readScene('strip-lifted-corner.json');
  delete scene.model.handles;
  scene.name = 'e2e free strip';
  return scene;
}

/** bench/ws_latency.py strip_scene: two cubic curves of spans + 3 control points each. */
export function stripScene(spans) {
  const n = spans + 3;
  const a = [];
  const b = [];
  for (let i = 0; i < n; i++) {
    const t = (20 * Math.PI / 180) * i / (n - 1);
    const x = 10 * i / (n - 1);
    a.push([x, 0, 0]);
    b.push([x, Math.cos(t), Math.sin(t)]);
  }
  return {
    format: 'devsurf-scene', version: 1, name: `bench strip ${spans} spans`,
    model: { kind: 'strip', a: { degree: 3, points: a }, b: { degree: 3, points: b },
      fixed: [{ curve: 'a', index: 0 }, { curve: 'b', index: 0 }] },
    solver: { fairness: 0.01, regularization: 0.01 },
  };
}

// ---------------------------------------------------------------------------------------------
// Browser

export const LAUNCH_ARGS = ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader', '--disable-background-networking', '--disable-component-update',
  '--disable-sync', '--no-first-run', '--disable-quic'];
export const VIEWPORT = { width: 1280, height: 720 };

export function launchBrowser() {
  return chromium.launch({ executablePath: CHROMIUM, headless: true, args: LAUNCH_ARGS });
}

/** A new context + page; browser console errors and page errors are collected in page.logs. */
export async function newPage(browser) {
  const context = await browser.newContext({ viewport: VIEWPORT });
  const page = await context.newPage();
  page.logs = [];
  page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') page.logs.push(`${m.type()}: ${m.text()}`); });
  page.on('pageerror', (e) => page.logs.push(`pageerror: ${e.message}`));
  return page;
}

export const state = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.__devsurf.state)));

/** Waits until fn(state, arg) holds in the page (fn is serialized: no closures). */
export async function waitState(page, fn, arg, { timeout = 30000, what = String(fn) } = {}) {
  const expr = `(() => { const s = window.__devsurf && window.__devsurf.state;
    return !!s && (${String(fn)})(s, ${JSON.stringify(arg === undefined ? null : arg)}); })()`;
  try {
    await page.waitForFunction(expr, null, { timeout, polling: 50 });
  } catch (e) {
    let s = null;
    try { s = await state(page); } catch { /* page gone */ }
    throw new Error(`timed out waiting for ${what}; state = ${JSON.stringify(summary(s))}; logs = ${JSON.stringify(page.logs?.slice(-5))}`);
  }
}

export function summary(s) {
  if (!s) return s;
  const { connection, session, role, seq, metrics, iterateCount, lastError, participants } = s;
  return { connection, session, role, seq, iterateCount, lastError,
    warp: metrics && metrics.warp_angle_max_deg, participants: participants && participants.length };
}

/** Opens an editor URL and waits for the editor, a connected socket, and a first render. */
export async function openEditor(page, url) {
  await page.goto(url);
  await page.getByTestId('editor').waitFor({ timeout: 30000 });
  await waitForConnected(page);
  await settleFrames(page);
}

/**
 * Opens the editor of a quad_mesh demo session `id` (a daemon's demo, listed by /api/sessions) and
 * waits until M′ is drawn — and, with `spline`, until the editor shows a spline surface.
 */
export async function openQuadMeshDemo(page, daemon, id, { spline = false } = {}) {
  const listed = (await daemon.api('GET', '/api/sessions')).body.sessions;
  const demo = listed.find((s) => s.id === id);
  if (!demo) throw new Error(`${id} is not a demo session: ${listed.map((s) => s.id).join(', ')}`);
  await openEditor(page, daemon.editorUrl(demo.id, demo.edit_token));
  await waitState(page, (st) => st.kind === 'quad_mesh', undefined, { what: 'a quad_mesh session' });
  if (spline)
    await page.waitForFunction(() => document.querySelector('[data-testid="editor"]').dataset.spline === 'true', null, { timeout: 30000 });
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="unfolding-view"]').dataset.faces) > 0);
  return demo;
}

export async function waitForConnected(page, timeout = 30000) {
  await waitState(page, (s) => s.connection === 'connected' && s.seq !== undefined && s.seq !== null,
    undefined, { timeout, what: 'connection connected' });
  await page.waitForFunction(() => {
    const el = document.querySelector('[data-testid="status-connection"]');
    return el && el.textContent.trim().toLowerCase().includes('connected')
      && !el.textContent.trim().toLowerCase().includes('reconnect');
  }, null, { timeout });
}

/** A few animation frames, so that what the state says is on screen. */
export function settleFrames(page, n = 3) {
  return page.evaluate((k) => new Promise((r) => {
    const step = () => (k-- <= 0 ? r() : requestAnimationFrame(step));
    requestAnimationFrame(step);
  }), n);
}

/** Resolves once iterateCount has not changed for `quietMs` (the solve after a release is over). */
export async function waitQuiet(page, { quietMs = 1000, timeout = 30000 } = {}) {
  const deadline = Date.now() + timeout;
  let last = (await state(page)).iterateCount;
  let since = Date.now();
  while (Date.now() < deadline) {
    await sleep(100);
    const c = (await state(page)).iterateCount;
    if (c !== last) { last = c; since = Date.now(); } else if (Date.now() - since >= quietMs) return;
  }
  throw new Error('iterates kept coming');
}

/** Page coordinates (CSS px) of a control point's handle. */
export async function controlPointPagePosition(page, curve, index) {
  const box = await page.getByTestId('viewport').boundingBox();
  const p = await page.evaluate(([c, i]) => window.__devsurf.controlPointScreenPosition(c, i), [curve, index]);
  if (!p || !Number.isFinite(p.x) || !Number.isFinite(p.y)) throw new Error(`no screen position for ${curve}[${index}]: ${JSON.stringify(p)}`);
  return { x: box.x + p.x, y: box.y + p.y, local: p, box };
}

/** Page coordinates (CSS px) of any point target ({curve, index}, {vertex}, {edge, index}). */
export async function pointPagePosition(page, target) {
  const box = await page.getByTestId('viewport').boundingBox();
  const p = await page.evaluate((t) => window.__devsurf.pointScreenPosition(t), target);
  if (!p || !Number.isFinite(p.x) || !Number.isFinite(p.y)) throw new Error(`no screen position for ${JSON.stringify(target)}: ${JSON.stringify(p)}`);
  return { x: box.x + p.x, y: box.y + p.y, local: p, box };
}

/**
 * A real pointer drag: move onto the point, press, move by (dx, dy) in `steps` steps with a pause
 * between them, release.
 */
export async function dragBy(page, from, { dx = 0, dy = -60, steps = 12, pauseMs = 30 } = {}) {
  await page.mouse.move(from.x, from.y);
  await sleep(50);
  await page.mouse.down();
  for (let k = 1; k <= steps; k++) {
    await page.mouse.move(from.x + (dx * k) / steps, from.y + (dy * k) / steps);
    await sleep(pauseMs);
  }
  await page.mouse.up();
}

// Only the 3D canvas: everything else on the page, among it the overlays over the viewport
// (toggles, legend, labels, banners), is hidden while the screenshot is taken, so that the pixel
// checks see what WebGL drew and nothing else.
const CANVAS_ONLY = '* { visibility: hidden !important; } '
  + '[data-testid="viewport"] canvas { visibility: visible !important; }';

/** Screenshot of the viewport element showing the WebGL canvas only; decoded to RGBA. */
/** A drag as a mouse sends it (dragBy), then waits for its iterates and for the page to go quiet.
 *  Returns the page's state from before the drag. */
export async function dragAndSettle(page, from, options) {
  const before = await state(page);
  await dragBy(page, from, options);
  await waitState(page, (st, n) => st.iterateCount > n, before.iterateCount, { what: 'iterates after the drag' });
  await waitQuiet(page);
  return before;
}

export async function screenshotViewport(page, name) {
  const file = path.join(ARTIFACTS, `${name}.png`);
  const viewport = page.getByTestId('viewport');
  if (await viewport.locator('canvas').count() === 0) throw new Error('the viewport holds no canvas');
  const clip = await viewport.boundingBox();
  if (!clip || clip.width < 1 || clip.height < 1) throw new Error(`the viewport has no area: ${JSON.stringify(clip)}`);
  const buf = await page.screenshot({ path: file, clip, animations: 'disabled', style: CANVAS_ONLY });
  return { buf, file, image: decodePNG(buf) };
}

export async function screenshotPage(page, name) {
  const file = path.join(ARTIFACTS, `${name}.png`);
  await page.screenshot({ path: file });
  return file;
}

// ---------------------------------------------------------------------------------------------
// Pixels

/** Decodes an 8-bit, non-interlaced PNG (grey, RGB, palette, grey+alpha or RGBA) into RGBA. */
export function decodePNG(buf) {
  const sig = [137, 80, 78, 71, 13, 10, 26, 10];
  for (let i = 0; i < 8; i++) if (buf[i] !== sig[i]) throw new Error('not a PNG');
  let off = 8;
  let width = 0; let height = 0; let depth = 0; let type = 0; let interlace = 0;
  let palette = null;
  const idat = [];
  while (off < buf.length) {
    const len = buf.readUInt32BE(off);
    const kind = buf.toString('latin1', off + 4, off + 8);
    const data = buf.subarray(off + 8, off + 8 + len);
    off += 12 + len;
    if (kind === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      depth = data[8]; type = data[9]; interlace = data[12];
    } else if (kind === 'PLTE') palette = data;
    else if (kind === 'IDAT') idat.push(data);
    else if (kind === 'IEND') break;
  }
  if (depth !== 8 || interlace !== 0) throw new Error(`unsupported PNG: depth ${depth}, interlace ${interlace}`);
  const channels = { 0: 1, 2: 3, 3: 1, 4: 2, 6: 4 }[type];
  if (!channels) throw new Error(`unsupported PNG colour type ${type}`);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const px = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const out = px.subarray(y * stride, (y + 1) * stride);
    const prev = y > 0 ? px.subarray((y - 1) * stride, y * stride) : null;
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? out[i - channels] : 0;
      const b = prev ? prev[i] : 0;
      const c = prev && i >= channels ? prev[i - channels] : 0;
      let v = line[i];
      switch (filter) {
        case 0: break;
        case 1: v += a; break;
        case 2: v += b; break;
        case 3: v += (a + b) >> 1; break;
        case 4: {
          const p = a + b - c;
          const pa = Math.abs(p - a); const pb = Math.abs(p - b); const pc = Math.abs(p - c);
          v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: throw new Error(`bad PNG filter ${filter}`);
      }
      out[i] = v & 255;
    }
  }
  const rgba = Buffer.alloc(width * height * 4);
  for (let i = 0; i < width * height; i++) {
    let r; let g; let b; let al = 255;
    if (type === 0) { r = g = b = px[i]; } else if (type === 4) { r = g = b = px[2 * i]; al = px[2 * i + 1]; } else if (type === 3) {
      const k = px[i];
      r = palette[3 * k]; g = palette[3 * k + 1]; b = palette[3 * k + 2];
    } else { r = px[i * channels]; g = px[i * channels + 1]; b = px[i * channels + 2]; if (channels === 4) al = px[i * 4 + 3]; }
    rgba[4 * i] = r; rgba[4 * i + 1] = g; rgba[4 * i + 2] = b; rgba[4 * i + 3] = al;
  }
  return { width, height, data: rgba };
}

/** Distinct colours, the share of the most common colour, and the luminance standard deviation. */
export function pixelStats(img) {
  const counts = new Map();
  const n = img.width * img.height;
  let sum = 0; let sum2 = 0;
  for (let i = 0; i < n; i++) {
    const r = img.data[4 * i]; const g = img.data[4 * i + 1]; const b = img.data[4 * i + 2];
    const key = (r << 16) | (g << 8) | b;
    counts.set(key, (counts.get(key) || 0) + 1);
    const l = 0.299 * r + 0.587 * g + 0.114 * b;
    sum += l; sum2 += l * l;
  }
  let top = 0;
  for (const c of counts.values()) top = Math.max(top, c);
  const mean = sum / n;
  return { distinct: counts.size, dominantShare: top / n, lumaStd: Math.sqrt(Math.max(0, sum2 / n - mean * mean)), pixels: n };
}

/** Share of pixels whose colour differs by more than `tolerance` in any channel. */
export function diffFraction(a, b, tolerance = 8) {
  if (a.width !== b.width || a.height !== b.height) throw new Error(`sizes differ: ${a.width}x${a.height} vs ${b.width}x${b.height}`);
  let diff = 0;
  const n = a.width * a.height;
  for (let i = 0; i < n; i++) {
    for (let c = 0; c < 3; c++) {
      if (Math.abs(a.data[4 * i + c] - b.data[4 * i + c]) > tolerance) { diff++; break; }
    }
  }
  return diff / n;
}

export function percentile(values, p) {
  if (!values.length) return NaN;
  const s = [...values].sort((x, y) => x - y);
  return s[Math.min(s.length - 1, Math.floor((p / 100) * s.length))];
}

export function median(values) {
  if (!values.length) return NaN;
  const s = [...values].sort((x, y) => x - y);
  const m = s.length >> 1;
  return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2;
}

// ---------------------------------------------------------------------------------------------
// Fixtures

/** Registers before/after hooks of the calling test file: one daemon and one browser. */
export function useDaemonAndBrowser(name, options = {}) {
  const ctx = { daemon: null, browser: null, pages: [] };
  before(async () => {
    ctx.daemon = await new Daemon({ name, ...options }).start();
    ctx.browser = await launchBrowser();
  });
  after(async () => {
    if (ctx.browser) await ctx.browser.close();
    if (ctx.daemon) await ctx.daemon.stop();
  });
  ctx.page = async () => {
    const p = await newPage(ctx.browser);
    ctx.pages.push(p);
    return p;
  };
  /** Runs a test body; on failure saves a screenshot of every open page and prints their logs. */
  ctx.guard = async (label, fn) => {
    ctx.pages = [];
    try {
      await fn();
    } catch (e) {
      for (const [k, p] of ctx.pages.entries()) {
        try {
          await p.screenshot({ path: path.join(ARTIFACTS, `FAILED-${label}-page${k}.png`) });
          if (p.logs.length) console.log(`page${k} console:\n  ${p.logs.slice(-20).join('\n  ')}`);
        } catch { /* page gone */ }
      }
      throw e;
    } finally {
      for (const p of ctx.pages) await p.context().close().catch(() => {});
    }
  };
  return ctx;
}

/**
 * Calls fn until it returns a truthy value or the time is up; returns the last value. A value
 * with an `ok` key is done only when `ok` is truthy (a condition written as `a && b` yields null
 * or undefined, not false, when it fails); callers assert `ok` on the returned value.
 */
export async function poll(fn, { timeout = 15000, interval = 200 } = {}) {
  const deadline = Date.now() + timeout;
  let v;
  for (;;) {
    v = await fn();
    if (v && (typeof v !== 'object' || !('ok' in v) || Boolean(v.ok))) return v;
    if (Date.now() > deadline) return v;
    await sleep(interval);
  }
}

/** The value of a (readonly) input once the app has filled it. */
export async function inputValueWhenSet(page, testid, timeout = 15000) {
  const input = page.getByTestId(testid);
  await page.waitForFunction((id) => {
    const el = document.querySelector(`[data-testid="${id}"]`);
    return el && el.value && el.value.length > 0;
  }, testid, { timeout });
  return input.inputValue();
}

/** First number in an element's text (status-warp, status-iteration). */
export async function numberIn(page, testid) {
  const text = await page.getByTestId(testid).textContent();
  const m = /-?\d+(?:\.\d+)?(?:e-?\d+)?/i.exec(text || '');
  return { text, value: m ? Number(m[0]) : NaN };
}
