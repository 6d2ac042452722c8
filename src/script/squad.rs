//! The squad part of the script API (seed 004 at run time): read access to the plan's tables,
//! a plan request, and line of sight over the terrain as a perception query.
//!
//! Part of stage 4 (decision): registered on every script engine next to the agent view. The
//! view carries a snapshot published before the tick; a plan made by `plan_path` is computed in
//! the call (it reads only that snapshot) and adopted by the runtime after the tick, so runs stay
//! deterministic. The task classes' names ([`task_named`]) are defined here and shared with the
//! scenario's squad setup (`crate::squad`, which re-exports this module as `squad::script`).
//!
//! | on `this` | what |
//! |---|---|
//! | `in_squad`, `is_leader` | bools |
//! | `slot` | Vec3: the member's slot now, on the ground (the leader's: its point on the path; own position outside a squad) |
//! | `slot_dist` | horizontal distance to the slot |
//! | `leader_pos`, `squad_goal` | Vec3 |
//! | `at_goal` | the leader has reached the end of the path |
//! | `formation` | name of the formation the members hold now, the one their slots take at the start of the current leg ("" outside a squad) |
//! | `key_points` | array of Vec3: the key-point table, on the ground |
//! | `transitions` | array of maps `#{at: Vec3, from: "triangle", to: "column", key: 3}` |
//! | `plan_path(goal, formation, task)` | plans the squad from the leader's position to `goal` (a Vec3; y is ignored) preferring `formation` ("" keeps the current order) under `task` (`"MustKeep"`, `"MayChangeRarely"`, `"ShortestFirst"`, `""` keeps the current one); returns whether a plan was found; the squad follows it from the next tick |
//! | `plan_error` | why the last `plan_path` of this call failed ("" when it did not) |
//! | `can_see(p)` | whether the line from this agent's eye (its position raised by its body height) to `p` raised by the same height clears the terrain (always true without terrain) |
//! | `ground_height(x, z)` | terrain height there (0 without terrain) |

use super::AgentView;
use crate::formation::{Formation, PlanRequest, TaskClass};
use crate::world::board::Planned;
use glam::{Vec2, Vec3};
use rhai::{Array, Dynamic, Engine, EvalAltResult, ImmutableString, Map, Position, FLOAT, INT};

/// The task class written `text`: `MustKeep`, `MayChangeRarely`, `ShortestFirst` or
/// `Custom(k1: …, k2: …, may_change: …)`.
pub fn task_named(text: &str) -> Option<TaskClass> {
    let t: TaskClass = ron::from_str(text.trim()).ok()?;
    t.weights().validate().ok()?;
    Some(t)
}

fn err(msg: String) -> Box<EvalAltResult> {
    Box::new(EvalAltResult::ErrorRuntime(
        Dynamic::from(msg),
        Position::NONE,
    ))
}

/// Registers a read-only property. Rhai writes a property back after calling a method on it
/// (`this.key_points.len()`); without a setter that write would fall through to the blackboard
/// indexer. The setter accepts the unchanged value and refuses any other.
fn read_only<T: Clone + Send + Sync + 'static>(
    e: &mut Engine,
    name: &'static str,
    get: fn(&AgentView) -> T,
    same: fn(&T, &T) -> bool,
) {
    e.register_get(name, move |v: &mut AgentView| get(v));
    e.register_set(
        name,
        move |v: &mut AgentView, x: T| -> Result<(), Box<EvalAltResult>> {
            if same(&get(v), &x) {
                Ok(())
            } else {
                Err(err(format!("`this.{name}` is read-only")))
            }
        },
    );
}

fn eq<T: PartialEq>(a: &T, b: &T) -> bool {
    a == b
}

fn same_array(a: &Array, b: &Array) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

fn key_points(v: &AgentView) -> Array {
    v.squad.as_ref().map_or_else(Array::new, |s| {
        s.shared
            .key_points
            .iter()
            .map(|&p| Dynamic::from(p))
            .collect()
    })
}

fn transitions(v: &AgentView) -> Array {
    v.squad.as_ref().map_or_else(Array::new, |s| {
        let name =
            |i: usize| -> Dynamic { ImmutableString::from(s.shared.formations[i].name()).into() };
        s.shared
            .transitions
            .iter()
            .map(|t| {
                let mut m = Map::new();
                m.insert("at".into(), Dynamic::from(t.at));
                m.insert("from".into(), name(t.from));
                m.insert("to".into(), name(t.to));
                m.insert("key".into(), Dynamic::from(t.key as INT));
                Dynamic::from_map(m)
            })
            .collect()
    })
}

