//! The script side of named events (seed 003's messages, extended): `this.send(name, radius)`
//! and `this.send(name, #{ field: value }, radius)` for the built-in kinds and the species'
//! declared events, payload fields checked against the declaration, and `this.heard_payload`,
//! the fields of the event heard last tick. Touches only the agent view's outbox.

use super::view::{from_mem, to_mem, AgentView};
use crate::events::MessageKind;
use crate::load::did_you_mean;
use crate::world::{field_fits, MemValue, Payload, Signal};
use rhai::{Dynamic, Engine, EvalAltResult, Map, Position, FLOAT};
use std::sync::Arc;

/// Most messages one script call may queue (two of them are sent).
const OUTBOX: usize = 8;

fn err(msg: impl Into<String>) -> Box<EvalAltResult> {
    Box::new(EvalAltResult::ErrorRuntime(
        Dynamic::from(msg.into()),
        Position::NONE,
    ))
}

/// A payload as a script map (fields by name).
pub fn payload_map(p: &Payload) -> Map {
    p.iter()
        .map(|(k, v)| (k.as_ref().into(), from_mem(v)))
        .collect()
}

/// What `name` names for an agent whose species declares `v.events`.
fn signal(v: &AgentView, name: &str) -> Result<Signal, Box<EvalAltResult>> {
    if let Some(k) = MessageKind::parse(name) {
        return Ok(Signal::Kind(k));
    }
    match v.events.iter().position(|e| &*e.name == name) {
        Some(i) => Ok(Signal::Event(i as u16)),
        None => {
            let declared: Vec<&str> = v.events.iter().map(|e| &*e.name).collect();
            Err(err(format!(
                "unknown event \"{name}\": {}; built-in kinds are danger, obstacle, mate{}",
                if declared.is_empty() {
                    "the species declares no `events`".to_string()
                } else {
                    format!("declared events are {}", declared.join(", "))
                },
                did_you_mean(
                    name,
                    declared
                        .iter()
                        .copied()
                        .chain(["danger", "obstacle", "mate"])
                )
            )))
        }
    }
}

/// The payload of declared event `e` from a script map, every field checked.
fn payload(v: &AgentView, e: u16, map: Map) -> Result<Payload, Box<EvalAltResult>> {
    let spec = &v.events[e as usize];
    let mut given: Vec<(Arc<str>, MemValue)> = Vec::with_capacity(map.len());
    for (key, value) in map {
        let Some(t) = spec.field(&key) else {
            let names: Vec<&str> = spec.fields.iter().map(|(f, _)| &**f).collect();
            return Err(err(format!(
                "event \"{}\" has no field `{key}`: its fields are {}{}",
                spec.name,
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                },
                did_you_mean(&key, names.iter().copied())
            )));
        };
        let mut m = to_mem(value)?;
        if let (crate::world::FieldType::Float, MemValue::Int(i)) = (t, &m) {
            m = MemValue::Float(*i as f32);
        }
        if !field_fits(t, &m) {
            return Err(err(format!(
                "field `{key}` of event \"{}\" is a {}, not this value",
                spec.name,
                t.name()
            )));
        }
        given.push((key.as_str().into(), m));
    }
    Ok(spec.complete(&given))
}

/// Registers `send` and `heard_payload` on the agent view.
pub(super) fn register(e: &mut Engine) {
    e.register_fn(
        "send",
        |v: &mut AgentView, name: &str, radius: FLOAT| -> Result<(), Box<EvalAltResult>> {
            let s = signal(v, name)?;
            if v.outbox.len() < OUTBOX {
                v.outbox.push((s, radius, None));
            }
            Ok(())
        },
    );
    e.register_fn(
        "send",
        |v: &mut AgentView,
         name: &str,
         fields: Map,
         radius: FLOAT|
         -> Result<(), Box<EvalAltResult>> {
            let Signal::Event(i) = signal(v, name)? else {
                return Err(err(format!(
                    "message \"{name}\" is a built-in kind and carries no fields: write `this.send(\"{name}\", radius)`"
                )));
            };
            let p = payload(v, i, fields)?;
            if v.outbox.len() < OUTBOX {
                v.outbox.push((Signal::Event(i), radius, Some(p)));
            }
            Ok(())
        },
    );
    e.register_get("heard_payload", |v: &mut AgentView| -> Map {
        v.heard_payload
            .as_ref()
            .map(payload_map)
            .unwrap_or_default()
    });
    e.register_set(
        "heard_payload",
        |_: &mut AgentView, _: Map| -> Result<(), Box<EvalAltResult>> {
            Err(err("`this.heard_payload` is read-only"))
        },
    );
}
