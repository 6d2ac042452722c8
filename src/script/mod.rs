//! Part of stage 4 (decision): the Rhai script host.
//!
//! One [`Script`] per species file, compiled once per (re)load with the imports it names compiled
//! as static modules, each module once per load (`imports`), and every call it makes checked
//! against what exists ([`calls`]); a worker thread that calls it often gets a replica of its
//! own, compiled from the same texts (`Script::local`: threads sharing one engine contend).
//! Scripts run sandboxed: no file, network, environment or
//! clock access, and limits on operations per call (a `loop {}` is stopped), call depth, string,
//! array and map sizes. Calls bind the agent's typed [`AgentView`] as `this`; nothing is looked
//! up by string in the hot path, and calls happen only at the species' decision rate or on
//! events.
//!
//! Determinism: the operation limit is the deterministic bound of a call; the wall-time budgets
//! of [`budget`] are a guard only. A call that runs past one is aborted with an error naming the
//! script, the function and the agent; the run reports it like any other script error and
//! counts it apart, so a result that depends on the machine's speed is never passed off as a
//! normal one.
//!
//! In the core's layers (`tests/layers.rs`) the host sits below the species, which holds a
//! compiled script, and above perception and the world, which the agent view reads: it imports
//! nothing of the stages that call it.

pub mod brackets;
pub mod budget;
pub mod calls;
pub mod events;
mod imports;
pub mod math;
pub mod memory;
pub mod names;
pub mod native;
pub mod squad;
pub mod steps;
mod view;

pub use budget::{with_tick, Exceeded, TickClock, TimeBudget};
pub use view::{from_mem, register_api, to_mem, AgentView, CategoryView, ScriptSteer, SteerTerm};

use crate::diag::{Diagnostic, Diagnostics};
use rhai::packages::{
    ArithmeticPackage, BasicArrayPackage, BasicBlobPackage, BasicFnPackage, BasicIteratorPackage,
    BasicMapPackage, BasicMathPackage, BasicStringPackage, BitFieldPackage, LogicPackage,
    MoreStringPackage, Package,
};
use rhai::{CallFnOptions, Dynamic, Engine, EvalAltResult, Position, Scope, AST};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

/// Safety limits applied to every script call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SandboxLimits {
    /// Operations per call; a call that exceeds it is stopped.
    pub max_operations: u64,
    /// Call depth.
    pub max_call_levels: usize,
    /// Longest string.
    pub max_string_size: usize,
    /// Largest array.
    pub max_array_size: usize,
    /// Largest map.
    pub max_map_size: usize,
}

impl Default for SandboxLimits {
    fn default() -> Self {
        SandboxLimits {
            max_operations: 200_000,
            max_call_levels: 32,
            max_string_size: 4096,
            max_array_size: 4096,
            max_map_size: 256,
        }
    }
}

/// A compiled species script with its own engine (which holds the imported modules).
pub struct Script {
    engine: Engine,
    ast: AST,
    /// The script file.
    pub file: PathBuf,
    /// Its text (for locating diagnostics).
    pub text: Arc<str>,
    /// Every file it imports, directly or not.
    pub imports: Vec<PathBuf>,
    /// Functions it defines, with their parameter count.
    pub functions: Vec<(String, usize)>,
    /// Its functions that are evaluated natively ([`native`]), by name.
    natives: Vec<(String, native::Native)>,
    /// The modules its engine holds, by alias (what native evaluation may call into).
    modules: Vec<(String, rhai::Shared<rhai::Module>)>,
    /// Its `on_tick()` compiled for native evaluation ([`steps`]), once the blackboard is
    /// declared.
    on_tick: Option<steps::Steps>,
    /// Whether it or a file it imports names a category's mean heading ([`names_heading`]).
    reads_heading: bool,
    /// The behaviors folder it was compiled against.
    root: PathBuf,
    /// Its sandbox limits.
    limits: SandboxLimits,
    /// What compiling it read of its imports (replicas are compiled from it).
    sources: imports::Sources,
    /// Its blackboard declaration, once bound ([`Script::declare_memory`]).
    memory: Option<Arc<memory::MemorySpec>>,
    /// Per worker thread, its own engine and compiled script ([`Script::local`]).
    replicas: Box<[Slot]>,
}

