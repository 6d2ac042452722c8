//! The species' declared blackboard and the names its script writes, checked at load: the
//! `memory` block (types, start values, at most [`MEMORY_CAPACITY`] keys), every literal key the
//! script reads or writes (declared, and written with a value of its type), and every behavior
//! name it compares `this.behavior` with (a behavior of the species). Called once from
//! `validate.rs`, before and after the behavior walk; the AST walks are in
//! [`crate::script::names`].

use super::{MemDecl, Species, SpeciesDef};
use crate::load::{locate, locate_key, Diagnostic, Diagnostics};
use crate::script::memory::{MemType, MemorySpec};
use crate::script::{names, Script};
use crate::world::{MemValue, MEMORY_CAPACITY};
use std::path::Path;
use std::sync::Arc;

/// The declaration `def.memory` as the script host holds it; problems go to `diags`, located in
/// the species file.
fn spec_of(def: &SpeciesDef, file: &Path, text: &str, diags: &mut Vec<Diagnostic>) -> MemorySpec {
    let block = locate_key(text, "memory", 0).map_or(0, |x| x.2);
    let mut error = |key: &str, msg: String| {
        let (l, c, _) = locate(text, &format!("\"{key}\""), block)
            .or_else(|| locate_key(text, "memory", 0))
            .unwrap_or((0, 0, 0));
        diags.push(Diagnostic::new(file, l, c, msg, Some(text)));
    };
    if def.memory.len() > MEMORY_CAPACITY {
        error(
            "",
            format!(
                "`memory` declares {} keys; an agent remembers at most {MEMORY_CAPACITY}",
                def.memory.len()
            ),
        );
    }
    let mut spec = MemorySpec::default();
    for (key, d) in &def.memory {
        if key.is_empty() || key.len() > 64 {
            error(key, "a memory key has 1 to 64 bytes".into());
        }
        let (t, start) = match d {
            MemDecl::Bool(v) => (MemType::Bool, v.map(MemValue::Bool)),
            MemDecl::Int(v) => (MemType::Int, v.map(MemValue::Int)),
            MemDecl::Float(v) => (MemType::Float, v.map(MemValue::Float)),
            MemDecl::Vec3(v) => (MemType::Vec3, v.map(MemValue::Vec3)),
            MemDecl::Str(v) => (MemType::Str, v.clone().map(MemValue::Str)),
        };
        match &start {
            Some(MemValue::Float(f)) if !f.is_finite() => error(
                key,
                format!("memory key \"{key}\": the start value must be finite"),
            ),
            Some(MemValue::Vec3(v)) if !v.is_finite() => error(
                key,
                format!("memory key \"{key}\": the start value must be finite"),
            ),
            Some(MemValue::Str(s)) if s.len() > 256 => error(
                key,
                format!("memory key \"{key}\": memory strings are limited to 256 bytes"),
            ),
            _ => {}
        }
        let key: Arc<str> = Arc::from(key.as_str());
        spec.keys.push((key.clone(), t));
        if let Some(v) = start {
            spec.initial.push((key, v));
        }
    }
    spec
}

/// Checks the species' `memory` block and the keys its script uses, and binds the script's
/// blackboard to the declaration (`script` is the one just compiled, not yet shared).
pub(super) fn declare(
    file: &Path,
    text: &str,
    def: &SpeciesDef,
    mut script: Option<Arc<Script>>,
) -> Result<(Option<Arc<Script>>, Arc<MemorySpec>), Diagnostics> {
    let mut diags = Vec::new();
    let spec = Arc::new(spec_of(def, file, text, &mut diags));
    if let Some(s) = script.as_mut().and_then(Arc::get_mut) {
        if diags.is_empty() {
            diags.extend(names::check_keys(s.ast(), &spec, &s.file, &s.text));
        }
        s.declare_memory(spec.clone());
    }
    if diags.is_empty() {
        Ok((script, spec))
    } else {
        Err(Diagnostics(diags))
    }
}

/// Gives the built species its blackboard declaration and checks the behavior names its script
/// compares `this.behavior` with.
pub(super) fn finish(
    mut species: Species,
    memory: Arc<MemorySpec>,
) -> Result<Species, Diagnostics> {
    species.memory = memory;
    let Some(s) = &species.script else {
        return Ok(species);
    };
    let known: Vec<&str> = species.behaviors.iter().map(|b| &*b.name).collect();
    let owner = format!("species \"{}\"", species.name);
    let diags: Vec<Diagnostic> = names::behavior_uses(s.ast())
        .into_iter()
        .filter(|n| !names::is_behavior(&n.name, &known))
        .map(|n| {
            Diagnostic::new(
                &s.file,
                n.line,
                n.col,
                names::unknown_behavior(&n.name, &owner, &known),
                Some(&s.text),
            )
        })
        .collect();
    if diags.is_empty() {
        Ok(species)
    } else {
        Err(Diagnostics(diags))
    }
}
