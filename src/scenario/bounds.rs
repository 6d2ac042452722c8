//! Run-health bounds of scenario expectations (`MaxFrozen`, `MaxSwitchRate`, …): what each
//! expects in words and how the figures of a species' run-health report are judged against it.
//! Not a tick stage: read by [`super::expect::Tracker`] at the end of a run, from the report of
//! [`crate::health`].

use crate::health::{self, SpeciesHealth};

/// A run-health bound (see [`crate::health`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Bound {
    Frozen(u64),
    SwitchRate(f32),
    PitchLimitShare(f32),
    ShortEpisodes(f32),
    TurningWaste(f32),
    Interpenetration(f32),
    ObstaclePenetration(u64),
}

impl Bound {
    /// What is expected of `sp`, in words.
    pub(super) fn expected(self, sp: &str) -> String {
        match self {
            Bound::Frozen(n) => format!(
                "at most {n} {sp} frozen (stopped ≥ {} s where their steering asks to move)",
                health::FROZEN_SECONDS
            ),
            Bound::SwitchRate(r) => {
                format!("at most {r} behavior switches per {sp} per second")
            }
            Bound::PitchLimitShare(f) => format!(
                "at most {} of {sp} agent-ticks at the pitch limit",
                health::percent(f as f64)
            ),
            Bound::ShortEpisodes(f) => format!(
                "at most {} of {sp} behavior episodes shorter than {} s",
                health::percent(f as f64),
                health::SHORT_EPISODE_SECONDS
            ),
            Bound::TurningWaste(r) => format!("{sp} turning waste at most {r}×"),
            Bound::Interpenetration(f) => format!(
                "at most {} of {sp} neighbor pairs overlapping by more than 10% of the body width",
                health::percent(f as f64)
            ),
            Bound::ObstaclePenetration(n) => format!(
                "at most {n} {sp} agent-ticks inside or within half a body width of an obstacle"
            ),
        }
    }

    /// Whether the figures of `s` keep the bound, and what they are (with the bound).
    pub(super) fn judge(self, s: &SpeciesHealth) -> (bool, String) {
        match self {
            Bound::Frozen(n) => {
                let mut text = format!("{} frozen (bound {n})", s.frozen_agents);
                if let Some(b) = s.behaviors.iter().max_by_key(|b| b.frozen_agents) {
                    if b.frozen_agents > 0 {
                        text.push_str(&format!("; {} in {}", b.frozen_agents, b.name));
                        if let Some(at) = b.frozen_at.first() {
                            text.push_str(&format!(", {} at {}", at.agents, at.place));
                        }
                    }
                }
                (s.frozen_agents <= n, text)
            }
            Bound::SwitchRate(r) => {
                let mut text = format!(
                    "{:.2} switches per agent per second (bound {r})",
                    s.switch_rate
                );
                if let Some(f) = s.flips.first() {
                    text.push_str(&format!(
                        "; most frequent flip {}↔{} ({})",
                        f.a,
                        f.b,
                        health::thousands(f.count)
                    ));
                }
                (s.switch_rate <= r as f64, text)
            }
            Bound::PitchLimitShare(f) => (
                s.pitch_limit_share <= f as f64,
                format!(
                    "{} at the pitch limit (bound {})",
                    health::percent(s.pitch_limit_share),
                    health::percent(f as f64)
                ),
            ),
            Bound::ShortEpisodes(f) => (
                s.short_episode_share <= f as f64,
                format!(
                    "{} of {} episodes short (bound {})",
                    health::percent(s.short_episode_share),
                    health::thousands(s.episodes),
                    health::percent(f as f64)
                ),
            ),
            Bound::TurningWaste(r) => match s.turning_waste {
                Some(w) => (w <= r as f64, format!("turning waste {w:.2}× (bound {r}×)")),
                None => (true, format!("no heading change measured (bound {r}×)")),
            },
            Bound::Interpenetration(f) => (
                s.overlap_share <= f as f64,
                format!(
                    "{} of {} neighbor pairs overlap (bound {})",
                    health::percent(s.overlap_share),
                    health::thousands(s.neighbor_pairs),
                    health::percent(f as f64)
                ),
            ),
            Bound::ObstaclePenetration(n) => {
                let o = &s.obstacles;
                (
                    o.agent_ticks <= n,
                    format!(
                        "{} agent-ticks, {} of them inside (bound {n})",
                        health::thousands(o.agent_ticks),
                        health::thousands(o.inside_ticks)
                    ),
                )
            }
        }
    }
}
