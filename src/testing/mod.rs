//! Designers' tests (`shoal test`): script tests written in Rhai beside the behaviors
//! (`behaviors/tests/*.rhai`, every `fn test_*()`), and scenario files whose `expect: [...]` is
//! checked at the end of a run. Not a tick stage: a layer above the whole pipeline that builds
//! tiny worlds with the real species, steps the real [`crate::tick::Pipeline`] and checks the
//! prioritized FSM of seed 000 §3 (interrupts, persistence, the behavior stack).
//!
//! Every test runs in a fresh world with a fixed seed, so results do not depend on the order or
//! the number of threads tests run on; they run in parallel (rayon) and are reported in a stable
//! order. The library returns a [`Report`]; printing is the caller's business.

pub mod api;
pub mod coverage;
pub mod failure;
mod names;
pub mod world;

use crate::diag::{Diagnostic, Diagnostics};
use crate::scenario::expect::Tracker;
use crate::scenario::{Run, Scenario, ScenarioDef};
use crate::species::validate::ron_options;
use api::TestCtx;
use coverage::Coverage;
use failure::{Kind, LimitsInfo};
use rayon::prelude::*;
use rhai::{CallFnOptions, Dynamic, Scope, AST};
use std::collections::BTreeMap;
use std::fmt::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use world::{lock, Library};

/// How tests run.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Only tests whose id (`file::test_name`, or the scenario file) contains this.
    pub filter: Option<String>,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Rhai operations one test may use (a test is one call).
    pub max_operations: u64,
    /// Ticks one test world may run.
    pub max_ticks: u64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            filter: None,
            threads: None,
            max_operations: 5_000_000,
            max_ticks: 20_000,
        }
    }
}

/// How a test ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestStatus {
    /// Everything held.
    Passed,
    /// An assertion or expectation did not hold.
    Failed,
    /// The test could not run as written (syntax, unknown name, a limit reached).
    Error,
    /// The test asked to be skipped, or a scenario given by name declares no expectation.
    Skipped,
}

/// One test's result.
#[derive(Debug, Clone, PartialEq)]
pub struct TestResult {
    /// `file::test_name`, or the file for a scenario or a file that does not compile.
    pub id: String,
    /// How it ended.
    pub status: TestStatus,
    /// Why it failed (or was skipped): located message, state and last decisions.
    pub details: String,
}

/// The results of a run, in a stable order (files sorted, tests in declaration order).
#[derive(Debug, Default)]
pub struct Report {
    /// One per test.
    pub results: Vec<TestResult>,
    coverage: Arc<Coverage>,
}

impl Report {
    /// Tests passed.
    pub fn passed(&self) -> usize {
        self.count(|s| s == TestStatus::Passed)
    }
    /// Tests failed (errors included).
    pub fn failed(&self) -> usize {
        self.count(|s| matches!(s, TestStatus::Failed | TestStatus::Error))
    }
    /// Tests skipped.
    pub fn skipped(&self) -> usize {
        self.count(|s| s == TestStatus::Skipped)
    }
    fn count(&self, f: impl Fn(TestStatus) -> bool) -> usize {
        self.results.iter().filter(|r| f(r.status)).count()
    }
    /// The closing line: `N passed, N failed` and `, N skipped` when some were.
    pub fn summary(&self) -> String {
        let mut s = format!("{} passed, {} failed", self.passed(), self.failed());
        if self.skipped() > 0 {
            let _ = write!(s, ", {} skipped", self.skipped());
        }
        s
    }
    /// The coverage report: behaviors and transitions no test exercised, per species.
    pub fn coverage(&self) -> String {
        self.coverage.report()
    }
}

impl Report {
    /// One line per test, details of failures indented below it (without the summary line).
    pub fn lines(&self) -> String {
        let mut f = String::new();
        for r in &self.results {
            let tag = match r.status {
                TestStatus::Passed => "ok   ",
                TestStatus::Failed => "FAIL ",
                TestStatus::Error => "ERROR",
                TestStatus::Skipped => "skip ",
            };
            let _ = writeln!(f, "{tag} {}", r.id);
            for line in r.details.lines() {
                let _ = writeln!(f, "      {line}");
            }
        }
        f
    }
}

impl fmt::Display for Report {
    /// [`Report::lines`] then the summary line.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", self.lines(), self.summary())
    }
}

/// What discovery found.
#[derive(Debug, Clone, PartialEq)]
enum Found {
    Script(PathBuf),
    Scenario(PathBuf),
    Bad(PathBuf, String),
}

fn in_tests_folder(p: &Path) -> bool {
    p.parent()
        .is_some_and(|d| d.components().any(|c| c.as_os_str() == "tests"))
}

