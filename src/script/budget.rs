//! Part of stage 4 (decision): wall-time guards of script calls.
//!
//! The deterministic bound of a script call is its operation limit ([`super::SandboxLimits`]): the same
//! script stops at the same operation on every machine. Wall time is not deterministic, so the
//! budgets here never decide what a run computes: a call that runs past its budget is aborted
//! with an error naming the script, the function and the agent, reported like any other script
//! error and counted apart ([`TimeBudget`] users such as `shoal run` then fail the whole run),
//! so a run whose results could depend on the machine's speed is never mistaken for a good one.
//!
//! Two budgets: per call (a legal call that fills a map can take ~70 ms), and per tick, the
//! script time the calls of one tick add up to on one worker thread (a slow `on_tick` at a high
//! decision rate). The engine's `on_progress` callback reads the current call's deadline from a
//! thread-local every [`CHECK_EVERY`] operations; the pipeline installs the tick's clock on each
//! thread that runs script calls ([`install`], [`with_tick`]).

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Operations between two looks at the clock (a look costs a thread-local read and `now()`).
pub const CHECK_EVERY: u64 = 512;

/// Wall-time budgets of script calls. `None` turns a budget off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimeBudget {
    /// Longest one call may run.
    pub per_call: Option<Duration>,
    /// Script time the calls of one tick may add up to on one worker thread.
    pub per_tick: Option<Duration>,
}

impl Default for TimeBudget {
    fn default() -> Self {
        TimeBudget {
            per_call: Some(Duration::from_millis(50)),
            per_tick: Some(Duration::from_millis(250)),
        }
    }
}

/// Which budget a call ran past.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exceeded {
    /// The call's own budget.
    Call(Duration),
    /// The tick's budget, shared by every call of the tick.
    Tick(Duration),
}

/// The clock of the current tick, shared by the threads that run its calls. Each thread adds up
/// its own calls' time (nothing is written to shared memory per call); a new tick is a new
/// epoch, which starts every thread again from zero.
#[derive(Debug, Default)]
pub struct TickClock {
    budget: TimeBudget,
    epoch: AtomicU64,
    exceeded: AtomicU64,
}

impl TickClock {
    /// A clock with these budgets.
    pub fn new(budget: TimeBudget) -> Self {
        TickClock {
            budget,
            ..Default::default()
        }
    }

    /// Starts a new tick: no script time spent yet on any thread.
    pub fn reset(&self) {
        self.epoch.fetch_add(1, Ordering::Relaxed);
    }

    /// The budgets.
    pub fn budget(&self) -> TimeBudget {
        self.budget
    }

    /// Calls aborted for time since the last call of this method.
    pub fn take_exceeded(&self) -> u64 {
        self.exceeded.swap(0, Ordering::Relaxed)
    }
}

thread_local! {
    static TICK: RefCell<Option<Arc<TickClock>>> = const { RefCell::new(None) };
    static DEADLINE: Cell<Option<(Instant, Exceeded)>> = const { Cell::new(None) };
    /// This thread's script time in the tick of that epoch.
    static SPENT: Cell<(u64, Duration)> = const { Cell::new((0, Duration::ZERO)) };
}

/// Makes `clock` this thread's tick clock until another is installed (for the worker threads
/// of a pool: called at the start of each job of the tick).
pub fn install(clock: &Arc<TickClock>) {
    TICK.with(|t| {
        let mut t = t.borrow_mut();
        if !t.as_ref().is_some_and(|c| Arc::ptr_eq(c, clock)) {
            *t = Some(clock.clone());
        }
    });
}

/// Runs `f` with `clock` as this thread's tick clock, then puts the previous one back.
pub fn with_tick<R>(clock: &Arc<TickClock>, f: impl FnOnce() -> R) -> R {
    let before = TICK.with(|t| t.borrow_mut().replace(clock.clone()));
    let r = f();
    TICK.with(|t| *t.borrow_mut() = before);
    r
}

/// This thread's script time in the current tick of its clock.
pub fn spent_on_this_thread() -> Duration {
    TICK.with(|t| {
        let t = t.borrow();
        let epoch = t.as_ref().map_or(0, |c| c.epoch.load(Ordering::Relaxed));
        let (e, d) = SPENT.get();
        if e == epoch {
            d
        } else {
            Duration::ZERO
        }
    })
}

/// A call being timed: sets the thread's deadline when made, clears it and books the time when
/// finished.
pub(crate) struct CallTimer {
    start: Instant,
    /// The tick's epoch, when a clock is installed.
    epoch: Option<u64>,
}

