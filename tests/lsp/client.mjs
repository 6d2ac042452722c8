// Shared by the language-server tests: a temporary copy of the shipped project, `shoal lsp`
// spawned on it and driven over stdio by VS Code's own client-side protocol library
// (vscode-languageserver-protocol + vscode-jsonrpc, the code the VS Code extension runs), and
// helpers for positions, edits and the answers' several shapes.
//
// The binary is $SHOAL_BIN (tests/lsp_client.rs passes the one cargo built). Every wait has a
// deadline ($SHOAL_LSP_TIMEOUT_MS, 15 s by default), so a server that never answers fails the test
// with what it was asked instead of hanging it.

import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import jsonrpc from 'vscode-jsonrpc/node.js';
import protocol from 'vscode-languageserver-protocol/node.js';

const { StreamMessageReader, StreamMessageWriter } = jsonrpc;
const {
  createProtocolConnection,
  InitializeRequest,
  InitializedNotification,
  ShutdownRequest,
  ExitNotification,
  DidOpenTextDocumentNotification,
  DidChangeTextDocumentNotification,
  DidCloseTextDocumentNotification,
  PublishDiagnosticsNotification,
} = protocol;

export { protocol };

/** The repository root. */
export const REPO = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
/** How long any one answer or notification may take. */
export const TIMEOUT_MS = Number(process.env.SHOAL_LSP_TIMEOUT_MS || 15000);

/** The `shoal` binary under test. */
export function shoalBin() {
  const bin = process.env.SHOAL_BIN;
  assert.ok(
    bin && fs.existsSync(bin),
    `SHOAL_BIN must name a built shoal binary (got ${JSON.stringify(bin)}); ` +
      'run these through `cargo test --test lsp_client`',
  );
  return bin;
}

/** A temporary copy of the shipped project (behaviors/, scenarios/, assets/); its real path. */
export function copyProject() {
  const root = fs.realpathSync(fs.mkdtempSync(path.join(os.tmpdir(), 'shoal-lsp-')));
  for (const dir of ['behaviors', 'scenarios', 'assets']) {
    fs.cpSync(path.join(REPO, dir), path.join(root, dir), { recursive: true });
  }
  return root;
}

/** Removes a copy made by copyProject. */
export function removeProject(root) {
  fs.rmSync(root, { recursive: true, force: true });
}

/** The file: URI of `rel` under `root`. */
export const uriOf = (root, rel) => pathToFileURL(path.join(root, rel)).href;

/** The path a file: URI names, normalised so that URIs written differently compare equal. */
export const pathOf = (uri) => path.normalize(fileURLToPath(uri));

/** The 0-based { line, character } (UTF-16 units, the protocol's default) of byte index `i`. */
export function positionAt(text, i) {
  const before = text.slice(0, i);
  const line = before.split('\n').length - 1;
  return { line, character: i - (before.lastIndexOf('\n') + 1) };
}

/** The index in `text` of `needle`'s `nth` occurrence (0-based), plus `within`. */
export function indexOf(text, needle, { nth = 0, within = 0 } = {}) {
  let at = -1;
  for (let k = 0; k <= nth; k++) {
    at = text.indexOf(needle, at + 1);
    assert.ok(at >= 0, `${JSON.stringify(needle)} occurs ${nth + 1} times`);
  }
  return at + within;
}

/** The position of `needle`'s `nth` occurrence in `text`, `within` characters into it. */
export const positionOf = (text, needle, opts) => positionAt(text, indexOf(text, needle, opts));

/** The 0-based line of the first line of `text` that contains `needle`. */
export function lineOf(text, needle) {
  const i = text.split('\n').findIndex((l) => l.includes(needle));
  assert.ok(i >= 0, `a line containing ${JSON.stringify(needle)}`);
  return i;
}

/** `promise`, or a failure naming `what` after TIMEOUT_MS. */
export function deadline(promise, what, ms = TIMEOUT_MS) {
  let timer;
  const late = new Promise((_, reject) => {
    timer = setTimeout(() => reject(new Error(`no ${what} within ${ms} ms`)), ms);
  });
  return Promise.race([promise, late]).finally(() => clearTimeout(timer));
}

/** What a real editor tells the server it can do (VS Code's answers, trimmed to what we use). */
const CLIENT_CAPABILITIES = {
  general: { positionEncodings: ['utf-16'] },
  textDocument: {
    synchronization: { dynamicRegistration: false, didSave: true },
    publishDiagnostics: { relatedInformation: true, versionSupport: true },
    completion: {
      completionItem: {
        snippetSupport: false,
        documentationFormat: ['markdown', 'plaintext'],
        labelDetailsSupport: true,
      },
      contextSupport: true,
    },
    hover: { contentFormat: ['markdown', 'plaintext'] },
    definition: { linkSupport: true },
    references: {},
    documentSymbol: { hierarchicalDocumentSymbolSupport: true },
    rename: { prepareSupport: true },
  },
  workspace: {
    workspaceFolders: true,
    workspaceEdit: { documentChanges: true },
  },
};

