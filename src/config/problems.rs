//! Every problem of a scene document at once: unknown keys (with the
//! nearest valid name), values of the wrong type and missing keys.
//!
//! serde stops at the first error, so the document is deserialised again
//! after each one with the culprit taken out (an unknown key or a bad
//! value removed, a missing or removed value replaced by a stand-in of a
//! type the schema takes), until it passes.

use super::overrides::Part;
use super::{SceneConfig, humanize};

/// What is wrong at a key.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Kind {
    /// A key the table does not take; the keys it does.
    Unknown(Vec<String>),
    /// A value of the wrong type or an unknown name (serde's words,
    /// humanised).
    Invalid(String),
    /// A required key or table that is absent.
    Missing,
}

impl Kind {
    /// The order problems are reported in: unknown keys (whose misspelling
    /// often explains a missing key), bad values, missing keys.
    pub fn rank(&self) -> u8 {
        match self {
            Kind::Unknown(_) => 0,
            Kind::Invalid(_) => 1,
            Kind::Missing => 2,
        }
    }
}

/// One problem and the key it is at.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Problem {
    pub parts: Vec<Part>,
    pub kind: Kind,
}

/// At most this many problems are collected (a file of another kind
/// would otherwise list hundreds).
const MAX_PROBLEMS: usize = 50;

/// The config, or every problem found (unknown keys first, then bad
/// values, then missing keys).
pub(super) fn check(table: &toml::Table) -> Result<SceneConfig, Vec<Problem>> {
    let mut doc = table.clone();
    let mut problems: Vec<Problem> = Vec::new();
    // Keys already reported or filled in: nothing below them is reported.
    let mut quiet: Vec<Vec<Part>> = Vec::new();
    let mut last_error = None;
    for _ in 0..4 * MAX_PROBLEMS {
        let (parts, message) = match attempt(&doc) {
            Ok(config) if problems.is_empty() => return Ok(config),
            Ok(_) => break,
            Err(e) => e,
        };
        if last_error.as_ref() == Some(&(parts.clone(), message.clone()))
            || problems.len() >= MAX_PROBLEMS
        {
            break;
        }
        last_error = Some((parts.clone(), message.clone()));
        let hushed = quiet.iter().any(|q| parts.starts_with(q));
        if let Some((field, expected)) = unknown_field(&message) {
            // The path may or may not end at the key itself.
            let mut at = parts.clone();
            if at.last() != Some(&Part::Key(field.clone())) {
                at.push(Part::Key(field));
            }
            if !hushed {
                problems.push(Problem {
                    parts: at.clone(),
                    kind: Kind::Unknown(expected),
                });
            }
            if !remove(&mut doc, &at) {
                break;
            }
        } else if let Some(field) = missing_field(&message) {
            let mut at = parts.clone();
            at.push(Part::Key(field));
            if !hushed && !quiet.iter().any(|q| at.starts_with(q)) {
                problems.push(Problem {
                    parts: at.clone(),
                    kind: Kind::Missing,
                });
            }
            quiet.push(at.clone());
            if !stand_in(&mut doc, &at) {
                break;
            }
        } else {
            if !hushed {
                problems.push(Problem {
                    parts: parts.clone(),
                    kind: Kind::Invalid(humanize(&message).replace('\n', " ")),
                });
            }
            quiet.push(parts.clone());
            // A table key goes; a list entry is replaced, so that the
            // entries after it keep their numbers.
            let done = match parts.last() {
                Some(Part::Key(_)) => remove(&mut doc, &parts),
                Some(Part::Index(_)) => stand_in(&mut doc, &parts),
                None => false,
            };
            if !done {
                break;
            }
        }
    }
    problems.sort_by_key(|p| p.kind.rank());
    if problems.is_empty() {
        // Nothing could be said about the first error: report it as is.
        if let Err((parts, message)) = attempt(table) {
            problems.push(Problem {
                parts,
                kind: Kind::Invalid(humanize(&message).replace('\n', " ")),
            });
        }
    }
    Err(problems)
}

