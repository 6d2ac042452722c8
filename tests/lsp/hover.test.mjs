// Hover shows the designers' reference entry (behaviors/README.md) of the name under the cursor,
// as Markdown, for a steering primitive and a condition in a species file and for a `this.`
// method in a script.

import assert from 'node:assert/strict';
import test from 'node:test';
import { docText, expectCapability, positionOf, protocol, referenceText, withServer } from './client.mjs';

const { HoverRequest } = protocol;
const squash = (t) => t.replace(/\s+/g, ' ');

/** The hover at `needle` (`within` characters into it) in `rel`. */
async function hoverAt(s, rel, needle, within = 1) {
  const doc = await s.open(rel);
  const position = positionOf(doc.text, needle, { within });
  const hover = await s.request(HoverRequest.type, { textDocument: { uri: doc.uri }, position });
  return { hover, position };
}

function expectMarkdown(hover, expected, word, position) {
  assert.ok(hover, `a hover for ${word}`);
  // The client said it renders Markdown first.
  assert.equal(hover.contents.kind, 'markdown', JSON.stringify(hover.contents));
  const text = docText(hover.contents);
  assert.ok(squash(text).includes(squash(expected)), `the hover of ${word} has "${expected}": ${text}`);
  if (hover.range) {
    // The range is the word's: on its line, covering the cursor.
    assert.equal(hover.range.start.line, position.line);
    assert.ok(hover.range.start.character <= position.character && position.character < hover.range.end.character);
    assert.equal(hover.range.end.character - hover.range.start.character, word.length, JSON.stringify(hover.range));
  }
}

test('a steering primitive in a species file', async () => {
  await withServer(async (s) => {
    expectCapability(s, 'hoverProvider');
    const { hover, position } = await hoverAt(s, 'behaviors/reef_fish.ron', 'Wander(cruise: 0.4)', 2);
    expectMarkdown(hover, referenceText('## Steering', 'Wander', 2), 'Wander', position);
  });
});

test('a condition in a species file', async () => {
  await withServer(async (s) => {
    const { hover, position } = await hoverAt(s, 'behaviors/reef_fish.ron', 'when: TrafficNear', 8);
    expectMarkdown(hover, referenceText('## Conditions', 'TrafficNear', 1), 'TrafficNear', position);
  });
});

test('a `this.` method in a script', async () => {
  await withServer(async (s) => {
    const { hover, position } = await hoverAt(s, 'behaviors/jellyfish.rhai', 'this.has(', 6);
    // "| `this.has("key")`, `this.forget("key")` | whether the key is set; unset it |"
    expectMarkdown(hover, 'whether the key is set', 'has', position);
  });
});

test('no hover on a comment', async () => {
  await withServer(async (s) => {
    const { hover } = await hoverAt(s, 'behaviors/reef_fish.ron', 'A reef fish with the nine', 3);
    assert.equal(hover, null);
  });
});
