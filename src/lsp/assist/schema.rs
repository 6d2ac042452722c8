//! The vocabulary of the species and scenario formats, as one table: every type a file can
//! write, with its fields or variants, their types and their doc lines (`species.table`,
//! `scenario.table`, read once). Completion, hover and `shoal defs`' JSON Schemas read it; a test
//! (`tests.rs`) checks it against the real serde types (`species::def`, `scenario::def`, …), so
//! it cannot drift from what the loaders accept.
//!
//! Table syntax, one entry a line: `struct NAME | doc`, `enum NAME | doc` or
//! `either NAME: A, B | doc` (a value of one of several types, e.g. `MessageRef`) starts a type;
//! two-space lines are its fields (`name: TYPE | doc`, `TYPE !` when required) or variants
//! (`Name | doc`, `Name(T, U) | doc`, `Name{} | doc` followed by four-space field lines). Types
//! are written as in Rust (`Option<Recipe>`, `Vec<Cond>`, `BTreeMap<String, MemDecl>`); a few
//! names stand for strings that name something: `SpeciesName`, `BehaviorName`, `FunctionName`,
//! `GroupName`, `EventName`, `ScriptPath`, `FilePath`, `FolderPath`.

use std::sync::OnceLock;

const SPECIES: &str = include_str!("species.table");
const SCENARIO: &str = include_str!("scenario.table");

/// A field of a struct (or of a struct-like variant).
#[derive(Debug, Clone)]
pub struct Field {
    /// Its name as written in RON.
    pub name: &'static str,
    /// Its type.
    pub ty: &'static str,
    /// Whether a file must write it.
    pub required: bool,
    /// Its doc line.
    pub doc: String,
}

/// What follows a variant's name.
#[derive(Debug, Clone)]
pub enum Args {
    /// Nothing (`Stop`).
    Unit,
    /// Positional values (`Within(Food, 2.0)`); one struct type is written with its fields
    /// directly (`Chase(d0: 0.6)`).
    Tuple(Vec<&'static str>),
    /// Named fields (`Latch(on: …, off: …)`).
    Named(Vec<Field>),
}

/// A variant of an enum.
#[derive(Debug, Clone)]
pub struct Variant {
    /// Its name.
    pub name: &'static str,
    /// What it holds.
    pub args: Args,
    /// Its doc line.
    pub doc: String,
}

/// What a type is made of.
#[derive(Debug, Clone)]
pub enum Form {
    /// Named fields.
    Struct(Vec<Field>),
    /// Variants.
    Enum(Vec<Variant>),
    /// A value of one of these types (written bare, untagged).
    Either(Vec<&'static str>),
}

/// One type of the formats.
#[derive(Debug, Clone)]
pub struct TypeDef {
    /// The Rust type's name.
    pub name: &'static str,
    /// Its doc line.
    pub doc: String,
    /// Its fields or variants.
    pub form: Form,
}

/// Strings that name something of the project, and what.
pub const NAME_TYPES: [&str; 8] = [
    "SpeciesName",
    "BehaviorName",
    "FunctionName",
    "GroupName",
    "EventName",
    "ScriptPath",
    "FilePath",
    "FolderPath",
];

/// Number and other plain types the formats use.
pub const PLAIN_TYPES: [&str; 11] = [
    "f32", "f64", "u8", "u16", "u32", "u64", "usize", "i64", "bool", "String", "Vec3",
];

/// Every type of both formats.
pub fn types() -> &'static [TypeDef] {
    static TYPES: OnceLock<Vec<TypeDef>> = OnceLock::new();
    TYPES.get_or_init(|| {
        let mut t = parse(SPECIES);
        for s in parse(SCENARIO) {
            if !t.iter().any(|x| x.name == s.name) {
                t.push(s);
            }
        }
        t
    })
}

/// The type named `name`.
pub fn get(name: &str) -> Option<&'static TypeDef> {
    types().iter().find(|t| t.name == name)
}

