//! Part of stage 4 (decision): the declared blackboard. A species declares the keys its agents
//! remember, each with a type and an optional start value ([`MemorySpec`]); the species script's
//! engine gets blackboard functions bound to that declaration, so a key that is not declared, or
//! a value of another type, is a located script error rather than a silent `()`. The load-time
//! check of string-literal keys is in [`super::names`]; this file is what runs.

use super::view::{from_mem, to_mem, AgentView};
use crate::load::did_you_mean;
use crate::world::{MemValue, MEMORY_CAPACITY};
use rhai::{Dynamic, Engine, EvalAltResult, Position};
use std::sync::Arc;
use thin_vec::ThinVec;

/// Makes `dst` a copy of the blackboard `src`, reusing its room and its keys (a blackboard is
/// copied into a script's view and back on every call; a thin list's own `clone_from` would
/// allocate it afresh). An equal key is kept, not cloned: the keys a species declares are
/// shared by all its agents, and counting their references from every thread would make
/// threads contend for one cache line.
pub fn copy_blackboard(dst: &mut ThinVec<(Arc<str>, MemValue)>, src: &[(Arc<str>, MemValue)]) {
    dst.truncate(src.len());
    let n = dst.len();
    for (d, s) in dst.iter_mut().zip(src) {
        if d.0 != s.0 {
            d.0 = s.0.clone();
        }
        d.1.clone_from(&s.1);
    }
    dst.extend(src[n..].iter().cloned());
}

/// The type of a declared blackboard key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MemType {
    /// `true` or `false`.
    Bool,
    /// An integer.
    Int,
    /// A number.
    Float,
    /// A vector.
    Vec3,
    /// A short string.
    Str,
}

impl MemType {
    /// The type of a value.
    pub fn of(v: &MemValue) -> MemType {
        match v {
            MemValue::Bool(_) => MemType::Bool,
            MemValue::Int(_) => MemType::Int,
            MemValue::Float(_) => MemType::Float,
            MemValue::Vec3(_) => MemType::Vec3,
            MemValue::Str(_) => MemType::Str,
        }
    }

    /// Its name in the species file (`Float`, `Vec3`, ...).
    pub fn ron_name(self) -> &'static str {
        match self {
            MemType::Bool => "Bool",
            MemType::Int => "Int",
            MemType::Float => "Float",
            MemType::Vec3 => "Vec3",
            MemType::Str => "String",
        }
    }

    /// In words, for messages ("a float").
    pub fn words(self) -> &'static str {
        match self {
            MemType::Bool => "a bool",
            MemType::Int => "an int",
            MemType::Float => "a float",
            MemType::Vec3 => "a Vec3",
            MemType::Str => "a string",
        }
    }
}

/// A species' declared blackboard: its keys with their types, and the values agents start with.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MemorySpec {
    /// Declared keys with their types, in key order.
    pub keys: Vec<(Arc<str>, MemType)>,
    /// What a new agent remembers: the keys declared with a start value, in key order (keys
    /// declared without one start unset: `has` is false until a script writes them).
    pub initial: ThinVec<(Arc<str>, MemValue)>,
}

impl MemorySpec {
    /// A declaration of `keys` with their types, none with a start value.
    pub fn declaring(keys: &[(&str, MemType)]) -> MemorySpec {
        let mut keys: Vec<(Arc<str>, MemType)> =
            keys.iter().map(|(k, t)| (Arc::from(*k), *t)).collect();
        keys.sort_by(|a, b| a.0.cmp(&b.0));
        MemorySpec {
            keys,
            initial: ThinVec::new(),
        }
    }

    /// The declared type of `key`.
    pub fn type_of(&self, key: &str) -> Option<MemType> {
        self.keys
            .binary_search_by(|(k, _)| (**k).cmp(key))
            .ok()
            .map(|i| self.keys[i].1)
    }

    /// `key` as agents hold it: the declaration's own copy (shared by every agent of the
    /// species, so remembering it allocates nothing), or a new one for an undeclared key.
    pub fn key(&self, key: &str) -> Arc<str> {
        match self.keys.binary_search_by(|(k, _)| (**k).cmp(key)) {
            Ok(i) => self.keys[i].0.clone(),
            Err(_) => Arc::from(key),
        }
    }

    /// Why `key` may not be used (`None` when it is declared).
    pub fn undeclared(&self, key: &str) -> Option<String> {
        if self.type_of(key).is_some() {
            return None;
        }
        if self.keys.is_empty() {
            return Some(format!(
                "memory key \"{key}\" is not declared: the species declares no memory (add `memory: {{ \"{key}\": Float(None) }}` to the species file, with its type and start value)"
            ));
        }
        Some(format!(
            "memory key \"{key}\" is not declared in the species' `memory`{}: it declares {}",
            did_you_mean(key, self.keys.iter().map(|(k, _)| &**k)),
            self.key_list()
        ))
    }

