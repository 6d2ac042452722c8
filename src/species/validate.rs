//! Loading and validation: RON parse → [`SpeciesDef`] → semantic checks → runtime [`Species`].
//! Every problem is a [`Diagnostic`] naming the file, line and column and what was expected.
//!
//! This file holds the walk over the species (behaviors, initial behavior, named recipes) and
//! the script slots; conditions, recipes and the species' own constants are checked in
//! `conditions.rs`, `recipes.rs` and `params.rs` beside it.

use super::*;
use crate::load::{Diagnostic, Diagnostics, NumberCheck};
use crate::perception::MAX_NEIGHBORS;
use crate::script::{SandboxLimits, Script};
use std::collections::BTreeMap;
use std::path::Path;

// Paths through `species::validate` from before these moved keep working.
pub use super::describe::describe;
pub use super::set::SpeciesSet;
pub use crate::load::{did_you_mean, locate, ron_diag, ron_options};

/// Reads and validates one species file (script included). Relations are checked by
/// [`SpeciesSet::new`], which sees every species of the world.
pub fn load_species(
    file: &Path,
    root: &Path,
    limits: &SandboxLimits,
) -> Result<Species, Diagnostics> {
    let text = crate::load::read_text(file, "species file")?;
    load_species_str(file, &text, root, limits)
}

/// Validates species `text` (named `file`); its script path is relative to the file's folder.
pub fn load_species_str(
    file: &Path,
    text: &str,
    root: &Path,
    limits: &SandboxLimits,
) -> Result<Species, Diagnostics> {
    let def: SpeciesDef = ron_options()
        .from_str(text)
        .map_err(|e| Diagnostics::from(ron_diag(file, text, &e)))?;
    let script = match &def.script {
        Some(rel) => {
            let path = file.parent().unwrap_or(Path::new(".")).join(rel);
            // Checked here, before the script loader opens it: a named pipe would block it.
            if let Some(problem) = crate::load::diag::file_problem(&path) {
                let (l, c, _) = locate(text, &format!("\"{rel}\""), 0).unwrap_or((0, 0, 0));
                return Err(Diagnostic::new(
                    file,
                    l,
                    c,
                    format!("script file \"{}\" {problem}", path.display()),
                    Some(text),
                )
                .into());
            }
            Some(Arc::new(Script::load(&path, root, limits)?))
        }
        None => None,
    };
    let (script, memory) = super::blackboard::declare(file, text, &def, script)?;
    Builder {
        file,
        text,
        script: script.as_deref(),
        slots: Vec::new(),
        latches: 0,
        diags: Vec::new(),
        def: &def,
        cursor: 0,
        nums: NumberCheck::new(file, text),
    }
    .build(&def, script.clone())
    .and_then(|s| super::blackboard::finish(s, memory))
}

/// The state of one species' validation: where it is in the text, what it found wrong, the
/// script slots and latches handed out so far.
pub(super) struct Builder<'a> {
    pub(super) file: &'a Path,
    pub(super) text: &'a str,
    pub(super) script: Option<&'a Script>,
    pub(super) slots: Vec<ScriptSlot>,
    pub(super) latches: u8,
    pub(super) diags: Vec<Diagnostic>,
    pub(super) def: &'a SpeciesDef,
    /// Byte offset of the behavior being resolved, so located errors point into it.
    pub(super) cursor: usize,
    /// Number checks; its section moves forward through the text as the walk visits values.
    pub(super) nums: NumberCheck<'a>,
}