fn is_scenario_text(t: &str) -> bool {
    t.lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with("//"))
        .is_some_and(|l| l.starts_with("Scenario"))
}

fn walk(dir: &Path, out: &mut Vec<Found>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    entries.sort();
    for e in entries {
        if e.is_dir() {
            // Fixtures (deliberately failing tests) run only when named; build outputs, recorded
            // runs (with copies of their inputs) and hidden folders never.
            let name = e.file_name().map(|n| n.to_string_lossy().into_owned());
            if name.is_some_and(|n| {
                !matches!(n.as_str(), "fixtures" | "target" | "runs") && !n.starts_with('.')
            }) {
                walk(&e, out);
            }
        } else if e.extension().is_some_and(|x| x == "rhai") {
            if in_tests_folder(&e) {
                out.push(Found::Script(e));
            }
        } else if e.extension().is_some_and(|x| x == "ron") {
            let Ok(text) = std::fs::read_to_string(&e) else {
                continue;
            };
            if !is_scenario_text(&text) {
                continue;
            }
            // Found by walking, a scenario is a test only when it declares expectations (or
            // does not parse: that is worth reporting).
            match ron_options().from_str::<ScenarioDef>(&text) {
                Ok(def) if def.expect.is_empty() => {}
                _ => out.push(Found::Scenario(e)),
            }
        }
    }
}

/// The test files and scenarios under `paths` (folders walked in sorted order, `fixtures`
/// folders skipped; files named explicitly are always taken).
fn discover(paths: &[PathBuf]) -> Vec<Found> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            walk(p, &mut out);
        } else if !p.exists() {
            out.push(Found::Bad(p.clone(), "no such file or folder".into()));
        } else if p.extension().is_some_and(|x| x == "rhai") {
            out.push(Found::Script(p.clone()));
        } else if p.extension().is_some_and(|x| x == "ron") {
            out.push(Found::Scenario(p.clone()));
        } else {
            out.push(Found::Bad(
                p.clone(),
                "not a test file: expected a `.rhai` script test or a `.ron` scenario".into(),
            ));
        }
    }
    out
}

/// The default places tests live: `behaviors/tests` and `scenarios/tests` (those that exist).
pub fn default_paths() -> Vec<PathBuf> {
    ["behaviors/tests", "scenarios/tests"]
        .iter()
        .map(PathBuf::from)
        .filter(|p| p.is_dir())
        .collect()
}

/// A compiled test file.
struct TestFile {
    path: PathBuf,
    text: String,
    ast: AST,
    library: Arc<Library>,
    fn_params: BTreeMap<String, usize>,
}

enum Job {
    Script(Arc<TestFile>, String),
    Scenario(PathBuf),
    Done(TestResult),
}

fn limits(o: &Options) -> crate::script::SandboxLimits {
    crate::script::SandboxLimits {
        max_operations: o.max_operations,
        ..crate::scenario::script_limits()
    }
}

/// Hint for a condition that reads a variable of the test (anonymous functions cannot).
fn hint(message: &str) -> String {
    if message.contains("Variable not found") || message.contains("Undefined variable") {
        format!(
            "{message} (conditions passed to `assert_within`, `assert_always` and `step_until` cannot see the test's variables: they get the world or the agent as `this` and as their parameter, e.g. `assert_within(fish, 20, |f| f.behavior == \"escape\")`, and named agents as `w[\"fish\"]`)"
        )
    } else {
        message.to_string()
    }
}

/// The test file `text` (named `path`) compiled, or where it does not parse.
fn parse(
    path: &Path,
    text: &str,
    limits: &crate::script::SandboxLimits,
) -> Result<AST, Diagnostic> {
    crate::script::check_size(path, text, "test file")?;
    let mut engine = crate::script::new_engine(limits);
    crate::script::exact_power(&mut engine, text);
    let mut ast = engine.compile(text).map_err(|e| {
        let (line, col) = crate::script::position_of(e.1);
        // Rhai points where parsing failed; the bracket left open may be far above.
        let note = crate::script::brackets::note(text, line, col).unwrap_or_default();
        Diagnostic::new(
            path,
            line,
            col,
            format!("{}{note}", hint(&e.0.to_string())),
            Some(text),
        )
    })?;
    ast.set_source(path.display().to_string());
    Ok(ast)
}

/// What `shoal test` reports about the test file `text` (named `path`) before running it: a
/// syntax error, or literal species and behavior names that do not exist. The species are read
/// from the behaviors folder above the file's `tests` folder (through the loaders' reader, so an
/// editor's overlay applies).
pub fn check_text(path: &Path, text: &str) -> Vec<Diagnostic> {
    match parse(path, text, &crate::scenario::script_limits()) {
        Ok(ast) => names::check(&ast, &Library::new(world::behaviors_root(path)), path, text),
        Err(d) => vec![d],
    }
}

