// The protocol's life cycle: initialize → capabilities, initialized, shutdown, exit with status 0;
// and a server whose editor goes away (stdin closed) ends by itself.

import assert from 'node:assert/strict';
import test from 'node:test';
import { copyProject, deadline, removeProject, startServer } from './client.mjs';

test('initialize, then shutdown and exit with status 0', async () => {
  const root = copyProject();
  const s = await startServer(root);
  try {
    const sync = s.capabilities.textDocumentSync;
    // Full (1) or incremental (2) sync; a client may then send whole texts either way.
    const kind = typeof sync === 'object' ? sync.change : sync;
    assert.ok(kind === 1 || kind === 2, `textDocumentSync: ${JSON.stringify(sync)}`);
    if (typeof sync === 'object') assert.equal(sync.openClose, true, 'the server wants open/close');
    assert.deepEqual(await s.shutdown(), { code: 0, signal: null }, s.stderr());
  } finally {
    s.kill();
    removeProject(root);
  }
});

test('the server ends when its editor goes away', async () => {
  const root = copyProject();
  const s = await startServer(root);
  try {
    s.proc.stdin.end();
    const status = await deadline(s.exited, 'exit after stdin closed', 5000);
    assert.equal(status.signal, null, `ended by itself, not killed: ${JSON.stringify(status)}`);
  } finally {
    s.kill();
    removeProject(root);
  }
});
