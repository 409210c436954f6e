// The printer dialog (docs/MODELER.md, docs/PRINTING.md,
// docs/CALIBRATION.md): a printer of one's own (build volume, origin, E per
// mm³, nozzle, start and end code, its print host), kept in this browser;
// the calibration print and its fit; the printer a design names.

import { download, postDesign } from './io.js';
import { fmtE, fmtMm, parseDecimal } from './numbers.js';
import { setVerdict, showError } from './status.js';
import { clone, edit, setDesign, state } from './store.js';

const $ = (id) => document.getElementById(id);
export const PRINTERS = 'sweepclay.printers.v1';

/** Printers the user made, kept in this browser: [{ printer, nozzle_height }]. */
export function keptPrinters() {
  try {
    const v = JSON.parse(localStorage.getItem(PRINTERS));
    return Array.isArray(v) ? v.filter((p) => p && p.printer && p.printer.name) : [];
  } catch (e) {
    return [];
  }
}

const PRINTER_FIELDS = [['pr-bv', 'build_volume', 3], ['pr-bm', 'bed_min', 3], ['pr-o', 'origin', 2]];

/** The design's printer: its own, or the preset it names. */
export function currentPrinter(d) {
  return typeof d.printer === 'object' && d.printer ? d.printer : state.meta.presets.find((p) => p.name === (d.printer || 'generic'));
}

export function openPrinter() {
  const d = state.design;
  const current = currentPrinter(d);
  const base = { ...state.meta.presets.find((p) => p.name === 'generic'), ...current };
  state.printerBase = base;
  $('pr-name').value = typeof d.printer === 'object' ? base.name : `my ${base.name}`;
  for (const [id, key, n] of PRINTER_FIELDS) {
    for (let k = 0; k < n; k++) $(`${id}${k}`).value = (base[key] || [0, 0, 0])[k];
  }
  $('pr-dia').value = base.bed_diameter || '';
  $('pr-e').value = fmtE(base.e_per_mm3);
  $('pr-r').value = base.nozzle_radius;
  $('pr-h').value = { ...state.meta.params, ...(d.params || {}) }.nozzle_height;
  $('pr-rel').checked = !!base.relative_e;
  $('pr-start').value = base.start_gcode || '';
  $('pr-end').value = base.end_gcode || '';
  $('pr-nozzle').value = base.nozzle_diameter ?? '';
  nozzleNote();
  $('pr-host-kind').value = base.host ? base.host.kind : '';
  $('pr-host-url').value = base.host ? base.host.url : '';
  $('pr-host-cert').value = (base.host && base.host.cert_sha256) || '';
  $('pr-host-key').value = '';
  $('pr-error').textContent = '';
  $('printer-dialog').returnValue = '';
  $('printer-dialog').showModal();
}

/**
 * What a nozzle's bore means for the beads, under the dialog's field:
 * from the bore (a bead laid without pressing) to twice it (pressed to half
 * its height), as "Use" sets them (docs/FORMATS.md).
 */
function nozzleNote() {
  const d = parseDecimal($('pr-nozzle').value);
  $('pr-nozzle-note').textContent = d > 0
    ? `Beads from ${fmtMm(d)} to ${fmtMm(2 * d)} mm wide: the bore laid without pressing, and pressed to half its height. "Use" sets the bead widths to these.`
    : 'With the bore, the bead widths follow from it.';
}
$('pr-nozzle').addEventListener('input', nozzleNote);

/** The printer as the dialog's fields say now, for the calibration. */
function dialogPrinter() {
  const printer = { ...state.printerBase };
  for (const [id, key, n] of PRINTER_FIELDS) printer[key] = Array.from({ length: n }, (_, k) => parseFloat($(`${id}${k}`).value));
  const dia = $('pr-dia').value.trim();
  if (dia) printer.bed_diameter = parseFloat(dia);
  else delete printer.bed_diameter;
  printer.e_per_mm3 = parseFloat($('pr-e').value);
  printer.relative_e = $('pr-rel').checked;
  printer.start_gcode = $('pr-start').value;
  printer.end_gcode = $('pr-end').value;
  delete printer.host;
  return printer;
}

/**
 * Where the E per mm³ a calibration print was written with is kept, per
 * printer name: it travels with the print, so Compute is idempotent
 * (docs/CALIBRATION.md).
 */
