//! Stages 3–6 of the tick, the agent pass: per agent, in parallel (rayon), drives (seeds 000 §2,
//! 003), decision (scripts at the decision rate, then arbitration, seed 000 §3), steering (seed
//! 000 §4, the focuser of §1) and locomotion with animation (seeds 001, 002). Each agent's pass
//! reads its own record and perception's copy of the others from the start of the tick, then
//! rewrites only its own record and its [`Outcome`] slot; what reaches beyond the agent is
//! applied in agent order by stage 7 (`events/apply.rs`), so results do not depend on the
//! thread count. An agent of a species with one behavior and nothing to decide (a boid) takes
//! a shorter pass with the same result ([`pass_lone`]: no arbitration, its mind left in its
//! record).

use super::explain::{self, Explain};
use super::Pipeline;
use crate::decision::{self, focus, scripts, Ctx, Transitions};
use crate::diag::Diagnostic;
use crate::drives::{self, Stimuli};
use crate::locomotion::{self, anim, Motion};
use crate::perception::{
    Category, GroupQueries, Percept, PerceptBuf, Perception, Reads, Source, Summary, SummaryBuf,
};
use crate::script::AgentView;
use crate::species::{ActionNode, Contact, Species, SpeciesSet};
use crate::steering::recipe::{self, Scratch};
use crate::steering::Steer;
use crate::world::{Agent, ForwardCache, Mind, Spot, World};
use crate::world::{Payload, Signal};
use glam::Vec3;
use rayon::prelude::*;
use rhai::{Dynamic, ImmutableString, Scope};

/// An empty mind: what an agent's record holds while its pass has its mind.
impl Default for Mind {
    fn default() -> Self {
        Mind::new(0, 0)
    }
}

/// One worker thread's reusable buffers for stages 3–6.
pub(super) struct Worker {
    scope: Scope<'static>,
    scratch: Scratch,
    /// The script view, refilled in place for each call.
    view: Dynamic,
    /// The agent's summaries, when its row holds some categories only.
    summaries: SummaryBuf,
    /// The agent's percepts.
    percepts: PerceptBuf,
    /// Locomotion's response factors of the last agent's body (the next is most often alike).
    gains: Option<locomotion::Gains>,
}

impl Default for Worker {
    fn default() -> Self {
        Worker {
            scope: Scope::new(),
            scratch: Scratch::default(),
            view: Dynamic::from(AgentView::default()),
            summaries: SummaryBuf::default(),
            percepts: PerceptBuf::default(),
            gains: None,
        }
    }
}

/// What one agent's pass produced beyond its own record (applied in agent order by stage 7).
#[derive(Debug, Default)]
pub(crate) struct Outcome {
    /// Species and behavior after the tick (for the counters, read without touching the agent).
    pub(crate) species: u16,
    pub(crate) behavior: u16,
    /// Transitions, messages, contacts, errors and explanations: a few agents a tick have any,
    /// so they are boxed and the per-agent buffer stays small (16 bytes).
    pub(crate) rare: Option<Box<Rare>>,
}

/// The parts of an outcome most agents do not have in a given tick: most that have one have a
/// transition and nothing else (a whole school's first transitions, say), so the rest is boxed
/// again (56 bytes an agent then, not 136).
#[derive(Debug, Default)]
pub(crate) struct Rare {
    pub(crate) transitions: Transitions,
    pub(crate) more: Option<Box<More>>,
}

/// What an outcome rarely has even beside a transition.
#[derive(Debug, Default)]
pub(crate) struct More {
    /// Contact intent (a meal, a catch, a mating), resolved in agent order by stage 7.
    pub(crate) contact: Option<(Contact, Source)>,
    pub(crate) messages: [Option<(Signal, f32)>; 4],
    /// Payloads of the declared events among `messages`, by slot.
    pub(crate) payloads: Vec<(usize, Payload)>,
    /// Boxed: most outcomes that have a rare part have a transition, not an error (a whole
    /// school's first transitions would otherwise hold room for a diagnostic each).
    pub(crate) error: Option<Box<Diagnostic>>,
    /// What this pass explains, when asked ([`super::explain`]).
    pub(crate) explain: Option<Box<explain::Explained>>,
}

