//! Scenario validation: a scenario file → [`ScenarioDef`] → checks (species named and loaded
//! once each, regions inside the bounds and with room outside the obstacles, events that name
//! what exists) → the runtime [`Scenario`], its species set, terrain and squads. Every problem is
//! a located diagnostic; as many are reported as can be found, up to
//! [`MAX_DIAGNOSTICS`].

use super::numbers::scenario_numbers;
use super::*;
use crate::load::diag::MAX_DIAGNOSTICS;
use crate::load::{locate, ron_diag, ron_options, Diagnostic, Diagnostics};
use crate::species::{load_species, Species};
use crate::world::{Aabb, Shape};
use glam::Vec3;

fn check_region(
    diags: &mut Vec<Diagnostic>,
    file: &Path,
    text: &str,
    bounds: &Aabb,
    region: &Aabb,
    what: &str,
    from: usize,
) {
    if !bounds.contains_box(region) || region.min.cmpgt(region.max).any() {
        let (l, c, _) = locate(text, "region", from).unwrap_or((0, 0, 0));
        diags.push(Diagnostic::new(
            file,
            l,
            c,
            format!(
                "{what}: spawn region {:?}..{:?} is outside the world bounds {:?}..{:?}",
                region.min.to_array(),
                region.max.to_array(),
                bounds.min.to_array(),
                bounds.max.to_array()
            ),
            Some(text),
        ));
    }
}

/// Whether no point of a 9×9×9 lattice over `region` lies outside every obstacle: a region
/// that cannot hold a group (spawning would have to put agents inside rock).
fn region_blocked(region: &Aabb, obstacles: &[ObstacleDef]) -> bool {
    let shapes: Vec<Shape> = obstacles.iter().map(ObstacleDef::shape).collect();
    if shapes.is_empty() {
        return false;
    }
    const N: usize = 9;
    let step = region.size() / (N - 1) as f32;
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                let p = region.min + step * Vec3::new(i as f32, j as f32, k as f32);
                if shapes.iter().all(|s| s.push_out(p, 0.0).is_none()) {
                    return false;
                }
            }
        }
    }
    true
}

impl Scenario {
    /// Reads, validates and loads a scenario and every species it names.
    pub fn load(file: &Path) -> Result<Scenario, Diagnostics> {
        let text = crate::load::read_text(file, "scenario")?;
        Self::load_str(file, &text)
    }

