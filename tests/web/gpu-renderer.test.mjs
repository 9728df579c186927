// The view on a hardware GPU. This machine renders WebGL in software (SwiftShader), so the editor
// takes its software path (no antialiasing, the probe context kept). Here the page is told, as a
// GPU's driver would tell it, that the renderer is hardware: the editor must then drop its probe
// context, create an antialiased renderer of its own, and draw every kind of demo with it.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import * as h from './lib/harness.mjs';

// The first example scene of every kind (discovered, so a new kind is covered).
const firstOfKind = new Map();
for (const file of fs.readdirSync(h.EXAMPLES).filter((f) => f.endsWith('.json')).sort()) {
  const kind = JSON.parse(fs.readFileSync(path.join(h.EXAMPLES, file), 'utf8')).model.kind;
  if (!firstOfKind.has(kind)) firstOfKind.set(kind, path.join(h.EXAMPLES, file));
}
const ctx = h.useDaemonAndBrowser('gpu-renderer', { demos: [...firstOfKind.values()] });

/**
 * UNMASKED_RENDERER_WEBGL answered as a discrete GPU's driver answers it (both WebGL versions);
 * contexts given up through WEBGL_lose_context are counted in window.__contextsLost.
 */
function pretendHardwareGPU() {
  const UNMASKED_RENDERER_WEBGL = 0x9246;
  window.__contextsLost = 0;
  for (const proto of [WebGLRenderingContext.prototype, WebGL2RenderingContext.prototype]) {
    const getParameter = proto.getParameter;
    proto.getParameter = function patched(p) {
      if (p === UNMASKED_RENDERER_WEBGL) return 'ANGLE (NVIDIA Corporation, NVIDIA GeForce RTX 3060/PCIe/SSE2, OpenGL 4.5.0)';
      return getParameter.call(this, p);
    };
    const getExtension = proto.getExtension;
    proto.getExtension = function patchedExtension(name) {
      const extension = getExtension.call(this, name);
      if (name === 'WEBGL_lose_context' && extension && !extension.__counted) {
        const loseContext = extension.loseContext.bind(extension);
        extension.loseContext = () => { window.__contextsLost += 1; loseContext(); };
        extension.__counted = true;
      }
      return extension;
    };
  }
}

test('told it runs on a hardware GPU, the editor draws every kind of demo with an antialiased renderer of its own', { timeout: 240000 }, () =>
  ctx.guard('gpu-renderer', async () => {
    const { daemon } = ctx;
    const listed = (await daemon.api('GET', '/api/sessions')).body.sessions;
    const kinds = new Map();
    for (const demo of listed) kinds.set((await daemon.session(demo.id, demo.view_token)).scene.model.kind, demo);
    assert.deepEqual([...kinds.keys()].sort(), [...firstOfKind.keys()].sort(), 'a demo of every kind');
    for (const [kind, demo] of kinds) {
      const page = await ctx.page();
      await page.addInitScript(pretendHardwareGPU);
      await h.openEditor(page, daemon.editorUrl(demo.id, demo.edit_token));
      const gl = await page.evaluate(() => {
        const view = window.__devsurf.editor.viewport;
        const context = view.renderer.getContext();
        return {
          softwareGL: view.softwareGL,
          contextsLost: window.__contextsLost,
          antialias: context.getContextAttributes().antialias,
          lost: context.isContextLost(),
          canvases: document.querySelectorAll('[data-testid="viewport"] canvas').length,
          ownCanvas: view.renderer.domElement === document.querySelector('[data-testid="viewport"] canvas'),
        };
      });
      assert.equal(gl.softwareGL, false, `${kind}: the editor believes the GPU`);
      assert.equal(gl.antialias, true, `${kind}: the hardware path asks for antialiasing`);
      assert.equal(gl.contextsLost, 1, `${kind}: the probe context was given up, once`);
      assert.equal(gl.lost, false, `${kind}: the renderer's own context is live (only the probe's was lost)`);
      assert.equal(gl.canvases, 1, `${kind}: one canvas in the view`);
      assert.ok(gl.ownCanvas, `${kind}: the canvas shown is the renderer's`);
      const shot = await h.poll(async () => {
        await h.settleFrames(page);
        const sh = await h.screenshotViewport(page, `gpu-${kind}`);
        const st = h.pixelStats(sh.image);
        return { st, ok: st.distinct >= 64 && st.dominantShare < 0.97 && st.lumaStd > 4 };
      });
      console.log(`${kind} (${demo.id}): ${shot.st.distinct} colours, dominant ${(100 * shot.st.dominantShare).toFixed(1)} %`);
      assert.ok(shot.ok, `${kind}: the view is drawn (${shot.st.distinct} colours, dominant ${shot.st.dominantShare})`);
      // (Driver performance messages such as "GPU stall due to ReadPixels", from the screenshot's
      // read-back, are not errors.)
      assert.deepEqual(page.logs.filter((l) => /pageerror|GL_INVALID|CONTEXT_LOST|WebGL: /.test(l)), [], `${kind}: no WebGL errors`);
    }
  }));
