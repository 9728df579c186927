// Manual end-to-end walk through the app against a daemon this script starts itself
// (../build/server/devsurf on port 8091, fresh data dir), with screenshots.
// Usage: node scripts/check.cjs [out-dir]
const { chromium } = require('playwright-core');
const { spawn } = require('child_process');
const fs = require('fs');
const path = require('path');

const out = process.argv[2] || '/tmp/devsurf-check';
const port = 8091;
const base = `http://127.0.0.1:${port}`;
const repo = path.resolve(__dirname, '../..');
const data = fs.mkdtempSync('/tmp/devsurf-check-data-');
let daemon = null;

function startDaemon() {
  const examples = fs.readdirSync(path.join(repo, 'examples')).filter((f) => f.endsWith('.json'));
  const args = ['serve', '--port', String(port), '--data', data, '--web', path.join(repo, 'web/dist')];
  for (const f of examples) args.push('--demo', path.join(repo, 'examples', f));
  daemon = spawn(path.join(repo, 'build/server/devsurf'), args, { stdio: 'ignore' });
  return new Promise((resolve) => setTimeout(resolve, 700));
}

function stopDaemon() {
  if (daemon) daemon.kill('SIGTERM');
  daemon = null;
  return new Promise((resolve) => setTimeout(resolve, 300));
}

const results = [];
function check(name, ok, detail = '') {
  results.push(`${ok ? 'PASS' : 'FAIL'} ${name}${detail ? ` — ${detail}` : ''}`);
}