/// What every agent's pass reads of the tick besides its own record: the same for all agents.
#[derive(Clone, Copy)]
struct Inputs<'a> {
    /// The world at the start of the tick, without its agents (their records are out of it for
    /// the pass: what an agent reads of another is perception's copy).
    world: &'a World,
    set: &'a SpeciesSet,
    perception: &'a Perception,
    /// Script-visible names of the species and, by species, of their behaviors.
    species_names: &'a [ImmutableString],
    behavior_names: &'a [Vec<ImmutableString>],
    /// Targets of planned paths, by agent index.
    plan_targets: &'a [Option<Vec3>],
    /// Per species: what its behaviors read of perception.
    reads: &'a [Reads],
    /// Every agent's own best food position at the start of the tick, by agent index.
    known_food: &'a [Spot],
    scripts_every_tick: bool,
    /// What this tick explains, and agent ids by index (for percept sources).
    explain: Explain,
    ids: &'a [u32],
}

/// What one agent's stages read besides its own record, looked up once per pass: a [`Ctx`]
/// without the agent, whose record the pass rewrites between stages.
#[derive(Clone, Copy)]
struct Seen<'a> {
    world: &'a World,
    perception: &'a Perception,
    species: &'a Species,
    percepts: &'a [Percept],
    summaries: &'a [Summary; Category::COUNT],
    group_queries: &'a GroupQueries,
    group_sums: &'a [u32],
    tick: u64,
    dt: f32,
}

impl<'a> Seen<'a> {
    /// The context of a stage: this and the agent's record as it stands now.
    fn ctx<'b>(&self, agent: &'b Agent) -> Ctx<'b>
    where
        'a: 'b,
    {
        Ctx {
            world: self.world,
            perception: self.perception,
            species: self.species,
            agent,
            percepts: self.percepts,
            summaries: self.summaries,
            group_queries: self.group_queries,
            group_sums: self.group_sums,
            tick: self.tick,
            dt: self.dt,
        }
    }
}

impl Pipeline {
    /// Stages 3–6 for every agent, in parallel. Each agent's pass reads and then rewrites its
    /// own record; the records are out of the world meanwhile, and what an agent reads of
    /// another is perception's copy from the start of the tick.
    pub(super) fn agent_pass(&mut self, world: &mut World) {
        let n = world.agents.len();
        let set = self.species.clone();
        self.outcomes.resize_with(n, Outcome::default);
        self.known_food.clear();
        // In a world where nobody knows food (boids, flocks) there is no list at all: every
        // lookup in it is `None` either way. Both walks read every record: in parallel, as
        // the pass itself (one thread alone took 0.18 ms a tick of a 10k reef's 4.4).
        let knows = |a: &Agent| a.mind.best_food().is_some();
        let min = crate::par::min_len(1024);
        if world.agents.par_iter().with_min_len(min).any(knows) {
            self.known_food.resize(n, Spot::NONE);
            self.known_food
                .par_iter_mut()
                .zip(world.agents.par_iter())
                .with_min_len(min)
                .for_each(|(k, a)| *k = Spot::new(a.mind.best_food()));
        }
        self.explain_ids.clear();
        if self.explain.on() {
            self.explain_ids.extend(world.agents.iter().map(|a| a.id.0));
        }
        let mut agents = std::mem::take(&mut world.agents);
        let threads = rayon::current_num_threads();
        if self.workers.len() < threads {
            self.workers.resize_with(threads, Default::default);
        }
        let inputs = Inputs {
            world,
            set: &set,
            perception: &self.perception,
            species_names: &self.species_names,
            behavior_names: &self.behavior_names,
            plan_targets: &self.plan_targets,
            reads: &self.reads,
            known_food: &self.known_food,
            scripts_every_tick: self.scripts_every_tick,
            explain: self.explain,
            ids: &self.explain_ids,
        };
        let outcomes = &mut self.outcomes;
        let workers = &self.workers;
        let clock = &self.script_clock;
        clock.reset();
        // A panic in the pass (a bug) still gives the world its agents back before it unwinds.
        let pass = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            agents
                .par_iter_mut()
                .zip(outcomes.par_iter_mut())
                .enumerate()
                .with_min_len(crate::par::min_len(32))
                .for_each_init(
                    || {
                        crate::script::budget::install(clock);
                        // This thread's buffers, kept from tick to tick (a one-thread tick
                        // called from outside any pool takes the first set); a fresh set only if
                        // they are somehow in use.
                        let own = rayon::current_thread_index()
                            .or_else(|| crate::par::is_alone().then_some(0))
                            .and_then(|t| workers.get(t))
                            .and_then(|w| w.try_lock().ok());
                        let fresh = own.is_none().then(Worker::default);
                        (own, fresh)
                    },
                    |(own, fresh), (i, (agent, out))| {
                        let w = match (own.as_deref_mut(), fresh.as_mut()) {
                            (Some(w), _) => w,
                            (None, Some(w)) => w,
                            (None, None) => unreachable!("one of the two is set"),
                        };
                        pass_one(&inputs, i, agent, out, w);
                    },
                );
        }));
        world.agents = agents;
        if let Err(panic) = pass {
            std::panic::resume_unwind(panic);
        }
    }
}

