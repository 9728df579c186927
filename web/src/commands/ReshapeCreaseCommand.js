import { Command } from './Command.js';
import { checkCrease, checkCurved, sheetPoints } from './DrawCreaseCommand.js';

/**
 * Replaces the points of drawn stroke `crease` (a point added, moved or deleted); `curved`
 * (optional) switches between a straight crease (2 points) and a spline through ≥ 3.
 */
export class ReshapeCreaseCommand extends Command {
  constructor(crease, points, curved, options) {
    super('reshape_crease', options);
    this.crease = checkCrease(crease);
    this.points = sheetPoints(points);
    this.curved = curved === undefined ? undefined : checkCurved(curved, this.points.length);
    this.name = `reshape crease ${crease}`;
  }

  fields() {
    return { crease: this.crease, points: this.points, curved: this.curved };
  }
}
