//! Formations as data and the formation function, seed 004 ("formation function H", "a leader
//! is chosen by slot, by role or at random, and kept").
//!
//! Not a tick stage: read once when a team is defined, then evaluated by path planning and by
//! whoever steers members to their slots. A slot is `(forward, right)` relative to the formation's
//! frame; the formation function puts member `i` at
//! `leader_pos + heading · (fᵢ − f_leader) + right(heading) · (rᵢ − r_leader)`, where
//! `right(heading)` is the heading turned 90° clockwise seen from above (+Y): heading north (−Z)
//! has east (+X) on its right.

use crate::terrain::SplitMix64;
use glam::Vec2;
use serde::{Deserialize, Serialize};

/// The geometry of a formation; every built-in is given in units of the formation's spacing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum FormationShape {
    /// Abreast, centred on slot 0, then alternately right and left outwards.
    Line,
    /// Single file behind slot 0.
    Column,
    /// A "V" opening backwards from slot 0 at the apex: pairs right then left, one row back each.
    Wedge,
    /// A filled triangle from slot 0 at the apex: row `k` back holds `k + 1` members.
    Triangle,
    /// Slot 0 in the centre, then diamond rings (front, right, rear, left on the first ring).
    Diamond,
    /// Explicit `(forward, right)` slots in units of spacing, one per member.
    Custom(Vec<(f32, f32)>),
}

impl FormationShape {
    /// Slots `(forward, right)` in units of spacing for `members` members.
    fn unit_slots(&self, members: usize) -> Vec<Vec2> {
        match self {
            FormationShape::Line => {
                let mut p: Vec<f32> = (0..members)
                    .map(|j| j as f32 - (members as f32 - 1.0) / 2.0)
                    .collect();
                // Centre first, then outwards, right before left.
                p.sort_by(|a, b| a.abs().total_cmp(&b.abs()).then(b.total_cmp(a)));
                p.into_iter().map(|r| Vec2::new(0.0, r)).collect()
            }
            FormationShape::Column => (0..members).map(|i| Vec2::new(-(i as f32), 0.0)).collect(),
            FormationShape::Wedge => (0..members)
                .map(|i| {
                    let k = i.div_ceil(2) as f32;
                    let side = if i % 2 == 1 { 1.0 } else { -1.0 };
                    Vec2::new(-k, side * k)
                })
                .collect(),
            FormationShape::Triangle => {
                let mut out = Vec::with_capacity(members);
                let mut row = 0usize;
                while out.len() < members {
                    let mut across: Vec<f32> =
                        (0..=row).map(|j| j as f32 - row as f32 / 2.0).collect();
                    across.sort_by(|a, b| a.abs().total_cmp(&b.abs()).then(b.total_cmp(a)));
                    for r in across.into_iter().take(members - out.len()) {
                        out.push(Vec2::new(-(row as f32), r));
                    }
                    row += 1;
                }
                out
            }
            FormationShape::Diamond => {
                let mut out = vec![Vec2::ZERO];
                let mut k = 1i32;
                while out.len() < members {
                    // Clockwise from the front tip: front → right → rear → left.
                    for s in 0..4 * k {
                        let (quadrant, t) = (s / k, s % k);
                        let (f, r) = match quadrant {
                            0 => (k - t, t),
                            1 => (-t, k - t),
                            2 => (-k + t, -t),
                            _ => (t, -k + t),
                        };
                        out.push(Vec2::new(f as f32, r as f32));
                    }
                    k += 1;
                }
                out.truncate(members);
                out
            }
            FormationShape::Custom(slots) => slots.iter().map(|&(f, r)| Vec2::new(f, r)).collect(),
        }
    }
}

/// A formation as written in a team file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormationDef {
    /// A name for reports; defaults to the shape's.
    #[serde(default)]
    pub name: Option<String>,
    /// The geometry.
    pub shape: FormationShape,
    /// Distance between neighbouring slots in world units.
    #[serde(default = "default_spacing")]
    pub spacing: f32,
}

