//! A headless app (`MinimalPlugins` + `ShoalPlugin`) stepped frame by frame with a manual clock:
//! entities follow the simulation's agents (positions, headings, interpolation between ticks,
//! spawns and despawns both ways), species files reload while the app runs (a bad edit keeps the
//! last good version), and a shipped scenario runs as a resource.

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use shoal_bevy::prelude::{
    Aabb, AgentBehavior, AgentEntities, AgentId, AgentMotion, Overrides, Run, Scenario, ShoalAgent,
    ShoalPlugin, ShoalSim, Sim, Species, SpeciesReloadFailed, SpeciesReloaded, SpeciesSet,
};
use std::collections::HashMap;
use std::path::Path;
use std::time::Duration;

const DT: f32 = 0.05;

/// A species whose one behavior cruises at `speed` × the default top speed (2).
fn drifter(speed: f32, behavior: &str) -> String {
    format!(
        r#"(
    name: "drifter",
    initial: "{behavior}",
    behaviors: [Behavior(name: "{behavior}", priority: 1, steer: Cruise(speed: {speed:.1}))],
)"#
    )
}

fn v(x: f32, y: f32, z: f32) -> shoal::prelude::Vec3 {
    shoal::prelude::Vec3::new(x, y, z)
}

/// A world of drifters read from `file`, spread out and heading different ways.
fn drifters(file: &Path, n: usize) -> Sim {
    let species = Species::load(file).expect("the species loads");
    let water = Aabb::new(v(-50.0, 0.0, -50.0), v(50.0, 40.0, 50.0));
    let mut sim = Sim::new(SpeciesSet::new(vec![species.into()]).unwrap(), water, DT, 3);
    for k in 0..n {
        let at = v(k as f32 * 4.0 - 10.0, 10.0 + k as f32, 0.0);
        sim.spawn("drifter", at, k as f32 * 0.7).unwrap();
    }
    sim
}

fn app(sim: Sim, frame: Duration) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, ShoalPlugin::default()))
        .insert_resource(ShoalSim::new(sim))
        .insert_resource(TimeUpdateStrategy::ManualDuration(frame));
    app
}

fn set_frame(app: &mut App, frame: Duration) {
    app.insert_resource(TimeUpdateStrategy::ManualDuration(frame));
}

fn tick(app: &App) -> u64 {
    app.world().resource::<ShoalSim>().sim().tick()
}

/// Every agent's position and heading, in Bevy's vectors.
fn poses(app: &App) -> HashMap<AgentId, (Vec3, Vec3)> {
    let sim = app.world().resource::<ShoalSim>().sim();
    sim.agents()
        .iter()
        .map(|a| {
            let p = Vec3::from_array(a.pos.to_array());
            let f = Vec3::from_array(a.forward().to_array());
            (a.id, (p, f))
        })
        .collect()
}

/// Every agent entity's transform, by agent.
fn transforms(app: &mut App) -> HashMap<AgentId, Transform> {
    let mut q = app.world_mut().query::<(&ShoalAgent, &Transform)>();
    q.iter(app.world()).map(|(a, t)| (a.0, *t)).collect()
}

fn assert_near(a: Vec3, b: Vec3, what: &str) {
    assert!((a - b).length() < 1e-4, "{what}: {a} vs {b}");
}

#[test]
fn entities_follow_the_simulation_and_blend_between_ticks() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("drifter.ron");
    std::fs::write(&file, drifter(0.8, "drift")).unwrap();
    let mut app = app(drifters(&file, 6), Duration::from_millis(50));

    // Warm up until one 50-ms frame is exactly one tick (the fixed clock takes the sim's dt).
    for _ in 0..3 {
        app.update();
    }
    let mut before = poses(&app);
    for frame in 0..8 {
        let t0 = tick(&app);
        app.update();
        assert_eq!(
            tick(&app),
            t0 + 1,
            "frame {frame}: one tick per 50-ms frame"
        );
        let now = poses(&app);
        let tr = transforms(&mut app);
        assert_eq!(tr.len(), now.len(), "one entity per agent");
        // The fixed clock is exactly on a tick: the render shows the previous tick's pose.
        for (id, (p, f)) in &before {
            let t = tr[id];
            assert_near(t.translation, *p, "position one tick behind");
            assert_near(*t.forward(), *f, "heading one tick behind");
        }
        before = now;
    }
    // Half a tick more: the transforms are halfway between the last two ticks.
    let last = poses(&app);
    set_frame(&mut app, Duration::from_millis(50));
    app.update();
    let newest = poses(&app);
    set_frame(&mut app, Duration::from_millis(25));
    let t0 = tick(&app);
    app.update();
    assert_eq!(tick(&app), t0, "a 25-ms frame runs no tick");
    let tr = transforms(&mut app);
    for (id, (p0, _)) in &last {
        let (p1, _) = newest[id];
        assert!(p0.distance(p1) > 0.01, "{id:?} moves");
        assert_near(tr[id].translation, p0.lerp(p1, 0.5), "halfway");
    }

    // The motion component carries the sim's velocity.
    let sim_v: HashMap<AgentId, Vec3> = app
        .world()
        .resource::<ShoalSim>()
        .sim()
        .agents()
        .iter()
        .map(|a| (a.id, Vec3::from_array(a.velocity().to_array())))
        .collect();
    let mut q = app.world_mut().query::<(&ShoalAgent, &AgentMotion)>();
    for (a, m) in q.iter(app.world()) {
        assert_near(m.velocity, sim_v[&a.0], "velocity");
    }

    // Despawning an entity removes its agent; an agent the sim removes loses its entity; an
    // agent the app spawns gets one.
    set_frame(&mut app, Duration::from_millis(50));
    let ids: Vec<AgentId> = last.keys().copied().collect();
    let gone_by_entity = ids[0];
    let gone_by_sim = ids[1];
    let e = app
        .world()
        .resource::<AgentEntities>()
        .entity(gone_by_entity);
    app.world_mut().despawn(e.expect("mirrored"));
    {
        let mut sim = app.world_mut().resource_mut::<ShoalSim>();
        assert!(sim.sim_mut().despawn(gone_by_sim));
        sim.sim_mut()
            .spawn("drifter", v(0.0, 5.0, 5.0), 0.0)
            .unwrap();
    }
    app.update();
    let sim = app.world().resource::<ShoalSim>().sim();
    assert!(
        sim.agent(gone_by_entity).is_none(),
        "despawned entity's agent left"
    );
    let alive: Vec<AgentId> = sim.agents().iter().map(|a| a.id).collect();
    let tr = transforms(&mut app);
    let mut mirrored: Vec<AgentId> = tr.keys().copied().collect();
    mirrored.sort();
    assert_eq!(mirrored, alive, "entities are exactly the sim's agents");
    assert!(!tr.contains_key(&gone_by_sim));
}

