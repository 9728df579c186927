// The example scenes of ../examples, bundled into the build (Vite JSON import).

const modules = import.meta.glob('../../examples/*.json', { eager: true, import: 'default' });

// Sessions of the start page's presets: strips, the strips between two given curves (quasi_strip,
// conical_strip) and quad meshes (quad_mesh, Jiang et al. 2020); the composite examples are demo
// sessions, `devsurf solve` inputs and jobs.
export const PRESETS = Object.entries(modules)
  .filter(([, scene]) => scene.model && ['strip', 'quasi_strip', 'conical_strip', 'quad_mesh'].includes(scene.model.kind))
  .map(([path, scene]) => {
    const file = path.split('/').pop();
    return { file, id: file.replace(/\.json$/, ''), name: scene.name || file.replace(/\.json$/, ''), description: scene.description || '', scene };
  })
  .sort((a, b) => a.file.localeCompare(b.file));
