// extension.js against stand-ins for the `vscode` module and the language client: which program
// it starts, with which arguments, for which documents, and that a changed `shoal.path` restarts
// the server with the new program.
'use strict';

const test = require('node:test');
const assert = require('node:assert/strict');
const Module = require('node:module');

const state = { config: {}, clients: [], configListeners: [], errors: [] };

class FakeClient {
  constructor(id, name, server, client) {
    Object.assign(this, { id, name, server, client, started: false, stopped: false });
    state.clients.push(this);
  }
  async start() {
    if (state.failStart) throw new Error('spawn ENOENT');
    this.started = true;
  }
  async stop() {
    this.stopped = true;
  }
}

const fakeVscode = {
  workspace: {
    getConfiguration: (section) => ({ get: (key) => state.config[`${section}.${key}`] }),
    workspaceFolders: [{ uri: { scheme: 'file', fsPath: '/home/designer/reef' } }],
    createFileSystemWatcher: (glob) => ({ glob }),
    onDidChangeConfiguration: (f) => {
      state.configListeners.push(f);
      return { dispose() {} };
    },
  },
  commands: { registerCommand: (name, f) => ({ name, f, dispose() {} }) },
  window: { showErrorMessage: (m) => state.errors.push(m) },
};
const fakeClientModule = { LanguageClient: FakeClient, TransportKind: { stdio: 0 } };

const load = Module._load;
Module._load = function (request, ...rest) {
  if (request === 'vscode') return fakeVscode;
  if (request === 'vscode-languageclient/node') return fakeClientModule;
  return load.call(this, request, ...rest);
};
const extension = require('../extension.js');
Module._load = load;

test('starts `shoal lsp` for RON and Rhai files, from the workspace root', async () => {
  const context = { subscriptions: [] };
  await extension.activate(context);
  assert.equal(state.clients.length, 1);
  const c = state.clients[0];
  assert.equal(c.id, 'shoal', 'the id that `shoal.trace.server` traces');
  assert.deepEqual(c.server, {
    command: 'shoal',
    args: ['lsp'],
    transport: 0,
    options: { cwd: '/home/designer/reef' },
  });
  assert.deepEqual(c.client.documentSelector, [
    { scheme: 'file', language: 'ron' },
    { scheme: 'file', language: 'rhai' },
  ]);
  assert.equal(c.client.synchronize.fileEvents.glob, '**/*.{ron,rhai}');
  assert.ok(c.started);
  assert.ok(context.subscriptions.some((s) => s.name === 'shoal.restartServer'));
});

test('a changed `shoal.path` restarts the server with that program', async () => {
  state.config['shoal.path'] = ' /opt/shoal/bin/shoal ';
  for (const f of state.configListeners) f({ affectsConfiguration: (s) => s === 'shoal.path' });
  await new Promise((r) => setTimeout(r, 10));
  const [old, now] = state.clients;
  assert.ok(old.stopped, 'the old server is stopped');
  assert.equal(now.server.command, '/opt/shoal/bin/shoal');
  assert.ok(now.started);
  // Other settings leave the server alone.
  for (const f of state.configListeners) f({ affectsConfiguration: () => false });
  await new Promise((r) => setTimeout(r, 10));
  assert.equal(state.clients.length, 2);
});

test('a program that does not start is reported with the setting to fix', async () => {
  state.failStart = true;
  state.config['shoal.path'] = '/nowhere/shoal';
  for (const f of state.configListeners) f({ affectsConfiguration: (s) => s === 'shoal.path' });
  await new Promise((r) => setTimeout(r, 10));
  assert.equal(state.errors.length, 1);
  assert.match(state.errors[0], /\/nowhere\/shoal lsp.*spawn ENOENT.*"shoal\.path"/);
  state.failStart = false;
  await extension.deactivate();
  assert.ok(state.clients.at(-1).stopped);
});
