//! The Rhai APIs as the engines register them: the species scripts' (`script::new_engine`:
//! `this.` properties and methods, `Percepts`, `Vec3`, steering values, the squad part) and the
//! script tests' (`testing::api`, registered on top of it). Read from the engines' function
//! metadata (Rhai's `metadata` feature), so a function added to either API is offered at once;
//! its documentation is its entry in the designers' references, and a test fails when a
//! registered function has none.

use super::reference;
use crate::script::{new_engine, SandboxLimits};
use crate::testing::api::{register, TestCtx};
use crate::testing::coverage::Coverage;
use crate::testing::world::Library;
use rhai::Engine;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Which API.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Api {
    /// Species scripts (`this.`).
    Script,
    /// Script tests (only what tests add to the script API).
    Test,
}

/// One registered function, property or method.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ApiFn {
    /// Its name (`seek`, `pos`, `vec3`).
    pub name: String,
    /// The type it is called on (`Agent`, `Percepts`, `Vec3`, `World`); empty for a global
    /// function.
    pub receiver: String,
    /// Whether it is a property (`this.pos`) rather than a call.
    pub property: bool,
    /// Whether a script may assign it.
    pub settable: bool,
    /// Its parameters' types, the receiver left out.
    pub params: Vec<String>,
    /// What it returns.
    pub ret: String,
    /// Its reference entry (cut once, when the API is first read).
    pub doc: Option<String>,
}

impl ApiFn {
    /// How it is written: `this.seek(Vec3) -> Steer`, `this.pos: Vec3`, `vec3(float, float,
    /// float) -> Vec3`.
    pub fn signature(&self) -> String {
        let on = match self.receiver.as_str() {
            "" => String::new(),
            r => format!("{r}."),
        };
        if self.property {
            let set = if self.settable { " (settable)" } else { "" };
            return format!("{on}{}: {}{set}", self.name, self.ret);
        }
        let ret = if self.ret.is_empty() || self.ret == "()" {
            String::new()
        } else {
            format!(" -> {}", self.ret)
        };
        format!("{on}{}({}){ret}", self.name, self.params.join(", "))
    }

    /// Its entry in the reference of `api`.
    fn entry(&self, api: Api) -> Option<String> {
        match api {
            Api::Script => {
                let section = match self.receiver.as_str() {
                    "Agent" => Some("What `this` is"),
                    _ => None,
                };
                reference::entry(reference::SPECIES, &self.name, section)
                    .or_else(|| reference::entry(reference::SQUADS, &self.name, None))
            }
            Api::Test => reference::entry(reference::TESTS, &self.name, None),
        }
    }
}

/// A function's raw metadata: name, parameters (`name: type` with Rust type paths), return
/// type.
type Raw = (String, Vec<String>, String);

fn raw(e: &Engine) -> Vec<Raw> {
    e.collect_fn_metadata(
        None,
        |f| {
            let m = f.metadata;
            // Rhai's own, replaced by the engine's with the same bits on every machine.
            if crate::script::math::REPLACED.contains(&m.name.as_str()) {
                return None;
            }
            Some((
                m.name.to_string(),
                m.params_info.iter().map(|p| p.to_string()).collect(),
                m.return_type.to_string(),
            ))
        },
        false,
    )
}

/// A Rust type path as scripts know it (`Agent`, `float`, `String`).
fn display(e: &Engine, ty: &str) -> String {
    let t = ty
        .trim()
        .trim_start_matches("&mut ")
        .trim_start_matches('&');
    let mapped = e.map_type_name(t);
    let short = mapped.rsplit("::").next().unwrap_or(mapped);
    match short {
        "f32" | "f64" | "FLOAT" => "float",
        "i64" | "INT" => "int",
        "str" | "ImmutableString" => "String",
        "Dynamic" => "?",
        "Array" | "Vec<Dynamic>" => "Array",
        s => s,
    }
    .to_string()
}

fn is_ident(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_')
}

