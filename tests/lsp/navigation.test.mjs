// Go to definition, find references and the outline, across the files of a project: RON script
// slots to Rhai functions, behavior names to the species' `Behavior(name: …)`, imports to shared
// modules, module calls to the module's function, scenario species to species files.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import test from 'node:test';
import {
  expectCapability,
  lineOf,
  locations,
  pathOf,
  positionOf,
  protocol,
  uriOf,
  withServer,
} from './client.mjs';

const { DefinitionRequest, ReferencesRequest, DocumentSymbolRequest } = protocol;

const textOf = (s, rel) => fs.readFileSync(path.join(s.root, rel), 'utf8');

/** The one definition of the name at `needle` (`within` characters into it) in `rel`. */
async function definitionAt(s, rel, needle, within) {
  const doc = await s.open(rel);
  const position = positionOf(doc.text, needle, { within });
  const found = locations(
    await s.request(DefinitionRequest.type, { textDocument: { uri: doc.uri }, position }),
  );
  assert.equal(found.length, 1, `one definition of ${needle}: ${JSON.stringify(found)}`);
  return found[0];
}

/** Asserts `loc` is in `rel` on the line holding `lineText`, covering `word` there if given. */
function expectAt(s, loc, rel, lineText, word) {
  assert.equal(pathOf(loc.uri), pathOf(uriOf(s.root, rel)), JSON.stringify(loc));
  const text = textOf(s, rel);
  const line = lineOf(text, lineText);
  assert.equal(loc.range.start.line, line, `${rel} line ${line + 1} (${lineText}): ${JSON.stringify(loc.range)}`);
  if (word) {
    const col = text.split('\n')[line].indexOf(word);
    const ends = loc.range.end.line > line ? Infinity : loc.range.end.character;
    assert.ok(
      loc.range.start.character <= col && col + word.length <= ends,
      `the range covers ${word} (column ${col}): ${JSON.stringify(loc.range)}`,
    );
  }
}

test('from a RON script slot to the Rhai function', async () => {
  await withServer(async (s) => {
    expectCapability(s, 'definitionProvider');
    const loc = await definitionAt(s, 'behaviors/reef_fish.ron', 'Script("crowded")', 12);
    expectAt(s, loc, 'behaviors/reef_fish.rhai', 'fn crowded()', 'crowded');
  });
});

test('from a behavior name to its Behavior(name: …)', async () => {
  await withServer(async (s) => {
    // `initial: "wander"` in the same species.
    const own = await definitionAt(s, 'behaviors/reef_fish.ron', 'initial: "wander"', 12);
    expectAt(s, own, 'behaviors/reef_fish.ron', 'name: "wander"', 'wander');
    // A script comparing `this.behavior`, and a designers' test.
    const script = await definitionAt(s, 'behaviors/goby.rhai', 'this.behavior == "flee"', 19);
    expectAt(s, script, 'behaviors/goby.ron', 'name: "flee"', 'flee');
    const inTest = await definitionAt(s, 'behaviors/tests/goby.rhai', 'assert_behavior(lookout, "flee")', 27);
    expectAt(s, inTest, 'behaviors/goby.ron', 'name: "flee"', 'flee');
  });
});

test('from an import to the shared module, and from a module call to its function', async () => {
  await withServer(async (s) => {
    const module = await definitionAt(s, 'behaviors/sardine.rhai', 'import "common/schooling"', 10);
    assert.equal(pathOf(module.uri), pathOf(uriOf(s.root, 'behaviors/common/schooling.rhai')));
    const fn = await definitionAt(s, 'behaviors/sardine.rhai', 'school::running_mean', 10);
    expectAt(s, fn, 'behaviors/common/schooling.rhai', 'fn running_mean(', 'running_mean');
  });
});

test('from a species named in a scenario to its species file', async () => {
  await withServer(async (s) => {
    const loc = await definitionAt(s, 'scenarios/reef.ron', '(species: "sardine"', 13);
    assert.equal(pathOf(loc.uri), pathOf(uriOf(s.root, 'behaviors/sardine.ron')));
  });
});

test('references of a script function and of a behavior, across RON, Rhai and tests', async () => {
  await withServer(async (s) => {
    expectCapability(s, 'referencesProvider');
    const rhai = await s.open('behaviors/reef_fish.rhai');
    const fnRefs = locations(
      await s.request(ReferencesRequest.type, {
        textDocument: { uri: rhai.uri },
        position: positionOf(rhai.text, 'fn crowded', { within: 4 }),
        context: { includeDeclaration: true },
      }),
    );
    const where = (refs) => refs.map((r) => `${path.relative(s.root, pathOf(r.uri))}:${r.range.start.line + 1}`).sort();
    assert.deepEqual(where(fnRefs), [
      `behaviors/reef_fish.rhai:${lineOf(rhai.text, 'fn crowded') + 1}`,
      `behaviors/reef_fish.ron:${lineOf(textOf(s, 'behaviors/reef_fish.ron'), 'Script("crowded")') + 1}`,
    ]);

    const ron = await s.open('behaviors/goby.ron');
    const behaviorRefs = locations(
      await s.request(ReferencesRequest.type, {
        textDocument: { uri: ron.uri },
        position: positionOf(ron.text, 'name: "flee"', { within: 8 }),
        context: { includeDeclaration: false },
      }),
    );
    const script = textOf(s, 'behaviors/goby.rhai').split('\n');
    const tests = textOf(s, 'behaviors/tests/goby.rhai').split('\n');
    const uses = (lines, rel) =>
      lines.flatMap((l, i) => (l.includes('"flee"') ? [`${rel}:${i + 1}`] : []));
    assert.deepEqual(
      where(behaviorRefs),
      [...uses(script, 'behaviors/goby.rhai'), ...uses(tests, 'behaviors/tests/goby.rhai')].sort(),
    );
  });
});

test('the outline: behaviors of a species, functions of a script', async () => {
  await withServer(async (s) => {
    expectCapability(s, 'documentSymbolProvider');
    const names = async (rel) => {
      const doc = await s.open(rel);
      const symbols = await s.request(DocumentSymbolRequest.type, { textDocument: { uri: doc.uri } });
      // DocumentSymbol trees or flat SymbolInformation lists: every name, at any depth.
      const all = [];
      const walk = (list) => list.forEach((x) => (all.push(x.name), walk(x.children || [])));
      walk(symbols || []);
      return all;
    };
    const ron = await names('behaviors/reef_fish.ron');
    for (const b of ['avoid_static', 'escape', 'avoid_dynamic', 'eat', 'chase', 'mate', 'leave', 'school', 'wander']) {
      assert.ok(ron.some((n) => n === b || n.includes(`"${b}"`)), `${b} in the outline: ${ron.join(', ')}`);
    }
    const rhai = await names('behaviors/reef_fish.rhai');
    for (const f of ['crowded', 'on_event']) {
      assert.ok(rhai.some((n) => n === f || n.startsWith(`${f}(`)), `${f} in the outline: ${rhai.join(', ')}`);
    }
  });
});
