//! What a run's summary and a profile read of the pipeline: the running counters ([`Stats`],
//! added to by stage 7 and the script clock) and the wall time of each stage ([`StageTimes`]).
//! Nothing here changes what a tick does.

use super::Pipeline;
use std::time::Duration;

/// Counters a run summary reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Food items eaten.
    pub meals: u64,
    /// Prey caught.
    pub catches: u64,
    /// Matings.
    pub matings: u64,
    /// Behavior transitions.
    pub transitions: u64,
    /// Failed script calls (each agent's first one is also an event).
    pub script_errors: u64,
    /// Of those, calls stopped by a wall-time budget ([`crate::script::TimeBudget`]): when
    /// non-zero, the run's results depend on the machine's speed.
    pub script_timeouts: u64,
    /// Agent-ticks spent in each behavior, by species then behavior index.
    pub behavior_ticks: Vec<Vec<u64>>,
}

/// Wall time spent in each stage of the tick, summed over the ticks since the last
/// [`Pipeline::reset_stage_times`] (what a profile of the pipeline starts from: `shoal bench
/// --stages` prints it). Stages 3–6 run together, per agent, so they are one figure.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Stage 1: the spatial index (agent and food grids).
    pub index: Duration,
    /// Stage 2: perception.
    pub perception: Duration,
    /// Stages 3–6: drives, decision, steering and locomotion, per agent.
    pub agents: Duration,
    /// Stage 7: world events, in agent order.
    pub events: Duration,
    /// Ticks summed (calls of [`Pipeline::perceive`] alone count for stages 1–2 only).
    pub ticks: u64,
}

impl StageTimes {
    /// The stages' names, in pipeline order.
    pub const NAMES: [&'static str; 4] = ["index", "perception", "agents", "events"];

    /// The stages' names and their summed times, in pipeline order.
    pub fn parts(&self) -> [(&'static str, Duration); 4] {
        let [a, b, c, d] = Self::NAMES;
        [
            (a, self.index),
            (b, self.perception),
            (c, self.agents),
            (d, self.events),
        ]
    }

    /// The stages' names and their mean milliseconds per tick, in pipeline order.
    pub fn ms_per_tick(&self) -> [(&'static str, f64); 4] {
        let per = |d: Duration| 1e3 * d.as_secs_f64() / self.ticks.max(1) as f64;
        self.parts().map(|(name, d)| (name, per(d)))
    }
}
impl Pipeline {
    /// Wall time spent in each stage since the last [`Pipeline::reset_stage_times`] (or since
    /// the pipeline was made).
    pub fn stage_times(&self) -> StageTimes {
        self.times
    }

    /// Starts the stage times again from zero.
    pub fn reset_stage_times(&mut self) {
        self.times = StageTimes::default();
    }
}
