//! Loading and validation: RON parse → [`SpeciesDef`] → semantic checks → runtime [`Species`].
//! Every problem is a [`Diagnostic`] naming the file, line and column and what was expected.

use super::*;
use crate::decision::focus::Focus;
use crate::diag::{Diagnostic, Diagnostics};
use crate::numbers::NumberCheck;
use crate::perception::Relations;
use crate::script::{Limits, Script};
use crate::steering::avoid::AvoidParams;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// RON options used for every file the engine reads: newtype variants may be written with their
/// fields directly (`AvoidStatic(m0: 2.0)` or `AvoidStatic()`), and an optional value may be
/// written bare (`hunger: Fixed(0.9)`) as well as `Some(Fixed(0.9))`.
pub fn ron_options() -> ron::Options {
    use ron::extensions::Extensions;
    ron::Options::default()
        .with_default_extension(Extensions::UNWRAP_VARIANT_NEWTYPES)
        .with_default_extension(Extensions::IMPLICIT_SOME)
}

/// What designers call the types of the file format, for messages.
fn designer_name(type_name: &str) -> &str {
    match type_name {
        "Recipe" => "steering recipe",
        "Cond" => "condition",
        "Value" => "value",
        "Category" => "category",
        "DriveKind" => "drive",
        "AttrKind" => "attribute",
        "MessageKind" => "message kind",
        "Action" => "action",
        "Contact" => "contact",
        "Draw" => "draw",
        "Target" => "target",
        "Sector" => "sector",
        "Level" => "level",
        other => other,
    }
}

/// Edit distance between two short names (for "did you mean" hints).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diag + usize::from(!ca.eq_ignore_ascii_case(&cb)))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// ` (did you mean `x`?)` when one of `known` is close to `found`, else nothing.
pub fn did_you_mean<'a>(found: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    let best = known
        .into_iter()
        .map(|k| (edit_distance(found, k), k))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((d, k)) if d > 0 && d <= 2.max(found.chars().count() / 3) => {
            format!(" (did you mean `{k}`?)")
        }
        _ => String::new(),
    }
}