/// Seed 003's foraging memory, particle-swarm style. The own best food position is where the
/// agent last perceived food (the nearest item or prey), forgotten once the place is within
/// its vision radius and no food is perceived (eaten or gone). The school's best is the own
/// best of a perceived kin nearest to it (their values from the start of the tick); none when
/// no perceived kin knows food, so a school without food has no foraging target.
#[inline(always)]
fn remember_food(
    mind: &mut Mind,
    pos: Vec3,
    percepts: &[Percept],
    vision_radius: f32,
    known_food: &[Spot],
) {
    let food = percepts
        .iter()
        .filter(|p| p.category() == Category::Food)
        .min_by(|a, b| a.dist.total_cmp(&b.dist));
    match food {
        Some(f) => mind.set_best_food(Some(pos + f.offset)),
        None => {
            if mind
                .best_food()
                .is_some_and(|b| b.distance_squared(pos) <= vision_radius * vision_radius)
            {
                mind.set_best_food(None);
            }
        }
    }
    mind.set_school_best(
        percepts
            .iter()
            .filter(|p| p.category() == Category::Kin)
            .filter_map(|p| match p.source() {
                Source::Agent(j) => known_food.get(j as usize).and_then(|s| s.get()),
                _ => None,
            })
            .min_by(|a, b| a.distance_squared(pos).total_cmp(&b.distance_squared(pos))),
    );
}

