//! A small live-editing project on disk (scenario, species file, script and an imported module)
//! and helpers to wait for what a live session reports.
#![allow(dead_code)]

use shoal::live::{LiveEvent, Session};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The test fish: grazes when its hunger is above the threshold, wanders otherwise. Drives are
/// not native, so each fish keeps the hunger it was spawned with; its script counts its decision
/// passes on its blackboard (`n`), through an imported module.
pub const FISH: &str = r##"// Test fish: grazes when hungry enough, wanders otherwise.
Species(
    name: "fish",
    color: "#f0a030",
    body: (limits: (max_speed: 2.0, max_turn: 1.0)),
    drives: (native: false),
    script: Some("fish.rhai"),
    memory: { "n": Int(None), "edit": Int(None) },
    decision_interval: 2,
    initial: "wander",
    behaviors: [
        Behavior(
            name: "graze",
            priority: 2,
            when: Above(Drive(Hunger), 0.95),
            done: Below(Drive(Hunger), 0.95),
            steer: Priority([Contain(), Cruise(speed: 0.2)]),
        ),
        Behavior(
            name: "wander",
            priority: 3,
            steer: Priority([Contain(), Wander(cruise: 0.4)]),
        ),
    ],
)
"##;

/// The fish's script.
pub const FISH_RHAI: &str = r#"import "common/util" as util;

// Counts decision passes on the blackboard.
fn on_tick() {
    let n = if this.has("n") { this["n"] } else { 0 };
    this["n"] = util::next(n);
}
"#;

/// The imported module.
pub const UTIL_RHAI: &str = "fn next(n) { n + 1 }\n";

/// A crab, added live.
pub const CRAB: &str = r##"Species(
    name: "crab",
    color: "#c04020",
    initial: "walk",
    behaviors: [
        Behavior(name: "walk", priority: 1, steer: Priority([Contain(), Wander(cruise: 0.3)])),
    ],
)
"##;

/// The scenario.
pub const SCENARIO: &str = r#"// Live-editing test world.
Scenario(
    seed: 5,
    dt: 0.05,
    duration: 10.0,
    bounds: (min: (-20.0, 0.0, -20.0), max: (20.0, 10.0, 20.0)),
    species: ["fish"],
    groups: [
        (species: "fish", count: 24, region: (min: (-10.0, 2.0, -10.0), max: (10.0, 8.0, 10.0)), drives: (hunger: Some(Uniform(0.1, 0.9)))),
    ],
)
"#;

/// A fish for debugging tests: `dart` (priority 2, by chance) over `wander`; its script fails in
/// `oops()` on its 40th decision pass.
pub const DEBUG_FISH: &str = r##"// Debugging test fish: darts now and then; its script fails after a while.
Species(
    name: "fish",
    color: "#f0a030",
    body: (limits: (max_speed: 2.0, max_turn: 1.0)),
    drives: (native: false),
    script: Some("fish.rhai"),
    memory: { "n": Int(None), "edit": Int(None) },
    decision_interval: 2,
    initial: "wander",
    behaviors: [
        Behavior(
            name: "dart",
            priority: 2,
            when: Chance(0.5),
            done: TimeIn(0.5),
            steer: Priority([Contain(), Cruise(speed: 1.0)]),
        ),
        Behavior(
            name: "wander",
            priority: 3,
            steer: Priority([Contain(), Wander(cruise: 0.4)]),
        ),
    ],
)
"##;

/// The debugging fish's script.
pub const DEBUG_FISH_RHAI: &str = r#"import "common/util" as util;

fn on_tick() {
    let n = if this.has("n") { this["n"] } else { 0 };
    this["n"] = util::next(n);
    if n == 40 {
        oops(n);
    }
}

fn oops(n) {
    throw "gave up after " + n + " passes";
}
"#;

/// A project folder with the files above.
pub struct Project {
    /// Keeps the folder alive.
    pub dir: tempfile::TempDir,
}

