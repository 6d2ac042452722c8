//! Formation-keeping path planning for a team on real terrain, seed 004.
//!
//! Not a tick stage: path planning, called by the runtime when a team is given a goal; it reads a
//! [`CostGrid`] and knows nothing of agents or the world. The steps are the source's:
//! set K1, K2 and the may-change flag from the task class ([`TaskClass`]); choose and keep a
//! leader ([`LeaderChoice`]); plan the leader with formation-aware A* ([`astar`]), relaxing
//! `K2 −= 0.1, K1 += 0.1` after each failure while the formation may change; smooth the leader's
//! path into the key-point and formation-transition tables ([`smooth`]); derive every member's
//! path from them ([`follow`]).
//!
//! One step the source does not have: the source checks a formation at the leader's nodes only,
//! but a member walks straight from one waypoint to the next, and at a corner (its waypoint faces
//! the next leg) its way can cross a wall beside a clear leader path. After smoothing, every
//! follower's leg is checked ([`follow::leg_passable`]); where one crosses a blocked cell and the
//! formation may change, each node of that leg may only take a formation narrower than the one
//! it took, and the path is laid out again, until no leg crosses a wall or nothing narrower is
//! left. [`smooth::formation_along`] and [`smooth::smooth`] without that floor are the source's
//! form.
//!
//! ```
//! use shoal::formation::{Formation, PlanRequest, Planner, FormationShape, TaskClass};
//! use shoal::terrain::CostGrid;
//! use glam::Vec2;
//!
//! let grid = CostGrid::open(64, 64, 2.0, Vec2::ZERO);
//! let formations = [
//!     Formation::new(&FormationShape::Wedge, 5, 4.0).unwrap(),
//!     Formation::new(&FormationShape::Column, 5, 3.0).unwrap(),
//! ];
//! let mut planner = Planner::new();
//! let plan = planner
//!     .plan(&PlanRequest {
//!         grid: &grid,
//!         start: Vec2::new(20.0, 20.0),
//!         goal: Vec2::new(100.0, 90.0),
//!         formations: &formations,
//!         leader: 0,
//!         weights: TaskClass::MayChangeRarely.weights(),
//!     })
//!     .unwrap();
//! assert_eq!(plan.member_paths.len(), 5);
//! assert_eq!(plan.tried, vec![(0.1, 0.9)]);
//! ```

pub mod astar;
pub mod follow;
pub mod shape;
pub mod smooth;

pub use astar::{
    ClassFactors, GridFormations, LeaderSearch, Planner, PlanningParams, SlotOffsets, TaskClass,
    Weights, FM_BROKEN, RELAX_STEP,
};
pub use follow::{member_paths, MemberPath};
pub use shape::{Formation, FormationDef, FormationError, FormationShape, LeaderChoice};
pub use smooth::{FormationChange, KeyPoint};

use crate::diag::{Diagnostic, Diagnostics};
use crate::terrain::{Cell, CostGrid};
use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Everything one plan needs.
#[derive(Debug, Clone, Copy)]
pub struct PlanRequest<'a> {
    /// The planning grid (costs and blocked cells).
    pub grid: &'a CostGrid,
    /// The leader's start, world `(x, z)`.
    pub start: Vec2,
    /// The leader's goal, world `(x, z)`.
    pub goal: Vec2,
    /// The formations the team may take, preferred (and widest) first; the first is the one
    /// the formation term keeps. All must have the same number of members.
    pub formations: &'a [Formation],
    /// The leader's member index.
    pub leader: usize,
    /// Starting factors and the may-change flag.
    pub weights: Weights,
}

