#!/usr/bin/env node
// Renders an STL file (binary or ASCII) to a PNG with three.js in Debian's chromium (headless,
// SwiftShader): a shaded view from above-front with the mesh's edges, for looking at exports
// (e.g. the STEP file a spline surface exports, as OpenCascade imports and tessellates it; see
// docs/architecture.md "Developable spline surfaces").
//
// usage: node scripts/render_mesh.mjs in.stl out.png [title] [--reference shape.off|.stl]
//        [--up x|y|z] [--view X,Y,Z] [--edges DEG]
// --reference draws a second mesh (e.g. the shape a composite approximates) translucent grey
// behind the first; --up picks the vertical axis (default z), --view the direction from the centre
// to the camera (default 0.55,-1.05,0.75 in a z-up frame), --edges the crease angle in degrees
// above which mesh edges are drawn (default 25).
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

const positional = [];
const flags = { reference: null, up: 'z', view: null, edges: '25' };
for (let i = 2; i < process.argv.length; ++i) {
  const a = process.argv[i];
  if (a === '--reference' || a === '--up' || a === '--view' || a === '--edges') flags[a.slice(2)] = process.argv[++i];
  else positional.push(a);
}
const [input, output, title = path.basename(positional[0] || '')] = positional;
if (!input || !output || !['x', 'y', 'z'].includes(flags.up)) {
  console.error('usage: node scripts/render_mesh.mjs in.stl out.png [title] [--reference shape.off|.stl] [--up x|y|z] [--view X,Y,Z] [--edges DEG]');
  process.exit(2);
}

/// An OFF file's triangles (polygons as fans) as a flat array of vertex coordinates.
function offTriangles(text) {
  const tokens = text.replace(/#[^\n]*/g, ' ').split(/\s+/).filter(Boolean);
  let k = tokens[0].toUpperCase() === 'OFF' ? 1 : 0;
  const nv = Number(tokens[k++]), nf = Number(tokens[k++]);
  k++;
  const v = [];
  for (let i = 0; i < nv; ++i, k += 3) v.push([Number(tokens[k]), Number(tokens[k + 1]), Number(tokens[k + 2])]);
  const out = [];
  for (let f = 0; f < nf; ++f) {
    const n = Number(tokens[k++]);
    const ids = tokens.slice(k, k + n).map(Number);
    k += n;
    for (let j = 1; j + 1 < n; ++j) for (const id of [ids[0], ids[j], ids[j + 1]]) out.push(...v[id]);
  }
  return out;
}
let reference = null;
if (flags.reference) {
  reference = flags.reference.toLowerCase().endsWith('.off')
    ? { kind: 'triangles', data: offTriangles(fs.readFileSync(flags.reference, 'utf8')) }
    : { kind: 'stl' };
}
const upAxis = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] }[flags.up];
const viewDirection = flags.view ? flags.view.split(',').map(Number) : null;

const page = `<!doctype html><html><head><meta charset="utf-8"><style>body{margin:0;background:#fff;font:14px sans-serif}
#t{position:absolute;left:12px;top:8px;color:#222}</style>
<script type="importmap">{"imports":{"three":"/three/build/three.module.js","three/addons/":"/three/examples/jsm/"}}</script>
</head><body><div id="t"></div><script type="module">
import * as THREE from 'three';
import { STLLoader } from 'three/addons/loaders/STLLoader.js';
const geometry = new STLLoader().parse(await (await fetch('/mesh.stl')).arrayBuffer());
geometry.computeVertexNormals();
geometry.computeBoundingBox();
const referenceKind = ${JSON.stringify(reference ? reference.kind : null)};
let referenceGeometry = null;
if (referenceKind === 'stl') referenceGeometry = new STLLoader().parse(await (await fetch('/reference.stl')).arrayBuffer());
if (referenceKind === 'triangles') {
  referenceGeometry = new THREE.BufferGeometry();
  referenceGeometry.setAttribute('position', new THREE.Float32BufferAttribute(await (await fetch('/reference.json')).json(), 3));
}
if (referenceGeometry) referenceGeometry.computeVertexNormals();
const box = geometry.boundingBox.clone();
if (referenceGeometry) { referenceGeometry.computeBoundingBox(); box.union(referenceGeometry.boundingBox); }
const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
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
scene.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, ${Number(flags.edges)}), new THREE.LineBasicMaterial({ color: 0x1c3550 })));
if (referenceGeometry) {
  const ghost = new THREE.MeshStandardMaterial({ color: 0xb8b8b8, roughness: 0.9, transparent: true, opacity: 0.55, side: THREE.DoubleSide, depthWrite: false });
  scene.add(new THREE.Mesh(referenceGeometry, ghost));
}
const camera = new THREE.PerspectiveCamera(35, 1000 / 750, size / 100, size * 10);
camera.up.set(...${JSON.stringify(upAxis)});
const view = ${JSON.stringify(viewDirection)};
const direction = view ? new THREE.Vector3(...view).normalize() : new THREE.Vector3(0.55, -1.05, 0.75).normalize();
camera.position.copy(centre).add(direction.multiplyScalar(size * 1.05 * 1.4));
camera.lookAt(centre);
renderer.render(scene, camera);
document.getElementById('t').textContent = ${JSON.stringify(title)} + ' — ' + (geometry.attributes.position.count / 3) + ' triangles';
window.rendered = true;
</script></body></html>`;

const server = http.createServer((req, res) => {
  if (req.url === '/') return res.end(page);
  if (req.url === '/mesh.stl') return res.end(fs.readFileSync(input));
  if (req.url === '/reference.stl' && reference) return res.end(fs.readFileSync(flags.reference));
  if (req.url === '/reference.json' && reference) return res.end(JSON.stringify(reference.data));
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
