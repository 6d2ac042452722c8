//! The figures of a [`Health`] report, read from the monitor's counters (episodes still going
//! count up to the last tick observed). Nothing is measured here.

use super::place::obstacle_label;
use super::track::{close_runs, FrozenRec};
use super::{FlipAcc, Monitor, SpeciesAcc, SpeciesInfo};
use crate::health::{
    ratio, BehaviorHealth, Coincident, Flip, Frozen, FrozenAt, Health, Penetration, SpeciesHealth,
    Spot, FORMAT, FROZEN_EXAMPLES, PAIR_INTERVAL, TOP_FLIPS,
};

impl Monitor {
    /// The figures so far (episodes still going count up to the last tick observed).
    pub fn report(&self) -> Health {
        let mut m = self.clone();
        for (id, t) in m.tracks.iter_mut().enumerate() {
            if t.seen {
                close_runs(t, id as u32, &mut m.acc, &mut m.frozen);
            }
        }
        let dt = m.seconds;
        let species = m
            .species
            .iter()
            .zip(&m.acc)
            .enumerate()
            .map(|(s, (info, acc))| m.species_health(s, info, acc, dt))
            .collect();
        let c = &m.coincident;
        Health {
            format: FORMAT,
            dt: m.dt,
            ticks: m.ticks,
            pair_interval: PAIR_INTERVAL,
            species,
            coincident: Coincident {
                mean: ratio(m.coincident_sum as f64, c.samples as f64),
                ..c.clone()
            },
        }
    }

    fn species_health(
        &self,
        s: usize,
        info: &SpeciesInfo,
        acc: &SpeciesAcc,
        dt: f64,
    ) -> SpeciesHealth {
        let seconds = acc.ticks as f64 * dt;
        let mut frozen: Vec<&FrozenRec> = self
            .frozen
            .iter()
            .filter(|f| f.species as usize == s)
            .collect();
        frozen.sort_by(|a, b| b.ticks.cmp(&a.ticks).then(a.start.cmp(&b.start)));
        let behaviors: Vec<BehaviorHealth> = info
            .behaviors
            .iter()
            .zip(&acc.behaviors)
            .enumerate()
            .map(|(b, (name, ba))| {
                let mut at: Vec<FrozenAt> = ba
                    .frozen_at
                    .iter()
                    .map(|(place, n)| FrozenAt {
                        place: place.clone(),
                        agents: *n,
                    })
                    .collect();
                at.sort_by_key(|x| std::cmp::Reverse(x.agents));
                BehaviorHealth {
                    name: name.clone(),
                    may_stop: info.may_stop[b],
                    agent_ticks: ba.ticks,
                    stopped_share: ratio(ba.stopped as f64, ba.ticks as f64),
                    longest_stop: ba.longest_stop.map(|x| x.1),
                    frozen_agents: ba.frozen_agents,
                    frozen_at: at,
                    longest_frozen: frozen.iter().find(|f| f.behavior as usize == b).map(|f| {
                        Spot {
                            tick: f.start,
                            agent: f.agent,
                        }
                    }),
                }
            })
            .collect();
        let (moving_ticks, moving_stopped) = info
            .may_stop
            .iter()
            .zip(&acc.behaviors)
            .filter(|(m, _)| !**m)
            .fold((0u64, 0u64), |(n, k), (_, ba)| {
                (n + ba.ticks, k + ba.stopped)
            });
        let mut flips: Vec<&FlipAcc> = acc.flips.values().collect();
        flips.sort_by(|x, y| y.count.cmp(&x.count).then(x.first.tick.cmp(&y.first.tick)));
        let name = |b: u16| {
            info.behaviors
                .get(b as usize)
                .cloned()
                .unwrap_or_else(|| "?".into())
        };
        let most_switches_at = self
            .tracks
            .iter()
            .enumerate()
            .filter(|(_, t)| t.seen && t.species as usize == s && t.transitions > 0)
            .max_by(|(i, x), (j, y)| x.transitions.cmp(&y.transitions).then(j.cmp(i)))
            .map(|(i, t)| Spot {
                tick: t.last_switch_tick,
                agent: i as u32,
            });
        SpeciesHealth {
            name: info.name.clone(),
            agents: acc.agents,
            agent_ticks: acc.ticks,
            stopped_share: ratio(moving_stopped as f64, moving_ticks as f64),
            frozen_agents: acc.frozen_agents,
            frozen_episodes: frozen.len() as u64,
            pitch_limit_share: ratio(acc.pinned as f64, acc.ticks as f64),
            upright: info.upright,
            pitch_limit_at: acc.longest_pinned.map(|x| x.1),
            transitions: acc.transitions,
            switch_rate: ratio(acc.transitions as f64, seconds),
            most_switches_at,
            episodes: acc.episodes,
            short_episode_share: ratio(acc.short as f64, acc.episodes as f64),
            one_tick_share: ratio(acc.one_tick as f64, acc.episodes as f64),
            short_episode_at: acc.first_short,
            flips: flips
                .into_iter()
                .take(TOP_FLIPS)
                .map(|f| Flip {
                    a: name(f.a),
                    b: name(f.b),
                    count: f.count,
                    first: f.first,
                })
                .collect(),
            turning: acc.turning,
            net_turning: acc.net_turning,
            turning_waste: (acc.net_turning > 0.0).then(|| acc.turning / acc.net_turning),
            turning_waste_at: acc.worst_window.map(|x| x.1),
            neighbor_pairs: acc.neighbor_pairs,
            overlapping_pairs: acc.overlapping_pairs,
            overlap_share: ratio(acc.overlapping_pairs as f64, acc.neighbor_pairs as f64),
            overlap_at: acc.overlap_peak.map(|x| x.1),
            obstacles: Penetration {
                agent_ticks: acc.penetrating,
                inside_ticks: acc.inside,
                agents_inside: acc.agents_inside,
                closest: acc.closest.map(|x| x.0),
                closest_at: acc.closest.map(|x| x.1),
                closest_obstacle: acc.closest.map(|x| obstacle_label(&x.2)),
            },
            messages: acc.messages,
            messages_per_agent_second: ratio(acc.messages as f64, seconds),
            behaviors,
            frozen: frozen
                .into_iter()
                .take(FROZEN_EXAMPLES)
                .map(|f| Frozen {
                    agent: f.agent,
                    behavior: name(f.behavior),
                    start_tick: f.start,
                    seconds: f.ticks as f64 * dt,
                    pos: f.pos,
                    near: f.near.clone(),
                })
                .collect(),
        }
    }
}