/// A worker thread's calls of a script and, past [`REPLICATE_AFTER`], its replica (a cache line
/// of its own: each thread writes only its slot).
#[derive(Default)]
#[repr(align(64))]
struct Slot {
    calls: AtomicU32,
    replica: OnceLock<Option<Box<Replica>>>,
}

/// Calls a worker thread makes on the shared engine before it compiles a replica of its own.
const REPLICATE_AFTER: u32 = 512;

/// Worker threads past the first that get a replica of a script ([`Script::local`]); more run
/// on the shared one.
const MAX_REPLICAS: usize = 63;

/// An engine and compiled script of a worker thread's own.
struct Replica {
    engine: Engine,
    ast: AST,
}

/// Compiles `text` (the script `file`) on a new engine with its imports from `loader`.
fn build(
    file: &Path,
    text: &str,
    loader: &mut imports::Loader,
) -> Result<(Engine, AST, calls::Known), Diagnostics> {
    let mut engine = new_engine(loader.limits());
    let known = loader.register(&mut engine, file, text);
    // Imported functions run on this engine too.
    if !exact_power(&mut engine, text) && loader.power {
        engine.set_fast_operators(false);
    }
    let mut diags = std::mem::take(&mut loader.diags);
    let mut ast = match engine.compile(text) {
        Ok(a) => a,
        Err(e) => {
            diags.push(parse_diag(file, text, &e));
            return Err(Diagnostics(diags));
        }
    };
    ast.set_source(file.display().to_string());
    // Calls into modules that did not load would only repeat the import errors; a replayed
    // load (a replica) was checked when it was first compiled.
    if diags.is_empty() && !loader.replaying() {
        diags.extend(calls::check(&ast, &known, file, text));
    }
    if !diags.is_empty() {
        return Err(Diagnostics(diags));
    }
    Ok((engine, ast, known))
}

impl std::fmt::Debug for Script {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Script")
            .field("file", &self.file)
            .field("functions", &self.functions)
            .finish()
    }
}

/// A failed call, located in the script.
#[derive(Debug, Clone, PartialEq)]
pub struct CallError {
    /// `file:line:col: message` (boxed: errors are rare, and a small `Result` keeps every
    /// successful call cheap).
    pub diagnostic: Box<Diagnostic>,
    /// The wall-time budget the call ran past, when that is why it failed.
    pub time_budget: Option<Exceeded>,
}

/// The budget a failed call ran past, when that is why it failed.
fn exceeded(e: &EvalAltResult) -> Option<Exceeded> {
    match e {
        EvalAltResult::ErrorTerminated(token, _) => budget::exceeded_of(token),
        EvalAltResult::ErrorInFunctionCall(_, _, inner, _)
        | EvalAltResult::ErrorInModule(_, inner, _) => exceeded(inner),
        _ => None,
    }
}

fn time_message(name: &str, agent: &str, over: Exceeded) -> String {
    match over {
        Exceeded::Call(d) => format!(
            "`{name}()`{agent} ran longer than the {} ms a script call may take, and was stopped; the run's results now depend on the machine's speed (make the function do less, or raise the budget)",
            d.as_millis()
        ),
        Exceeded::Tick(d) => format!(
            "`{name}()`{agent} was stopped: the tick's script calls took more than {} ms together; the run's results now depend on the machine's speed (make the scripts do less, or raise the budget)",
            d.as_millis()
        ),
    }
}