impl CallTimer {
    /// Starts timing a call under the thread's tick clock (or the default per-call budget
    /// outside a tick).
    pub(crate) fn start() -> Self {
        let start = Instant::now();
        let (budget, epoch) = TICK.with(|t| {
            t.borrow()
                .as_ref()
                .map_or((TimeBudget::default(), None), |c| {
                    (c.budget, Some(c.epoch.load(Ordering::Relaxed)))
                })
        });
        let call = budget.per_call.map(|d| (start + d, Exceeded::Call(d)));
        let tick = epoch.zip(budget.per_tick).map(|(epoch, d)| {
            let (e, spent) = SPENT.get();
            let spent = if e == epoch { spent } else { Duration::ZERO };
            (start + d.saturating_sub(spent), Exceeded::Tick(d))
        });
        let deadline = match (call, tick) {
            (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
            (a, b) => a.or(b),
        };
        DEADLINE.with(|d| d.set(deadline));
        CallTimer { start, epoch }
    }

    /// Stops timing; `aborted` says the call was stopped by its deadline.
    pub(crate) fn finish(self, aborted: bool) {
        DEADLINE.with(|d| d.set(None));
        let Some(epoch) = self.epoch else {
            return;
        };
        let (e, spent) = SPENT.get();
        let spent = if e == epoch { spent } else { Duration::ZERO };
        SPENT.set((epoch, spent + self.start.elapsed()));
        if aborted {
            TICK.with(|t| {
                if let Some(c) = t.borrow().as_ref() {
                    c.exceeded.fetch_add(1, Ordering::Relaxed);
                }
            });
        }
    }
}

/// Called by the engine's `on_progress`: the budget the current call ran past, if it did.
pub(crate) fn check(ops: u64) -> Option<Exceeded> {
    if !ops.is_multiple_of(CHECK_EVERY) {
        return None;
    }
    DEADLINE.with(|d| match d.get() {
        Some((at, which)) if Instant::now() >= at => Some(which),
        _ => None,
    })
}

/// The token an aborted call carries (`EvalAltResult::ErrorTerminated`), and back.
pub(crate) fn token(e: Exceeded) -> rhai::Dynamic {
    let mut m = rhai::Map::new();
    let (kind, d) = match e {
        Exceeded::Call(d) => ("call", d),
        Exceeded::Tick(d) => ("tick", d),
    };
    m.insert("time_budget".into(), kind.into());
    m.insert(
        "ms".into(),
        (d.as_millis().min(i64::MAX as u128) as rhai::INT).into(),
    );
    rhai::Dynamic::from_map(m)
}

/// The budget an `ErrorTerminated` token names, if it is one of ours.
pub fn exceeded_of(token: &rhai::Dynamic) -> Option<Exceeded> {
    let m = token.read_lock::<rhai::Map>()?;
    let kind = m.get("time_budget")?.clone().into_string().ok()?;
    let ms = m.get("ms")?.as_int().ok()?.max(0) as u64;
    let d = Duration::from_millis(ms);
    match kind.as_str() {
        "call" => Some(Exceeded::Call(d)),
        "tick" => Some(Exceeded::Tick(d)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spent_tick_leaves_no_time_to_the_next_call() {
        let clock = Arc::new(TickClock::new(TimeBudget {
            per_call: Some(Duration::from_secs(60)),
            per_tick: Some(Duration::from_millis(1)),
        }));
        with_tick(&clock, || {
            let t = CallTimer::start();
            std::thread::sleep(Duration::from_millis(3));
            t.finish(false);
            let t = CallTimer::start();
            assert_eq!(
                check(CHECK_EVERY),
                Some(Exceeded::Tick(Duration::from_millis(1)))
            );
            t.finish(true);
        });
        assert_eq!(clock.take_exceeded(), 1);
        assert_eq!(clock.take_exceeded(), 0);
        with_tick(&clock, || {
            assert!(spent_on_this_thread() >= Duration::from_millis(3));
            clock.reset();
            assert_eq!(spent_on_this_thread(), Duration::ZERO);
        });
        assert_eq!(check(CHECK_EVERY), None, "no call, no deadline");
    }

    #[test]
    fn tokens_round_trip() {
        for e in [
            Exceeded::Call(Duration::from_millis(50)),
            Exceeded::Tick(Duration::from_millis(250)),
        ] {
            assert_eq!(exceeded_of(&token(e)), Some(e));
        }
        assert_eq!(exceeded_of(&rhai::Dynamic::from(3 as rhai::INT)), None);
    }
}