/** The language id VS Code gives a file (the extension's package.json). */
const languageOf = (rel) => (rel.endsWith('.rhai') ? 'rhai' : 'ron');

/**
 * `shoal lsp` started in `root` and initialized as VS Code does (rootUri and one workspace
 * folder). The returned session opens, changes and closes documents, sends requests with a
 * deadline, waits for diagnostics, and shuts the server down.
 */
export async function startServer(root) {
  const proc = spawn(shoalBin(), ['lsp'], { cwd: root, stdio: ['pipe', 'pipe', 'pipe'] });
  let stderr = '';
  proc.stderr.on('data', (d) => (stderr += d));
  const exited = new Promise((resolve) => proc.on('exit', (code, signal) => resolve({ code, signal })));
  const connection = createProtocolConnection(
    new StreamMessageReader(proc.stdout),
    new StreamMessageWriter(proc.stdin),
  );
  const published = []; // every publishDiagnostics, in arrival order
  const waiters = [];
  connection.onNotification(PublishDiagnosticsNotification.type, (params) => {
    published.push(params);
    for (const w of waiters.slice()) w();
  });
  connection.listen();

  const session = {
    root,
    proc,
    connection,
    published,
    exited,
    stderr: () => stderr,
    docs: new Map(),

    /** `request` of `type`, answered within the deadline. */
    async request(type, params, what = type.method) {
      return deadline(connection.sendRequest(type, params), `answer to ${what}`).catch((e) => {
        throw new Error(`${e.message}\nserver stderr:\n${stderr}`);
      });
    },

    /** Opens `rel` with its text on disk (or `text`); returns the document. */
    async open(rel, text = fs.readFileSync(path.join(root, rel), 'utf8')) {
      const doc = { rel, uri: uriOf(root, rel), text, version: 1 };
      session.docs.set(rel, doc);
      await connection.sendNotification(DidOpenTextDocumentNotification.type, {
        textDocument: { uri: doc.uri, languageId: languageOf(rel), version: 1, text },
      });
      return doc;
    },

    /** Replaces the whole text of an open document (never saved to disk). */
    async change(doc, text) {
      doc.text = text;
      doc.version += 1;
      await connection.sendNotification(DidChangeTextDocumentNotification.type, {
        textDocument: { uri: doc.uri, version: doc.version },
        contentChanges: [{ text }],
      });
    },

    async close(doc) {
      session.docs.delete(doc.rel);
      await connection.sendNotification(DidCloseTextDocumentNotification.type, {
        textDocument: { uri: doc.uri },
      });
    },

    /**
     * The first publishDiagnostics for `uri` from index `from` of `published` on that satisfies
     * `ok(diagnostics)`, waiting for it up to the deadline.
     */
    async diagnostics(uri, ok = () => true, from = 0, what = 'matching diagnostics') {
      const find = () =>
        published.slice(from).find((p) => pathOf(p.uri) === pathOf(uri) && ok(p.diagnostics));
      let wake;
      const found = new Promise((resolve) => {
        wake = () => {
          const p = find();
          if (p) resolve(p);
        };
        waiters.push(wake);
        wake();
      });
      try {
        return await deadline(found, `publishDiagnostics of ${what} for ${uri}`);
      } catch (e) {
        const seen = published
          .slice(from)
          .filter((p) => pathOf(p.uri) === pathOf(uri))
          .map((p) => JSON.stringify(p.diagnostics));
        throw new Error(`${e.message}; published for it: [${seen.join(', ')}]\nserver stderr:\n${stderr}`);
      } finally {
        waiters.splice(waiters.indexOf(wake), 1);
      }
    },

    /** shutdown, then exit; the server's exit status and signal. */
    async shutdown() {
      await session.request(ShutdownRequest.type, undefined);
      await connection.sendNotification(ExitNotification.type);
      const status = await deadline(exited, 'exit of the server after `exit`');
      connection.dispose();
      return status;
    },

    /** Ends the server however it is (for cleanup after a failure). */
    kill() {
      connection.dispose();
      if (proc.exitCode === null && proc.signalCode === null) proc.kill('SIGKILL');
    },
  };

  const init = await session.request(InitializeRequest.type, {
    processId: process.pid,
    clientInfo: { name: 'shoal-lsp-tests' },
    rootUri: pathToFileURL(root).href,
    rootPath: root,
    workspaceFolders: [{ uri: pathToFileURL(root).href, name: path.basename(root) }],
    capabilities: CLIENT_CAPABILITIES,
  });
  session.capabilities = init.capabilities;
  session.serverInfo = init.serverInfo;
  await connection.sendNotification(InitializedNotification.type, {});
  return session;
}

/**
 * Runs `body(session)` against a server on a fresh copy of the project, then shuts the server
 * down (asserting a clean exit) and removes the copy.
 */
export async function withServer(body) {
  const root = copyProject();
  const session = await startServer(root);
  try {
    await body(session);
    const status = await session.shutdown();
    assert.deepEqual(status, { code: 0, signal: null }, `server exit after shutdown\n${session.stderr()}`);
  } finally {
    session.kill();
    removeProject(root);
  }
}

