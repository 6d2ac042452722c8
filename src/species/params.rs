//! The species' own constants outside its behaviors — body, senses, avoidance, attributes,
//! drives — checked at load (seeds 000 §1–§2, 001, 002, 003). The tick loop clamps with several
//! of them, and `clamp` panics on NaN or on `min > max`. Part of validation.

use super::recipes::check_avoid;
use super::validate::Builder;
use super::*;
use crate::load::NumberCheck;

impl Builder<'_> {
    /// The numbers of the species outside its behaviors, each located at its key.
    pub(super) fn species_numbers(&mut self, def: &SpeciesDef) {
        let n = &mut self.nums;
        let draw = |n: &mut NumberCheck, key: &str, d: Draw| match d {
            Draw::Fixed(x) => {
                n.finite(key, x);
            }
            Draw::Uniform(lo, hi) if n.finite(key, lo) & n.finite(key, hi) && lo > hi => {
                n.error(
                    key,
                    format!("`{key}`: `Uniform(lo, hi)` needs lo ≤ hi, not {lo} > {hi}"),
                );
            }
            Draw::Uniform(..) => {}
        };
        n.from = 0;
        n.non_negative("resend_after", def.resend_after);
        // Body.
        n.from = 0;
        n.enter("body");
        let body = n.from;
        let size = def.body.size;
        if !size.to_array().iter().all(|x| x.is_finite() && *x > 0.0) {
            n.error(
                "size",
                format!(
                    "`size` must be three finite numbers > 0 (width, height, length), not {:?}",
                    size.to_array()
                ),
            );
        }
        n.enter("limits");
        let l = &def.body.limits;
        if n.positive("max_speed", l.max_speed) & n.non_negative("min_speed", l.min_speed) {
            n.order("min_speed", l.min_speed, "max_speed", l.max_speed);
        }
        n.positive("max_turn", l.max_turn);
        n.range("max_pitch", l.max_pitch, 0.0, std::f32::consts::FRAC_PI_2);
        n.positive("max_accel", l.max_accel);
        n.non_negative("response", l.response);
        if let Some(r) = l.speed_response {
            n.non_negative("speed_response", r);
        }
        n.non_negative("smoothing", l.smoothing);
        if let crate::params::locomotion::Mode::RigidBody(r) = &def.body.locomotion {
            n.from = body;
            n.enter("RigidBody");
            n.positive("mass", r.mass);
            n.non_negative("max_thrust", r.max_thrust);
            n.non_negative("thrust_gain", r.thrust_gain);
            n.non_negative("drag", r.drag);
            n.non_negative("max_yaw_torque", r.max_yaw_torque);
            n.non_negative("max_pitch_torque", r.max_pitch_torque);
            n.non_negative("turn_gain", r.turn_gain);
            n.non_negative("angular_damping", r.angular_damping);
            n.positive("inertia", r.inertia);
        }
        n.from = body;
        n.enter("anim");
        let a = &def.body.anim;
        n.non_negative("max_bend", a.max_bend);
        n.non_negative("idle_rate", a.idle_rate);
        n.non_negative("beats_per_length", a.beats_per_length);
        n.non_negative("accel_rate", a.accel_rate);
        n.from = body;
        n.enter("mobility");
        let m = &def.body.mobility;
        n.range("max_slope_deg", m.max_slope_deg, 0.0, 90.0);
        n.non_negative("slope_cost", m.slope_cost);
        n.positive("road_factor", m.road_factor);
        n.non_negative("vegetation_factor", m.vegetation_factor);
        n.non_negative("vegetation_blocks_at", m.vegetation_blocks_at);
        n.positive("water_factor", m.water_factor);
        // Senses.
        n.from = 0;
        let senses = n.enter("senses");
        let s = &def.senses;
        let vision = n.non_negative("vision_radius", s.vision_radius);
        let a = s.vision_half_angle;
        if !(a.is_finite() && a > 0.0 && a <= std::f32::consts::PI) {
            n.error(
                "vision_half_angle",
                format!(
                    "`vision_half_angle` must be an angle > 0 and ≤ π (3.1415927: all around) \
                     in radians, not {a}"
                ),
            );
        }
        // Seed 000 §1: smell reaches farther than vision (O_r > v_r); 0 is no smell at all.
        let reach = s.volume.map_or(s.vision_radius, |v| v.max_reach());
        if n.non_negative("smell_radius", s.smell_radius)
            && vision
            && s.smell_radius > 0.0
            && s.smell_radius < reach
        {
            let what = if s.volume.is_some() {
                "the reach of `volume`"
            } else {
                "`vision_radius`"
            };
            n.error(
                "smell_radius",
                format!(
                    "`smell_radius` ({}) must be 0 (no smell) or at least {what} ({reach}): \
                     smell reaches farther than vision",
                    s.smell_radius
                ),
            );
        }
        use crate::perception::Volume;
        match s.volume {
            Some(Volume::Egg {
                ahead,
                behind,
                side,
                up,
            }) => {
                n.enter("Egg");
                n.non_negative("ahead", ahead);
                n.non_negative("behind", behind);
                n.non_negative("side", side);
                n.non_negative("up", up);
            }
            // Seed 002's volume is a closed surface around the body: every axis > 0.
            Some(Volume::Ellipsoid {
                offset,
                length,
                side,
                up,
            }) => {
                n.enter("Ellipsoid");
                let axes = n.positive("length", length);
                n.positive("side", side);
                n.positive("up", up);
                if n.finite("offset", offset) && axes && offset.abs() >= length {
                    n.error(
                        "offset",
                        format!(
                            "`offset` ({offset}) must lie within ±`length` ({length}): the \
                             body must be inside its perception volume"
                        ),
                    );
                }
            }
            Some(Volume::Superquadric {
                ahead,
                behind,
                side,
                up,
                exponent,
            }) => {
                n.enter("Superquadric");
                n.positive("ahead", ahead);
                n.positive("behind", behind);
                n.positive("side", side);
                n.positive("up", up);
                // Below 0.5 the shape thins to spikes along the axes; above 16 it is a box.
                n.range("exponent", exponent, 0.5, 16.0);
            }
            None => {}
        }
        // Seed 001's strength: a fall with distance (power > 0) from a distance > 0.
        n.from = senses;
        n.enter("strength");
        n.positive("power", s.strength.power);
        n.positive("near", s.strength.near);
        // Seed 000 §4.3's sectors: the front half-width within a quarter turn, the rear from there
        // to π.
        n.from = senses;
        n.enter("sectors");
        n.range("front", s.sectors.front, 0.0, std::f32::consts::FRAC_PI_2);
        n.range(
            "rear",
            s.sectors.rear,
            std::f32::consts::FRAC_PI_2,
            std::f32::consts::PI,
        );
        // Avoidance constants.
        n.from = 0;
        n.enter("avoid");
        check_avoid(n, &def.avoid);
        // Attributes and drives.
        n.from = 0;
        n.enter("attributes");
        draw(n, "age", def.attributes.age);
        draw(n, "mass", def.attributes.mass);
        n.from = 0;
        n.enter("drives");
        let drives = n.from;
        let d = &def.drives;
        draw(n, "hunger", d.hunger);
        draw(n, "libido", d.libido);
        draw(n, "since_meal", d.since_meal);
        n.non_negative("meal_size", d.meal_size);
        n.enter("params");
        let q = &d.params;
        for (key, v) in [
            ("p0", q.p0),
            ("p1", q.p1),
            ("d0", q.d0),
            ("rho0", q.rho0),
            ("s_max", q.s_max),
            ("delta", q.delta),
        ] {
            n.non_negative(key, v);
        }
        for (key, v) in [("a_h", q.a_h), ("a_l", q.a_l)] {
            n.finite(key, v);
        }
        // n_a divides the meal in seed 000's hunger, C the exponent of seed 003's; `u` > 0 keeps
        // seed 003's hunger rising with the time since the meal.
        for (key, v) in [("appetite", q.appetite), ("u", q.u), ("c", q.c)] {
            n.positive(key, v);
        }
        n.from = drives;
    }
}
