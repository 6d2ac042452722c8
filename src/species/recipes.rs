//! Steering recipes of a species, resolved into [`RecipeNode`]s with every primitive's numbers
//! checked against its seed's ranges (seeds 000 §4, 001, 002, 003). Part of validation; reads
//! only the species file.

use super::validate::Builder;
use super::*;
use crate::load::NumberCheck;
use crate::params::steering::AvoidParams;

impl Builder<'_> {
    pub(super) fn recipe(&mut self, r: &Recipe) -> RecipeNode {
        match r {
            Recipe::Priority(v) => {
                if v.is_empty() {
                    self.error_at("Priority", "`Priority` needs at least one entry".into());
                }
                RecipeNode::Priority(v.iter().map(|r| self.recipe(r)).collect())
            }
            Recipe::Blend(v) => {
                if v.is_empty() {
                    self.error_at("Blend", "`Blend` needs at least one entry".into());
                }
                RecipeNode::Blend(
                    v.iter()
                        .map(|w| {
                            self.nums.enter("w");
                            self.nums.finite("w", w.w);
                            (
                                w.w,
                                w.by.as_ref().map(|b| self.value(b)),
                                self.recipe(&w.steer),
                            )
                        })
                        .collect(),
                )
            }
            Recipe::Script(name) => RecipeNode::Script(self.slot(name, SlotKind::Steer)),
            leaf => {
                self.leaf_numbers(leaf);
                match leaf {
                    Recipe::Chase(c) => self.check_category_at(c.target, "`Chase`", "Chase("),
                    Recipe::Escape(e) => self.check_category_at(e.from, "`Escape`", "Escape("),
                    Recipe::EscapeMirror(e) => {
                        self.check_category_at(e.from, "`EscapeMirror`", "EscapeMirror(")
                    }
                    Recipe::Pursue(p) => self.check_category_at(p.target, "`Pursue`", "Pursue("),
                    Recipe::Seek(s) | Recipe::Flee(s) | Recipe::Arrive(s) => {
                        if let Target::Nearest(c) | Target::Centroid(c) = s.target {
                            self.check_category(c, "the target")
                        }
                    }
                    _ => {}
                }
                // Avoidance written without parameters uses the species' `avoid` constants.
                match leaf {
                    Recipe::AvoidStatic(p) if *p == AvoidParams::default() => {
                        RecipeNode::Leaf(Recipe::AvoidStatic(self.def.avoid))
                    }
                    Recipe::AvoidDynamic(p) if *p == AvoidParams::default() => {
                        RecipeNode::Leaf(Recipe::AvoidDynamic(self.def.avoid))
                    }
                    _ => RecipeNode::Leaf(leaf.clone()),
                }
            }
        }
    }

    /// The numbers of a recipe primitive (`leaf`), located from its name on.
    pub(super) fn leaf_numbers(&mut self, leaf: &Recipe) {
        let n = &mut self.nums;
        let escape = |n: &mut NumberCheck, e: &EscapeDef| {
            use std::f32::consts::{FRAC_PI_2, PI};
            n.range("level_band", e.level_band, 0.0, FRAC_PI_2);
            n.range("max_pitch", e.max_pitch, 0.0, FRAC_PI_2);
            n.range("speed_floor", e.speed_floor, 0.0, 1.0);
            n.range("turn", e.turn, 0.0, PI);
            n.range("vision_turn", e.vision_turn, 0.0, PI);
            n.range("front", e.front, 0.0, FRAC_PI_2);
            n.range("smell_brake", e.smell_brake, 0.0, 1.0);
            n.range("far_speed", e.far_speed, 0.0, 1.0);
        };
        let seek = |n: &mut NumberCheck, s: &SeekDef| {
            n.non_negative("slow_radius", s.slow_radius);
            n.non_negative("speed", s.speed);
            if let Target::Point(p) = s.target {
                n.point("Point", &p.to_array());
            }
        };
        let group = |n: &mut NumberCheck, g: &GroupRuleDef| {
            n.finite("k", g.k);
            n.finite("factor", g.factor);
            n.non_negative_or_inf("radius", g.radius);
        };
        let look = |n: &mut NumberCheck, l: &LookAheadDef| {
            n.non_negative("horizon", l.horizon);
            n.finite("margin", l.margin);
        };
        match leaf {
            Recipe::AvoidStatic(p) => {
                n.enter("AvoidStatic");
                check_avoid(n, p)
            }
            Recipe::AvoidDynamic(p) => {
                n.enter("AvoidDynamic");
                check_avoid(n, p)
            }
            Recipe::PredictCollision(l) => {
                n.enter("PredictCollision");
                look(n, l)
            }
            Recipe::Contain(l) => {
                n.enter("Contain");
                look(n, l)
            }
            Recipe::Chase(c) => {
                n.enter("Chase");
                use std::f32::consts::{FRAC_PI_2, PI};
                n.non_negative("d0", c.d0);
                n.positive("max_turn", c.max_turn);
                n.range("turn", c.turn, 0.0, PI);
                n.range("rear_turn", c.rear_turn, 0.0, PI);
                // Front sector within ±π/2, rear sectors from ±π/2 on.
                n.range("front", c.front, 0.0, FRAC_PI_2);
                n.range("rear", c.rear, FRAC_PI_2, PI);
            }
            Recipe::Escape(e) => {
                n.enter("Escape");
                escape(n, e)
            }
            Recipe::EscapeMirror(e) => {
                n.enter("EscapeMirror");
                escape(n, e)
            }
            Recipe::Seek(s) => {
                n.enter("Seek");
                seek(n, s)
            }
            Recipe::Flee(s) => {
                n.enter("Flee");
                seek(n, s)
            }
            Recipe::Arrive(s) => {
                n.enter("Arrive");
                seek(n, s)
            }
            Recipe::HoldStation(h) => {
                n.enter("HoldStation");
                n.non_negative("slow_radius", h.slow_radius);
                n.non_negative("speed", h.speed);
            }
            Recipe::Separation(g) => {
                n.enter("Separation");
                group(n, g)
            }
            Recipe::Alignment(g) => {
                n.enter("Alignment");
                group(n, g)
            }
            Recipe::Cohesion(g) => {
                n.enter("Cohesion");
                group(n, g)
            }
            Recipe::Zones(z) => {
                n.enter("Zones");
                // Seed 003 needs r_r < r_m < r_a: equal radii leave a zone empty, reversed ones
                // make repulsion win where attraction was meant.
                if n.non_negative("repulsion", z.repulsion)
                    & n.non_negative("matching", z.matching)
                    & n.non_negative("attraction", z.attraction)
                {
                    for (lo_key, lo, hi_key, hi) in [
                        ("repulsion", z.repulsion, "matching", z.matching),
                        ("matching", z.matching, "attraction", z.attraction),
                    ] {
                        if lo >= hi {
                            n.error(
                                lo_key,
                                format!(
                                    "`{lo_key}` ({lo}) must be below `{hi_key}` ({hi}): \
                                     seed 003's zones need repulsion < matching < attraction"
                                ),
                            );
                        }
                    }
                }
                // The soft band is a fraction of r_r; 1 would make the whole zone a ramp
                // starting at 0 distance.
                if z.soft.is_nan() || !(0.0..1.0).contains(&z.soft) {
                    n.error(
                        "soft",
                        format!(
                            "`soft` must be a number from 0 up to (not including) 1, not {}",
                            z.soft
                        ),
                    );
                }
            }
            Recipe::Vicsek(v) => {
                n.enter("Vicsek");
                n.non_negative("radius", v.radius);
                n.non_negative("noise", v.noise);
                n.non_negative("speed", v.speed);
            }
            Recipe::Disperse(d) => {
                n.enter("Disperse");
                n.non_negative("below", d.below);
            }
            Recipe::Wander(w) => {
                n.enter("Wander");
                n.non_negative("yaw_jitter", w.yaw_jitter);
                n.non_negative("pitch_jitter", w.pitch_jitter);
                n.non_negative("level_bias", w.level_bias);
                n.non_negative("cruise", w.cruise);
            }
            Recipe::Cruise(c) => {
                n.enter("Cruise");
                n.non_negative("speed", c.speed);
            }
            Recipe::FollowPlan(c) => {
                n.enter("FollowPlan");
                n.non_negative("speed", c.speed);
            }
            Recipe::Pursue(_)
            | Recipe::Stop
            | Recipe::Priority(_)
            | Recipe::Blend(_)
            | Recipe::Script(_) => {}
        }
    }
}

/// Avoidance constants (seed 000 §4.1–§4.2), of a primitive or of the species' `avoid`: the
/// braking factor a fraction, the dynamic `M_min` factor `1 − cos(half-angle)` of some view, so
/// in [0, 2].
pub(super) fn check_avoid(n: &mut NumberCheck, p: &AvoidParams) {
    n.non_negative("m0", p.m0);
    n.range("turn", p.turn, 0.0, std::f32::consts::PI);
    if let Some(r) = p.range {
        n.non_negative("range", r);
    }
    n.range("brake_floor", p.brake_floor, 0.0, 1.0);
    n.range("brake", p.brake, 0.0, 1.0);
    if let Some(f) = p.m_min_factor {
        n.range("m_min_factor", f, 0.0, 2.0);
    }
}
