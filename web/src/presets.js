// The example scenes of ../examples, bundled into the build (Vite JSON import).

const modules = import.meta.glob('../../examples/*.json', { eager: true, import: 'default' });

// Sessions of the start page's presets: every example of every kind (strips, composites with
// curved creases, the strips between two given curves, quad meshes); the demo cards take their
// descriptions from here too.
export const PRESETS = Object.entries(modules)
  .filter(([, scene]) => scene.model && typeof scene.model.kind === 'string')
  .map(([path, scene]) => {
    const file = path.split('/').pop();
    return { file, id: file.replace(/\.json$/, ''), name: scene.name || file.replace(/\.json$/, ''), description: scene.description || '', scene };
  })
  .sort((a, b) => a.file.localeCompare(b.file));