fn default_spacing() -> f32 {
    2.0
}

/// A validated formation: one slot per member, `(forward, right)` in world units.
#[derive(Debug, Clone, PartialEq)]
pub struct Formation {
    name: String,
    slots: Vec<Vec2>,
}

/// Why a formation or team definition is invalid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FormationError {
    /// The team has no members.
    #[error("a team needs at least one member")]
    NoMembers,
    /// The team has no formation.
    #[error("a team needs at least one formation")]
    NoFormations,
    /// A spacing that is not a positive number.
    #[error("formation {formation}: spacing must be a positive number, found {spacing}")]
    BadSpacing {
        /// 1-based formation number.
        formation: usize,
        /// The spacing given.
        spacing: f32,
    },
    /// A custom formation whose slot count differs from the member count.
    #[error("formation {formation}: {slots} slots for {members} members")]
    SlotCount {
        /// 1-based formation number.
        formation: usize,
        /// Slots given.
        slots: usize,
        /// Members in the team.
        members: usize,
    },
    /// A slot coordinate that is not finite.
    #[error("formation {formation}: slot coordinates must be finite")]
    BadSlot {
        /// 1-based formation number.
        formation: usize,
    },
    /// A leader slot beyond the team.
    #[error("leader slot {slot} is out of range for {members} members")]
    LeaderSlot {
        /// The slot asked for.
        slot: usize,
        /// Members in the team.
        members: usize,
    },
    /// A leader role no member has.
    #[error("no member has the role `{role}`; the roles are {roles}")]
    UnknownRole {
        /// The role asked for.
        role: String,
        /// The roles there are, comma-separated.
        roles: String,
    },
    /// Task weights out of range.
    #[error("task weights must satisfy 0 < K1 ≤ 1, 0 ≤ K2 ≤ 1, 0 < step ≤ 1, a finite fm_broken ≥ 1 and 1 ≤ search_weight ≤ 10; found K1 = {k1}, K2 = {k2}, step = {step}, fm_broken = {fm_broken}, search_weight = {search_weight}")]
    BadWeights {
        /// K1 given.
        k1: f32,
        /// K2 given.
        k2: f32,
        /// Relaxation step given.
        step: f32,
        /// Formation cost of an all-blocked step given.
        fm_broken: f32,
        /// Heuristic weight given.
        search_weight: f32,
    },
}

impl FormationError {
    /// The team-file key this error is about, to locate it.
    pub(crate) fn key(&self) -> &'static str {
        match self {
            FormationError::NoMembers => "members",
            FormationError::NoFormations
            | FormationError::BadSpacing { .. }
            | FormationError::SlotCount { .. }
            | FormationError::BadSlot { .. } => "formations",
            FormationError::LeaderSlot { .. } | FormationError::UnknownRole { .. } => "leader",
            FormationError::BadWeights { .. } => "task",
        }
    }
}

impl Formation {
    /// A formation of `shape` for `members` members, `spacing` world units apart.
    pub fn new(
        shape: &FormationShape,
        members: usize,
        spacing: f32,
    ) -> Result<Formation, FormationError> {
        FormationDef {
            name: None,
            shape: shape.clone(),
            spacing,
        }
        .validate(members, 1)
    }

    /// The formation's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of members (slots).
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether the formation has no slots.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// The slots `(forward, right)` in world units, in member order.
    pub fn slots(&self) -> &[Vec2] {
        &self.slots
    }

    /// Member `member`'s slot relative to the leader's, `(forward, right)` in world units.
    pub fn offset(&self, member: usize, leader: usize) -> Vec2 {
        self.slots[member] - self.slots[leader]
    }

    /// The formation function: member `member`'s world `(x, z)` when the leader (member `leader`)
    /// stands at `leader_pos` facing `heading` (any non-zero length).
    pub fn world_slot(
        &self,
        member: usize,
        leader: usize,
        leader_pos: Vec2,
        heading: Vec2,
    ) -> Vec2 {
        leader_pos + to_world(self.offset(member, leader), heading)
    }
}