/// A team's plan: the leader's path, the two tables, every member's path, and the factors tried.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The leader's member index.
    pub leader: usize,
    /// The leader's A* path, cell by cell.
    pub leader_cells: Vec<Cell>,
    /// The same path as world `(x, z)` cell centres.
    pub leader_path: Vec<Vec2>,
    /// Per node of the leader path: the formation held (index into the list).
    pub formation_along: Vec<usize>,
    /// The key-point table (the smoothed leader path).
    pub key_points: Vec<KeyPoint>,
    /// The formation-transition table.
    pub transitions: Vec<FormationChange>,
    /// Every member's path, indexed by member (the leader's follows the key points).
    pub member_paths: Vec<MemberPath>,
    /// Per key point, the formation the members' slots take there (index into the list): the
    /// key point's own, or the one before a widening transition held over the leg after it
    /// ([`follow::held_formations`]).
    #[serde(default)]
    pub held: Vec<usize>,
    /// The `(K1, K2)` of each search, in order; the last one found the path.
    pub tried: Vec<(f32, f32)>,
    /// Terrain cost of the leader's path (step lengths in cells × cell costs).
    pub cost: f32,
    /// The successful search's minimised score `Σ len · (K1·cost + K2·FM)`.
    #[serde(default)]
    pub score: f32,
    /// Nodes expanded by the successful search.
    pub expanded: usize,
}

/// Why a plan could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The formation list is empty.
    #[error("the team has no formation to plan with")]
    NoFormations,
    /// Formations of different sizes.
    #[error("formation {formation} has {slots} slots but the team has {members} members")]
    MemberMismatch {
        /// 1-based number of the odd formation.
        formation: usize,
        /// Its slot count.
        slots: usize,
        /// The first formation's.
        members: usize,
    },
    /// A leader index outside the team.
    #[error("leader {leader} is not a member of a {members}-member team")]
    LeaderOutOfRange {
        /// The index given.
        leader: usize,
        /// Team size.
        members: usize,
    },
    /// Start or goal outside the grid.
    #[error("the {which} ({}, {}) lies outside the terrain", .pos.x, .pos.y)]
    Outside {
        /// `"start"` or `"goal"`.
        which: &'static str,
        /// The position given.
        pos: Vec2,
    },
    /// Start or goal on a blocked cell.
    #[error("the {which} ({}, {}) is on a blocked cell", .pos.x, .pos.y)]
    Blocked {
        /// `"start"` or `"goal"`.
        which: &'static str,
        /// The position given.
        pos: Vec2,
    },
    /// Invalid factors.
    #[error(transparent)]
    Weights(#[from] FormationError),
    /// No feasible path under any of the factors tried.
    #[error("no path keeps the formation from start to goal; tried (K1, K2) = {}", format_tried(.tried))]
    NoPath {
        /// The `(K1, K2)` of each failed search.
        tried: Vec<(f32, f32)>,
    },
}

fn format_tried(tried: &[(f32, f32)]) -> String {
    tried
        .iter()
        .map(|(a, b)| format!("({a}, {b})"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Planner {
    /// Plans the team: leader A* with relaxation, smoothing, follower paths.
    pub fn plan(&mut self, req: &PlanRequest<'_>) -> Result<Plan, PlanError> {
        let grid = req.grid;
        let members = req.formations.first().ok_or(PlanError::NoFormations)?.len();
        if let Some((i, f)) = req
            .formations
            .iter()
            .enumerate()
            .find(|(_, f)| f.len() != members)
        {
            return Err(PlanError::MemberMismatch {
                formation: i + 1,
                slots: f.len(),
                members,
            });
        }
        if req.leader >= members {
            return Err(PlanError::LeaderOutOfRange {
                leader: req.leader,
                members,
            });
        }
        let mut w = req.weights.validate()?;
        let cell = |which: &'static str, pos: Vec2| -> Result<Cell, PlanError> {
            let c = grid.cell_of(pos).ok_or(PlanError::Outside { which, pos })?;
            if grid.blocked[grid.index(c)] {
                return Err(PlanError::Blocked { which, pos });
            }
            Ok(c)
        };
        let (start, goal) = (cell("start", req.start)?, cell("goal", req.goal)?);
        let team = GridFormations::new(req.formations, req.leader, grid.cell_size);

        let mut tried = Vec::new();
        let found = loop {
            tried.push((w.k1, w.k2));
            if let Some(found) = self.search(grid, start, goal, &team, w) {
                break found;
            }
            match w.relaxed() {
                Some(next) => w = next,
                None => return Err(PlanError::NoPath { tried }),
            }
        };
        let laid = lay_out(grid, &found.cells, &team, w.may_change);

        Ok(Plan {
            leader: req.leader,
            leader_path: found.cells.iter().map(|&c| grid.center_of(c)).collect(),
            leader_cells: found.cells,
            formation_along: laid.along.iter().map(|&(f, _)| f).collect(),
            key_points: laid.key_points,
            transitions: laid.transitions,
            member_paths: laid.member_paths,
            held: laid.held,
            tried,
            cost: found.cost,
            score: found.score,
            expanded: found.expanded,
        })
    }
}

/// Side-to-side extent of a formation: its largest `right` offset minus its smallest.
fn width(f: &Formation) -> f32 {
    let (lo, hi) = f
        .slots()
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s.y), hi.max(s.y))
        });
    hi - lo
}

