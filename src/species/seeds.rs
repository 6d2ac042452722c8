//! Every constant of the five source documents (`../shared/SEEDS.md`) that a species or scenario
//! file can override: its key, the engine's default, the paper's value and the section it comes
//! from. The designers' reference lists the same table (`behaviors/README.md`, "Seed
//! constants"); `tests/designer_reference.rs` keeps the two equal and checks that each species
//! key exists in the format with that default.
//!
//! A default read here comes from the `Default` of the type that holds the key, so the table
//! cannot drift from the code. A default that differs from the paper's value says why in the
//! reference.

use crate::drives::DriveParams;
use crate::params::steering::{AvoidParams, PAPER_M_MIN_FACTOR};
use crate::perception::SenseParams;
use crate::species::{ChaseDef, EscapeDef};

/// One overridable seed constant.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedConstant {
    /// Where it is written: `senses.vision_half_angle` (a species key, dotted path), `Chase(max_turn)`
    /// (a parameter of a steering primitive or condition), `squads[].…` (a scenario key).
    pub key: &'static str,
    /// The engine's default.
    pub default: f32,
    /// The paper's value (`None`: the paper names the constant without a number).
    pub paper: Option<f32>,
    /// Source document and section: `000 §4.1`.
    pub seed: &'static str,
}

fn c(key: &'static str, default: f32, paper: Option<f32>, seed: &'static str) -> SeedConstant {
    SeedConstant {
        key,
        default,
        paper,
        seed,
    }
}

/// The seed constants, grouped by the part of the engine that uses them.
pub fn seed_constants() -> Vec<SeedConstant> {
    use std::f32::consts::{FRAC_PI_4, FRAC_PI_6, FRAC_PI_8};
    let senses = SenseParams::default();
    let drives = DriveParams::default();
    let avoid = AvoidParams::default();
    let chase = ChaseDef::default();
    let escape = EscapeDef::default();
    let mut out = Vec::new();

    // Perception (000 §1, 001, 002).
    out.extend([c(
        "senses.vision_half_angle",
        senses.vision_half_angle,
        Some(150f32.to_radians()),
        "000 §1",
    )]);
    // Perceived strength (001: inverse square, or cube: power 3) and the direction sectors that
    // conditions and scripts read (000 §4.3).
    out.extend([
        c(
            "senses.strength.power",
            senses.strength.power,
            Some(crate::perception::strength::PAPER_POWER),
            "001",
        ),
        c(
            "senses.sectors.front",
            senses.sectors.front,
            Some(FRAC_PI_6),
            "000 §4.3",
        ),
        c(
            "senses.sectors.rear",
            senses.sectors.rear,
            Some(5.0 * FRAC_PI_6),
            "000 §4.3",
        ),
    ]);

    // Perception volume and focus (002; the focuser of 000 §1 has no number).
    out.extend([c(
        "Superquadric(exponent)",
        crate::perception::volume::DEFAULT_EXPONENT,
        None,
        "002",
    )]);

    // Drives (000 §2, 003).
    out.extend([
        c("drives.params.p0", drives.p0, Some(0.00067), "000 §2"),
        c("drives.params.p1", drives.p1, Some(0.0025), "000 §2"),
        c("drives.params.d0", drives.d0, Some(200.0), "000 §2"),
        c("drives.params.a_h", drives.a_h, None, "000 §2"),
        c("drives.params.a_l", drives.a_l, None, "000 §2"),
        c("drives.params.u", drives.u, None, "003"),
        c("drives.params.rho0", drives.rho0, None, "003"),
        c("drives.params.c", drives.c, None, "003"),
        c("drives.params.s_max", drives.s_max, None, "003"),
        c("drives.params.delta", drives.delta, None, "003"),
    ]);

    // Obstacle avoidance, move to goal and escape (000 §4).
    out.extend([
        c("avoid.m0", avoid.m0, None, "000 §4.1"),
        c("avoid.turn", avoid.turn, Some(FRAC_PI_8), "000 §4.1"),
        c("avoid.brake", avoid.brake, Some(0.5), "000 §4.1"),
        // Derived from the species' view: the number shown is the default view's (150°).
        c(
            "AvoidDynamic(m_min_factor)",
            avoid.dynamic_m_min_factor(senses.vision_half_angle),
            Some(PAPER_M_MIN_FACTOR),
            "000 §4.2",
        ),
        c(
            "Chase(max_turn)",
            chase.max_turn,
            Some(FRAC_PI_4),
            "000 §4.3",
        ),
        c("Chase(turn)", chase.turn, Some(FRAC_PI_8), "000 §4.3"),
        c(
            "Chase(rear_turn)",
            chase.rear_turn,
            Some(FRAC_PI_4),
            "000 §4.3",
        ),
        c("Chase(front)", chase.front, Some(FRAC_PI_6), "000 §4.3"),
        c("Chase(rear)", chase.rear, Some(5.0 * FRAC_PI_6), "000 §4.3"),
        c("Escape(turn)", escape.turn, Some(FRAC_PI_8), "000 §4.4"),
        c(
            "Escape(vision_turn)",
            escape.vision_turn,
            Some(FRAC_PI_4),
            "000 §4.4",
        ),
        c("Escape(front)", escape.front, Some(FRAC_PI_6), "000 §4.4"),
        c(
            "Escape(smell_brake)",
            escape.smell_brake,
            Some(0.5),
            "000 §4.4",
        ),
        c("Escape(far_speed)", escape.far_speed, Some(0.5), "000 §4.4"),
    ]);

    // Schooling and group rules (001, 003).
    let vicsek = crate::species::VicsekDef::default();
    let disperse = crate::species::DisperseDef::default();
    out.extend([
        c("Vicsek(radius)", vicsek.radius, None, "003"),
        c("Vicsek(noise)", vicsek.noise, None, "003"),
        c("Disperse(below)", disperse.below, None, "003"),
    ]);

    // Formation planning (004).
    let plan = crate::formation::PlanningParams::default();
    out.extend([
        c(
            "squads[].planning.relax_step",
            plan.relax_step,
            Some(0.1),
            "004",
        ),
        c("squads[].planning.fm_broken", plan.fm_broken, None, "004"),
        c(
            "squads[].planning.must_keep.k1",
            plan.must_keep.k1,
            Some(0.05),
            "004",
        ),
        c(
            "squads[].planning.must_keep.k2",
            plan.must_keep.k2,
            Some(0.95),
            "004",
        ),
        c(
            "squads[].planning.may_change_rarely.k1",
            plan.may_change_rarely.k1,
            Some(0.1),
            "004",
        ),
        c(
            "squads[].planning.may_change_rarely.k2",
            plan.may_change_rarely.k2,
            Some(0.9),
            "004",
        ),
        c(
            "squads[].planning.shortest_first.k1",
            plan.shortest_first.k1,
            Some(0.9),
            "004",
        ),
        c(
            "squads[].planning.shortest_first.k2",
            plan.shortest_first.k2,
            Some(0.1),
            "004",
        ),
    ]);

    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_unique() {
        let all = seed_constants();
        for (i, a) in all.iter().enumerate() {
            assert!(
                all[i + 1..].iter().all(|b| b.key != a.key),
                "{} listed twice",
                a.key
            );
        }
    }
}
