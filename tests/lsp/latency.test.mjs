// Response times of `shoal lsp` on the shipped project, per request kind: each request repeated
// $SHOAL_LSP_REPS times (20 by default) after one warm-up, median and 95th percentile printed as
// a Markdown table (the figures of BENCHMARKS.md come from a release build:
// `SHOAL_BIN=target/release/shoal SHOAL_LSP_REPS=200 node --test tests/lsp/latency.test.mjs`).
// With $SHOAL_LSP_BUDGET_MS set, every kind's 95th percentile must be within it.

import assert from 'node:assert/strict';
import test from 'node:test';
import { performance } from 'node:perf_hooks';
import { lineOf, positionOf, protocol, shoalBin, stats, withServer } from './client.mjs';

const { CompletionRequest, HoverRequest, DefinitionRequest, ReferencesRequest, DocumentSymbolRequest, RenameRequest } =
  protocol;
const REPS = Number(process.env.SHOAL_LSP_REPS || 20);
const BUDGET_MS = process.env.SHOAL_LSP_BUDGET_MS ? Number(process.env.SHOAL_LSP_BUDGET_MS) : null;

test(`median and p95 response times over ${REPS} requests of each kind`, async () => {
  await withServer(async (s) => {
    const ron = await s.open('behaviors/reef_fish.ron');
    const rhai = await s.open('behaviors/reef_fish.rhai');
    const at = (doc, needle, within) => ({ textDocument: { uri: doc.uri }, position: positionOf(doc.text, needle, { within }) });
    const steerAt = { ...at(ron, 'steer: Priority([AvoidStatic(), Contain(), Wander', 7), context: { triggerKind: 1 } };
    const thisAt = { ...at(rhai, 'this.kin', 5), context: { triggerKind: 2, triggerCharacter: '.' } };
    const kinds = {
      'completion (`steer: `)': () => s.request(CompletionRequest.type, steerAt),
      'completion (`this.`)': () => s.request(CompletionRequest.type, thisAt),
      'hover (primitive)': () => s.request(HoverRequest.type, at(ron, 'Wander(cruise', 2)),
      'definition (RON → Rhai)': () => s.request(DefinitionRequest.type, at(ron, 'Script("crowded")', 12)),
      references: () =>
        s.request(ReferencesRequest.type, { ...at(rhai, 'fn crowded', 5), context: { includeDeclaration: true } }),
      'document symbols': () => s.request(DocumentSymbolRequest.type, { textDocument: { uri: ron.uri } }),
      rename: () => s.request(RenameRequest.type, { ...at(ron, 'name: "wander"', 8), newName: 'roam' }),
    };

    // Diagnostics: a change that introduces an error until its diagnostics arrive, then the
    // change that fixes it until they are cleared.
    const original = ron.text;
    const typo = original.replace('when: TrafficNear,', 'when: TraficNear,');
    const typoLine = lineOf(typo, 'TraficNear');
    const roundTrip = async (text, ok, what) => {
      const from = s.published.length;
      const t0 = performance.now();
      await s.change(ron, text);
      await s.diagnostics(ron.uri, ok, from, what);
      return performance.now() - t0;
    };
    const hasTypo = (ds) => ds.some((d) => d.range.start.line === typoLine);
    const none = (ds) => ds.length === 0;

    const rows = [];
    for (const [kind, send] of Object.entries(kinds)) {
      const first = await send(); // warm-up; also: it is answered
      assert.notEqual(first, undefined, kind);
      const times = [];
      for (let i = 0; i < REPS; i++) {
        const t0 = performance.now();
        await send();
        times.push(performance.now() - t0);
      }
      rows.push([kind, stats(times)]);
    }
    const errorTimes = [];
    const clearTimes = [];
    await roundTrip(typo, hasTypo, 'the typo (warm-up)');
    await roundTrip(original, none, 'the fix (warm-up)');
    for (let i = 0; i < REPS; i++) {
      errorTimes.push(await roundTrip(typo, hasTypo, 'the typo'));
      clearTimes.push(await roundTrip(original, none, 'the fix'));
    }
    rows.push(['diagnostics after a change (error appears)', stats(errorTimes)]);
    rows.push(['diagnostics after a change (error cleared)', stats(clearTimes)]);

    const ms = (x) => x.toFixed(1);
    const table = [
      `shoal lsp on the shipped project (${shoalBin()}), ${REPS} requests of each kind after a warm-up:`,
      '',
      '| request | median (ms) | p95 (ms) |',
      '|---|---|---|',
      ...rows.map(([kind, st]) => `| ${kind} | ${ms(st.median)} | ${ms(st.p95)} |`),
    ].join('\n');
    console.log(table);
    if (BUDGET_MS !== null) {
      const slow = rows.filter(([, st]) => st.p95 > BUDGET_MS).map(([k, st]) => `${k}: ${ms(st.p95)} ms`);
      assert.deepEqual(slow, [], `p95 within ${BUDGET_MS} ms`);
    }
  });
});
