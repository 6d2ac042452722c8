//! Conditions and values of a species' behaviors, resolved into native evaluators (seed 000 §3)
//! with their numbers checked; and a behavior's `focus` (seed 000 §1) checked against what its
//! steering targets. Part of validation; reads only the species file.

use super::validate::Builder;
use super::*;
use crate::params::decision::Focus;

/// The categories a recipe's primitives steer by, with the primitive's name: what a `focus`
/// must keep for the behavior to steer at all.
fn steered_by(r: &Recipe, out: &mut Vec<(Category, &'static str)>) {
    let target = |t: &Target| match *t {
        Target::Nearest(c) | Target::Centroid(c) => Some(c),
        Target::Point(_) | Target::Home | Target::Station => None,
    };
    let need = match r {
        Recipe::Priority(v) => {
            v.iter().for_each(|r| steered_by(r, out));
            None
        }
        Recipe::Blend(v) => {
            v.iter().for_each(|w| steered_by(&w.steer, out));
            None
        }
        Recipe::Chase(c) => Some((c.target, "Chase")),
        Recipe::Escape(e) => Some((e.from, "Escape")),
        Recipe::EscapeMirror(e) => Some((e.from, "EscapeMirror")),
        Recipe::Pursue(p) => Some((p.target, "Pursue")),
        Recipe::Seek(s) => target(&s.target).map(|c| (c, "Seek")),
        Recipe::Flee(s) => target(&s.target).map(|c| (c, "Flee")),
        Recipe::Arrive(s) => target(&s.target).map(|c| (c, "Arrive")),
        Recipe::AvoidStatic(_) => Some((Category::Obstacle, "AvoidStatic")),
        Recipe::PredictCollision(_) => Some((Category::Obstacle, "PredictCollision")),
        Recipe::Separation(_) => Some((Category::Kin, "Separation")),
        Recipe::Alignment(_) => Some((Category::Kin, "Alignment")),
        Recipe::Cohesion(_) => Some((Category::Kin, "Cohesion")),
        Recipe::Zones(_) => Some((Category::Kin, "Zones")),
        Recipe::Vicsek(_) => Some((Category::Kin, "Vicsek")),
        // Moving obstacles are any agent; the rest read no percept.
        _ => None,
    };
    out.extend(need);
}

impl Builder<'_> {
    /// A behavior's `focus` (seed 000 §1): not empty, and holding every category its own
    /// steering targets (a `Chase(target: Food)` focused away from food would never move).
    pub(super) fn focus(&mut self, b: &BehaviorDef, list: &[Category]) -> Focus {
        if list.is_empty() {
            self.error_at(
                "focus",
                format!(
                    "behavior \"{}\": `focus` lists no category, so its steering would see \
                     nothing: list what it steers by, or leave `focus` out to see everything",
                    b.name
                ),
            );
        }
        let focus = Focus::of(list);
        let mut needs = Vec::new();
        if let Some(steer) = &b.steer {
            steered_by(steer, &mut needs);
        }
        let mut reported = Vec::new();
        for (c, what) in needs {
            if !focus.contains(c) && !reported.contains(&c) {
                reported.push(c);
                self.error_at(
                    "focus",
                    format!(
                        "behavior \"{}\": `focus` leaves out `{c:?}`, which its `{what}` \
                         steers by: add `{c:?}` to the list",
                        b.name
                    ),
                );
            }
        }
        focus
    }

    pub(super) fn value(&mut self, v: &Value) -> ValueNode {
        match v {
            Value::Const(x) => {
                self.nums.enter("Const");
                self.nums.finite("Const", *x);
                ValueNode::Const(*x)
            }
            Value::Drive(d) => ValueNode::Drive(*d),
            Value::Distance(c) => {
                self.check_category(*c, "`Distance`");
                ValueNode::Distance(*c)
            }
            Value::Count(c) => {
                self.check_category(*c, "`Count`");
                ValueNode::Count(*c)
            }
            Value::Strength(c) => {
                self.check_category(*c, "`Strength`");
                ValueNode::Strength(*c)
            }
            Value::Speed => ValueNode::Speed,
            Value::TimeInBehavior => ValueNode::TimeInBehavior,
            Value::Attribute(a) => ValueNode::Attribute(*a),
            Value::KinSpeed => ValueNode::KinSpeed,
            Value::OneMinus(x) => ValueNode::OneMinus(Box::new(self.value(x))),
            Value::Mul(a, b) => ValueNode::Mul(Box::new(self.value(a)), Box::new(self.value(b))),
            Value::Add(a, b) => ValueNode::Add(Box::new(self.value(a)), Box::new(self.value(b))),
            Value::Script(name) => ValueNode::Script(self.slot(name, SlotKind::Number)),
        }
    }

    pub(super) fn cond(&mut self, c: &Cond) -> CondNode {
        match c {
            Cond::Always => CondNode::Always,
            Cond::Never => CondNode::Never,
            Cond::All(v) => CondNode::All(v.iter().map(|c| self.cond(c)).collect()),
            Cond::Any(v) => CondNode::Any(v.iter().map(|c| self.cond(c)).collect()),
            Cond::Not(c) => CondNode::Not(Box::new(self.cond(c))),
            Cond::Above(v, x) => {
                let here = self.nums.enter("Above");
                let v = self.value(v);
                // The threshold is checked at this `Above`, not at what its value entered.
                let after = std::mem::replace(&mut self.nums.from, here);
                self.nums.finite("Above", *x);
                self.nums.from = after;
                CondNode::Above(v, *x)
            }
            Cond::Below(v, x) => {
                let here = self.nums.enter("Below");
                let v = self.value(v);
                // The threshold is checked at this `Below`, not at what its value entered.
                let after = std::mem::replace(&mut self.nums.from, here);
                self.nums.finite("Below", *x);
                self.nums.from = after;
                CondNode::Below(v, *x)
            }
            Cond::Latch { on, off } => {
                let bit = self.latches;
                if bit >= 64 {
                    self.error_at(
                        "Latch",
                        "more than 64 `Latch` conditions in one species".into(),
                    );
                }
                self.latches = self.latches.saturating_add(1);
                CondNode::Latch {
                    bit: bit.min(63),
                    on: Box::new(self.cond(on)),
                    off: Box::new(self.cond(off)),
                }
            }
            Cond::Sees(k) => {
                self.check_category(*k, "`Sees`");
                CondNode::Sees(*k)
            }
            Cond::Smells(k) => {
                self.check_category(*k, "`Smells`");
                CondNode::Smells(*k)
            }
            Cond::Perceives(k) => {
                self.check_category(*k, "`Perceives`");
                CondNode::Perceives(*k)
            }
            Cond::Within(k, d) => {
                self.nums.enter("Within");
                self.nums.non_negative("Within", *d);
                self.check_category(*k, "`Within`");
                CondNode::Within(*k, *d)
            }
            Cond::InSector(k, sectors) => {
                self.check_category(*k, "`InSector`");
                if sectors.is_empty() {
                    self.error_at(
                        "InSector",
                        "`InSector` lists no sector, so it is never true: list one or more of \
                         Front, LeftFront, RightFront, LeftRear, RightRear, Rear"
                            .into(),
                    );
                }
                let mask = sectors
                    .iter()
                    .fold(0, |m, s| m | crate::params::decision::sector_bit(*s));
                CondNode::InSector(*k, mask)
            }
            Cond::AtLevel(k, levels) => {
                self.check_category(*k, "`AtLevel`");
                if levels.is_empty() {
                    self.error_at(
                        "AtLevel",
                        "`AtLevel` lists no level, so it is never true: list one or more of \
                         Above, Level, Below"
                            .into(),
                    );
                }
                let mask = levels
                    .iter()
                    .fold(0, |m, l| m | crate::params::decision::level_bit(*l));
                CondNode::AtLevel(*k, mask)
            }
            Cond::EscapeDone => CondNode::EscapeDone,
            Cond::ObstacleNear => CondNode::ObstacleNear,
            Cond::TrafficNear => CondNode::TrafficNear,
            Cond::Heard(m) => CondNode::Heard(self.signal(m, "Heard")),
            Cond::TimeIn(t) => {
                self.nums.enter("TimeIn");
                self.nums.non_negative("TimeIn", *t);
                CondNode::TimeIn(*t)
            }
            Cond::Chance(p) => {
                self.nums.enter("Chance");
                self.nums.non_negative("Chance", *p);
                CondNode::Chance(*p)
            }
            Cond::NearBounds(m) => {
                self.nums.enter("NearBounds");
                self.nums.finite("NearBounds", *m);
                CondNode::NearBounds(*m)
            }
            Cond::Script(name) => CondNode::Script(self.slot(name, SlotKind::Bool)),
            Cond::Contacted => CondNode::Contacted,
            Cond::AtStation(d) => {
                self.nums.enter("AtStation");
                self.nums.non_negative("AtStation", *d);
                CondNode::AtStation(*d)
            }
        }
    }
}
