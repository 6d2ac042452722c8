//! Agents as entities: the components that mirror an agent's state, and the systems that keep
//! them in step with the simulation (the sim is the source of truth; entities follow it).
//! Reads and writes [`ShoalSim`] and the agents' entities; nothing else.

use crate::sim::ShoalSim;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use shoal::prelude::{Agent, AgentId, Event};

/// The simulation agent this entity mirrors. Despawning the entity despawns the agent.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[require(Transform)]
pub struct ShoalAgent(pub AgentId);

/// The agent's species: its index in the running species set and its name.
#[derive(Component, Debug, Clone, PartialEq, Eq)]
pub struct AgentSpecies {
    /// Index in [`shoal::prelude::SpeciesSet::species`] (may change on a hot reload).
    pub index: usize,
    /// The species' name.
    pub name: String,
}

/// The behavior the agent is in.
#[derive(Component, Debug, Clone, PartialEq, Eq)]
pub struct AgentBehavior {
    /// Index among its species' behaviors.
    pub index: u16,
    /// The behavior's name.
    pub name: String,
}

/// How the agent moves, as of the last tick.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct AgentMotion {
    /// Velocity (heading × speed, without the world's current), world units per second.
    pub velocity: Vec3,
    /// Speed along the heading.
    pub speed: f32,
    /// Heading yaw about world up (radians, 0 heads +z; shoal's convention).
    pub yaw: f32,
    /// Heading pitch (radians, up positive).
    pub pitch: f32,
}

/// The agent's drives (hunger, libido, fear, fatigue, S(t)…) as of the last tick.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct AgentDrives(pub shoal::world::Drives);

/// The agent's pose after the previous tick and after the last one: the two ends that
/// [`crate::ShoalSystems::Interpolate`] blends the entity's [`Transform`] between.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct SimPose {
    /// Position and heading one tick before `current`.
    pub previous: Pose,
    /// Position and heading after the last tick.
    pub current: Pose,
}

/// A position and a rotation whose [`Transform::forward`] (local −z) is the agent's heading,
/// with no roll.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Position.
    pub translation: Vec3,
    /// Rotation.
    pub rotation: Quat,
}

impl Pose {
    /// The pose of `agent`.
    pub fn of(agent: &Agent) -> Pose {
        let f = agent.forward().to_array();
        let forward = Vec3::from_array(f);
        // `looking_to` keeps world up as up: shoal's bodies do not roll and |pitch| < 90°.
        let rotation = Transform::IDENTITY
            .looking_to(forward, Vec3::Y)
            .rotation
            .normalize();
        Pose {
            translation: Vec3::from_array(agent.pos.to_array()),
            rotation,
        }
    }

    /// The pose `t` of the way from `self` to `to` (0 = `self`, 1 = `to`).
    pub fn lerp(&self, to: &Pose, t: f32) -> Pose {
        Pose {
            translation: self.translation.lerp(to.translation, t),
            rotation: self.rotation.slerp(to.rotation, t),
        }
    }
}

/// The entity of each agent in the world, kept by the write-back system.
#[derive(Resource, Debug, Default)]
pub struct AgentEntities {
    by_agent: HashMap<AgentId, (Entity, u64)>,
    by_entity: HashMap<Entity, AgentId>,
    pass: u64,
}

impl AgentEntities {
    /// The entity mirroring agent `id`.
    pub fn entity(&self, id: AgentId) -> Option<Entity> {
        self.by_agent.get(&id).map(|(e, _)| *e)
    }

    /// The agent entity `e` mirrors.
    pub fn agent(&self, e: Entity) -> Option<AgentId> {
        self.by_entity.get(&e).copied()
    }

    /// Agents mirrored.
    pub fn len(&self) -> usize {
        self.by_agent.len()
    }

    /// Whether no agent is mirrored.
    pub fn is_empty(&self) -> bool {
        self.by_agent.is_empty()
    }
}

/// One of the simulation's events, sent after the tick that produced it.
#[derive(Message, Debug, Clone, PartialEq)]
pub struct ShoalEvent {
    /// The tick count after the step that produced it.
    pub tick: u64,
    /// What happened.
    pub event: Event,
}