/// The first formation after `j` in the list that is narrower than formation `j` (a script may
/// list a narrow formation first: nothing after it is narrower).
fn narrower(formations: &[Formation], j: usize) -> Option<usize> {
    let w = width(&formations[j]);
    (j + 1..formations.len()).find(|&n| width(&formations[n]) < w)
}

/// A leader path laid out into the tables and the members' paths.
struct Laid {
    along: Vec<(usize, bool)>,
    key_points: Vec<KeyPoint>,
    transitions: Vec<FormationChange>,
    member_paths: Vec<MemberPath>,
    held: Vec<usize>,
}

/// Smooths `cells` and derives the members' paths; where a follower's leg crosses a blocked
/// cell and the formation may change, every node of that leg (the start node too on the first
/// leg) may only take formations from the next narrower one of the list on ([`narrower`]), and
/// the layout is done again, until no leg crosses a wall or no node of such a leg can narrow.
fn lay_out(grid: &CostGrid, cells: &[Cell], team: &GridFormations<'_>, may_change: bool) -> Laid {
    let mut floor = vec![0usize; cells.len()];
    loop {
        let along = smooth::formation_along_from(grid, cells, team, may_change, &floor);
        let (key_points, transitions) =
            smooth::smooth_from(grid, cells, &along, team, may_change, &floor);
        let headings = follow::key_headings(&key_points);
        let held =
            follow::held_formations(grid, &key_points, team.formations, team.leader, &headings);
        let member_paths =
            follow::member_paths_held(&key_points, team.formations, team.leader, &headings, &held);
        let blocked = follow::blocked_per_leg(grid, &member_paths, team.leader);
        let mut narrowed = false;
        if may_change {
            for (j, _) in blocked.iter().enumerate().filter(|&(_, &b)| b > 0) {
                let from = if j == 0 {
                    0
                } else {
                    key_points[j].path_index + 1
                };
                for n in from..=key_points[j + 1].path_index {
                    if let Some(next) = narrower(team.formations, along[n].0) {
                        if floor[n] < next {
                            floor[n] = next;
                            narrowed = true;
                        }
                    }
                }
            }
        }
        if !narrowed {
            return Laid {
                along,
                key_points,
                transitions,
                member_paths,
                held,
            };
        }
    }
}

/// Plans with fresh buffers; keep a [`Planner`] to plan repeatedly without reallocating.
pub fn plan(req: &PlanRequest<'_>) -> Result<Plan, PlanError> {
    Planner::new().plan(req)
}

/// A team as written in a team file:
///
/// ```ron
/// Team(
///     members: ["scout", "rifle", "rifle", "medic", "rifle"],
///     leader: Role("scout"),          // or Slot(0), or Random(7)
///     formations: [
///         (shape: Wedge, spacing: 4.0),
///         (shape: Column, spacing: 3.0),
///     ],
///     task: MayChangeRarely,          // MustKeep, ShortestFirst, Custom(k1: …, k2: …, may_change: …)
/// )
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Team", deny_unknown_fields)]
pub struct TeamDef {
    /// One role name per member; the member count is their number.
    pub members: Vec<String>,
    /// How the leader is chosen (default: slot 0).
    #[serde(default)]
    pub leader: LeaderChoice,
    /// Formations, preferred first.
    pub formations: Vec<FormationDef>,
    /// The task class (default: may change rarely).
    #[serde(default)]
    pub task: TaskClass,
}

