export { Command, sameTarget, targetKey, targetLabel, targetOf } from './Command.js';
export { DragCommand } from './DragCommand.js';
export { DragEndCommand } from './DragEndCommand.js';
export { SolveCommand } from './SolveCommand.js';
export { AddHandleCommand } from './AddHandleCommand.js';
export { RemoveHandleCommand } from './RemoveHandleCommand.js';
export { SetFixedCommand } from './SetFixedCommand.js';
export { SetSolverCommand, SOLVER_KEYS } from './SetSolverCommand.js';
export { UndoCommand } from './UndoCommand.js';
export { RedoCommand } from './RedoCommand.js';
export { ResetCommand } from './ResetCommand.js';
export { PresenceCommand } from './PresenceCommand.js';
export { JoinCommand, PingCommand } from './JoinCommand.js';
export { SetCreaseCommand, CREASE_KINDS } from './SetCreaseCommand.js';
export { SetParamsCommand, PARAM_KEYS } from './SetParamsCommand.js';
export { FoldCommand, FoldEndCommand } from './FoldCommand.js';
export { SetUnitsCommand, UNITS } from './SetUnitsCommand.js';
export {
  DrawCreaseCommand, DRAW_ASSIGNMENTS, ASSIGNMENT_NAMES, STROKE_POINTS_MIN, STROKE_POINTS_MAX,
} from './DrawCreaseCommand.js';
export { EraseCreaseCommand } from './EraseCreaseCommand.js';
export { RelabelCreaseCommand } from './RelabelCreaseCommand.js';
export { ReshapeCreaseCommand } from './ReshapeCreaseCommand.js';
export { RotatePointsCommand, ROTATE_ANGLE_MAX, ROTATE_ITERATIONS_MAX, ROTATE_TARGETS_MAX } from './RotatePointsCommand.js';
export { AddControlPointCommand, RemoveControlPointCommand } from './ControlPointCommands.js';
export { MergeFacesCommand, RelabelEdgeCommand, RemoveVertexCommand, SplitAlongRulingCommand, SplitEdgeCommand, SplitFaceCommand } from './LabelledMeshCommands.js';
