//! Loading a scenario's terrain and squads: the DEM and feature files, each walking species' cost
//! grid, and every squad checked and planned once, with located diagnostics (seed 004).
//!
//! Not a tick stage: part of `Scenario::load`.

use super::Ground;
use crate::diag::{Diagnostic, Diagnostics};
use crate::formation::Plan;
use crate::formation::{
    Formation, FormationDef, FormationShape, PlanError, PlanRequest, Planner, PlanningParams,
    TaskClass,
};
use crate::scenario::{normalize, ScenarioDef, SquadLeader};
use crate::script::squad::task_named;
use crate::species::validate::locate;
use crate::species::SpeciesSet;
use crate::terrain::{load_asc, load_pgm, Features};
use glam::Vec2;
use std::path::Path;
use std::sync::Arc;

/// A squad checked at load time, with its first plan.
#[derive(Debug, Clone)]
pub struct SquadSetup {
    /// Species index of the members.
    pub species: usize,
    /// Formations in the order the scenario lists them (preferred first), one slot per member.
    pub formations: Vec<Formation>,
    /// The leader's member index (the squad's `leader`, slot 0 by default).
    pub leader: usize,
    /// Task class.
    pub task: TaskClass,
    /// Seed 004's planning constants (relaxation step, task-class factors, …).
    pub planning: PlanningParams,
    /// Leader start, world `(x, z)`.
    pub start: Vec2,
    /// Goal, world `(x, z)`.
    pub goal: Vec2,
    /// The plan from start to goal.
    pub plan: Plan,
}

/// The formation shapes a squad may name, lower case.
pub const SHAPE_NAMES: [&str; 5] = ["line", "column", "wedge", "triangle", "diamond"];

/// The shape called `name` (any case), one of [`SHAPE_NAMES`].
pub fn shape_named(name: &str) -> Option<FormationShape> {
    match name.to_ascii_lowercase().as_str() {
        "line" => Some(FormationShape::Line),
        "column" => Some(FormationShape::Column),
        "wedge" => Some(FormationShape::Wedge),
        "triangle" => Some(FormationShape::Triangle),
        "diamond" => Some(FormationShape::Diamond),
        _ => None,
    }
}

