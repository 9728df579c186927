// Start from your own mesh (issue 15): the start page uploads a triangle mesh (CGAL's
// patch-01.off, a box nobody here made) to POST /api/approximations, opens the glued developable
// patches as a session, and Solve makes them isometric to their unfoldings near the mesh. A mesh
// that is not a disk is refused on the start page with the field named.
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

const ctx = h.useDaemonAndBrowser('approximate', { demos: [path.join(h.EXAMPLES, 'strip-twisted.json')] });

function cgalMesh(member) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'devsurf-cgal-'));
  execFileSync('tar', ['-xzf', '/usr/share/doc/libcgal-dev/data.tar.gz', '-C', dir, member]);
  return path.join(dir, member);
}

test('a mesh uploaded on the start page opens as glued developable patches that Solve makes isometric near the mesh',
  { timeout: 180000 }, () => ctx.guard('approximate', async () => {
    const { daemon } = ctx;
    const mesh = cgalMesh('data/meshes/patch-01.off');
    const page = await ctx.page();
    await page.goto(daemon.url);
    await page.getByTestId('start-page').waitFor();
    await page.getByTestId('mesh-file').setInputFiles(mesh);
    await page.getByTestId('mesh-patches').fill('8');
    await page.getByTestId('mesh-faces').fill('800');
    await h.screenshotPage(page, '10-start-page-mesh');
    await page.getByTestId('approximate-mesh').click();
    await page.getByTestId('editor').waitFor({ timeout: 60000 });
    await h.waitForConnected(page);
    const opened = await h.state(page);
    const server = await daemon.session(opened.session, new URL(page.url()).searchParams.get('token'));
    assert.equal(server.scene.model.kind, 'quad_mesh');
    assert.equal(server.scene.model.reference.faces.length, 1396, "patch-01.off's triangles are the reference");
    assert.equal(server.scene.name, 'patch-01 in developable patches');
    await page.getByTestId('solve').click();
    await h.waitState(page, (s) => s.lastSolved && s.metrics && typeof s.metrics.approximation_distance_rms_relative === 'number'
      && s.metrics.length_error < 1e-3, undefined, { what: 'solved patches with approximation metrics', timeout: 90000 });
    const st = await h.state(page);
    console.log(`patch-01 in ${server.scene.model.mesh.faces.length} faces: L-Err ${(100 * st.metrics.length_error).toFixed(4)} %, `
      + `RMS ${(100 * st.metrics.approximation_distance_rms_relative).toFixed(3)} % of the diagonal`);
    assert.ok(st.metrics.approximation_distance_rms_relative < 0.01, 'the patches stay on the mesh');
    assert.match(await page.getByTestId('status-fit').textContent(), /^RMS [\d.]+ % · max [\d.]+ % · [\d.]+ % covered$/);
    const shot = await h.poll(async () => {
      await h.settleFrames(page);
      const sh = await h.screenshotViewport(page, '10-approximate-patch-01');
      const s = h.pixelStats(sh.image);
      return { ...sh, s, ok: s.distinct >= 64 && s.dominantShare < 0.97 };
    });
    await h.screenshotPage(page, '10-approximate-editor');
    assert.ok(shot.ok, `the patches are drawn (${shot.s.distinct} colours, dominant ${shot.s.dominantShare})`);
    assert.deepEqual(page.logs.filter((l) => l.startsWith('pageerror')), [], 'no uncaught page errors');

    // A closed mesh: refused on the start page, naming the field; the page stays usable.
    const closed = path.join(path.dirname(mesh), 'tetrahedron.off');
    fs.writeFileSync(closed, 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n');
    const start = await ctx.page();
    await start.goto(daemon.url);
    await start.getByTestId('start-page').waitFor();
    await start.getByTestId('mesh-file').setInputFiles(closed);
    await start.getByTestId('approximate-mesh').click();
    const error = start.locator('.start-status .field-error');
    await error.waitFor({ state: 'visible' });
    assert.match(await error.textContent(), /approximate tetrahedron\.off: .*mesh.*closed/);
    assert.equal(await start.getByTestId('approximate-mesh').isDisabled(), false);
  }));