impl Project {
    /// Writes the project.
    pub fn new() -> Project {
        let dir = tempfile::tempdir().unwrap();
        let p = Project { dir };
        std::fs::create_dir_all(p.path("behaviors/common")).unwrap();
        std::fs::create_dir_all(p.path("scenarios")).unwrap();
        p.write("behaviors/fish.ron", FISH);
        p.write("behaviors/fish.rhai", FISH_RHAI);
        p.write("behaviors/common/util.rhai", UTIL_RHAI);
        p.write("scenarios/live.ron", SCENARIO);
        p
    }

    /// The project with the debugging fish ([`DEBUG_FISH`]) in place of the test fish.
    pub fn debugging() -> Project {
        let p = Project::new();
        p.write("behaviors/fish.ron", DEBUG_FISH);
        p.write("behaviors/fish.rhai", DEBUG_FISH_RHAI);
        p
    }

    /// Absolute path of `rel`.
    pub fn path(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }

    /// The scenario file.
    pub fn scenario(&self) -> PathBuf {
        self.path("scenarios/live.ron")
    }

    /// Writes `rel` in place (truncate and write).
    pub fn write(&self, rel: &str, text: &str) {
        std::fs::write(self.path(rel), text).unwrap();
    }

    /// Saves `rel` the way many editors do: a temporary file in the same folder renamed over it.
    pub fn save_atomic(&self, rel: &str, text: &str) {
        let target = self.path(rel);
        let tmp = target.with_file_name(format!(
            ".{}.tmp{}",
            target.file_name().unwrap().to_string_lossy(),
            std::process::id()
        ));
        std::fs::write(&tmp, text).unwrap();
        std::fs::rename(&tmp, &target).unwrap();
    }

    /// Current text of `rel`.
    pub fn read(&self, rel: &str) -> String {
        std::fs::read_to_string(self.path(rel)).unwrap()
    }
}

/// 1-based line and column of the first `needle` in `text`.
pub fn line_col(text: &str, needle: &str) -> (usize, usize) {
    let at = text.find(needle).expect("needle in text");
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

/// Waits up to `timeout` for an event matching `pred` and returns it with everything seen
/// before it (reload events only; first-tick notices are left out).
pub fn wait_for(
    s: &Session,
    timeout: Duration,
    what: &str,
    mut pred: impl FnMut(&LiveEvent) -> bool,
) -> (LiveEvent, Vec<LiveEvent>) {
    let deadline = Instant::now() + timeout;
    let mut seen = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match s.events().recv_timeout(left) {
            Ok(e) if pred(&e) => return (e, seen),
            Ok(LiveEvent::FirstTick { .. }) => {}
            Ok(e) => seen.push(e),
            Err(_) => panic!("no {what} within {timeout:?}; saw {seen:#?}"),
        }
    }
}

/// Waits for the next accepted reload.
pub fn accepted(s: &Session) -> shoal::live::Accepted {
    match wait_for(s, Duration::from_secs(10), "accepted reload", |e| {
        matches!(e, LiveEvent::Accepted(_))
    }) {
        (LiveEvent::Accepted(a), _) => a,
        _ => unreachable!(),
    }
}

/// Waits for the next rejected reload.
pub fn rejected(s: &Session) -> shoal::live::Rejected {
    match wait_for(s, Duration::from_secs(10), "rejected reload", |e| {
        matches!(e, LiveEvent::Rejected(_))
    }) {
        (LiveEvent::Rejected(r), _) => r,
        _ => unreachable!(),
    }
}

/// Polls `f` every 10 ms until it returns `Some`, up to `timeout`.
pub fn poll<T>(timeout: Duration, what: &str, mut f: impl FnMut() -> Option<T>) -> T {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(x) = f() {
            return x;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Waits until the session's tick passes `tick`.
pub fn wait_past_tick(s: &Session, tick: u64) -> u64 {
    poll(Duration::from_secs(10), "the simulation to advance", || {
        let t = s.status().tick;
        (t > tick).then_some(t)
    })
}

/// `path` relative display helper: the file name.
pub fn name(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}
