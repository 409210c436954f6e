// Makes the G-code of coilCAM's example vessels (sambourgault/coilCAM-js at
// commit 7d98d22, its `examples/`) with the coilCAM library they are
// written for (npm `coilcam` 1.0.69), the way its web editor runs them:
// the library's functions in global scope, the example evaluated, its
// `gcode` written out. Nothing of theirs is kept in this repository.
//
//   mkdir cc && cd cc && npm install coilcam@1.0.69 @flatten-js/core
//   mkdir -p node_modules/coilcam/node_modules/@flatten-js
//   ln -s "$PWD/node_modules/@flatten-js/core" node_modules/coilcam/node_modules/@flatten-js/core
//   git clone https://github.com/sambourgault/coilCAM-js && git -C coilCAM-js checkout 7d98d22
//   node path/to/scripts/corpus/coilcam.mjs coilCAM-js/examples out
//
// Examples that make no G-code (the function demos, most tutorials) or
// call functions the library no longer has are listed and skipped.
import fs from 'fs';
import path from 'path';

globalThis.window = globalThis;
const lib = await import(path.resolve('node_modules/coilcam/src/index.js'));
for (const group of Object.values(lib)) Object.assign(globalThis, group);
// The editor's viewers: nothing to show here.
globalThis.updatePath = () => {};
globalThis.downloadGCode = () => {};
globalThis.showCurve = () => {};

const [examples, out] = process.argv.slice(2);
fs.mkdirSync(out, { recursive: true });
for (const dir of fs.readdirSync(examples)) {
  const full = path.join(examples, dir);
  if (!fs.statSync(full).isDirectory()) continue;
  for (const file of fs.readdirSync(full).filter((f) => f.endsWith('.js'))) {
    const code = fs.readFileSync(path.join(full, file), 'utf8');
    try {
      const g = new Function(`${code}\n;return typeof gcode !== "undefined" ? gcode : null;`)();
      if (!g) {
        console.log(`${file}: no G-code`);
        continue;
      }
      fs.writeFileSync(path.join(out, file.replace(/\.js$/, '.gcode')), g);
      console.log(`${file}: ${g.split('\n').length} lines`);
    } catch (e) {
      console.log(`${file}: ${String(e).split('\n')[0]}`);
    }
  }
}
