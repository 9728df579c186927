import fs from 'node:fs/promises';
import path from 'node:path';
import { promisify } from 'node:util';
import zlib from 'node:zlib';
import { defineConfig } from 'vite';

// `npm run dev` proxies the API and the WebSocket to a running daemon
// (default http://127.0.0.1:8090, override with DEVSURF_SERVER).
const server = process.env.DEVSURF_SERVER || 'http://127.0.0.1:8090';

// Compressible files of the build also get precompressed siblings FILE.br (Brotli, quality 11)
// and FILE.gz (gzip -9): the daemon serves those as they are (server/src/StaticAssets.cpp checks
// that they decode to FILE) instead of compressing at start-up at a lower quality.
const brotli = promisify(zlib.brotliCompress);
const gzip = promisify(zlib.gzip);
const COMPRESSIBLE = /\.(js|mjs|css|html|json|svg|map|txt|wasm)$/;
function precompress() {
  return {
    name: 'devsurf-precompress',
    apply: 'build',
    // From the files as written: Vite still rewrites chunks (preload lists) in generateBundle.
    async writeBundle(options, bundle) {
      await Promise.all(Object.keys(bundle).filter((name) => COMPRESSIBLE.test(name)).map(async (name) => {
        const file = path.join(options.dir, name);
        const bytes = await fs.readFile(file);
        if (bytes.length < 256) return;
        const [br, gz] = await Promise.all([
          brotli(bytes, { params: { [zlib.constants.BROTLI_PARAM_QUALITY]: 11, [zlib.constants.BROTLI_PARAM_SIZE_HINT]: bytes.length } }),
          gzip(bytes, { level: 9 }),
        ]);
        await Promise.all([fs.writeFile(`${file}.br`, br), fs.writeFile(`${file}.gz`, gz)]);
      }));
    },
  };
}

export default defineConfig({
  base: './',
  plugins: [precompress()],
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    chunkSizeWarningLimit: 1000,
    rolldownOptions: {
      output: {
        // three.js (~600 KB) in a chunk of its own: an app change does not invalidate it in caches.
        // Vite names every chunk by its content hash (assets/NAME-HASH.js), which is what lets the
        // daemon serve /assets/ as immutable.
        codeSplitting: {
          groups: [{ name: 'three', test: /node_modules[\\/]three[\\/]/ }],
        },
      },
    },
  },
  server: {
    // The example scenes are bundled from ../examples.
    fs: { allow: ['..'] },
    proxy: {
      '/api': { target: server, changeOrigin: true },
      '/ws': { target: server.replace(/^http/, 'ws'), ws: true },
    },
  },
  test: {
    include: ['test/**/*.test.js'],
    environment: 'node',
  },
});