/// Reload results seen by an app system.
#[derive(Resource, Default)]
struct Seen {
    reloaded: Vec<SpeciesReloaded>,
    failed: Vec<SpeciesReloadFailed>,
}

fn collect(
    mut seen: ResMut<Seen>,
    mut ok: MessageReader<SpeciesReloaded>,
    mut bad: MessageReader<SpeciesReloadFailed>,
) {
    seen.reloaded.extend(ok.read().cloned());
    seen.failed.extend(bad.read().cloned());
}

fn behaviors(app: &mut App) -> Vec<String> {
    let mut q = app.world_mut().query::<&AgentBehavior>();
    q.iter(app.world()).map(|b| b.name.clone()).collect()
}

fn mean_speed(app: &App) -> f32 {
    let sim = app.world().resource::<ShoalSim>().sim();
    sim.agents().iter().map(|a| a.speed).sum::<f32>() / sim.agents().len() as f32
}

#[test]
fn species_files_reload_in_the_running_app() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("drifter.ron");
    std::fs::write(&file, drifter(0.5, "drift")).unwrap();
    let mut app = app(drifters(&file, 4), Duration::from_millis(50));
    app.init_resource::<Seen>().add_systems(Update, collect);
    for _ in 0..40 {
        app.update();
    }
    assert!(behaviors(&mut app).iter().all(|b| b == "drift"));
    let slow = mean_speed(&app);
    assert!((slow - 1.0).abs() < 0.1, "cruising at 0.5 × 2: {slow}");

    // A new version: the behavior renamed and faster. Agents fall back to the new initial
    // behavior and speed up.
    std::fs::write(&file, drifter(0.9, "glide")).unwrap();
    for _ in 0..40 {
        app.update();
    }
    let seen = app.world().resource::<Seen>();
    assert_eq!(seen.reloaded.len(), 1, "one reload");
    assert_eq!(seen.reloaded[0].species, vec!["drifter".to_string()]);
    assert!(seen.failed.is_empty());
    assert!(behaviors(&mut app).iter().all(|b| b == "glide"));
    let fast = mean_speed(&app);
    assert!(fast > 1.6, "cruising at 0.9 × 2 after the reload: {fast}");

    // A bad edit: reported, the last good version keeps running, nothing panics.
    std::fs::write(&file, "(name: \"drifter\", initial: oops").unwrap();
    let t0 = tick(&app);
    for _ in 0..20 {
        app.update();
    }
    assert!(tick(&app) > t0, "the world still runs");
    let seen = app.world().resource::<Seen>();
    assert_eq!(seen.failed.len(), 1, "one failure reported");
    assert!(
        seen.failed[0].error.contains("drifter.ron"),
        "{}",
        seen.failed[0].error
    );
    assert_eq!(seen.reloaded.len(), 1);
    assert!(behaviors(&mut app).iter().all(|b| b == "glide"));
    let sim = app.world().resource::<ShoalSim>().sim();
    assert_eq!(&*sim.species().species[0].behaviors[0].name, "glide");
}

#[test]
fn a_shipped_scenario_runs_as_a_resource() {
    let reef = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/reef.ron");
    let scenario = Scenario::load(&reef).expect("reef loads");
    let run = Run::new(scenario, Overrides::default());
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        ShoalPlugin::default().with_interpolation(false),
    ))
    .insert_resource(ShoalSim::from_run(run))
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_millis(
        50,
    )));
    for _ in 0..4 {
        app.update();
    }
    assert!(tick(&app) >= 3);
    let now = poses(&app);
    let tr = transforms(&mut app);
    assert_eq!(tr.len(), now.len(), "one entity per agent");
    assert!(
        now.len() > 500,
        "the reef's fish, sardines, shark and jellyfish"
    );
    // Without interpolation transforms are the last tick's poses.
    for (id, (p, f)) in &now {
        assert_near(tr[id].translation, *p, "position");
        assert_near(*tr[id].forward(), *f, "heading");
    }
}
