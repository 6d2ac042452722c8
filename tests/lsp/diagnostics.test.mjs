// Diagnostics as the designer types, before any save: the errors `shoal check` reports, located
// at the same line and column (0-based here), with what was expected and a did-you-mean; fixing
// the text clears them. Includes the errors that span files (a script function the species names,
// a behavior name a script compares with).

import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import test from 'node:test';
import { lineOf, uriOf, withServer } from './client.mjs';

const ERROR = 1;
const errorsAt = (line) => (ds) => ds.some((d) => d.range.start.line === line && (d.severity ?? ERROR) === ERROR);
const clean = (ds) => ds.length === 0;

/** Asserts `d` starts at the string literal `literal` of `lineText`: its quote or its first letter. */
function expectStringAt(d, lineText, literal) {
  const quote = lineText.indexOf(literal);
  assert.ok(
    d.range.start.character === quote || d.range.start.character === quote + 1,
    `the diagnostic starts at ${literal} (column ${quote}): ${JSON.stringify(d)}`,
  );
}

test('a misspelt condition in a species file: located before save, cleared when fixed', async () => {
  await withServer(async (s) => {
    const file = path.join(s.root, 'behaviors/reef_fish.ron');
    const onDisk = fs.readFileSync(file, 'utf8');
    const doc = await s.open('behaviors/reef_fish.ron');
    // On open: the shipped species is clean.
    await s.diagnostics(doc.uri, clean, 0, 'the shipped reef_fish.ron (none)');

    const typo = doc.text.replace('when: TrafficNear,', 'when: TraficNear,');
    const line = lineOf(typo, 'when: TraficNear,');
    const from = s.published.length;
    await s.change(doc, typo);
    const got = await s.diagnostics(doc.uri, errorsAt(line), from, `an error on line ${line}`);
    const d = got.diagnostics.find((x) => x.range.start.line === line);
    // `shoal check`: reef_fish.ron:72:19: unknown condition `TraficNear` (did you mean …)
    assert.equal(d.range.start.character, typo.split('\n')[line].indexOf('TraficNear'), JSON.stringify(d));
    assert.match(d.message, /TraficNear/);
    assert.match(d.message, /did you mean `TrafficNear`/);
    assert.match(d.message, /expected one of .*`TrafficNear`/);
    assert.equal(got.diagnostics.length, 1, `only the typo: ${JSON.stringify(got.diagnostics)}`);
    // Nothing was saved: the server read the editor's text.
    assert.equal(fs.readFileSync(file, 'utf8'), onDisk);

    const fixed = s.published.length;
    await s.change(doc, onDisk);
    await s.diagnostics(doc.uri, clean, fixed, 'the fixed file (none)');
  });
});

test('a script function the species names but its script lacks', async () => {
  await withServer(async (s) => {
    const doc = await s.open('behaviors/reef_fish.ron');
    const typo = doc.text.replace('Script("crowded")', 'Script("crowde")');
    const line = lineOf(typo, 'Script("crowde")');
    const from = s.published.length;
    await s.change(doc, typo);
    const got = await s.diagnostics(doc.uri, errorsAt(line), from, `an error on line ${line}`);
    const d = got.diagnostics.find((x) => x.range.start.line === line);
    // `shoal check` points at the string (reef_fish.ron:139:26); the name inside it will do too.
    expectStringAt(d, typo.split('\n')[line], '"crowde"');
    assert.match(d.message, /crowde\b/);
    assert.match(d.message, /did you mean `crowded`/);
  });
});

test('a function renamed in an unsaved script is reported where the species names it', async () => {
  await withServer(async (s) => {
    const ron = await s.open('behaviors/reef_fish.ron');
    const rhai = await s.open('behaviors/reef_fish.rhai');
    await s.diagnostics(ron.uri, clean, 0, 'the shipped reef_fish.ron (none)');
    const line = lineOf(ron.text, 'Script("crowded")');
    const original = rhai.text;
    const from = s.published.length;
    await s.change(rhai, original.replace('fn crowded()', 'fn should_go()'));
    const got = await s.diagnostics(ron.uri, errorsAt(line), from, `an error on reef_fish.ron line ${line}`);
    assert.match(got.diagnostics.find((x) => x.range.start.line === line).message, /crowded/);
    const back = s.published.length;
    await s.change(rhai, original);
    await s.diagnostics(ron.uri, clean, back, 'reef_fish.ron once the script is back (none)');
  });
});

test('a behavior name a script compares `this.behavior` with', async () => {
  await withServer(async (s) => {
    const doc = await s.open('behaviors/goby.rhai');
    const typo = doc.text.replace('this.behavior == "flee"', 'this.behavior == "fle"');
    const line = lineOf(typo, '"fle"');
    const from = s.published.length;
    await s.change(doc, typo);
    const got = await s.diagnostics(doc.uri, errorsAt(line), from, `an error on line ${line}`);
    const d = got.diagnostics.find((x) => x.range.start.line === line);
    expectStringAt(d, typo.split('\n')[line], '"fle"');
    assert.match(d.message, /did you mean `flee`/);
    assert.equal(uriOf(s.root, 'behaviors/goby.rhai'), doc.uri);
  });
});
