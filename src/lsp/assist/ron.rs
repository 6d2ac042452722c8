//! Completion and hover in species and scenario files: the cursor's brackets ([`super::cursor`])
//! are matched against the format's table ([`super::schema`]) from the file's root type down, so
//! each open bracket gets a type; the keys of a struct, the variants of an enum and the project's
//! names are offered where that type expects them, with their reference entries.

use super::cursor::{self, Cursor, Frame};
use super::schema::{self, Args, Field, Form, Variant};
use super::{reference, seeds, FileKind, Hover, Item, ItemKind, ProjectNames};

/// What an open bracket holds.
#[derive(Debug, Clone)]
enum Slot {
    /// Named fields of `owner` (a struct, or a variant written with fields).
    Fields {
        owner: &'static str,
        fields: &'static [Field],
        variant: Option<&'static str>,
    },
    /// Positional values of these types.
    Tuple(Vec<&'static str>),
    /// A list of this type.
    List(&'static str),
    /// A map with values of this type.
    Map(&'static str),
    /// `Some(…)` around a value of this type (a struct's fields may be written directly).
    Some(&'static str),
    /// Nothing the table knows (a vector, a broken spot).
    Unknown,
}

/// The root type of a file kind.
fn root(kind: FileKind) -> Option<&'static str> {
    match kind {
        FileKind::Species => Some("SpeciesDef"),
        FileKind::Scenario => Some("ScenarioDef"),
        _ => None,
    }
}

/// The reference of a file kind.
fn doc_of(kind: FileKind) -> &'static str {
    if kind == FileKind::Scenario {
        reference::SCENARIOS
    } else {
        reference::SPECIES
    }
}

/// The slot a bracket opens where a value of type `ty` is expected.
fn open(ty: &'static str, f: &Frame) -> Slot {
    let t = schema::bare(ty);
    match f.open {
        b'[' => schema::element(t).map_or(Slot::Unknown, Slot::List),
        b'{' => schema::map_value(t).map_or(Slot::Unknown, Slot::Map),
        // `Some(…)` around an optional value: the value itself.
        _ if f.name == "Some" => Slot::Some(t),
        _ => {
            if let Some(fields) = schema::fields(t) {
                return Slot::Fields {
                    owner: schema::get(t).map_or("", |d| d.name),
                    fields,
                    variant: None,
                };
            }
            let Some(v) = schema::variant(t, f.name) else {
                return Slot::Unknown;
            };
            if let Some(fields) = schema::variant_fields(v) {
                let owner = match &v.args {
                    Args::Tuple(a) => a[0],
                    _ => v.name,
                };
                return Slot::Fields {
                    owner,
                    fields,
                    variant: Some(v.name),
                };
            }
            match &v.args {
                Args::Tuple(a) => Slot::Tuple(a.clone()),
                _ => Slot::Unknown,
            }
        }
    }
}

/// The type expected at the frame's current position, if any (`None` where a key is expected).
fn expected(slot: &Slot, f: &Frame) -> Option<&'static str> {
    match slot {
        Slot::Fields { fields, .. } => {
            let k = f.key?;
            fields.iter().find(|x| x.name == k).map(|x| x.ty)
        }
        Slot::Tuple(a) => a.get(f.commas).copied(),
        Slot::List(t) => Some(t),
        Slot::Map(t) => f.key.map(|_| *t),
        Slot::Some(t) => match (f.key, schema::fields(t)) {
            (Some(k), Some(fields)) => fields.iter().find(|x| x.name == k).map(|x| x.ty),
            (None, Some(_)) => None,
            _ => Some(t),
        },
        Slot::Unknown => None,
    }
}

/// The fields written in a slot, with their owner type and variant.
fn fields_of(slot: &Slot) -> Option<(&'static str, &'static [Field], Option<&'static str>)> {
    match slot {
        Slot::Fields {
            owner,
            fields,
            variant,
        } => Some((owner, fields, *variant)),
        Slot::Some(t) => schema::fields(t).map(|f| (*t, f, None)),
        _ => None,
    }
}

/// The slots of every frame of the cursor, outermost first. A named bracket the scan cannot
/// type where it stands (a bracket left open above it) is typed by the nearest list around it
/// that holds values of that name (`Behavior(` in `behaviors: [`).
fn slots(kind: FileKind, cur: &Cursor) -> Vec<Slot> {
    let mut out: Vec<Slot> = Vec::new();
    let mut ty = root(kind);
    for f in &cur.frames {
        if ty.is_none() && f.name.is_empty() {
            // `Some((field: …))`: the struct in parentheses inside `Some(`.
            if let Some(Slot::Some(t)) = out.last() {
                ty = Some(t);
            }
        }
        let mut slot = ty.map_or(Slot::Unknown, |t| open(t, f));
        if matches!(slot, Slot::Unknown) && !f.name.is_empty() {
            slot = out
                .iter()
                .rev()
                .find_map(|s| match s {
                    Slot::List(t) if accepts(t, f.name) => Some(open(t, f)),
                    _ => None,
                })
                .unwrap_or(Slot::Unknown);
        }
        ty = expected(&slot, f);
        out.push(slot);
    }
    out
}

/// Whether a value of type `ty` may be written `name(…)`: a struct of that name (`Behavior` for
/// `BehaviorDef`) or a variant.
fn accepts(ty: &str, name: &str) -> bool {
    let t = schema::bare(ty);
    match schema::get(t).map(|d| &d.form) {
        Some(Form::Struct(_)) => t == name || t.strip_suffix("Def") == Some(name),
        Some(_) => schema::variant(t, name).is_some(),
        None => false,
    }
}

/// Completion items at `offset`.
pub fn complete(kind: FileKind, text: &str, offset: usize, names: &ProjectNames) -> Vec<Item> {
    let cur = cursor::at(text, offset);
    let slots = slots(kind, &cur);
    let (Some(slot), Some(f)) = (slots.last(), cur.frames.last()) else {
        return Vec::new();
    };
    let doc = doc_of(kind);
    if cur.in_string {
        return expected(slot, f).map_or_else(Vec::new, |t| name_items(t, names, false));
    }
    match (fields_of(slot), expected(slot, f)) {
        (Some((owner, fields, variant)), None) => fields
            .iter()
            .filter(|x| !f.keys.contains(&x.name) || x.name == cur.prefix)
            .map(|x| key_item(doc, owner, variant, x))
            .collect(),
        (_, Some(t)) => values(doc, t, names),
        _ => Vec::new(),
    }
}

fn key_item(doc: &str, owner: &str, variant: Option<&str>, f: &Field) -> Item {
    let detail = match schema::field_default(owner, f.name) {
        _ if f.required => format!("{}: {} (required)", f.name, f.ty),
        Some(d) => format!("{}: {} = {d}", f.name, f.ty),
        None => format!("{}: {}", f.name, f.ty),
    };
    Item {
        label: f.name.to_string(),
        kind: ItemKind::Key,
        detail,
        doc: field_doc(doc, owner, variant, f),
        insert: Some(format!("{}: ", f.name)),
    }
}

/// A field's reference entry (preferring its owner's section), else its doc line.
fn field_doc(doc: &str, owner: &str, variant: Option<&str>, f: &Field) -> String {
    let section = variant
        .or_else(|| owner.strip_suffix("Def"))
        .unwrap_or(owner);
    let entry = variant
        .and_then(|v| reference::entry(doc, v, None))
        .filter(|e| reference::names(e, f.name))
        .or_else(|| reference::entry(doc, f.name, Some(section)));
    join(&f.doc, entry)
}

fn join(line: &str, entry: Option<String>) -> String {
    match entry {
        Some(e) if line.is_empty() => e,
        Some(e) => format!("{line}\n\n{e}"),
        None => line.to_string(),
    }
}

/// The values a value of type `ty` may be: variants, `true`/`false`, or the project's names.
fn values(doc: &str, ty: &'static str, names: &ProjectNames) -> Vec<Item> {
    let t = schema::bare(ty);
    if t == "bool" {
        return ["true", "false"]
            .iter()
            .map(|b| Item {
                label: b.to_string(),
                kind: ItemKind::Constant,
                detail: "bool".into(),
                doc: String::new(),
                insert: None,
            })
            .collect();
    }
    let mut out: Vec<Item> = schema::variants(t)
        .into_iter()
        .map(|v| variant_item(doc, v))
        .collect();
    out.extend(name_items(t, names, true));
    out
}

/// The item of a variant: its signature, reference entry and a template to insert.
pub fn variant_item(doc: &str, v: &'static Variant) -> Item {
    let template = schema::template(v);
    Item {
        label: v.name.to_string(),
        kind: ItemKind::Variant,
        detail: schema::signature(v),
        doc: join(&v.doc, reference::entry(doc, v.name, None)),
        insert: (template != v.name).then_some(template),
    }
}

/// The project's names where a value of `ty` names one (`quote`: the cursor is not yet in a
/// string, so the item inserts the quotes).
fn name_items(ty: &str, names: &ProjectNames, quote: bool) -> Vec<Item> {
    let t = schema::bare(ty);
    let t = schema::element(t).unwrap_or(t);
    let (list, kind, what) = match t {
        "SpeciesName" => (&names.species, ItemKind::Species, "species"),
        "BehaviorName" => (&names.behaviors, ItemKind::Behavior, "behavior"),
        "FunctionName" => (&names.functions, ItemKind::Function, "script function"),
        _ => return Vec::new(),
    };
    list.iter()
        .map(|n| Item {
            label: n.clone(),
            kind,
            detail: what.to_string(),
            doc: String::new(),
            insert: quote.then(|| format!("\"{n}\"")),
        })
        .collect()
}

/// Hover for the word at `offset`: a key's or variant's reference entry, and for a seed
/// constant its paper default and section.
pub fn hover(kind: FileKind, text: &str, offset: usize) -> Option<Hover> {
    let (word, start, end) = cursor::word_at(text, offset)?;
    let cur = cursor::at(text, start);
    let slots = slots(kind, &cur);
    let doc = doc_of(kind);
    let is_key = cursor::tokens(&text[end..])
        .first()
        .is_some_and(|t| t.0 == cursor::Tok::Colon);
    let markdown = if is_key {
        let (owner, fields, variant) = fields_of(slots.last()?)?;
        let field = fields.iter().find(|x| x.name == word)?;
        let head = format!("`{}: {}`", field.name, field.ty);
        let mut md = format!("{head}\n\n{}", field_doc(doc, owner, variant, field));
        if let Some(s) = seeds::describe(&seed_key(&cur, &slots, word)) {
            md.push_str("\n\n");
            md.push_str(&s);
        }
        md
    } else {
        let ty = match (slots.last(), cur.frames.last()) {
            (Some(s), Some(f)) => expected(s, f),
            _ => None,
        };
        let v = ty
            .and_then(|t| schema::variant(schema::element(t).unwrap_or(t), word))
            .or_else(|| any_variant(word))?;
        let item = variant_item(doc, v);
        format!("`{}`\n\n{}", item.detail, item.doc)
    };
    Some(Hover {
        markdown,
        start,
        end,
    })
}

/// A variant of any enum of the table named `word` (hover on a word the cursor scan could not
/// type, e.g. in a broken document).
fn any_variant(word: &str) -> Option<&'static Variant> {
    schema::types().iter().find_map(|t| match &t.form {
        Form::Enum(v) => v.iter().find(|v| v.name == word),
        _ => None,
    })
}

/// The seed-constant key of `word` written at the cursor: `Chase(max_turn)` inside a variant,
/// else the dotted path of keys from the root (`senses.sectors.front`, `squads[].planning.k1`).
fn seed_key(cur: &Cursor, slots: &[Slot], word: &str) -> String {
    if let Some(Slot::Fields {
        variant: Some(v), ..
    }) = slots.last()
    {
        return format!("{v}({word})");
    }
    let mut path = String::new();
    // The key of each frame that holds the next one.
    for (i, f) in cur.frames.iter().enumerate() {
        if i + 1 == cur.frames.len() {
            break;
        }
        match (f.key, cur.frames[i + 1].open) {
            (Some(k), b'[') => {
                path.push_str(k);
                path.push_str("[].");
            }
            (Some(k), _) if !k.is_empty() => {
                path.push_str(k);
                path.push('.');
            }
            _ => {}
        }
    }
    path.push_str(word);
    path
}