/// Turns a `(forward, right)` offset into world `(x, z)` for a leader facing `heading`.
pub fn to_world(offset: Vec2, heading: Vec2) -> Vec2 {
    let f = heading.normalize_or(Vec2::new(0.0, -1.0));
    let right = Vec2::new(-f.y, f.x);
    f * offset.x + right * offset.y
}

impl FormationDef {
    /// Checks the definition for a team of `members` and builds the formation; `number` is its
    /// 1-based place in the team's list, for messages.
    pub fn validate(self, members: usize, number: usize) -> Result<Formation, FormationError> {
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(FormationError::BadSpacing {
                formation: number,
                spacing: self.spacing,
            });
        }
        if let FormationShape::Custom(s) = &self.shape {
            if s.len() != members {
                return Err(FormationError::SlotCount {
                    formation: number,
                    slots: s.len(),
                    members,
                });
            }
            if s.iter().any(|&(f, r)| !(f.is_finite() && r.is_finite())) {
                return Err(FormationError::BadSlot { formation: number });
            }
        }
        let name = self.name.unwrap_or_else(|| {
            match &self.shape {
                FormationShape::Custom(_) => "Custom",
                FormationShape::Line => "Line",
                FormationShape::Column => "Column",
                FormationShape::Wedge => "Wedge",
                FormationShape::Triangle => "Triangle",
                FormationShape::Diamond => "Diamond",
            }
            .to_string()
        });
        let slots = self
            .shape
            .unit_slots(members)
            .into_iter()
            .map(|s| s * self.spacing)
            .collect();
        Ok(Formation { name, slots })
    }
}

/// How the leader is chosen; once chosen it is kept for the whole plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum LeaderChoice {
    /// The member in this slot (0-based).
    Slot(usize),
    /// The first member with this role.
    Role(String),
    /// A member drawn with SplitMix64 from this seed.
    Random(u64),
}

impl Default for LeaderChoice {
    fn default() -> Self {
        LeaderChoice::Slot(0)
    }
}

