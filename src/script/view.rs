//! The script API: the typed [`AgentView`] bound as `this`, glam vectors with operators, the
//! blackboard, deterministic random numbers, messages and steering values.

use crate::perception::{Category, Level, Sector, Strength};
use crate::world::{EventSpec, MemValue, Payload, Rng, Signal};
use glam::Vec3;
use rhai::{Dynamic, Engine, EvalAltResult, ImmutableString, Position, FLOAT, INT};
use std::sync::Arc;
use thin_vec::ThinVec;

/// What a script sees of one category of percepts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CategoryView {
    /// Number perceived.
    pub count: INT,
    /// Number seen (vision).
    pub seen: INT,
    /// Distance to the nearest (a large number when none).
    pub nearest_dist: FLOAT,
    /// Position of the nearest (own position when none).
    pub nearest_pos: Vec3,
    /// Bearing of the nearest (rad, right positive).
    pub nearest_bearing: FLOAT,
    /// Elevation of the nearest (rad, up positive).
    pub nearest_elevation: FLOAT,
    /// Horizontal sector of the nearest (seed 000 §4.3, bounds `senses.sectors`), `None` when
    /// none.
    pub nearest_sector: Option<Sector>,
    /// Level of the nearest (above, level, below), `None` when none.
    pub nearest_level: Option<Level>,
    /// The species' fall of perceived strength (seed 001): `nearest_strength` is computed from
    /// `nearest_dist` only when a script reads it.
    pub strength: Strength,
    /// Mean position.
    pub centroid: Vec3,
    /// Mean heading.
    pub mean_heading: Vec3,
    /// Mean velocity.
    pub mean_velocity: Vec3,
}

/// A steering value built by a script: a weighted sum of terms, evaluated natively every tick
/// until the script runs again (so a script composes native primitives without running per tick).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScriptSteer {
    /// Weighted terms.
    pub terms: Vec<(f32, SteerTerm)>,
}

pub use crate::command::Term as SteerTerm;

/// The agent as a script sees it, bound as `this`. Fields are filled from the agent before a
/// call and the writable ones (drives, memory, outbox, random stream) copied back after.
#[derive(Debug, Clone, Default)]
pub struct AgentView {
    /// Stable id.
    pub id: INT,
    /// Species name.
    pub species: ImmutableString,
    /// Current tick.
    pub tick: INT,
    /// Simulated time (s).
    pub time: FLOAT,
    /// Time step (s).
    pub dt: FLOAT,
    /// Position.
    pub pos: Vec3,
    /// Velocity.
    pub vel: Vec3,
    /// Forward unit vector.
    pub fwd: Vec3,
    /// Speed.
    pub speed: FLOAT,
    /// Maximum speed.
    pub max_speed: FLOAT,
    /// Hunger.
    pub hunger: FLOAT,
    /// Libido.
    pub libido: FLOAT,
    /// Fear.
    pub fear: FLOAT,
    /// Fatigue.
    pub fatigue: FLOAT,
    /// Seed 003 internal state S(t) (read-only).
    pub state: FLOAT,
    /// Own best food position (a `Vec3`, or `()` when it knows none; read-only).
    pub best_food: Dynamic,
    /// The school's best food position (a `Vec3`, or `()`; read-only).
    pub school_best: Dynamic,
    /// Current behavior name.
    pub behavior: ImmutableString,
    /// Seconds in the current behavior.
    pub time_in_behavior: FLOAT,
    /// Depth of the behavior stack.
    pub stack_depth: INT,
    /// "female" or "male".
    pub sex: ImmutableString,
    /// Age.
    pub age: FLOAT,
    /// Mass.
    pub mass: FLOAT,
    /// Type tag.
    pub kind: INT,
    /// Percept summaries by [`Category`] index.
    pub cats: [CategoryView; Category::COUNT],
    /// Highest-priority message heard last tick ("" when none).
    pub heard: ImmutableString,
    /// The blackboard.
    pub memory: ThinVec<(Arc<str>, MemValue)>,
    /// The agent's random stream.
    pub rng: Rng,
    /// Messages to broadcast: (kind or declared event, radius, payload of a declared event).
    pub outbox: Vec<(Signal, f32, Option<Payload>)>,
    /// Names of the species' named recipes.
    pub recipes: Arc<[String]>,
    /// Whether a script wrote a drive.
    pub drives_written: bool,
    /// The ground, for line-of-sight queries (`this.can_see(p)`).
    pub terrain: Option<Arc<crate::terrain::Terrain>>,
    /// Eye height above the agent's position (its body height).
    pub eye_height: FLOAT,
    /// The agent's squad and plan, when it is a squad member.
    pub squad: Option<crate::world::board::SquadView>,
    /// The species' declared events (what `send` names may be).
    pub events: Arc<[EventSpec]>,
    /// The payload of the declared event heard last tick, if that is what was heard.
    pub heard_payload: Option<Payload>,
}