/// A validated team, ready to plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Team {
    /// Role of each member.
    pub roles: Vec<String>,
    /// The leader's member index, chosen once.
    pub leader: usize,
    /// Formations, preferred first, all with one slot per member.
    pub formations: Vec<Formation>,
    /// The task class.
    pub task: TaskClass,
}

impl TeamDef {
    /// Checks the definition and resolves the leader.
    pub fn validate(self) -> Result<Team, FormationError> {
        let members = self.members.len();
        if members == 0 {
            return Err(FormationError::NoMembers);
        }
        if self.formations.is_empty() {
            return Err(FormationError::NoFormations);
        }
        self.task.weights().validate()?;
        let leader = self.leader.resolve(&self.members)?;
        let formations = self
            .formations
            .into_iter()
            .enumerate()
            .map(|(i, f)| f.validate(members, i + 1))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Team {
            roles: self.members,
            leader,
            formations,
            task: self.task,
        })
    }
}

impl Team {
    /// Reads and parses a team file.
    pub fn load(path: &Path) -> Result<Team, Diagnostics> {
        let text = crate::diag::read_text(path, "team file")?;
        Team::parse(&text, path)
    }

    /// Parses a team file's text; `file` names it in diagnostics. Syntax errors are located by
    /// RON; a validation error is located at the key it concerns.
    pub fn parse(text: &str, file: impl AsRef<Path>) -> Result<Team, Diagnostics> {
        let file = file.as_ref();
        let def: TeamDef =
            ron::from_str(text).map_err(|e| crate::load::ron_diag(file, text, &e))?;
        def.validate().map_err(|e| {
            let (line, col) = key_position(text, e.key()).unwrap_or((0, 0));
            Diagnostics::from(Diagnostic::new(file, line, col, e.to_string(), Some(text)))
        })
    }

    /// Plans this team over `grid` from `start` to `goal` with its own task class.
    pub fn plan(
        &self,
        planner: &mut Planner,
        grid: &CostGrid,
        start: Vec2,
        goal: Vec2,
    ) -> Result<Plan, PlanError> {
        planner.plan(&PlanRequest {
            grid,
            start,
            goal,
            formations: &self.formations,
            leader: self.leader,
            weights: self.task.weights(),
        })
    }
}

