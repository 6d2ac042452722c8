//! Stage 3 of the tick: drives. Hunger, libido and fear with the formulas of seed 000 §2, the
//! internal-state curve `S(t)` and hunger variant of seed 003. Every constant is a field of
//! [`DriveParams`] with the papers' value as its default.
//!
//! Choices where the papers leave a gap: seed 003 gives `S(t) = S_max·exp(−t²/δ²)` without
//! saying what `t` counts or giving numbers; here `t` is the time since the last meal (a
//! satiety that fades, read as `Drive(State)` and `this.state`), with S_max = 1 and δ = 100 s.
//! Seed 000's stimulus `S_h` has no formula: [`stimulus`] is the nearness `1 − d/O_r`.

use serde::{Deserialize, Serialize};

/// Drive constants (defaults from seed 000 §2 and seed 003).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DriveParams {
    /// Which hunger model to use.
    pub hunger_model: HungerModel,
    /// Digestion rate p0 of `r(x) = 1 − p0·x` (per second of simulated time).
    pub p0: f32,
    /// Appetite n_a (bigger fish, bigger appetite).
    pub appetite: f32,
    /// Weight a_h of the food stimulus S_h.
    pub a_h: f32,
    /// Libido growth p1 of `l(x) = p1·x`.
    pub p1: f32,
    /// Weight a_l of the mate stimulus S_l.
    pub a_l: f32,
    /// Fear distance D0 of `F_i = min(D0/d_i, 1)`.
    pub d0: f32,
    /// Seed 003 hunger variant: u.
    pub u: f32,
    /// Seed 003 hunger variant: ρ0.
    pub rho0: f32,
    /// Seed 003 hunger variant: C.
    pub c: f32,
    /// Seed 003 internal state `S(t) = S_max·exp(−t²/δ²)`: S_max.
    pub s_max: f32,
    /// Seed 003 internal state: δ (s), the time since the last meal at which S has fallen to
    /// S_max/e.
    pub delta: f32,
}

impl Default for DriveParams {
    fn default() -> Self {
        DriveParams {
            hunger_model: HungerModel::Digestion,
            p0: 0.00067,
            appetite: 1.0,
            a_h: 0.0,
            p1: 0.0025,
            a_l: 0.0,
            d0: 200.0,
            u: 1.0,
            rho0: 0.01,
            c: 1.0,
            s_max: 1.0,
            delta: 100.0,
        }
    }
}

/// Hunger formula in use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum HungerModel {
    /// Seed 000: `H = min(1 − n_e·r(Δt_H)/n_a + a_h·S_h, 1)`.
    #[default]
    Digestion,
    /// Seed 003: `H = min(1 − exp(u·(1 − ρ0·Δt_H)/C) + a_h·S_h, 1)`.
    Exponential,
}

