// Manual smoke check: loads the app from a running daemon in Debian's chromium, takes
// screenshots of the start page and the editor, drags a control point and checks iterates.
// Usage: node scripts/smoke.cjs [http://127.0.0.1:8090] [out-dir]
const { chromium } = require('playwright-core');

const base = process.argv[2] || 'http://127.0.0.1:8090';
const out = process.argv[3] || '/tmp/devsurf-shots';

(async () => {
  require('fs').mkdirSync(out, { recursive: true });
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
  const page = await browser.newPage({ viewport: { width: 1280, height: 720 } });
  const logs = [];
  page.on('console', (m) => logs.push(`[${m.type()}] ${m.text()}`));
  page.on('pageerror', (e) => logs.push(`[pageerror] ${e.stack || e.message}`));
  await page.goto(base + '/');
  await page.getByTestId('demo-session').first().waitFor();
  await page.screenshot({ path: `${out}/start.png` });
  const demo = page.getByTestId('demo-session').filter({ hasText: process.env.DEMO || 'twisted' }).first();
  await demo.click();
  await page.getByTestId('editor').waitFor();
  await page.waitForFunction(() => window.__devsurf.state.connection === 'connected');
  await page.waitForTimeout(500);
  await page.screenshot({ path: `${out}/editor.png` });

  const before = await page.evaluate(() => window.__devsurf.state.iterateCount);
  const box = await page.getByTestId('viewport').boundingBox();
  const p = await page.evaluate(() => window.__devsurf.controlPointScreenPosition('b', 4));
  await page.mouse.move(box.x + p.x, box.y + p.y);
  await page.mouse.down();
  for (let i = 1; i <= 15; i++) {
    await page.mouse.move(box.x + p.x + i * 3, box.y + p.y - i * 5);
    await page.waitForTimeout(30);
  }
  await page.screenshot({ path: `${out}/dragging.png` });
  await page.mouse.up();
  await page.waitForTimeout(1200);
  const after = await page.evaluate(() => ({
    iterates: window.__devsurf.state.iterateCount, seq: window.__devsurf.state.seq,
    warp: window.__devsurf.state.metrics.warp_angle_max_deg, times: window.__devsurf.iterateApplyTimes().slice(-5),
    err: window.__devsurf.state.lastError,
  }));
  console.log('iterates before', before, 'after', JSON.stringify(after));
  await page.screenshot({ path: `${out}/after-drag.png` });
  await page.keyboard.press('?');
  await page.screenshot({ path: `${out}/help.png` });
  await page.keyboard.press('Escape');
  console.log(logs.join('\n'));
  await browser.close();
})().catch((e) => {
  console.error(e);
  process.exit(1);
});
