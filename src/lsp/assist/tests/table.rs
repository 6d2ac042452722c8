//! The format table against the real serde types (a variant missing from it is caught), and
//! the script API fully documented (also in the Rhai definitions).

use crate::load::ron_options;
use crate::lsp::assist::api::{self, Api};
use crate::lsp::assist::schema::{self, Args, Form, NAME_TYPES, PLAIN_TYPES};
use serde::de::DeserializeOwned;

/// Problems of the table's type `name` against the real type `T`: the field or variant lists
/// differ, or a variant's template does not parse.
fn check_type<T: DeserializeOwned + serde::Serialize>(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let Some(t) = schema::get(name) else {
        return vec![format!("{name} is not in the table")];
    };
    let (probe, listed): (&str, Vec<&str>) = match &t.form {
        Form::Struct(f) => ("(zz_not_a_key: 0)", f.iter().map(|f| f.name).collect()),
        Form::Enum(v) => ("ZzNotAVariant", v.iter().map(|v| v.name).collect()),
        Form::Either(alts) => {
            for alt in alts {
                let s = schema::sample(alt);
                if let Err(e) = ron_options().from_str::<T>(&s) {
                    out.push(format!("{name}: {s} does not parse: {e}"));
                }
            }
            return out;
        }
    };
    let mut real: Vec<&str> = match ron_options().from_str::<T>(probe).map_err(|e| e.code) {
        Err(::ron::Error::NoSuchStructField { expected, .. })
        | Err(::ron::Error::NoSuchEnumVariant { expected, .. }) => expected.to_vec(),
        Err(::ron::Error::MissingStructField { .. }) => {
            // Unknown keys are ignored by this type: write every listed key and read back
            // the keys the type keeps.
            let all: Vec<String> = match &t.form {
                Form::Struct(f) => f
                    .iter()
                    .map(|f| format!("{}: {}", f.name, schema::sample(f.ty)))
                    .collect(),
                _ => Vec::new(),
            };
            let text = format!("({})", all.join(", "));
            match ron_options().from_str::<T>(&text) {
                Ok(v) => match serde_json::to_value(&v) {
                    Ok(serde_json::Value::Object(m)) => {
                        m.keys().map(|k| &*k.clone().leak()).collect()
                    }
                    other => return vec![format!("{name}: serialized as {other:?}")],
                },
                Err(e) => return vec![format!("{name}: `{text}` does not parse: {e}")],
            }
        }
        other => return vec![format!("{name}: {probe} gave {:?}", other.err())],
    };
    let mut listed_sorted = listed.clone();
    listed_sorted.sort_unstable();
    real.sort_unstable();
    if listed_sorted != real {
        out.push(format!(
            "{name}: the table has {listed_sorted:?}, the type {real:?}"
        ));
    }
    if let Form::Enum(vs) = &t.form {
        for v in vs {
            let s = schema::template(v);
            if let Err(e) = ron_options().from_str::<T>(&s) {
                out.push(format!("{name}: `{s}` does not parse: {e}"));
            }
        }
    }
    if let Form::Struct(_) = &t.form {
        let s = schema::sample(name);
        if let Err(e) = ron_options().from_str::<T>(&s) {
            out.push(format!(
                "{name}: `{s}` (the required fields) does not parse: {e}"
            ));
        }
    }
    out
}

