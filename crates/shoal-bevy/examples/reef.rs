//! The shipped reef (`scenarios/reef.ron`) in a window: rocks as meshes, fish as bodies turned
//! by their heading, food, a seabed, sunlight through blue water. The simulation runs in
//! `FixedUpdate` through `ShoalPlugin`; this file only draws.
//!
//! ```text
//! cargo run -p shoal-bevy --example reef --features render [-- SCENARIO] [--screenshot PATH] [--after S]
//! ```
//!
//! `--screenshot PATH` saves a frame once `S` simulated seconds have run (default 4) and exits.
//! Editing a species file of the scenario while it runs reloads that species.

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use shoal_bevy::prelude::*;
use std::collections::HashMap;
use std::path::PathBuf;

/// Command-line options.
#[derive(Resource, Clone, Debug)]
struct Options {
    scenario: PathBuf,
    screenshot: Option<PathBuf>,
    after: f64,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        scenario: PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/reef.ron"),
        screenshot: None,
        after: 4.0,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--screenshot" => o.screenshot = Some(args.next().ok_or("--screenshot PATH")?.into()),
            "--after" => {
                o.after = args
                    .next()
                    .and_then(|s| s.parse().ok())
                    .ok_or("--after SECONDS")?;
            }
            s if !s.starts_with('-') => o.scenario = s.into(),
            s => return Err(format!("unknown option {s}")),
        }
    }
    Ok(o)
}

fn main() -> AppExit {
    let opts = match options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}\nusage: reef [SCENARIO] [--screenshot PATH] [--after SECONDS]");
            return AppExit::error();
        }
    };
    let scenario = match Scenario::load(&opts.scenario) {
        Ok(s) => s,
        Err(d) => {
            eprintln!("{d}");
            return AppExit::error();
        }
    };
    let run = Run::new(scenario, Overrides::default());
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window {
                title: "shoal: reef".into(),
                resolution: (1280u32, 720u32).into(),
                ..default()
            }),
            ..default()
        }))
        .add_plugins(ShoalPlugin::default())
        .insert_resource(ShoalSim::from_run(run))
        .insert_resource(ClearColor(WATER))
        .insert_resource(GlobalAmbientLight {
            color: Color::srgb(0.55, 0.75, 0.9),
            brightness: 350.0,
            ..default()
        })
        .insert_resource(opts)
        .init_resource::<FoodMarkers>()
        .add_systems(Startup, (scene, rocks))
        .add_systems(
            Update,
            (dress_agents, food, hide_removed_rocks, orbit, screenshot),
        )
        .run()
}

/// The water's colour (clear colour and fog).
const WATER: Color = Color::srgb(0.05, 0.22, 0.33);

/// Colours of the shipped species (their files' `color`), others grey.
fn species_color(name: &str) -> Color {
    match name {
        "reef_fish" => Color::srgb_u8(0xf0, 0xa0, 0x30),
        "sardine" => Color::srgb_u8(0xb8, 0xc8, 0xd8),
        "shark" => Color::srgb_u8(0x70, 0x78, 0x88),
        "jellyfish" => Color::srgba_u8(0xe0, 0xa0, 0xe8, 0xb0),
        _ => Color::srgb(0.6, 0.6, 0.6),
    }
}

fn v(p: shoal::prelude::Vec3) -> Vec3 {
    Vec3::from_array(p.to_array())
}