const CAL_WRITTEN = 'sweepclay.calibration-written';
function writtenE(name) {
  try {
    return JSON.parse(localStorage.getItem(CAL_WRITTEN) || '{}')[name];
  } catch (e) {
    return undefined;
  }
}
function keepWrittenE(name, e) {
  try {
    const all = JSON.parse(localStorage.getItem(CAL_WRITTEN) || '{}');
    all[name] = e;
    localStorage.setItem(CAL_WRITTEN, JSON.stringify(all));
  } catch (err) {
    /* the dialog still says it */
  }
}

/** What the calibration routes take: the dialog's printer, the design's widths. */
function calibrationAsk(measured, written) {
  const p = { ...state.meta.params, ...(state.design.params || {}) };
  const params = { layer_height: p.layer_height, width_min: p.width_min, width_max: p.width_max };
  return JSON.stringify({
    printer: dialogPrinter(),
    params,
    ...(measured ? { measured } : {}),
    ...(written ? { written_e_per_mm3: written } : {}),
  });
}

$('pr-cal-print').addEventListener('click', async () => {
  const r = await postDesign('/api/calibrate', calibrationAsk());
  if (!r.ok) {
    $('pr-cal-result').textContent = (await r.json()).error;
    return;
  }
  download(await r.blob(), 'calibration.gcode');
  const e = parseFloat($('pr-e').value);
  keepWrittenE($('pr-name').value.trim(), e);
  $('pr-cal-result').textContent = `Written with E per mm³ ${fmtE(e)}; Compute uses that, whatever the field says later.`;
});

$('pr-cal-fit').addEventListener('click', async () => {
  const measured = [1, 2, 3, 4].map((k) => parseDecimal($(`pr-cal-${k}`).value));
  if (!measured.every((v) => v > 0)) {
    $('pr-cal-result').textContent = 'give the wall thickness of each of the four bands, in mm';
    return;
  }
  const written = writtenE($('pr-name').value.trim());
  const r = await postDesign('/api/calibrate/fit', calibrationAsk(measured, written));
  const f = await r.json();
  if (!r.ok) {
    $('pr-cal-result').textContent = f.error;
    return;
  }
  const spread = (f.spread * 100).toFixed(1);
  if (!f.trusted) {
    $('pr-cal-result').textContent = `The bands disagree by ${spread} %: measure again at each band's middle (nothing changed).`;
    return;
  }
  $('pr-e').value = fmtE(f.e_per_mm3);
  const from = written ? `the print was written with ${written}` : `no print downloaded here: taken as written with ${fmtE(f.written_e_per_mm3)}`;
  $('pr-cal-result').textContent = `E per mm³ ${fmtE(f.e_per_mm3)} (${from}; the bands agree within ${spread} %). "Use and keep" keeps it.`;
});

