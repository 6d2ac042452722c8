//! Conditions as designers read them (`hunger > 0.6 and sees food`): the text of a behavior's
//! `when` and `done`, shown as the cause of a transition. Built once at load.

use super::*;
use std::fmt::Write as _;

/// Human-readable text of a condition, e.g. `hunger > 0.6 and sees food`.
pub fn describe(c: &Cond) -> String {
    let mut s = String::new();
    describe_into(c, &mut s);
    s
}

fn value_text(v: &Value) -> String {
    match v {
        Value::Const(x) => format!("{x}"),
        Value::Drive(d) => format!("{d:?}").to_lowercase(),
        Value::Distance(c) => format!("distance to {}", c.name()),
        Value::Count(c) => format!("number of {}", c.name()),
        Value::Strength(c) => format!("strength of {}", c.name()),
        Value::Speed => "speed".into(),
        Value::TimeInBehavior => "time in behavior".into(),
        Value::Attribute(a) => format!("{a:?}").to_lowercase(),
        Value::KinSpeed => "school speed".into(),
        Value::OneMinus(x) => format!("1 - {}", value_text(x)),
        Value::Mul(a, b) => format!("{} * {}", value_text(a), value_text(b)),
        Value::Add(a, b) => format!("({} + {})", value_text(a), value_text(b)),
        Value::Script(n) => format!("{n}()"),
    }
}

fn describe_into(c: &Cond, s: &mut String) {
    let join = |v: &Vec<Cond>, sep: &str, s: &mut String| {
        for (i, c) in v.iter().enumerate() {
            if i > 0 {
                s.push_str(sep);
            }
            let nested = matches!(c, Cond::All(_) | Cond::Any(_));
            if nested {
                s.push('(');
            }
            describe_into(c, s);
            if nested {
                s.push(')');
            }
        }
    };
    match c {
        Cond::Always => s.push_str("always"),
        Cond::Never => s.push_str("never"),
        Cond::All(v) => join(v, " and ", s),
        Cond::Any(v) => join(v, " or ", s),
        Cond::Not(c) => {
            s.push_str("not (");
            describe_into(c, s);
            s.push(')');
        }
        Cond::Above(v, x) => {
            let _ = write!(s, "{} > {x}", value_text(v));
        }
        Cond::Below(v, x) => {
            let _ = write!(s, "{} < {x}", value_text(v));
        }
        Cond::Latch { on, off } => {
            s.push_str("latched on (");
            describe_into(on, s);
            s.push_str(") until (");
            describe_into(off, s);
            s.push(')');
        }
        Cond::Sees(k) => {
            let _ = write!(s, "sees {}", k.name());
        }
        Cond::Smells(k) => {
            let _ = write!(s, "smells {}", k.name());
        }
        Cond::Perceives(k) => {
            let _ = write!(s, "perceives {}", k.name());
        }
        Cond::Within(k, d) => {
            let _ = write!(s, "{} within {d}", k.name());
        }
        Cond::InSector(k, v) => {
            let names: Vec<&str> = v.iter().map(|x| x.name()).collect();
            let _ = write!(s, "{} in {}", k.name(), names.join(" or "));
        }
        Cond::AtLevel(k, v) => {
            let names: Vec<&str> = v.iter().map(|x| x.name()).collect();
            let _ = write!(s, "{} at {}", k.name(), names.join(" or "));
        }
        Cond::EscapeDone => s.push_str("predator behind and out of sight"),
        Cond::ObstacleNear => s.push_str("obstacle pressure above M_min"),
        Cond::TrafficNear => s.push_str("moving obstacle pressure above M_min"),
        Cond::Heard(MessageRef::Kind(m)) => {
            let _ = write!(s, "heard {}", m.name());
        }
        Cond::Heard(MessageRef::Event(n)) => {
            let _ = write!(s, "heard {n}");
        }
        Cond::TimeIn(t) => {
            let _ = write!(s, "{t} s in behavior");
        }
        Cond::Chance(p) => {
            let _ = write!(s, "chance {p}/s");
        }
        Cond::NearBounds(m) => {
            let _ = write!(s, "within {m} of the bounds");
        }
        Cond::Script(n) => {
            let _ = write!(s, "{n}()");
        }
        Cond::Contacted => s.push_str("contact made"),
        Cond::AtStation(d) => {
            let _ = write!(s, "within {d} of its station");
        }
    }
}