/// Turns raw metadata into API entries; the first parameter is the receiver when its type is
/// one of `receivers`.
fn build(e: &Engine, raws: &[Raw], receivers: &[&str]) -> Vec<ApiFn> {
    let mut out: Vec<ApiFn> = Vec::new();
    let mut setters = Vec::new();
    for (name, params, ret) in raws {
        let raw_types: Vec<&str> = params
            .iter()
            .map(|p| p.split_once(": ").map_or(p.as_str(), |x| x.1))
            .collect();
        let types: Vec<String> = raw_types.iter().map(|t| display(e, t)).collect();
        if let Some(prop) = name.strip_prefix("set$") {
            // Read-only properties register a setter that refuses a change (see
            // `script::view::read_only`): fallible, unlike a real one.
            if !ret.contains("Result") {
                setters.push((prop.to_string(), types.first().cloned().unwrap_or_default()));
            }
            continue;
        }
        let (name, property) = match name.strip_prefix("get$") {
            Some(p) => (p, true),
            None => (name.as_str(), false),
        };
        if !is_ident(name) || name == "to_string" || name == "to_debug" {
            continue; // operators, indexers and what `print` uses
        }
        // Methods take their receiver by reference; a function taking an agent by value
        // (`assert_behavior(a, …)`) is called as a function.
        let by_ref = raw_types.first().is_some_and(|t| t.starts_with("&mut"));
        let (receiver, rest) = match types.first() {
            Some(t) if by_ref && receivers.contains(&t.as_str()) => {
                (t.clone(), types[1..].to_vec())
            }
            _ => (String::new(), types.clone()),
        };
        let f = ApiFn {
            name: name.to_string(),
            receiver,
            property,
            settable: false,
            params: rest,
            ret: display(e, ret),
            doc: None,
        };
        if !out.contains(&f) {
            out.push(f);
        }
    }
    for f in &mut out {
        f.settable = f.property
            && setters
                .iter()
                .any(|(n, r)| *n == f.name && *r == f.receiver);
    }
    // Overloads by their parameters too: Rhai lists them in an order that differs between
    // processes, and completion inserts the first one's form.
    out.sort_by(|a, b| {
        (
            &a.receiver,
            &a.name,
            a.params.len(),
            &a.params,
            a.property,
            &a.ret,
        )
            .cmp(&(
                &b.receiver,
                &b.name,
                b.params.len(),
                &b.params,
                b.property,
                &b.ret,
            ))
    });
    out
}

/// The engine of script tests (the script API plus the test API), for its metadata only.
pub fn test_engine() -> Engine {
    let ctx = Arc::new(TestCtx {
        library: Arc::new(Library::new(std::path::PathBuf::from("behaviors"))),
        coverage: Arc::new(Coverage::default()),
        max_ticks: 0,
        worlds: Mutex::new(Vec::new()),
        output: Mutex::new(String::new()),
        fn_params: BTreeMap::new(),
    });
    let mut e = new_engine(&SandboxLimits::default());
    register(&mut e, ctx);
    e
}

/// The functions of `api` (computed once).
pub fn functions(api: Api) -> &'static [ApiFn] {
    static SCRIPT: OnceLock<Vec<ApiFn>> = OnceLock::new();
    static TEST: OnceLock<Vec<ApiFn>> = OnceLock::new();
    match api {
        Api::Script => SCRIPT.get_or_init(|| {
            let e = new_engine(&SandboxLimits::default());
            with_docs(
                Api::Script,
                build(&e, &raw(&e), &["Agent", "Percepts", "Vec3", "Steer"]),
            )
        }),
        Api::Test => TEST.get_or_init(|| {
            let script = raw(&new_engine(&SandboxLimits::default()));
            let e = test_engine();
            let own: Vec<Raw> = raw(&e)
                .into_iter()
                .filter(|r| !script.contains(r))
                .collect();
            with_docs(Api::Test, build(&e, &own, &["Agent", "World"]))
        }),
    }
}

fn with_docs(api: Api, mut fns: Vec<ApiFn>) -> Vec<ApiFn> {
    for f in &mut fns {
        f.doc = f.entry(api);
    }
    fns
}

/// Members of `receiver` in `api` (properties and methods).
pub fn members(api: Api, receiver: &str) -> impl Iterator<Item = &'static ApiFn> + '_ {
    functions(api)
        .iter()
        .filter(move |f| f.receiver == receiver)
}

/// Rhai's definitions file (`.d.rhai`) of `api`: the script API, or everything a test script
/// may call (the script API and the test API). Rhai's standard library is left out.
pub fn definitions(api: Api) -> String {
    let header = match api {
        Api::Script => "// The shoal script API (species scripts: `this` is the agent).\n",
        Api::Test => "// The shoal test API (behaviors/tests/*.rhai), with the script API.\n",
    };
    let body = match api {
        Api::Script => new_engine(&SandboxLimits::default())
            .definitions()
            .include_standard_packages(false)
            .single_file(),
        Api::Test => test_engine()
            .definitions()
            .include_standard_packages(false)
            .single_file(),
    };
    format!("{header}{body}")
}
