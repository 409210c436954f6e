// The design's parameters as the page names them (docs/FORMATS.md): what
// the Parameters panel shows and what an error about one says.

// Each parameter: its key, its label, its unit, its input step, what it
// does (the tooltip, with the default), and the factor between the file's
// value and the one shown (overlap is a fraction in the file, % here).
export const PARAMS = [
  ['layer_height', 'layer height', 'mm', 0.05, 'the thinnest layer of clay (the paper\'s Δz₀)', 1],
  ['max_layer_height', 'max layer height', 'mm', 0.05, 'the thickest layer allowed where the two profiles differ in height', 1],
  ['spacing', 'point spacing', 'mm', 0.05, 'distance between points along the path seen from above', 1],
  ['nozzle_height', 'extruder body height', 'mm', 1, 'how high the extruder body reaches above the nozzle tip (the paper\'s H): no clay may rise above it', 1],
  ['width_min', 'bead width min', 'mm', 0.1, 'the narrowest bead of clay', 1],
  ['width_max', 'bead width max', 'mm', 0.1, 'the widest bead of clay', 1],
  ['overlap', 'overlap with the bead below', '%', 1, 'how much of each bead rests on the bead below it', 100],
  ['max_overhang_deg', 'steepest overhang', '°', 1, 'how far from vertical the wall may lean before it is corrected', 1],
  ['feedrate', 'print speed', 'mm/min', 50, 'how fast the nozzle moves while printing', 1],
  ['floor_layers', 'floor layers (vessel)', '', 1, 'flat layers of the floor of a closed vessel; 0 for bottomless', 1],
  ['shrinkage_xy', 'firing shrinkage across', '%', 0.5, 'how much your clay body shrinks across from wet to fired (0 to 50 %): the piece is printed that much larger, so the fired piece has the drawn size', 100],
  ['shrinkage_z', 'firing shrinkage in height', '%', 0.5, 'how much your clay body shrinks in height from wet to fired (0 to 50 %)', 100],
];

/** The label, unit and factor of parameter `key`, if it is one. */
export function param(key) {
  const p = PARAMS.find((q) => q[0] === key);
  return p && { label: p[1], unit: p[2], factor: p[5] };
}