impl LeaderChoice {
    /// The leader's member index in a team with these `roles`.
    pub fn resolve(&self, roles: &[String]) -> Result<usize, FormationError> {
        if roles.is_empty() {
            return Err(FormationError::NoMembers);
        }
        match self {
            LeaderChoice::Slot(s) if *s < roles.len() => Ok(*s),
            LeaderChoice::Slot(s) => Err(FormationError::LeaderSlot {
                slot: *s,
                members: roles.len(),
            }),
            LeaderChoice::Role(r) => {
                roles
                    .iter()
                    .position(|x| x == r)
                    .ok_or_else(|| FormationError::UnknownRole {
                        role: r.clone(),
                        roles: roles.join(", "),
                    })
            }
            LeaderChoice::Random(seed) => Ok(SplitMix64::new(*seed).below(roles.len())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn approx(a: Vec2, b: Vec2) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn built_in_shapes_place_members_as_named() {
        let w = Formation::new(&FormationShape::Wedge, 5, 2.0).unwrap();
        assert_eq!(
            w.slots(),
            &[
                Vec2::new(0.0, 0.0),
                Vec2::new(-2.0, 2.0),
                Vec2::new(-2.0, -2.0),
                Vec2::new(-4.0, 4.0),
                Vec2::new(-4.0, -4.0)
            ]
        );
        let l = Formation::new(&FormationShape::Line, 3, 1.0).unwrap();
        assert_eq!(
            l.slots(),
            &[Vec2::ZERO, Vec2::new(0.0, 1.0), Vec2::new(0.0, -1.0)]
        );
        let c = Formation::new(&FormationShape::Column, 3, 3.0).unwrap();
        assert_eq!(c.slots()[2], Vec2::new(-6.0, 0.0));
        let d = Formation::new(&FormationShape::Diamond, 5, 1.0).unwrap();
        assert_eq!(
            d.slots(),
            &[
                Vec2::ZERO,
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 1.0),
                Vec2::new(-1.0, 0.0),
                Vec2::new(0.0, -1.0)
            ]
        );
        let d12 = Formation::new(&FormationShape::Diamond, 12, 1.0).unwrap();
        assert_eq!(d12.len(), 12);
        assert!(d12.slots()[5..]
            .iter()
            .all(|s| s.x.abs() + s.y.abs() == 2.0));
        let t = Formation::new(&FormationShape::Triangle, 6, 1.0).unwrap();
        assert_eq!(
            t.slots()[3..],
            [
                Vec2::new(-2.0, 0.0),
                Vec2::new(-2.0, 1.0),
                Vec2::new(-2.0, -1.0)
            ]
        );
        // Every built-in gives distinct slots.
        for shape in [
            FormationShape::Line,
            FormationShape::Column,
            FormationShape::Wedge,
            FormationShape::Triangle,
            FormationShape::Diamond,
        ] {
            let f = Formation::new(&shape, 12, 1.0).unwrap();
            for i in 0..12 {
                for j in 0..i {
                    assert_ne!(f.slots()[i], f.slots()[j], "{shape:?}");
                }
            }
        }
    }

    #[test]
    fn formation_function_rotates_with_the_heading() {
        let w = Formation::new(&FormationShape::Wedge, 3, 1.0).unwrap();
        // Heading north (−Z): member 1 is one back (+Z) and one to the right (+X).
        assert!(approx(
            w.world_slot(1, 0, Vec2::new(10.0, 10.0), Vec2::new(0.0, -1.0)),
            Vec2::new(11.0, 11.0)
        ));
        // Heading east (+X): right is south (+Z).
        assert!(approx(
            w.world_slot(1, 0, Vec2::ZERO, Vec2::new(3.0, 0.0)),
            Vec2::new(-1.0, 1.0)
        ));
        // With member 1 as leader, member 0 is one ahead and one to the left of it.
        assert!(approx(
            w.world_slot(0, 1, Vec2::ZERO, Vec2::new(1.0, 0.0)),
            Vec2::new(1.0, -1.0)
        ));
        assert!(approx(
            w.world_slot(1, 1, Vec2::new(4.0, 5.0), Vec2::new(1.0, 1.0)),
            Vec2::new(4.0, 5.0)
        ));
    }

    #[test]
    fn leader_by_slot_role_or_seeded_draw() {
        let roles: Vec<String> = ["scout", "medic", "rifle"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(LeaderChoice::Slot(2).resolve(&roles), Ok(2));
        assert_eq!(LeaderChoice::Role("medic".into()).resolve(&roles), Ok(1));
        assert_eq!(
            LeaderChoice::Role("cook".into())
                .resolve(&roles)
                .unwrap_err()
                .to_string(),
            "no member has the role `cook`; the roles are scout, medic, rifle"
        );
        assert!(LeaderChoice::Slot(3).resolve(&roles).is_err());
        let a = LeaderChoice::Random(42).resolve(&roles).unwrap();
        assert_eq!(LeaderChoice::Random(42).resolve(&roles).unwrap(), a);
        let drawn: std::collections::BTreeSet<usize> = (0..32)
            .map(|s| LeaderChoice::Random(s).resolve(&roles).unwrap())
            .collect();
        assert_eq!(drawn.len(), 3, "every member can be drawn");
    }

    #[test]
    fn custom_shapes_are_checked() {
        let def = FormationDef {
            name: None,
            shape: FormationShape::Custom(vec![(0.0, 0.0), (-1.0, 0.5)]),
            spacing: 2.0,
        };
        assert_eq!(
            def.clone().validate(3, 2).unwrap_err().to_string(),
            "formation 2: 2 slots for 3 members"
        );
        let f = def.validate(2, 1).unwrap();
        assert_eq!(f.name(), "Custom");
        assert_eq!(f.slots()[1], Vec2::new(-2.0, 1.0));
        assert!(Formation::new(&FormationShape::Line, 2, 0.0).is_err());
    }
}