/// Sync-in: an agent whose entity the app despawned leaves the simulation.
pub(crate) fn despawn_removed(
    mut removed: RemovedComponents<ShoalAgent>,
    mut map: ResMut<AgentEntities>,
    sim: Option<ResMut<ShoalSim>>,
) {
    let Some(mut sim) = sim else {
        removed.clear();
        return;
    };
    for e in removed.read() {
        // Entities the write-back removed (their agent died) are no longer in the map.
        if let Some(id) = map.by_entity.remove(&e) {
            map.by_agent.remove(&id);
            sim.sim_mut().despawn(id);
        }
    }
}

/// Step: one tick of the simulation, its events sent as [`ShoalEvent`]s.
pub(crate) fn step(sim: Option<ResMut<ShoalSim>>, mut events: MessageWriter<ShoalEvent>) {
    let Some(mut sim) = sim else { return };
    if !sim.running {
        return;
    }
    sim.step();
    let s = sim.sim();
    let tick = s.tick();
    events.write_batch(s.events().iter().map(|e| ShoalEvent {
        tick,
        event: e.clone(),
    }));
}

/// The components of an agent's entity, as the write-back updates them.
type Mirror<'a> = (
    &'a mut SimPose,
    &'a mut AgentMotion,
    &'a mut AgentDrives,
    &'a mut AgentSpecies,
    &'a mut AgentBehavior,
);

/// Write-back: entities for new agents, none for gone ones, and every mirror component
/// refreshed from the simulation.
pub(crate) fn write_back(
    mut commands: Commands,
    sim: Option<Res<ShoalSim>>,
    mut map: ResMut<AgentEntities>,
    mut mirrors: Query<Mirror>,
) {
    let Some(sim) = sim else { return };
    let sim = sim.sim();
    let set = sim.species();
    map.pass += 1;
    let pass = map.pass;
    for a in sim.agents() {
        let species = set.species.get(a.species.0 as usize);
        let species_name = species.map_or("?", |s| s.name.as_str());
        let behavior_name = species.map_or("?", |s| s.behavior_name(a.mind.current));
        let pose = Pose::of(a);
        let motion = AgentMotion {
            velocity: Vec3::from_array(a.velocity().to_array()),
            speed: a.speed,
            yaw: a.yaw,
            pitch: a.pitch,
        };
        let known = map.by_agent.get(&a.id).map(|(e, _)| *e);
        if let Some((mut p, mut m, mut d, mut sp, mut b)) =
            known.and_then(|e| mirrors.get_mut(e).ok())
        {
            p.previous = p.current;
            p.current = pose;
            *m = motion;
            d.0 = a.drives;
            // Names are rewritten only when they change, so `Changed<…>` means a change.
            if sp.index != a.species.0 as usize || sp.name != species_name {
                sp.index = a.species.0 as usize;
                sp.name = species_name.to_string();
            }
            if b.index != a.mind.current || b.name != behavior_name {
                b.index = a.mind.current;
                b.name = behavior_name.to_string();
            }
            map.by_agent
                .insert(a.id, (known.expect("found above"), pass));
            continue;
        }
        let e = commands
            .spawn((
                ShoalAgent(a.id),
                Name::new(format!("{species_name} {}", a.id.0)),
                Transform::from_translation(pose.translation).with_rotation(pose.rotation),
                SimPose {
                    previous: pose,
                    current: pose,
                },
                motion,
                AgentDrives(a.drives),
                AgentSpecies {
                    index: a.species.0 as usize,
                    name: species_name.to_string(),
                },
                AgentBehavior {
                    index: a.mind.current,
                    name: behavior_name.to_string(),
                },
            ))
            .id();
        map.by_agent.insert(a.id, (e, pass));
        map.by_entity.insert(e, a.id);
    }
    let gone: Vec<(AgentId, Entity)> = map
        .by_agent
        .iter()
        .filter(|(_, (_, seen))| *seen != pass)
        .map(|(id, (e, _))| (*id, *e))
        .collect();
    for (id, e) in gone {
        map.by_agent.remove(&id);
        map.by_entity.remove(&e);
        // The app may have despawned it already.
        commands.entity(e).try_despawn();
    }
}
