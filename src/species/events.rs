//! Named events of a species (seed 003's messages, extended): the `events` declarations checked
//! into [`EventSpec`]s, what `Send(…)` and `Heard(…)` name resolved to a [`Signal`], and the
//! event names and payload fields written as literals in the script's `send` calls checked at
//! load time. Reads the species file and the compiled script; touches nothing at run time.

use super::validate::Builder;
use super::*;
use crate::load::{did_you_mean, locate, Diagnostic};
pub use crate::world::{field_fits, field_zero, EventSpec};
use crate::world::{MessageKind, Signal};
use rhai::{ASTNode, Expr};

impl Species {
    /// Index of the declared event named `name`.
    pub fn event_index(&self, name: &str) -> Option<u16> {
        self.events
            .iter()
            .position(|e| &*e.name == name)
            .map(|i| i as u16)
    }
    /// Rank of a message in this species' inbox slot (higher is kept).
    pub fn rank(&self, s: Signal) -> u8 {
        match s {
            Signal::Kind(k) => k.rank(),
            Signal::Event(e) => self.events.get(e as usize).map_or(0, |e| e.priority),
        }
    }
    /// The name of a message as scripts and the event log write it.
    pub fn signal_name(&self, s: Signal) -> &str {
        match s {
            Signal::Kind(k) => k.name(),
            Signal::Event(e) => self.events.get(e as usize).map_or("?", |e| &e.name),
        }
    }
}

const BUILT_IN: [&str; 3] = ["Danger", "Obstacle", "Mate"];

impl Builder<'_> {
    /// Checks the `events` declarations (names unique and not a built-in kind's, ranks not a
    /// built-in's) and the script's `send` literals against them.
    pub(super) fn events(&mut self, def: &SpeciesDef) -> Vec<EventSpec> {
        let mut out: Vec<EventSpec> = Vec::new();
        // Each declaration is located after the one before it, from the `events` key on.
        let start = locate(self.text, "events:", 0).map_or(0, |x| x.2);
        let mut from = start;
        for e in &def.events {
            let needle = format!("\"{}\"", e.name);
            self.cursor = from;
            if let Some((_, _, at)) = locate(self.text, &needle, from) {
                self.cursor = at;
                from = at + 1;
            }
            if e.name.trim().is_empty() {
                self.error_at("events", "an event's `name` is empty".into());
            } else if out.iter().any(|o| *o.name == e.name) {
                self.error_at(
                    &needle,
                    format!("event \"{}\" is declared twice in `events`", e.name),
                );
            } else if MessageKind::parse(&e.name.to_lowercase()).is_some() {
                self.error_at(
                    &needle,
                    format!(
                        "event \"{}\" has the name of a built-in message kind: write `{}` without quotes to use it, or name the event otherwise",
                        e.name,
                        BUILT_IN
                            .iter()
                            .find(|b| b.eq_ignore_ascii_case(&e.name))
                            .unwrap_or(&"Danger")
                    ),
                );
            }
            if let Some(k) = [
                MessageKind::Danger,
                MessageKind::Obstacle,
                MessageKind::Mate,
            ]
            .into_iter()
            .find(|k| k.rank() == e.priority)
            {
                self.error_at(
                    &needle,
                    format!(
                        "event \"{}\": `priority: {}` is the rank of {k:?}; choose another number (Danger 30, Obstacle 20, Mate 10; higher is heard first)",
                        e.name, e.priority
                    ),
                );
            }
            out.push(EventSpec {
                name: e.name.as_str().into(),
                priority: e.priority,
                fields: e
                    .fields
                    .iter()
                    .map(|(k, t)| (Arc::from(k.as_str()), *t))
                    .collect(),
                shared: e.shared,
            });
        }
        self.cursor = 0;
        self.script_sends(&out);
        out
    }

    /// Resolves what `Send(…)` or `Heard(…)` (`what`) names.
    pub(super) fn signal(&mut self, m: &MessageRef, what: &str) -> Signal {
        let name = match m {
            MessageRef::Kind(k) => return Signal::Kind(*k),
            MessageRef::Event(n) => n,
        };
        if let Some(i) = self.def.events.iter().position(|e| e.name == *name) {
            return Signal::Event(i as u16);
        }
        let quoted = format!("\"{name}\"");
        let needle = if locate(self.text, &quoted, self.cursor).is_some() {
            quoted
        } else {
            name.clone()
        };
        let msg = unknown_event(name, what, self.def.events.iter().map(|e| e.name.as_str()));
        self.error_at(&needle, msg);
        Signal::Kind(MessageKind::Danger)
    }

    /// Event names and payload fields written as literals in the script's `this.send(…)`
    /// calls: an unknown name or field, or a literal of the wrong type, is a load-time error.
    fn script_sends(&mut self, events: &[EventSpec]) {
        let Some(script) = self.script else {
            return;
        };
        let mut found = Vec::new();
        script.ast().walk(&mut |path: &[ASTNode]| {
            if let Some(ASTNode::Expr(Expr::MethodCall(call, _))) = path.last() {
                if call.name == "send" && call.args.len() >= 2 {
                    if let Expr::StringConstant(name, pos) = &call.args[0] {
                        let fields = match (call.args.len(), &call.args[1]) {
                            (3, Expr::Map(m, _)) => {
                                m.0.iter()
                                    .map(|(k, v)| (k.name.to_string(), k.pos, literal_type(v)))
                                    .collect()
                            }
                            // A map of constants is folded into one value when compiled.
                            (3, Expr::DynamicConstant(d, pos)) => d
                                .read_lock::<rhai::Map>()
                                .map(|m| {
                                    m.iter()
                                        .map(|(k, v)| (k.to_string(), *pos, dynamic_type(v)))
                                        .collect()
                                })
                                .unwrap_or_default(),
                            _ => Vec::new(),
                        };
                        if let Some(msg) = check_send(events, name, &fields) {
                            found.push((msg.1.unwrap_or(*pos), msg.0));
                        }
                    }
                }
            }
            true
        });
        // Functions are walked in the order of Rhai's table, which differs between processes.
        let mut found: Vec<_> = found
            .into_iter()
            .map(|(pos, msg)| (crate::script::position_of(pos), msg))
            .collect();
        found.sort_by_key(|f| f.0);
        for ((l, c), msg) in found {
            self.diags
                .push(Diagnostic::new(&script.file, l, c, msg, Some(&script.text)));
        }
    }
}

