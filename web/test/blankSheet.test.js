import { describe, expect, it } from 'vitest';
import { BLANK_DEFAULT, blankSheetImport, blankSheetName, blankSheetSvg, checkBlankSheet } from '../src/ui/blankSheet.js';

describe('a blank sheet', () => {
  it('is the SVG of a rectangle outline, its numbers as typed', () => {
    const svg = blankSheetSvg(200, 150, 'mm');
    expect(svg).toBe('<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="150mm" viewBox="0 0 200 150">\n'
      + '  <rect x="0" y="0" width="200" height="150" fill="none" stroke="#000" stroke-width="0.5"/>\n</svg>\n');
    expect(BLANK_DEFAULT).toEqual({ width: 200, height: 150, units: 'mm' });
  });

  it('says its size in the unit chosen, the typed numbers in its viewBox; the import is told the unit', () => {
    // The import converts a drawing that states its units to the units asked for: a "20cm" wide
    // drawing imported in cm is 20 wide (it was read as 200 mm and kept as 200 "cm" before).
    const cm = blankSheetSvg(20, 15, 'cm');
    expect(cm).toContain('width="20cm" height="15cm" viewBox="0 0 20 15"');
    expect(cm).toContain('<rect x="0" y="0" width="20" height="15" fill="none" stroke="#000" stroke-width="0.05"/>');
    expect(blankSheetSvg(8.5, 11, 'in')).toContain('width="8.5in" height="11in" viewBox="0 0 8.5 11"');
    expect(blankSheetSvg(1.2, 0.8, 'm')).toContain('width="1200mm" height="800mm" viewBox="0 0 1.2 0.8"');
    expect(blankSheetSvg(0.1 + 0.2, 1, 'mm')).toContain('width="0.3mm"');
    expect(blankSheetImport(300, 100, 'cm')).toEqual({ svg: blankSheetSvg(300, 100, 'cm'), name: 'Blank sheet 300 × 100 cm', units: 'cm' });
    expect(blankSheetImport(200, 150, 'mm').units).toBe('mm');
    expect(() => blankSheetImport(0, 1, 'cm')).toThrow(/width/);
  });

  it('refuses sizes that are not positive numbers, or too large, naming the field', () => {
    expect(() => blankSheetSvg(0, 150)).toThrow(/width/);
    expect(() => blankSheetSvg(200, -1)).toThrow(/height/);
    expect(() => blankSheetSvg(NaN, 150)).toThrow(/width/);
    expect(() => blankSheetSvg(200, 150, 'ft')).toThrow(/units/);
    expect(() => checkBlankSheet(200, 1e6, 'mm')).toThrow(/height: at most 100000 mm/);
    expect(() => checkBlankSheet(200, 150, 'm')).toThrow(/width: at most 100 m/);
  });

  it('is named by its size', () => {
    expect(blankSheetName(200, 150, 'mm')).toBe('Blank sheet 200 × 150 mm');
  });
});
