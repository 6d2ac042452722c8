//! Breakpoints of a live session: pause when an agent (or any agent of a species) enters a
//! behavior, when a behavior's `when` or `done` condition fires, or on a script error. Not a
//! tick stage: the simulation thread checks the tick's events against them right after the
//! tick that produced them, so the run stops at that tick; the page then steps tick by tick.
//!
//! A condition is seen when it fires, that is when the decision acts on it (seed 000 §3): a
//! `when` that holds while a higher level keeps its behavior from starting does not stop the run.

use crate::events::{Cause, Event};
use crate::species::SpeciesSet;
use serde::Serialize;
use serde_json::Value;

/// Most breakpoints a session keeps (a page sending more gets an error, not a slower tick).
pub const MAX_BREAKPOINTS: usize = 64;

/// What stops the run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Trigger {
    /// An agent starts or resumes this behavior.
    Enter(String),
    /// This behavior's `when` fires: it starts (activated or interrupting).
    When(String),
    /// This behavior's `done` fires: it completes.
    Done(String),
    /// A script fails.
    ScriptError,
}

/// One breakpoint: a trigger, for one agent, the agents of one species, or all.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Breakpoint {
    /// Number given by the session (for removing it).
    pub id: u32,
    /// What stops the run.
    pub trigger: Trigger,
    /// Only this agent.
    pub agent: Option<u32>,
    /// Only agents of this species.
    pub species: Option<String>,
}

/// The breakpoint that stopped the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Hit {
    /// Ticks done when the run stopped (the tick of the frame shown).
    pub tick: u64,
    /// The breakpoint's number.
    pub breakpoint: u32,
    /// The agent that triggered it.
    pub agent: u32,
    /// Its species.
    pub species: String,
    /// What happened, in words.
    pub reason: String,
}

/// A breakpoint named by its trigger and scope, for the page and `/status`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Listed {
    /// Its number.
    pub id: u32,
    /// What it stops on, in words.
    pub text: String,
}

impl Breakpoint {
    /// Reads a breakpoint from a `/control` body: `{"cmd":"break","on":"enter"|"when"|"done",
    /// "behavior":NAME}` or `{"cmd":"break","on":"script_error"}`, with `"agent":ID` or
    /// `"species":NAME` to narrow it. The number is given later.
    pub fn parse(v: &Value) -> Result<Breakpoint, String> {
        let on = v["on"]
            .as_str()
            .ok_or("\"break\" needs \"on\": \"enter\", \"when\", \"done\" or \"script_error\"")?;
        let behavior = || -> Result<String, String> {
            match v["behavior"].as_str() {
                Some(b) if !b.is_empty() && b.len() <= 200 => Ok(b.to_string()),
                _ => Err(format!("\"on\": \"{on}\" needs a \"behavior\" name")),
            }
        };
        let trigger = match on {
            "enter" => Trigger::Enter(behavior()?),
            "when" => Trigger::When(behavior()?),
            "done" => Trigger::Done(behavior()?),
            "script_error" => Trigger::ScriptError,
            other => {
                return Err(format!(
                    "unknown \"on\": \"{other}\": expected enter, when, done or script_error"
                ))
            }
        };
        let agent = match &v["agent"] {
            Value::Null => None,
            a => Some(
                a.as_u64()
                    .and_then(|a| u32::try_from(a).ok())
                    .ok_or("\"agent\" must be an agent id (a whole number)")?,
            ),
        };
        let species = match &v["species"] {
            Value::Null => None,
            Value::String(s) if !s.is_empty() && s.len() <= 200 => Some(s.clone()),
            _ => return Err("\"species\" must be a species name".into()),
        };
        Ok(Breakpoint {
            id: 0,
            trigger,
            agent,
            species,
        })
    }

