//! Designer-facing warnings: the figures of a [`Health`] report that break their default
//! bounds, in words, each with a tick and an agent to look at.

use super::{
    Health, SpeciesHealth, Spot, FROZEN_SECONDS, MAX_COINCIDENT, MAX_FROZEN,
    MAX_OBSTACLE_PENETRATION, MAX_OVERLAP_SHARE, MAX_PITCH_LIMIT_SHARE, MAX_SHORT_EPISODE_SHARE,
    MAX_STOPPED_SHARE, MAX_SWITCH_RATE, MAX_TURNING_WASTE, SHORT_EPISODE_SECONDS,
    TURN_WINDOW_SECONDS,
};
use serde::{Deserialize, Serialize};

/// Which figure a warning is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Figure {
    /// Stopped share of a behavior that asks to move.
    Stopped,
    /// Frozen agents in a behavior.
    Frozen,
    /// Share of agent-ticks at the pitch limit.
    PitchLimit,
    /// Behavior switches per agent per second.
    SwitchRate,
    /// Share of short behavior episodes.
    ShortEpisodes,
    /// Turning ÷ net heading change.
    TurningWaste,
    /// Coincident agents.
    Coincident,
    /// Overlapping same-species neighbors.
    Overlap,
    /// Agent-ticks in or against obstacles.
    ObstaclePenetration,
}

/// One line for the designer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Warning {
    /// The species (none for figures over all species).
    pub species: Option<String>,
    /// The behavior, for per-behavior figures.
    pub behavior: Option<String>,
    /// Which figure.
    pub figure: Figure,
    /// Its value.
    pub value: f64,
    /// The bound it broke.
    pub bound: f64,
    /// The line, in words.
    pub message: String,
    /// A tick to look at.
    pub tick: Option<u64>,
    /// An agent to look at.
    pub agent: Option<u32>,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.message)?;
        match (self.tick, self.agent) {
            (Some(t), Some(a)) => write!(f, " [tick {t}, agent {a}]"),
            (Some(t), None) => write!(f, " [tick {t}]"),
            _ => Ok(()),
        }
    }
}

/// `1234567` → `1,234,567`.
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::with_capacity(s.len() + s.len() / 3);
    for (k, c) in s.chars().enumerate() {
        if k > 0 && (s.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A share as a percentage: one decimal below 10 %, none above.
pub fn percent(x: f64) -> String {
    if x < 0.1 {
        format!("{:.1}%", x * 100.0)
    } else {
        format!("{:.0}%", x * 100.0)
    }
}

fn plural(n: u64, one: &str, many: &str) -> String {
    format!("{} {}", thousands(n), if n == 1 { one } else { many })
}

struct Out<'a> {
    species: &'a str,
    list: Vec<Warning>,
}

impl Out<'_> {
    fn push(
        &mut self,
        behavior: Option<&str>,
        figure: Figure,
        (value, bound): (f64, f64),
        message: String,
        spot: Option<Spot>,
    ) {
        self.list.push(Warning {
            species: (!self.species.is_empty()).then(|| self.species.to_string()),
            behavior: behavior.map(str::to_string),
            figure,
            value,
            bound,
            message,
            tick: spot.map(|s| s.tick),
            agent: spot.map(|s| s.agent),
        });
    }
}

impl Health {
    /// The figures that break their default bounds, species by species in the report's order
    /// (the worst problems of a species first: frozen agents, stops, then the rest).
    pub fn warnings(&self) -> Vec<Warning> {
        let mut out = Out {
            species: "",
            list: Vec::new(),
        };
        for s in &self.species {
            out.species = &s.name;
            species_warnings(s, &mut out);
        }
        let c = &self.coincident;
        if c.max > MAX_COINCIDENT {
            out.species = "";
            out.push(
                None,
                Figure::Coincident,
                (c.max as f64, MAX_COINCIDENT as f64),
                format!(
                    "up to {} of agents closer than {} in one sampled tick (mean {:.2}; bound {MAX_COINCIDENT})",
                    plural(c.max, "pair", "pairs"),
                    super::COINCIDENT_DISTANCE,
                    c.mean
                ),
                c.max_at,
            );
        }
        out.list
    }
}