/** Asserts the server advertises `provider` in its capabilities. */
export function expectCapability(session, provider) {
  const cap = session.capabilities && session.capabilities[provider];
  assert.ok(cap, `the server advertises ${provider}; it advertises ${JSON.stringify(session.capabilities)}`);
  return cap;
}

/** Location | Location[] | LocationLink[] | null → [{ uri, range }] (the target's name range). */
export function locations(answer) {
  if (!answer) return [];
  const list = Array.isArray(answer) ? answer : [answer];
  return list.map((l) =>
    'targetUri' in l ? { uri: l.targetUri, range: l.targetSelectionRange || l.targetRange } : l,
  );
}

/** CompletionItem[] | CompletionList | null → CompletionItem[]. */
export const completionItems = (answer) => (!answer ? [] : Array.isArray(answer) ? answer : answer.items);

/** A completion item's or hover's documentation as text (MarkupContent, string or MarkedString[]). */
export function docText(doc) {
  if (!doc) return '';
  if (typeof doc === 'string') return doc;
  if (Array.isArray(doc)) return doc.map(docText).join('\n');
  return doc.value || '';
}

/** WorkspaceEdit → Map(path → TextEdit[]); file operations (create, rename, delete) are refused. */
export function editsByFile(edit) {
  const byFile = new Map();
  const add = (uri, edits) => {
    const p = pathOf(uri);
    byFile.set(p, (byFile.get(p) || []).concat(edits));
  };
  for (const [uri, edits] of Object.entries(edit.changes || {})) add(uri, edits);
  for (const change of edit.documentChanges || []) {
    assert.ok(change.textDocument, `a text edit, not a file operation: ${JSON.stringify(change)}`);
    add(change.textDocument.uri, change.edits);
  }
  return byFile;
}

/** The byte index in `text` of an LSP position (UTF-16 columns). */
function offsetAt(text, { line, character }) {
  let i = 0;
  for (let l = 0; l < line; l++) {
    i = text.indexOf('\n', i) + 1;
    assert.ok(i > 0, `line ${line} exists`);
  }
  return i + character;
}

/** `text` with `edits` applied (as the protocol says: all ranges refer to the original text). */
export function applyEdits(text, edits) {
  const spans = edits
    .map((e) => ({ from: offsetAt(text, e.range.start), to: offsetAt(text, e.range.end), text: e.newText }))
    .sort((a, b) => b.from - a.from);
  for (let k = 1; k < spans.length; k++) {
    assert.ok(spans[k].to <= spans[k - 1].from, 'edits of one file do not overlap');
  }
  for (const s of spans) text = text.slice(0, s.from) + s.text + text.slice(s.to);
  return text;
}

/** Writes a WorkspaceEdit to the files it names; the paths it changed. */
export function applyWorkspaceEdit(edit) {
  const byFile = editsByFile(edit);
  for (const [file, edits] of byFile) {
    fs.writeFileSync(file, applyEdits(fs.readFileSync(file, 'utf8'), edits));
  }
  return [...byFile.keys()];
}

/** `shoal ARGS…` run in `root`: { status, out } with stdout and stderr together. */
export function runShoal(root, args) {
  const r = spawnSync(shoalBin(), args, { cwd: root, encoding: 'utf8' });
  return { status: r.status, out: `${r.stdout}${r.stderr}` };
}

/** The designers' reference (behaviors/README.md). */
export const reference = () => fs.readFileSync(path.join(REPO, 'behaviors', 'README.md'), 'utf8');

/**
 * The reference table rows of a section: { names, cells } for each row whose first cell starts
 * with a code span (`Wander(…)`, `Flee(…)` / `Arrive(…)`), names being the capitalised names of
 * the first cell's code spans.
 */
export function referenceRows(heading) {
  const text = reference();
  const start = indexOf(text, `\n${heading}\n`);
  const end = text.indexOf('\n## ', start + heading.length + 2);
  return text
    .slice(start, end < 0 ? undefined : end)
    .split('\n')
    .filter((l) => l.startsWith('| `'))
    .map((l) => {
      const cells = l.split(/(?<!\\)\|/).slice(1, -1).map((c) => c.trim());
      const names = [...cells[0].matchAll(/`([A-Z][A-Za-z0-9]*)/g)].map((m) => m[1]);
      return { names, cells };
    });
}

/** The reference's prose for `name` in `heading`'s table (column `col`), up to its first code span. */
export function referenceText(heading, name, col) {
  const row = referenceRows(heading).find((r) => r.names.includes(name));
  assert.ok(row, `${name} is in the reference's "${heading}" table`);
  return row.cells[col].split('`')[0].trim().replace(/[,:;(]$/, '').trim();
}

/** Median and 95th percentile of `xs` (nearest rank). */
export function stats(xs) {
  const s = [...xs].sort((a, b) => a - b);
  const rank = (q) => s[Math.min(s.length - 1, Math.ceil(q * s.length) - 1)];
  return { median: rank(0.5), p95: rank(0.95), n: s.length };
}
