//! The `terrain` and `plans` entries of a run's `world.json` (see `docs/viewer.md`).
//!
//! Not a tick stage: written by the recorder at the end of a run, from the squads' current plans.

use super::{Squads, DRAW_LIFT};
use crate::terrain::Terrain;
use glam::Vec2;
use serde_json::{json, Value};

/// Terrains with more cells than this are downsampled for the viewer.
pub const MAX_TERRAIN_CELLS: usize = 512 * 512;

/// `x` rounded to the millimetre, so the JSON holds `11.18` rather than `11.180000305175781`.
fn mm(x: f32) -> f64 {
    (f64::from(x) * 1000.0).round() / 1000.0
}

/// `{"origin":[x0,z0],"cell","cols","rows","heights":[…],"blocked":[0|1…]}` (metres to
/// the millimetre), row-major, row 0
/// at the smallest z; `blocked` is the first squad's grid (else the first walking species'),
/// empty when no species walks. Larger terrains are sampled every `k` cells (a blocked flag set
/// when any cell of the block is blocked). `null` without terrain.
pub fn terrain_json(squads: &Squads) -> Value {
    let Some(g) = &squads.ground else {
        return Value::Null;
    };
    let t: &Terrain = &g.terrain;
    let grid = squads
        .squads
        .first()
        .map(|s| s.grid.clone())
        .or_else(|| g.grids.iter().flatten().next().cloned());
    let mut k = 1;
    while t.cols.div_ceil(k) * t.rows.div_ceil(k) > MAX_TERRAIN_CELLS {
        k += 1;
    }
    let (cols, rows) = (t.cols.div_ceil(k), t.rows.div_ceil(k));
    let cell = t.cell_size * k as f32;
    let mut heights = Vec::with_capacity(cols * rows);
    let mut blocked = Vec::with_capacity(if grid.is_some() { cols * rows } else { 0 });
    for r in 0..rows {
        for c in 0..cols {
            let centre = t.origin + Vec2::new(c as f32 + 0.5, r as f32 + 0.5) * cell;
            heights.push(mm(if k == 1 {
                t.heights[r * t.cols + c]
            } else {
                t.height_at(centre.x, centre.y)
            }));
            if let Some(gr) = &grid {
                let any = (r * k..((r + 1) * k).min(t.rows)).any(|rr| {
                    (c * k..((c + 1) * k).min(t.cols)).any(|cc| gr.blocked[rr * t.cols + cc])
                });
                blocked.push(u8::from(any));
            }
        }
    }
    json!({
        "origin": [mm(t.origin.x), mm(t.origin.y)],
        "cell": cell,
        "cols": cols,
        "rows": rows,
        "heights": heights,
        "blocked": blocked,
    })
}

/// One entry per squad: `{"agent": leader id, "squad", "members": [ids], "path": [[x,y,z]…],
/// "key_points": […], "transitions": [{"at", "formation"}], "slots": [[[x,y,z]…] per key
/// point]}`, every point on the ground raised by [`DRAW_LIFT`]; `formation` is the name of the
/// formation taken there.
pub fn plans_json(squads: &Squads) -> Value {
    let Some(g) = &squads.ground else {
        return json!([]);
    };
    let t = &g.terrain;
    let p3 = |p: Vec2| [mm(p.x), mm(t.height_at(p.x, p.y) + DRAW_LIFT), mm(p.y)];
    let plans: Vec<Value> = squads
        .squads
        .iter()
        .map(|s| {
            let plan = &s.plan;
            json!({
                "agent": s.members[s.leader].0,
                "squad": s.index,
                "members": s.members.iter().map(|m| m.0).collect::<Vec<_>>(),
                "path": plan.leader_path.iter().map(|&p| p3(p)).collect::<Vec<_>>(),
                "key_points": plan.key_points.iter().map(|k| p3(k.pos)).collect::<Vec<_>>(),
                "transitions": plan.transitions.iter().map(|x| json!({
                    "at": p3(x.pos),
                    "formation": s.formations[s.formation_of(x.to)].name(),
                })).collect::<Vec<_>>(),
                "slots": (0..plan.key_points.len()).map(|j| {
                    plan.member_paths.iter().map(|m| p3(m.waypoints[j])).collect::<Vec<_>>()
                }).collect::<Vec<_>>(),
            })
        })
        .collect();
    Value::Array(plans)
}