    /// Validates scenario `text` (named `file`).
    pub fn load_str(file: &Path, text: &str) -> Result<Scenario, Diagnostics> {
        let def: ScenarioDef = ron_options()
            .from_str(text)
            .map_err(|e| Diagnostics::from(ron_diag(file, text, &e)))?;
        let dir = file.parent().unwrap_or(Path::new("."));
        let behaviors_dir =
            normalize(&dir.join(def.behaviors.as_deref().unwrap_or("../behaviors")));
        let mut diags = Vec::new();
        let at = |needle: &str, from: usize| locate(text, needle, from).unwrap_or((0, 0, 0));
        // A species name written with escapes is not in the text as parsed: point at the list.
        let at_species = |needle: &str, from: usize| {
            locate(text, needle, from)
                .or_else(|| locate(text, "species", 0))
                .unwrap_or((0, 0, 0))
        };
        if !(def.dt > 0.0 && def.dt.is_finite()) {
            let (l, c, _) = at("dt", 0);
            diags.push(Diagnostic::new(
                file,
                l,
                c,
                "`dt` must be a positive number of seconds",
                Some(text),
            ));
        }
        if !(def.duration >= 0.0 && def.duration.is_finite()) {
            let (l, c, _) = at("duration", 0);
            diags.push(Diagnostic::new(
                file,
                l,
                c,
                "`duration` must be ≥ 0 seconds",
                Some(text),
            ));
        }
        diags.extend(scenario_numbers(file, text, &def));
        if def.bounds.min.cmpge(def.bounds.max).any() {
            let (l, c, _) = at("bounds", 0);
            diags.push(Diagnostic::new(
                file,
                l,
                c,
                "`bounds`: `min` must be below `max` on every axis",
                Some(text),
            ));
        }
        let mut loaded: Vec<Arc<Species>> = Vec::new();
        let mut listed = std::collections::BTreeSet::new();
        let mut missing_one = false;
        for name in &def.species {
            // Each problem scans the text to locate it: a list of 40,000 bad names took 5 s.
            if diags.len() >= MAX_DIAGNOSTICS {
                break;
            }
            // Loaded once each: a name repeated 40,000 times would compile its script as often.
            if !listed.insert(name.as_str()) {
                let needle = format!("\"{name}\"");
                let second = locate(text, &needle, 0).map_or(0, |x| x.2 + 1);
                let (l, c, _) = at_species(&needle, second);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("species \"{name}\" is listed twice"),
                    Some(text),
                ));
                continue;
            }
            let path = behaviors_dir.join(format!("{name}.ron"));
            if let Some(problem) = crate::load::diag::file_problem(&path) {
                // The folder and how to point elsewhere are said once, at the first missing file.
                let missing_before = std::mem::replace(&mut missing_one, true);
                let (l, c, _) = at_species(&format!("\"{name}\""), 0);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!(
                        "species file \"{}\" {problem}{}",
                        path.display(),
                        if missing_before {
                            format!(
                                "{}; looked for in the same folder as above",
                                crate::load::did_you_mean(
                                    name,
                                    species_files(&behaviors_dir).iter().map(String::as_str)
                                )
                            )
                        } else {
                            where_species_are(&behaviors_dir, name, def.behaviors.is_some())
                        }
                    ),
                    Some(text),
                ));
                continue;
            }
            match load_species(&path, &behaviors_dir, &script_limits()) {
                Ok(s) => {
                    if &s.name != name {
                        let (l, c, _) = at_species(&format!("\"{name}\""), 0);
                        diags.push(Diagnostic::new(
                            file,
                            l,
                            c,
                            format!(
                                "\"{}\" defines species \"{}\", not \"{name}\"",
                                path.display(),
                                s.name
                            ),
                            Some(text),
                        ));
                    }
                    loaded.push(Arc::new(s))
                }
                Err(d) => diags.extend(d.0),
            }
        }
        let known = |n: &str| def.species.iter().any(|s| s == n);
        let check_group = |g: &SpawnGroupDef, diags: &mut Vec<Diagnostic>, from: usize| {
            let from = locate(text, &format!("\"{}\"", g.species), from).map_or(from, |x| x.2);
            if !known(&g.species) {
                let (l, c, _) = at(&format!("\"{}\"", g.species), from);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!(
                        "unknown species \"{}\"{}: the scenario loads {}",
                        g.species,
                        crate::load::did_you_mean(
                            &g.species,
                            def.species.iter().map(String::as_str)
                        ),
                        def.species.join(", ")
                    ),
                    Some(text),
                ));
            }
            if g.count < 0 {
                let (l, c, _) = at("count", from);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("`count` must be ≥ 0, not {}", g.count),
                    Some(text),
                ));
            }
            check_region(
                diags,
                file,
                text,
                &def.bounds,
                &g.region,
                &format!("group of \"{}\"", g.species),
                from,
            );
            if g.count > 0 && region_blocked(&g.region, &def.obstacles) {
                let (l, c, _) = at("region", from);
                diags.push(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!(
                        "group of \"{}\": its spawn region {:?}..{:?} lies inside obstacles; \
                         expected a region with room outside them",
                        g.species,
                        g.region.min.to_array(),
                        g.region.max.to_array()
                    ),
                    Some(text),
                ));
            }
            from + 1
        };
        let mut from = locate(text, "groups", 0).map_or(0, |x| x.2);
        for g in &def.groups {
            if diags.len() >= MAX_DIAGNOSTICS {
                break;
            }
            from = check_group(g, &mut diags, from);
        }
        let mut from = locate(text, "events", 0).map_or(0, |x| x.2);
        for e in &def.events {
            if diags.len() >= MAX_DIAGNOSTICS {
                break;
            }
            match e.action.clone() {
                EventAction::Spawn(g) => from = check_group(&g, &mut diags, from),
                EventAction::RemoveObstacle(id) if id as usize >= def.obstacles.len() => {
                    let (l, c, _) = at("RemoveObstacle", from);
                    diags.push(Diagnostic::new(
                        file,
                        l,
                        c,
                        format!(
                            "no obstacle {id}: the scenario has {} (ids start at 0)",
                            def.obstacles.len()
                        ),
                        Some(text),
                    ));
                }
                EventAction::DropFood { region, .. } => check_region(
                    &mut diags,
                    file,
                    text,
                    &def.bounds,
                    &region,
                    "DropFood",
                    from,
                ),
                _ => {}
            }
        }
        if let Some(r) = def.food.region {
            check_region(&mut diags, file, text, &def.bounds, &r, "food", 0);
        }
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        let lib = behaviors_dir.clone();
        let species = Arc::new(SpeciesSet::with_library(loaded, |n| {
            lib.join(format!("{n}.ron")).is_file()
        })?);
        let (ground, squads) = crate::squad::setup::load(file, text, &def, &species)?;
        let scenario = Scenario {
            name: def.name.clone().unwrap_or_else(|| {
                file.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            file: file.to_path_buf(),
            text: text.to_string(),
            def,
            behaviors_dir,
            species,
            ground,
            squads,
            settings: Vec::new(),
            patched: Default::default(),
        };
        // The expectations name species and behaviors: resolved here so that `check`, `run` and
        // a reload reject a bad one with its location instead of a run judging nothing.
        crate::scenario::expect::Tracker::new(&scenario)?;
        Ok(scenario)
    }
}

/// What a "species file not found" message adds: the folder searched and why that one, how to
/// point elsewhere, and a near name among the species files that are there.
fn where_species_are(dir: &Path, name: &str, set_by_scenario: bool) -> String {
    let present = species_files(dir);
    let why = if set_by_scenario {
        "the scenario's `behaviors:` folder"
    } else {
        "the default `behaviors: \"../behaviors\"`, relative to the scenario file's folder"
    };
    let there = if dir.is_dir() {
        ""
    } else {
        ", a folder that does not exist"
    };
    let near = crate::load::did_you_mean(name, present.iter().map(String::as_str));
    format!(
        "{near}; species are looked for in {}{there} ({why}); set `behaviors: \"<folder>\"` in \
         the scenario (relative to the scenario file, or absolute) to load them from elsewhere",
        dir.display()
    )
}

/// The species names of the `.ron` files in `dir`, sorted (none when it cannot be read).
fn species_files(dir: &Path) -> Vec<String> {
    let mut present: Vec<String> = std::fs::read_dir(dir)
        .map(|it| {
            it.filter_map(|e| e.ok())
                .filter_map(|e| {
                    let p = e.path();
                    let stem = p.file_stem()?.to_str()?.to_string();
                    (p.extension()? == "ron").then_some(stem)
                })
                .collect()
        })
        .unwrap_or_default();
    present.sort();
    present
}