fn species_warnings(s: &SpeciesHealth, out: &mut Out) {
    let name = s.name.clone();
    for b in &s.behaviors {
        if b.frozen_agents > MAX_FROZEN {
            let mut msg = format!(
                "{name}: {} stopped ≥ {FROZEN_SECONDS} s in {}",
                plural(b.frozen_agents, "agent", "agents"),
                b.name
            );
            if let Some(top) = b.frozen_at.first() {
                if b.frozen_agents == 1 {
                    msg.push_str(&format!(", at {}", top.place));
                } else if top.agents == b.frozen_agents {
                    msg.push_str(&format!(", all at {}", top.place));
                } else {
                    msg.push_str(&format!(", {} of them at {}", top.agents, top.place));
                }
            }
            out.push(
                Some(&b.name),
                Figure::Frozen,
                (b.frozen_agents as f64, MAX_FROZEN as f64),
                msg,
                b.longest_frozen,
            );
        }
    }
    for b in &s.behaviors {
        if !b.may_stop && b.agent_ticks > 0 && b.stopped_share > MAX_STOPPED_SHARE {
            out.push(
                Some(&b.name),
                Figure::Stopped,
                (b.stopped_share, MAX_STOPPED_SHARE),
                format!(
                    "{name}: stopped {} of the time in {}, whose steering asks to move (bound {})",
                    percent(b.stopped_share),
                    b.name,
                    percent(MAX_STOPPED_SHARE)
                ),
                b.longest_stop,
            );
        }
    }
    if s.switch_rate > MAX_SWITCH_RATE {
        let mut msg = format!(
            "{name}: {:.2} behavior switches per agent per second (bound {MAX_SWITCH_RATE})",
            s.switch_rate
        );
        let mut spot = s.most_switches_at;
        if let Some(f) = s.flips.first() {
            msg.push_str(&format!(
                "; most frequent flip {}↔{} ({})",
                f.a,
                f.b,
                thousands(f.count)
            ));
            spot = Some(f.first);
        }
        out.push(
            None,
            Figure::SwitchRate,
            (s.switch_rate, MAX_SWITCH_RATE),
            msg,
            spot,
        );
    }
    if s.judged(Figure::ShortEpisodes) && s.short_episode_share > MAX_SHORT_EPISODE_SHARE {
        out.push(
            None,
            Figure::ShortEpisodes,
            (s.short_episode_share, MAX_SHORT_EPISODE_SHARE),
            format!(
                "{name}: {} of {} behavior episodes shorter than {SHORT_EPISODE_SECONDS} s, {} a single tick (bound {})",
                percent(s.short_episode_share),
                thousands(s.episodes),
                percent(s.one_tick_share),
                percent(MAX_SHORT_EPISODE_SHARE)
            ),
            s.short_episode_at,
        );
    }
    if s.judged(Figure::PitchLimit) && s.pitch_limit_share > MAX_PITCH_LIMIT_SHARE {
        out.push(
            None,
            Figure::PitchLimit,
            (s.pitch_limit_share, MAX_PITCH_LIMIT_SHARE),
            format!(
                "{name}: at the pitch limit {} of the time (bound {})",
                percent(s.pitch_limit_share),
                percent(MAX_PITCH_LIMIT_SHARE)
            ),
            s.pitch_limit_at,
        );
    }
    if let Some(w) = s.turning_waste.filter(|w| *w > MAX_TURNING_WASTE) {
        out.push(
            None,
            Figure::TurningWaste,
            (w, MAX_TURNING_WASTE),
            format!(
                "{name}: turns {w:.2}× as far as its heading changes over {TURN_WINDOW_SECONDS} s (bound {MAX_TURNING_WASTE}×)"
            ),
            s.turning_waste_at,
        );
    }
    if s.overlap_share > MAX_OVERLAP_SHARE {
        out.push(
            None,
            Figure::Overlap,
            (s.overlap_share, MAX_OVERLAP_SHARE),
            format!(
                "{name}: {} of neighbor pairs overlap by more than 10% of the body width (bound {})",
                percent(s.overlap_share),
                percent(MAX_OVERLAP_SHARE)
            ),
            s.overlap_at,
        );
    }
    let o = &s.obstacles;
    if o.agent_ticks > MAX_OBSTACLE_PENETRATION {
        let mut msg = format!(
            "{name}: {} inside an obstacle or within half a body width of it (bound {MAX_OBSTACLE_PENETRATION})",
            plural(o.agent_ticks, "agent-tick", "agent-ticks")
        );
        if o.inside_ticks > 0 {
            msg.push_str(&format!(
                "; {} inside, {} ever inside",
                thousands(o.inside_ticks),
                plural(o.agents_inside, "agent", "agents")
            ));
        }
        if let (Some(d), Some(at)) = (o.closest, &o.closest_obstacle) {
            if d < 0.0 {
                msg.push_str(&format!("; deepest {:.2} inside {at}", -d));
            } else {
                msg.push_str(&format!("; closest {d:.2} from {at}"));
            }
        }
        out.push(
            None,
            Figure::ObstaclePenetration,
            (o.agent_ticks as f64, MAX_OBSTACLE_PENETRATION as f64),
            msg,
            o.closest_at,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_easily() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1234), "1,234");
        assert_eq!(thousands(1234567), "1,234,567");
        assert_eq!(percent(0.031), "3.1%");
        assert_eq!(percent(0.5), "50%");
    }
}
