//! The `plan` benchmark workload: formation-keeping A* on a 1024² terrain (seed 004).
//!
//! HOOK(plan): the formation planner lives in `src/formation/` (branch `terrain`) and is not part
//! of this tree yet. Once merged, [`measure`] should build a 1024×1024 terrain (e.g. a smooth
//! random height field with a few impassable features), plan one squad's formation path from one
//! corner to the opposite one `passes` times, and return a [`Sample`] with `agents` = squad size,
//! `ticks` = `passes` and `updates` = expanded search nodes. Until then `shoal bench plan` says
//! the workload is not available and `cargo bench` skips it.

use super::Sample;

/// Side of the terrain grid the workload plans on.
pub const TERRAIN_SIDE: usize = 1024;

/// Measures `passes` formation plans; `None` while the planner is not wired (see the module
/// header).
pub fn measure(passes: u64) -> Option<Sample> {
    let _ = passes;
    None
}
