// The TextMate grammars as VS Code runs them (vscode-textmate with the Oniguruma regex engine),
// on the shipped species, script and test files: every pattern compiles, and a few tokens get the
// scopes themes color.
'use strict';

const test = require('node:test');
const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');
const vsctm = require('vscode-textmate');
const oniguruma = require('vscode-oniguruma');

const EXT = path.join(__dirname, '..');
const BEHAVIORS = path.join(EXT, '..', '..', 'behaviors');

const onig = (async () => {
  const wasm = fs.readFileSync(path.join(path.dirname(require.resolve('vscode-oniguruma')), 'onig.wasm'));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  return {
    createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
    createOnigString: (s) => new oniguruma.OnigString(s),
  };
})();

const registry = new vsctm.Registry({
  onigLib: onig,
  loadGrammar: async (scopeName) => {
    const file = { 'source.ron': 'ron', 'source.rhai': 'rhai' }[scopeName];
    if (!file) return null;
    const p = path.join(EXT, 'syntaxes', `${file}.tmLanguage.json`);
    return vsctm.parseRawGrammar(fs.readFileSync(p, 'utf8'), p);
  },
});

/** Every token of `text` as { line, text, scopes }. */
async function tokenize(scope, text) {
  const grammar = await registry.loadGrammar(scope);
  assert.ok(grammar, `grammar ${scope} loads`);
  let stack = vsctm.INITIAL;
  const tokens = [];
  text.split('\n').forEach((line, i) => {
    const r = grammar.tokenizeLine(line, stack);
    for (const t of r.tokens) {
      tokens.push({ line: i + 1, text: line.slice(t.startIndex, t.endIndex), scopes: t.scopes });
    }
    stack = r.ruleStack;
  });
  return tokens;
}

/** Asserts that the first token reading `text` (after `afterLine`, if given) has scope `scope`. */
function expectScope(tokens, text, scope, afterLine = 0) {
  const t = tokens.find((k) => k.line > afterLine && k.text === text);
  assert.ok(t, `a token "${text}" after line ${afterLine}`);
  assert.ok(
    t.scopes.includes(scope),
    `"${text}" (line ${t.line}) has scope ${scope}; it has ${t.scopes.join(' ')}`,
  );
}

const read = (f) => fs.readFileSync(path.join(BEHAVIORS, f), 'utf8');
const lineOf = (text, needle) => text.split('\n').findIndex((l) => l.includes(needle)) + 1;

test('package.json declares both grammars and languages', () => {
  const pkg = JSON.parse(fs.readFileSync(path.join(EXT, 'package.json'), 'utf8'));
  const langs = pkg.contributes.languages.map((l) => [l.id, l.extensions[0]]);
  assert.deepEqual(langs, [['ron', '.ron'], ['rhai', '.rhai']]);
  for (const g of pkg.contributes.grammars) {
    assert.ok(fs.existsSync(path.join(EXT, g.path)), g.path);
    const raw = JSON.parse(fs.readFileSync(path.join(EXT, g.path), 'utf8'));
    assert.equal(raw.scopeName, g.scopeName);
  }
  for (const l of pkg.contributes.languages) {
    JSON.parse(fs.readFileSync(path.join(EXT, l.configuration), 'utf8'));
  }
  assert.equal(pkg.contributes.configuration.properties['shoal.path'].default, 'shoal');
  // A range (any VS Code from the client library's minimum on), not one exact version.
  assert.match(pkg.engines.vscode, /^\^1\.\d+\.\d+$/);
  assert.equal(pkg.main, './extension.js');
  assert.ok(pkg.contributes.configuration.properties['shoal.trace.server']);
});

