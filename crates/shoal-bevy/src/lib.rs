//! A [Bevy](https://bevy.org) plugin (Bevy 0.19) that runs a shoal simulation inside an app.
//!
//! - [`ShoalPlugin`] steps the simulation held by the [`ShoalSim`] resource once per run of a
//!   schedule of your choice (`FixedUpdate` by default, whose step it sets to the simulation's
//!   `dt`), in three public [`ShoalSystems`] sets you can order your own systems against:
//!   `SyncBackend` (entities the app despawned leave the simulation; changed species files are
//!   reloaded), `Step` (one tick; its events become [`ShoalEvent`] messages) and `Writeback`
//!   (agents become entities and their components follow the simulation).
//! - Each agent is an entity with [`ShoalAgent`] (its id), [`AgentSpecies`],
//!   [`AgentBehavior`], [`AgentMotion`] (velocity, speed, heading), [`AgentDrives`], a
//!   [`SimPose`] and a [`Transform`](bevy::prelude::Transform) whose `forward()` is the agent's
//!   heading. Entities appear and disappear with the simulation's agents.
//! - Transforms are interpolated between fixed ticks (`ShoalSystems::Interpolate`, in
//!   `PostUpdate` before transform propagation), so motion is smooth at any frame rate.
//! - Species hot reload: a species whose files change is read again and swapped in between
//!   ticks; a bad edit keeps the last good version and sends [`SpeciesReloadFailed`] (and logs
//!   a warning). [`ReloadSpecies`] asks for a reload now.
//!
//! The pattern follows the physics and navigation plugins of the ecosystem (bevy_rapier's
//! `in_schedule` and sync/step/write-back sets, landmass's agents as entities, big-brain's
//! user-chosen schedule).
//!
//! ```
//! use bevy::prelude::*;
//! use shoal_bevy::prelude::*;
//! use shoal_bevy::shoal::prelude::Vec3 as SimVec3; // the engine's vectors
//!
//! let drifter = r#"(
//!     name: "drifter",
//!     initial: "drift",
//!     behaviors: [Behavior(name: "drift", priority: 1, steer: Cruise(speed: 0.5))],
//! )"#;
//! let species = SpeciesSet::new(vec![Species::parse("drifter.ron", drifter).unwrap().into()]);
//! let water = Aabb::new(SimVec3::new(-50.0, 0.0, -50.0), SimVec3::new(50.0, 40.0, 50.0));
//! let mut sim = Sim::new(species.unwrap(), water, 0.05, 7);
//! sim.spawn("drifter", SimVec3::new(0.0, 10.0, 0.0), 0.0).unwrap();
//!
//! let mut app = App::new();
//! app.add_plugins((MinimalPlugins, ShoalPlugin::default()))
//!     .insert_resource(ShoalSim::new(sim))
//!     // A clock of 50 ms a frame for this example (an app runs on real time).
//!     .insert_resource(bevy::time::TimeUpdateStrategy::ManualDuration(
//!         std::time::Duration::from_millis(50),
//!     ));
//! // Your systems run around the simulation's:
//! fn react(mut events: MessageReader<ShoalEvent>) {
//!     for e in events.read() {
//!         if let SimEvent::Catch { agent, prey } = e.event {
//!             println!("{agent:?} caught {prey:?} at tick {}", e.tick);
//!         }
//!     }
//! }
//! app.add_systems(FixedUpdate, react.after(ShoalSystems::Step));
//! app.update(); // the clock starts
//! app.update(); // 50 ms: one tick, and an entity for the drifter
//! let mut agents = app.world_mut().query::<(&ShoalAgent, &Transform, &AgentBehavior)>();
//! let (_, transform, behavior) = agents.single(app.world()).unwrap();
//! assert_eq!(behavior.name, "drift");
//! assert!(transform.translation.y > 9.0);
//! ```
//!
//! Note the two vector types: `shoal::prelude::Vec3` is the engine's, `bevy::prelude::Vec3`
//! Bevy's (both are glam vectors of different releases); convert with `to_array`/`from_array`.

/// The engine this crate runs (its own `Vec3` is glam's release the engine uses).
pub use shoal;

mod agents;
mod interpolate;
mod reload;
mod sim;

pub use agents::{
    AgentBehavior, AgentDrives, AgentEntities, AgentMotion, AgentSpecies, Pose, ShoalAgent,
    ShoalEvent, SimPose,
};
pub use interpolate::Interpolation;
pub use reload::{ReloadSpecies, SpeciesReloadFailed, SpeciesReloaded, SpeciesWatch};
pub use sim::ShoalSim;

use bevy::app::{FixedUpdate, Last, Plugin, PostUpdate, PreUpdate};
use bevy::ecs::intern::Interned;
use bevy::ecs::schedule::{IntoScheduleConfigs, ScheduleLabel, SystemSet};
use bevy::prelude::App;
use bevy::transform::TransformSystems;

