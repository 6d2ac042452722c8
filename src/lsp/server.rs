//! The protocol side of `shoal lsp`: the stdio connection, the initialize handshake, and the
//! dispatcher that hands each request and notification to the module of its concept (documents,
//! diagnostics, symbols, navigation, rename, and the formats' vocabulary in `assist`). Requests
//! are answered in arrival order on one thread; nothing here runs a scenario. A bad request gets
//! an error response, a handler that fails unexpectedly an internal error: the server never stops
//! on what a client sends.

use super::assist::{self, FileKind, ItemKind};
use super::diagnostics::Analysis;
use super::docs::{offset, path_to_uri, range, uri_to_path, Documents, LineIndex};
use super::index::{index, project_files, Index};
use super::{navigate, rename, symbols};
use crate::load::overlay::normalize;
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, RequestId, Response};
use lsp_types::*;
use serde_json::Value;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

/// Serves the Language Server Protocol on stdin/stdout until the client says `exit`; returns
/// the process's exit code (1 when `exit` came without `shutdown`, or the client went away).
pub fn serve_stdio() -> anyhow::Result<i32> {
    let (connection, io_threads) = Connection::stdio();
    let code = serve(&connection);
    drop(connection);
    // The reader stops after `exit`; when the client vanished instead, it has stopped too.
    let _ = io_threads.join();
    Ok(code)
}

/// What the server offers.
fn capabilities() -> ServerCapabilities {
    ServerCapabilities {
        text_document_sync: Some(TextDocumentSyncCapability::Kind(TextDocumentSyncKind::FULL)),
        document_symbol_provider: Some(OneOf::Left(true)),
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        rename_provider: Some(OneOf::Right(RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: Default::default(),
        })),
        completion_provider: Some(CompletionOptions {
            trigger_characters: Some(vec![".".into(), ":".into(), "\"".into(), "(".into()]),
            ..Default::default()
        }),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        ..Default::default()
    }
}

/// Runs the session on `conn`; returns the exit code.
pub fn serve(conn: &Connection) -> i32 {
    let mut s = Server {
        conn,
        root: None,
        loaded: false,
        docs: Documents::default(),
        index: Index::new(),
        analysis: Analysis::default(),
        engine: crate::script::new_engine(&crate::scenario::script_limits()),
        mtimes: BTreeMap::new(),
    };
    // Before `initialize`: requests are refused, `exit` ends the session.
    loop {
        match conn.receiver.recv() {
            Err(_) => return 1,
            Ok(Message::Request(req)) if req.method == "initialize" => {
                match serde_json::from_value::<InitializeParams>(req.params.clone()) {
                    Ok(_) => {
                        s.root = root_of(&req.params);
                        let result = InitializeResult {
                            capabilities: capabilities(),
                            server_info: Some(ServerInfo {
                                name: "shoal".into(),
                                version: Some(env!("CARGO_PKG_VERSION").into()),
                            }),
                        };
                        s.ok(req.id, result);
                        break;
                    }
                    Err(e) => s.err(req.id, ErrorCode::InvalidParams, e.to_string()),
                }
            }
            Ok(Message::Request(req)) => s.err(
                req.id,
                ErrorCode::ServerNotInitialized,
                "the server is not initialized: send `initialize` first".into(),
            ),
            Ok(Message::Notification(n)) if n.method == "exit" => return 1,
            Ok(_) => {}
        }
    }
    let mut shut = false;
    loop {
        match conn.receiver.recv() {
            Err(_) => return 1,
            Ok(Message::Request(req)) => {
                if shut {
                    s.err(
                        req.id,
                        ErrorCode::InvalidRequest,
                        "the server is shut down".into(),
                    );
                } else if req.method == "shutdown" {
                    shut = true;
                    s.ok(req.id, Value::Null);
                } else {
                    let id = req.id.clone();
                    let r =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| s.request(req)));
                    if r.is_err() {
                        s.err(id, ErrorCode::InternalError, "internal error".into());
                    }
                }
            }
            Ok(Message::Notification(n)) if n.method == "exit" => return i32::from(!shut),
            Ok(Message::Notification(n)) => {
                if !shut {
                    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| s.notify(n)));
                }
            }
            Ok(Message::Response(_)) => {}
        }
    }
}