/// A fresh sandboxed engine with the shoal API registered.
///
/// Rhai's standard packages except the two that reach outside the script: `BasicTimePackage`
/// (`timestamp`, `elapsed`) and `LanguageCorePackage` (`sleep`, `exit`, and reflection that
/// scripts have no use for). See [`calls::DENIED`].
pub fn new_engine(limits: &SandboxLimits) -> Engine {
    let mut e = Engine::new_raw();
    e.set_max_strings_interned(256);
    for p in [
        ArithmeticPackage::new().as_shared_module(),
        BasicStringPackage::new().as_shared_module(),
        BasicIteratorPackage::new().as_shared_module(),
        BasicFnPackage::new().as_shared_module(),
        BitFieldPackage::new().as_shared_module(),
        LogicPackage::new().as_shared_module(),
        BasicMathPackage::new().as_shared_module(),
        BasicArrayPackage::new().as_shared_module(),
        BasicBlobPackage::new().as_shared_module(),
        BasicMapPackage::new().as_shared_module(),
        MoreStringPackage::new().as_shared_module(),
    ] {
        e.register_global_module(p);
    }
    e.set_max_operations(limits.max_operations);
    e.set_max_call_levels(limits.max_call_levels);
    e.set_max_string_size(limits.max_string_size);
    e.set_max_array_size(limits.max_array_size);
    e.set_max_map_size(limits.max_map_size);
    e.set_max_expr_depths(64, 32);
    e.set_max_modules(64);
    e.set_strict_variables(true);
    // `eval` would compile text at run time, past every load-time check (calls, imports).
    e.disable_symbol("eval");
    // Scripts write nothing to the terminal by themselves.
    e.on_print(|_| {});
    e.on_debug(|_, _, _| {});
    // Imports are resolved by the host (static modules); nothing loads files at run time.
    e.set_module_resolver(rhai::module_resolvers::DummyModuleResolver::new());
    // The wall-time guard (not a deterministic bound: see the module header).
    e.on_progress(|ops| budget::check(ops).map(budget::token));
    register_api(&mut e);
    math::register(&mut e);
    e
}

/// Whether `text` names a category's mean heading (the `mean_heading` property). Only a
/// script that names it can read it (`eval` is off and a property is read by its name), so
/// perception keeps the mean headings only for species whose scripts do (12 bytes a summary).
/// A comment naming it counts too: the test errs on keeping.
pub fn names_heading(text: &str) -> bool {
    text.contains("mean_heading")
}

/// Readies `engine` for compiling and running `text`: where the text raises a number to a
/// power (`**`, `**=`), Rhai's fast paths for operators are turned off. Rhai computes `**` on
/// numbers by a built-in path with the platform's `powf` (and folds constant ones at compile
/// time with it), which no registration reaches; without the fast paths it looks for a
/// registered operator first, `math::register`'s, and falls back to the built-in ones for the
/// others. That lookup makes arithmetic about twice as slow, so only scripts that use the
/// operator pay for it. Call it before compiling, on every engine that runs the text's
/// functions. Returns whether the text raises to a power.
pub fn exact_power(engine: &mut Engine, text: &str) -> bool {
    let inputs = [text];
    // Rhai's token stream does not end: it repeats `EOF`. After the `}` of a `${…}` in a
    // template string only the parser knows the string goes on, so past one the tokens may be
    // wrong: a text with one falls back to looking for `**` in its characters (a `**` in a
    // comment or a string then slows it needlessly, never the other way round).
    let mut template = false;
    let power = engine
        .lex(&inputs)
        .0
        .take_while(|(t, _)| *t != rhai::Token::EOF)
        .any(|(t, _)| {
            template |= matches!(t, rhai::Token::InterpolatedString(_));
            matches!(t, rhai::Token::PowerOf | rhai::Token::PowerOfAssign)
        })
        || (template && text.contains("**"));
    if power {
        engine.set_fast_operators(false);
    }
    power
}

/// Largest script, module, test or reduction file, in bytes. Rhai's optimizer takes a block's
/// do-nothing statements out one at a time, so a block of many (`();();…`) costs time quadratic
/// in their number: 190 KB of them took 0.7 s to load, a megabyte would take about 20 s.
/// Designers' scripts are a few kilobytes; a bigger one can be split into modules.
pub const MAX_SCRIPT_BYTES: usize = 256 * 1024;

/// Refuses a `what` (script, module, …) file of more than [`MAX_SCRIPT_BYTES`].
pub fn check_size(file: &Path, text: &str, what: &str) -> Result<(), Diagnostic> {
    if text.len() <= MAX_SCRIPT_BYTES {
        return Ok(());
    }
    Err(Diagnostic::file(
        file,
        format!(
            "{what} of {} KiB: at most {} KiB (split it into modules)",
            text.len().div_ceil(1024),
            MAX_SCRIPT_BYTES / 1024
        ),
    ))
}

pub(crate) fn parse_diag(file: &Path, text: &str, err: &rhai::ParseError) -> Diagnostic {
    let (line, col) = position_of(err.1);
    let mut message = err.0.to_string();
    // Rhai points where parsing failed; the bracket left open may be far above.
    message.push_str(&brackets::note(text, line, col).unwrap_or_default());
    Diagnostic::new(file, line, col, message, Some(text))
}

