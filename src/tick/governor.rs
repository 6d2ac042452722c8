//! Choosing, tick by tick, whether a tick runs on the whole thread pool or on one thread.
//!
//! A tick is a chain of parallel passes, each ending when its last piece does. When another
//! process holds one of the two cores, the pool's second thread is pre-empted in the middle of
//! pieces it took, and every pass waits for it: measured on the 2-core machine of
//! `BENCHMARKS.md`, two threads then ran boids at half the speed of one. Which thread runs what
//! changes nothing in the results (every pass writes per-agent outputs), so the tick may run
//! either way; the governor measures both and keeps the faster. It runs the current mode, and
//! every so often a couple of probe ticks in the other, comparing wall time per agent; a probe
//! that loses makes the next one come later (up to [`MAX_INTERVAL`] ticks), so a quiet machine
//! pays well under 1 % for the watch. One-thread ticks run on a pool of one thread of their own.
//! Not a tick stage: [`super::Pipeline::step`] asks it how to run each tick.

use std::time::Duration;

/// How a tick runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// On the pool the tick was called from (all its threads).
    Pool,
    /// On one thread.
    Solo,
}

impl Mode {
    fn other(self) -> Mode {
        match self {
            Mode::Pool => Mode::Solo,
            Mode::Solo => Mode::Pool,
        }
    }
}

/// How the governor decides (tests and benchmarks may fix the mode).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Schedule {
    /// Measure and keep the faster mode (the default).
    #[default]
    Adaptive,
    /// Always this mode.
    Fixed(Mode),
    /// Switch every tick (tests: results must not depend on it).
    Alternate,
}

/// Ticks before the first probe: a short run should not spend its first ticks in the wrong mode.
pub const FIRST_PROBE: u64 = 4;
/// Ticks between probes after a switch.
pub const MIN_INTERVAL: u64 = 16;
/// Longest interval between probes.
pub const MAX_INTERVAL: u64 = 512;
/// Probe ticks in a row: the first pays the other mode's warm-up, the second is the one timed.
const PROBE_TICKS: u64 = 2;
/// A probe must be this much faster to switch (noise between two ticks is a few percent).
const MARGIN: f64 = 0.9;
/// Weight of a new tick in the running figure of its mode.
const SMOOTHING: f64 = 0.25;

/// The governor's state: per mode, a running wall time per agent; when the next probe is due.
#[derive(Debug)]
pub struct Governor {
    /// How it decides.
    pub schedule: Schedule,
    mode: Mode,
    per_agent: [Option<f64>; 2],
    /// Ticks in the current mode until the next probe.
    until_probe: u64,
    interval: u64,
    /// Probe ticks left (0: not probing).
    probing: u64,
    ticks: u64,
}

impl Default for Governor {
    fn default() -> Self {
        Governor {
            schedule: Schedule::Adaptive,
            mode: Mode::Pool,
            per_agent: [None, None],
            until_probe: FIRST_PROBE,
            interval: MIN_INTERVAL,
            probing: 0,
            ticks: 0,
        }
    }
}

fn slot(m: Mode) -> usize {
    match m {
        Mode::Pool => 0,
        Mode::Solo => 1,
    }
}

impl Governor {
    /// The mode the next tick runs in.
    pub fn next_mode(&mut self) -> Mode {
        match self.schedule {
            Schedule::Fixed(m) => m,
            Schedule::Alternate => {
                if self.ticks.is_multiple_of(2) {
                    Mode::Pool
                } else {
                    Mode::Solo
                }
            }
            Schedule::Adaptive => {
                if self.probing == 0 && self.until_probe == 0 {
                    self.probing = PROBE_TICKS;
                }
                if self.probing > 0 {
                    self.mode.other()
                } else {
                    self.mode
                }
            }
        }
    }