/// Loads the scenario's terrain (paths relative to `file`) and builds each walking species'
/// cost grid, then checks and plans every squad. `Ok((None, []))` when the scenario has neither.
pub fn load(
    file: &Path,
    text: &str,
    def: &ScenarioDef,
    species: &SpeciesSet,
) -> Result<(Option<Arc<Ground>>, Vec<SquadSetup>), Diagnostics> {
    let at = |needle: &str, from: usize| locate(text, needle, from).unwrap_or((0, 0, 0));
    let diag = |(l, c, _): (usize, usize, usize), msg: String| {
        Diagnostic::new(file, l, c, msg, Some(text))
    };
    let dir = file.parent().unwrap_or(Path::new("."));
    let ground = match &def.terrain {
        None => None,
        Some(t) => {
            let dem = normalize(&dir.join(&t.dem));
            if let Some(problem) = crate::diag::file_problem(&dem) {
                return Err(diag(
                    at(&format!("\"{}\"", t.dem), 0),
                    format!("terrain file \"{}\" {problem}", dem.display()),
                )
                .into());
            }
            let ext = dem.extension().and_then(|e| e.to_str()).unwrap_or("");
            let key_at = |key: &str| crate::numbers::locate_key(text, key, 0).unwrap_or(at(key, 0));
            let mut terrain = if ext.eq_ignore_ascii_case("asc") {
                for (key, given) in [("cell_size", t.cell_size), ("height_scale", t.height_scale)] {
                    if given.is_some() {
                        return Err(diag(
                            key_at(key),
                            format!("`{key}` is for a PGM height map: an ESRI ASCII grid gives its own cell size and heights"),
                        )
                        .into());
                    }
                }
                load_asc(&dem)?
            } else if ext.eq_ignore_ascii_case("pgm") {
                let (Some(cell), Some(scale)) = (t.cell_size, t.height_scale) else {
                    return Err(diag(
                        at(&format!("\"{}\"", t.dem), 0),
                        format!(
                            "terrain file \"{}\": a PGM height map needs `cell_size` (metres per pixel) and `height_scale` (metres per sample unit) beside `dem`",
                            dem.display()
                        ),
                    )
                    .into());
                };
                for (key, v) in [("cell_size", cell), ("height_scale", scale)] {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(diag(
                            key_at(key),
                            format!("`{key}` must be a finite number > 0, not {v}"),
                        )
                        .into());
                    }
                }
                let terrain = load_pgm(&dem, cell, scale)?;
                let side = terrain.cols.max(terrain.rows) as f32 * cell;
                if side > crate::numbers::MAX_COORD {
                    return Err(diag(
                        key_at("cell_size"),
                        format!(
                            "`cell_size` {cell} makes the terrain {side:e} units wide; it may be at most {:e}",
                            crate::numbers::MAX_COORD
                        ),
                    )
                    .into());
                }
                terrain
            } else {
                return Err(diag(
                    at(&format!("\"{}\"", t.dem), 0),
                    format!(
                        "terrain file \"{}\": expected an ESRI ASCII grid (.asc) or a binary PGM height map (.pgm)",
                        dem.display()
                    ),
                )
                .into());
            };
            if let Some(f) = &t.features {
                let path = normalize(&dir.join(f));
                if let Some(problem) = crate::diag::file_problem(&path) {
                    return Err(diag(
                        at(&format!("\"{f}\""), 0),
                        format!("feature file \"{}\" {problem}", path.display()),
                    )
                    .into());
                }
                terrain.apply_features(&Features::load(&path)?);
            }
            let grids = species
                .species
                .iter()
                .map(|s| {
                    s.def
                        .body
                        .on_ground
                        .then(|| Arc::new(terrain.cost_grid(&s.def.body.mobility)))
                })
                .collect();
            let (lo, hi) = terrain
                .heights
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &h| {
                    (a.min(h), b.max(h))
                });
            let b = def.bounds;
            if lo < b.min.y || hi > b.max.y {
                return Err(diag(
                    at("bounds", 0),
                    format!(
                        "`bounds` must hold the terrain: its heights run from {lo} to {hi}, the bounds' y from {} to {}",
                        b.min.y, b.max.y
                    ),
                )
                .into());
            }
            Some(Arc::new(Ground {
                terrain: Arc::new(terrain),
                grids,
            }))
        }
    };
    let mut diags = Vec::new();
    let mut setups = Vec::new();
    let mut from = locate(text, "squads", 0).map_or(0, |x| x.2);
    let mut planner = Planner::new();
    for (index, sq) in def.squads.iter().enumerate() {
        let here = locate(text, &format!("\"{}\"", sq.species), from).map_or(from, |x| x.2);
        from = here + 1;
        let Some(g) = &ground else {
            diags.push(diag(
                at("squads", 0),
                "squads need a `terrain: (dem: \"…\")` to plan over".into(),
            ));
            break;
        };
        let Some(s) = species.index_of(&sq.species) else {
            diags.push(diag(
                at(&format!("\"{}\"", sq.species), here),
                format!(
                    "unknown species \"{}\": the scenario loads {}",
                    sq.species,
                    def.species.join(", ")
                ),
            ));
            continue;
        };
        let Some(grid) = g.grids[s].clone() else {
            diags.push(diag(
                at(&format!("\"{}\"", sq.species), here),
                format!(
                    "squad species \"{}\" must walk: give it `body: (on_ground: true)`",
                    sq.species
                ),
            ));
            continue;
        };
        let mut ok = true;
        let members = sq.count as usize;
        if members == 0 {
            diags.push(diag(at("count", here), "`count` must be at least 1".into()));
            ok = false;
        }
        // A formation spans about `spacing × count`; past MAX_COORD its slots leave any grid.
        let widest = crate::numbers::MAX_COORD / (members.max(1) as f32);
        if !(sq.spacing.is_finite() && sq.spacing > 0.0 && sq.spacing <= widest) {
            diags.push(diag(
                crate::numbers::locate_key(text, "spacing", here).unwrap_or(at("spacing", here)),
                format!(
                    "`spacing` must be a positive number of at most {widest} for {members} members (the formation spans at most {:e} world units), not {}",
                    crate::numbers::MAX_COORD, sq.spacing
                ),
            ));
            ok = false;
        }
        if sq.formations.is_empty() {
            diags.push(diag(
                at("formations", here),
                "a squad needs at least one formation".into(),
            ));
            ok = false;
        }
        let mut formations = Vec::new();
        for (i, name) in sq.formations.iter().enumerate() {
            match shape_named(name) {
                Some(shape) => {
                    if members > 0 && sq.spacing > 0.0 {
                        if let Ok(f) = (FormationDef {
                            name: Some(name.to_ascii_lowercase()),
                            shape,
                            spacing: sq.spacing,
                        })
                        .validate(members, i + 1)
                        {
                            formations.push(f);
                        }
                    }
                }
                None => {
                    diags.push(diag(
                        at(&format!("\"{name}\""), here),
                        format!(
                            "unknown formation \"{name}\": expected one of {}",
                            SHAPE_NAMES.join(", ")
                        ),
                    ));
                    ok = false;
                }
            }
        }
        let task = task_named(&sq.task);
        if task.is_none() {
            diags.push(diag(
                at("task", here),
                format!(
                    "unknown task class \"{}\": expected MustKeep, MayChangeRarely, ShortestFirst or Custom(k1: …, k2: …, may_change: …)",
                    sq.task
                ),
            ));
            ok = false;
        }
        if !sq.roles.is_empty() && sq.roles.len() != members {
            diags.push(diag(
                crate::numbers::locate_key(text, "roles", here).unwrap_or(at("roles", here)),
                format!(
                    "`roles` names {} members but the squad has {members}: give one role per member",
                    sq.roles.len()
                ),
            ));
            ok = false;
        }
        // A squad with no members is refused at its `count` already.
        let leader = match sq
            .leader
            .resolve(members.max(1), &sq.roles, def.seed, index)
        {
            Ok(l) => Some(l),
            Err(msg) => {
                diags.push(diag(
                    crate::numbers::locate_key(text, "leader", here).unwrap_or(at("leader", here)),
                    msg,
                ));
                None
            }
        };
        if !ok {
            continue;
        }
        let Some(leader) = leader else {
            continue;
        };
        let task = task.expect("checked");
        let (start, goal) = (
            Vec2::new(sq.start.0, sq.start.1),
            Vec2::new(sq.goal.0, sq.goal.1),
        );
        match planner.plan(&PlanRequest {
            grid: &grid,
            start,
            goal,
            formations: &formations,
            leader,
            weights: task.weights_with(&sq.planning),
        }) {
            Ok(plan) => setups.push(SquadSetup {
                species: s,
                formations,
                leader,
                task,
                planning: sq.planning,
                start,
                goal,
                plan,
            }),
            Err(e) => {
                let key = match &e {
                    PlanError::Outside { which, .. } | PlanError::Blocked { which, .. } => which,
                    _ => &"goal",
                };
                diags.push(diag(
                    at(key, here),
                    format!("squad of \"{}\": {e}", sq.species),
                ));
            }
        }
    }
    if diags.is_empty() {
        Ok((ground, setups))
    } else {
        Err(Diagnostics(diags))
    }
}