impl Script {
    /// Compiles the script at `file`; imports are resolved relative to `root` (the behaviors
    /// folder), then relative to the script's own folder, with the `.rhai` extension added.
    pub fn load(file: &Path, root: &Path, limits: &SandboxLimits) -> Result<Script, Diagnostics> {
        let text = crate::diag::read_text(file, "script")?;
        Self::compile(file, &text, root, limits)
    }

    /// Compiles script `text` (named `file` in diagnostics).
    pub fn compile(
        file: &Path,
        text: &str,
        root: &Path,
        limits: &SandboxLimits,
    ) -> Result<Script, Diagnostics> {
        check_size(file, text, "script")?;
        let mut loader = imports::Loader::new(file, root, limits);
        let (engine, ast, known) = build(file, text, &mut loader)?;
        let imports = std::mem::take(&mut loader.files);
        // Rhai's table is in an order that differs between processes; messages list these.
        let mut functions: Vec<(String, usize)> = ast
            .iter_functions()
            .map(|f| (f.name.to_string(), f.params.len()))
            .collect();
        functions.sort();
        let modules: Vec<_> = known
            .nested
            .iter()
            .map(|(alias, _, m)| (alias.clone(), m.clone()))
            .collect();
        // Without the species' blackboard declaration: functions that read the blackboard are
        // taken once it is known ([`Script::declare_memory`]).
        let natives = native::compile_all(&ast, &modules, None);
        let reads_heading = names_heading(text) || loader.heading;
        Ok(Script {
            engine,
            ast,
            file: file.to_path_buf(),
            text: text.into(),
            imports,
            functions,
            natives,
            modules,
            on_tick: None,
            reads_heading,
            root: root.to_path_buf(),
            limits: *limits,
            sources: loader.sources,
            memory: None,
            replicas: (0..MAX_REPLICAS).map(|_| Slot::default()).collect(),
        })
    }

    /// The engine and compiled script this thread calls: worker thread `i` of a pool (`i` > 0)
    /// gets a replica of its own once it has made [`REPLICATE_AFTER`] calls, compiled from the
    /// texts this script was compiled from, so it is the same code. Rhai counts references to
    /// what an engine and a compiled script share (the function library, registered functions,
    /// string constants) on every call; two threads calling one engine write the same counters,
    /// and on the 2-core machine of `BENCHMARKS.md` that made a blackboard-writing `on_tick()`
    /// twice as slow on two threads as on one. A replica costs a compile (about a millisecond),
    /// so a thread that calls a few times (a designer's test) keeps the shared one.
    fn local(&self) -> (&Engine, &AST) {
        let replica = rayon::current_thread_index()
            .filter(|&i| i > 0)
            .and_then(|i| self.replicas.get(i - 1))
            .and_then(|slot| {
                if let Some(r) = slot.replica.get() {
                    return r.as_deref();
                }
                // Only this thread counts in its slot: a plain load and store.
                let calls = slot.calls.load(Ordering::Relaxed);
                if calls < REPLICATE_AFTER {
                    slot.calls.store(calls + 1, Ordering::Relaxed);
                    return None;
                }
                slot.replica.get_or_init(|| self.replicate()).as_deref()
            });
        match replica {
            Some(r) => (&r.engine, &r.ast),
            None => (&self.engine, &self.ast),
        }
    }

    /// A replica of the engine and compiled script ([`Script::local`]); `None` should the texts
    /// kept not compile again (then the thread calls the shared one: the same code).
    fn replicate(&self) -> Option<Box<Replica>> {
        let mut loader = imports::Loader::replay(&self.sources, &self.root, &self.limits);
        let (mut engine, ast, _) = build(&self.file, &self.text, &mut loader).ok()?;
        if let Some(spec) = &self.memory {
            memory::register(&mut engine, spec.clone());
        }
        Some(Box::new(Replica { engine, ast }))
    }

    /// Whether it may read a category's mean heading ([`names_heading`]).
    pub fn reads_heading(&self) -> bool {
        self.reads_heading
    }

    /// The compiled script (for load-time checks of what it writes).
    pub fn ast(&self) -> &AST {
        &self.ast
    }

