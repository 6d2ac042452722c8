//! The species file's named events: the `events` declarations and what `Send(…)` and
//! `Heard(…)` name (seed 003's messages, extended). Checked by `species/events.rs`.

use super::MessageKind;
pub use crate::world::FieldType;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What `Send(…)` and `Heard(…)` name: a built-in kind written bare (`Danger`), or a declared
/// event written as a string (`"alarm_call"`). A bare word that is not a built-in kind is read
/// as an event name, so a misspelt kind is reported as an unknown name with a suggestion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MessageRef {
    /// Danger, Obstacle or Mate.
    Kind(MessageKind),
    /// A declared event, by name.
    Event(String),
}

impl MessageRef {
    /// How it is written in a species file (`Danger`, `"alarm_call"`).
    pub fn written(&self) -> String {
        match self {
            MessageRef::Kind(k) => format!("{k:?}"),
            MessageRef::Event(n) => format!("\"{n}\""),
        }
    }
}

/// A named event the species sends or reacts to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventDef {
    /// Its name (`"alarm_call"`), used by `Send`, `Heard`, and scripts.
    pub name: String,
    /// Rank in the one inbox slot, on the scale of the built-in kinds: Danger 30, Obstacle 20,
    /// Mate 10 (higher is heard first; it may not equal a built-in rank).
    #[serde(default)]
    pub priority: u8,
    /// The payload's fields and their types.
    #[serde(default)]
    pub fields: BTreeMap<String, FieldType>,
    /// Whether agents of other species that declare an event of the same name hear it too
    /// (otherwise only the sender's species does).
    #[serde(default)]
    pub shared: bool,
}
