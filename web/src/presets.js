// The example scenes of ../examples, bundled into the build (Vite JSON import).

const modules = import.meta.glob('../../examples/*.json', { eager: true, import: 'default' });

// Sessions of the start page's presets: every example of every kind (strips, composites with
// curved creases, the strips between two given curves, quad meshes); the demo cards take their
// descriptions from here too.
export const PRESETS = Object.entries(modules)
  .filter(([, scene]) => scene.model && typeof scene.model.kind === 'string')
  .map(([path, scene]) => {
    const file = path.split('/').pop();
    const description = scene.description || '';
    return {
      file, id: file.replace(/\.json$/, ''), name: scene.name || file.replace(/\.json$/, ''), description,
      summary: sceneSummary(scene), scene,
    };
  })
  .sort((a, b) => a.file.localeCompare(b.file));

/**
 * The line a card shows: the scene's `summary`, else the first sentence of its description (a
 * full stop followed by a space and a capital, or the end), else nothing.
 */
export function sceneSummary(scene) {
  if (scene && typeof scene.summary === 'string' && scene.summary.trim()) return scene.summary.trim();
  const text = scene && typeof scene.description === 'string' ? scene.description.trim() : '';
  const end = text.search(/[.!?](\s+[A-Z]|$)/);
  return end >= 0 ? text.slice(0, end + 1) : text;
}