/// 1-based line and column of the first `key:` in `text` (a whole identifier followed by `:`).
fn key_position(text: &str, key: &str) -> Option<(usize, usize)> {
    let mut from = 0;
    while let Some(off) = text[from..].find(key) {
        let at = from + off;
        let before_ok = text[..at]
            .chars()
            .next_back()
            .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
        let after = text[at + key.len()..].trim_start();
        if before_ok && after.starts_with(':') {
            let line = text[..at].matches('\n').count() + 1;
            let col = text[..at].rsplit('\n').next().unwrap_or("").chars().count() + 1;
            return Some((line, col));
        }
        from = at + key.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map with a start area and a goal area joined by a straight corridor `width` rows high
    /// (0 = closed) and, when `detour`, by a wide band around the north.
    fn corridor_map(width: usize, detour: bool) -> CostGrid {
        let (cols, rows) = (60usize, 18usize);
        let mut s = String::new();
        for r in 0..rows {
            for c in 0..cols {
                let border = r == 0 || r == rows - 1 || c == 0 || c == cols - 1;
                let connector = (1..=5).contains(&c) || (cols - 6..=cols - 2).contains(&c);
                let band = detour && (1..=5).contains(&r);
                let corridor = (10..10 + width).contains(&r);
                s.push(if !border && (connector || band || corridor) {
                    '.'
                } else {
                    '#'
                });
            }
            s.push('\n');
        }
        CostGrid::from_ascii(&s)
    }

    fn line3() -> Vec<Formation> {
        vec![Formation::new(&FormationShape::Line, 3, 1.0).unwrap()]
    }

    fn request<'a>(
        grid: &'a CostGrid,
        formations: &'a [Formation],
        weights: Weights,
    ) -> PlanRequest<'a> {
        PlanRequest {
            grid,
            start: Vec2::new(3.5, 14.5),
            goal: Vec2::new(56.5, 14.5),
            formations,
            leader: 0,
            weights,
        }
    }

    fn through(plan: &Plan, col: usize, rows: std::ops::Range<usize>) -> bool {
        plan.leader_cells
            .iter()
            .any(|c| c.col == col && rows.contains(&c.row))
    }

    #[test]
    fn formation_term_steers_the_leader_around_a_narrow_corridor() {
        let grid = corridor_map(2, true);
        let f = line3();
        let keep = plan(&request(&grid, &f, TaskClass::MayChangeRarely.weights())).unwrap();
        assert!(through(&keep, 30, 1..6), "K2 = 0.9 takes the wide detour");
        assert!(!through(&keep, 30, 10..12));
        let shortest = TaskClass::Custom {
            k1: 1.0,
            k2: 0.0,
            may_change: true,
        }
        .weights();
        let short = plan(&request(&grid, &f, shortest)).unwrap();
        assert!(through(&short, 30, 10..12), "K2 = 0 takes the corridor");
        assert!(short.cost < keep.cost);
        assert_eq!(keep.tried, vec![(0.1, 0.9)]);
    }

    #[test]
    fn factors_relax_as_the_source_prescribes_until_a_path_is_found() {
        // The only way is a corridor one cell wide: no member but the leader fits in a line.
        let grid = corridor_map(1, false);
        let f = line3();
        let p = plan(&request(&grid, &f, TaskClass::MayChangeRarely.weights())).unwrap();
        assert_eq!(
            p.tried,
            vec![
                (0.1, 0.9),
                (0.2, 0.8),
                (0.3, 0.7),
                (0.4, 0.6),
                (0.5, 0.5),
                (0.6, 0.4),
                (0.7, 0.3),
                (0.8, 0.2),
                (0.9, 0.1),
                (1.0, 0.0)
            ]
        );
        assert!(through(&p, 30, 10..11));
        let s = plan(&request(&grid, &f, TaskClass::ShortestFirst.weights())).unwrap();
        assert_eq!(s.tried, vec![(0.9, 0.1), (1.0, 0.0)]);
    }

    #[test]
    fn an_intermediate_relaxation_step_succeeds_where_the_team_fits_that_well() {
        // The only way is a corridor one row high. A T of 5 (two followers behind the leader, one
        // on each side) has 2 of its 4 followers on free cells there. ⌈K2·4⌉ must fit:
        // K2 = 0.9 → 4, 0.8 → ⌈3.2⌉ = 4, 0.7 → ⌈2.8⌉ = 3, 0.6 → ⌈2.4⌉ = 3, 0.5 → 2: the fifth
        // search succeeds.
        let grid = corridor_map(1, false);
        let t = FormationShape::Custom(vec![
            (0.0, 0.0),
            (-1.0, 0.0),
            (-2.0, 0.0),
            (0.0, 1.0),
            (0.0, -1.0),
        ]);
        let f = vec![Formation::new(&t, 5, 1.0).unwrap()];
        let p = plan(&request(&grid, &f, TaskClass::MayChangeRarely.weights())).unwrap();
        assert_eq!(
            p.tried,
            vec![(0.1, 0.9), (0.2, 0.8), (0.3, 0.7), (0.4, 0.6), (0.5, 0.5)]
        );
        assert!(through(&p, 30, 10..11));
        // Shortest first starts at K2 = 0.1 (⌈0.4⌉ = 1 must fit): found at once.
        let s = plan(&request(&grid, &f, TaskClass::ShortestFirst.weights())).unwrap();
        assert_eq!(s.tried, vec![(0.9, 0.1)]);
        // A step of 0.25: 0.9 → 0.65 (⌈2.6⌉ = 3) → 0.4 (⌈1.6⌉ = 2) succeeds.
        let quarter = Weights {
            step: 0.25,
            ..TaskClass::MayChangeRarely.weights()
        };
        let q = plan(&request(&grid, &f, quarter)).unwrap();
        assert_eq!(q.tried, vec![(0.1, 0.9), (0.35, 0.65), (0.6, 0.4)]);
        // The literal reading (one follower is enough at any K2 > 0) takes it at once too.
        let literal = Weights {
            keep_share: false,
            ..TaskClass::MayChangeRarely.weights()
        };
        let l = plan(&request(&grid, &f, literal)).unwrap();
        assert_eq!(l.tried, vec![(0.1, 0.9)]);
    }

    #[test]
    fn no_path_at_all_tries_every_factor_then_fails() {
        let grid = corridor_map(0, false);
        let f = line3();
        let err = plan(&request(&grid, &f, TaskClass::MayChangeRarely.weights())).unwrap_err();
        let PlanError::NoPath { tried } = &err else {
            panic!("{err}")
        };
        assert_eq!(tried.len(), 10);
        assert_eq!(tried[0], (0.1, 0.9));
        assert_eq!(tried[9], (1.0, 0.0));
        assert!(err.to_string().starts_with(
            "no path keeps the formation from start to goal; tried (K1, K2) = (0.1, 0.9), (0.2, 0.8),"
        ));
    }

    #[test]
    fn must_keep_fails_at_once() {
        let grid = corridor_map(1, false);
        let f = line3();
        let err = plan(&request(&grid, &f, TaskClass::MustKeep.weights())).unwrap_err();
        assert_eq!(
            err,
            PlanError::NoPath {
                tried: vec![(0.05, 0.95)]
            }
        );
        // With room for the line everywhere it succeeds and never changes formation.
        let open = corridor_map(3, false);
        let ok = plan(&request(&open, &f, TaskClass::MustKeep.weights())).unwrap();
        assert!(ok.transitions.is_empty());
    }

    #[test]
    fn a_narrower_formation_carries_the_team_through_and_back() {
        let grid = corridor_map(1, false);
        let f = vec![
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        let p = plan(&request(&grid, &f, TaskClass::MayChangeRarely.weights())).unwrap();
        assert_eq!(p.tried, vec![(0.1, 0.9)]);
        let changes: Vec<(usize, usize)> = p.transitions.iter().map(|t| (t.from, t.to)).collect();
        assert_eq!(changes, vec![(0, 1), (1, 0)]);
        // Key points never cut through walls; members sit on the formation function at key
        // points and the leader is on its own path.
        for w in p.key_points.windows(2) {
            assert!(grid.clear_line(w[0].cell, w[1].cell));
        }
        // The column is held from the entrance up to the exit and the line taken after it.
        let headings = follow::key_headings(&p.key_points);
        let held = follow::held_formations(&grid, &p.key_points, &f, 0, &headings);
        assert_eq!(p.held, held);
        let (entrance, exit) = (p.transitions[0].key_index, p.transitions[1].key_index);
        assert!(held[entrance..exit].iter().all(|&h| h == 1), "{held:?}");
        assert_eq!(*held.last().unwrap(), 0);
        for m in &p.member_paths {
            for (j, k) in p.key_points.iter().enumerate() {
                let slot = f[held[j]].world_slot(m.member, 0, k.pos, headings[j]);
                // Slots follow the formation (a slot may be in a wall: see `follow`'s header).
                assert_eq!(m.waypoints[j], slot);
            }
        }
        // In the corridor the column's followers stand on free cells behind the leader.
        let t = &p.transitions[0];
        for m in &p.member_paths[1..] {
            let c = grid.cell_of(m.waypoints[t.key_index]).unwrap();
            assert!(!grid.blocked[grid.index(c)], "member {} at {c:?}", m.member);
        }
    }

    #[test]
    fn a_member_whose_way_crosses_a_wall_narrows_the_formation_there() {
        // Only the band around the north is open (5 rows; the connectors 5 columns). A line of 3
        // fits on every cell of the leader's path, facing along the step into it, but at the
        // band's corners the waypoints face the next leg: a side member's slot at (5, 6) → (6.5,
        // 6.5) lies in the wall east of the connector, and its way there crosses it.
        let grid = corridor_map(0, true);
        let line = line3();
        let p = plan(&request(&grid, &line, TaskClass::MayChangeRarely.weights())).unwrap();
        let blocked = follow::blocked_per_leg(&grid, &p.member_paths, 0);
        assert!(blocked.iter().any(|&b| b > 0), "{blocked:?}");
        // With a column to narrow to, the team files round each corner and spreads again after
        // it; no member's way crosses a wall, and the first search is kept.
        let both = vec![
            Formation::new(&FormationShape::Line, 3, 1.0).unwrap(),
            Formation::new(&FormationShape::Column, 3, 1.0).unwrap(),
        ];
        let p = plan(&request(&grid, &both, TaskClass::MayChangeRarely.weights())).unwrap();
        assert_eq!(p.tried, vec![(0.1, 0.9)]);
        let changes: Vec<(usize, usize)> = p.transitions.iter().map(|t| (t.from, t.to)).collect();
        assert_eq!(changes, vec![(0, 1), (1, 0), (0, 1), (1, 0)]);
        assert!(follow::blocked_per_leg(&grid, &p.member_paths, 0)
            .iter()
            .all(|&b| b == 0));
        // The column is taken at the corners only: west (columns 1–7) and east (51–58).
        for (k, h) in p.key_points.iter().zip(&p.held) {
            if *h == 1 {
                assert!(k.cell.col <= 7 || k.cell.col >= 51, "{:?}", k.cell);
            }
        }
        assert!(p.held.iter().filter(|&&h| h == 0).count() > 4);
        // The formation may not change: nothing to narrow to, the plan is the line's.
        let keep = plan(&request(&grid, &line, TaskClass::MustKeep.weights())).unwrap();
        assert!(keep.transitions.is_empty());
        assert!(keep.held.iter().all(|&h| h == 0));
    }

    #[test]
    fn narrower_means_less_wide_side_to_side_and_later_in_the_list() {
        // Widths: line of 3 at spacing 1: 1 − (−1) = 2; wedge of 3 at 2: 2 − (−2) = 4; column 0.
        let line = Formation::new(&FormationShape::Line, 3, 1.0).unwrap();
        let wedge = Formation::new(&FormationShape::Wedge, 3, 2.0).unwrap();
        let column = Formation::new(&FormationShape::Column, 3, 1.0).unwrap();
        assert_eq!(width(&line), 2.0);
        assert_eq!(width(&wedge), 4.0);
        assert_eq!(width(&column), 0.0);
        let list = [wedge.clone(), column.clone(), line.clone()];
        assert_eq!(narrower(&list, 0), Some(1));
        assert_eq!(narrower(&list, 1), None);
        assert_eq!(narrower(&list, 2), None);
        // A wider formation after a narrow one is not a narrowing; an equal one is not either.
        let list = [line.clone(), wedge, line, column];
        assert_eq!(narrower(&list, 0), Some(3));
    }

    #[test]
    fn bad_requests_are_refused() {
        let grid = corridor_map(2, true);
        let f = line3();
        let mut r = request(&grid, &f, TaskClass::MayChangeRarely.weights());
        r.start = Vec2::new(0.5, 0.5);
        assert_eq!(
            plan(&r).unwrap_err().to_string(),
            "the start (0.5, 0.5) is on a blocked cell"
        );
        r.start = Vec2::new(-3.0, 2.0);
        assert!(matches!(
            plan(&r),
            Err(PlanError::Outside { which: "start", .. })
        ));
        let mixed = vec![
            f[0].clone(),
            Formation::new(&FormationShape::Column, 4, 1.0).unwrap(),
        ];
        let r = request(&grid, &mixed, TaskClass::MayChangeRarely.weights());
        assert!(matches!(
            plan(&r),
            Err(PlanError::MemberMismatch { formation: 2, .. })
        ));
    }

    const TEAM: &str = r#"Team(
    members: ["scout", "rifle", "rifle", "medic", "rifle"],
    leader: Role("medic"),
    formations: [
        (shape: Wedge, spacing: 4.0),
        (name: Some("file"), shape: Column, spacing: 3.0),
    ],
    task: MayChangeRarely,
)"#;

    #[test]
    fn team_files_parse_and_plan() {
        let team = Team::parse(TEAM, "squad.ron").unwrap();
        assert_eq!(team.leader, 3);
        assert_eq!(team.formations[1].name(), "file");
        let grid = CostGrid::open(40, 40, 2.0, Vec2::ZERO);
        let p = team
            .plan(
                &mut Planner::new(),
                &grid,
                Vec2::new(10.0, 10.0),
                Vec2::new(70.0, 60.0),
            )
            .unwrap();
        assert_eq!(p.leader, 3);
        assert_eq!(p.member_paths[3].waypoints[0], Vec2::new(11.0, 11.0));
    }

    #[test]
    fn team_file_errors_are_located() {
        let bad = TEAM.replace("Role(\"medic\")", "Role(\"cook\")");
        let d = Team::parse(&bad, "squad.ron").unwrap_err().0.remove(0);
        assert_eq!((d.line, d.col), (3, 5));
        assert_eq!(
            d.message,
            "no member has the role `cook`; the roles are scout, rifle, rifle, medic, rifle"
        );
        let bad = TEAM.replace("shape: Wedge", "shape: Wegde");
        let d = Team::parse(&bad, "squad.ron").unwrap_err().0.remove(0);
        assert_eq!((d.line, d.col), (5, 17));
        assert!(d.message.contains("Wegde"), "{}", d.message);
        let bad = TEAM.replace("spacing: 4.0", "spacing: -1.0");
        let d = Team::parse(&bad, "squad.ron").unwrap_err().0.remove(0);
        assert_eq!((d.line, d.col), (4, 5));
        assert_eq!(
            d.message,
            "formation 1: spacing must be a positive number, found -1"
        );
    }

    #[test]
    fn the_valley_squad_takes_the_pass_or_squeezes_through_the_gap() {
        use crate::terrain::{load_asc, Features, Mobility};
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/terrain");
        let mut terrain = load_asc(&root.join("valley.asc")).unwrap();
        terrain.apply_features(&Features::load(&root.join("valley_features.ron")).unwrap());
        let grid = terrain.cost_grid(&Mobility::default());
        let f = vec![
            Formation::new(&FormationShape::Wedge, 5, 4.0).unwrap(),
            Formation::new(&FormationShape::Column, 5, 3.0).unwrap(),
        ];
        let (start, goal) = (
            grid.center_of(Cell::new(200, 70)),
            grid.center_of(Cell::new(40, 165)),
        );
        let mut planner = Planner::new();
        let mut run = |formations: &[Formation], task: TaskClass| {
            planner
                .plan(&PlanRequest {
                    grid: &grid,
                    start,
                    goal,
                    formations,
                    leader: 0,
                    weights: task.weights(),
                })
                .unwrap()
        };
        // The slot canyon through the ridge (columns 58–61) is too narrow for the wedge.
        let in_gap = |p: &Plan| {
            p.leader_cells
                .iter()
                .any(|c| (56..64).contains(&c.col) && (100..136).contains(&c.row))
        };
        let in_pass = |p: &Plan| {
            p.leader_cells
                .iter()
                .any(|c| (200..240).contains(&c.col) && (100..136).contains(&c.row))
        };

        let keep = run(&f[..1], TaskClass::MustKeep);
        assert!(in_pass(&keep) && !in_gap(&keep));
        assert!(keep.transitions.is_empty());
        let rarely = run(&f, TaskClass::MayChangeRarely);
        assert!(in_pass(&rarely) && !in_gap(&rarely));
        let shortest = run(&f, TaskClass::ShortestFirst);
        assert!(in_gap(&shortest) && !in_pass(&shortest));
        assert!(shortest.cost < rarely.cost);
        // In the canyon the team files through as a column.
        let gap_nodes: Vec<usize> = (0..shortest.leader_cells.len())
            .filter(|&k| (100..120).contains(&shortest.leader_cells[k].row))
            .collect();
        assert!(!gap_nodes.is_empty());
        assert!(gap_nodes.iter().all(|&k| shortest.formation_along[k] == 1));
        assert!(shortest
            .transitions
            .iter()
            .any(|t| t.from == 0 && t.to == 1));
        for p in [&keep, &rarely, &shortest] {
            for w in p.key_points.windows(2) {
                assert!(grid.clear_line(w[0].cell, w[1].cell));
            }
        }
    }
}