    /// Records that a tick of `agents` agents ran in `mode` and took `took`.
    pub fn record(&mut self, mode: Mode, agents: usize, took: Duration) {
        self.ticks += 1;
        if self.schedule != Schedule::Adaptive {
            return;
        }
        let t = took.as_secs_f64() / agents.max(1) as f64;
        if self.probing > 0 {
            self.probing -= 1;
            if self.probing > 0 {
                // The warm-up tick of a probe is not timed.
                return;
            }
            let ours = self.per_agent[slot(self.mode)];
            self.per_agent[slot(mode)] = Some(t);
            if ours.is_some_and(|ours| t < ours * MARGIN) {
                self.mode = mode;
                self.interval = MIN_INTERVAL;
            } else {
                self.interval = (self.interval * 2).min(MAX_INTERVAL);
            }
            self.until_probe = self.interval;
            return;
        }
        let run = &mut self.per_agent[slot(mode)];
        *run = Some(run.map_or(t, |r| r + SMOOTHING * (t - r)));
        self.until_probe = self.until_probe.saturating_sub(1);
    }

    /// The mode ticks run in outside probes.
    pub fn mode(&self) -> Mode {
        self.mode
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Drives a governor with tick times given by `cost(mode, tick)` for `ticks` ticks; returns
    /// the modes it ran.
    fn drive(g: &mut Governor, ticks: usize, cost: impl Fn(Mode, usize) -> f64) -> Vec<Mode> {
        (0..ticks)
            .map(|k| {
                let m = g.next_mode();
                g.record(m, 1000, Duration::from_secs_f64(cost(m, k)));
                m
            })
            .collect()
    }

    #[test]
    fn a_slower_other_mode_is_probed_less_and_less_often() {
        let mut g = Governor::default();
        let modes = drive(&mut g, 4000, |m, _| if m == Mode::Pool { 1.0 } else { 2.0 });
        assert_eq!(g.mode(), Mode::Pool);
        let solo = modes.iter().filter(|&&m| m == Mode::Solo).count();
        // 2 ticks per probe, probes after 4 ticks, then 32, 64, … then every 512 ticks.
        assert!(solo > 0 && solo <= 2 * 12, "{solo} solo ticks of 4000");
        assert_eq!(g.interval, MAX_INTERVAL);
    }

    #[test]
    fn the_governor_moves_to_the_faster_mode_and_back_when_it_changes() {
        let mut g = Governor::default();
        // A busy core from tick 100 to 1100: one thread is then faster.
        let busy = |k: usize| (100..1100).contains(&k);
        let cost = |m: Mode, k: usize| match (m, busy(k)) {
            (Mode::Pool, false) => 1.0,
            (Mode::Solo, false) => 1.8,
            (Mode::Pool, true) => 4.0,
            (Mode::Solo, true) => 2.0,
        };
        let modes = drive(&mut g, 2400, cost);
        // Within a few hundred ticks of each change, the faster mode runs (probes aside).
        let solo_share = |r: std::ops::Range<usize>| {
            modes[r.clone()]
                .iter()
                .filter(|&&m| m == Mode::Solo)
                .count() as f64
                / r.len() as f64
        };
        assert!(solo_share(700..1100) > 0.95, "{}", solo_share(700..1100));
        assert!(solo_share(1700..2400) < 0.05, "{}", solo_share(1700..2400));
    }

    #[test]
    fn a_difference_within_the_noise_margin_does_not_switch() {
        let mut g = Governor::default();
        drive(
            &mut g,
            2000,
            |m, _| if m == Mode::Pool { 1.0 } else { 0.95 },
        );
        assert_eq!(g.mode(), Mode::Pool);
    }

    #[test]
    fn fixed_and_alternate_schedules_ignore_the_clock() {
        let mut g = Governor {
            schedule: Schedule::Fixed(Mode::Solo),
            ..Governor::default()
        };
        assert!(drive(&mut g, 50, |_, _| 1.0)
            .iter()
            .all(|&m| m == Mode::Solo));
        let mut g = Governor {
            schedule: Schedule::Alternate,
            ..Governor::default()
        };
        let modes = drive(&mut g, 6, |_, _| 1.0);
        assert_eq!(
            modes,
            [
                Mode::Pool,
                Mode::Solo,
                Mode::Pool,
                Mode::Solo,
                Mode::Pool,
                Mode::Solo
            ]
        );
    }
}