/// Stages 3–6 for agent `i` (drives, decide, steer, move): `agent` is its record, `out` its
/// outcome slot, `w` this thread's buffers.
fn pass_one(inp: &Inputs, i: usize, agent: &mut Agent, out: &mut Outcome, w: &mut Worker) {
    let Inputs {
        world,
        set,
        perception,
        species_names,
        behavior_names,
        plan_targets,
        reads,
        known_food,
        scripts_every_tick,
        explain,
        ids,
    } = *inp;
    let Worker {
        scope,
        scratch,
        view,
        summaries: summary_buf,
        percepts: percept_buf,
        gains,
    } = w;
    scratch.reset();
    scratch.set_velocity(perception.velocity(i));
    scratch.plan_target = plan_targets.get(i).copied().flatten();
    // The random stream is the pass's own copy, written back at the end.
    let mut rng = agent.rng;
    let rng = &mut rng;
    let s = agent.species.0 as usize;
    let group_queries = reads.get(s).map_or(&GroupQueries::EMPTY, |r| &r.groups);
    let sp = &set.species[s];
    let percepts = perception.percepts_in(i, percept_buf);
    let summaries = perception.summaries_in(i, summary_buf);
    let group_sums = perception.group_words(i);
    let dt = world.dt;
    let tick = world.tick;
    // What every stage reads besides the agent's record, looked up once; each stage's `Ctx`
    // adds the record as it stands then (the stages before it rewrite it).
    let seen = Seen {
        world,
        perception,
        species: sp,
        percepts,
        summaries,
        group_queries,
        group_sums,
        tick,
        dt,
    };

    // 3. Drives, in the agent's own record (what others read of it is perception's copy from
    // the start of the tick).
    let me = agent;
    update_drives(me, sp, summaries, dt);
    if lone(sp) && !explain.on() {
        pass_lone(&seen, i, me, out, rng, scratch, known_food, gains);
        return;
    }
    // The mind is out of the record until the end of the pass (the record is read through
    // `Ctx` meanwhile).
    let mut mind = std::mem::take(&mut me.mind);
    let mind = &mut mind;
    remember_food(mind, me.pos, percepts, sp.senses.vision_radius, known_food);
    let mut error = None;
    let mut messages: [Option<(Signal, f32)>; 4] = [None; 4];
    let mut payloads: Vec<(usize, Payload)> = Vec::new();

    // 4. Decision: scripts at the decision rate, then arbitration.
    let script = sp
        .script
        .as_deref()
        .filter(|_| !sp.slots.is_empty() || sp.has_on_tick);
    if let Some(script) = script {
        // Right after a contact (a meal, a mating) the script's last answers predate what just
        // happened (its `on_event` may have changed the blackboard): its conditions are asked
        // again now, so the behavior that ends on the contact hands over to the right next one
        // at once instead of to a stale choice that the next scheduled call overturns a few
        // ticks later.
        let due = scripts_every_tick || scripts::due(tick, me.id.0, sp.decision_interval);
        if due || mind.reached {
            let ctx = seen.ctx(me);
            // The worker's view is refilled in place (no allocation per call). The blackboard
            // is copied in and back out, not moved: a script that replaces `this` leaves the
            // agent's own blackboard as it was.
            if !view.is::<AgentView>() {
                *view = Dynamic::from(AgentView::default());
            }
            if let Some(mut v) = view.write_lock::<AgentView>() {
                let behavior = &behavior_names[s][mind.current as usize];
                scripts::fill_for_slots(&mut v, &ctx, mind, &species_names[s], behavior);
                v.rng = *rng;
            }
            let r = if due {
                scripts::run_slots(sp, script, mind, view, scope)
            } else {
                scripts::run_conditions(sp, script, mind, view, scope)
            };
            // Natively evaluated slots write nothing: there is nothing to copy back.
            let back = if sp.scripts_native {
                None
            } else {
                view.write_lock::<AgentView>()
            };
            if let Some(mut v) = back {
                scripts::write_back(&v, me);
                *rng = v.rng;
                for (k, (m, r, p)) in v.outbox.drain(..).take(2).enumerate() {
                    messages[2 + k] = Some((m, r));
                    if let Some(p) = p {
                        payloads.push((2 + k, p));
                    }
                }
            }
            if let Err(e) = r {
                error = Some(e);
            }
        }
    }
    let ctx = seen.ctx(me);
    // Explaining reads copies only: the run is the same with it on or off.
    let explaining = explain.covers(me.id.0);
    let before = explaining.then(|| explain::Before::of(mind, rng));
    let transitions = decision::arbitrate(&ctx, mind, rng);
    let explained_decision = before
        .as_ref()
        .and_then(|b| explain::decision(&ctx, mind, b, &transitions, me.id.0));
    let mut pending = None;
    if let Some(t) = transitions.iter().flatten().last() {
        let b = &sp.behaviors[t.to as usize];
        let mut k = 0;
        for a in &b.on_enter {
            match a {
                ActionNode::Send(signal, r) if k < 2 => {
                    let quiet = match *signal {
                        Signal::Kind(kind) => &mut mind.rare_mut().quiet_until[kind as usize],
                        Signal::Event(e) => {
                            let q = &mut mind.rare_mut().quiet_events;
                            if q.len() <= e as usize {
                                q.resize(sp.events.len().max(e as usize + 1), 0);
                            }
                            &mut q[e as usize]
                        }
                    };
                    if tick >= *quiet {
                        *quiet = tick.saturating_add((sp.resend_after.max(0.0) / dt).ceil() as u64);
                        messages[k] = Some((*signal, *r));
                        k += 1;
                    }
                }
                ActionNode::Call(f) => {
                    if let Some(script) = sp.script.as_deref() {
                        let mut view = scripts::view_of(
                            &ctx,
                            mind,
                            &species_names[s],
                            &behavior_names[s][mind.current as usize],
                        );
                        // The stream as arbitration left it (the record's is the tick's start).
                        view.rng = *rng;
                        let mut this = Dynamic::from(view);
                        match script.call::<Dynamic>(scope, &mut this, f) {
                            Ok(_) => pending = this.try_cast::<crate::script::AgentView>(),
                            Err(e) => error = Some(*e.diagnostic),
                        }
                    }
                }
                ActionNode::MarkStation => mind.rare_mut().station = Spot::new(Some(me.pos)),
                _ => {}
            }
        }
    }
    // The record changes only where an entered behavior's call wrote back.
    let ctx = match pending {
        Some(v) => {
            scripts::write_back(&v, me);
            *rng = v.rng;
            seen.ctx(me)
        }
        None => ctx,
    };

    // 5. Steering.
    let b = &sp.behaviors[mind.current as usize];
    let steer_rng = *rng;
    let mut steer = match b.focus {
        None => recipe::evaluate(&b.steer, &ctx, mind, rng, scratch, 0),
        // Seed 000 §1's focuser: the steering of the current intention sees only what it
        // cares about (the group sums are kin's).
        Some(f) => {
            let mut kept = std::mem::take(&mut scratch.focused);
            let summaries = focus::narrow(f, percepts, summaries, &mut kept);
            let focused = Ctx {
                percepts: &kept,
                summaries: &summaries,
                group_sums: if f.contains(Category::Kin) {
                    group_sums
                } else {
                    &[]
                },
                ..ctx
            };
            let s = recipe::evaluate(&b.steer, &focused, mind, rng, scratch, 0);
            scratch.focused = kept;
            s
        }
    };
    steer = settled(steer, error.is_some(), &mind.last_steer, &ctx);
    mind.last_steer = steer;
    let explained_frame = explain.frame(tick, me.id.0).then(|| {
        let st = explain::Steering {
            rng: steer_rng,
            velocity: perception.velocity(i),
            plan_target: plan_targets.get(i).copied().flatten(),
            steer,
            ids,
        };
        explain::frame(&ctx, mind, b, &st)
    });
    let explained = (explained_decision.is_some() || explained_frame.is_some()).then(|| {
        Box::new(explain::Explained {
            decision: explained_decision,
            frame: explained_frame,
        })
    });

    // 6. Locomotion and animation.
    let moved = move_body(&seen, i, me, steer, b.response, gains);
    // Contact intent (resolved in agent order by stage 7).
    let contact = match b.contact {
        Some(c @ Contact::Eat { reach }) => ctx
            .nearest(Category::Food)
            .filter(|p| p.dist <= reach)
            .map(|p| (c, p.source())),
        Some(c @ Contact::Mate { reach }) => ctx
            .nearest(Category::Mate)
            .filter(|p| p.dist <= reach)
            .map(|p| (c, p.source())),
        None => None,
    };
    // A payload goes with a message.
    let more = messages.iter().any(Option::is_some)
        || error.is_some()
        || contact.is_some()
        || explained.is_some();
    let rare = more || transitions.iter().any(Option::is_some);
    out.rare = rare.then(|| {
        Box::new(Rare {
            transitions,
            more: more.then(|| {
                Box::new(More {
                    contact,
                    messages,
                    payloads,
                    error: error.map(Box::new),
                    explain: explained,
                })
            }),
        })
    });
    out.species = me.species.0;
    out.behavior = mind.current;

    // The agent's new state, in its own record.
    moved.write(me, world);
    // Swapped, not taken: the placeholder goes out with this pass, and no second empty mind
    // is made.
    std::mem::swap(&mut me.mind, mind);
    me.rng = *rng;
}

