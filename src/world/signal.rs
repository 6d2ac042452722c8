//! Named events (seed 003's messages, extended): what a message names — one of the built-in
//! kinds or an event a species declares — and what an agent heard of a named event. Pure data:
//! the tick delivers them (`events/apply.rs`), species declare them (`species/events.rs`).

use super::{MemValue, MessageKind};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// What a message names: a built-in kind, or an event the species declares (its index in the
/// species' `events`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Signal {
    /// Seed 003's danger, obstacle or mate.
    Kind(MessageKind),
    /// A declared event, by its index in the sending (or hearing) species' declarations.
    Event(u16),
}

/// A named event heard last tick: the hearing species' index of the event and where its
/// payload lies in the world's table of the tick ([`crate::world::World::event_payloads`]).
/// Small and `Copy`, like the built-in inbox.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct HeardEvent {
    /// Index of the event in the hearing species' `events`.
    pub event: u16,
    /// Index of the payload in the world's `event_payloads`.
    pub payload: u32,
}

/// An agent's one inbox slot (seed 003): the highest-ranked message it received last tick, a
/// built-in kind or a declared event, or none. Eight bytes: the two as options side by side took
/// thirteen of the agent record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Inbox {
    /// Nothing received.
    #[default]
    Empty,
    /// A built-in message.
    Kind(MessageKind),
    /// A declared event (see [`HeardEvent`]; its fields inline, so that the tag takes a
    /// byte of the record's padding instead of four more).
    Event {
        /// Index of the event in the hearing species' `events`.
        event: u16,
        /// Index of the payload in the world's `event_payloads`.
        payload: u32,
    },
}

impl Inbox {
    /// The slot holding `heard`, else `kind` (a slot holds one of the two at most).
    pub fn of(kind: Option<MessageKind>, heard: Option<HeardEvent>) -> Inbox {
        match (heard, kind) {
            (Some(h), _) => Inbox::Event {
                event: h.event,
                payload: h.payload,
            },
            (None, Some(k)) => Inbox::Kind(k),
            (None, None) => Inbox::Empty,
        }
    }

    /// The built-in message held, if that is what it holds.
    pub fn kind(self) -> Option<MessageKind> {
        match self {
            Inbox::Kind(k) => Some(k),
            _ => None,
        }
    }

    /// The declared event held, if that is what it holds.
    pub fn heard(self) -> Option<HeardEvent> {
        match self {
            Inbox::Event { event, payload } => Some(HeardEvent { event, payload }),
            _ => None,
        }
    }
}

/// The fields a sender gave a named event, by name (declared fields only; a field not given
/// reads as its type's zero).
pub type Payload = Arc<[(Arc<str>, MemValue)]>;

impl MessageKind {
    /// Rank in one inbox slot (seed 003: danger > obstacle > mate); declared events take a rank
    /// of their own on the same scale, higher heard first.
    pub fn rank(self) -> u8 {
        match self {
            MessageKind::Danger => 30,
            MessageKind::Obstacle => 20,
            MessageKind::Mate => 10,
        }
    }
}

/// The type of a payload field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FieldType {
    /// A number.
    Float,
    /// An integer.
    Int,
    /// A flag.
    Bool,
    /// A vector.
    Vec3,
}

impl FieldType {
    /// Lower-case name, as in messages.
    pub fn name(self) -> &'static str {
        match self {
            FieldType::Float => "float",
            FieldType::Int => "int",
            FieldType::Bool => "bool",
            FieldType::Vec3 => "vec3",
        }
    }
}

/// A declared event, checked (`species/events.rs` builds it from the species file).
#[derive(Debug, Clone, PartialEq)]
pub struct EventSpec {
    /// Its name.
    pub name: Arc<str>,
    /// Rank in the inbox slot (Danger 30, Obstacle 20, Mate 10; never equal to one of them).
    pub priority: u8,
    /// Payload fields in name order.
    pub fields: Vec<(Arc<str>, FieldType)>,
    /// Whether other species that declare the same name hear it.
    pub shared: bool,
}

impl EventSpec {
    /// The type of field `name`, if declared.
    pub fn field(&self, name: &str) -> Option<FieldType> {
        self.fields
            .iter()
            .find(|(f, _)| &**f == name)
            .map(|(_, t)| *t)
    }
    /// `given` completed to every declared field in name order: a field not given is its
    /// type's zero.
    pub fn complete(&self, given: &[(Arc<str>, MemValue)]) -> Payload {
        self.fields
            .iter()
            .map(|(f, t)| {
                let v = given.iter().find(|(g, _)| g == f).map(|(_, v)| v.clone());
                (f.clone(), v.unwrap_or_else(|| field_zero(*t)))
            })
            .collect()
    }
}

/// Whether `v` is a value of type `t`.
pub fn field_fits(t: FieldType, v: &MemValue) -> bool {
    matches!(
        (t, v),
        (FieldType::Float, MemValue::Float(_))
            | (FieldType::Int, MemValue::Int(_))
            | (FieldType::Bool, MemValue::Bool(_))
            | (FieldType::Vec3, MemValue::Vec3(_))
    )
}

/// The zero of type `t`: what a field the sender did not give reads as.
pub fn field_zero(t: FieldType) -> MemValue {
    match t {
        FieldType::Float => MemValue::Float(0.0),
        FieldType::Int => MemValue::Int(0),
        FieldType::Bool => MemValue::Bool(false),
        FieldType::Vec3 => MemValue::Vec3(glam::Vec3::ZERO),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inbox_gives_back_the_one_message_it_holds() {
        let h = HeardEvent {
            event: 3,
            payload: 70_000,
        };
        let danger = Some(MessageKind::Danger);
        assert_eq!(Inbox::of(None, None), Inbox::Empty);
        assert_eq!(Inbox::of(danger, None).kind(), danger);
        assert_eq!(Inbox::of(danger, None).heard(), None);
        assert_eq!(Inbox::of(None, Some(h)).heard(), Some(h));
        assert_eq!(Inbox::of(None, Some(h)).kind(), None);
        // A slot never holds both; given both, `of` keeps the event.
        assert_eq!(Inbox::of(danger, Some(h)).heard(), Some(h));
        assert_eq!(Inbox::default(), Inbox::Empty);
        assert_eq!((Inbox::Empty.kind(), Inbox::Empty.heard()), (None, None));
    }
}
