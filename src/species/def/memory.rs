//! The species file's `memory` block: the blackboard keys a species' agents keep, each with a
//! type and a start value (`"meals": Int(0)`) or none (`"home_y": Float(None)`: unset until a
//! script writes it). Checked and turned into the script host's [`crate::script::memory::MemorySpec`]
//! by `species/blackboard.rs`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// One declared blackboard key: its type, and the value a new agent starts with (`None`: the key
/// starts unset, and `this.has(key)` is false until a script writes it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum MemDecl {
    /// `true` or `false`.
    Bool(Option<bool>),
    /// An integer.
    Int(Option<i64>),
    /// A number.
    Float(Option<f32>),
    /// A vector, written `Vec3(x, y, z)`.
    Vec3(Option<Vec3>),
    /// A string of at most 256 bytes.
    #[serde(rename = "String")]
    Str(Option<String>),
}
