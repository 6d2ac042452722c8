//! The protocol side of `shoal lsp`: the stdio connection, the initialize handshake and the
//! message loop. Requests are answered in arrival order on one thread; nothing here runs a
//! scenario.

use lsp_server::{Connection, Message};
use lsp_types::{
    InitializeParams, ServerCapabilities, TextDocumentSyncCapability, TextDocumentSyncKind,
};

/// Serves the Language Server Protocol on stdin/stdout until the client says `exit`.
pub fn serve_stdio() -> anyhow::Result<()> {
    let (connection, io_threads) = Connection::stdio();
    let caps = ServerCapabilities {
        text_document_sync: Some(TextDocumentSyncCapability::Kind(TextDocumentSyncKind::FULL)),
        ..Default::default()
    };
    let init = connection.initialize(serde_json::to_value(caps)?)?;
    let _params: InitializeParams = serde_json::from_value(init)?;
    for msg in &connection.receiver {
        if let Message::Request(req) = msg {
            if connection.handle_shutdown(&req)? {
                break;
            }
        }
    }
    drop(connection);
    io_threads.join()?;
    Ok(())
}