fn compile(
    path: &Path,
    opts: &Options,
    libraries: &Mutex<BTreeMap<PathBuf, Arc<Library>>>,
) -> Result<TestFile, Diagnostics> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Diagnostic::file(path, format!("cannot read test file: {e}")))?;
    let ast = parse(path, &text, &limits(opts))?;
    // Sorted first: Rhai's table is in an order that differs between processes, and of two
    // overloads the last inserted is kept.
    let mut fns: Vec<(String, usize)> = ast
        .iter_functions()
        .map(|f| (f.name.to_string(), f.params.len()))
        .collect();
    fns.sort();
    let fn_params = fns.into_iter().collect();
    let root = world::behaviors_root(path);
    let library = lock(libraries)
        .entry(root.clone())
        .or_insert_with(|| Arc::new(Library::new(root)))
        .clone();
    let wrong = names::check(&ast, &library, path, &text);
    if !wrong.is_empty() {
        return Err(Diagnostics(wrong));
    }
    Ok(TestFile {
        path: path.to_path_buf(),
        text,
        ast,
        library,
        fn_params,
    })
}

fn run_script(file: &TestFile, name: &str, opts: &Options, coverage: &Arc<Coverage>) -> TestResult {
    let id = format!("{}::{name}", file.path.display());
    let ctx = Arc::new(TestCtx {
        library: file.library.clone(),
        coverage: coverage.clone(),
        max_ticks: opts.max_ticks,
        worlds: Mutex::new(Vec::new()),
        output: Mutex::new(String::new()),
        fn_params: file.fn_params.clone(),
    });
    let lim = limits(opts);
    let mut engine = crate::script::new_engine(&lim);
    crate::script::exact_power(&mut engine, &file.text);
    api::register(&mut engine, ctx.clone());
    let mut scope = Scope::new();
    let call = CallFnOptions::new().eval_ast(false).rewind_scope(true);
    let r = engine.call_fn_with_options::<Dynamic>(call, &mut scope, &file.ast, name, ());
    let output = std::mem::take(&mut *lock(&ctx.output));
    let with_output = |mut details: String| {
        if !output.is_empty() {
            details.push_str("printed:\n");
            for l in output.lines() {
                let _ = writeln!(details, "  {l}");
            }
        }
        details
    };
    match r {
        Ok(_) => {
            // A species script that failed during the test fails the test.
            let worlds = lock(&ctx.worlds).clone();
            for w in worlds {
                let tw = lock(&w.0);
                if let Some(m) = tw.script_error() {
                    return TestResult {
                        id,
                        status: TestStatus::Failed,
                        details: with_output(format!("{m}\n{}", tw.all_decisions(8))),
                    };
                }
            }
            TestResult {
                id,
                status: TestStatus::Passed,
                details: String::new(),
            }
        }
        Err(e) => {
            let info = LimitsInfo {
                max_operations: lim.max_operations,
                max_call_levels: lim.max_call_levels,
            };
            let mut located = failure::locate(&e, &file.path, &file.text, info);
            if located.diagnostic.line == 0 {
                // No position (e.g. an empty endless loop): point at the test function.
                let (line, col) = crate::script::position_of(fn_position(&file.text, name));
                let d = &located.diagnostic;
                located.diagnostic =
                    Diagnostic::new(&d.file, line, col, d.message.clone(), Some(&file.text));
            }
            let status = match located.kind {
                Kind::Fail => TestStatus::Failed,
                Kind::Skip => TestStatus::Skipped,
                Kind::Error => TestStatus::Error,
            };
            let mut details = if status == TestStatus::Skipped {
                located.diagnostic.message.clone()
            } else {
                format!("{}\n", located.diagnostic)
            };
            if !details.ends_with('\n') && !details.is_empty() {
                details.push('\n');
            }
            details.push_str(&located.context);
            TestResult {
                id,
                status,
                details: with_output(details),
            }
        }
    }
}