/// Camera with underwater fog, sunlight with shadows, the seabed.
fn scene(
    mut commands: Commands,
    sim: Res<ShoalSim>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let b = sim.sim().world.bounds;
    let (min, max) = (v(b.min), v(b.max));
    let center = (min + max) * 0.5;
    commands.spawn((
        Camera3d::default(),
        Transform::from_xyz(center.x + 10.0, max.y + 18.0, max.z + 38.0)
            .looking_at(Vec3::new(center.x, 4.0, center.z + 4.0), Vec3::Y),
        DistanceFog {
            color: WATER,
            falloff: FogFalloff::Linear {
                start: 35.0,
                end: 150.0,
            },
            ..default()
        },
        Orbit {
            center: Vec3::new(center.x, 4.0, center.z),
        },
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: 9_000.0,
            shadow_maps_enabled: true,
            color: Color::srgb(0.9, 0.97, 1.0),
            ..default()
        },
        Transform::from_xyz(20.0, 60.0, 25.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let size = max - min;
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(size.x * 1.6, size.z * 1.6))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.62, 0.56, 0.42),
            perceptual_roughness: 0.95,
            ..default()
        })),
        Transform::from_xyz(center.x, min.y, center.z),
    ));
}

/// One entity per obstacle of the scenario.
#[derive(Component)]
struct Rock(usize);

fn rocks(
    mut commands: Commands,
    sim: Res<ShoalSim>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let stone = materials.add(StandardMaterial {
        base_color: Color::srgb(0.36, 0.33, 0.30),
        perceptual_roughness: 0.9,
        ..default()
    });
    for (k, o) in sim.sim().world.obstacles.iter().enumerate() {
        let (mesh, at) = match o.shape {
            Shape::Sphere { center, radius } => (
                meshes.add(Sphere::new(radius).mesh().ico(3).expect("ico 3")),
                v(center),
            ),
            Shape::Box(b) => (
                meshes.add(Cuboid::from_corners(v(b.min), v(b.max))),
                (v(b.min) + v(b.max)) * 0.5,
            ),
            Shape::Cylinder {
                base,
                radius,
                height,
            } => (
                meshes.add(Cylinder::new(radius, height)),
                v(base) + Vec3::Y * height * 0.5,
            ),
        };
        commands.spawn((
            Rock(k),
            Mesh3d(mesh),
            MeshMaterial3d(stone.clone()),
            Transform::from_translation(at),
        ));
    }
}

/// A timed event may remove a rock: hide it.
fn hide_removed_rocks(sim: Res<ShoalSim>, mut rocks: Query<(&Rock, &mut Visibility)>) {
    for (r, mut vis) in &mut rocks {
        let active = sim.sim().world.obstacles.get(r.0).is_some_and(|o| o.active);
        let want = if active {
            Visibility::Inherited
        } else {
            Visibility::Hidden
        };
        if *vis != want {
            *vis = want;
        }
    }
}

/// Shared meshes and materials, one body look per species.
#[derive(Default)]
struct Looks {
    body: Option<Handle<Mesh>>,
    tail: Option<Handle<Mesh>>,
    materials: HashMap<String, Handle<StandardMaterial>>,
}

/// New agents get a body: an ellipsoid of the species' size, a tail fin behind it. The plugin
/// moves and turns the entity (its `forward()` is the heading); the scale is ours.
fn dress_agents(
    mut commands: Commands,
    sim: Res<ShoalSim>,
    mut new: Query<(Entity, &ShoalAgent, &AgentSpecies, &mut Transform), Added<ShoalAgent>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut looks: Local<Looks>,
) {
    let body = looks
        .body
        .get_or_insert_with(|| meshes.add(Sphere::new(0.5).mesh().uv(16, 10)))
        .clone();
    let tail = looks
        .tail
        .get_or_insert_with(|| meshes.add(Cone::new(0.35, 0.5)))
        .clone();
    for (e, agent, species, mut transform) in &mut new {
        let Some(a) = sim.sim().agent(agent.0) else {
            continue;
        };
        let material = looks
            .materials
            .entry(species.name.clone())
            .or_insert_with(|| {
                let c = species_color(&species.name);
                materials.add(StandardMaterial {
                    base_color: c,
                    perceptual_roughness: 0.45,
                    alpha_mode: if c.alpha() < 1.0 {
                        AlphaMode::Blend
                    } else {
                        AlphaMode::Opaque
                    },
                    emissive: if species.name == "jellyfish" {
                        LinearRgba::rgb(0.5, 0.2, 0.55)
                    } else {
                        LinearRgba::BLACK
                    },
                    ..default()
                })
            })
            .clone();
        // Size is (width, height, length); the body's length runs along local z.
        let size = v(a.size).max(Vec3::splat(0.05));
        let jelly = species.name == "jellyfish";
        transform.scale = size;
        let mut ec = commands.entity(e);
        ec.insert((
            Mesh3d(body.clone()),
            MeshMaterial3d(material.clone()),
            Visibility::default(),
        ));
        if !jelly {
            // The cone's apex points +y; laid along +z it trails behind (forward is −z).
            ec.with_child((
                Mesh3d(tail.clone()),
                MeshMaterial3d(material),
                Transform::from_xyz(0.0, 0.0, 0.62)
                    .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2))
                    .with_scale(Vec3::new(1.0, 0.6, 0.25)),
            ));
        }
    }
}

