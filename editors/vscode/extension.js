// The Shoal extension: starts `shoal lsp` for the RON and Rhai documents of the workspace and
// hands them to it. Highlighting comes from the grammars in syntaxes/, declared in package.json.
'use strict';

const vscode = require('vscode');
const { LanguageClient, TransportKind } = require('vscode-languageclient/node');

/** @type {LanguageClient | undefined} */
let client;

/** How to start the server: `shoal.path` (a path or a name on PATH), with `lsp`. */
function serverOptions() {
  const configured = vscode.workspace.getConfiguration('shoal').get('path');
  const command = typeof configured === 'string' && configured.trim() ? configured.trim() : 'shoal';
  const folder = vscode.workspace.workspaceFolders && vscode.workspace.workspaceFolders[0];
  // The project's relative paths (scripts, terrain files) resolve from its root, as with
  // `shoal check` run there.
  const options = folder && folder.uri.scheme === 'file' ? { cwd: folder.uri.fsPath } : {};
  return { command, args: ['lsp'], transport: TransportKind.stdio, options };
}

/** What the server is given: saved and unsaved RON and Rhai files, and disk changes to them. */
function clientOptions() {
  return {
    documentSelector: [
      { scheme: 'file', language: 'ron' },
      { scheme: 'file', language: 'rhai' },
    ],
    synchronize: {
      // A species, script or test edited elsewhere (git, another editor) changes the names the
      // open documents may use.
      fileEvents: vscode.workspace.createFileSystemWatcher('**/*.{ron,rhai}'),
    },
  };
}

async function start(context) {
  // The client id `shoal` makes the `shoal.trace.server` setting trace this client.
  client = new LanguageClient('shoal', 'Shoal', serverOptions(), clientOptions());
  try {
    await client.start();
  } catch (err) {
    const command = serverOptions().command;
    vscode.window.showErrorMessage(
      `Shoal: could not start \`${command} lsp\` (${err && err.message ? err.message : err}). ` +
        'Set "shoal.path" to the shoal program.',
    );
  }
  context.subscriptions.push({ dispose: () => client && client.stop() });
}

async function restart(context) {
  if (client) {
    const old = client;
    client = undefined;
    await old.stop().catch(() => {});
  }
  await start(context);
}

/** Called by VS Code when a RON or Rhai document opens. */
async function activate(context) {
  context.subscriptions.push(
    vscode.commands.registerCommand('shoal.restartServer', () => restart(context)),
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration('shoal.path')) restart(context);
    }),
  );
  await start(context);
}

/** Called by VS Code on shutdown: stop the server cleanly (shutdown, then exit). */
function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate, serverOptions, clientOptions };