/// `this.is_leader`.
pub(crate) fn is_leader(v: &AgentView) -> bool {
    v.squad.as_ref().is_some_and(|s| s.is_leader())
}

/// `this.at_goal`.
pub(crate) fn at_goal(v: &AgentView) -> bool {
    v.squad.as_ref().is_some_and(|s| s.at_goal)
}

/// `this.slot_dist`: the horizontal distance to the slot (0 outside a squad).
pub(crate) fn slot_dist(v: &AgentView) -> FLOAT {
    v.squad.as_ref().map_or(0.0, |s| {
        Vec2::new(s.slot.x - v.pos.x, s.slot.z - v.pos.z).length()
    })
}

/// Registers the squad functions on `e`.
pub fn register(e: &mut Engine) {
    read_only(e, "in_squad", |v| v.squad.is_some(), eq);
    read_only(e, "is_leader", is_leader, eq);
    read_only(
        e,
        "slot",
        |v| v.squad.as_ref().map_or(v.pos, |s| s.slot),
        eq,
    );
    read_only(e, "slot_dist", slot_dist, eq);
    read_only(
        e,
        "leader_pos",
        |v| v.squad.as_ref().map_or(v.pos, |s| s.leader_pos),
        eq,
    );
    read_only(
        e,
        "squad_goal",
        |v| v.squad.as_ref().map_or(v.pos, |s| s.shared.goal),
        eq,
    );
    read_only(e, "at_goal", at_goal, eq);
    read_only(
        e,
        "formation",
        |v| -> ImmutableString {
            v.squad.as_ref().map_or_else(ImmutableString::new, |s| {
                s.shared.formations[s.formation].name().into()
            })
        },
        eq,
    );
    read_only(e, "key_points", key_points, same_array);
    read_only(e, "transitions", transitions, same_array);
    read_only(
        e,
        "plan_error",
        |v| -> ImmutableString {
            v.squad
                .as_ref()
                .map_or_else(ImmutableString::new, |s| s.error.as_str().into())
        },
        eq,
    );
    e.register_fn("plan_path", plan_path);
    e.register_fn("can_see", |v: &mut AgentView, p: Vec3| -> bool {
        let Some(t) = &v.terrain else {
            return true;
        };
        let up = Vec3::Y * v.eye_height;
        t.line_of_sight(v.pos + up, p + up)
    });
    e.register_fn(
        "ground_height",
        |v: &mut AgentView, x: FLOAT, z: FLOAT| -> FLOAT {
            v.terrain.as_ref().map_or(0.0, |t| t.height_at(x, z))
        },
    );
}

/// `this.plan_path(goal, formation, task)`.
fn plan_path(
    v: &mut AgentView,
    goal: Vec3,
    formation: &str,
    task: &str,
) -> Result<bool, Box<EvalAltResult>> {
    let id = v.id;
    let Some(s) = v.squad.as_mut() else {
        return Ok(false);
    };
    let sh = s.shared.clone();
    let task = if task.is_empty() {
        sh.task
    } else {
        task_named(task).ok_or_else(|| {
            err(format!(
                "unknown task class \"{task}\": expected MustKeep, MayChangeRarely or ShortestFirst"
            ))
        })?
    };
    let order: Vec<usize> = if formation.is_empty() {
        sh.order.clone()
    } else {
        let Some(first) = sh
            .formations
            .iter()
            .position(|f| f.name().eq_ignore_ascii_case(formation))
        else {
            return Err(err(format!(
                "the squad has no formation \"{formation}\": it has {}",
                sh.formations
                    .iter()
                    .map(|f| f.name().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        };
        std::iter::once(first)
            .chain(sh.order.iter().copied().filter(|&i| i != first))
            .chain((0..sh.formations.len()).filter(|i| *i != first && !sh.order.contains(i)))
            .collect()
    };
    let formations: Vec<Formation> = order.iter().map(|&i| sh.formations[i].clone()).collect();
    let goal = Vec2::new(goal.x, goal.z);
    match crate::formation::plan(&PlanRequest {
        grid: &sh.grid,
        start: Vec2::new(s.leader_pos.x, s.leader_pos.z),
        goal,
        formations: &formations,
        leader: sh.leader,
        weights: task.weights_with(&sh.planning),
    }) {
        Ok(plan) => {
            s.error.clear();
            sh.requests
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(Planned {
                    agent: crate::world::AgentId(id as u32),
                    goal,
                    order,
                    task,
                    plan,
                });
            Ok(true)
        }
        Err(e) => {
            s.error = e.to_string();
            Ok(false)
        }
    }
}