/// The project folder the client names: the first workspace folder, else `rootUri`, else
/// `rootPath`.
fn root_of(params: &Value) -> Option<PathBuf> {
    let uri = params["workspaceFolders"][0]["uri"]
        .as_str()
        .or_else(|| params["rootUri"].as_str());
    if let Some(p) = uri
        .and_then(|u| u.parse::<Uri>().ok())
        .and_then(|u| uri_to_path(&u))
    {
        return Some(p);
    }
    params["rootPath"].as_str().map(|p| normalize(Path::new(p)))
}

struct Server<'c> {
    conn: &'c Connection,
    root: Option<PathBuf>,
    loaded: bool,
    docs: Documents,
    index: Index,
    analysis: Analysis,
    /// Compiles scripts and tests for the index's behavior names.
    engine: rhai::Engine,
    /// When each indexed file that is not open was last read from disk.
    mtimes: BTreeMap<PathBuf, Option<SystemTime>>,
}

fn mtime(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

/// A request's failure: its error code and message.
type Fail = (ErrorCode, String);

fn params<P: serde::de::DeserializeOwned>(req: &Request) -> Result<P, Fail> {
    serde_json::from_value(req.params.clone())
        .map_err(|e| (ErrorCode::InvalidParams, e.to_string()))
}

fn json<T: serde::Serialize>(v: T) -> Result<Value, Fail> {
    serde_json::to_value(v).map_err(|e| (ErrorCode::InternalError, e.to_string()))
}

fn file_of(uri: &Uri) -> Result<PathBuf, Fail> {
    uri_to_path(uri).ok_or_else(|| {
        (
            ErrorCode::InvalidParams,
            format!("not a file URI: {}", uri.as_str()),
        )
    })
}

impl Server<'_> {
    fn send(&self, m: Message) {
        // A client that went away is noticed by the reader.
        let _ = self.conn.sender.send(m);
    }

    fn ok(&self, id: RequestId, v: impl serde::Serialize) {
        let v = serde_json::to_value(v).unwrap_or(Value::Null);
        self.send(Response::new_ok(id, v).into());
    }

    fn err(&self, id: RequestId, code: ErrorCode, msg: String) {
        self.send(Response::new_err(id, code as i32, msg).into());
    }

    /// The project root: the client's, else the nearest folder above `file` holding
    /// `behaviors/`. Once known, every file of the project is indexed and checked.
    fn ensure_loaded(&mut self, file: Option<&Path>) {
        let has_behaviors = |p: &Path| p.join("behaviors").is_dir();
        if !self.root.as_deref().is_some_and(has_behaviors) {
            if let Some(found) = file.and_then(|f| f.ancestors().skip(1).find(|a| has_behaviors(a)))
            {
                self.root = Some(found.to_path_buf());
                self.loaded = false;
            }
        }
        if self.loaded {
            return;
        }
        let Some(root) = self.root.clone() else {
            return;
        };
        self.loaded = true;
        let files = project_files(&root);
        for f in &files {
            self.reindex(&normalize(f));
        }
        self.analysis.load_all(&files, &self.docs);
        self.publish(None);
    }

    fn reindex(&mut self, path: &Path) {
        if !self.docs.open.contains_key(path) {
            self.mtimes.insert(path.to_path_buf(), mtime(path));
        }
        match self.docs.text(path) {
            Some(t) => {
                let f = index(path, &t, &self.engine);
                self.index.insert(path.to_path_buf(), f);
            }
            None => {
                self.index.remove(path);
            }
        }
    }

    fn publish(&mut self, edited: Option<&Path>) {
        for (p, diagnostics) in self.analysis.publish(&self.docs, edited) {
            let Some(uri) = path_to_uri(&p) else { continue };
            let params = PublishDiagnosticsParams {
                uri,
                diagnostics,
                version: None,
            };
            let n = Notification::new("textDocument/publishDiagnostics".into(), params);
            self.send(n.into());
        }
    }

    /// After `path`'s text changed (or it was opened or closed): its index entry, the checks
    /// that read it, and the diagnostics that changed.
    fn changed(&mut self, path: &Path) {
        self.ensure_loaded(Some(path));
        self.reindex(path);
        self.analysis.changed(path, &self.docs);
        self.publish(Some(path));
    }

    fn notify(&mut self, n: Notification) {
        let path = |uri: &Uri| uri_to_path(uri);
        match n.method.as_str() {
            "initialized" => self.ensure_loaded(None),
            "textDocument/didOpen" => {
                let Ok(p) = serde_json::from_value::<DidOpenTextDocumentParams>(n.params) else {
                    return;
                };
                if let Some(f) = path(&p.text_document.uri) {
                    self.docs
                        .open
                        .insert(f.clone(), Arc::from(p.text_document.text));
                    self.changed(&f);
                }
            }
            "textDocument/didChange" => {
                let Ok(p) = serde_json::from_value::<DidChangeTextDocumentParams>(n.params) else {
                    return;
                };
                let (Some(f), Some(c)) = (
                    path(&p.text_document.uri),
                    p.content_changes.into_iter().last(),
                ) else {
                    return;
                };
                // Full sync: the last change holds the whole text.
                self.docs.open.insert(f.clone(), Arc::from(c.text));
                self.changed(&f);
            }
            "textDocument/didSave" => {
                let Ok(p) = serde_json::from_value::<DidSaveTextDocumentParams>(n.params) else {
                    return;
                };
                if let (Some(f), Some(t)) = (path(&p.text_document.uri), p.text) {
                    self.docs.open.insert(f.clone(), Arc::from(t));
                    self.changed(&f);
                }
            }
            "textDocument/didClose" => {
                let Ok(p) = serde_json::from_value::<DidCloseTextDocumentParams>(n.params) else {
                    return;
                };
                if let Some(f) = path(&p.text_document.uri) {
                    if self.docs.open.remove(&f).is_some() {
                        self.changed(&f);
                    }
                }
            }
            "workspace/didChangeWatchedFiles" => {
                let Ok(p) = serde_json::from_value::<DidChangeWatchedFilesParams>(n.params) else {
                    return;
                };
                for c in p.changes {
                    if let Some(f) = path(&c.uri) {
                        if !self.docs.open.contains_key(&f) {
                            self.changed(&f);
                        }
                    }
                }
            }
            _ => {}
        }
    }

    fn request(&mut self, req: Request) {
        let id = req.id.clone();
        let r = match req.method.as_str() {
            "textDocument/documentSymbol" => self.symbols(&req),
            "textDocument/definition" => self.definition(&req),
            "textDocument/references" => self.references(&req),
            "textDocument/prepareRename" => self.prepare_rename(&req),
            "textDocument/rename" => self.rename(&req),
            "textDocument/completion" => self.completion(&req),
            "textDocument/hover" => self.hover(&req),
            m => Err((ErrorCode::MethodNotFound, format!("unknown method `{m}`"))),
        };
        match r {
            Ok(v) => self.ok(id, v),
            Err((code, msg)) => self.err(id, code, msg),
        }
    }

    /// Files changed on disk behind the server's back (a rename's edits applied to closed
    /// files, a checkout): re-read, re-checked.
    fn refresh(&mut self) {
        let stale: Vec<PathBuf> = self
            .mtimes
            .iter()
            .filter(|(p, t)| !self.docs.open.contains_key(*p) && mtime(p) != **t)
            .map(|(p, _)| p.clone())
            .collect();
        for p in stale {
            self.changed(&p);
        }
    }

    /// The file, text and byte offset of a position in a request.
    fn at(&mut self, pos: &TextDocumentPositionParams) -> Result<(PathBuf, Arc<str>, usize), Fail> {
        let f = file_of(&pos.text_document.uri)?;
        self.ensure_loaded(Some(&f));
        self.refresh();
        let text = self.docs.text(&f).unwrap_or_else(|| Arc::from(""));
        if !self.index.contains_key(&f) && !text.is_empty() {
            self.reindex(&f);
        }
        let at = offset(&text, pos.position);
        Ok((f, text, at))
    }

    fn location(&self, file: &Path, span: (usize, usize)) -> Option<Location> {
        let text = self.docs.text(file).unwrap_or_else(|| Arc::from(""));
        Some(Location {
            uri: path_to_uri(file)?,
            range: range(&text, span),
        })
    }

    fn symbols(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: DocumentSymbolParams = params(req)?;
        let f = file_of(&p.text_document.uri)?;
        self.ensure_loaded(Some(&f));
        let Some(text) = self.docs.text(&f) else {
            return json(Vec::<DocumentSymbol>::new());
        };
        if !self.index.contains_key(&f) {
            self.reindex(&f);
        }
        let outline = self
            .index
            .get(&f)
            .map(|x| symbols::outline(x, &text))
            .unwrap_or_default();
        json(DocumentSymbolResponse::Nested(outline))
    }

    fn definition(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: GotoDefinitionParams = params(req)?;
        let (f, text, at) = self.at(&p.text_document_position_params)?;
        let found = navigate::target_at(&self.index, &f, &text, at)
            .and_then(|(t, _)| navigate::definition(&self.index, &t))
            .and_then(|(file, span)| self.location(&file, span));
        json(found.map(GotoDefinitionResponse::Scalar))
    }

    fn references(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: ReferenceParams = params(req)?;
        let (f, text, at) = self.at(&p.text_document_position)?;
        let Some((t, _)) = navigate::target_at(&self.index, &f, &text, at) else {
            return json(Value::Null);
        };
        // One line index per file: a file may hold many references.
        let mut texts: HashMap<PathBuf, Arc<str>> = HashMap::new();
        let found = navigate::references(&self.index, &t, p.context.include_declaration);
        for (file, _) in &found {
            texts
                .entry(file.clone())
                .or_insert_with(|| self.docs.text(file).unwrap_or_else(|| Arc::from("")));
        }
        let lines: HashMap<&PathBuf, LineIndex> =
            texts.iter().map(|(p, t)| (p, LineIndex::new(t))).collect();
        let locs: Vec<Location> = found
            .iter()
            .filter_map(|(file, span)| {
                Some(Location {
                    uri: path_to_uri(file)?,
                    range: lines.get(file)?.range(*span),
                })
            })
            .collect();
        json(locs)
    }

    fn prepare_rename(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: TextDocumentPositionParams = params(req)?;
        let (f, text, at) = self.at(&p)?;
        match rename::prepare(&self.index, &f, &text, at) {
            Ok((_, span)) => json(PrepareRenameResponse::Range(range(&text, span))),
            Err(why) => Err((ErrorCode::RequestFailed, why)),
        }
    }

    // The protocol's `WorkspaceEdit` keys its changes by `Uri`, which clippy deems mutable.
    #[allow(clippy::mutable_key_type)]
    fn rename(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: RenameParams = params(req)?;
        let (f, text, at) = self.at(&p.text_document_position)?;
        let edits = rename::rename(&self.index, &f, &text, at, &p.new_name)
            .map_err(|why| (ErrorCode::RequestFailed, why))?;
        let mut changes: HashMap<Uri, Vec<TextEdit>> = HashMap::new();
        for (file, spans) in edits {
            let Some(uri) = path_to_uri(&file) else {
                continue;
            };
            let t = self.docs.text(&file).unwrap_or_else(|| Arc::from(""));
            let lines = LineIndex::new(&t);
            let list = spans
                .into_iter()
                .map(|s| TextEdit::new(lines.range(s), p.new_name.clone()))
                .collect();
            changes.insert(uri, list);
        }
        json(WorkspaceEdit::new(changes))
    }

    fn completion(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: CompletionParams = params(req)?;
        let (f, text, at) = self.at(&p.text_document_position)?;
        let kind = FileKind::of(&f, &text);
        let names = symbols::names(&self.index, &f, self.index.get(&f));
        let items: Vec<CompletionItem> = assist::complete(kind, &text, at, &names)
            .into_iter()
            .map(|i| CompletionItem {
                label: i.label,
                kind: Some(item_kind(i.kind)),
                detail: (!i.detail.is_empty()).then_some(i.detail),
                documentation: (!i.doc.is_empty()).then_some(Documentation::MarkupContent(
                    MarkupContent {
                        kind: MarkupKind::Markdown,
                        value: i.doc,
                    },
                )),
                insert_text: i.insert,
                ..Default::default()
            })
            .collect();
        json(CompletionResponse::Array(items))
    }

    fn hover(&mut self, req: &Request) -> Result<Value, Fail> {
        let p: HoverParams = params(req)?;
        let (f, text, at) = self.at(&p.text_document_position_params)?;
        let kind = FileKind::of(&f, &text);
        let h = assist::hover(kind, &text, at).map(|h| Hover {
            contents: HoverContents::Markup(MarkupContent {
                kind: MarkupKind::Markdown,
                value: h.markdown,
            }),
            range: Some(range(&text, (h.start, h.end))),
        });
        json(h)
    }
}

fn item_kind(k: ItemKind) -> CompletionItemKind {
    match k {
        ItemKind::Key => CompletionItemKind::FIELD,
        ItemKind::Variant => CompletionItemKind::ENUM_MEMBER,
        ItemKind::Function => CompletionItemKind::FUNCTION,
        ItemKind::Behavior => CompletionItemKind::CLASS,
        ItemKind::Species => CompletionItemKind::STRUCT,
        ItemKind::Module => CompletionItemKind::MODULE,
        ItemKind::Constant => CompletionItemKind::CONSTANT,
    }
}