#[test]
fn the_table_matches_the_serde_types() {
    use crate::drives::{DriveParams, HungerModel};
    use crate::events::MessageKind;
    use crate::formation::astar::{ClassFactors, PlanningParams};
    use crate::params::locomotion::{AnimParams, BodyLimits, Mode, RigidParams};
    use crate::params::steering::{AvoidParams, Prediction, VisionTurn, WanderParams, Zones};
    use crate::perception::{
        Category, Extent, Level, Occluders, Sector, Sectors, SenseParams, Strength, Volume,
    };
    use crate::scenario::def::*;
    use crate::species::def::*;
    use crate::terrain::Mobility;
    use crate::world::Aabb;
    let mut problems = Vec::new();
    let mut checked = Vec::new();
    macro_rules! check {
        ($($t:ident),* $(,)?) => {$(
            problems.extend(check_type::<$t>(stringify!($t)));
            checked.push(stringify!($t));
        )*};
    }
    check!(
        SpeciesDef,
        BodyDef,
        SenseParams,
        AvoidParams,
        AttributesDef,
        DrivesDef,
        RelationsDef,
        BehaviorDef,
        Recipe,
        LookDef,
        EventDef,
        MemDecl,
        BodyLimits,
        Mode,
        AnimParams,
        Mobility,
        Volume,
        Occluders,
        Extent,
        Strength,
        Sectors,
        SexDef,
        Draw,
        DriveParams,
        Cond,
        Contact,
        Action,
        Category,
        Weighted,
        LookAheadDef,
        ChaseDef,
        EscapeDef,
        PursueDef,
        SeekDef,
        GroupRuleDef,
        Zones,
        VicsekDef,
        DisperseDef,
        WanderParams,
        CruiseDef,
        HoldDef,
        ShapeDef,
        FieldType,
        RigidParams,
        HungerModel,
        Value,
        Sector,
        Level,
        MessageRef,
        VisionTurn,
        Prediction,
        Target,
        DriveKind,
        AttrKind,
        MessageKind,
        ScenarioDef,
        Aabb,
        ObstacleDef,
        FoodDef,
        SpawnGroupDef,
        TimedEvent,
        RecordDef,
        Expectation,
        TerrainDef,
        SquadDef,
        HeadingDef,
        DrivesOverride,
        EventAction,
        PlanningParams,
        SquadLeader,
        ClassFactors,
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // Every type of the table is checked, and every type a field names is in the table.
    for t in schema::types() {
        assert!(
            checked.contains(&t.name),
            "{} is not checked against its type",
            t.name
        );
    }
    let mut named: Vec<&str> = Vec::new();
    for t in schema::types() {
        match &t.form {
            Form::Struct(f) => named.extend(f.iter().map(|f| f.ty)),
            Form::Enum(v) => {
                for v in v {
                    match &v.args {
                        Args::Tuple(a) => named.extend(a.iter().copied()),
                        Args::Named(f) => named.extend(f.iter().map(|f| f.ty)),
                        Args::Unit => {}
                    }
                }
            }
            Form::Either(a) => named.extend(a.iter().copied()),
        }
    }
    for ty in named {
        let mut t = schema::bare(ty);
        t = schema::element(t)
            .or_else(|| schema::map_value(t))
            .map_or(t, schema::bare);
        let known = schema::get(t).is_some()
            || PLAIN_TYPES.contains(&t)
            || NAME_TYPES.contains(&t)
            || t == "(f32, f32)";
        assert!(known, "type {ty} of the table is unknown");
    }
}

#[test]
fn a_variant_missing_from_the_table_is_caught() {
    // `Level` checked as if it were `Sector`: the lists differ and it is said.
    let p = check_type::<crate::perception::Level>("Sector");
    assert!(p.iter().any(|p| p.contains("the table has")), "{p:?}");
    let p = check_type::<crate::species::def::ChaseDef>("SeekDef");
    assert!(p.iter().any(|p| p.contains("the table has")), "{p:?}");
}

#[test]
fn every_registered_api_function_has_documentation() {
    let mut missing = Vec::new();
    for api in [Api::Script, Api::Test] {
        let fns = api::functions(api);
        assert!(fns.len() > 20, "{api:?}: {} functions", fns.len());
        for f in fns {
            if f.doc.is_none() {
                missing.push(format!("{api:?}: {}", f.signature()));
            }
        }
    }
    assert!(missing.is_empty(), "undocumented:\n{}", missing.join("\n"));
    // Rhai's own library is not part of the API.
    let script = api::functions(Api::Script);
    assert!(!script.iter().any(|f| f.name == "sin" || f.name == "len"));
    assert!(script
        .iter()
        .any(|f| f.name == "vec3" && f.receiver.is_empty()));
    let test = api::functions(Api::Test);
    assert!(test.iter().any(|f| f.name == "assert_behavior"));
    assert!(
        !test.iter().any(|f| f.name == "seek"),
        "script API listed as test API"
    );
}

#[test]
fn rhai_definitions_list_the_this_api() {
    let d = api::definitions(Api::Script);
    for f in ["fn seek(", "fn arrive(", "get pos(", "fn vec3("] {
        assert!(d.contains(f), "{f} missing from the definitions:\n{d}");
    }
    let t = api::definitions(Api::Test);
    assert!(
        t.contains("fn assert_behavior(") && t.contains("fn seek("),
        "{t}"
    );
}