    /// Binds the blackboard to the species' declaration: reads and writes of keys it does not
    /// declare, and writes of another type, become script errors ([`memory::register`]).
    pub fn declare_memory(&mut self, spec: Arc<memory::MemorySpec>) {
        self.natives = native::compile_all(&self.ast, &self.modules, Some(&spec));
        self.on_tick = steps::Steps::compile(&self.ast, &self.modules, &spec, "on_tick");
        memory::register(&mut self.engine, spec.clone());
        self.memory = Some(spec);
        // Replicas are compiled with the declaration from now on.
        self.replicas.iter_mut().for_each(|r| *r = Slot::default());
    }

    /// The modules its engine holds, by alias.
    pub fn modules(&self) -> &native::Modules {
        &self.modules
    }

    /// `on_tick()` compiled for native evaluation, when it is of the forms [`steps`] takes.
    pub fn native_on_tick(&self) -> Option<&steps::Steps> {
        self.on_tick.as_ref()
    }

    /// Whether a natively evaluated function reads the blackboard (the view must hold it).
    pub fn natives_read_memory(&self) -> bool {
        self.natives.iter().any(|(_, f)| f.reads_memory())
    }

    /// The function `name` (without parameters) compiled for native evaluation, when its body
    /// is one expression of the forms [`native`] evaluates.
    pub fn native(&self, name: &str) -> Option<&native::Native> {
        self.natives.iter().find(|(n, _)| n == name).map(|(_, f)| f)
    }

    /// Whether the script defines `name` taking `params` parameters.
    pub fn has_fn(&self, name: &str, params: usize) -> bool {
        self.functions
            .iter()
            .any(|(n, p)| n == name && *p == params)
    }

    /// Line and column of `fn name` in the script (for errors about a function's result).
    pub fn fn_position(&self, name: &str) -> (usize, usize) {
        let pat = format!("fn {name}");
        for (i, line) in self.text.lines().enumerate() {
            if let Some(c) = line.find(&pat) {
                let rest = &line[c + pat.len()..];
                if rest.trim_start().starts_with('(') {
                    return (i + 1, c + 1);
                }
            }
        }
        (0, 0)
    }

    /// Calls `name` with `view` bound as `this` and no arguments.
    pub fn call<T: Clone + Send + Sync + 'static>(
        &self,
        scope: &mut Scope,
        this: &mut Dynamic,
        name: &str,
    ) -> Result<T, CallError> {
        self.call_args(scope, this, name, ())
    }

    /// Calls `name` with `this` bound and `args`.
    pub fn call_args<T: Clone + Send + Sync + 'static>(
        &self,
        scope: &mut Scope,
        this: &mut Dynamic,
        name: &str,
        args: impl rhai::FuncArgs,
    ) -> Result<T, CallError> {
        let options = CallFnOptions::new()
            .eval_ast(false)
            .rewind_scope(true)
            .bind_this_ptr(this);
        let (engine, ast) = self.local();
        let timer = budget::CallTimer::start();
        let r = engine.call_fn_with_options::<T>(options, scope, ast, name, args);
        let over = r.as_ref().err().and_then(|e| exceeded(e));
        timer.finish(over.is_some());
        r.map_err(|e| {
            let mut diagnostic = self.locate_error(&e);
            if let Some(over) = over {
                let agent = this
                    .read_lock::<AgentView>()
                    .map(|v| format!(" of agent {}", v.id))
                    .unwrap_or_default();
                diagnostic.message = time_message(name, &agent, over);
            }
            // Some errors (the operation limit) carry no position: point at the function.
            if diagnostic.line == 0 && diagnostic.file == self.file {
                let (line, col) = self.fn_position(name);
                diagnostic =
                    Diagnostic::new(&self.file, line, col, diagnostic.message, Some(&self.text));
            }
            CallError {
                diagnostic: Box::new(diagnostic),
                time_budget: over,
            }
        })
    }

    /// Turns a runtime error into a diagnostic that names the right file at the innermost frame.
    pub fn locate_error(&self, err: &EvalAltResult) -> Diagnostic {
        let site = error_site(err, &self.file, &self.text);
        let message = match site.error {
            EvalAltResult::ErrorTooManyOperations(_) => {
                "script exceeded its operation limit (an endless loop?); the agent keeps its last valid steering".to_string()
            }
            other => bare_message(other),
        };
        let (file, pos, text) = (site.file, site.pos, site.text);
        Diagnostic::new(
            file,
            pos.line().unwrap_or(0),
            pos.position().unwrap_or(0),
            message,
            text.as_deref(),
        )
    }
}

