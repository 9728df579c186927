import { Command } from './Command.js';

/** The units of one coordinate of the design (set_units; the numbers stay, exports follow). */
export const UNITS = ['mm', 'cm', 'm', 'in'];

export class SetUnitsCommand extends Command {
  constructor(units, options) {
    super('set_units', options);
    if (!UNITS.includes(units)) throw new TypeError(`units: expected one of ${UNITS.join(', ')}, got ${units}`);
    this.units = units;
    this.name = `units ${units}`;
  }

  fields() {
    return { units: this.units };
  }
}
