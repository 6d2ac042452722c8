//! The squads' work around every tick (seed 004), sequential and in member order: before it,
//! each member's target (the leader's lookahead point, each follower's slot led by its lag,
//! replaced by a local detour where the straight way is blocked) and the members' views; after
//! it, walkers back on the ground, plans from scripts adopted, the formation error measured, and
//! blocked followers and stalled leaders answered with detours and re-plans.

use super::slots::on_ground;
use super::{
    Squads, CLEARANCE, DETOUR_SECONDS, LAG_GO, LAG_STOP, LEADER_STALL_SECONDS, LOOKAHEAD,
    REPLAN_COOLDOWN, STUCK_GAIN, STUCK_MIN_DIST, STUCK_SECONDS,
};
use crate::species::SpeciesSet;
use crate::tick::Pipeline;
use crate::world::board::{Board, SquadView};
use crate::world::World;
use glam::Vec2;
use std::sync::Arc;

impl Squads {
    /// Sets every member's target in `pipeline.plan_targets` and publishes the squads' views on
    /// `world.squads`. Does nothing when there are no squads.
    pub fn before_tick(&mut self, world: &mut World, pipeline: &mut Pipeline) {
        if self.squads.is_empty() {
            return;
        }
        let n = world.agents.len();
        pipeline.plan_targets.clear();
        pipeline.plan_targets.resize(n, None);
        let mut views = Vec::new();
        let dt = world.dt.max(1e-6);
        for sq in &mut self.squads {
            let idx: Vec<Option<usize>> =
                sq.members.iter().map(|&id| world.agent_index(id)).collect();
            let Some(li) = idx[sq.leader] else {
                continue;
            };
            let lp = world.agents[li].pos;
            sq.update_progress(Vec2::new(lp.x, lp.z));
            let slots: Vec<Vec2> = (0..sq.members.len()).map(|m| sq.slot(m)).collect();
            let xz = |i: usize| Vec2::new(world.agents[i].pos.x, world.agents[i].pos.z);
            let max_lag = idx
                .iter()
                .enumerate()
                .filter(|&(m, _)| m != sq.leader)
                .filter_map(|(m, i)| i.map(|i| xz(i).distance(slots[m])))
                .fold(0.0f32, f32::max);
            let go = ((LAG_STOP - max_lag) / (LAG_STOP - LAG_GO)).clamp(0.0, 1.0);
            let vmax = pipeline
                .species
                .species
                .get(sq.species)
                .map_or(1.0, |s| s.def.body.limits.max_speed)
                .max(1e-3);
            let shared = sq.shared.clone();
            let formation = sq.formation_now();
            for (m, i) in idx.iter().enumerate() {
                let Some(i) = *i else { continue };
                let want = if m == sq.leader {
                    sq.point_ahead(LOOKAHEAD * go)
                } else {
                    // Lead the slot by the lag of `arrive` at the slot's speed (v / v_max).
                    let v = (slots[m] - sq.prev_slots[m]) / dt;
                    slots[m] + (v / vmax).clamp_length_max(1.0)
                };
                let force = sq.trackers[m].detour_until > world.tick;
                let (to, detour) = self.router.route(&sq.grid, xz(i), want, CLEARANCE, force);
                sq.stats.detour_ticks += u64::from(detour);
                let target = on_ground(&sq.terrain, to);
                sq.targets[m] = target;
                pipeline.plan_targets[i] = Some(target);
                views.push((
                    sq.members[m],
                    SquadView {
                        shared: shared.clone(),
                        member: m,
                        slot: on_ground(&sq.terrain, slots[m]),
                        leader_pos: lp,
                        at_goal: sq.progress.finished,
                        formation,
                        error: String::new(),
                    },
                ));
            }
            sq.prev_slots = slots;
        }
        views.sort_by_key(|(id, _)| *id);
        world.squads = Some(Arc::new(Board { views }));
    }

    /// Puts walking agents on the ground, adopts plans made by scripts, measures the formation
    /// error and re-plans blocked squads.
    pub fn after_tick(&mut self, world: &mut World, set: &SpeciesSet) {
        self.settle(world, set, true);
        let dt = world.dt.max(1e-6);
        let tick = world.tick;
        for sq in &mut self.squads {
            let mut asked =
                std::mem::take(&mut *sq.shared.requests.lock().unwrap_or_else(|e| e.into_inner()));
            // Several members may ask in one tick: the last in id order wins.
            asked.sort_by_key(|p| p.agent);
            if let Some(p) = asked.pop() {
                sq.adopt(p.plan, p.order, p.task, p.goal);
                sq.stats.script_plans += 1;
            }
            let idx: Vec<Option<usize>> =
                sq.members.iter().map(|&id| world.agent_index(id)).collect();
            let Some(li) = idx[sq.leader] else {
                continue;
            };
            let xz = |i: usize| Vec2::new(world.agents[i].pos.x, world.agents[i].pos.z);
            let lp = xz(li);
            sq.update_progress(lp);
            let mut max_lag = 0.0f32;
            let mut strikes = false;
            for (m, i) in idx.iter().enumerate() {
                let Some(i) = *i else { continue };
                if m == sq.leader {
                    continue;
                }
                let d = xz(i).distance(sq.slot(m));
                max_lag = max_lag.max(d);
                sq.stats.error_sum += f64::from(d);
                sq.stats.error_samples += 1;
                sq.stats.error_max = sq.stats.error_max.max(d);
                let tr = &mut sq.trackers[m];
                if d < STUCK_MIN_DIST {
                    tr.tracking = false;
                    tr.strikes = 0;
                } else if !tr.tracking || d < tr.best - STUCK_GAIN {
                    tr.tracking = true;
                    tr.best = d;
                    tr.since = 0;
                } else {
                    tr.since += 1;
                    if tr.since as f32 * dt >= STUCK_SECONDS {
                        sq.stats.stuck += 1;
                        tr.since = 0;
                        tr.best = d;
                        tr.detour_until = tick + (DETOUR_SECONDS / dt) as u64;
                        tr.strikes += 1;
                        strikes |= tr.strikes >= 2;
                    }
                }
            }
            let waiting = max_lag > LAG_GO;
            let done = sq.distance_done();
            if done > sq.leader_best + 0.5 {
                sq.leader_best = done;
                sq.leader_since = 0;
            } else if !waiting && !sq.progress.finished {
                sq.leader_since += 1;
            }
            let stalled = sq.leader_since as f32 * dt >= LEADER_STALL_SECONDS;
            let cooled = sq
                .last_replan
                .is_none_or(|t| (tick - t) as f32 * dt >= REPLAN_COOLDOWN);
            if (strikes || stalled) && cooled && !sq.progress.finished {
                sq.last_replan = Some(tick);
                if sq.replan(&mut self.planner, lp) {
                    sq.stats.replans += 1;
                } else {
                    sq.stats.failed_replans += 1;
                    sq.leader_since = 0;
                }
            }
        }
    }
}