/// Fields of `ty` when a value of it is written as `(field: …)`: a struct's own.
pub fn fields(ty: &str) -> Option<&'static [Field]> {
    match &get(ty)?.form {
        Form::Struct(f) => Some(f),
        _ => None,
    }
}

/// The variant `name` of the enum `ty` (or of one of the types an `either` allows).
pub fn variant(ty: &str, name: &str) -> Option<&'static Variant> {
    match &get(ty)?.form {
        Form::Enum(v) => v.iter().find(|v| v.name == name),
        Form::Either(alts) => alts.iter().find_map(|a| variant(a, name)),
        Form::Struct(_) => None,
    }
}

/// The variants a value of `ty` may be written as (an `either`'s alternatives' too).
pub fn variants(ty: &str) -> Vec<&'static Variant> {
    match get(ty).map(|t| &t.form) {
        Some(Form::Enum(v)) => v.iter().collect(),
        Some(Form::Either(alts)) => alts.iter().flat_map(|a| variants(a)).collect(),
        _ => Vec::new(),
    }
}

/// `ty` without `Option<…>` and `Box<…>` around it.
pub fn bare(ty: &str) -> &str {
    let mut t = ty.trim();
    loop {
        if let Some(inner) = wrapped(t, "Option").or_else(|| wrapped(t, "Box")) {
            t = inner;
        } else {
            return t;
        }
    }
}

/// The `T` of `Outer<T>`.
pub fn wrapped<'a>(ty: &'a str, outer: &str) -> Option<&'a str> {
    ty.strip_prefix(outer)?
        .strip_prefix('<')?
        .strip_suffix('>')
        .map(str::trim)
}

/// Element type of a list type (`Vec<T>`).
pub fn element(ty: &str) -> Option<&str> {
    wrapped(bare(ty), "Vec")
}

/// Value type of a map type (`BTreeMap<String, T>`).
pub fn map_value(ty: &str) -> Option<&str> {
    let inner = wrapped(bare(ty), "BTreeMap")?;
    inner.split_once(',').map(|(_, v)| v.trim())
}