/// Turns a RON error into a located diagnostic.
pub fn ron_diag(file: &Path, text: &str, e: &ron::error::SpannedError) -> Diagnostic {
    let (mut line, mut col) = (e.span.start.line, e.span.start.col);
    let list = |v: &[&str]| {
        v.iter()
            .map(|x| format!("`{x}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let msg = match &e.code {
        ron::Error::NoSuchEnumVariant {
            expected,
            found,
            outer,
        } => {
            let what = outer.as_deref().map_or("value", designer_name);
            format!(
                "unknown {what} `{found}`{}: expected one of {}",
                did_you_mean(found, expected.iter().copied()),
                list(expected)
            )
        }
        ron::Error::NoSuchStructField {
            expected,
            found,
            outer,
        } => {
            let what = outer.as_deref().unwrap_or("struct");
            format!(
                "unknown field `{found}` in {what}{}: expected one of {}",
                did_you_mean(found, expected.iter().copied()),
                list(expected)
            )
        }
        ron::Error::ExpectedIdentifier => "expected a field name (`name: value`); a struct inside `Variant(…)` or `Some(…)` \
             is written without its own parentheses: `Spawn(species: \"shark\", …)`, `Some(min: …, max: …)`"
            .to_string(),
        ron::Error::ExpectedOption => "expected an optional value: `Some(…)` or `None`".to_string(),
        ron::Error::MissingStructField { field, outer } => match outer {
            Some(o) => format!("`{o}` is missing its required field `{field}`"),
            None => format!("missing required field `{field}`"),
        },
        ron::Error::ExpectedComma => {
            // RON notices a missing comma at the next token; point just after the previous one,
            // where the comma belongs.
            if let Some((l, c)) = end_of_previous_token(text, line, col) {
                (line, col) = (l, c);
            }
            "expected a `,` here, between two fields or list entries".to_string()
        }
        other => other.to_string(),
    };
    Diagnostic::new(file, line, col, msg, Some(text))
}

/// Line and column just after the last non-blank, non-comment character before `line:col`.
fn end_of_previous_token(text: &str, line: usize, col: usize) -> Option<(usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut l = line.checked_sub(1)?;
    let mut upto = col.saturating_sub(1);
    loop {
        let full = lines.get(l)?;
        let chars: Vec<char> = full.chars().collect();
        let mut head: String = chars[..upto.min(chars.len())].iter().collect();
        if let Some(i) = head.find("//") {
            head.truncate(i);
        }
        let trimmed = head.trim_end();
        if !trimmed.is_empty() {
            return Some((l + 1, trimmed.chars().count() + 1));
        }
        l = l.checked_sub(1)?;
        upto = usize::MAX;
    }
}

/// Line and column (1-based) of the first occurrence of `needle` at or after byte `from`.
pub fn locate(text: &str, needle: &str, from: usize) -> Option<(usize, usize, usize)> {
    let at = text.get(from..)?.find(needle)? + from;
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
    Some((line, col, at))
}

/// Reads and validates one species file (script included). Relations are checked by
/// [`SpeciesSet::new`], which sees every species of the world.
pub fn load_species(file: &Path, root: &Path, limits: &Limits) -> Result<Species, Diagnostics> {
    let text = crate::diag::read_text(file, "species file")?;
    load_species_str(file, &text, root, limits)
}

/// Validates species `text` (named `file`); its script path is relative to the file's folder.
pub fn load_species_str(
    file: &Path,
    text: &str,
    root: &Path,
    limits: &Limits,
) -> Result<Species, Diagnostics> {
    let def: SpeciesDef = ron_options()
        .from_str(text)
        .map_err(|e| Diagnostics::from(ron_diag(file, text, &e)))?;
    let script = match &def.script {
        Some(rel) => {
            let path = file.parent().unwrap_or(Path::new(".")).join(rel);
            // Checked here, before the script loader opens it: a named pipe would block it.
            if let Some(problem) = crate::diag::file_problem(&path) {
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
}

/// The categories a recipe's primitives steer by, with the primitive's name: what a `focus`
/// must keep for the behavior to steer at all.
fn steered_by(r: &Recipe, out: &mut Vec<(Category, &'static str)>) {
    let target = |t: &Target| match *t {
        Target::Nearest(c) | Target::Centroid(c) => Some(c),
        Target::Point(_) | Target::Home => None,
    };
    let need = match r {
        Recipe::Priority(v) => {
            v.iter().for_each(|r| steered_by(r, out));
            None
        }
        Recipe::Blend(v) => {
            v.iter().for_each(|w| steered_by(&w.steer, out));
            None
        }
        Recipe::Chase(c) => Some((c.target, "Chase")),
        Recipe::Escape(e) => Some((e.from, "Escape")),
        Recipe::EscapeMirror(e) => Some((e.from, "EscapeMirror")),
        Recipe::Pursue(p) => Some((p.target, "Pursue")),
        Recipe::Seek(s) => target(&s.target).map(|c| (c, "Seek")),
        Recipe::Flee(s) => target(&s.target).map(|c| (c, "Flee")),
        Recipe::Arrive(s) => target(&s.target).map(|c| (c, "Arrive")),
        Recipe::AvoidStatic(_) => Some((Category::Obstacle, "AvoidStatic")),
        Recipe::PredictCollision(_) => Some((Category::Obstacle, "PredictCollision")),
        Recipe::Separation(_) => Some((Category::Kin, "Separation")),
        Recipe::Alignment(_) => Some((Category::Kin, "Alignment")),
        Recipe::Cohesion(_) => Some((Category::Kin, "Cohesion")),
        Recipe::Zones(_) => Some((Category::Kin, "Zones")),
        Recipe::Vicsek(_) => Some((Category::Kin, "Vicsek")),
        // Moving obstacles are any agent; the rest read no percept.
        _ => None,
    };
    out.extend(need);
}

struct Builder<'a> {
    file: &'a Path,
    text: &'a str,
    script: Option<&'a Script>,
    slots: Vec<ScriptSlot>,
    latches: u8,
    diags: Vec<Diagnostic>,
    def: &'a SpeciesDef,
    /// Byte offset of the behavior being resolved, so located errors point into it.
    cursor: usize,
    /// Number checks; its section moves forward through the text as the walk visits values.
    nums: NumberCheck<'a>,
}

impl Builder<'_> {
    fn error_at(&mut self, needle: &str, msg: String) {
        // A value written with escapes (`"a\u{62}"`) is not found as parsed: then the error
        // points at the behavior being resolved, not at no line at all.
        let (l, c, _) = locate(self.text, needle, self.cursor)
            .or_else(|| locate(self.text, needle, 0))
            .or_else(|| locate(self.text, "", self.cursor))
            .unwrap_or((0, 0, 0));
        self.diags
            .push(Diagnostic::new(self.file, l, c, msg, Some(self.text)));
    }

    fn slot(&mut self, name: &str, kind: SlotKind) -> u16 {
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
                        "script function `{name}()` is not defined in {} (functions without parameters: {})",
                        s.file.display(),
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

    fn check_category(&mut self, c: Category, what: &str) {
        self.check_category_at(c, what, &format!("{c:?}"));
    }

    /// Like `check_category`, pointing at `needle` (e.g. the primitive, when the category is
    /// its default and not written).
    fn check_category_at(&mut self, c: Category, what: &str, needle: &str) {
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

    /// A behavior's `focus` (seed 000 §1): not empty, and holding every category its own
    /// steering targets (a `Chase(target: Food)` focused away from food would never move).
    fn focus(&mut self, b: &BehaviorDef, list: &[Category]) -> Focus {
        if list.is_empty() {
            self.error_at(
                "focus",
                format!(
                    "behavior \"{}\": `focus` lists no category, so its steering would see \
                     nothing: list what it steers by, or leave `focus` out to see everything",
                    b.name
                ),
            );
        }
        let focus = Focus::of(list);
        let mut needs = Vec::new();
        steered_by(&b.steer, &mut needs);
        let mut reported = Vec::new();
        for (c, what) in needs {
            if !focus.contains(c) && !reported.contains(&c) {
                reported.push(c);
                self.error_at(
                    "focus",
                    format!(
                        "behavior \"{}\": `focus` leaves out `{c:?}`, which its `{what}` \
                         steers by: add `{c:?}` to the list",
                        b.name
                    ),
                );
            }
        }
        focus
    }

    fn value(&mut self, v: &Value) -> ValueNode {
        match v {
            Value::Const(x) => {
                self.nums.enter("Const");
                self.nums.finite("Const", *x);
                ValueNode::Const(*x)
            }
            Value::Drive(d) => ValueNode::Drive(*d),
            Value::Distance(c) => {
                self.check_category(*c, "`Distance`");
                ValueNode::Distance(*c)
            }
            Value::Count(c) => {
                self.check_category(*c, "`Count`");
                ValueNode::Count(*c)
            }
            Value::Strength(c) => {
                self.check_category(*c, "`Strength`");
                ValueNode::Strength(*c)
            }
            Value::Speed => ValueNode::Speed,
            Value::TimeInBehavior => ValueNode::TimeInBehavior,
            Value::Attribute(a) => ValueNode::Attribute(*a),
            Value::KinSpeed => ValueNode::KinSpeed,
            Value::OneMinus(x) => ValueNode::OneMinus(Box::new(self.value(x))),
            Value::Mul(a, b) => ValueNode::Mul(Box::new(self.value(a)), Box::new(self.value(b))),
            Value::Add(a, b) => ValueNode::Add(Box::new(self.value(a)), Box::new(self.value(b))),
            Value::Script(name) => ValueNode::Script(self.slot(name, SlotKind::Number)),
        }
    }

    fn cond(&mut self, c: &Cond) -> CondNode {
        match c {
            Cond::Always => CondNode::Always,
            Cond::Never => CondNode::Never,
            Cond::All(v) => CondNode::All(v.iter().map(|c| self.cond(c)).collect()),
            Cond::Any(v) => CondNode::Any(v.iter().map(|c| self.cond(c)).collect()),
            Cond::Not(c) => CondNode::Not(Box::new(self.cond(c))),
            Cond::Above(v, x) => {
                let here = self.nums.enter("Above");
                let v = self.value(v);
                // The threshold is checked at this `Above`, not at what its value entered.
                let after = std::mem::replace(&mut self.nums.from, here);
                self.nums.finite("Above", *x);
                self.nums.from = after;
                CondNode::Above(v, *x)
            }
            Cond::Below(v, x) => {
                let here = self.nums.enter("Below");
                let v = self.value(v);
                // The threshold is checked at this `Below`, not at what its value entered.
                let after = std::mem::replace(&mut self.nums.from, here);
                self.nums.finite("Below", *x);
                self.nums.from = after;
                CondNode::Below(v, *x)
            }
            Cond::Latch { on, off } => {
                let bit = self.latches;
                if bit >= 64 {
                    self.error_at(
                        "Latch",
                        "more than 64 `Latch` conditions in one species".into(),
                    );
                }
                self.latches = self.latches.saturating_add(1);
                CondNode::Latch {
                    bit: bit.min(63),
                    on: Box::new(self.cond(on)),
                    off: Box::new(self.cond(off)),
                }
            }
            Cond::Sees(k) => {
                self.check_category(*k, "`Sees`");
                CondNode::Sees(*k)
            }
            Cond::Smells(k) => {
                self.check_category(*k, "`Smells`");
                CondNode::Smells(*k)
            }
            Cond::Perceives(k) => {
                self.check_category(*k, "`Perceives`");
                CondNode::Perceives(*k)
            }
            Cond::Within(k, d) => {
                self.nums.enter("Within");
                self.nums.non_negative("Within", *d);
                self.check_category(*k, "`Within`");
                CondNode::Within(*k, *d)
            }
            Cond::InSector(k, sectors) => {
                self.check_category(*k, "`InSector`");
                if sectors.is_empty() {
                    self.error_at(
                        "InSector",
                        "`InSector` lists no sector, so it is never true: list one or more of \
                         Front, LeftFront, RightFront, LeftRear, RightRear, Rear"
                            .into(),
                    );
                }
                let mask = sectors
                    .iter()
                    .fold(0, |m, s| m | crate::decision::sector_bit(*s));
                CondNode::InSector(*k, mask)
            }
            Cond::AtLevel(k, levels) => {
                self.check_category(*k, "`AtLevel`");
                if levels.is_empty() {
                    self.error_at(
                        "AtLevel",
                        "`AtLevel` lists no level, so it is never true: list one or more of \
                         Above, Level, Below"
                            .into(),
                    );
                }
                let mask = levels
                    .iter()
                    .fold(0, |m, l| m | crate::decision::level_bit(*l));
                CondNode::AtLevel(*k, mask)
            }
            Cond::EscapeDone => CondNode::EscapeDone,
            Cond::ObstacleNear => CondNode::ObstacleNear,
            Cond::TrafficNear => CondNode::TrafficNear,
            Cond::Heard(m) => CondNode::Heard(*m),
            Cond::TimeIn(t) => {
                self.nums.enter("TimeIn");
                self.nums.non_negative("TimeIn", *t);
                CondNode::TimeIn(*t)
            }
            Cond::Chance(p) => {
                self.nums.enter("Chance");
                self.nums.non_negative("Chance", *p);
                CondNode::Chance(*p)
            }
            Cond::NearBounds(m) => {
                self.nums.enter("NearBounds");
                self.nums.finite("NearBounds", *m);
                CondNode::NearBounds(*m)
            }
            Cond::Script(name) => CondNode::Script(self.slot(name, SlotKind::Bool)),
        }
    }

    fn recipe(&mut self, r: &Recipe) -> RecipeNode {
        match r {
            Recipe::Priority(v) => {
                if v.is_empty() {
                    self.error_at("Priority", "`Priority` needs at least one entry".into());
                }
                RecipeNode::Priority(v.iter().map(|r| self.recipe(r)).collect())
            }
            Recipe::Blend(v) => {
                if v.is_empty() {
                    self.error_at("Blend", "`Blend` needs at least one entry".into());
                }
                RecipeNode::Blend(
                    v.iter()
                        .map(|w| {
                            self.nums.enter("w");
                            self.nums.finite("w", w.w);
                            (
                                w.w,
                                w.by.as_ref().map(|b| self.value(b)),
                                self.recipe(&w.steer),
                            )
                        })
                        .collect(),
                )
            }
            Recipe::Script(name) => RecipeNode::Script(self.slot(name, SlotKind::Steer)),
            leaf => {
                self.leaf_numbers(leaf);
                match leaf {
                    Recipe::Chase(c) => self.check_category_at(c.target, "`Chase`", "Chase("),
                    Recipe::Escape(e) => self.check_category_at(e.from, "`Escape`", "Escape("),
                    Recipe::EscapeMirror(e) => {
                        self.check_category_at(e.from, "`EscapeMirror`", "EscapeMirror(")
                    }
                    Recipe::Pursue(p) => self.check_category_at(p.target, "`Pursue`", "Pursue("),
                    Recipe::Seek(s) | Recipe::Flee(s) | Recipe::Arrive(s) => {
                        if let Target::Nearest(c) | Target::Centroid(c) = s.target {
                            self.check_category(c, "the target")
                        }
                    }
                    _ => {}
                }
                // Avoidance written without parameters uses the species' `avoid` constants.
                match leaf {
                    Recipe::AvoidStatic(p) if *p == AvoidParams::default() => {
                        RecipeNode::Leaf(Recipe::AvoidStatic(self.def.avoid))
                    }
                    Recipe::AvoidDynamic(p) if *p == AvoidParams::default() => {
                        RecipeNode::Leaf(Recipe::AvoidDynamic(self.def.avoid))
                    }
                    _ => RecipeNode::Leaf(leaf.clone()),
                }
            }
        }
    }

    /// The numbers of a recipe primitive (`leaf`), located from its name on.
    fn leaf_numbers(&mut self, leaf: &Recipe) {
        let n = &mut self.nums;
        let avoid = |n: &mut NumberCheck, p: &AvoidParams| {
            n.non_negative("m0", p.m0);
            n.range("turn", p.turn, 0.0, std::f32::consts::PI);
            if let Some(r) = p.range {
                n.non_negative("range", r);
            }
            n.range("brake_floor", p.brake_floor, 0.0, 1.0);
            avoid_factors(n, p);
        };
        let escape = |n: &mut NumberCheck, e: &EscapeDef| {
            use std::f32::consts::{FRAC_PI_2, PI};
            n.range("level_band", e.level_band, 0.0, FRAC_PI_2);
            n.range("max_pitch", e.max_pitch, 0.0, FRAC_PI_2);
            n.range("speed_floor", e.speed_floor, 0.0, 1.0);
            n.range("turn", e.turn, 0.0, PI);
            n.range("vision_turn", e.vision_turn, 0.0, PI);
            n.range("front", e.front, 0.0, FRAC_PI_2);
            n.range("smell_brake", e.smell_brake, 0.0, 1.0);
            n.range("far_speed", e.far_speed, 0.0, 1.0);
        };
        let seek = |n: &mut NumberCheck, s: &SeekDef| {
            n.non_negative("slow_radius", s.slow_radius);
            n.non_negative("speed", s.speed);
            if let Target::Point(p) = s.target {
                n.point("Point", &p.to_array());
            }
        };
        let group = |n: &mut NumberCheck, g: &GroupDef| {
            n.finite("k", g.k);
            n.finite("factor", g.factor);
            n.non_negative_or_inf("radius", g.radius);
        };
        let look = |n: &mut NumberCheck, l: &LookAheadDef| {
            n.non_negative("horizon", l.horizon);
            n.finite("margin", l.margin);
        };
        match leaf {
            Recipe::AvoidStatic(p) => {
                n.enter("AvoidStatic");
                avoid(n, p)
            }
            Recipe::AvoidDynamic(p) => {
                n.enter("AvoidDynamic");
                avoid(n, p)
            }
            Recipe::PredictCollision(l) => {
                n.enter("PredictCollision");
                look(n, l)
            }
            Recipe::Contain(l) => {
                n.enter("Contain");
                look(n, l)
            }
            Recipe::Chase(c) => {
                n.enter("Chase");
                use std::f32::consts::{FRAC_PI_2, PI};
                n.non_negative("d0", c.d0);
                n.positive("max_turn", c.max_turn);
                n.range("turn", c.turn, 0.0, PI);
                n.range("rear_turn", c.rear_turn, 0.0, PI);
                // Front sector within ±π/2, rear sectors from ±π/2 on.
                n.range("front", c.front, 0.0, FRAC_PI_2);
                n.range("rear", c.rear, FRAC_PI_2, PI);
            }
            Recipe::Escape(e) => {
                n.enter("Escape");
                escape(n, e)
            }
            Recipe::EscapeMirror(e) => {
                n.enter("EscapeMirror");
                escape(n, e)
            }
            Recipe::Seek(s) => {
                n.enter("Seek");
                seek(n, s)
            }
            Recipe::Flee(s) => {
                n.enter("Flee");
                seek(n, s)
            }
            Recipe::Arrive(s) => {
                n.enter("Arrive");
                seek(n, s)
            }
            Recipe::Separation(g) => {
                n.enter("Separation");
                group(n, g)
            }
            Recipe::Alignment(g) => {
                n.enter("Alignment");
                group(n, g)
            }
            Recipe::Cohesion(g) => {
                n.enter("Cohesion");
                group(n, g)
            }
            Recipe::Zones(z) => {
                n.enter("Zones");
                // Seed 003 needs r_r < r_m < r_a: equal radii leave a zone empty, reversed ones
                // make repulsion win where attraction was meant.
                if n.non_negative("repulsion", z.repulsion)
                    & n.non_negative("matching", z.matching)
                    & n.non_negative("attraction", z.attraction)
                {
                    for (lo_key, lo, hi_key, hi) in [
                        ("repulsion", z.repulsion, "matching", z.matching),
                        ("matching", z.matching, "attraction", z.attraction),
                    ] {
                        if lo >= hi {
                            n.error(
                                lo_key,
                                format!(
                                    "`{lo_key}` ({lo}) must be below `{hi_key}` ({hi}): \
                                     seed 003's zones need repulsion < matching < attraction"
                                ),
                            );
                        }
                    }
                }
                // The soft band is a fraction of r_r; 1 would make the whole zone a ramp
                // starting at 0 distance.
                if z.soft.is_nan() || !(0.0..1.0).contains(&z.soft) {
                    n.error(
                        "soft",
                        format!(
                            "`soft` must be a number from 0 up to (not including) 1, not {}",
                            z.soft
                        ),
                    );
                }
            }
            Recipe::Vicsek(v) => {
                n.enter("Vicsek");
                n.non_negative("radius", v.radius);
                n.non_negative("noise", v.noise);
                n.non_negative("speed", v.speed);
            }
            Recipe::Disperse(d) => {
                n.enter("Disperse");
                n.non_negative("below", d.below);
            }
            Recipe::Wander(w) => {
                n.enter("Wander");
                n.non_negative("yaw_jitter", w.yaw_jitter);
                n.non_negative("pitch_jitter", w.pitch_jitter);
                n.non_negative("level_bias", w.level_bias);
                n.non_negative("cruise", w.cruise);
            }
            Recipe::Cruise(c) => {
                n.enter("Cruise");
                n.non_negative("speed", c.speed);
            }
            Recipe::FollowPlan(c) => {
                n.enter("FollowPlan");
                n.non_negative("speed", c.speed);
            }
            Recipe::Pursue(_)
            | Recipe::Stop
            | Recipe::Priority(_)
            | Recipe::Blend(_)
            | Recipe::Script(_) => {}
        }
    }

    /// The numbers of the species outside its behaviors: body, senses, avoidance, attributes,
    /// drives. The tick loop clamps with several of them, and `clamp` panics on NaN or on
    /// `min > max`.
    fn species_numbers(&mut self, def: &SpeciesDef) {
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
        if let crate::locomotion::Mode::RigidBody(r) = &def.body.locomotion {
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
        let p = &def.avoid;
        n.non_negative("m0", p.m0);
        n.range("turn", p.turn, 0.0, std::f32::consts::PI);
        if let Some(r) = p.range {
            n.non_negative("range", r);
        }
        n.range("brake_floor", p.brake_floor, 0.0, 1.0);
        avoid_factors(n, p);
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

    fn build(
        mut self,
        def: &SpeciesDef,
        script: Option<Arc<Script>>,
    ) -> Result<Species, Diagnostics> {
        if def.behaviors.is_empty() {
            self.error_at("behaviors", "a species needs at least one behavior".into());
        }
        if def.behaviors.len() > 64 {
            self.error_at(
                "behaviors",
                "a species may have at most 64 behaviors".into(),
            );
        }
        let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
        let mut behaviors = Vec::new();
        for (i, b) in def.behaviors.iter().enumerate() {
            let needle = format!("\"{}\"", b.name);
            self.cursor = locate(self.text, &needle, 0).map_or(0, |x| x.2);
            if let Some(j) = seen.insert(&b.name, i) {
                let from = locate(self.text, &needle, 0).map_or(0, |x| x.2 + 1);
                self.cursor = from;
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{}\" is defined twice (first as behavior {})",
                        b.name,
                        j + 1
                    ),
                );
            }
            if b.priority == 0 {
                self.error_at(
                    "priority",
                    format!(
                        "behavior \"{}\": priority levels start at 1 (the highest)",
                        b.name
                    ),
                );
            }
            let initial_defined = def.behaviors.iter().any(|x| x.name == def.initial);
            if b.when == Cond::Never && b.name != def.initial && initial_defined {
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{}\" is unreachable: it has no `when` condition and is not the initial behavior",
                        b.name
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
            self.nums.enter("steer");
            let steer = self.recipe(&b.steer);
            let focus = b.focus.as_deref().map(|f| self.focus(b, f));
            let on_enter = b
                .on_enter
                .iter()
                .map(|a| match a {
                    Action::Send(k, r) => ActionNode::Send(*k, *r),
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
                })
                .collect();
            behaviors.push(Behavior {
                name: b.name.as_str().into(),
                priority: b.priority,
                when_text: describe(&b.when).into(),
                done_text: describe(&b.done).into(),
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
            });
        }
        // Two behaviors of one level with the same trigger can never be told apart.
        for i in 0..def.behaviors.len() {
            for j in i + 1..def.behaviors.len() {
                let (a, b) = (&def.behaviors[i], &def.behaviors[j]);
                if a.priority == b.priority && a.when == b.when && a.when != Cond::Never {
                    self.cursor =
                        locate(self.text, &format!("\"{}\"", b.name), 0).map_or(0, |x| x.2);
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
        let initial = match def.behaviors.iter().position(|b| b.name == def.initial) {
            Some(i) => i as u16,
            None => {
                let names: Vec<&str> = def.behaviors.iter().map(|b| b.name.as_str()).collect();
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
        self.species_numbers(def);
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
        Ok(Species {
            name: def.name.clone(),
            file: self.file.to_path_buf(),
            def: def.clone(),
            senses: def.senses,
            behaviors,
            initial,
            recipes,
            recipe_names: recipe_names.into(),
            script,
            slots: self.slots,
            steer_slots,
            has_on_tick,
            has_on_event,
        })
    }
}

/// The factors of the pressure fields (seed 000 §4.1–§4.2): the braking factor a fraction,
/// the dynamic `M_min` factor `1 − cos(half-angle)` of some view, so in [0, 2].
fn avoid_factors(n: &mut NumberCheck, p: &AvoidParams) {
    n.range("brake", p.brake, 0.0, 1.0);
    if let Some(f) = p.m_min_factor {
        n.range("m_min_factor", f, 0.0, 2.0);
    }
}

/// Human-readable text of a condition, e.g. `hunger > 0.6 and sees food`.
pub fn describe(c: &Cond) -> String {
    let mut s = String::new();
    describe_into(c, &mut s);
    s
}

fn value_text(v: &Value) -> String {
    match v {
        Value::Const(x) => format!("{x}"),
        Value::Drive(d) => format!("{d:?}").to_lowercase(),
        Value::Distance(c) => format!("distance to {}", c.name()),
        Value::Count(c) => format!("number of {}", c.name()),
        Value::Strength(c) => format!("strength of {}", c.name()),
        Value::Speed => "speed".into(),
        Value::TimeInBehavior => "time in behavior".into(),
        Value::Attribute(a) => format!("{a:?}").to_lowercase(),
        Value::KinSpeed => "school speed".into(),
        Value::OneMinus(x) => format!("1 - {}", value_text(x)),
        Value::Mul(a, b) => format!("{} * {}", value_text(a), value_text(b)),
        Value::Add(a, b) => format!("({} + {})", value_text(a), value_text(b)),
        Value::Script(n) => format!("{n}()"),
    }
}

fn describe_into(c: &Cond, s: &mut String) {
    let join = |v: &Vec<Cond>, sep: &str, s: &mut String| {
        for (i, c) in v.iter().enumerate() {
            if i > 0 {
                s.push_str(sep);
            }
            let nested = matches!(c, Cond::All(_) | Cond::Any(_));
            if nested {
                s.push('(');
            }
            describe_into(c, s);
            if nested {
                s.push(')');
            }
        }
    };
    match c {
        Cond::Always => s.push_str("always"),
        Cond::Never => s.push_str("never"),
        Cond::All(v) => join(v, " and ", s),
        Cond::Any(v) => join(v, " or ", s),
        Cond::Not(c) => {
            s.push_str("not (");
            describe_into(c, s);
            s.push(')');
        }
        Cond::Above(v, x) => {
            let _ = write!(s, "{} > {x}", value_text(v));
        }
        Cond::Below(v, x) => {
            let _ = write!(s, "{} < {x}", value_text(v));
        }
        Cond::Latch { on, off } => {
            s.push_str("latched on (");
            describe_into(on, s);
            s.push_str(") until (");
            describe_into(off, s);
            s.push(')');
        }
        Cond::Sees(k) => {
            let _ = write!(s, "sees {}", k.name());
        }
        Cond::Smells(k) => {
            let _ = write!(s, "smells {}", k.name());
        }
        Cond::Perceives(k) => {
            let _ = write!(s, "perceives {}", k.name());
        }
        Cond::Within(k, d) => {
            let _ = write!(s, "{} within {d}", k.name());
        }
        Cond::InSector(k, v) => {
            let names: Vec<&str> = v.iter().map(|x| x.name()).collect();
            let _ = write!(s, "{} in {}", k.name(), names.join(" or "));
        }
        Cond::AtLevel(k, v) => {
            let names: Vec<&str> = v.iter().map(|x| x.name()).collect();
            let _ = write!(s, "{} at {}", k.name(), names.join(" or "));
        }
        Cond::EscapeDone => s.push_str("predator behind and out of sight"),
        Cond::ObstacleNear => s.push_str("obstacle pressure above M_min"),
        Cond::TrafficNear => s.push_str("moving obstacle pressure above M_min"),
        Cond::Heard(m) => {
            let _ = write!(s, "heard {}", m.name());
        }
        Cond::TimeIn(t) => {
            let _ = write!(s, "{t} s in behavior");
        }
        Cond::Chance(p) => {
            let _ = write!(s, "chance {p}/s");
        }
        Cond::NearBounds(m) => {
            let _ = write!(s, "within {m} of the bounds");
        }
        Cond::Script(n) => {
            let _ = write!(s, "{n}()");
        }
    }
}

/// Every species of a world, with relations resolved between them.
#[derive(Debug, Clone)]
pub struct SpeciesSet {
    /// Species by index ([`crate::world::SpeciesId`]).
    pub species: Vec<Arc<Species>>,
    /// What each species is to each other one.
    pub relations: Relations,
    /// Senses by species index.
    pub senses: Vec<SenseParams>,
}

impl SpeciesSet {
    /// Resolves relations between `species` (names must be unique, and every relation must name
    /// one of them).
    pub fn new(species: Vec<Arc<Species>>) -> Result<SpeciesSet, Diagnostics> {
        Self::with_library(species, |_| false)
    }

    /// Like [`SpeciesSet::new`], but a relation may also name a species that is not in this
    /// world as long as `exists(name)` says it is defined elsewhere (e.g. another file of the
    /// behaviors folder): a shark that eats sardines runs in a world without sardines.
    pub fn with_library(
        species: Vec<Arc<Species>>,
        exists: impl Fn(&str) -> bool,
    ) -> Result<SpeciesSet, Diagnostics> {
        let mut diags = Vec::new();
        let index: BTreeMap<&str, usize> = species
            .iter()
            .enumerate()
            .map(|(i, s)| (s.name.as_str(), i))
            .collect();
        if index.len() != species.len() {
            for (i, s) in species.iter().enumerate() {
                if index[s.name.as_str()] != i {
                    diags.push(Diagnostic::file(
                        &s.file,
                        format!("species name \"{}\" is used by two files", s.name),
                    ));
                }
            }
        }
        let n = species.len();
        let mut rel = Relations::new(n);
        for (i, s) in species.iter().enumerate() {
            let text = std::fs::read_to_string(&s.file).unwrap_or_default();
            let r = &s.def.relations;
            rel.set_eats_items(i, r.eats_items);
            rel.set_mates(i, r.mates);
            if r.see_others {
                for j in 0..n {
                    rel.set(i, j, Some(Category::Other));
                }
            }
            let mut resolve = |names: &Vec<String>, cat: Category, field: &str| {
                for name in names {
                    match index.get(name.as_str()) {
                        Some(&j) => rel.set(i, j, Some(cat)),
                        None if exists(name) => {}
                        None => {
                            let (l, c, _) =
                                locate(&text, &format!("\"{name}\""), 0).unwrap_or((0, 0, 0));
                            let known: Vec<&str> = index.keys().copied().collect();
                            diags.push(Diagnostic::new(
                                &s.file,
                                l,
                                c,
                                format!("unknown species \"{name}\" in `{field}`: loaded species are {}", known.join(", ")),
                                Some(&text),
                            ));
                        }
                    }
                }
            };
            resolve(&r.kin, Category::Kin, "kin");
            resolve(&r.prey, Category::Food, "prey");
            resolve(&r.predators, Category::Predator, "predators");
            rel.set(i, i, Some(Category::Kin));
        }
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        let senses = species.iter().map(|s| s.senses).collect();
        Ok(SpeciesSet {
            species,
            relations: rel,
            senses,
        })
    }

    /// Index of the species named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.species.iter().position(|s| s.name == name)
    }
}
