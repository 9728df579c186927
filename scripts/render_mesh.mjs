#!/usr/bin/env node
// Renders an STL file (binary or ASCII) to a PNG with three.js in Debian's chromium (headless,
// SwiftShader): a shaded view from above-front with the mesh's edges, for looking at exports
// (e.g. the STEP file a spline surface exports, as OpenCascade imports and tessellates it; see
// docs/architecture.md "Developable spline surfaces").
//
// usage: node scripts/render_mesh.mjs in.stl out.png [title]
// (playwright-core from tests/web/node_modules, three from web/node_modules; run
//  scripts/setup.sh first.)
import { createRequire } from 'node:module';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(path.join(root, 'tests/web/package.json'));
const { chromium } = require('playwright-core');

const [input, output, title = path.basename(process.argv[2] || '')] = process.argv.slice(2);
if (!input || !output) {
  console.error('usage: node scripts/render_mesh.mjs in.stl out.png [title]');
  process.exit(2);
}

const page = `<!doctype html><html><head><meta charset="utf-8"><style>body{margin:0;background:#fff;font:14px sans-serif}
#t{position:absolute;left:12px;top:8px;color:#222}</style>
<script type="importmap">{"imports":{"three":"/three/build/three.module.js","three/addons/":"/three/examples/jsm/"}}</script>
</head><body><div id="t"></div><script type="module">
import * as THREE from 'three';
import { STLLoader } from 'three/addons/loaders/STLLoader.js';
const geometry = new STLLoader().parse(await (await fetch('/mesh.stl')).arrayBuffer());
geometry.computeVertexNormals();
geometry.computeBoundingBox();
const box = geometry.boundingBox, centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setSize(1000, 750);
renderer.setClearColor(0xffffff);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 0.9));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(1, 2, 3);
scene.add(sun);
const material = new THREE.MeshStandardMaterial({ color: 0x6fa8dc, roughness: 0.55, metalness: 0.05, side: THREE.DoubleSide });
scene.add(new THREE.Mesh(geometry, material));
scene.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 25), new THREE.LineBasicMaterial({ color: 0x1c3550 })));
const camera = new THREE.PerspectiveCamera(35, 1000 / 750, size / 100, size * 10);
camera.up.set(0, 0, 1);
camera.position.copy(centre).add(new THREE.Vector3(0.55, -1.05, 0.75).multiplyScalar(size * 1.05));
camera.lookAt(centre);
renderer.render(scene, camera);
document.getElementById('t').textContent = ${JSON.stringify(title)} + ' — ' + (geometry.attributes.position.count / 3) + ' triangles';
window.rendered = true;
</script></body></html>`;

const server = http.createServer((req, res) => {
  if (req.url === '/') return res.end(page);
  if (req.url === '/mesh.stl') return res.end(fs.readFileSync(input));
  if (req.url.startsWith('/three/')) {
    const file = path.join(root, 'web/node_modules', req.url.split('?')[0]);
    if (!file.startsWith(path.join(root, 'web/node_modules/three/')) || !fs.existsSync(file)) {
      res.statusCode = 404;
      return res.end();
    }
    res.setHeader('content-type', 'text/javascript');
    return res.end(fs.readFileSync(file));
  }
  res.statusCode = 404;
  res.end();
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: ['--use-gl=swiftshader', '--enable-unsafe-swiftshader'] });
try {
  const tab = await browser.newPage({ viewport: { width: 1000, height: 750 } });
  tab.on('pageerror', (e) => console.error('page error:', e.message));
  await tab.goto(`http://127.0.0.1:${server.address().port}/`);
  await tab.waitForFunction(() => window.rendered === true, null, { timeout: 60000 });
  await tab.screenshot({ path: output });
  console.log(`${output}: written`);
} finally {
  await browser.close();
  server.close();
}