/// Food items as small glowing pellets.
#[derive(Resource, Default)]
struct FoodMarkers {
    by_id: HashMap<u32, Entity>,
    mesh: Option<(Handle<Mesh>, Handle<StandardMaterial>)>,
}

fn food(
    mut commands: Commands,
    sim: Res<ShoalSim>,
    mut markers: ResMut<FoodMarkers>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let (mesh, material) = markers
        .mesh
        .get_or_insert_with(|| {
            (
                meshes.add(Sphere::new(0.18).mesh().ico(1).expect("ico 1")),
                materials.add(StandardMaterial {
                    base_color: Color::srgb(0.5, 0.9, 0.4),
                    emissive: LinearRgba::rgb(0.3, 0.8, 0.2),
                    ..default()
                }),
            )
        })
        .clone();
    let world = &sim.sim().world;
    let alive: std::collections::HashSet<u32> = world.food.iter().map(|f| f.id).collect();
    markers.by_id.retain(|id, e| {
        let keep = alive.contains(id);
        if !keep {
            commands.entity(*e).despawn();
        }
        keep
    });
    for f in &world.food {
        if !markers.by_id.contains_key(&f.id) {
            let e = commands
                .spawn((
                    Mesh3d(mesh.clone()),
                    MeshMaterial3d(material.clone()),
                    Transform::from_translation(v(f.pos)),
                ))
                .id();
            markers.by_id.insert(f.id, e);
        }
    }
}

/// The camera circles the reef slowly.
#[derive(Component)]
struct Orbit {
    center: Vec3,
}

fn orbit(time: Res<Time>, mut cams: Query<(&Orbit, &mut Transform)>) {
    for (o, mut t) in &mut cams {
        let r = Quat::from_rotation_y(time.delta_secs() * 0.03);
        t.rotate_around(o.center, r);
    }
}

/// With `--screenshot`, a frame is saved once the simulation has run `--after` seconds, then the
/// app exits.
fn screenshot(
    mut commands: Commands,
    opts: Res<Options>,
    sim: Res<ShoalSim>,
    mut asked: Local<bool>,
) {
    let Some(path) = opts.screenshot.clone() else {
        return;
    };
    if *asked || sim.sim().time() < opts.after {
        return;
    }
    *asked = true;
    commands.spawn(Screenshot::primary_window()).observe(
        move |shot: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                let _ = std::fs::create_dir_all(dir);
            }
            let saved = shot
                .image
                .clone()
                .try_into_dynamic()
                .map_err(|e| e.to_string())
                .and_then(|img| img.to_rgb8().save(&path).map_err(|e| e.to_string()));
            match saved {
                Ok(()) => {
                    println!("saved {}", path.display());
                    exit.write(AppExit::Success);
                }
                Err(e) => {
                    eprintln!("cannot save {}: {e}", path.display());
                    exit.write(AppExit::error());
                }
            }
        },
    );
}
