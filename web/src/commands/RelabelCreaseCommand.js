import { Command } from './Command.js';
import { ASSIGNMENT_NAMES, checkAssignment, checkCrease, checkFoldAngle } from './DrawCreaseCommand.js';

/** Changes drawn stroke `crease` to mountain, valley, flat or cut; `foldAngle`: magnitude in degrees (M, V). */
export class RelabelCreaseCommand extends Command {
  constructor(crease, assignment, foldAngle, options) {
    super('relabel_crease', options);
    this.crease = checkCrease(crease);
    this.assignment = checkAssignment(assignment);
    this.foldAngle = assignment === 'M' || assignment === 'V' ? checkFoldAngle(foldAngle) : undefined;
    this.name = `crease ${crease} → ${ASSIGNMENT_NAMES[this.assignment]}${this.foldAngle !== undefined ? ` ${this.foldAngle}°` : ''}`;
  }

  fields() {
    return { crease: this.crease, assignment: this.assignment, fold_angle: this.foldAngle };
  }
}
