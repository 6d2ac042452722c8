//! Reading a test script's arguments: numbers, integers, vectors, strings, option maps with
//! their known keys, category names and ground positions, each failing with a message that
//! names the argument and what it must be.

use super::R;
use crate::perception::Category;
use crate::testing::failure::error;
use glam::{Vec2, Vec3};
use rhai::{Array, Dynamic, Map};

pub(super) fn num(d: &Dynamic, what: &str) -> R<f32> {
    if let Ok(f) = d.as_float() {
        Ok(f)
    } else if let Ok(i) = d.as_int() {
        Ok(i as f32)
    } else {
        Err(error(format!(
            "`{what}` must be a number, not {}",
            d.type_name()
        )))
    }
}

pub(super) fn int(d: &Dynamic, what: &str) -> R<i64> {
    d.as_int()
        .map_err(|t| error(format!("`{what}` must be an integer, not {t}")))
}

pub(super) fn vec3(d: &Dynamic, what: &str) -> R<Vec3> {
    d.clone().try_cast::<Vec3>().ok_or_else(|| {
        error(format!(
            "`{what}` must be a vec3(x, y, z), not {}",
            d.type_name()
        ))
    })
}

pub(super) fn string(d: &Dynamic, what: &str) -> R<String> {
    d.clone()
        .into_immutable_string()
        .map(|s| s.to_string())
        .map_err(|t| error(format!("`{what}` must be a string, not {t}")))
}

pub(super) fn strings(a: &Array, what: &str) -> R<Vec<String>> {
    a.iter().map(|d| string(d, what)).collect()
}

pub(super) fn check_keys(m: &Map, known: &[&str], what: &str) -> R<()> {
    for k in m.keys() {
        if !known.contains(&k.as_str()) {
            return Err(error(format!(
                "unknown {what} option `{k}`: expected one of {}",
                known.join(", ")
            )));
        }
    }
    Ok(())
}

pub(super) fn category(name: &str) -> R<Category> {
    Category::ALL
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| {
            error(format!(
                "unknown category \"{name}\": expected one of food, predator, kin, mate, obstacle, other"
            ))
        })
}

/// World `(x, z)` from a vec3 (its `y` ignored) or an array `[x, z]`.
pub(super) fn xz(d: &Dynamic, what: &str) -> R<Vec2> {
    if let Some(v) = d.clone().try_cast::<Vec3>() {
        return Ok(Vec2::new(v.x, v.z));
    }
    match d.clone().try_cast::<Array>() {
        Some(a) if a.len() == 2 => Ok(Vec2::new(num(&a[0], what)?, num(&a[1], what)?)),
        _ => Err(error(format!(
            "`{what}` must be [x, z] or a vec3, not {}",
            d.type_name()
        ))),
    }
}
