//! What a live session shows to its viewers: the latest world description, frame, diagnostics,
//! run-health figures and reload messages, each with a sequence number. Every stream reader keeps the numbers it
//! has sent and is woken when one changes; a slow reader skips frames instead of queueing them.

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Duration;

/// Reload messages kept for readers that connect late (only the newest matter).
const RELOADS_KEPT: usize = 8;

/// Runtime script errors kept, and sent to a reader that connects late: an error raised before
/// the page opened must still show.
const ERRORS_KEPT: usize = 8;

/// Longest message kept (bytes): a diagnostic that echoes a huge line, or a huge script error,
/// must not grow every `/status` answer, stream event and record line with it.
pub const MAX_MESSAGE: usize = 4 * 1024;

/// `message`, cut to at most [`MAX_MESSAGE`] bytes (on a character boundary) with an ellipsis
/// saying how much was left out.
pub fn cap_message(message: &str) -> String {
    if message.len() <= MAX_MESSAGE {
        return message.to_string();
    }
    let tail = format!("… ({} more bytes)", message.len());
    let mut end = MAX_MESSAGE.saturating_sub(tail.len());
    while !message.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}… ({} more bytes)", &message[..end], message.len() - end)
}

/// Where a live session stands.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SessionStatus {
    /// Ticks done.
    pub tick: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Version of the scenario running (0 = as started).
    pub version: u32,
    /// Whether the simulation is paused.
    pub paused: bool,
    /// Simulated seconds per wall-clock second.
    pub speed: f32,
    /// Agents alive.
    pub agents: usize,
    /// Diagnostics of the last rejected edit, empty once it is fixed.
    pub diagnostics: Vec<String>,
    /// The breakpoints set ([`super::breakpoints`]).
    pub breakpoints: Vec<super::breakpoints::Listed>,
    /// The breakpoint that paused the run, until it runs again.
    pub hit: Option<super::breakpoints::Hit>,
}

#[derive(Debug, Clone, Default)]
struct Item {
    seq: u64,
    data: Option<Arc<str>>,
}

#[derive(Debug)]
struct State {
    world: Item,
    diagnostics: Item,
    frame: Item,
    health: Item,
    reloads: VecDeque<(u64, Arc<str>)>,
    reload_seq: u64,
    errors: VecDeque<(u64, Arc<str>)>,
    error_seq: u64,
    breakpoint: Item,
    status: SessionStatus,
    closed: bool,
}

/// The latest of everything a viewer is sent, shared between the simulation, the loader and the
/// stream readers.
#[derive(Debug)]
pub struct Hub {
    state: Mutex<State>,
    changed: Condvar,
}

/// What a stream reader has already sent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Seen {
    world: u64,
    diagnostics: u64,
    frame: u64,
    health: u64,
    reload: u64,
    error: u64,
    breakpoint: u64,
    started: bool,
}

/// Server-sent event names of the live protocol.
pub mod event {
    /// The world description (bounds, obstacles, species and their behaviors).
    pub const WORLD: &str = "world";
    /// One frame of agent states.
    pub const FRAME: &str = "frame";
    /// The diagnostics of a rejected edit (an empty array once fixed).
    pub const DIAGNOSTICS: &str = "diagnostics";
    /// A version was swapped in.
    pub const RELOAD: &str = "reload";
    /// The run-health figures of the version running (about once a second).
    pub const HEALTH: &str = "health";
    /// A runtime script error (agent, species, function, place, message).
    pub const SCRIPT_ERROR: &str = "script_error";
    /// The breakpoint that paused the run (`null` once it runs again).
    pub const BREAKPOINT: &str = "breakpoint";
}

