import { Command } from './Command.js';

// The members of the scene's solver object (scene.schema.json#/$defs/solver).
export const SOLVER_KEYS = [
  'iterations', 'fairness', 'fairness_decay', 'regularization', 'unit_normal_weight',
  'developability_weight', 'handle_weight', 'time_budget_ms', 'residual_tolerance',
  'relative_change_tolerance', 'linear_solver', 'normalize', 'softening', 'step_control', 'hard_band',
  'hard_tolerance', 'normal_splines', 'crease_normals', 'development_solve',
];

/**
 * Change any subset of the solver settings, and/or the session's drag settings
 * ({drag_iterations, release_iterations}), and/or the normal representation
 * (session.normals = {type: 'vectors'} | {type: 'spline', degree, points}).
 */
export class SetSolverCommand extends Command {
  constructor(solver = {}, session = {}, options) {
    super('set_solver', options);
    this.solver = {};
    for (const [k, v] of Object.entries(solver)) {
      if (!SOLVER_KEYS.includes(k)) throw new TypeError(`unknown solver setting ${k}`);
      if (v !== undefined) this.solver[k] = v;
    }
    if (session.drag_iterations !== undefined) this.drag_iterations = session.drag_iterations;
    if (session.release_iterations !== undefined) this.release_iterations = session.release_iterations;
    if (session.normals !== undefined) {
      const n = session.normals;
      if (n.type !== 'vectors' && n.type !== 'spline') throw new TypeError(`unknown normal representation ${n.type}`);
      this.normals = n.type === 'vectors' ? { type: 'vectors' } : { type: 'spline', ...(n.degree !== undefined ? { degree: n.degree } : {}), ...(n.points !== undefined ? { points: n.points } : {}) };
    }
    const keys = [...Object.keys(this.solver), ...['drag_iterations', 'release_iterations', 'normals'].filter((k) => this[k] !== undefined)];
    this.name = `set ${keys.join(', ') || 'solver'}`;
  }

  fields() {
    return { solver: { ...this.solver }, drag_iterations: this.drag_iterations, release_iterations: this.release_iterations, normals: this.normals };
  }
}