fn err(msg: impl Into<String>) -> Box<EvalAltResult> {
    Box::new(EvalAltResult::ErrorRuntime(
        Dynamic::from(msg.into()),
        Position::NONE,
    ))
}

/// A script value as a blackboard entry (bools, ints, floats, vectors, strings up to 256 bytes).
pub fn to_mem(v: Dynamic) -> Result<MemValue, Box<EvalAltResult>> {
    if let Some(b) = v.clone().try_cast::<bool>() {
        Ok(MemValue::Bool(b))
    } else if let Some(i) = v.clone().try_cast::<INT>() {
        Ok(MemValue::Int(i))
    } else if let Some(f) = v.clone().try_cast::<FLOAT>() {
        Ok(MemValue::Float(f))
    } else if let Some(x) = v.clone().try_cast::<Vec3>() {
        Ok(MemValue::Vec3(x))
    } else if let Some(s) = v.clone().try_cast::<ImmutableString>() {
        if s.len() > 256 {
            return Err(err("memory strings are limited to 256 bytes"));
        }
        Ok(MemValue::Str(s.to_string()))
    } else {
        Err(err(format!(
            "memory holds bools, ints, floats, Vec3 and strings, not {}",
            v.type_name()
        )))
    }
}

/// A blackboard entry as a script value.
pub fn from_mem(v: &MemValue) -> Dynamic {
    match v {
        MemValue::Bool(b) => Dynamic::from(*b),
        MemValue::Int(i) => Dynamic::from(*i),
        MemValue::Float(f) => Dynamic::from(*f),
        MemValue::Vec3(x) => Dynamic::from(*x),
        MemValue::Str(s) => Dynamic::from(ImmutableString::from(s.as_str())),
    }
}

/// Registers a read-only property of the agent view. Rhai writes a property back after calling a
/// method on it (`this.pos.length()`); without a setter that write would fall through to the
/// blackboard indexer and store a copy there. The setter accepts the unchanged value and refuses
/// any other.
pub fn read_only<T: Clone + PartialEq + Send + Sync + 'static>(
    e: &mut Engine,
    name: &'static str,
    get: fn(&AgentView) -> T,
) {
    e.register_get(name, move |v: &mut AgentView| get(v));
    e.register_set(
        name,
        move |v: &mut AgentView, x: T| -> Result<(), Box<EvalAltResult>> {
            if get(v) == x {
                Ok(())
            } else {
                Err(err(format!("`this.{name}` is read-only")))
            }
        },
    );
}

fn single(term: SteerTerm) -> ScriptSteer {
    ScriptSteer {
        terms: vec![(1.0, term)],
    }
}

/// Registers the whole API on an engine.
pub fn register_api(e: &mut Engine) {
    register_vec3(e);
    register_category(e);
    register_steer(e);
    register_agent(e);
    super::squad::register(e);
}