    /// The declared keys, quoted, for messages.
    pub fn key_list(&self) -> String {
        self.keys
            .iter()
            .map(|(k, t)| format!("\"{k}\" ({})", t.ron_name()))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Carries an agent's blackboard over to this declaration (hot reload): a value stays where
    /// its key is still declared with the same type; a newly declared key, or one whose type
    /// changed, starts at its start value (or unset); keys no longer declared are dropped, as
    /// nothing could read them. Without this, a key added while the run goes on would read as
    /// `()` in every agent already swimming.
    pub fn carry(&self, memory: &mut ThinVec<(Arc<str>, MemValue)>) {
        memory.retain(|(k, v)| self.type_of(k) == Some(MemType::of(v)));
        for (k, v) in &self.initial {
            if let Err(i) = memory.binary_search_by(|(m, _)| m.cmp(k)) {
                memory.insert(i, (k.clone(), v.clone()));
            }
        }
    }

    /// Checks that `value` may be stored under `key`.
    pub fn check_write(&self, key: &str, value: &MemValue) -> Result<(), String> {
        if let Some(why) = self.undeclared(key) {
            return Err(why);
        }
        let want = self.type_of(key).unwrap_or(MemType::of(value));
        let got = MemType::of(value);
        if want != got {
            return Err(format!(
                "memory key \"{key}\" is declared {} (`{}`), but {} was written",
                want.words(),
                want.ron_name(),
                got.words()
            ));
        }
        Ok(())
    }
}

fn err(msg: String) -> Box<EvalAltResult> {
    Box::new(EvalAltResult::ErrorRuntime(
        Dynamic::from(msg),
        Position::NONE,
    ))
}

/// Stores `value` under `key` in `memory` (kept in key order), refusing a full blackboard;
/// the key of a new entry is `spec`'s ([`MemorySpec::key`]).
pub fn store(
    memory: &mut ThinVec<(Arc<str>, MemValue)>,
    key: &str,
    value: MemValue,
    spec: &MemorySpec,
) -> Result<(), String> {
    match memory.binary_search_by(|(k, _)| (**k).cmp(key)) {
        Ok(i) => memory[i].1 = value,
        Err(i) => {
            if memory.len() >= MEMORY_CAPACITY {
                return Err(format!("memory is full ({MEMORY_CAPACITY} keys)"));
            }
            memory.insert(i, (spec.key(key), value));
        }
    }
    Ok(())
}

/// Replaces the blackboard functions of `engine` (`this["k"]`, `this["k"] = v`, `this.has("k")`,
/// `this.forget("k")`) by ones that accept only the keys and types of `spec`.
pub fn register(engine: &mut Engine, spec: Arc<MemorySpec>) {
    let s = spec.clone();
    engine.register_indexer_get(
        move |v: &mut AgentView, key: &str| -> Result<Dynamic, Box<EvalAltResult>> {
            if let Some(why) = s.undeclared(key) {
                return Err(err(why));
            }
            Ok(v.memory
                .iter()
                .find(|(k, _)| &**k == key)
                .map(|(_, m)| from_mem(m))
                .unwrap_or(Dynamic::UNIT))
        },
    );
    let s = spec.clone();
    engine.register_indexer_set(
        move |v: &mut AgentView, key: &str, value: Dynamic| -> Result<(), Box<EvalAltResult>> {
            let m = to_mem(value)?;
            s.check_write(key, &m).map_err(err)?;
            store(&mut v.memory, key, m, &s).map_err(err)
        },
    );
    let s = spec.clone();
    engine.register_fn(
        "has",
        move |v: &mut AgentView, key: &str| -> Result<bool, Box<EvalAltResult>> {
            if let Some(why) = s.undeclared(key) {
                return Err(err(why));
            }
            Ok(v.memory.iter().any(|(k, _)| &**k == key))
        },
    );
    engine.register_fn(
        "forget",
        move |v: &mut AgentView, key: &str| -> Result<(), Box<EvalAltResult>> {
            if let Some(why) = spec.undeclared(key) {
                return Err(err(why));
            }
            v.memory.retain(|(k, _)| &**k != key);
            Ok(())
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blackboard_is_copied_into_the_room_it_had_keeping_equal_keys() {
        let board = |keys: &[(&str, f32)]| -> ThinVec<(Arc<str>, MemValue)> {
            keys.iter()
                .map(|(k, v)| (Arc::from(*k), MemValue::Float(*v)))
                .collect()
        };
        let mut dst = board(&[("meals", 1.0), ("mated_at", 2.0), ("spare", 3.0)]);
        let room = dst.as_ptr();
        let meals = dst[0].0.clone();
        let src = board(&[("meals", 4.0), ("rest", 5.0)]);
        copy_blackboard(&mut dst, &src);
        assert_eq!(dst, src);
        assert_eq!(dst.as_ptr(), room, "the list's room is reused");
        assert!(Arc::ptr_eq(&dst[0].0, &meals), "an equal key is kept");
        assert!(Arc::ptr_eq(&dst[1].0, &src[1].0), "another key is shared");
        let longer = board(&[("a", 1.0), ("b", 2.0), ("c", 3.0), ("d", 4.0)]);
        copy_blackboard(&mut dst, &longer);
        assert_eq!(dst, longer);
        copy_blackboard(&mut dst, &[]);
        assert!(dst.is_empty());
    }

    #[test]
    fn a_declared_key_is_the_declarations_own() {
        let spec = MemorySpec {
            keys: vec![(Arc::from("meals"), MemType::Int)],
            initial: ThinVec::new(),
        };
        let mut m = ThinVec::new();
        store(&mut m, "meals", MemValue::Int(2), &spec).unwrap();
        store(&mut m, "other", MemValue::Int(3), &spec).unwrap();
        assert!(Arc::ptr_eq(&m[0].0, &spec.keys[0].0));
        assert_eq!(&*m[1].0, "other");
        store(&mut m, "meals", MemValue::Int(5), &spec).unwrap();
        assert_eq!(m[0].1, MemValue::Int(5));
        assert_eq!(m.len(), 2);
    }
}