fn run_scenario(path: &Path, coverage: &Coverage) -> TestResult {
    let id = path.display().to_string();
    let error = |details: String| TestResult {
        id: id.clone(),
        status: TestStatus::Error,
        details,
    };
    let sc = match Scenario::load(path) {
        Ok(s) => s,
        Err(d) => return error(d.to_string()),
    };
    let mut tracker = match Tracker::new(&sc) {
        Ok(t) => t,
        Err(d) => return error(d.to_string()),
    };
    if tracker.is_empty() {
        return TestResult {
            id,
            status: TestStatus::Skipped,
            details: "the scenario declares no expectations (`expect: [...]`)".into(),
        };
    }
    coverage.add_root(&sc.behaviors_dir);
    let names: Vec<(String, Vec<String>)> = sc
        .species
        .species
        .iter()
        .map(|s| {
            (
                s.name.clone(),
                s.behaviors.iter().map(|b| b.name.to_string()).collect(),
            )
        })
        .collect();
    let mut run = Run::new(sc, Default::default());
    tracker.observe_run(&run);
    while !run.finished() {
        run.step();
        tracker.observe_run(&run);
        for e in &run.pipeline.events {
            if let crate::events::Event::Transition {
                species,
                from,
                to,
                cause,
                ..
            } = e
            {
                let (s, b) = &names[*species as usize];
                coverage.transition(s, &b[*from as usize], &b[*to as usize], *cause);
            }
        }
        for a in &run.world.agents {
            let (s, b) = &names[a.species.0 as usize];
            coverage.behavior(s, &b[a.mind.current as usize]);
        }
    }
    let verdicts = tracker.finish(&run.world, &run.pipeline);
    let failed = verdicts.iter().any(|v| !v.passed);
    let mut details = String::new();
    if failed {
        for v in &verdicts {
            let _ = writeln!(
                details,
                "{} expected {}: {}",
                if v.passed { "ok  " } else { "FAIL" },
                v.expected,
                v.observed
            );
        }
    }
    TestResult {
        id,
        status: if failed {
            TestStatus::Failed
        } else {
            TestStatus::Passed
        },
        details,
    }
}

/// Discovers and runs the tests under `paths` (see [`default_paths`]).
pub fn run(paths: &[PathBuf], opts: &Options) -> Report {
    let coverage = Arc::new(Coverage::default());
    let libraries = Mutex::new(BTreeMap::new());
    let matches = |id: &str| opts.filter.as_deref().is_none_or(|f| id.contains(f));
    let mut jobs = Vec::new();
    for found in discover(paths) {
        match found {
            Found::Bad(p, why) => jobs.push(Job::Done(TestResult {
                id: p.display().to_string(),
                status: TestStatus::Error,
                details: format!("{}: {why}", p.display()),
            })),
            Found::Scenario(p) => {
                if matches(&p.display().to_string()) {
                    jobs.push(Job::Scenario(p));
                }
            }
            Found::Script(p) => match compile(&p, opts, &libraries) {
                Err(d) => {
                    if matches(&p.display().to_string()) {
                        jobs.push(Job::Done(TestResult {
                            id: p.display().to_string(),
                            status: TestStatus::Error,
                            details: d.to_string(),
                        }));
                    }
                }
                Ok(f) => {
                    let f = Arc::new(f);
                    let mut tests: Vec<(String, usize, usize)> = f
                        .ast
                        .iter_functions()
                        .filter(|m| m.name.starts_with("test_"))
                        .map(|m| {
                            let (line, _) =
                                crate::script::position_of(fn_position(&f.text, m.name));
                            (m.name.to_string(), m.params.len(), line)
                        })
                        .collect();
                    tests.sort_by(|a, b| (a.2, &a.0, a.1).cmp(&(b.2, &b.0, b.1)));
                    for (name, params, line) in tests {
                        let id = format!("{}::{name}", p.display());
                        if !matches(&id) {
                            continue;
                        }
                        if params > 0 {
                            jobs.push(Job::Done(TestResult {
                                id,
                                status: TestStatus::Error,
                                details: Diagnostic::new(
                                    &p,
                                    line,
                                    1,
                                    format!("test functions take no parameters: `{name}` takes {params}"),
                                    Some(&f.text),
                                )
                                .to_string(),
                            }));
                        } else {
                            jobs.push(Job::Script(f.clone(), name));
                        }
                    }
                }
            },
        }
    }
    let exec = |job: &Job| match job {
        Job::Done(r) => r.clone(),
        Job::Script(f, name) => run_script(f, name, opts, &coverage),
        Job::Scenario(p) => run_scenario(p, &coverage),
    };
    // Rhai evaluation is deeply recursive and a waiting worker may pick up another test: give
    // workers room.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .stack_size(64 << 20)
        .build();
    let results = match pool {
        Ok(pool) => pool.install(|| jobs.par_iter().map(exec).collect()),
        Err(_) => jobs.iter().map(exec).collect(),
    };
    Report { results, coverage }
}

/// Position of `fn name(` in a test file, for ordering tests and locating errors about them.
fn fn_position(text: &str, name: &str) -> rhai::Position {
    let pat = format!("fn {name}");
    for (i, line) in text.lines().enumerate() {
        if let Some(c) = line.find(&pat) {
            if line[c + pat.len()..].trim_start().starts_with('(') {
                return rhai::Position::new((i + 1) as u16, (c + 1) as u16);
            }
        }
    }
    rhai::Position::NONE
}