(async () => {
  fs.mkdirSync(out, { recursive: true });
  await startDaemon();
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
  const ctx = await browser.newContext({ viewport: { width: 1280, height: 720 }, acceptDownloads: true });
  const page = await ctx.newPage();
  const logs = [];
  page.on('pageerror', (e) => logs.push(`[pageerror] ${e.stack || e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') logs.push(`[console] ${m.text()}`); });

  // A. new session from a preset
  await page.goto(base + '/');
  await page.getByTestId('preset-select').selectOption('strip-lifted-corner');
  await page.getByTestId('new-session').click();
  await page.getByTestId('editor').waitFor();
  await page.waitForFunction(() => window.__devsurf.state.connection === 'connected');
  const session = await page.evaluate(() => window.__devsurf.state.session);
  check('new session from preset', !session.startsWith('demo-'), session);
  const shareEdit = await page.getByTestId('share-edit').inputValue();
  const shareView = await page.getByTestId('share-view').inputValue();
  check('share links', shareEdit.includes(`session=${session}`) && shareView.includes('token=') && shareEdit !== shareView, `${shareEdit} | ${shareView}`);
  await page.waitForTimeout(300);
  await page.screenshot({ path: `${out}/A-new-session.png` });

  // C. select b[3] by clicking, F to fix it, select b[4], H to add a handle
  const vp = await page.getByTestId('viewport').boundingBox();
  const click = async (curve, index) => {
    const p = await page.evaluate(([c, i]) => window.__devsurf.controlPointScreenPosition(c, i), [curve, index]);
    await page.mouse.click(vp.x + p.x, vp.y + p.y);
  };
  await click('b', 3);
  await page.keyboard.press('f');
  await page.waitForFunction(() => window.__devsurf.state.scene.model.fixed.some((f) => f.curve === 'b' && f.index === 3));
  check('F fixes the selected point', true);
  await click('b', 4);
  await page.keyboard.press('h');
  await page.waitForFunction(() => (window.__devsurf.state.scene.model.handles || []).some((f) => f.curve === 'b' && f.index === 4));
  check('H adds a handle', true);
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => !(window.__devsurf.state.scene.model.handles || []).some((f) => f.curve === 'b' && f.index === 4));
  check('Ctrl+Z undoes it', true);
  await page.keyboard.press('Control+Shift+Z');
  await page.waitForFunction(() => (window.__devsurf.state.scene.model.handles || []).some((f) => f.curve === 'b' && f.index === 4));
  check('Ctrl+Shift+Z redoes it', true);
  const it0 = await page.evaluate(() => window.__devsurf.state.iterateCount);
  await page.keyboard.press('s');
  await page.waitForFunction((n) => window.__devsurf.state.iterateCount > n, it0);
  check('S solves', true);
  await page.waitForTimeout(600);
  await page.screenshot({ path: `${out}/C-fixed-handle.png` });

  // D. a value the server rejects: developability weight 0 (must be > 0)
  const field = page.locator('[data-setting="developability_weight"] input');
  await field.fill('0');
  await field.press('Enter');
  await page.getByTestId('error-message').waitFor({ state: 'visible' });
  const errText = await page.getByTestId('error-message').innerText();
  const slotText = await page.locator('.field-error[data-source="solver:developability_weight"]').innerText();
  check('server error shown as toast and next to the control', /developability_weight/.test(errText) && slotText.length > 0, `${errText.replace(/\n/g, ' ')} | ${slotText}`);
  const reverted = await field.inputValue();
  check('control reverted to the server value', reverted === '1', reverted);
  await page.screenshot({ path: `${out}/D-error.png` });
  // a valid change is acked
  await field.fill('2');
  await field.press('Enter');
  await page.waitForFunction(() => window.__devsurf.state.scene.solver.developability_weight === 2);
  check('solver change acked and applied', true);

  // E. a second participant with the view link
  const page2 = await ctx.newPage();
  page2.on('pageerror', (e) => logs.push(`[pageerror 2] ${e.stack || e.message}`));
  await page2.goto(shareView);
  await page2.waitForFunction(() => window.__devsurf.state.connection === 'connected');
  check('view link joins as view', (await page2.evaluate(() => window.__devsurf.state.role)) === 'view');
  await page.waitForFunction(() => window.__devsurf.state.participants.length === 2);
  check('participants list shows both', (await page.getByTestId('participant').count()) === 2);
  await click('a', 2); // page 1 selects a[2]: page 2 sees it highlighted
  await page2.waitForFunction(() => window.__devsurf.state.participants.some((p) => p.selection && p.selection.index === 2));
  const vp2 = await page2.getByTestId('viewport').boundingBox();
  const q = await page2.evaluate(() => window.__devsurf.controlPointScreenPosition('b', 5));
  await page2.mouse.move(vp2.x + q.x, vp2.y + q.y);
  await page2.mouse.down();
  await page2.mouse.move(vp2.x + q.x + 20, vp2.y + q.y - 30, { steps: 5 });
  await page2.mouse.up();
  await page2.getByTestId('error-message').waitFor({ state: 'visible' });
  check('viewer drag is forbidden by the server', /forbidden/i.test(await page2.getByTestId('error-message').innerText()));
  await page2.waitForTimeout(300);
  await page2.screenshot({ path: `${out}/E-viewer.png` });

  // F. exports
  for (const [id, ext] of [['export-json', '.json'], ['export-obj', '.obj']]) {
    const [dl] = await Promise.all([page.waitForEvent('download'), page.getByTestId(id).click()]);
    const file = await dl.path();
    const text = fs.readFileSync(file, 'utf8');
    check(`${id} downloads`, dl.suggestedFilename().endsWith(ext) && text.length > 100, `${dl.suggestedFilename()} ${text.length} B`);
  }

  // G. help overlay and accessibility mode
  await page.keyboard.press('?');
  check('help overlay toggles on', await page.getByTestId('help-overlay').isVisible());
  await page.keyboard.press('?');
  check('help overlay toggles off', !(await page.getByTestId('help-overlay').isVisible()));
  await page.getByTestId('toggle-a11y').click();
  await page.waitForTimeout(400);
  await page.screenshot({ path: `${out}/G-a11y.png` });
  await page.getByTestId('toggle-a11y').click();

  // H. reconnect: the daemon goes away and comes back
  await stopDaemon();
  await page.waitForFunction(() => window.__devsurf.state.connection === 'reconnecting');
  check('status reconnecting', (await page.getByTestId('status-connection').innerText()) === 'reconnecting');
  await page.waitForTimeout(1500);
  await page.screenshot({ path: `${out}/H-reconnecting.png` });
  await startDaemon();
  await page.waitForFunction(() => window.__devsurf.state.connection === 'connected', null, { timeout: 15000 });
  check('reconnected and resynced', (await page.evaluate(() => window.__devsurf.state.scene.solver.developability_weight)) === 2);

  // I. open a scene file; a broken one shows the server's message
  const start = await ctx.newPage();
  await start.goto(base + '/');
  await start.getByTestId('scene-file').setInputFiles({ name: 'bad.json', mimeType: 'application/json', buffer: Buffer.from('{"format":"devsurf-scene","version":1,"model":{"kind":"strip","a":{"degree":3,"points":[[0,0]]},"b":{"degree":3,"points":[]}}}') });
  await start.getByTestId('error-message').waitFor({ state: 'visible' });
  check('bad scene file rejected with the path', /model\.a/.test(await start.getByTestId('error-message').innerText()), (await start.getByTestId('error-message').innerText()).replace(/\n/g, ' '));
  await start.screenshot({ path: `${out}/I-bad-file.png` });
  await start.getByTestId('scene-file').setInputFiles(path.join(repo, 'examples/strip-cylinder.json'));
  await start.getByTestId('editor').waitFor();
  await start.waitForFunction(() => window.__devsurf.state.connection === 'connected');
  check('scene file opens a session', true);

  for (const l of logs) console.log(l);
  console.log(results.join('\n'));
  console.log(`${results.filter((r) => r.startsWith('PASS')).length} passed, ${results.filter((r) => r.startsWith('FAIL')).length} failed`);
  await browser.close();
  await stopDaemon();
})().catch(async (e) => {
  console.error(e);
  console.log(results.join('\n'));
  await stopDaemon();
  process.exit(1);
});
