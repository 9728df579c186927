// Which exports apply to a scene: the export menu shows exactly these (checked against the
// server for every shipped preset by tests/server/e2e/test_fabrication.py).

/** Every export format the server knows, in menu order. */
export const EXPORT_FORMATS = ['json', 'obj', 'stl', 'fold', 'svg', 'dxf', 'unfolding_obj', 'iges', 'step'];

/**
 * Whether a composite model is pieces cut apart along seams: no development, and some S edge
 * shared by two faces without a crease condition (the server then exports its flat pieces).
 */
export function cutAlongSeams(model) {
  if (!model || model.development || !Array.isArray(model.edges) || !Array.isArray(model.faces)) return false;
  const uses = new Map();
  for (const face of model.faces) for (const e of face) uses.set(e, (uses.get(e) || 0) + 1);
  return model.edges.some((edge, e) => edge && edge.type === 'S' && (edge.crease || 'none') === 'none' && uses.get(e) === 2);
}

/**
 * The formats that apply to a scene of `kind` with `model` (the scene's "model" object):
 * json, obj and stl always; svg and dxf where there is a flat pattern — a composite's crease
 * pattern (with a development) or its pieces (cut along seams), a quad mesh's planar unfolding,
 * any strip kind unrolled; fold for composites with a development or cut along seams and for quad meshes;
 * unfolding_obj for quad meshes; iges and step for strip kinds, composites and spline surfaces
 * (quad meshes with a control net).
 */
export function exportFormats(kind, model) {
  const composite = kind === 'composite';
  const quad = kind === 'quad_mesh';
  const development = composite && !!(model && model.development);
  const pieces = composite && cutAlongSeams(model);
  const flat = composite ? development || pieces : quad ? !(model && model.unfolding && model.unfolding.planar === false) : true;
  const spline = quad && !!(model && model.control);
  const formats = new Set(['json', 'obj', 'stl']);
  if (flat) { formats.add('svg'); formats.add('dxf'); }
  if (development || quad || pieces) formats.add('fold');
  if (quad) formats.add('unfolding_obj');
  if (!quad || spline) { formats.add('iges'); formats.add('step'); }
  return EXPORT_FORMATS.filter((f) => formats.has(f));
}