    /// What it stops on, in words.
    pub fn text(&self) -> String {
        let what = match &self.trigger {
            Trigger::Enter(b) => format!("enters {b}"),
            Trigger::When(b) => format!("{b}'s when fires"),
            Trigger::Done(b) => format!("{b}'s done fires"),
            Trigger::ScriptError => "script error".to_string(),
        };
        match (&self.agent, &self.species) {
            (Some(a), _) => format!("agent {a}: {what}"),
            (None, Some(s)) => format!("any {s}: {what}"),
            (None, None) => format!("any agent: {what}"),
        }
    }

    /// The reason `e` (an event of the tick just done) triggers this breakpoint, if it does.
    pub fn matches(&self, e: &Event, set: &SpeciesSet) -> Option<(u32, String, String)> {
        let (agent, species) = match e {
            Event::Transition { agent, species, .. }
            | Event::ScriptError { agent, species, .. } => (agent.0, *species),
            _ => return None,
        };
        let sp = set.species.get(species as usize)?;
        if self.agent.is_some_and(|a| a != agent)
            || self.species.as_deref().is_some_and(|s| s != sp.name)
        {
            return None;
        }
        let name = |b: u16| sp.behavior_name(b).to_string();
        let reason = match (&self.trigger, e) {
            (Trigger::Enter(b), Event::Transition { from, to, .. }) if name(*to) == *b => {
                format!(
                    "agent {agent} ({}) entered {b} from {}",
                    sp.name,
                    name(*from)
                )
            }
            (Trigger::When(b), Event::Transition { to, cause, .. })
                if name(*to) == *b && matches!(cause, Cause::Activated | Cause::Interrupted) =>
            {
                format!(
                    "{b}'s when fired for agent {agent} ({}): {}",
                    sp.name, sp.behaviors[*to as usize].when_text
                )
            }
            (Trigger::Done(b), Event::Transition { from, cause, .. })
                if name(*from) == *b && matches!(cause, Cause::Completed | Cause::Resumed) =>
            {
                format!(
                    "{b}'s done fired for agent {agent} ({}): {}",
                    sp.name, sp.behaviors[*from as usize].done_text
                )
            }
            (Trigger::ScriptError, Event::ScriptError { message, .. }) => format!(
                "script error of agent {agent} ({}): {}",
                sp.name,
                message.lines().next().unwrap_or("")
            ),
            _ => return None,
        };
        Some((agent, sp.name.clone(), reason))
    }
}

/// The breakpoints of a session, checked after every tick.
#[derive(Debug, Clone, Default)]
pub struct Breakpoints {
    list: Vec<Breakpoint>,
    next_id: u32,
}

impl Breakpoints {
    /// Adds `b` and returns its number.
    pub fn add(&mut self, mut b: Breakpoint) -> Result<u32, String> {
        if self.list.len() >= MAX_BREAKPOINTS {
            return Err(format!("at most {MAX_BREAKPOINTS} breakpoints"));
        }
        self.next_id += 1;
        b.id = self.next_id;
        self.list.push(b);
        Ok(self.next_id)
    }