fn register_vec3(e: &mut Engine) {
    e.register_type_with_name::<Vec3>("Vec3")
        .register_fn("vec3", |x: FLOAT, y: FLOAT, z: FLOAT| Vec3::new(x, y, z))
        .register_fn("+", |a: Vec3, b: Vec3| a + b)
        .register_fn("-", |a: Vec3, b: Vec3| a - b)
        .register_fn("-", |a: Vec3| -a)
        .register_fn("*", |a: Vec3, k: FLOAT| a * k)
        .register_fn("*", |k: FLOAT, a: Vec3| a * k)
        .register_fn("/", |a: Vec3, k: FLOAT| a / k)
        .register_fn("==", |a: Vec3, b: Vec3| a == b)
        .register_get_set("x", |v: &mut Vec3| v.x, |v: &mut Vec3, x: FLOAT| v.x = x)
        .register_get_set("y", |v: &mut Vec3| v.y, |v: &mut Vec3, x: FLOAT| v.y = x)
        .register_get_set("z", |v: &mut Vec3| v.z, |v: &mut Vec3, x: FLOAT| v.z = x)
        .register_fn("length", |v: &mut Vec3| v.length())
        .register_fn("normalize", |v: &mut Vec3| v.normalize_or_zero())
        .register_fn("dot", |a: &mut Vec3, b: Vec3| a.dot(b))
        .register_fn("cross", |a: &mut Vec3, b: Vec3| a.cross(b))
        .register_fn("distance", |a: &mut Vec3, b: Vec3| a.distance(b))
        .register_fn("to_string", |v: &mut Vec3| {
            format!("({}, {}, {})", v.x, v.y, v.z)
        })
        .register_fn("to_debug", |v: &mut Vec3| {
            format!("vec3({}, {}, {})", v.x, v.y, v.z)
        });
}

fn register_category(e: &mut Engine) {
    e.register_type_with_name::<CategoryView>("Percepts")
        .register_get("count", |c: &mut CategoryView| c.count)
        .register_get("seen", |c: &mut CategoryView| c.seen)
        .register_get("exists", |c: &mut CategoryView| c.count > 0)
        .register_get("nearest_dist", |c: &mut CategoryView| c.nearest_dist)
        .register_get("nearest_pos", |c: &mut CategoryView| c.nearest_pos)
        .register_get("nearest_bearing", |c: &mut CategoryView| c.nearest_bearing)
        .register_get("nearest_elevation", |c: &mut CategoryView| {
            c.nearest_elevation
        })
        .register_get("nearest_strength", |c: &mut CategoryView| {
            nearest_strength(c)
        })
        .register_get("nearest_sector", |c: &mut CategoryView| {
            ImmutableString::from(c.nearest_sector.map_or("", Sector::name))
        })
        .register_get("nearest_level", |c: &mut CategoryView| {
            ImmutableString::from(c.nearest_level.map_or("", Level::name))
        })
        .register_get("centroid", |c: &mut CategoryView| c.centroid)
        .register_get("mean_heading", |c: &mut CategoryView| c.mean_heading)
        .register_get("mean_velocity", |c: &mut CategoryView| c.mean_velocity);
}

/// `nearest_strength` of a category (0 when none is perceived).
pub(crate) fn nearest_strength(c: &CategoryView) -> FLOAT {
    if c.count > 0 {
        c.strength.at(c.nearest_dist)
    } else {
        0.0
    }
}

fn register_steer(e: &mut Engine) {
    e.register_type_with_name::<ScriptSteer>("Steer")
        .register_fn("+", |a: ScriptSteer, b: ScriptSteer| {
            let mut t = a.terms;
            t.extend(b.terms);
            ScriptSteer { terms: t }
        })
        .register_fn("*", |a: ScriptSteer, k: FLOAT| ScriptSteer {
            terms: a.terms.into_iter().map(|(w, t)| (w * k, t)).collect(),
        })
        .register_fn("*", |k: FLOAT, a: ScriptSteer| ScriptSteer {
            terms: a.terms.into_iter().map(|(w, t)| (w * k, t)).collect(),
        })
        .register_fn("to_string", |s: &mut ScriptSteer| format!("{:?}", s.terms));
}

