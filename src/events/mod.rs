//! Stage 7 of the tick: world events. Contacts resolved in agent order (eating removes food or
//! kills the prey, mating resets libido), messages delivered for the next tick (seed 003
//! interaction constraints: danger > obstacle > mate), and the [`Event`] log every later layer
//! (recording, viewers, tests) reads, with the cause of every behavior transition.

mod apply;

use crate::world::AgentId;
pub use crate::world::{MessageKind, Payload, Signal};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Why a behavior transition happened (seed 000 §3 arbitration).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Cause {
    /// A behavior's activation condition fired and it started (nothing interrupted).
    Activated,
    /// A higher (or equal) level fired and interrupted the current behavior, which went on the
    /// stack.
    Interrupted,
    /// The current behavior's completion condition fired; a new one started.
    Completed,
    /// The current behavior completed and a stacked one resumed (it outranked any new one).
    Resumed,
    /// The behavior no longer exists after a reload, or nothing else applies: back to the
    /// initial behavior.
    Fallback,
    /// A script requested the change.
    Script,
    /// The current behavior (or a composed one holding it) succeeded: its `done` held, or
    /// its last step did; the next step or its `on_success` started.
    Succeeded,
    /// The current behavior (or a composed one holding it) failed: its `fail` held, or a step
    /// of a sequence (the last of a fallback) did; its `on_failure` or the list's choice
    /// started.
    Failed,
}

impl Cause {
    /// Every cause, in the order the docs list them.
    pub const ALL: [Cause; 8] = [
        Cause::Activated,
        Cause::Interrupted,
        Cause::Completed,
        Cause::Resumed,
        Cause::Fallback,
        Cause::Script,
        Cause::Succeeded,
        Cause::Failed,
    ];
    /// Lower-case name, as in the event log.
    pub fn name(self) -> &'static str {
        match self {
            Cause::Activated => "activated",
            Cause::Interrupted => "interrupted",
            Cause::Completed => "completed",
            Cause::Resumed => "resumed",
            Cause::Fallback => "fallback",
            Cause::Script => "script",
            Cause::Succeeded => "succeeded",
            Cause::Failed => "failed",
        }
    }
}

/// Something that happened during a tick. Names are resolved by whoever renders the event.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// An agent appeared.
    Spawn {
        /// Who.
        agent: AgentId,
        /// Its species index.
        species: u16,
    },
    /// An agent died.
    Death {
        /// Who.
        agent: AgentId,
        /// Its species index.
        species: u16,
        /// Why (e.g. "caught", "removed").
        cause: &'static str,
    },
    /// An agent ate a food item.
    Meal {
        /// Who ate.
        agent: AgentId,
        /// The food item's id.
        food: u32,
    },
    /// An agent caught (and ate) another.
    Catch {
        /// The predator.
        agent: AgentId,
        /// The prey.
        prey: AgentId,
    },
    /// Two agents mated.
    Mating {
        /// Who initiated.
        agent: AgentId,
        /// The partner.
        mate: AgentId,
    },
    /// A behavior transition, with its cause.
    Transition {
        /// Who.
        agent: AgentId,
        /// Species index (behavior indices refer to it).
        species: u16,
        /// Behavior before.
        from: u16,
        /// Behavior after.
        to: u16,
        /// Why.
        cause: Cause,
        /// Text of the condition that fired (activation or completion), if any.
        condition: Option<std::sync::Arc<str>>,
        /// The stack after the transition, bottom first.
        stack: Vec<u16>,
    },
    /// A message was broadcast.
    Message {
        /// Sender.
        from: AgentId,
        /// Kind.
        kind: MessageKind,
        /// Radius.
        radius: f32,
    },
    /// A declared event was broadcast (logged as a message, with its name and payload).
    Named {
        /// Sender.
        from: AgentId,
        /// The event's name, as its species declares it.
        name: Arc<str>,
        /// The fields the sender gave.
        payload: Payload,
        /// Radius.
        radius: f32,
    },
    /// A script failed for an agent (reported once per agent).
    ScriptError {
        /// Who.
        agent: AgentId,
        /// Species index.
        species: u16,
        /// `file:line:col: message`.
        message: String,
    },
}

impl Event {
    /// Short kind name, as in the event log.
    pub fn kind(&self) -> &'static str {
        match self {
            Event::Spawn { .. } => "spawn",
            Event::Death { .. } => "death",
            Event::Meal { .. } => "meal",
            Event::Catch { .. } => "catch",
            Event::Mating { .. } => "mating",
            Event::Transition { .. } => "transition",
            Event::Message { .. } | Event::Named { .. } => "message",
            Event::ScriptError { .. } => "script_error",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn danger_outranks_obstacle_outranks_mate() {
        assert_eq!(
            MessageKind::max_priority(Some(MessageKind::Mate), MessageKind::Danger),
            MessageKind::Danger
        );
        assert_eq!(
            MessageKind::max_priority(Some(MessageKind::Danger), MessageKind::Obstacle),
            MessageKind::Danger
        );
        assert_eq!(
            MessageKind::max_priority(None, MessageKind::Mate),
            MessageKind::Mate
        );
        assert_eq!(MessageKind::parse("obstacle"), Some(MessageKind::Obstacle));
    }
}