    /// Removes breakpoint `id` (`None`: all of them).
    pub fn remove(&mut self, id: Option<u32>) {
        match id {
            Some(id) => self.list.retain(|b| b.id != id),
            None => self.list.clear(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Every breakpoint, in words.
    pub fn listed(&self) -> Vec<Listed> {
        self.list
            .iter()
            .map(|b| Listed {
                id: b.id,
                text: b.text(),
            })
            .collect()
    }

    /// The first breakpoint that the tick's `events` trigger, in event order; `tick` is the
    /// number of ticks done.
    pub fn check(&self, events: &[Event], set: &SpeciesSet, tick: u64) -> Option<Hit> {
        events.iter().find_map(|e| {
            self.list.iter().find_map(|b| {
                b.matches(e, set).map(|(agent, species, reason)| Hit {
                    tick,
                    breakpoint: b.id,
                    agent,
                    species,
                    reason,
                })
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn bad_breakpoints_are_refused_with_a_reason() {
        for (v, says) in [
            (json!({"cmd": "break"}), "needs \"on\""),
            (json!({"on": "enter"}), "needs a \"behavior\""),
            (
                json!({"on": "enter", "behavior": 3}),
                "needs a \"behavior\"",
            ),
            (json!({"on": "jump"}), "unknown \"on\""),
            (
                json!({"on": "enter", "behavior": "a", "agent": -1}),
                "\"agent\" must be",
            ),
            (
                json!({"on": "enter", "behavior": "a", "agent": 1e20}),
                "\"agent\" must be",
            ),
            (
                json!({"on": "enter", "behavior": "a", "species": []}),
                "\"species\" must be",
            ),
        ] {
            let e = Breakpoint::parse(&v).unwrap_err();
            assert!(e.contains(says), "{v}: {e}");
        }
        let b = Breakpoint::parse(&json!({"on": "when", "behavior": "graze", "species": "fish"}))
            .unwrap();
        assert_eq!(b.trigger, Trigger::When("graze".into()));
        assert_eq!(b.text(), "any fish: graze's when fires");
    }

    #[test]
    fn a_breakpoint_fires_for_its_agent_species_and_trigger_only() {
        let scenario = crate::scenario::Scenario::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/reef.ron"
        )))
        .unwrap();
        let set = scenario.species.clone();
        let (s, sp) = set
            .species
            .iter()
            .enumerate()
            .find(|(_, s)| s.behaviors.len() >= 2)
            .unwrap();
        let (a, b) = (
            sp.behaviors[0].name.to_string(),
            sp.behaviors[1].name.to_string(),
        );
        let t = |agent: u32, from: u16, to: u16, cause: Cause| Event::Transition {
            agent: crate::world::AgentId(agent),
            species: s as u16,
            from,
            to,
            cause,
            condition: None,
            stack: vec![to],
        };
        let mut bps = Breakpoints::default();
        let parse = |v: Value| Breakpoint::parse(&v).unwrap();
        bps.add(parse(json!({"on": "enter", "behavior": b, "agent": 7})))
            .unwrap();
        // Another agent entering, or agent 7 entering another behavior: nothing.
        assert!(bps
            .check(&[t(8, 0, 1, Cause::Activated)], &set, 5)
            .is_none());
        assert!(bps
            .check(&[t(7, 1, 0, Cause::Activated)], &set, 5)
            .is_none());
        let hit = bps
            .check(
                &[t(8, 0, 1, Cause::Activated), t(7, 0, 1, Cause::Resumed)],
                &set,
                5,
            )
            .unwrap();
        assert_eq!((hit.tick, hit.agent, hit.breakpoint), (5, 7, 1));
        assert!(hit.reason.contains(&format!("entered {b} from {a}")));

        let mut bps = Breakpoints::default();
        bps.add(parse(
            json!({"on": "when", "behavior": b, "species": sp.name.clone()}),
        ))
        .unwrap();
        assert!(bps.check(&[t(3, 0, 1, Cause::Resumed)], &set, 9).is_none());
        assert!(bps
            .check(&[t(3, 0, 1, Cause::Interrupted)], &set, 9)
            .is_some());
        bps.add(parse(
            json!({"on": "done", "behavior": a, "species": "nobody"}),
        ))
        .unwrap();
        assert!(bps
            .check(&[t(3, 0, 1, Cause::Completed)], &set, 9)
            .is_none());
        bps.remove(None);
        assert!(bps.is_empty());

        bps.add(parse(json!({"on": "script_error"}))).unwrap();
        let err = Event::ScriptError {
            agent: crate::world::AgentId(4),
            species: s as u16,
            message: "f.rhai:3:1: boom\n3 | x".into(),
        };
        let hit = bps.check(&[err], &set, 2).unwrap();
        assert!(hit.reason.ends_with("f.rhai:3:1: boom"), "{}", hit.reason);
    }
}