/// Drives (stage 3), in the agent's own record: seed 000 §2's when the species' are native,
/// else only the times since the last meal and mating and seed 003's internal state.
#[inline(always)]
fn update_drives(me: &mut Agent, sp: &Species, summaries: &[Summary; Category::COUNT], dt: f32) {
    if sp.drives.native {
        let stim = |c: Category| {
            drives::stimulus(summaries[c as usize].nearest_dist, sp.senses.smell_radius)
        };
        let stimuli = Stimuli {
            food: stim(Category::Food),
            mate: stim(Category::Mate),
        };
        // Every predator perceived, not only the kept percepts.
        let sm = &summaries[Category::Predator as usize];
        let predators = drives::PredatorSums {
            count: sm.count,
            nearest: sm.nearest_dist,
            inv_dist_sum: sm.inv_dist_sum,
        };
        drives::update(&mut me.drives, &sp.drives.params, stimuli, &predators, dt);
    } else {
        me.drives.since_meal += dt;
        me.drives.since_mating += dt;
        let q = &sp.drives.params;
        me.drives.state = drives::internal_state(me.drives.since_meal, q.s_max, q.delta);
    }
}

/// Whether every agent of `sp` has one behavior, always the current one, and nothing to decide:
/// no script slot or `on_tick`, one behavior that never ends (arbitration then leaves it as it
/// is, [`decision::arbitrate`]), no focus and no contact (a boid, a plain flocker). Its pass
/// skips the decision stage's machinery ([`pass_lone`]).
#[inline(always)]
pub(super) fn lone(sp: &Species) -> bool {
    let scripted = sp.script.is_some() && (!sp.slots.is_empty() || sp.has_on_tick);
    match &sp.behaviors[..] {
        [only] => {
            !scripted
                && sp.depth == 0
                && matches!(only.done, crate::species::CondNode::Never)
                && only.focus.is_none()
                && only.contact.is_none()
        }
        _ => false,
    }
}