/// Stimulus of perceived food or mate (seed 000 §2's `S_h`, `S_l`): the nearness of the nearest
/// one, `1 − d/O_r` with `O_r` the smell radius, in [0, 1]; 0 when none is perceived or the
/// species has no smell. The paper names the stimulus without a formula; this is the one the
/// engine uses.
pub fn stimulus(nearest: f32, smell_radius: f32) -> f32 {
    if nearest.is_finite() && smell_radius > 0.0 {
        (1.0 - nearest / smell_radius).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Digestion `r(x) = 1 − p0·x`, never below 0.
pub fn digestion(x: f32, p0: f32) -> f32 {
    (1.0 - p0 * x).max(0.0)
}

/// Hunger of seed 000: `H(t) = min(1 − n_e·r(Δt_H)/n_a + a_h·S_h, 1)`, clamped to [0, 1].
pub fn hunger(eaten: f32, since_meal: f32, stimulus: f32, p: &DriveParams) -> f32 {
    let h = match p.hunger_model {
        HungerModel::Digestion => {
            1.0 - eaten * digestion(since_meal, p.p0) / p.appetite.max(1e-6) + p.a_h * stimulus
        }
        HungerModel::Exponential => hunger_exponential(since_meal, stimulus, p),
    };
    clamp01(h)
}

/// Hunger variant of seed 003: `H(t) = min(1 − exp(u·(1 − ρ0·Δt_H)/C) + a_h·S_h(t), 1)`.
pub fn hunger_exponential(since_meal: f32, stimulus: f32, p: &DriveParams) -> f32 {
    clamp01(
        1.0 - crate::math::exp(p.u * (1.0 - p.rho0 * since_meal) / p.c.max(1e-6))
            + p.a_h * stimulus,
    )
}

/// Where an agent's meal clock starts so that its hunger is `hunger` (no food stimulus), as
/// `(n_e, Δt_H)`; `since_meal` is the species' starting time since the last meal.
/// - Digestion (seed 000): `n_e = (1 − H)·n_a` with the clock at `since_meal` (at 0, the first
///   tick's `1 − n_e·r(dt)/n_a` is `H` plus a step of digestion).
/// - Exponential (seed 003) ignores `n_e`: the clock itself says the hunger. It starts at the
///   `Δt_H` where `1 − exp(u·(1 − ρ0·Δt_H)/C) = H`, i.e. `Δt_H = (1 − C·ln(1 − H)/u)/ρ0`, plus
///   `since_meal`. `H` is taken below 1 by 1e-6 (1 itself is only reached at infinity); without
///   a solution (`u` or `ρ0` not > 0) the clock starts at `since_meal`.
pub fn meal_clock_for(hunger: f32, since_meal: f32, p: &DriveParams) -> (f32, f32) {
    match p.hunger_model {
        HungerModel::Digestion => ((1.0 - hunger).max(0.0) * p.appetite, since_meal),
        HungerModel::Exponential => {
            let h = if hunger.is_nan() {
                0.0
            } else {
                hunger.clamp(0.0, 1.0 - 1e-6)
            };
            let dt = (1.0 - p.c * crate::math::ln(1.0 - h) / p.u) / p.rho0;
            if p.u > 0.0 && p.rho0 > 0.0 && dt.is_finite() {
                (0.0, dt + since_meal)
            } else {
                (0.0, since_meal)
            }
        }
    }
}

/// Libido of seed 000: `L(t) = min(l(Δt_L)·(1 − H(t)) + a_l·S_l, 1)` with `l(x) = p1·x`.
pub fn libido(since_mating: f32, hunger: f32, stimulus: f32, p: &DriveParams) -> f32 {
    clamp01(p.p1 * since_mating * (1.0 - hunger) + p.a_l * stimulus)
}

/// The time since the last mating Δt_L at which [`libido`] gives `libido` for this hunger (no mate
/// stimulus): `Δt_L = L/(p1·(1 − H))`, 0 when that has no solution. Used to start an agent with a
/// given libido, as its hunger starts from `n_e`.
pub fn since_mating_for(libido: f32, hunger: f32, p: &DriveParams) -> f32 {
    let room = p.p1 * (1.0 - hunger);
    if libido > 0.0 && room > 0.0 && (libido / room).is_finite() {
        libido / room
    } else {
        0.0
    }
}

/// Fear term of one predator: `F_i = min(D0/d_i, 1)` (1 when d_i is 0).
pub fn fear_term(dist: f32, d0: f32) -> f32 {
    if dist <= 0.0 {
        1.0
    } else {
        (d0 / dist).min(1.0)
    }
}

/// Fear of seed 000: `F(t) = min(Σ_i F_i, 1)` over perceived predators.
pub fn fear(distances: impl IntoIterator<Item = f32>, d0: f32) -> f32 {
    clamp01(distances.into_iter().map(|d| fear_term(d, d0)).sum())
}

/// What perception sums of the predators an agent perceives, all of them (not only the percepts
/// it keeps): how many, the nearest one's distance and `Σ 1/d_i`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PredatorSums {
    /// Predators perceived.
    pub count: u32,
    /// Distance to the nearest.
    pub nearest: f32,
    /// `Σ_i 1/d_i` over all of them.
    pub inv_dist_sum: f32,
}

impl PredatorSums {
    /// The sums of these distances.
    pub fn of(distances: impl IntoIterator<Item = f32>) -> PredatorSums {
        let mut s = PredatorSums {
            nearest: f32::INFINITY,
            ..Default::default()
        };
        for d in distances {
            s.count += 1;
            s.nearest = s.nearest.min(d);
            s.inv_dist_sum += 1.0 / d.max(1e-6);
        }
        s
    }

    /// [`fear`] over every predator, from the sums: a predator within `D0` makes one term 1 and
    /// the clamped sum 1; otherwise every term is `D0/d_i`, and their sum `D0·Σ 1/d_i`. The
    /// same value as [`fear`] of the distances, without keeping them.
    pub fn fear(&self, d0: f32) -> f32 {
        if self.count == 0 {
            0.0
        } else if self.nearest <= d0 {
            1.0
        } else {
            clamp01(d0 * self.inv_dist_sum)
        }
    }
}

/// Internal-state curve of seed 003: `S(t) = S_max·exp(−t²/δ²)`.
pub fn internal_state(t: f32, s_max: f32, delta: f32) -> f32 {
    if delta == 0.0 {
        return if t == 0.0 { s_max } else { 0.0 };
    }
    s_max * crate::math::exp(-(t * t) / (delta * delta))
}

fn clamp01(x: f32) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        // `+ 0.0` turns the −0.0 of an empty sum into 0.0, so recordings never print "-0".
        x.clamp(0.0, 1.0) + 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hunger_after_a_meal_rises_with_digestion() {
        let p = DriveParams::default();
        // n_e = 1, n_a = 1, just eaten: H = 1 − 1·1/1 = 0.
        assert_eq!(hunger(1.0, 0.0, 0.0, &p), 0.0);
        // After 1000 s: r = 1 − 0.00067·1000 = 0.33 → H = 0.67.
        assert!((hunger(1.0, 1000.0, 0.0, &p) - 0.67).abs() < 1e-5);
        // Appetite 2 halves the effect of a meal: H = 1 − 1·1/2 = 0.5.
        let big = DriveParams { appetite: 2.0, ..p };
        assert!((hunger(1.0, 0.0, 0.0, &big) - 0.5).abs() < 1e-6);
        // Stimulus a_h·S_h = 0.5·0.4 = 0.2 on top of 0.67, clamped to 1 at most.
        let stim = DriveParams { a_h: 0.5, ..p };
        assert!((hunger(1.0, 1000.0, 0.4, &stim) - 0.87).abs() < 1e-5);
        assert_eq!(hunger(0.0, 0.0, 10.0, &stim), 1.0);
    }

    #[test]
    fn food_stimulus_is_the_nearness_within_smell() {
        // O_r = 15: food at 6 → 1 − 6/15 = 0.6; at 12 → 0.2; at 0 → 1.
        assert!((stimulus(6.0, 15.0) - 0.6).abs() < 1e-6);
        assert!((stimulus(12.0, 15.0) - 0.2).abs() < 1e-6);
        assert_eq!(stimulus(0.0, 15.0), 1.0);
        // At and beyond the smell radius: 0 (never negative).
        assert_eq!(stimulus(15.0, 15.0), 0.0);
        assert_eq!(stimulus(20.0, 15.0), 0.0);
        // None perceived (the summary's nearest is ∞), or no smell.
        assert_eq!(stimulus(f32::INFINITY, 15.0), 0.0);
        assert_eq!(stimulus(3.0, 0.0), 0.0);
        // 0/0 must not leak a NaN; a negative radius is no smell, not 1 − 3/(−15) = 1.2.
        assert_eq!(stimulus(0.0, 0.0), 0.0);
        assert_eq!(stimulus(3.0, -15.0), 0.0);
        // Into hunger: a_h = 0.5, S_h = 1 − 6/15 = 0.6 → 0.67 + 0.3 = 0.97 (seed 000 §2).
        let p = DriveParams {
            a_h: 0.5,
            ..Default::default()
        };
        assert!((hunger(1.0, 1000.0, stimulus(6.0, 15.0), &p) - 0.97).abs() < 1e-5);
    }

    #[test]
    fn libido_grows_with_time_and_falls_with_hunger() {
        let p = DriveParams::default();
        // l(200) = 0.0025·200 = 0.5; (1 − H) with H = 0.2 → 0.4.
        assert!((libido(200.0, 0.2, 0.0, &p) - 0.4).abs() < 1e-6);
        assert_eq!(libido(200.0, 1.0, 0.0, &p), 0.0);
        assert_eq!(libido(1e6, 0.0, 0.0, &p), 1.0);
        // Starting libido 0.4 at H = 0.2 needs Δt_L = 0.4/(0.0025·0.8) = 200 s.
        assert!((since_mating_for(0.4, 0.2, &p) - 200.0).abs() < 1e-3);
        assert_eq!(since_mating_for(0.4, 1.0, &p), 0.0);
        assert_eq!(since_mating_for(0.0, 0.2, &p), 0.0);
    }

    #[test]
    fn fear_sums_clamped_terms() {
        // D0 = 200: predators at 400 and 800 → 0.5 + 0.25 = 0.75.
        assert!((fear([400.0, 800.0], 200.0) - 0.75).abs() < 1e-6);
        // A predator nearer than D0 saturates.
        assert_eq!(fear([100.0], 200.0), 1.0);
        assert_eq!(fear([], 200.0), 0.0);
        assert!(fear([], 200.0).is_sign_positive(), "no -0.0 in recordings");
        assert_eq!(fear([0.0], 200.0), 1.0);
    }

    #[test]
    fn seed_003_curves() {
        // S(t) = 1·exp(−4/4) at t = 2, δ = 2.
        assert!((internal_state(2.0, 1.0, 2.0) - crate::math::exp(-1.0)).abs() < 1e-6);
        // H = 1 − exp(1·(1 − 0.01·100)/1) = 1 − exp(0) = 0.
        let p = DriveParams::default();
        assert!(hunger_exponential(100.0, 0.0, &p).abs() < 1e-6);
        // Δt = 200: 1 − exp(−1) = 0.63212.
        assert!((hunger_exponential(200.0, 0.0, &p) - 0.632_120_6).abs() < 1e-5);
    }

    #[test]
    fn stimuli_add_to_exponential_hunger_and_libido() {
        // Seed 003 hunger at Δt_H = 200 plus a_h·S_h = 0.5·0.4: 1 − exp(−1) + 0.2 = 0.832121.
        let p = DriveParams {
            a_h: 0.5,
            a_l: 0.5,
            ..Default::default()
        };
        assert!((hunger_exponential(200.0, 0.4, &p) - 0.832_120_6).abs() < 1e-5);
        // Libido l(200)·(1 − 0.2) + a_l·S_l = 0.4 + 0.5·0.4 = 0.6.
        assert!((libido(200.0, 0.2, 0.4, &p) - 0.6).abs() < 1e-6);
    }

    #[test]
    fn since_mating_for_refuses_negative_or_infinite_answers() {
        let p = DriveParams::default();
        // L = −0.4 at H = 0.2 would be −0.4/0.002 = −200 s.
        assert_eq!(since_mating_for(-0.4, 0.2, &p), 0.0);
        // H = 1.5 leaves p1·(1 − H) = −0.00125: 0.4/−0.00125 = −320 s.
        assert_eq!(since_mating_for(0.4, 1.5, &p), 0.0);
        // p1 = 1e-39: L = 1 would take 1/1e-39 = 1e39 s, beyond f32::MAX (3.4e38).
        let slow = DriveParams { p1: 1e-39, ..p };
        assert_eq!(since_mating_for(1.0, 0.0, &slow), 0.0);
    }

    #[test]
    fn fear_saturates_at_zero_and_at_d0() {
        // −0.0 is a zero distance too, not 200/−0.0 = −∞.
        assert_eq!(fear_term(-0.0, 200.0), 1.0);
        assert_eq!(fear([-0.0], 200.0), 1.0);
        // A predator at exactly D0 = 41: F = 41/41 = 1, though 41·(1/41) rounds to 0.99999994.
        assert_eq!(fear([41.0], 41.0), 1.0);
        assert_eq!(PredatorSums::of([41.0]).fear(41.0), 1.0);
    }

    #[test]
    fn internal_state_is_gaussian_in_t() {
        // S_max = 2, δ = 4, t = 3: 2·exp(−9/16) = 1.139566.
        assert!((internal_state(3.0, 2.0, 4.0) - 1.139_565_6).abs() < 1e-5);
        // δ = 0: S_max at t = 0 only.
        assert_eq!(internal_state(0.0, 2.0, 0.0), 2.0);
        assert_eq!(internal_state(3.0, 2.0, 0.0), 0.0);
    }

    proptest! {
        #[test]
        fn drives_stay_in_unit_interval(a in -1e6f32..1e6, b in -1e6f32..1e6, c in -1e6f32..1e6) {
            let p = DriveParams::default();
            for v in [hunger(a, b, c, &p), hunger_exponential(b, c, &p), libido(a, b, c, &p), fear([a.abs(), b.abs()], 200.0)] {
                prop_assert!((0.0..=1.0).contains(&v), "{v}");
            }
        }
    }
}