/// Everything an app using the plugin needs, with shoal's own prelude (its `Vec3` excepted:
/// use Bevy's and convert; its `Event` and `World` as `SimEvent` and `SimWorld`).
pub mod prelude {
    pub use crate::{
        AgentBehavior, AgentDrives, AgentEntities, AgentMotion, AgentSpecies, Interpolation,
        ReloadSpecies, ShoalAgent, ShoalEvent, ShoalPlugin, ShoalSim, ShoalSystems, SimPose,
        SpeciesReloadFailed, SpeciesReloaded, SpeciesWatch,
    };
    pub use shoal::prelude::{
        Aabb, Agent, AgentId, Category, Diagnostic, Diagnostics, MessageKind, Overrides, Percept,
        Run, Scenario, Shape, Sim, Species, SpeciesSet, UnknownSpecies,
    };
    // Renamed: Bevy's prelude has an `Event` and a `World` of its own.
    pub use shoal::prelude::{Event as SimEvent, World as SimWorld};
}

/// The plugin's system sets, in the order they run in its schedule (plus `Interpolate`, in
/// `PostUpdate`).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ShoalSystems {
    /// Before the tick: agents of despawned entities leave the simulation; changed species files
    /// are reloaded. Put systems that feed the simulation (spawn, send, inject) before `Step`.
    SyncBackend,
    /// One tick of the simulation; its events are sent as [`ShoalEvent`]s.
    Step,
    /// After the tick: entities for new agents, none for gone ones, components refreshed.
    Writeback,
    /// In `PostUpdate`, before transform propagation: agents' transforms blended between the
    /// last two ticks.
    Interpolate,
}

/// Runs the [`ShoalSim`] resource in an app. See the crate docs.
#[derive(Debug, Clone)]
pub struct ShoalPlugin {
    schedule: Interned<dyn ScheduleLabel>,
    interpolate: bool,
    match_timestep: bool,
}

impl Default for ShoalPlugin {
    /// Steps in `FixedUpdate` at the simulation's `dt`, transforms interpolated.
    fn default() -> ShoalPlugin {
        ShoalPlugin {
            schedule: FixedUpdate.intern(),
            interpolate: true,
            match_timestep: true,
        }
    }
}

impl ShoalPlugin {
    /// Steps once per run of `schedule` (e.g. `Update` for one tick a frame). Outside
    /// `FixedUpdate` transforms are not interpolated and the fixed clock is left alone.
    pub fn in_schedule(schedule: impl ScheduleLabel) -> ShoalPlugin {
        let schedule = schedule.intern();
        let fixed = schedule == FixedUpdate.intern();
        ShoalPlugin {
            schedule,
            interpolate: fixed,
            match_timestep: fixed,
        }
    }

    /// Whether transforms blend between the last two ticks (default: when stepping in
    /// `FixedUpdate`); without it they jump to each tick's pose.
    pub fn with_interpolation(mut self, on: bool) -> ShoalPlugin {
        self.interpolate = on;
        self
    }

    /// Whether the plugin sets `Time<Fixed>`'s step to the simulation's `dt` (default: when
    /// stepping in `FixedUpdate`).
    pub fn with_matched_timestep(mut self, on: bool) -> ShoalPlugin {
        self.match_timestep = on;
        self
    }
}

impl Plugin for ShoalPlugin {
    fn build(&self, app: &mut App) {
        app.add_message::<ShoalEvent>()
            .add_message::<ReloadSpecies>()
            .add_message::<SpeciesReloaded>()
            .add_message::<SpeciesReloadFailed>()
            .init_resource::<AgentEntities>()
            .init_resource::<SpeciesWatch>()
            .insert_resource(Interpolation(self.interpolate))
            .configure_sets(
                self.schedule,
                (
                    ShoalSystems::SyncBackend,
                    ShoalSystems::Step,
                    ShoalSystems::Writeback,
                )
                    .chain(),
            )
            .add_systems(
                self.schedule,
                (
                    (agents::despawn_removed, reload::reload_species)
                        .chain()
                        .in_set(ShoalSystems::SyncBackend),
                    agents::step.in_set(ShoalSystems::Step),
                    agents::write_back.in_set(ShoalSystems::Writeback),
                ),
            )
            // Also every frame: the removals of a frame without a tick are kept for one frame only.
            .add_systems(Last, agents::despawn_removed)
            .configure_sets(
                PostUpdate,
                ShoalSystems::Interpolate.before(TransformSystems::Propagate),
            )
            .add_systems(
                PostUpdate,
                interpolate::interpolate.in_set(ShoalSystems::Interpolate),
            );
        if self.match_timestep {
            app.add_systems(PreUpdate, interpolate::match_timestep);
        }
    }
}