/// One deserialisation: the config, or the first error and its key.
fn attempt(doc: &toml::Table) -> Result<SceneConfig, (Vec<Part>, String)> {
    first_error::<SceneConfig>(doc).map_err(|(parts, message)| refine(doc, parts, message))
}

/// `T` from `table`, or its first error and the key it is at.
fn first_error<T: serde::de::DeserializeOwned>(
    table: &toml::Table,
) -> Result<T, (Vec<Part>, String)> {
    serde_path_to_error::deserialize(toml::Value::Table(table.clone())).map_err(
        |e: serde_path_to_error::Error<toml::de::Error>| {
            let mut parts = Vec::new();
            for s in e.path().iter() {
                match s {
                    serde_path_to_error::Segment::Map { key } => parts.push(Part::Key(key.clone())),
                    serde_path_to_error::Segment::Seq { index } => parts.push(Part::Index(*index)),
                    serde_path_to_error::Segment::Enum { .. } => {}
                    serde_path_to_error::Segment::Unknown => break,
                }
            }
            (parts, e.inner().message().to_string())
        },
    )
}

/// The error at the key inside a table chosen by its `kind` (an object, a
/// light, a material, the medium), which serde reports at the table itself: found by
/// reading the table as the struct its kind names.
fn refine(doc: &toml::Table, parts: Vec<Part>, message: String) -> (Vec<Part>, String) {
    use super::{
        GlowConfig, Gold2020Config, MeshConfig, RectangleConfig, SphereConfig, SunConfig,
        SurfaceConfig, SynchrotronConfig, UniformConfig,
    };
    let Some(toml::Value::Table(t)) = value_at(doc, &parts) else {
        return (parts, message);
    };
    let Some(kind) = t.get("kind").and_then(toml::Value::as_str) else {
        return (parts, message);
    };
    let mut body = t.clone();
    body.remove("kind");
    let place = match parts.as_slice() {
        [Part::Key(l), Part::Index(_)] if l == "object" => "object",
        [Part::Key(l), Part::Index(_)] if l == "light" => "light",
        [.., Part::Key(m)] if m == "material" => "material",
        [Part::Key(m)] if m == "medium" => "medium",
        _ => "",
    };
    let inner = match (place, kind) {
        ("object", "sphere") => first_error::<SphereConfig>(&body).err(),
        ("object", "rectangle") => first_error::<RectangleConfig>(&body).err(),
        ("object", "mesh") => first_error::<MeshConfig>(&body).err(),
        ("light", "sun") => first_error::<SunConfig>(&body).err(),
        ("light", "disk" | "ambient") => first_error::<GlowConfig>(&body).err(),
        ("material", "color" | "mirror" | "lit") => first_error::<SurfaceConfig>(&body).err(),
        ("medium", "gold2020") => first_error::<Gold2020Config>(&body).err(),
        ("medium", "uniform") => first_error::<UniformConfig>(&body).err(),
        ("medium", "synchrotron") => first_error::<SynchrotronConfig>(&body).err(),
        _ => None,
    };
    match inner {
        Some((sub, m)) if sub.is_empty() => (parts, m),
        Some((sub, m)) => {
            let full: Vec<Part> = parts.iter().cloned().chain(sub).collect();
            refine(doc, full, m)
        }
        None => (parts, message),
    }
}