/// Stages 4–6 for an agent of a [`lone`] species, drives done, when nothing is explained: what
/// [`pass_one`] does for it, without taking its mind out of the record. Arbitration would only
/// set the current behavior to the one there is; no transition, message, contact or error
/// comes of it.
#[allow(clippy::too_many_arguments)]
fn pass_lone(
    seen: &Seen,
    i: usize,
    me: &mut Agent,
    out: &mut Outcome,
    rng: &mut crate::world::Rng,
    scratch: &mut Scratch,
    known_food: &[Spot],
    gains: &mut Option<locomotion::Gains>,
) {
    let sp = seen.species;
    remember_food(
        &mut me.mind,
        me.pos,
        seen.percepts,
        sp.senses.vision_radius,
        known_food,
    );
    me.mind.current = 0;
    let b = &sp.behaviors[0];
    let ctx = seen.ctx(me);
    let steer = recipe::evaluate(&b.steer, &ctx, &me.mind, rng, scratch, 0);
    let steer = settled(steer, false, &me.mind.last_steer, &ctx);
    let moved = move_body(seen, i, me, steer, b.response, gains);
    out.rare = None;
    out.species = me.species.0;
    out.behavior = 0;
    me.mind.last_steer = steer;
    moved.write(me, seen.world);
    me.rng = *rng;
}

/// The steering stage 6 takes: `steer`, or the last tick's (`last`) where this tick's failed (a
/// script error, `failed`, or a value that is not finite), or keeping on as the agent goes
/// where it has none. Shared by both passes.
#[inline(always)]
fn settled(mut steer: Steer, failed: bool, last: &Steer, ctx: &Ctx) -> Steer {
    if failed || !steer.is_finite() {
        steer = *last;
    }
    if steer.is_none() {
        steer = Steer::keep(&ctx.kin());
    }
    steer
}

/// What stage 6 made of an agent's body this tick, written into its record by [`Moved::write`].
struct Moved {
    motion: Motion,
    forward: Vec3,
    anim: crate::world::Anim,
}

impl Moved {
    /// The agent's new position, heading, speeds, forward vector and animation, in its record.
    #[inline(always)]
    fn write(&self, a: &mut Agent, world: &World) {
        let m = &self.motion;
        a.prev_pos = a.pos;
        a.pos = world.bounds.closest_point(m.pos);
        a.yaw = m.yaw;
        a.pitch = m.pitch;
        a.speed = m.speed;
        a.yaw_rate = m.yaw_rate;
        a.pitch_rate = m.pitch_rate;
        a.forward_cache = ForwardCache::new(a.yaw, a.pitch, self.forward);
        a.anim = self.anim;
    }
}

/// Stage 6 for agent `i` under `steer`: locomotion (turning as fast as the behavior's
/// `response` says, else as the body does), solid bodies and animation, from its record as it
/// stands.
// Inlined, as are the other helpers of the two passes: out of line they cost a boid or a reef
// fish about 70 instructions a tick (the calls, and the compiler's other inlining choices).
#[inline(always)]
fn move_body(
    seen: &Seen,
    i: usize,
    me: &Agent,
    steer: Steer,
    response: Option<f32>,
    gains: &mut Option<locomotion::Gains>,
) -> Moved {
    let (sp, world, dt) = (seen.species, seen.world, seen.dt);
    let mut motion = Motion {
        pos: me.pos,
        yaw: me.yaw,
        pitch: me.pitch,
        speed: me.speed,
        yaw_rate: me.yaw_rate,
        pitch_rate: me.pitch_rate,
    };
    // A behavior may turn faster or slower than the body does by default.
    let body = &sp.body.limits;
    let limits = &match response {
        Some(response) => locomotion::BodyLimits { response, ..*body },
        None => *body,
    };
    let info = locomotion::step(
        &mut motion,
        steer,
        limits,
        &sp.body.locomotion,
        world.current,
        dt,
        gains,
    );
    locomotion::solid::keep_solid(
        &mut motion.pos,
        i,
        me,
        seen.percepts,
        world,
        seen.perception,
    );
    let mut anim = me.anim;
    let accel = if dt > 0.0 { info.dspeed / dt } else { 0.0 };
    anim::advance(
        &mut anim,
        &sp.body.anim,
        motion.speed,
        sp.body.size.z,
        accel,
        info.dyaw,
        limits.max_turn,
        dt,
    );
    Moved {
        motion,
        forward: info.forward,
        anim,
    }
}