test('RON: a species file', async () => {
  const text = read('reef_fish.ron');
  const tokens = await tokenize('source.ron', text);
  expectScope(tokens, ' A reef fish with the nine behaviors of seed 000 (path planning of an artificial fish).', 'comment.line.double-slash.ron');
  expectScope(tokens, 'Species', 'entity.name.type.ron');
  expectScope(tokens, 'name', 'variable.other.property.ron');
  expectScope(tokens, 'reef_fish', 'string.quoted.double.ron');
  expectScope(tokens, '4.0', 'constant.numeric.float.ron');
  expectScope(tokens, '8', 'constant.numeric.integer.decimal.ron', lineOf(text, 'max_percepts') - 1);
  expectScope(tokens, 'Kinematic', 'variable.other.enummember.ron');
  expectScope(tokens, 'true', 'constant.language.boolean.ron');
  expectScope(tokens, 'Some', 'keyword.other.option.ron');
  expectScope(tokens, 'None', 'keyword.other.option.ron');
  expectScope(tokens, 'Behavior', 'entity.name.type.ron');
  expectScope(tokens, 'Sees', 'entity.name.type.ron');
  expectScope(tokens, 'Predator', 'variable.other.enummember.ron');
  expectScope(tokens, 'steer', 'variable.other.property.ron');
  // Keys inside a steering primitive's parentheses.
  expectScope(tokens, 'd0', 'variable.other.property.ron', lineOf(text, 'Chase(target: Food, d0: 0.6)') - 1);
  // Nothing after the header is left as plain text of the file's root scope only.
  const bare = tokens.filter((t) => t.text.trim() && t.scopes.length === 1);
  assert.deepEqual(bare.map((t) => `${t.line}: ${t.text}`), []);
});

test('RON: nested block comments, raw strings, escapes, signed numbers', async () => {
  const tokens = await tokenize(
    'source.ron',
    '/* a /* nested */ still comment */ (x: -1.5e3, y: r#"raw "quoted""#, z: "a\\n", w: 0x1F, v: \'c\')',
  );
  expectScope(tokens, ' still comment ', 'comment.block.ron');
  expectScope(tokens, '-1.5e3', 'constant.numeric.float.ron');
  expectScope(tokens, 'raw "quoted"', 'string.quoted.other.raw.ron');
  expectScope(tokens, '\\n', 'constant.character.escape.ron');
  expectScope(tokens, '0x1F', 'constant.numeric.integer.hexadecimal.ron');
  expectScope(tokens, "'c'", 'string.quoted.single.char.ron');
});

test('Rhai: a behavior script', async () => {
  const text = read('reef_fish.rhai');
  const tokens = await tokenize('source.rhai', text);
  expectScope(tokens, ' Script of the reef fish: what the RON form cannot say.', 'comment.line.double-slash.rhai');
  expectScope(tokens, 'fn', 'storage.type.function.rhai');
  expectScope(tokens, 'crowded', 'entity.name.function.rhai');
  expectScope(tokens, 'this', 'variable.language.this.rhai');
  expectScope(tokens, 'mated_at', 'string.quoted.double.rhai');
  expectScope(tokens, '0.5', 'constant.numeric.float.rhai');
  const jelly = await tokenize('source.rhai', read('jellyfish.rhai'));
  expectScope(jelly, 'let', 'storage.type.rhai');
  expectScope(jelly, 'side', 'variable.other.declaration.rhai');
  expectScope(jelly, 'has', 'entity.name.function.member.rhai');
  expectScope(tokens, '8', 'constant.numeric.integer.decimal.rhai');
  expectScope(tokens, 'kin', 'variable.other.property.rhai');
  expectScope(tokens, 'if', 'keyword.control.rhai');
  expectScope(tokens, 'kind', 'variable.parameter.rhai');
  const bare = tokens.filter((t) => t.text.trim() && t.scopes.length === 1);
  assert.deepEqual(bare.map((t) => `${t.line}: ${t.text}`), []);
});

test('Rhai: imports, modules, maps, closures and interpolation', async () => {
  const sardine = await tokenize('source.rhai', read('sardine.rhai'));
  expectScope(sardine, 'import', 'keyword.control.import.rhai');
  expectScope(sardine, 'as', 'keyword.control.import.rhai');
  expectScope(sardine, 'school', 'entity.name.namespace.rhai', lineOf(read('sardine.rhai'), 'school::running_mean') - 1);
  expectScope(sardine, 'running_mean', 'entity.name.function.call.rhai');
  const tests = await tokenize('source.rhai', read('tests/reef_fish.rhai'));
  expectScope(tests, '#{', 'punctuation.definition.map.begin.rhai');
  expectScope(tests, 'hunger', 'variable.other.property.key.rhai');
  expectScope(tests, 'vec3', 'entity.name.function.call.rhai');
  expectScope(tests, 'assert_behavior', 'entity.name.function.call.rhai');
  const more = await tokenize('source.rhai', 'let s = `speed ${this.speed} /* x */`; /* a /* b */ c */ let n = 0xFF;');
  expectScope(more, 'speed', 'variable.other.property.rhai');
  expectScope(more, ' /* x */', 'string.interpolated.rhai');
  expectScope(more, ' c ', 'comment.block.rhai');
  expectScope(more, '0xFF', 'constant.numeric.integer.hexadecimal.rhai');
});