$('printer-form').addEventListener('submit', (e) => {
  if (e.submitter && e.submitter.value !== 'save') return;
  // Everything the dialog does not show (feedrates, relative E, a round
  // bed) stays as the printer it started from had it.
  const printer = { ...state.printerBase, name: $('pr-name').value.trim() };
  for (const [id, key, n] of PRINTER_FIELDS) printer[key] = Array.from({ length: n }, (_, k) => parseFloat($(`${id}${k}`).value));
  // A round bed (a delta, a WASP): its diameter; empty for a rectangle.
  const dia = $('pr-dia').value.trim();
  if (dia) printer.bed_diameter = parseFloat(dia);
  else delete printer.bed_diameter;
  printer.e_per_mm3 = parseFloat($('pr-e').value);
  printer.nozzle_radius = parseFloat($('pr-r').value);
  printer.relative_e = $('pr-rel').checked;
  printer.start_gcode = $('pr-start').value;
  const said = extrusionMode(printer.start_gcode);
  printer.end_gcode = $('pr-end').value;
  const h = parseFloat($('pr-h').value);
  const nozzleText = $('pr-nozzle').value.trim();
  const nozzle = nozzleText ? parseDecimal(nozzleText) : null;
  if (nozzle != null) printer.nozzle_diameter = nozzle;
  else delete printer.nozzle_diameter;
  const hostKind = $('pr-host-kind').value;
  const hostUrl = $('pr-host-url').value.trim().replace(/\/+$/, '');
  // A fingerprint as people copy it: colons, spaces, any case.
  const certText = $('pr-host-cert').value.trim().replace(/^sha256( fingerprint)?[=:]\s*/i, '');
  const certHex = certText.replace(/[:\s]/g, '');
  if (hostKind) {
    printer.host = { kind: hostKind, url: hostUrl };
    if (/^[0-9a-fA-F]{64}$/.test(certHex)) printer.host.cert_sha256 = certHex.toUpperCase().match(/../g).join(':');
  } else delete printer.host;
  const bad = [
    [!printer.name, 'give the printer a name'],
    [!printer.build_volume.every((v) => v > 0), 'the build volume must be positive on every axis'],
    [![...printer.bed_min, ...printer.origin].every(Number.isFinite), 'the box\'s lowest corner and where the pot\'s centre lands must be numbers'],
    [dia && !(printer.bed_diameter > 0), 'the bed diameter must be a positive number of mm, or empty for a rectangular bed'],
    [!(printer.e_per_mm3 > 0), 'E per mm³ must be positive'],
    [!(printer.nozzle_radius >= 0), 'the nozzle body radius must be a number of mm'],
    [!(h > 0), 'the nozzle body height must be positive'],
    [nozzle != null && !(nozzle > 0 && nozzle <= 100), `nozzle diameter "${nozzleText}": a bore from above 0 to 100 mm, or empty if not known`],
    [hostKind && !/^https?:\/\/[^\s/@?#]+(\/[^\s@?#]*)?$/.test(hostUrl), 'the print host address is http:// or https:// and its name or IP address, e.g. http://octopi.local (no user name or password in it)'],
    [hostKind && certHex && !/^[0-9a-fA-F]{64}$/.test(certHex), `certificate "${certText.slice(0, 20)}…": a SHA-256 fingerprint is 64 hex digits, e.g. AB:CD:…, as the refusal on sending names it`],
    [hostKind && certHex && !hostUrl.startsWith('https://'), 'a certificate goes with an https:// address only'],
    [said != null && said !== printer.relative_e, said ? 'the start code sets relative extrusion (M83) but "relative extrusion" is off: the G-code\'s own M82 would cancel it; tick it or take M83 out' : 'the start code sets absolute extrusion (M82) but "relative extrusion" is on: untick it or take M82 out'],
  ].find(([b]) => b);
  if (bad) {
    e.preventDefault();
    $('pr-error').textContent = bad[1];
    return;
  }
  // The host (and its key, if typed) goes to this computer's keys file,
  // never into the design: the server talks only to hosts saved there.
  const key = $('pr-host-key').value.trim();
  if (hostKind) saveHostKey(hostUrl, key);
  const kept = keptPrinters().filter((p) => p.printer.name !== printer.name);
  kept.push({ printer, nozzle_height: h });
  try {
    localStorage.setItem(PRINTERS, JSON.stringify(kept));
  } catch (err) {
    /* the design still carries it */
  }
  fillPrinterOptions();
  edit((d) => {
    d.printer = printer;
    d.params = { ...(d.params || {}), nozzle_height: h };
    // The bead widths follow the bore (docs/FORMATS.md).
    if (nozzle != null) Object.assign(d.params, { width_min: nozzle, width_max: 2 * nozzle });
  }, true);
});

/**
 * An example for the printer chosen now: the example's shape, the user's
 * printer (and, for a printer of their own, its extruder body height).
 */
export function withMyPrinter(d) {
  const mine = state.design?.printer;
  if (!mine) return d;
  d.printer = clone(mine);
  const h = state.design.params?.nozzle_height;
  if (typeof mine === 'object' && h != null) d.params = { ...(d.params || {}), nozzle_height: h };
  return d;
}

/**
 * The extrusion mode a start code leaves (true: M83, false: M82, null:
 * neither), as the pipeline reads it (docs/FORMATS.md).
 */
function extrusionMode(text) {
  let mode = null;
  for (const line of String(text).split('\n')) {
    const code = line.split(';')[0].trim().toUpperCase().split(/\s+/)[0];
    if (code === 'M83') mode = true;
    else if (code === 'M82') mode = false;
  }
  return mode;
}

export function fillPrinterOptions() {
  const sel = $('p-printer');
  sel.innerHTML = '';
  const add = (value, text) => {
    const o = document.createElement('option');
    o.value = value;
    o.textContent = text;
    sel.appendChild(o);
  };
  for (const p of state.meta.presets) add(p.name, `${p.name} (${p.build_volume.join('×')})`);
  for (const k of keptPrinters()) add(`kept:${k.printer.name}`, `${k.printer.name} (yours, ${k.printer.build_volume.join('×')})`);
  add('', 'custom (in the design)');
}

/** Saves a print host's key on the server's machine (docs/PRINTING.md). */
async function saveHostKey(url, key) {
  try {
    // An empty key keeps the one saved (the page never reads it back).
    const r = await postDesign('/api/host/key', JSON.stringify(key ? { url, key } : { url }));
    if (!r.ok) showError(`the key was not saved: ${(await r.json()).error}`);
  } catch (e) {
    showError(`the server did not answer: ${e.message || e}`);
  }
}
