// Completion where designers type: the steering primitives after `steer: ` in a species file
// (the names of the reference's Steering section, each with its reference text), the `this.` API
// in a behavior script (the properties and methods of src/script/view.rs, methods with their
// parameters), and the test API in a designers' test.

import assert from 'node:assert/strict';
import test from 'node:test';
import {
  completionItems,
  docText,
  expectCapability,
  positionAt,
  protocol,
  referenceRows,
  referenceText,
  withServer,
} from './client.mjs';

const { CompletionRequest, CompletionResolveRequest } = protocol;
const INVOKED = 1;
const TRIGGER_CHARACTER = 2;

/** The items offered at the end of `needle`, after replacing `from` by `to` in `rel`'s text. */
async function completeAfter(s, rel, from, to, needle, context = { triggerKind: INVOKED }) {
  const doc = await s.open(rel);
  const text = doc.text.replace(from, to);
  assert.notEqual(text, doc.text, `${rel} contains ${JSON.stringify(from)}`);
  await s.change(doc, text);
  const position = positionAt(text, text.indexOf(needle) + needle.length);
  const answer = await s.request(CompletionRequest.type, { textDocument: { uri: doc.uri }, position, context });
  return completionItems(answer);
}

/** The item for `name` (labelled `name` or `name(…)`). */
const itemFor = (items, name) => items.find((i) => i.label === name || i.label.startsWith(`${name}(`));

/** An item's documentation, resolved first when the server defers it. */
async function documentation(s, item) {
  if (item.documentation || !s.capabilities.completionProvider.resolveProvider) return docText(item.documentation);
  return docText((await s.request(CompletionResolveRequest.type, item)).documentation);
}

const squash = (t) => t.replace(/\s+/g, ' ');

test('`steer: ` lists the steering primitives with their reference text', async () => {
  await withServer(async (s) => {
    expectCapability(s, 'completionProvider');
    // A behavior whose steering the designer is writing: `steer: ` and the cursor after it.
    const items = await completeAfter(
      s,
      'behaviors/reef_fish.ron',
      'steer: Priority([AvoidStatic(), Contain(), Wander(cruise: 0.4)]),',
      'steer: ',
      'priority: 5,\n            steer: ',
    );
    const primitives = referenceRows('## Steering').flatMap((r) => r.names);
    assert.ok(primitives.length >= 20, `primitives read from the reference: ${primitives}`);
    const labels = items.map((i) => i.label);
    const missing = [...primitives, 'Priority', 'Blend'].filter((n) => !itemFor(items, n));
    assert.deepEqual(missing, [], `offered: ${labels.join(', ')}`);
    // Steering, not conditions: the slot's own vocabulary.
    for (const condition of ['TrafficNear', 'EscapeDone', 'Sees']) {
      assert.ok(!itemFor(items, condition), `${condition} (a condition) is not offered for steer`);
    }
    const wander = await documentation(s, itemFor(items, 'Wander'));
    const expected = referenceText('## Steering', 'Wander', 2);
    assert.ok(squash(wander).includes(squash(expected)), `Wander's documentation has "${expected}": ${wander}`);
  });
});

test('`this.` in a behavior script lists the script API', async () => {
  await withServer(async (s) => {
    const cap = expectCapability(s, 'completionProvider');
    assert.ok((cap.triggerCharacters || []).includes('.'), `'.' triggers completion: ${JSON.stringify(cap)}`);
    const items = await completeAfter(
      s,
      'behaviors/reef_fish.rhai',
      'fn crowded() {\n',
      'fn crowded() {\n    let probe = this.\n',
      'let probe = this.',
      { triggerKind: TRIGGER_CHARACTER, triggerCharacter: '.' },
    );
    const labels = items.map((i) => i.label.replace(/\(.*$/, ''));
    // Properties and methods bound on `this` (src/script/view.rs, behaviors/README.md "What `this` is").
    const api = [
      'pos', 'vel', 'fwd', 'speed', 'max_speed', 'time', 'dt', 'tick', 'id', 'species', 'behavior',
      'time_in_behavior', 'hunger', 'libido', 'fear', 'fatigue', 'food', 'predator', 'kin', 'mate',
      'obstacle', 'heard', 'has', 'forget', 'random', 'random_range', 'send', 'recipe', 'seek',
      'flee', 'arrive', 'velocity', 'turn', 'keep', 'stop',
    ];
    const missing = api.filter((n) => !labels.includes(n));
    assert.deepEqual(missing, [], `offered after this.: ${labels.join(', ')}`);
    // Not the test API, nor RON vocabulary.
    for (const other of ['assert_behavior', 'add_agent', 'Wander']) assert.ok(!labels.includes(other), other);
    // Methods come with their signature.
    const range = items.find((i) => i.label.replace(/\(.*$/, '') === 'random_range');
    // The registered signature (its types) and the reference entry (its parameters' names).
    assert.match(range.detail || '', /random_range\(float, float\) -> float/, `random_range's signature: ${JSON.stringify(range)}`);
    const doc = typeof range.documentation === 'string' ? range.documentation : (range.documentation || {}).value || '';
    assert.match(doc, /random_range\(lo, hi\)/, `random_range's reference entry: ${JSON.stringify(range)}`);
  });
});

test('a designers\' test lists the test API', async () => {
  await withServer(async (s) => {
    const rel = 'behaviors/tests/reef_fish.rhai';
    const items = await completeAfter(
      s,
      rel,
      '    w.run(3.0);\n',
      '    w.run(3.0);\n    assert_\n',
      '    w.run(3.0);\n    assert_',
    );
    const labels = items.map((i) => i.label.replace(/\(.*$/, ''));
    const api = ['assert_behavior', 'assert_stack', 'assert_transition', 'assert_within', 'assert_always', 'assert_eq'];
    const missing = api.filter((n) => !labels.includes(n));
    assert.deepEqual(missing, [], `offered in a test: ${labels.join(', ')}`);
    const behavior = items.find((i) => i.label.replace(/\(.*$/, '') === 'assert_behavior');
    const shown = [behavior.label, behavior.detail, behavior.labelDetails && behavior.labelDetails.detail].join(' ');
    assert.match(shown, /\(.+\)/, `assert_behavior shows its parameters: ${JSON.stringify(behavior)}`);
  });
});