impl Builder<'_> {
    pub(super) fn error_at(&mut self, needle: &str, msg: String) {
        // A value written with escapes (`"a\u{62}"`) is not found as parsed: then the error
        // points at the behavior being resolved, not at no line at all.
        let (l, c, _) = locate(self.text, needle, self.cursor)
            .or_else(|| locate(self.text, needle, 0))
            .or_else(|| locate(self.text, "", self.cursor))
            .unwrap_or((0, 0, 0));
        self.diags
            .push(Diagnostic::new(self.file, l, c, msg, Some(self.text)));
    }

    pub(super) fn slot(&mut self, name: &str, kind: SlotKind) -> u16 {
        if let Some(s) = self.slots.iter().find(|s| s.name == name && s.kind == kind) {
            return if kind == SlotKind::Steer {
                s.index
            } else {
                self.slots.iter().position(|x| x == s).unwrap() as u16
            };
        }
        match self.script {
            None => self.error_at(
                &format!("\"{name}\""),
                format!("`{name}` names a script function, but the species has no `script`"),
            ),
            Some(s) if !s.has_fn(name, 0) => {
                let known: Vec<&str> = s
                    .functions
                    .iter()
                    .filter(|f| f.1 == 0)
                    .map(|f| f.0.as_str())
                    .collect();
                self.error_at(
                    &format!("\"{name}\""),
                    format!(
                        "script function `{name}()` is not defined in {}{} (functions without parameters: {})",
                        s.file.display(),
                        did_you_mean(name, known.iter().copied()),
                        if known.is_empty() { "none".to_string() } else { known.join(", ") }
                    ),
                )
            }
            _ => {}
        }
        let index = self
            .slots
            .iter()
            .filter(|s| s.kind == SlotKind::Steer)
            .count() as u16;
        self.slots.push(ScriptSlot {
            name: name.to_string(),
            kind,
            index,
        });
        if kind == SlotKind::Steer {
            index
        } else {
            (self.slots.len() - 1) as u16
        }
    }

    pub(super) fn check_category(&mut self, c: Category, what: &str) {
        self.check_category_at(c, what, &format!("{c:?}"));
    }

    /// Like `check_category`, pointing at `needle` (e.g. the primitive, when the category is
    /// its default and not written).
    pub(super) fn check_category_at(&mut self, c: Category, what: &str, needle: &str) {
        let r = &self.def.relations;
        let ok = match c {
            Category::Food => r.eats_items || !r.prey.is_empty(),
            Category::Predator => !r.predators.is_empty(),
            Category::Mate => r.mates,
            Category::Kin | Category::Obstacle | Category::Other => true,
        };
        if !ok {
            let need = match c {
                Category::Food => "`relations: (eats_items: true)` or a `prey` list",
                Category::Predator => "a `predators` list in `relations`",
                _ => "`relations: (mates: true)`",
            };
            self.error_at(
                needle,
                format!(
                    "{what} refers to `{c:?}`, but the species has no such relation: add {need}"
                ),
            );
        }
    }

    fn build(
        mut self,
        def: &SpeciesDef,
        script: Option<Arc<Script>>,
    ) -> Result<Species, Diagnostics> {
        if def.behaviors.is_empty() {
            self.error_at("behaviors", "a species needs at least one behavior".into());
        }
        let nodes = compose::flatten(&def.behaviors);
        if nodes.len() > 64 {
            self.error_at(
                "behaviors",
                "a species may have at most 64 behaviors (composed ones and their parts \
                 included)"
                    .into(),
            );
        }
        // Where each behavior's name is written, in the order written.
        let mut at = Vec::with_capacity(nodes.len());
        let mut from = 0;
        for n in &nodes {
            let found = name_at(self.text, &n.def.name, from)
                .or_else(|| name_at(self.text, &n.def.name, 0));
            let x = found.unwrap_or(0);
            if found.is_some() {
                from = x + 1;
            }
            at.push(x);
        }
        let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
        let mut behaviors = Vec::new();
        for (i, n) in nodes.iter().enumerate() {
            let b = n.def;
            let name = n.path.as_str();
            let needle = format!("\"{}\"", b.name);
            self.cursor = at[i];
            if let Some(j) = seen.insert(name, i) {
                self.cursor = at[i] + 1;
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{}\" is defined twice (first as behavior {})",
                        name,
                        j + 1
                    ),
                );
                self.cursor = at[i];
            }
            let initial_defined = nodes.iter().any(|x| x.path == def.initial);
            if initial_defined && !Builder::reachable(&nodes, i, &def.initial) {
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{}\" is unreachable: it has no `when` condition and is not the initial behavior",
                        name
                    ),
                );
            }
            self.nums.from = self.cursor;
            self.nums.non_negative("min_time", b.min_time);
            self.nums.non_negative("cooldown", b.cooldown);
            if let Some(r) = b.response {
                self.nums.non_negative("response", r);
            }
            match b.contact {
                Some(Contact::Eat { reach }) | Some(Contact::Mate { reach }) => {
                    self.nums.enter("contact");
                    self.nums.non_negative("reach", reach);
                }
                None => {}
            }
            for a in &b.on_enter {
                if let Action::Send(_, r) = a {
                    self.nums.from = self.cursor;
                    self.nums.enter("Send");
                    self.nums.non_negative("Send", *r);
                }
            }
            match b.contact {
                Some(Contact::Eat { .. }) => {
                    self.check_category_at(Category::Food, "`contact: Eat`", "Eat(")
                }
                Some(Contact::Mate { .. }) => {
                    self.check_category_at(Category::Mate, "`contact: Mate`", "Mate(")
                }
                None => {}
            }
            // Each field's values are located from where the field is written.
            self.nums.from = self.cursor;
            self.nums.enter("when");
            let when = self.cond(&b.when);
            self.nums.from = self.cursor;
            self.nums.enter("done");
            let done = self.cond(&b.done);
            self.nums.from = self.cursor;
            self.nums.enter("fail");
            let fail = self.cond(&b.fail);
            self.nums.from = self.cursor;
            self.nums.enter("steer");
            let steer = match &b.steer {
                Some(r) => self.recipe(r),
                None => RecipeNode::Priority(Vec::new()),
            };
            let focus = b.focus.as_deref().map(|f| self.focus(b, f));
            let on_enter = b
                .on_enter
                .iter()
                .map(|a| match a {
                    Action::Send(k, r) => ActionNode::Send(self.signal(k, "Send"), *r),
                    Action::Call(f) => {
                        match self.script {
                            Some(s) if s.has_fn(f, 0) => {}
                            _ => self.error_at(
                                &format!("\"{f}\""),
                                format!("`Call(\"{f}\")`: no script function `{f}()`"),
                            ),
                        }
                        ActionNode::Call(f.clone())
                    }
                    Action::MarkStation => ActionNode::MarkStation,
                })
                .collect();
            behaviors.push(Behavior {
                name: name.into(),
                priority: b.priority,
                when_text: describe(&b.when).into(),
                done_text: describe(&b.done).into(),
                fail_text: describe(&b.fail).into(),
                fail,
                when,
                done,
                steer,
                equal_may_interrupt: b.equal_may_interrupt,
                min_time: b.min_time,
                cooldown: b.cooldown,
                contact: b.contact,
                on_enter,
                response: b.response,
                focus,
                source: line_col(self.text, at[i]),
                parent: None,
                level: 0,
                compose: Compose::Leaf,
                children: Vec::new(),
                on_success: None,
                on_failure: None,
            });
        }
        self.compose(&nodes, &at, &mut behaviors);
        // Two behaviors of one list and level with the same trigger can never be told apart.
        for i in 0..nodes.len() {
            for j in i + 1..nodes.len() {
                let (a, b) = (nodes[i].def, nodes[j].def);
                if nodes[i].parent == nodes[j].parent
                    && a.priority == b.priority
                    && a.when == b.when
                    && a.when != Cond::Never
                {
                    self.cursor = at[j];
                    self.error_at(
                        &format!("\"{}\"", b.name),
                        format!(
                            "priority conflict: \"{}\" and \"{}\" have the same level {} and the same `when`, so \"{}\" could never start",
                            a.name, b.name, a.priority, b.name
                        ),
                    );
                }
            }
        }
        self.cursor = 0;
        let initial_node = match nodes.iter().position(|n| n.path == def.initial) {
            Some(i) => i as u16,
            None => {
                let names: Vec<&str> = nodes.iter().map(|n| n.path.as_str()).collect();
                // Point at the name after `initial:`, not at the first mention of it.
                self.cursor = locate(self.text, "initial", 0).map_or(0, |x| x.2);
                self.error_at(
                    &format!("\"{}\"", def.initial),
                    format!(
                        "`initial` names an undefined behavior \"{}\"{}: the species defines {}",
                        def.initial,
                        did_you_mean(&def.initial, names.iter().copied()),
                        names
                            .iter()
                            .map(|n| format!("\"{n}\""))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                );
                self.cursor = 0;
                0
            }
        };
        let mut recipes = Vec::new();
        let mut recipe_names = Vec::new();
        for (name, r) in &def.recipes {
            self.cursor = locate(self.text, &format!("\"{name}\""), 0).map_or(0, |x| x.2);
            self.nums.from = self.cursor;
            recipes.push(self.recipe(r));
            recipe_names.push(name.clone());
        }
        let events = self.events(def);
        self.species_numbers(def);
        self.look(def);
        if def.decision_interval == 0 {
            self.error_at(
                "decision_interval",
                "`decision_interval` must be at least 1 tick".into(),
            );
        }
        let kept = def.senses.max_percepts;
        // One slot per category at least: the nearest of each is always kept.
        let fewest = crate::perception::Category::COUNT;
        if !(fewest..=crate::perception::MAX_PERCEPTS).contains(&kept) {
            self.error_at(
                "max_percepts",
                format!(
                    "`max_percepts` must be between {fewest} and {}, not {kept}",
                    crate::perception::MAX_PERCEPTS
                ),
            );
        }
        if let Some(n) = def.senses.neighbors {
            if !(1..=MAX_NEIGHBORS).contains(&n) {
                self.error_at(
                    "neighbors",
                    format!("`neighbors` must be between 1 and {MAX_NEIGHBORS}, not {n}"),
                );
            }
        }
        self.diags.append(&mut self.nums.diags);
        if !self.diags.is_empty() {
            return Err(Diagnostics(self.diags));
        }
        let steer_slots = self
            .slots
            .iter()
            .filter(|s| s.kind == SlotKind::Steer)
            .count();
        let (has_on_tick, has_on_event) = match &script {
            Some(s) => (s.has_fn("on_tick", 0), s.has_fn("on_event", 1)),
            None => (false, false),
        };
        let has_on_event_payload = script.as_ref().is_some_and(|s| s.has_fn("on_event", 2));
        let scripts_native = script.as_ref().is_some_and(|s| {
            !has_on_tick
                && self
                    .slots
                    .iter()
                    .all(|x| x.kind != SlotKind::Steer && s.native(&x.name).is_some())
        });
        let natives_read_memory = script.as_ref().is_some_and(|s| s.natives_read_memory());
        Ok(Species {
            name: def.name.clone(),
            file: self.file.to_path_buf(),
            def: def.clone(),
            body: def.body.clone(),
            senses: def.senses,
            avoid: def.avoid,
            attributes: def.attributes.clone(),
            drives: def.drives.clone(),
            decision_interval: def.decision_interval,
            resend_after: def.resend_after,
            initial: first_leaf(&behaviors, initial_node),
            roots: (0..behaviors.len() as u16)
                .filter(|&i| behaviors[i as usize].parent.is_none())
                .collect(),
            // A flat list whose behaviors end on failure or name what follows them needs the
            // composed rules, which alone read `fail`, `on_success` and `on_failure` (for a
            // flat list they are seed 000 §3's flat rules otherwise).
            depth: behaviors
                .iter()
                .filter(|b| b.compose != Compose::Leaf)
                .map(|b| b.level + 1)
                .max()
                .unwrap_or(0)
                .max(u8::from(behaviors.iter().any(|b| {
                    b.fail != CondNode::Never || b.on_success.is_some() || b.on_failure.is_some()
                }))),
            behaviors,
            initial_node,
            recipes,
            recipe_names: recipe_names.into(),
            script,
            slots: self.slots,
            steer_slots,
            has_on_tick,
            scripts_native,
            natives_read_memory,
            has_on_event,
            events: events.into(),
            has_on_event_payload,
            memory: Arc::default(),
        })
    }
}