/// Position of a rhai error, as (line, col).
pub fn position_of(p: Position) -> (usize, usize) {
    (p.line().unwrap_or(0), p.position().unwrap_or(0))
}

/// Where a runtime error happened: its innermost frame (through nested function calls and
/// modules), the file that frame is in (a module's path, or the script's own file) and that
/// file's text, and the position there.
pub struct ErrorSite<'e> {
    /// The innermost error.
    pub error: &'e EvalAltResult,
    /// The file it is in.
    pub file: PathBuf,
    /// The text of that file, when it can be read.
    pub text: Option<String>,
    /// Where in it.
    pub pos: Position,
}

/// The site of `err`, raised by a script read from `file` with text `text`.
pub fn error_site<'e>(err: &'e EvalAltResult, file: &Path, text: &str) -> ErrorSite<'e> {
    let mut source = String::new();
    let mut e = err;
    let mut pos = err.position();
    loop {
        match e {
            EvalAltResult::ErrorInFunctionCall(_, src, inner, p) => {
                if !src.is_empty() {
                    source = src.clone();
                }
                if !p.is_none() {
                    pos = *p;
                }
                e = inner;
                if !e.position().is_none() {
                    pos = e.position();
                }
            }
            EvalAltResult::ErrorInModule(_, inner, _) => e = inner,
            _ => break,
        }
    }
    let f = if source.is_empty() {
        file.to_path_buf()
    } else {
        PathBuf::from(source)
    };
    let text = if f == file {
        Some(text.to_string())
    } else {
        crate::diag::read_text(&f, "module").ok()
    };
    ErrorSite {
        error: e,
        file: f,
        text,
        pos,
    }
}

/// An error's message without Rhai's "(line …, position …)" suffix (the diagnostic says where).
pub fn bare_message(e: &EvalAltResult) -> String {
    let mut m = e.to_string();
    if let Some(i) = m.find(" (line ") {
        m.truncate(i);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::memory::MemType;
    use super::*;

    /// What `f()` returns, and the error of `bad()`, on worker thread 1 of a pool of two, after
    /// enough calls there for the thread to call its replica.
    fn on_worker(s: &Script) -> (Vec<i64>, String) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let out = pool.broadcast(|ctx| {
            if ctx.index() != 1 {
                return None;
            }
            let mut this = Dynamic::from(AgentView::default());
            let mut scope = Scope::new();
            let got: Vec<i64> = (0..REPLICATE_AFTER + 8)
                .map(|_| s.call::<i64>(&mut scope, &mut this, "f").unwrap())
                .collect();
            let err = s.call::<Dynamic>(&mut scope, &mut this, "bad").unwrap_err();
            Some((got, err.diagnostic.to_string()))
        });
        out.into_iter().flatten().next().unwrap()
    }

    #[test]
    fn a_worker_thread_calls_a_replica_of_the_texts_first_compiled_with_the_blackboard_declared() {
        let dir = tempfile::tempdir().unwrap();
        let module = dir.path().join("m.rhai");
        std::fs::write(&module, "fn v() { 40 }\n").unwrap();
        let file = dir.path().join("s.rhai");
        let text = "import \"m\" as m;\n\
                    fn f() { this[\"k\"] = m::v() + 2; this[\"k\"] }\n\
                    fn bad() { this[\"nope\"] = 1; }\n";
        std::fs::write(&file, text).unwrap();
        let mut s = Script::compile(&file, text, dir.path(), &SandboxLimits::default())
            .unwrap_or_else(|d| panic!("{d}"));
        s.declare_memory(native::tests::spec_of(&[("k", MemType::Int)]));
        // Edited after the load: a replica must not see it.
        std::fs::write(&module, "fn v() { 0 }\n").unwrap();
        let (got, err) = on_worker(&s);
        assert!(got.iter().all(|&x| x == 42), "{got:?}");
        assert!(
            matches!(s.replicas[0].replica.get(), Some(Some(_))),
            "thread 1 compiled its replica"
        );
        assert!(s.replicas[1..].iter().all(|r| r.replica.get().is_none()));
        let mut this = Dynamic::from(AgentView::default());
        let shared = s
            .call::<Dynamic>(&mut Scope::new(), &mut this, "bad")
            .unwrap_err();
        assert_eq!(err, shared.diagnostic.to_string());
        assert!(err.contains("\"nope\" is not declared"), "{err}");
    }
}
