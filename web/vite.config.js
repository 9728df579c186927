import { defineConfig } from 'vite';

// `npm run dev` proxies the API and the WebSocket to a running daemon
// (default http://127.0.0.1:8090, override with DEVSURF_SERVER).
const server = process.env.DEVSURF_SERVER || 'http://127.0.0.1:8090';

export default defineConfig({
  base: './',
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    chunkSizeWarningLimit: 1000,
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
