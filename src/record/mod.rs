//! Recording a run to a folder (an I/O layer above the core): trajectories (CSV), food (CSV),
//! events (JSON Lines), the world description (JSON), the resolved scenario with copies of every
//! input file, and a manifest with content hashes.
//!
//! Files are written as `*.partial` while the run goes on and the manifest says `incomplete`
//! from the first tick; only a finished run renames them and marks the manifest `complete`
//! (each final file is written by temp file + rename). An interrupted run keeps what it recorded,
//! clearly marked incomplete, and never a file that looks complete but is not.
//!
//! Why CSV: pandas (`read_csv`) and polars read it directly with no extra dependency on either
//! side, and floats are written in their shortest round-trip form so a re-read gives the exact
//! bits. Parquet would be smaller but costs a heavy dependency for little gain at these sizes.

mod decimal;
mod json;
pub mod schema;

pub use json::{behavior_info, event_json, world_json};

use crate::events::Event;
use crate::scenario::Run;
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Files a run folder holds when complete.
pub const RUN_FILES: [&str; 4] = ["trajectories.csv", "food.csv", "events.jsonl", "world.json"];

/// Files a complete run folder may hold besides [`RUN_FILES`], added by [`Recorder::add_output`]
/// (a new recording in the folder removes them first, so none is left from an earlier run).
pub const EXTRA_FILES: [&str; 2] = [crate::health::FILE, EXPLAIN_FILE];

/// What explains each recorded frame and every decision, one JSON object a line, written when
/// the run explains ([`crate::tick::Explain`]); see `docs/viewer.md`.
pub const EXPLAIN_FILE: &str = "explain.jsonl";

/// A recording in progress.
pub struct Recorder {
    dir: PathBuf,
    interval: u32,
    /// `trajectories.csv`: its rows are laid out in [`ROWS`]-agent pieces ([`traj_rows`]),
    /// written here in order.
    traj: BufWriter<File>,
    /// Each piece's bytes, kept from one recorded tick to the next.
    pieces: Vec<Vec<u8>>,
    food: csv::Writer<File>,
    events: BufWriter<File>,
    /// `explain.jsonl`, when the run explains.
    explain: Option<BufWriter<File>>,
    /// Ticks recorded so far.
    pub recorded: u64,
    removed: Vec<Option<u64>>,
    line: String,
    /// Extra output files written as `*.partial`, renamed by [`Recorder::finish`].
    extra: Vec<String>,
}

/// SHA-256 of a file's bytes, as hex.
pub fn sha256_file(path: &Path) -> std::io::Result<String> {
    let bytes = std::fs::read(path)?;
    Ok(hex(&Sha256::digest(&bytes)))
}

