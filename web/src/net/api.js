// REST helpers (docs/protocol.md): sessions and exports.

export class ApiError extends Error {
  constructor(status, body) {
    const e = (body && body.error) || {};
    const text = e.message || `HTTP ${status}`;
    super(e.path && !text.includes(e.path) ? `${e.path}: ${text}` : text);
    this.status = status;
    this.code = e.code || `http_${status}`;
    this.path = e.path;
  }
}

async function readJson(res) {
  const text = await res.text();
  if (!text) return null;
  try {
    return JSON.parse(text);
  } catch {
    return { error: { code: 'invalid_response', message: text.slice(0, 200) } };
  }
}

function apiUrl(path, base = './') {
  // Relative to the page so the app also works under a path prefix.
  return new URL(`api/${path}`, new URL(base, globalThis.location.href)).toString();
}

/** GET /api/sessions → [{id, name, participants, edit_token, view_token}] */
export async function listSessions() {
  const res = await fetch(apiUrl('sessions'));
  const body = await readJson(res);
  if (!res.ok) throw new ApiError(res.status, body);
  return (body && body.sessions) || [];
}

/**
 * POST /api/sessions (scene) → {id, edit_token, view_token, links}; `solved`: the session starts
 * from the scene's solved state (?solved=true).
 */
export async function createSession(scene, apiKey, { solved = false } = {}) {
  const headers = { 'Content-Type': 'application/json' };
  if (apiKey) headers.Authorization = `Bearer ${apiKey}`;
  const res = await fetch(apiUrl(solved ? 'sessions?solved=true' : 'sessions'), { method: 'POST', headers, body: typeof scene === 'string' ? scene : JSON.stringify(scene) });
  const body = await readJson(res);
  if (!res.ok) throw new ApiError(res.status, body);
  return body;
}

/**
 * POST /api/approximations?format=…&segments=…&faces=… with a mesh file as the body → {scene,
 * summary}: glued developable patches approximating the mesh (issue 15).
 */
export async function approximateMesh(file, { format, segments, faces, name }, apiKey) {
  const query = new URLSearchParams({ format });
  if (segments > 1) query.set('segments', String(segments));
  if (faces) query.set('faces', String(faces));
  if (name) query.set('name', name);
  const headers = { 'Content-Type': 'application/octet-stream' };
  if (apiKey) headers.Authorization = `Bearer ${apiKey}`;
  const res = await fetch(apiUrl(`approximations?${query}`), { method: 'POST', headers, body: file });
  const body = await readJson(res);
  if (!res.ok) throw new ApiError(res.status, body);
  return body;
}

/**
 * POST /api/imports?format=fold|svg&name=… with a crease pattern (FOLD or SVG text) as the body →
 * {scene, summary: {format, curved_creases, faces, edges: {mountain, valley, flat, boundary, cut},
 * folded_state, notes}} (issue 16).
 */
export async function importCreasePattern(text, { format = 'fold', name, units } = {}, apiKey) {
  const query = new URLSearchParams({ format });
  if (name) query.set('name', name.slice(0, 200));
  if (units) query.set('units', units);
  const headers = { 'Content-Type': format === 'svg' ? 'image/svg+xml' : 'application/json' };
  if (apiKey) headers.Authorization = `Bearer ${apiKey}`;
  const res = await fetch(apiUrl(`imports?${query}`), { method: 'POST', headers, body: text });
  const body = await readJson(res);
  if (!res.ok) throw new ApiError(res.status, body);
  return body;
}

/** POST a shape file to `route` with query parameters → the JSON answer (throws ApiError). */
async function postShape(route, file, query, apiKey) {
  const headers = { 'Content-Type': 'application/octet-stream' };
  if (apiKey) headers.Authorization = `Bearer ${apiKey}`;
  const res = await fetch(apiUrl(`${route}?${query}`), { method: 'POST', headers, body: file });
  const body = await readJson(res);
  if (!res.ok) throw new ApiError(res.status, body);
  return body;
}

/**
 * POST /api/references?format=…&points=… with a point cloud or mesh as the body → {points,
 * triangles, shown, positions (flat x,y,z), bounding_box, diagonal}: what to draw to pick a region.
 */
export function previewShape(file, { format, points = 20000 }, apiKey) {
  return postShape('references', file, new URLSearchParams({ format, points: String(points) }), apiKey);
}

/**
 * POST /api/fits (one strip) or /api/covers (strips side by side, a composite) for the region of a
 * shape within `radius` of `centre` ([x, y, z]), or for the whole file when `centre` is null;
 * `regions` > 1 cuts it into that many regions, each covered by `strips` strips (Fig. 10e);
 * `overhang` > 0 pulls back what spreads beyond the region
 * → {scene, summary} (issue 15).
 */
export function fitRegion(file, { format, centre, radius, cover, strips, regions = 1, overhang = 0, name }, apiKey) {
  // Without a centre the region is the whole file (a painted or lassoed region sent as its points).
  const query = new URLSearchParams(centre ? { format, centre: centre.join(','), radius: String(radius) } : { format });
  if (cover) query.set('strips', String(strips));
  if (cover && regions > 1) query.set('regions', String(regions));
  if (overhang > 0) query.set('overhang', String(overhang));
  if (name) query.set('name', name);
  return postShape(cover ? 'covers' : 'fits', file, query, apiKey);
}

/** GET /api/sessions/{id}/thumbnail (a PNG of the current surface) with the token as Bearer → Blob */
export async function sessionThumbnail(id, token) {
  const res = await fetch(apiUrl(`sessions/${encodeURIComponent(id)}/thumbnail`), {
    headers: { Authorization: `Bearer ${token}` },
  });
  if (!res.ok) throw new ApiError(res.status, await readJson(res));
  return res.blob();
}

/** GET /api/sessions/{id}/export?format=json|obj|fold|svg with the token as Bearer → Blob */
export async function exportSession(id, token, format) {
  const res = await fetch(apiUrl(`sessions/${encodeURIComponent(id)}/export?format=${format}`), {
    headers: { Authorization: `Bearer ${token}` },
  });
  if (!res.ok) throw new ApiError(res.status, await readJson(res));
  return res.blob();
}