/// Draws again, from a run's `seed`, the leader of every squad whose scenario says
/// `leader: Random`, and plans again a squad whose leader changes (seed 004: a leader chosen at
/// random, then kept for the run). [`load`] plans with the scenario's own `seed`; a run given
/// another one (`shoal run --seed N`) draws its own leader from it, from the same per-squad
/// stream, so the same scenario and seed always give the same leader. A squad whose plan with
/// the new leader fails keeps the leader and plan of the load. `setups` are the squads of `def`
/// in order, as [`load`] returns them.
pub fn redraw_leaders(
    def: &ScenarioDef,
    ground: Option<&Ground>,
    setups: &mut [SquadSetup],
    seed: u64,
) {
    let Some(g) = ground else {
        return;
    };
    let mut planner = Planner::new();
    for (index, (sq, setup)) in def.squads.iter().zip(setups.iter_mut()).enumerate() {
        if sq.leader != SquadLeader::Random {
            continue;
        }
        let members = setup.formations.first().map_or(0, Formation::len);
        let Ok(leader) = sq.leader.resolve(members, &sq.roles, seed, index) else {
            continue;
        };
        let Some(grid) = g.grids.get(setup.species).cloned().flatten() else {
            continue;
        };
        if leader == setup.leader {
            continue;
        }
        if let Ok(plan) = planner.plan(&PlanRequest {
            grid: &grid,
            start: setup.start,
            goal: setup.goal,
            formations: &setup.formations,
            leader,
            weights: setup.task.weights_with(&setup.planning),
        }) {
            setup.leader = leader;
            setup.plan = plan;
        }
    }
}