/// The value at `parts`.
fn value_at<'a>(doc: &'a toml::Table, parts: &[Part]) -> Option<&'a toml::Value> {
    let (first, rest) = parts.split_first()?;
    let Part::Key(k) = first else {
        return None;
    };
    let mut v = doc.get(k)?;
    for p in rest {
        v = match (p, v) {
            (Part::Key(k), toml::Value::Table(t)) => t.get(k)?,
            (Part::Index(i), toml::Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// The field and the expected names of serde's "unknown field `x`,
/// expected one of `a`, `b`" (or "expected `a`", "there are no fields").
fn unknown_field(message: &str) -> Option<(String, Vec<String>)> {
    let rest = message.strip_prefix("unknown field `")?;
    let (field, rest) = rest.split_once('`')?;
    Some((field.to_string(), quoted(rest)))
}

/// The field of serde's "missing field `x`".
fn missing_field(message: &str) -> Option<String> {
    let rest = message.strip_prefix("missing field `")?;
    Some(rest.split_once('`')?.0.to_string())
}

/// The names of serde's "unknown variant `x`, expected one of `a`, `b`".
fn unknown_variant(message: &str) -> Option<Vec<String>> {
    let rest = message.strip_prefix("unknown variant `")?;
    let names = quoted(rest.split_once('`')?.1);
    (!names.is_empty()).then_some(names)
}

/// Every `backquoted` word of `text`.
fn quoted(text: &str) -> Vec<String> {
    text.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The value at `parts`, as a place to change.
fn parent<'a>(doc: &'a mut toml::Table, parts: &[Part]) -> Option<Slot<'a>> {
    let mut slot = Slot::Table(doc);
    for p in parts {
        let v = match (slot, p) {
            (Slot::Table(t), Part::Key(k)) => t.get_mut(k)?,
            (Slot::Array(a), Part::Index(i)) => a.get_mut(*i)?,
            _ => return None,
        };
        slot = match v {
            toml::Value::Table(t) => Slot::Table(t),
            toml::Value::Array(a) => Slot::Array(a),
            _ => return None,
        };
    }
    Some(slot)
}

enum Slot<'a> {
    Table(&'a mut toml::Table),
    Array(&'a mut Vec<toml::Value>),
}

/// Removes the key at `parts`; whether there was one.
fn remove(doc: &mut toml::Table, parts: &[Part]) -> bool {
    let Some((Part::Key(k), up)) = parts.split_last() else {
        return false;
    };
    match parent(doc, up) {
        Some(Slot::Table(t)) => t.remove(k).is_some(),
        _ => false,
    }
}

/// Puts `value` at `parts` (the table or list above it must exist).
fn put(doc: &mut toml::Table, parts: &[Part], value: toml::Value) -> bool {
    let Some((last, up)) = parts.split_last() else {
        return false;
    };
    match (parent(doc, up), last) {
        (Some(Slot::Table(t)), Part::Key(k)) => {
            t.insert(k.clone(), value);
            true
        }
        (Some(Slot::Array(a)), Part::Index(i)) if *i < a.len() => {
            a[*i] = value;
            true
        }
        _ => false,
    }
}

/// Fills `parts` with a value of a type the schema takes there, so that
/// the rest of the document can be checked; whether one was found.
fn stand_in(doc: &mut toml::Table, parts: &[Part]) -> bool {
    use toml::Value as V;
    let nums = |n: usize| V::Array(vec![V::Float(1.0); n]);
    let mut candidates = vec![
        V::Table(toml::Table::new()),
        V::Float(1.0),
        V::Integer(1),
        V::Boolean(false),
        V::String("x".into()),
        nums(3),
        nums(2),
        V::Array(Vec::new()),
    ];
    let mut i = 0;
    while i < candidates.len() {
        let mut trial = doc.clone();
        if !put(&mut trial, parts, candidates[i].clone()) {
            return false;
        }
        match attempt(&trial) {
            Ok(_) => {
                *doc = trial;
                return true;
            }
            Err((at, message)) => {
                // The key the error is about: a missing field's own, else
                // where it was found. It is still this key, or a table
                // above it, when the stand-in did not do.
                let mut about = at.clone();
                if let Some(f) = missing_field(&message) {
                    about.push(Part::Key(f));
                }
                let here = parts.starts_with(&about);
                if !here {
                    *doc = trial;
                    return true;
                }
                // A name the schema lists: try the first one.
                if let Some(names) = unknown_variant(&message)
                    && !candidates.contains(&V::String(names[0].clone()))
                {
                    candidates.push(V::String(names[0].clone()));
                }
            }
        }
        i += 1;
    }
    false
}

/// The valid name nearest to `key`, when it is near enough to be a slip.
pub(super) fn nearest<'a>(key: &str, names: &'a [String]) -> Option<&'a str> {
    names
        .iter()
        .map(|n| (strsim::damerau_levenshtein(key, n), n))
        .filter(|(d, n)| *d <= 2.max(n.len() / 3))
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n.as_str())
}