impl Hub {
    /// An empty hub; nothing is sent before the first world and frame are published.
    pub fn new() -> Arc<Hub> {
        Arc::new(Hub {
            state: Mutex::new(State {
                world: Item::default(),
                diagnostics: Item {
                    seq: 1,
                    data: Some("[]".into()),
                },
                frame: Item::default(),
                health: Item::default(),
                reloads: VecDeque::new(),
                reload_seq: 0,
                errors: VecDeque::new(),
                error_seq: 0,
                breakpoint: Item::default(),
                status: SessionStatus {
                    tick: 0,
                    time: 0.0,
                    version: 0,
                    paused: false,
                    speed: 1.0,
                    agents: 0,
                    diagnostics: Vec::new(),
                    breakpoints: Vec::new(),
                    hit: None,
                },
                closed: false,
            }),
            changed: Condvar::new(),
        })
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A reader that panicked leaves consistent data behind: every update is one assignment.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn bump(item: &mut Item, data: Arc<str>) {
        item.seq += 1;
        item.data = Some(data);
    }

    /// Publishes a new world description (JSON).
    pub fn set_world(&self, json: String) {
        Self::bump(&mut self.lock().world, json.into());
        self.changed.notify_all();
    }

    /// Publishes a new frame (JSON).
    pub fn set_frame(&self, json: String) {
        Self::bump(&mut self.lock().frame, json.into());
        self.changed.notify_all();
    }

    /// Publishes the run-health figures (JSON).
    pub fn set_health(&self, json: String) {
        Self::bump(&mut self.lock().health, json.into());
        self.changed.notify_all();
    }

    /// Publishes the diagnostics of the last rejected edit (empty: none). Returns whether they
    /// changed.
    pub fn set_diagnostics(&self, lines: &[String]) -> bool {
        let lines: Vec<String> = lines.iter().map(|l| cap_message(l)).collect();
        let json = serde_json::to_string(&lines).unwrap_or_else(|_| "[]".into());
        let mut s = self.lock();
        if s.diagnostics.data.as_deref() == Some(json.as_str()) {
            return false;
        }
        Self::bump(&mut s.diagnostics, json.into());
        s.status.diagnostics = lines;
        drop(s);
        self.changed.notify_all();
        true
    }

    /// Publishes a reload message (`{"message": ...}`).
    pub fn push_reload(&self, message: &str) {
        let json = serde_json::json!({ "message": cap_message(message) }).to_string();
        let mut s = self.lock();
        s.reload_seq += 1;
        let seq = s.reload_seq;
        s.reloads.push_back((seq, json.into()));
        while s.reloads.len() > RELOADS_KEPT {
            s.reloads.pop_front();
        }
        drop(s);
        self.changed.notify_all();
    }

    /// Publishes a runtime script error (JSON, its message already cut with [`cap_message`]:
    /// cutting the JSON itself would break it); the last few are kept for late readers.
    pub fn push_script_error(&self, json: String) {
        let mut s = self.lock();
        s.error_seq += 1;
        let seq = s.error_seq;
        s.errors.push_back((seq, json.into()));
        while s.errors.len() > ERRORS_KEPT {
            s.errors.pop_front();
        }
        drop(s);
        self.changed.notify_all();
    }

    /// Publishes the breakpoint that paused the run (`None`: running again).
    pub fn set_hit(&self, hit: Option<super::breakpoints::Hit>) {
        let json = serde_json::to_string(&hit).unwrap_or_else(|_| "null".into());
        let mut s = self.lock();
        if s.status.hit == hit {
            return;
        }
        s.status.hit = hit;
        Self::bump(&mut s.breakpoint, json.into());
        drop(s);
        self.changed.notify_all();
    }

    /// Updates the status with `f`.
    pub fn update_status(&self, f: impl FnOnce(&mut SessionStatus)) {
        f(&mut self.lock().status);
    }

    /// The current status.
    pub fn status(&self) -> SessionStatus {
        self.lock().status.clone()
    }

    /// Wakes every reader and tells it to stop.
    pub fn close(&self) {
        self.lock().closed = true;
        self.changed.notify_all();
    }

    /// Whether the hub was closed.
    pub fn is_closed(&self) -> bool {
        self.lock().closed
    }

    /// Waits up to `timeout` for something `seen` has not sent yet and returns it as
    /// `(event name, data)` pairs in the order a viewer needs them (world before the frames that
    /// refer to it). `None` once the hub is closed; an empty list on timeout.
    pub fn next(
        &self,
        seen: &mut Seen,
        timeout: Duration,
    ) -> Option<Vec<(&'static str, Arc<str>)>> {
        let mut s = self.lock();
        let fresh = |s: &State, seen: &Seen| {
            (s.world.data.is_some() && s.world.seq != seen.world)
                || s.diagnostics.seq != seen.diagnostics
                || (s.frame.data.is_some() && s.frame.seq != seen.frame)
                || (s.health.data.is_some() && s.health.seq != seen.health)
                || (seen.started && s.reload_seq != seen.reload)
                || s.error_seq != seen.error
                || (s.breakpoint.data.is_some() && s.breakpoint.seq != seen.breakpoint)
        };
        if !s.closed && !fresh(&s, seen) {
            s = self
                .changed
                .wait_timeout_while(s, timeout, |s| !s.closed && !fresh(s, seen))
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        if s.closed {
            return None;
        }
        let mut out = Vec::new();
        if let (Some(d), true) = (&s.world.data, s.world.seq != seen.world) {
            out.push((event::WORLD, d.clone()));
            seen.world = s.world.seq;
        }
        if let (Some(d), true) = (&s.diagnostics.data, s.diagnostics.seq != seen.diagnostics) {
            out.push((event::DIAGNOSTICS, d.clone()));
            seen.diagnostics = s.diagnostics.seq;
        }
        if !seen.started {
            // A reader that connects late does not replay old reload messages.
            seen.started = true;
            seen.reload = s.reload_seq;
        } else if s.reload_seq != seen.reload {
            for (seq, d) in &s.reloads {
                if *seq > seen.reload {
                    out.push((event::RELOAD, d.clone()));
                }
            }
            seen.reload = s.reload_seq;
        }
        if s.error_seq != seen.error {
            // A late reader gets the kept ones too.
            for (seq, d) in &s.errors {
                if *seq > seen.error {
                    out.push((event::SCRIPT_ERROR, d.clone()));
                }
            }
            seen.error = s.error_seq;
        }
        if let (Some(d), true) = (&s.breakpoint.data, s.breakpoint.seq != seen.breakpoint) {
            out.push((event::BREAKPOINT, d.clone()));
            seen.breakpoint = s.breakpoint.seq;
        }
        // Frames need a world first.
        if let (Some(d), true) = (&s.frame.data, s.frame.seq != seen.frame && seen.world != 0) {
            out.push((event::FRAME, d.clone()));
            seen.frame = s.frame.seq;
        }
        if let (Some(d), true) = (&s.health.data, s.health.seq != seen.health) {
            out.push((event::HEALTH, d.clone()));
            seen.health = s.health.seq;
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[(&'static str, Arc<str>)]) -> Vec<&'static str> {
        v.iter().map(|x| x.0).collect()
    }

    #[test]
    fn world_comes_before_frames_and_slow_readers_skip_frames() {
        let hub = Hub::new();
        hub.set_frame("{\"tick\":1}".into());
        hub.set_world("{}".into());
        hub.set_frame("{\"tick\":2}".into());
        let mut seen = Seen::default();
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        assert_eq!(names(&got), ["world", "diagnostics", "frame"]);
        assert_eq!(&*got[2].1, "{\"tick\":2}");
        assert!(hub
            .next(&mut seen, Duration::from_millis(1))
            .unwrap()
            .is_empty());
        hub.push_reload("v1");
        hub.set_diagnostics(&["a.ron:1:2: bad".into()]);
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        assert_eq!(names(&got), ["diagnostics", "reload"]);
        assert_eq!(&*got[0].1, "[\"a.ron:1:2: bad\"]");
        assert!(!hub.set_diagnostics(&["a.ron:1:2: bad".into()]));
        hub.set_health("{\"ticks\":20}".into());
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        assert_eq!(names(&got), ["health"]);
        hub.close();
        assert!(hub.next(&mut seen, Duration::from_secs(5)).is_none());
    }

    #[test]
    fn long_messages_are_capped_with_an_ellipsis() {
        assert_eq!(cap_message("short"), "short");
        // Multi-byte characters around the cut.
        let long = "é".repeat(1_000_000);
        let c = cap_message(&long);
        assert!(c.len() <= MAX_MESSAGE, "{}", c.len());
        assert!(c.ends_with("more bytes)"), "{}", &c[c.len() - 40..]);
        assert!(c.starts_with("éé"));
        let exact = "x".repeat(MAX_MESSAGE);
        assert_eq!(cap_message(&exact), exact);

        let hub = Hub::new();
        hub.set_diagnostics(&[long.clone(), "b.ron:1:1: short".into()]);
        let st = hub.status();
        assert!(st.diagnostics[0].len() <= MAX_MESSAGE);
        assert_eq!(st.diagnostics[1], "b.ron:1:1: short");
        let mut seen = Seen::default();
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        let diag = got.iter().find(|x| x.0 == event::DIAGNOSTICS).unwrap();
        assert!(diag.1.len() < 2 * MAX_MESSAGE);
        hub.push_reload(&long);
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        assert!(got[0].1.len() < 2 * MAX_MESSAGE);
    }

    #[test]
    fn a_late_reader_does_not_replay_old_reload_messages() {
        let hub = Hub::new();
        hub.set_world("{}".into());
        hub.push_reload("old");
        let mut seen = Seen::default();
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        assert!(!names(&got).contains(&"reload"));
        hub.push_reload("new");
        let got = hub.next(&mut seen, Duration::from_millis(1)).unwrap();
        assert_eq!(names(&got), ["reload"]);
        assert!(got[0].1.contains("new"));
    }
}