fn register_agent(e: &mut Engine) {
    e.register_type_with_name::<AgentView>("Agent");
    read_only(e, "id", |v| v.id);
    read_only(e, "species", |v| v.species.clone());
    read_only(e, "tick", |v| v.tick);
    read_only(e, "time", |v| v.time);
    read_only(e, "dt", |v| v.dt);
    read_only(e, "pos", |v| v.pos);
    read_only(e, "vel", |v| v.vel);
    read_only(e, "fwd", |v| v.fwd);
    read_only(e, "speed", |v| v.speed);
    read_only(e, "max_speed", |v| v.max_speed);
    read_only(e, "state", |v| v.state);
    for (name, get) in [
        (
            "best_food",
            (|v| v.best_food.clone()) as fn(&AgentView) -> Dynamic,
        ),
        ("school_best", |v| v.school_best.clone()),
    ] {
        e.register_get(name, move |v: &mut AgentView| get(v));
        e.register_set(
            name,
            move |_: &mut AgentView, _: Dynamic| -> Result<(), Box<EvalAltResult>> {
                Err(err(format!("`this.{name}` is read-only")))
            },
        );
    }
    read_only(e, "behavior", |v| v.behavior.clone());
    read_only(e, "time_in_behavior", |v| v.time_in_behavior);
    read_only(e, "stack_depth", |v| v.stack_depth);
    read_only(e, "sex", |v| v.sex.clone());
    read_only(e, "age", |v| v.age);
    read_only(e, "mass", |v| v.mass);
    read_only(e, "kind", |v| v.kind);
    read_only(e, "heard", |v| v.heard.clone());
    macro_rules! drive {
        ($name:literal, $field:ident) => {
            e.register_get_set(
                $name,
                |v: &mut AgentView| v.$field,
                |v: &mut AgentView, x: FLOAT| {
                    v.$field = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
                    v.drives_written = true;
                },
            );
        };
    }
    drive!("hunger", hunger);
    drive!("libido", libido);
    drive!("fear", fear);
    drive!("fatigue", fatigue);
    for c in Category::ALL {
        let i = c as usize;
        let name = c.name();
        e.register_get(name, move |v: &mut AgentView| v.cats[i].clone());
        e.register_set(
            name,
            move |v: &mut AgentView, x: CategoryView| -> Result<(), Box<EvalAltResult>> {
                if v.cats[i] == x {
                    Ok(())
                } else {
                    Err(err(format!("`this.{name}` is read-only")))
                }
            },
        );
    }
    // Blackboard: this["key"], this["key"] = value, this.has("key"), this.forget("key").
    e.register_indexer_get(|v: &mut AgentView, key: &str| -> Dynamic {
        v.memory
            .iter()
            .find(|(k, _)| &**k == key)
            .map(|(_, m)| from_mem(m))
            .unwrap_or(Dynamic::UNIT)
    });
    e.register_indexer_set(
        |v: &mut AgentView, key: &str, value: Dynamic| -> Result<(), Box<EvalAltResult>> {
            let m = to_mem(value)?;
            // No declaration here: every key is the agent's own.
            super::memory::store(&mut v.memory, key, m, &super::memory::MemorySpec::default())
                .map_err(err)
        },
    );
    e.register_fn("has", |v: &mut AgentView, key: &str| {
        v.memory.iter().any(|(k, _)| &**k == key)
    });
    e.register_fn("forget", |v: &mut AgentView, key: &str| {
        v.memory.retain(|(k, _)| &**k != key)
    });
    e.register_fn("random", |v: &mut AgentView| v.rng.next_f32());
    e.register_fn("random_range", |v: &mut AgentView, lo: FLOAT, hi: FLOAT| {
        v.rng.range(lo, hi)
    });
    super::events::register(e);
    // Steering values.
    e.register_fn(
        "recipe",
        |v: &mut AgentView, name: &str| -> Result<ScriptSteer, Box<EvalAltResult>> {
            match v.recipes.iter().position(|r| r == name) {
                Some(i) => Ok(single(SteerTerm::Recipe(i as u16))),
                None => Err(err(format!(
                    "unknown recipe \"{name}\": the species defines {}",
                    if v.recipes.is_empty() {
                        "no named recipes".to_string()
                    } else {
                        v.recipes.join(", ")
                    }
                ))),
            }
        },
    );
    e.register_fn("seek", |v: &mut AgentView, p: Vec3| {
        single(SteerTerm::Velocity(
            (p - v.pos).normalize_or_zero() * v.max_speed,
        ))
    });
    e.register_fn("flee", |v: &mut AgentView, p: Vec3| {
        single(SteerTerm::Velocity(
            (v.pos - p).normalize_or_zero() * v.max_speed,
        ))
    });
    e.register_fn("arrive", |v: &mut AgentView, p: Vec3, slow: FLOAT| {
        let off = p - v.pos;
        let d = off.length();
        let s = if slow > 0.0 && d < slow {
            v.max_speed * d / slow
        } else {
            v.max_speed
        };
        single(SteerTerm::Velocity(off.normalize_or_zero() * s))
    });
    e.register_fn("velocity", |_: &mut AgentView, vel: Vec3| {
        single(SteerTerm::Velocity(vel))
    });
    e.register_fn(
        "turn",
        |_: &mut AgentView, yaw: FLOAT, pitch: FLOAT, speed: FLOAT| {
            single(SteerTerm::Turn(yaw, pitch, speed))
        },
    );
    e.register_fn("keep", |v: &mut AgentView| {
        single(SteerTerm::Turn(0.0, 0.0, v.speed))
    });
    e.register_fn("stop", |_: &mut AgentView| {
        single(SteerTerm::Turn(0.0, 0.0, 0.0))
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{SandboxLimits, Script};
    use rhai::Scope;
    use std::path::Path;

    #[test]
    fn methods_on_read_only_properties_leave_the_blackboard_alone() {
        let text = "fn probe() { this.pos.length() + this.kin.centroid.length() }\nfn poke() { this.pos = vec3(1.0, 2.0, 3.0); }";
        let s = Script::compile(
            Path::new("probe.rhai"),
            text,
            Path::new("."),
            &SandboxLimits::default(),
        )
        .unwrap();
        let mut view = AgentView {
            pos: Vec3::new(3.0, 4.0, 0.0),
            ..Default::default()
        };
        view.cats[Category::Kin as usize].centroid = Vec3::new(0.0, 0.0, 2.0);
        let mut this = Dynamic::from(view);
        let mut scope = Scope::new();
        let r: FLOAT = s.call(&mut scope, &mut this, "probe").unwrap();
        assert_eq!(r, 7.0);
        let v = this.clone().cast::<AgentView>();
        assert!(v.memory.is_empty(), "{:?}", v.memory);
        let e = s
            .call::<Dynamic>(&mut scope, &mut this, "poke")
            .unwrap_err();
        assert!(
            e.diagnostic.message.contains("`this.pos` is read-only"),
            "{}",
            e.diagnostic
        );
        assert_eq!(e.diagnostic.line, 2);
    }

    #[test]
    fn scripts_read_the_strength_sector_and_level_of_the_nearest() {
        let text = "fn strength() { this.predator.nearest_strength }
                    fn sector() { this.predator.nearest_sector }
                    fn level() { this.predator.nearest_level }
                    fn none() { this.food.nearest_strength }
                    fn no_sector() { this.food.nearest_sector + this.food.nearest_level }";
        let s = Script::compile(
            Path::new("probe.rhai"),
            text,
            Path::new("."),
            &SandboxLimits::default(),
        )
        .unwrap();
        let mut view = AgentView::default();
        view.cats[Category::Predator as usize] = CategoryView {
            count: 1,
            nearest_dist: 2.0,
            nearest_sector: Some(Sector::LeftRear),
            nearest_level: Some(Level::Below),
            strength: Strength {
                power: 2.0,
                near: 0.5,
            },
            ..Default::default()
        };
        view.cats[Category::Food as usize].nearest_dist = 1e30;
        let mut this = Dynamic::from(view);
        let mut scope = Scope::new();
        // (0.5/2)² = 0.0625.
        let r: FLOAT = s.call(&mut scope, &mut this, "strength").unwrap();
        assert_eq!(r, 0.0625);
        let r: ImmutableString = s.call(&mut scope, &mut this, "sector").unwrap();
        assert_eq!(r.as_str(), "left_rear");
        let r: ImmutableString = s.call(&mut scope, &mut this, "level").unwrap();
        assert_eq!(r.as_str(), "below");
        // Nothing perceived: no strength, no sector, no level.
        let r: FLOAT = s.call(&mut scope, &mut this, "none").unwrap();
        assert_eq!(r, 0.0);
        let r: ImmutableString = s.call(&mut scope, &mut this, "no_sector").unwrap();
        assert_eq!(r.as_str(), "");
    }
}
