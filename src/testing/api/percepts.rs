//! Percept injection (`perceive`): a test feeds an agent what it perceives (category,
//! distance, bearing, elevation, sense, size) in place of the world's perception, until
//! `perceive_world`; and `percepts(what)` reads an agent's summary of one category.

use super::args::{category, check_keys, num, string};
use super::{AgentRef, R};
use crate::perception::{Category, Sense};
use crate::testing::failure::error;
use crate::testing::world::Feed;
use rhai::{Array, Dynamic, Engine, Map, INT};

/// Registers `percepts`, `perceive` and `perceive_world`.
pub(super) fn register(e: &mut Engine) {
    e.register_fn("percepts", |a: &mut AgentRef, what: &str| -> R<Map> {
        let c = category(what)?;
        a.with(|tw, i| {
            let p = tw.sim.pipeline.perception();
            let mut m = Map::new();
            let (count, seen, dist) = if i < p.len() && p.len() == tw.sim.world.agents.len() {
                let s = p.summaries(i)[c as usize];
                (s.count as INT, s.seen as INT, s.nearest_dist)
            } else {
                (0, 0, f32::INFINITY)
            };
            m.insert("count".into(), Dynamic::from(count));
            m.insert("seen".into(), Dynamic::from(seen));
            m.insert(
                "nearest_dist".into(),
                Dynamic::from(if dist.is_finite() { dist } else { 1e30 }),
            );
            m
        })
    });
    e.register_fn("perceive", |a: &mut AgentRef, list: Array| -> R<()> {
        let feeds = list.iter().map(feed).collect::<R<Vec<_>>>()?;
        perceive(a, feeds)
    });
    e.register_fn("perceive", |a: &mut AgentRef, one: Map| -> R<()> {
        perceive(a, vec![feed(&Dynamic::from(one))?])
    });
    e.register_fn("perceive_world", |a: &mut AgentRef| {
        a.world.get().feeds.remove(&a.id);
    });
}

fn feed(d: &Dynamic) -> R<Feed> {
    let m = d
        .clone()
        .try_cast::<Map>()
        .ok_or_else(|| error("a percept is a map, e.g. #{ what: \"predator\", dist: 5.0 }"))?;
    check_keys(
        &m,
        &["what", "dist", "bearing", "elevation", "sense", "size"],
        "percept",
    )?;
    let what = m.get("what").ok_or_else(|| {
        error("a percept needs `what` (food, predator, kin, mate, obstacle, other)")
    })?;
    let category = category(&string(what, "what")?)?;
    let dist = m
        .get("dist")
        .ok_or_else(|| error("a percept needs `dist`"))
        .and_then(|d| num(d, "dist"))?;
    if !(dist >= 0.0 && dist.is_finite()) {
        return Err(error(format!("`dist` must be ≥ 0, not {dist}")));
    }
    let sense = match m
        .get("sense")
        .map(|d| string(d, "sense"))
        .transpose()?
        .as_deref()
    {
        None | Some("vision") => Sense::Vision,
        Some("smell") => Sense::Smell,
        Some(other) => {
            return Err(error(format!(
                "`sense` is \"vision\" or \"smell\", not \"{other}\""
            )))
        }
    };
    Ok(Feed {
        category,
        dist,
        bearing: m
            .get("bearing")
            .map_or(Ok(0.0), |d| num(d, "bearing"))?
            .to_radians(),
        elevation: m
            .get("elevation")
            .map_or(Ok(0.0), |d| num(d, "elevation"))?
            .to_radians(),
        sense,
        size: m.get("size").map_or(
            Ok(if category == Category::Food { 0.0 } else { 1.0 }),
            |d| num(d, "size"),
        )?,
    })
}

fn perceive(a: &AgentRef, feeds: Vec<Feed>) -> R<()> {
    a.with_mut(|tw, _| {
        tw.feeds.insert(a.id, feeds);
    })
}