/// SHA-256 of `bytes`, hex.
pub fn sha256_bytes(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// SHA-256 of an input of `run`: the text its settings patched, else the file.
fn input_hash(f: &Path, run: &Run) -> String {
    match run
        .scenario
        .patched
        .get(&crate::load::overlay::normalize(f))
    {
        Some(t) => sha256_bytes(t.as_bytes()),
        None => sha256_file(f).unwrap_or_default(),
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// Writes `bytes` to `path` atomically (temp file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    // A name of this writer's own: processes of a job array may write the same file at once
    // (a sweep's manifest), and a shared temporary name would let one rename the other's half.
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let tmp = path.with_extension(format!(
        "{}.{}-{}.tmp",
        path.extension().and_then(|e| e.to_str()).unwrap_or(""),
        std::process::id(),
        NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    {
        let mut f = File::create(&tmp).map_err(at(&tmp))?;
        f.write_all(bytes).map_err(at(&tmp))?;
        f.sync_all().map_err(at(&tmp))?;
    }
    std::fs::rename(&tmp, path).map_err(at(path))
}

/// Adds `path` to an I/O error, so that a failed write names the file it was writing.
fn at(path: &Path) -> impl Fn(std::io::Error) -> std::io::Error + '_ {
    move |e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

/// A CSV writer with a `capacity`-byte buffer (fields are quoted only when they must be: a
/// species or behavior name holding a comma or a quote).
fn csv_writer<W: Write>(capacity: usize, out: W) -> csv::Writer<W> {
    csv::WriterBuilder::new()
        .buffer_capacity(capacity)
        .from_writer(out)
}

/// Agents whose trajectory rows are laid out as one piece: small enough for a second thread
/// to take a share of a few hundred agents, large enough that a piece's writer costs little.
const ROWS: usize = 128;

/// Pieces laid out before they are written (about 300 KB of rows).
const BATCH: usize = 16;

/// One float field, in Rust's shortest round-trip form (a re-read gives the same bits).
fn float_field<W: Write>(w: &mut csv::Writer<W>, buf: &mut Vec<u8>, v: f32) -> csv::Result<()> {
    buf.clear();
    decimal::push_f32(buf, v);
    w.write_field(&buf)
}

/// One field as `Display` writes it.
fn field<W: Write>(
    w: &mut csv::Writer<W>,
    buf: &mut String,
    v: impl std::fmt::Display,
) -> csv::Result<()> {
    use std::fmt::Write as _;
    buf.clear();
    let _ = write!(buf, "{v}");
    w.write_field(buf.as_bytes())
}

/// The I/O error inside a CSV writer's error.
fn csv_io(e: csv::Error) -> std::io::Error {
    match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => std::io::Error::other(format!("{other:?}")),
    }
}

fn partial(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.partial"))
}

impl Recorder {
    /// Starts recording `run` into `dir` (created if needed; a previous recording there is
    /// replaced). Writes the resolved scenario, copies of the inputs and an `incomplete`
    /// manifest at once.
    pub fn start(
        dir: &Path,
        run: &Run,
        interval: u32,
        threads: usize,
    ) -> std::io::Result<Recorder> {
        std::fs::create_dir_all(dir).map_err(at(dir))?;
        for f in RUN_FILES
            .iter()
            .chain(EXTRA_FILES.iter())
            .chain(["manifest.json", "view.html", "INCOMPLETE"].iter())
        {
            let _ = std::fs::remove_file(dir.join(f));
            let _ = std::fs::remove_file(partial(dir, f));
        }
        let _ = std::fs::remove_dir_all(dir.join("inputs"));
        write_inputs(dir, run)?;
        let mut rec = Recorder {
            dir: dir.to_path_buf(),
            interval: interval.max(1),
            traj: BufWriter::with_capacity(1 << 20, create(&partial(dir, "trajectories.csv"))?),
            pieces: Vec::new(),
            food: csv_writer(1 << 16, create(&partial(dir, "food.csv"))?),
            events: BufWriter::new(create(&partial(dir, "events.jsonl"))?),
            explain: None,
            recorded: 0,
            removed: vec![None; run.world.obstacles.len()],
            line: String::with_capacity(256),
            extra: Vec::new(),
        };
        let mut header = csv_writer(1 << 10, Vec::new());
        let header = header
            .write_record(schema::TRAJECTORY_COLUMNS)
            .and_then(|()| header.into_inner().map_err(|e| e.into_error().into()))
            .map_err(csv_io)
            .and_then(|h| rec.traj.write_all(&h))
            .map_err(at(&partial(dir, "trajectories.csv")));
        header?;
        rec.food
            .write_record(schema::FOOD_COLUMNS)
            .map_err(csv_io)
            .map_err(at(&partial(dir, "food.csv")))?;
        if run.pipeline.explain.on() {
            let f = create(&partial(dir, EXPLAIN_FILE))?;
            rec.explain = Some(BufWriter::with_capacity(1 << 20, f));
            rec.extra.push(EXPLAIN_FILE.to_string());
        }
        let incomplete = dir.join("INCOMPLETE");
        std::fs::write(&incomplete, "this run did not finish; see manifest.json\n")
            .map_err(at(&incomplete))?;
        rec.write_manifest(run, "incomplete", threads, None)?;
        // Spawns at t = 0 happened before the first tick.
        rec.events_of(run, &run.pipeline.events.clone())?;
        Ok(rec)
    }

    /// The run folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Appends one event line to `events.jsonl`.
    fn event_line(&mut self, v: &serde_json::Value) -> std::io::Result<()> {
        serde_json::to_writer(&mut self.events, v)
            .map_err(std::io::Error::from)
            .and_then(|()| self.events.write_all(b"\n"))
            .map_err(at(&partial(&self.dir, "events.jsonl")))
    }

    fn events_of(&mut self, run: &Run, events: &[Event]) -> std::io::Result<()> {
        for e in events {
            let v = event_json(e, run.world.tick, run.world.dt, &run.scenario.species);
            self.event_line(&v)?;
        }
        Ok(())
    }

    /// Records what the last tick produced: its events always, agent states every `interval`
    /// ticks (and the state at tick 0).
    pub fn record_tick(&mut self, run: &Run) -> std::io::Result<()> {
        let tick = run.world.tick;
        // Events were produced while advancing from tick−1 to tick.
        let events = &run.pipeline.events;
        for e in events {
            let v = event_json(
                e,
                tick.saturating_sub(1),
                run.world.dt,
                &run.scenario.species,
            );
            self.event_line(&v)?;
        }
        if let Some(w) = self.explain.as_mut() {
            for v in &run.pipeline.explained {
                serde_json::to_writer(&mut *w, v)
                    .map_err(std::io::Error::from)
                    .and_then(|()| w.write_all(b"\n"))
                    .map_err(at(&partial(&self.dir, EXPLAIN_FILE)))?;
            }
        }
        for (k, o) in run.world.obstacles.iter().enumerate() {
            if !o.active && self.removed.get(k).is_some_and(|r| r.is_none()) {
                self.removed[k] = Some(tick);
            }
        }
        if tick.is_multiple_of(self.interval as u64) {
            self.states(run)?;
        }
        Ok(())
    }

    /// Writes agent and food states of the current tick. The trajectory rows are laid out in
    /// pieces of [`ROWS`] agents, in parallel when the tick itself ran on the whole pool
    /// (beside a busy core it ran on one thread, and so do they); the bytes are the same
    /// either way.
    pub fn states(&mut self, run: &Run) -> std::io::Result<()> {
        use rayon::prelude::*;
        let w = &run.world;
        let traj_path = || partial(&self.dir, "trajectories.csv");
        let parallel = w.agents.len() > ROWS
            && rayon::current_num_threads() > 1
            && !crate::par::is_alone()
            && run.pipeline.governor.mode() == crate::tick::governor::Mode::Pool;
        // A batch of pieces at a time: a million agents' rows are not held at once.
        self.pieces.resize_with(BATCH, Vec::new);
        for batch in w.agents.chunks(ROWS * BATCH) {
            let pieces = &mut self.pieces[..batch.len().div_ceil(ROWS)];
            let lay = |(k, piece): (usize, &mut Vec<u8>)| {
                let agents = &batch[k * ROWS..((k + 1) * ROWS).min(batch.len())];
                traj_rows(run, agents, piece)
            };
            let laid: csv::Result<()> = if parallel {
                pieces.par_iter_mut().enumerate().try_for_each(lay)
            } else {
                pieces.iter_mut().enumerate().try_for_each(lay)
            };
            laid.map_err(csv_io).map_err(at(&traj_path()))?;
            for piece in pieces.iter() {
                self.traj.write_all(piece).map_err(at(&traj_path()))?;
            }
        }
        let buf = &mut self.line;
        let food = &mut self.food;
        let mut bytes = Vec::with_capacity(32);
        let mut rows = || -> csv::Result<()> {
            for f in &w.food {
                // In `schema::FoodColumn` order.
                field(food, buf, w.tick)?;
                field(food, buf, f.id)?;
                for v in [f.pos.x, f.pos.y, f.pos.z] {
                    float_field(food, &mut bytes, v)?;
                }
                food.write_record(None::<&[u8]>)?;
            }
            Ok(())
        };
        rows()
            .map_err(csv_io)
            .map_err(at(&partial(&self.dir, "food.csv")))?;
        self.recorded += 1;
        Ok(())
    }

    fn write_manifest(
        &self,
        run: &Run,
        status: &str,
        threads: usize,
        summary: Option<serde_json::Value>,
    ) -> std::io::Result<()> {
        let mut files = serde_json::Map::new();
        for f in run.scenario.files() {
            let rel = rel_name(&f, run);
            files.insert(rel, serde_json::Value::String(input_hash(&f, run)));
        }
        let mut m = serde_json::json!({
            "format": 1,
            "status": status,
            "scenario": run.scenario.name,
            "scenario_file": run.scenario.file.display().to_string(),
            "seed": run.world.seed,
            "dt": format!("{}", run.world.dt).parse::<f64>().unwrap_or(run.world.dt as f64),
            "ticks": run.world.tick,
            "total_ticks": run.total_ticks,
            "record_interval": self.interval,
            "recorded_ticks": self.recorded,
            "threads": threads,
            "files": files,
            "summary": summary.unwrap_or(serde_json::Value::Null),
        });
        if !run.scenario.settings.is_empty() {
            // The inputs' copies hold the patched texts; the settings say what was patched.
            m["settings"] = serde_json::json!(run
                .scenario
                .settings
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>());
        }
        if status == "complete" {
            // What the folder holds besides its inputs: the recording and any extra outputs.
            let outputs: Vec<&str> = RUN_FILES
                .iter()
                .copied()
                .chain(self.extra.iter().map(String::as_str))
                .collect();
            m["outputs"] = serde_json::json!(outputs);
        }
        write_atomic(
            &self.dir.join("manifest.json"),
            serde_json::to_string_pretty(&m)?.as_bytes(),
        )
    }

    fn flush_all(&mut self, run: &Run) -> std::io::Result<()> {
        let dir = &self.dir;
        self.traj
            .flush()
            .map_err(at(&partial(dir, "trajectories.csv")))?;
        self.food.flush().map_err(at(&partial(dir, "food.csv")))?;
        self.events
            .flush()
            .map_err(at(&partial(dir, "events.jsonl")))?;
        if let Some(w) = self.explain.as_mut() {
            w.flush().map_err(at(&partial(dir, EXPLAIN_FILE)))?;
        }
        let world = world_json(run, &self.removed);
        let path = partial(dir, "world.json");
        std::fs::write(&path, serde_json::to_string(&world)?).map_err(at(&path))?;
        Ok(())
    }

    /// Adds a file to the run folder (such as [`crate::health::FILE`]): written now as
    /// `name.partial`, it takes its name with the others when the run finishes, and an
    /// interrupted run does not keep it.
    pub fn add_output(&mut self, name: &str, bytes: &[u8]) -> std::io::Result<()> {
        let path = partial(&self.dir, name);
        let mut f = create(&path)?;
        f.write_all(bytes).map_err(at(&path))?;
        f.sync_all().map_err(at(&path))?;
        if !self.extra.iter().any(|e| e == name) {
            self.extra.push(name.to_string());
        }
        Ok(())
    }

    /// Finishes a complete run: flushes, renames every file to its final name and marks the
    /// manifest complete with `summary`.
    pub fn finish(
        mut self,
        run: &Run,
        threads: usize,
        summary: serde_json::Value,
    ) -> std::io::Result<PathBuf> {
        self.flush_all(run)?;
        for f in RUN_FILES
            .iter()
            .copied()
            .chain(self.extra.iter().map(String::as_str))
        {
            let to = self.dir.join(f);
            std::fs::rename(partial(&self.dir, f), &to).map_err(at(&to))?;
        }
        self.write_manifest(run, "complete", threads, Some(summary))?;
        let _ = std::fs::remove_file(self.dir.join("INCOMPLETE"));
        Ok(self.dir)
    }

    /// Ends an interrupted run: keeps what was recorded under the final names, with the
    /// manifest and an `INCOMPLETE` file saying why it stopped.
    pub fn abort(mut self, run: &Run, threads: usize, reason: &str) -> std::io::Result<PathBuf> {
        self.flush_all(run)?;
        for f in RUN_FILES {
            let _ = std::fs::rename(partial(&self.dir, f), self.dir.join(f));
        }
        for f in &self.extra {
            let _ = std::fs::remove_file(partial(&self.dir, f));
        }
        self.write_manifest(
            run,
            "incomplete",
            threads,
            Some(serde_json::json!({ "stopped": reason })),
        )?;
        let incomplete = self.dir.join("INCOMPLETE");
        std::fs::write(
            &incomplete,
            format!(
                "this run stopped at tick {} of {}: {reason}\n",
                run.world.tick, run.total_ticks
            ),
        )
        .map_err(at(&incomplete))?;
        Ok(self.dir)
    }
}

/// Lays out the trajectory rows of `agents` into `out` (emptied first), in
/// `schema::TrajColumn` order, with the bytes the CSV writer gives them. Numbers never need
/// quotes, so a row is written straight as bytes; a row whose species or behavior name holds a
/// byte the CSV writer quotes goes through the writer.
fn traj_rows(run: &Run, agents: &[crate::world::Agent], out: &mut Vec<u8>) -> csv::Result<()> {
    let w = &run.world;
    let set = &run.scenario.species;
    out.clear();
    // The tick and the time are the same in every row of the tick.
    let mut head = Vec::with_capacity(40);
    decimal::push_u64(&mut head, w.tick);
    let _ = write!(head, ",{},", w.time());
    for a in agents {
        let sp = &set.species[a.species.0 as usize];
        let behavior = sp.behavior_name(a.mind.current);
        if !plain(&sp.name) || !plain(behavior) {
            out.extend_from_slice(&traj_row_quoted(run, a)?);
            continue;
        }
        out.extend_from_slice(&head);
        decimal::push_u64(out, u64::from(a.id.0));
        out.push(b',');
        out.extend_from_slice(sp.name.as_bytes());
        for v in traj_motion(a) {
            out.push(b',');
            decimal::push_f32(out, v);
        }
        out.push(b',');
        out.extend_from_slice(behavior.as_bytes());
        out.push(b',');
        decimal::push_u64(out, u64::from(a.mind.depth));
        for v in traj_body(a, sp) {
            out.push(b',');
            decimal::push_f32(out, v);
        }
        out.push(b'\n');
    }
    Ok(())
}

/// Whether the CSV writer writes `name` as it is (no delimiter, quote or line break in it).
fn plain(name: &str) -> bool {
    !name
        .bytes()
        .any(|b| matches!(b, b',' | b'"' | b'\n' | b'\r'))
}

/// Position, forward axis and speed: the float columns after the species.
fn traj_motion(a: &crate::world::Agent) -> [f32; 7] {
    let f = a.forward();
    [a.pos.x, a.pos.y, a.pos.z, f.x, f.y, f.z, a.speed]
}

/// Drives, swim phase and tail bend: the float columns after the stack depth.
fn traj_body(a: &crate::world::Agent, sp: &crate::species::Species) -> [f32; 5] {
    [
        a.drives.hunger,
        a.drives.libido,
        a.drives.fear,
        a.anim.phase,
        crate::locomotion::anim::bend(&a.anim, &sp.body.anim),
    ]
}

/// One trajectory row through the CSV writer (names quoted as it quotes them).
fn traj_row_quoted(run: &Run, a: &crate::world::Agent) -> csv::Result<Vec<u8>> {
    let w = &run.world;
    let sp = &run.scenario.species.species[a.species.0 as usize];
    let mut traj = csv_writer(256, Vec::new());
    let mut buf = String::new();
    let mut bytes = Vec::new();
    field(&mut traj, &mut buf, w.tick)?;
    field(&mut traj, &mut buf, w.time())?;
    field(&mut traj, &mut buf, a.id.0)?;
    traj.write_field(&sp.name)?;
    for v in traj_motion(a) {
        float_field(&mut traj, &mut bytes, v)?;
    }
    traj.write_field(sp.behavior_name(a.mind.current))?;
    field(&mut traj, &mut buf, a.mind.depth)?;
    for v in traj_body(a, sp) {
        float_field(&mut traj, &mut bytes, v)?;
    }
    traj.write_record(None::<&[u8]>)?;
    traj.into_inner().map_err(|e| e.into_error().into())
}

/// Name of an input file relative to the scenario's behaviors folder (species, scripts) or
/// `scenario/<file>` for the scenario itself.
fn rel_name(f: &Path, run: &Run) -> String {
    if let Ok(r) = f.strip_prefix(&run.scenario.behaviors_dir) {
        return format!("behaviors/{}", r.display());
    }
    if f == run.scenario.file {
        return format!(
            "scenario/{}",
            f.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        );
    }
    format!(
        "other/{}",
        f.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    )
}

/// Creates (or truncates) `path` for writing.
fn create(path: &Path) -> std::io::Result<File> {
    File::create(path).map_err(at(path))
}

/// Writes `scenario.ron` (resolved: seed and duration as run, species from `inputs/behaviors`)
/// and copies of every input under `inputs/`.
fn write_inputs(dir: &Path, run: &Run) -> std::io::Result<()> {
    let inputs = dir.join("inputs");
    for f in run.scenario.files() {
        let rel = rel_name(&f, run);
        let dest = inputs.join(&rel);
        if let Some(p) = dest.parent() {
            std::fs::create_dir_all(p).map_err(at(p))?;
        }
        match run
            .scenario
            .patched
            .get(&crate::load::overlay::normalize(&f))
        {
            Some(t) => std::fs::write(&dest, t.as_bytes()).map_err(at(&dest))?,
            None => {
                std::fs::copy(&f, &dest).map_err(at(&dest))?;
            }
        }
    }
    // Species named only in relations (a shark's prey that is not in this world) must still
    // resolve when the copy is loaded again.
    for sp in &run.scenario.species.species {
        let r = &sp.def.relations;
        for name in r.prey.iter().chain(&r.predators).chain(&r.kin) {
            let src = run.scenario.behaviors_dir.join(format!("{name}.ron"));
            let dest = inputs.join("behaviors").join(format!("{name}.ron"));
            if !dest.exists() && src.is_file() {
                std::fs::create_dir_all(inputs.join("behaviors")).map_err(at(&inputs))?;
                std::fs::copy(&src, &dest).map_err(at(&dest))?;
            }
        }
    }
    let mut def = run.scenario.def.clone();
    def.seed = run.world.seed;
    def.duration = run.total_ticks as f32 * run.world.dt;
    def.name = Some(run.scenario.name.clone());
    def.behaviors = Some("inputs/behaviors".into());
    // Terrain and feature files are copied next to the scenario copy.
    if let Some(t) = def.terrain.as_mut() {
        let base = run.scenario.file.parent().unwrap_or(Path::new("."));
        for p in std::iter::once(&mut t.dem).chain(t.features.iter_mut()) {
            let src = base.join(&*p);
            let name = src
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let dest = inputs.join("terrain").join(&name);
            std::fs::create_dir_all(dest.parent().expect("has parent")).map_err(at(&dest))?;
            std::fs::copy(&src, &dest).map_err(at(&dest))?;
            *p = format!("inputs/terrain/{name}");
        }
    }
    let text = ron::ser::to_string_pretty(
        &def,
        ron::ser::PrettyConfig::default()
            .struct_names(true)
            .extensions(ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES),
    )
    .map_err(std::io::Error::other)?;
    write_atomic(&dir.join("scenario.ron"), text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{Overrides, Scenario};

    /// The shipped school of sardines, `n` of them.
    fn school(n: i64) -> Run {
        let mut sc = Scenario::load(Path::new("scenarios/school_formation.ron")).unwrap();
        sc.def.groups[0].count = n;
        let o = Overrides {
            seed: None,
            duration: Some(0.2),
            set: Vec::new(),
        };
        Run::new(sc, o)
    }

    /// The trajectory file of `run` recorded at every tick on a two-thread pool, its rows laid
    /// out in parallel or (`alone`) on one thread; and the agent ids of each recorded tick.
    fn record(mut run: Run, alone: bool) -> (Vec<u8>, Vec<Vec<u32>>) {
        let dir = tempfile::tempdir().unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let mut ids = Vec::new();
        pool.install(|| {
            let mut go = || {
                let mut rec = Recorder::start(dir.path(), &run, 1, 2).unwrap();
                rec.states(&run).unwrap();
                ids.push(run.world.agents.iter().map(|a| a.id.0).collect());
                for _ in 0..2 {
                    run.step();
                    rec.record_tick(&run).unwrap();
                    ids.push(run.world.agents.iter().map(|a| a.id.0).collect());
                }
                rec.finish(&run, 2, serde_json::json!({})).unwrap();
            };
            if alone {
                crate::par::alone(go)
            } else {
                go()
            }
        });
        let bytes = std::fs::read(dir.path().join("trajectories.csv")).unwrap();
        (bytes, ids)
    }

    /// Each agent's row as [`traj_rows`] lays it out, and as the CSV writer does.
    fn both_rows(run: &Run) -> Vec<(Vec<u8>, Vec<u8>)> {
        let mut out = Vec::new();
        run.world
            .agents
            .iter()
            .map(|a| {
                traj_rows(run, std::slice::from_ref(a), &mut out).unwrap();
                (out.clone(), traj_row_quoted(run, a).unwrap())
            })
            .collect()
    }

    #[test]
    fn trajectory_rows_are_the_csv_writers_bytes_with_names_that_need_quotes_too() {
        let mut run = school(300);
        for _ in 0..3 {
            run.step();
        }
        for (ours, csv) in both_rows(&run) {
            assert_eq!(String::from_utf8(ours), String::from_utf8(csv));
        }
        let mut set = (*run.scenario.species).clone();
        for (i, name) in ["sar,dine", "sar\"dine", "sar\ndine", "sar\rdine"]
            .into_iter()
            .enumerate()
        {
            let sp = std::sync::Arc::make_mut(&mut set.species[0]);
            sp.name = name.to_string();
            // The behavior names: one plain, one to quote.
            if let Some(b) = sp.behaviors.get_mut(i % 2) {
                b.name = format!("b{i},\r").into();
            }
            run.scenario.species = std::sync::Arc::new(set.clone());
            let rows = both_rows(&run);
            assert!(!rows.is_empty());
            for (ours, csv) in rows {
                let text = String::from_utf8(ours).unwrap();
                assert_eq!(text, String::from_utf8(csv).unwrap());
                assert!(
                    text.contains(&format!("\"{}\"", name.replace('"', "\"\""))),
                    "{text}"
                );
            }
        }
    }

    #[test]
    fn trajectory_rows_laid_out_in_parallel_are_the_bytes_of_one_thread_in_agent_order() {
        // Two batches of pieces, the last piece partial.
        let n = (ROWS * BATCH + ROWS + 5) as i64;
        let (parallel, ids) = record(school(n), false);
        let (alone, _) = record(school(n), true);
        assert!(parallel == alone, "the two layouts differ");
        let text = String::from_utf8(parallel).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some(schema::TRAJECTORY_COLUMNS.join(",").as_str())
        );
        let id_col = schema::TrajColumn::Id as usize;
        let read: Vec<u32> = lines
            .map(|l| l.split(',').nth(id_col).unwrap().parse().unwrap())
            .collect();
        let want: Vec<u32> = ids.concat();
        assert_eq!(want.len(), 3 * n as usize);
        assert!(read == want, "rows are not in agent order, tick by tick");
    }
}