/// What drives read from perception this tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stimuli {
    /// Food stimulus S_h ∈ [0, 1] (nearness of the nearest food).
    pub food: f32,
    /// Mate stimulus S_l ∈ [0, 1].
    pub mate: f32,
}

/// Stage 3 for one agent: advances the clocks by `dt` and recomputes hunger, libido and fear from
/// the formulas (seed 000 §2). `predators` sums every perceived predator.
pub fn update(
    d: &mut crate::world::Drives,
    p: &DriveParams,
    stimuli: Stimuli,
    predators: &PredatorSums,
    dt: f32,
) {
    d.since_meal += dt;
    d.since_mating += dt;
    d.hunger = hunger(d.eaten, d.since_meal, stimuli.food, p);
    d.libido = libido(d.since_mating, d.hunger, stimuli.mate, p);
    d.fear = predators.fear(p.d0);
    d.state = internal_state(d.since_meal, p.s_max, p.delta);
}

#[cfg(test)]
mod update_tests {
    use super::*;

    #[test]
    fn update_advances_clocks_and_applies_formulas() {
        let p = DriveParams::default();
        let mut d = crate::world::Drives {
            eaten: 1.0,
            since_meal: 999.0,
            since_mating: 199.0,
            ..Default::default()
        };
        update(
            &mut d,
            &p,
            Stimuli::default(),
            &PredatorSums::of([400.0]),
            1.0,
        );
        assert_eq!(d.since_meal, 1000.0);
        assert!((d.hunger - 0.67).abs() < 1e-5);
        // l(200)·(1 − 0.67) = 0.5·0.33.
        assert!((d.libido - 0.165).abs() < 1e-5);
        assert!((d.fear - 0.5).abs() < 1e-6);
    }