/// The fields a variant is written with in parentheses: its named fields, or the fields of the
/// one struct it wraps (newtype variants are written unwrapped).
pub fn variant_fields(v: &'static Variant) -> Option<&'static [Field]> {
    match &v.args {
        Args::Named(f) => Some(f),
        Args::Tuple(a) if a.len() == 1 => fields(a[0]),
        _ => None,
    }
}

/// A value of `ty` as RON text: what completion inserts and what the table's test parses.
pub fn sample(ty: &str) -> String {
    sample_at(ty, 0)
}

fn sample_at(ty: &str, depth: usize) -> String {
    let t = bare(ty);
    if wrapped(t, "Vec").is_some() {
        return "[]".into();
    }
    if wrapped(t, "BTreeMap").is_some() {
        return "{}".into();
    }
    match t {
        "f32" | "f64" => return "1.0".into(),
        "u8" | "u16" | "u32" | "u64" | "usize" | "i64" => return "1".into(),
        "bool" => return "true".into(),
        "Vec3" => return "(0.0, 0.0, 0.0)".into(),
        "(f32, f32)" => return "(0.0, 0.0)".into(),
        _ if t == "String" || NAME_TYPES.contains(&t) => return "\"name\"".into(),
        _ => {}
    }
    match get(t).map(|d| &d.form) {
        Some(Form::Struct(f)) => format!("({})", required_fields(f, depth)),
        Some(Form::Enum(v)) if !v.is_empty() && depth < 8 => template_at(&v[0], depth + 1),
        Some(Form::Either(alts)) if !alts.is_empty() => sample_at(alts[0], depth + 1),
        _ => "()".into(),
    }
}

fn required_fields(f: &[Field], depth: usize) -> String {
    f.iter()
        .filter(|f| f.required)
        .map(|f| format!("{}: {}", f.name, sample_at(f.ty, depth + 1)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A variant written with sample values: `Within(Food, 1.0)`, `Chase()`, `Stop`.
pub fn template(v: &'static Variant) -> String {
    template_at(v, 0)
}

fn template_at(v: &'static Variant, depth: usize) -> String {
    if let Some(f) = variant_fields(v) {
        return format!("{}({})", v.name, required_fields(f, depth));
    }
    match &v.args {
        Args::Unit => v.name.to_string(),
        Args::Tuple(a) => {
            let args: Vec<String> = a.iter().map(|t| sample_at(t, depth + 1)).collect();
            match args.as_slice() {
                // One tuple (a vector) is written unwrapped: `Point(0.0, 0.0, 0.0)`.
                [one] if one.starts_with('(') => format!("{}{one}", v.name),
                _ => format!("{}({})", v.name, args.join(", ")),
            }
        }
        Args::Named(_) => format!("{}()", v.name),
    }
}

/// A variant's one-line signature: `Within(Category, f32)`, `Chase(target: Category, …)`.
pub fn signature(v: &'static Variant) -> String {
    if let Some(f) = variant_fields(v) {
        let fs: Vec<String> = f.iter().map(|f| format!("{}: {}", f.name, f.ty)).collect();
        return format!("{}({})", v.name, fs.join(", "));
    }
    match &v.args {
        Args::Unit => v.name.to_string(),
        Args::Tuple(a) => format!("{}({})", v.name, a.join(", ")),
        Args::Named(_) => format!("{}()", v.name),
    }
}

/// Parses a table's text (see the module header).
fn parse(text: &'static str) -> Vec<TypeDef> {
    let mut out: Vec<TypeDef> = Vec::new();
    for line in text.lines() {
        if line.trim().is_empty() || line.starts_with('#') {
            continue;
        }
        let (head, doc) = line.split_once(" | ").unwrap_or((line, ""));
        let doc = doc.replace("\\|", "|");
        let indent = head.len() - head.trim_start().len();
        let head = head.trim();
        if indent == 0 {
            let (kind, rest) = head.split_once(' ').unwrap_or((head, ""));
            let form = match kind {
                "struct" => Form::Struct(Vec::new()),
                "enum" => Form::Enum(Vec::new()),
                _ => Form::Either(
                    rest.split_once(':')
                        .map(|(_, a)| a.split(',').map(str::trim).collect())
                        .unwrap_or_default(),
                ),
            };
            let name = rest.split(':').next().unwrap_or(rest).trim();
            out.push(TypeDef { name, doc, form });
            continue;
        }
        let Some(t) = out.last_mut() else { continue };
        match (&mut t.form, indent) {
            (Form::Struct(f), 2) => f.push(field(head, doc)),
            (Form::Enum(v), 2) => v.push(variant_line(head, doc)),
            (Form::Enum(v), 4) => {
                if let Some(Variant {
                    args: Args::Named(f),
                    ..
                }) = v.last_mut()
                {
                    f.push(field(head, doc));
                }
            }
            _ => {}
        }
    }
    out
}

fn field(head: &'static str, doc: String) -> Field {
    let (name, ty) = head.split_once(':').unwrap_or((head, ""));
    let ty = ty.trim();
    let (ty, required) = match ty.strip_suffix('!') {
        Some(t) => (t.trim(), true),
        None => (ty, false),
    };
    Field {
        name: name.trim(),
        ty,
        required,
        doc,
    }
}

fn variant_line(head: &'static str, doc: String) -> Variant {
    if let Some(name) = head.strip_suffix("{}") {
        return Variant {
            name,
            args: Args::Named(Vec::new()),
            doc,
        };
    }
    match head.split_once('(') {
        Some((name, rest)) => {
            let inner = rest.strip_suffix(')').unwrap_or(rest);
            Variant {
                name,
                args: Args::Tuple(split_top(inner)),
                doc,
            }
        }
        None => Variant {
            name: head,
            args: Args::Unit,
            doc,
        },
    }
}

/// Splits `A, B<C, D>, (f32, f32)` at its top-level commas.
fn split_top(s: &'static str) -> Vec<&'static str> {
    let mut out = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (i, c) in s.char_indices() {
        match c {
            '<' | '(' => depth += 1,
            '>' | ')' => depth -= 1,
            ',' if depth == 0 => {
                out.push(s[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    if !s[start..].trim().is_empty() {
        out.push(s[start..].trim());
    }
    out
}

/// The serialized default of the struct `ty`, for the types that have one (completion shows a
/// field's default; the JSON Schemas carry it).
pub fn default_of(ty: &str) -> Option<serde_json::Value> {
    use crate::drives::DriveParams;
    use crate::formation::PlanningParams;
    use crate::params::locomotion::{AnimParams, BodyLimits, RigidParams};
    use crate::params::steering::{AvoidParams, WanderParams, Zones};
    use crate::perception::SenseParams;
    use crate::scenario::{DrivesOverride, FoodDef, RecordDef};
    use crate::species::{
        AttributesDef, BodyDef, ChaseDef, CruiseDef, DisperseDef, DrivesDef, EscapeDef,
        GroupRuleDef, HoldDef, LookAheadDef, LookDef, PursueDef, RelationsDef, SeekDef, VicsekDef,
    };
    use crate::terrain::Mobility;
    macro_rules! defaults {
        ($($t:ident),*) => {
            match ty {
                $(stringify!($t) => serde_json::to_value($t::default()).ok(),)*
                _ => None,
            }
        };
    }
    defaults!(
        DriveParams,
        PlanningParams,
        AnimParams,
        BodyLimits,
        RigidParams,
        AvoidParams,
        WanderParams,
        Zones,
        SenseParams,
        DrivesOverride,
        FoodDef,
        RecordDef,
        AttributesDef,
        BodyDef,
        ChaseDef,
        CruiseDef,
        DisperseDef,
        DrivesDef,
        EscapeDef,
        GroupRuleDef,
        HoldDef,
        LookAheadDef,
        LookDef,
        PursueDef,
        RelationsDef,
        SeekDef,
        VicsekDef,
        Mobility
    )
}

/// A field's default as RON-like text (`0.5`, `Kinematic`), when its type has a default.
pub fn field_default(owner: &str, field: &str) -> Option<String> {
    let v = default_of(owner)?.get(field)?.clone();
    Some(json_as_ron(&v))
}

fn json_as_ron(v: &serde_json::Value) -> String {
    use serde_json::Value as J;
    match v {
        J::Null => "None".into(),
        J::Bool(b) => b.to_string(),
        J::Number(n) => {
            let f = n.as_f64().unwrap_or(0.0);
            if n.is_f64() {
                let s = format!("{}", f as f32);
                if s.contains('.') || s.contains('e') || s.contains("inf") {
                    s
                } else {
                    format!("{s}.0")
                }
            } else {
                n.to_string()
            }
        }
        J::String(s) => s.clone(),
        J::Array(a) => {
            let parts: Vec<String> = a.iter().map(json_as_ron).collect();
            if a.len() == 3 && a.iter().all(|x| x.is_number()) {
                format!("({})", parts.join(", "))
            } else {
                format!("[{}]", parts.join(", "))
            }
        }
        J::Object(m) if m.len() == 1 => {
            let (k, v) = m.iter().next().expect("one entry");
            if k == "Some" {
                json_as_ron(v)
            } else {
                format!(
                    "{k}({})",
                    json_as_ron(v).trim_matches(|c| c == '(' || c == ')')
                )
            }
        }
        J::Object(m) => {
            let parts: Vec<String> = m
                .iter()
                .map(|(k, v)| format!("{k}: {}", json_as_ron(v)))
                .collect();
            format!("({})", parts.join(", "))
        }
    }
}