/// The message for an unknown event `name` in `what`, with a did-you-mean.
fn unknown_event<'a>(name: &str, what: &str, declared: impl Iterator<Item = &'a str>) -> String {
    let declared: Vec<&str> = declared.collect();
    let hint = did_you_mean(name, declared.iter().copied().chain(BUILT_IN));
    let list = if declared.is_empty() {
        "the species declares no `events`".to_string()
    } else {
        format!("declared events are {}", declared.join(", "))
    };
    format!(
        "unknown event \"{name}\" in `{what}`: {list}; built-in kinds are Danger, Obstacle, Mate{hint}"
    )
}

/// What is wrong with a `send(name, #{…}, radius)` written with literals (the message, and where
/// when it is not at the name).
fn check_send(
    events: &[EventSpec],
    name: &str,
    fields: &[(String, rhai::Position, Literal)],
) -> Option<(String, Option<rhai::Position>)> {
    if MessageKind::parse(name).is_some() {
        return None;
    }
    let Some(e) = events.iter().find(|e| &*e.name == name) else {
        let declared: Vec<&str> = events.iter().map(|e| &*e.name).collect();
        let hint = did_you_mean(
            name,
            declared
                .iter()
                .copied()
                .chain(["danger", "obstacle", "mate"]),
        );
        let list = if declared.is_empty() {
            "the species declares no `events`".to_string()
        } else {
            format!("declared events are {}", declared.join(", "))
        };
        return Some((
            format!("unknown event \"{name}\" in `send`: {list}; built-in kinds are danger, obstacle, mate{hint}"),
            None,
        ));
    };
    for (key, pos, literal) in fields {
        let Some(t) = e.field(key) else {
            let names: Vec<&str> = e.fields.iter().map(|(f, _)| &**f).collect();
            return Some((
                format!(
                    "event \"{name}\" has no field `{}`: its fields are {}{}",
                    key,
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    },
                    did_you_mean(key, names.iter().copied())
                ),
                Some(*pos),
            ));
        };
        let literal = match literal {
            Literal::Known(t) => Some(*t),
            Literal::Str => None,
            Literal::Other => continue,
        };
        let fits = literal == Some(t) || (t == FieldType::Float && literal == Some(FieldType::Int));
        if !fits {
            return Some((
                format!(
                    "field `{}` of event \"{name}\" is a {}, not {}",
                    key,
                    t.name(),
                    literal.map_or("a string", |l| match l {
                        FieldType::Float => "a float",
                        FieldType::Int => "an int",
                        FieldType::Bool => "a bool",
                        FieldType::Vec3 => "a vec3",
                    })
                ),
                Some(*pos),
            ));
        }
    }
    None
}

/// What a literal in a `send` payload is, as far as the compiled script tells.
enum Literal {
    /// A value of a field type.
    Known(FieldType),
    /// A string (no field takes one).
    Str,
    /// Anything else (computed at run time, checked then).
    Other,
}

fn literal_type(e: &Expr) -> Literal {
    match e {
        Expr::FloatConstant(..) => Literal::Known(FieldType::Float),
        Expr::IntegerConstant(..) => Literal::Known(FieldType::Int),
        Expr::BoolConstant(..) => Literal::Known(FieldType::Bool),
        Expr::StringConstant(..) => Literal::Str,
        Expr::DynamicConstant(d, _) => dynamic_type(d),
        _ => Literal::Other,
    }
}

fn dynamic_type(d: &rhai::Dynamic) -> Literal {
    if d.is::<rhai::FLOAT>() {
        Literal::Known(FieldType::Float)
    } else if d.is::<rhai::INT>() {
        Literal::Known(FieldType::Int)
    } else if d.is::<bool>() {
        Literal::Known(FieldType::Bool)
    } else if d.is::<rhai::ImmutableString>() {
        Literal::Str
    } else {
        Literal::Other
    }
}
