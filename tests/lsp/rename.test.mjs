// Rename across RON, Rhai and tests: the server's WorkspaceEdit is written to the files of a copy
// of the project as an editor would, and the project still checks (`shoal check`) and its tests
// still pass (`shoal test`) afterwards.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import test from 'node:test';
import {
  applyWorkspaceEdit,
  editsByFile,
  expectCapability,
  positionOf,
  protocol,
  runShoal,
  withServer,
} from './client.mjs';

const { RenameRequest, PrepareRenameRequest } = protocol;

/** Every file of the project copy, as { relative path: text }. */
function snapshot(root) {
  const out = {};
  const walk = (dir) => {
    for (const e of fs.readdirSync(dir, { withFileTypes: true })) {
      const p = path.join(dir, e.name);
      if (e.isDirectory()) walk(p);
      else out[path.relative(root, p)] = fs.readFileSync(p, 'utf8');
    }
  };
  walk(root);
  return out;
}

/** The rename of the name at `needle` (`within` into it) in `rel` to `newName`, applied. */
async function renameAt(s, rel, needle, within, newName) {
  const doc = await s.open(rel);
  const position = positionOf(doc.text, needle, { within });
  const params = { textDocument: { uri: doc.uri }, position };
  const cap = expectCapability(s, 'renameProvider');
  if (typeof cap === 'object' && cap.prepareProvider) {
    const prepared = await s.request(PrepareRenameRequest.type, params);
    assert.ok(prepared, `the name at ${needle} can be renamed`);
  }
  const edit = await s.request(RenameRequest.type, { ...params, newName });
  assert.ok(edit, `a WorkspaceEdit for ${needle}`);
  const before = snapshot(s.root);
  const changed = applyWorkspaceEdit(edit).map((p) => path.relative(s.root, p)).sort();
  return { edit, before, after: snapshot(s.root), changed };
}

/** The files whose text differs between two snapshots. */
const differing = (a, b) => Object.keys(b).filter((k) => a[k] !== b[k]).sort();

test('a behavior renamed in its species renames it in the script and the tests', async () => {
  await withServer(async (s) => {
    const { edit, before, after, changed } = await renameAt(s, 'behaviors/goby.ron', 'name: "flee"', 8, 'bolt');
    const files = ['behaviors/goby.ron', 'behaviors/goby.rhai', 'behaviors/tests/goby.rhai'];
    assert.deepEqual(changed, [...files].sort(), `the edit touches: ${JSON.stringify(edit)}`);
    assert.deepEqual(differing(before, after), [...files].sort());
    // Every use of the name as a whole string becomes the new name; other text stays.
    for (const f of files) {
      const uses = (t) => (t.match(/"flee"/g) || []).length;
      assert.equal(uses(after[f]), 0, `no "flee" left in ${f}`);
      assert.equal((after[f].match(/"bolt"/g) || []).length, uses(before[f]), f);
      assert.equal(after[f].replaceAll('"bolt"', '"flee"'), before[f], `${f} changes only at the name`);
    }
    const check = runShoal(s.root, ['check']);
    assert.equal(check.status, 0, `shoal check after the rename:\n${check.out}`);
    const tests = runShoal(s.root, ['test', 'behaviors/tests/goby.rhai']);
    assert.equal(tests.status, 0, `shoal test after the rename:\n${tests.out}`);
    assert.ok(editsByFile(edit).size === 3);
  });
});

test('a script function renamed in its script is renamed where the species names it', async () => {
  await withServer(async (s) => {
    const { before, after, changed } = await renameAt(s, 'behaviors/reef_fish.rhai', 'fn crowded', 5, 'wants_to_leave');
    const files = ['behaviors/reef_fish.rhai', 'behaviors/reef_fish.ron'];
    assert.deepEqual(changed, files);
    assert.deepEqual(differing(before, after), files);
    assert.match(after['behaviors/reef_fish.rhai'], /fn wants_to_leave\(\)/);
    assert.match(after['behaviors/reef_fish.ron'], /Script\("wants_to_leave"\)/);
    // Every use in code is renamed (comments are prose and stay as written).
    const code = (t) => t.split('\n').map((l) => l.replace(/\/\/.*$/, '')).join('\n');
    assert.doesNotMatch(code(after['behaviors/reef_fish.ron'] + after['behaviors/reef_fish.rhai']), /\bcrowded\b/);
    const check = runShoal(s.root, ['check']);
    assert.equal(check.status, 0, `shoal check after the rename:\n${check.out}`);
  });
});

test('a rename to a name the species already has is refused', async () => {
  await withServer(async (s) => {
    const doc = await s.open('behaviors/goby.ron');
    const position = positionOf(doc.text, 'name: "flee"', { within: 8 });
    await assert.rejects(
      s.request(RenameRequest.type, { textDocument: { uri: doc.uri }, position, newName: 'hide' }),
      (e) => /hide/.test(e.message),
      'renaming flee to hide (another behavior of the goby) is an error naming it',
    );
  });
});
