// The example scenes of ../examples, bundled into the build (Vite JSON import).

const modules = import.meta.glob('../../examples/*.json', { eager: true, import: 'default' });

// Sessions edit strips; the other examples (composite surfaces) are for `devsurf solve` and jobs.
export const PRESETS = Object.entries(modules)
  .filter(([, scene]) => scene.model && scene.model.kind === 'strip')
  .map(([path, scene]) => {
    const file = path.split('/').pop();
    return { file, id: file.replace(/\.json$/, ''), name: scene.name || file.replace(/\.json$/, ''), description: scene.description || '', scene };
  })
  .sort((a, b) => a.file.localeCompare(b.file));
