//! Species hot reload in a running app: between ticks, the files each running species was built
//! from (species file, script, imports) are checked for changes every
//! [`SpeciesWatch::interval`]; a changed species is read again and swapped in with
//! [`shoal::prelude::Sim::set_species`] (agents keep their state, matched by name). A bad edit
//! keeps the last good version running and is reported as a [`SpeciesReloadFailed`] message
//! and a warning in the log; nothing panics. An app can also ask for a reload of every species
//! with a [`ReloadSpecies`] message. Reads the file system and writes [`ShoalSim`]'s species.

use crate::sim::ShoalSim;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use shoal::prelude::{Species, SpeciesSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, SystemTime};

/// How species files are watched.
#[derive(Resource, Debug, Clone)]
pub struct SpeciesWatch {
    /// Whether files are checked at all ([`ReloadSpecies`] works either way).
    pub enabled: bool,
    /// Time between checks, on the clock of the plugin's schedule.
    pub interval: Duration,
    since: Duration,
    stamps: HashMap<PathBuf, Stamp>,
}

impl Default for SpeciesWatch {
    fn default() -> SpeciesWatch {
        SpeciesWatch {
            enabled: true,
            interval: Duration::from_millis(250),
            since: Duration::ZERO,
            stamps: HashMap::default(),
        }
    }
}

/// What identifies a version of a file: modification time and length (a coarse clock may give
/// two quick edits one time; an edit seldom keeps the length too).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stamp(Option<SystemTime>, u64);

fn stamp(file: &Path) -> Option<Stamp> {
    let m = std::fs::metadata(file).ok()?;
    Some(Stamp(m.modified().ok(), m.len()))
}

/// A request to read every running species from its files again now.
#[derive(Message, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReloadSpecies;

/// Species swapped in by a hot reload.
#[derive(Message, Debug, Clone, PartialEq, Eq)]
pub struct SpeciesReloaded {
    /// The species read again, by name.
    pub species: Vec<String>,
    /// The tick count at the swap (the next tick runs the new versions).
    pub tick: u64,
    /// Agents whose behavior no longer existed (they fell back to the initial one) or whose
    /// species was gone.
    pub remapped: usize,
}

/// A hot reload that failed: the species keep running in their last good version.
#[derive(Message, Debug, Clone, PartialEq, Eq)]
pub struct SpeciesReloadFailed {
    /// The species that could not be read again, by name.
    pub species: Vec<String>,
    /// The diagnostics (`file:line:col: message`, with the line quoted).
    pub error: String,
}

/// Sync-in: reloads the species whose files changed, or all on [`ReloadSpecies`].
pub(crate) fn reload_species(
    time: Res<Time>,
    sim: Option<ResMut<ShoalSim>>,
    mut watch: ResMut<SpeciesWatch>,
    mut asked: MessageReader<ReloadSpecies>,
    mut done: MessageWriter<SpeciesReloaded>,
    mut failed: MessageWriter<SpeciesReloadFailed>,
) {
    let Some(mut sim) = sim else {
        asked.clear();
        return;
    };
    let forced = asked.read().count() > 0;
    watch.since += time.delta();
    let due = watch.enabled && watch.since >= watch.interval;
    if !forced && !due {
        return;
    }
    watch.since = Duration::ZERO;
    let set = sim.sim().species();
    let mut changed = Vec::new();
    for (k, s) in set.species.iter().enumerate() {
        let mut edited = false;
        for f in s.files() {
            let now = stamp(&f);
            // A file seen for the first time is the version running, not an edit.
            match (watch.stamps.get(&f), now) {
                (Some(old), Some(new)) if *old != new => edited = true,
                _ => {}
            }
            match now {
                Some(n) => watch.stamps.insert(f, n),
                None => watch.stamps.remove(&f),
            };
        }
        if edited || forced {
            changed.push(k);
        }
    }
    if changed.is_empty() {
        return;
    }
    let names: Vec<String> = changed
        .iter()
        .map(|&k| set.species[k].name.clone())
        .collect();
    match rebuild(set, &changed) {
        Ok(new) => {
            let remap = sim.sim_mut().set_species(new);
            let tick = sim.sim().tick();
            log::info!("species reloaded at tick {tick}: {}", names.join(", "));
            done.write(SpeciesReloaded {
                species: names,
                tick,
                remapped: remap.events.len(),
            });
        }
        Err(error) => {
            log::warn!(
                "species not reloaded ({}), the last good version keeps running:\n{error}",
                names.join(", ")
            );
            failed.write(SpeciesReloadFailed {
                species: names,
                error,
            });
        }
    }
}

/// The running set with species `changed` read again from their files.
fn rebuild(set: &SpeciesSet, changed: &[usize]) -> Result<SpeciesSet, String> {
    let mut all = set.species.clone();
    let mut errors = Vec::new();
    for &k in changed {
        match Species::load(&all[k].file) {
            Ok(s) => all[k] = Arc::new(s),
            Err(d) => errors.push(d.to_string()),
        }
    }
    if !errors.is_empty() {
        return Err(errors.join("\n"));
    }
    // As a scenario's loader does: a relation may name a species defined beside the files
    // (a shark that eats sardines runs without sardines).
    let dirs: Vec<PathBuf> = all
        .iter()
        .filter_map(|s| s.file.parent().map(Path::to_path_buf))
        .collect();
    SpeciesSet::with_library(all, |n| {
        dirs.iter().any(|d| d.join(format!("{n}.ron")).is_file())
    })
    .map_err(|d| d.to_string())
}