    #[test]
    fn the_first_tick_keeps_the_starting_hunger_in_both_models() {
        let dt = 0.05;
        for model in [HungerModel::Digestion, HungerModel::Exponential] {
            let p = DriveParams {
                hunger_model: model,
                ..Default::default()
            };
            let (eaten, since_meal) = meal_clock_for(0.5, 0.0, &p);
            let mut d = crate::world::Drives {
                hunger: 0.5,
                eaten,
                since_meal,
                ..Default::default()
            };
            update(&mut d, &p, Stimuli::default(), &PredatorSums::of([]), dt);
            // Digestion: 1 − 0.5·(1 − 0.00067·0.05) = 0.50001675.
            // Exponential: Δt_H = (1 − ln 0.5)/0.01 = 169.3147 s; one tick later
            // 1 − exp(1 − 0.01·169.3647) = 1 − 0.5·exp(−0.0005) = 0.50025.
            let want = match model {
                HungerModel::Digestion => 0.500_016_75,
                HungerModel::Exponential => 0.500_249_9,
            };
            assert!((d.hunger - want).abs() < 2e-6, "{model:?}: {}", d.hunger);
        }
        let exp = DriveParams {
            hunger_model: HungerModel::Exponential,
            ..Default::default()
        };
        // Δt_H = (1 − 1·ln(1 − 0.5)/1)/0.01 = 169.3147, plus a starting since_meal of 10.
        let (e, t) = meal_clock_for(0.5, 10.0, &exp);
        assert_eq!(e, 0.0);
        assert!((t - 179.314_7).abs() < 1e-3, "{t}");
        // u = 2, C = 4, ρ0 = 0.02, H = 0.75: (1 − 4·ln 0.25/2)/0.02 = (1 + 2.7726)/0.02 = 188.63.
        let q = DriveParams {
            u: 2.0,
            c: 4.0,
            rho0: 0.02,
            ..exp
        };
        let (_, t) = meal_clock_for(0.75, 0.0, &q);
        assert!((t - 188.629_4).abs() < 1e-2, "{t}");
        assert!((hunger(0.0, t, 0.0, &q) - 0.75).abs() < 1e-5);
        // H = 1 is reached only at infinity: a finite clock whose hunger rounds to 1.
        let (_, t) = meal_clock_for(1.0, 0.0, &exp);
        assert!(t.is_finite() && hunger(0.0, t, 0.0, &exp) > 0.999_99);
        // Digestion: n_e = (1 − 0.5)·n_a = 0.5·2, clock left where the species starts it.
        let dig = DriveParams {
            appetite: 2.0,
            ..Default::default()
        };
        assert_eq!(meal_clock_for(0.5, 7.0, &dig), (1.0, 7.0));
        assert_eq!(meal_clock_for(1.5, 0.0, &dig), (0.0, 0.0));
        // No solution without a positive u: the clock starts at since_meal.
        let flat = DriveParams { u: 0.0, ..exp };
        assert_eq!(meal_clock_for(0.5, 3.0, &flat), (0.0, 3.0));
        // u < 0 gives a finite but meaningless (1 + ln 0.5)/0.01 = 30.7 s: refused too.
        let falling = DriveParams { u: -1.0, ..exp };
        assert_eq!(meal_clock_for(0.5, 3.0, &falling), (0.0, 3.0));
    }

    #[test]
    fn fear_from_the_sums_is_fear_of_the_distances() {
        // Three predators in a crowd, none within D0 = 6: 6/18 + 6/20 + 6/19 = 0.9491.
        let far = [18.0, 20.0, 19.0];
        let s = PredatorSums::of(far);
        assert!((s.fear(6.0) - 0.949_122_8).abs() < 1e-5, "{}", s.fear(6.0));
        assert!((s.fear(6.0) - fear(far, 6.0)).abs() < 1e-6);
        // One within D0: 1. None: 0.
        assert_eq!(PredatorSums::of([5.0, 30.0]).fear(6.0), 1.0);
        assert_eq!(PredatorSums::of([]).fear(6.0), 0.0);
        for ds in [[7.0, 40.0, 90.0], [6.5, 6.5, 6.5], [100.0, 200.0, 300.0]] {
            let a = PredatorSums::of(ds).fear(6.0);
            assert!((a - fear(ds, 6.0)).abs() < 1e-6, "{ds:?}: {a}");
        }
    }
}