/// The leaf a behavior starts in when nothing has been evaluated yet (spawn, a test's
/// `behavior:`): its default part ([`default_part`]), down to a leaf.
pub fn first_leaf(behaviors: &[Behavior], mut i: u16) -> u16 {
    while let Some(c) = default_part(behaviors, i) {
        i = c;
    }
    i
}

/// Behavior `i` and every composed behavior holding it, innermost first.
pub fn ancestors(behaviors: &[Behavior], i: u16) -> impl Iterator<Item = u16> + '_ {
    std::iter::successors(Some(i), |&a| {
        behaviors.get(a as usize).and_then(|b| b.parent)
    })
}

/// The part a composed behavior starts in when none of its parts' `when` holds: a sequence's or
/// fallback's first step; for sub-behaviors, the first without a `when` (as the species'
/// `initial` is the behavior that runs when nothing else applies), else the first. `None` for
/// a behavior that steers.
pub fn default_part(behaviors: &[Behavior], i: u16) -> Option<u16> {
    let b = behaviors.get(i as usize)?;
    let first = *b.children.first()?;
    if b.compose != Compose::Select {
        return Some(first);
    }
    Some(
        b.children
            .iter()
            .copied()
            .find(|&c| behaviors[c as usize].when == CondNode::Never)
            .unwrap_or(first),
    )
}

/// Byte offset of the first `name: "<name>"` at or after `from` in `text` (a behavior's name,
/// not `initial` or a condition naming it).
fn name_at(text: &str, name: &str, from: usize) -> Option<usize> {
    let needle = format!("\"{name}\"");
    let mut from = from;
    while let Some((_, _, at)) = locate(text, &needle, from) {
        let before = text[..at].trim_end();
        if let Some(key) = before.strip_suffix(':') {
            if key.trim_end().ends_with("name") {
                return Some(at);
            }
        }
        from = at + 1;
    }
    None
}

/// Line and column (1-based) of byte offset `at`; (0, 0) for offset 0 (not found).
fn line_col(text: &str, at: usize) -> (u32, u32) {
    if at == 0 {
        return (0, 0);
    }
    locate(text, "", at).map_or((0, 0), |(l, c, _)| (l as u32, c as u32))
}
