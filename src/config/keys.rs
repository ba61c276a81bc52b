//! Every key the scene file takes, found by asking the schema itself: a
//! document holding only an unknown key at some place makes serde name the
//! keys that table takes (and an unknown `kind` the kinds a tagged table
//! takes), so the whole tree is walked without a second list to keep in
//! step. The user guide's key reference is checked against it.

use super::SceneConfig;
use std::collections::BTreeSet;

/// The key no table takes.
const PROBE: &str = "__probe";

/// One step of a key's place in the document.
#[derive(Clone, Debug)]
enum Step {
    /// A key of a table.
    Key(String),
    /// An element of an array of tables (`[[object]]`).
    Each,
    /// The table's `kind` (tagged tables: objects, materials, lights).
    Kind(String),
}

/// The document with `leaf` at `path`.
fn document(path: &[Step], leaf: toml::Table) -> toml::Table {
    let mut value = toml::Value::Table(leaf);
    for step in path.iter().rev() {
        value = match step {
            Step::Key(k) => toml::Value::Table(toml::Table::from_iter([(k.clone(), value)])),
            Step::Each => toml::Value::Array(vec![value]),
            Step::Kind(kind) => {
                let toml::Value::Table(mut t) = value else {
                    unreachable!("a kind is set on a table")
                };
                t.insert("kind".into(), toml::Value::String(kind.clone()));
                toml::Value::Table(t)
            }
        };
    }
    match value {
        toml::Value::Table(t) => t,
        _ => unreachable!("the document is a table"),
    }
}

/// serde's message for the document.
fn message(doc: toml::Table) -> String {
    match toml::Value::Table(doc).try_into::<SceneConfig>() {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

/// The backticked names after "expected" in serde's message (its first
/// line: the lines after it say where).
fn expected(message: &str) -> Vec<String> {
    let message = message.lines().next().unwrap_or("");
    let Some(at) = message.find("expected") else {
        return Vec::new();
    };
    message[at..]
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The keys of the table at `path`, if a table is there.
fn fields(path: &[Step]) -> Option<Vec<String>> {
    let leaf = toml::Table::from_iter([(PROBE.to_string(), toml::Value::Integer(0))]);
    let m = message(document(path, leaf));
    if m.contains(&format!("unknown field `{PROBE}`")) {
        Some(expected(&m))
    } else {
        None
    }
}

/// The kinds of the tagged table at `path`, if a tagged table is there.
fn kinds(path: &[Step]) -> Option<Vec<String>> {
    let leaf = toml::Table::from_iter([("kind".to_string(), toml::Value::String(PROBE.into()))]);
    let m = message(document(path, leaf));
    if m.contains(&format!("unknown variant `{PROBE}`")) {
        Some(expected(&m))
    } else {
        None
    }
}

/// The dotted name of a key's place (array elements and kinds leave no
/// mark: `object.material.color`).
fn dotted(path: &[Step]) -> String {
    path.iter()
        .filter_map(|s| match s {
            Step::Key(k) => Some(k.as_str()),
            _ => None,
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// Adds every leaf key below the table at `path` (whose keys are `keys`).
fn walk(path: &[Step], keys: Vec<String>, out: &mut BTreeSet<String>) {
    for key in keys {
        let mut here = path.to_vec();
        here.push(Step::Key(key));
        // A table, an array of tables, a tagged table or an array of them;
        // anything else is a leaf.
        let mut each = here.clone();
        each.push(Step::Each);
        if let Some(sub) = fields(&here) {
            walk(&here, sub, out);
        } else if let Some(sub) = fields(&each) {
            walk(&each, sub, out);
        } else if let Some((at, found)) = kinds(&here)
            .map(|k| (here.clone(), k))
            .or_else(|| kinds(&each).map(|k| (each.clone(), k)))
        {
            out.insert(format!("{}.kind", dotted(&at)));
            for kind in found {
                let mut variant = at.clone();
                variant.push(Step::Kind(kind));
                let sub = fields(&variant).expect("a kind's keys");
                walk(&variant, sub, out);
            }
        } else {
            out.insert(dotted(&here));
        }
    }
}

/// Every leaf key of the scene file, dotted (`image.width`,
/// `object.material.color`).
pub fn all() -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    walk(&[], fields(&[]).expect("the top table's keys"), &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The backticked key paths in the first cell of each table row of
    /// the guide's "Scene keys" section.
    fn documented(guide: &str) -> BTreeSet<String> {
        let section = guide
            .split("\n## ")
            .find(|s| s.starts_with("Scene keys"))
            .expect("GUIDE.md has a \"## Scene keys\" section");
        let mut keys = BTreeSet::new();
        for line in section.lines() {
            let Some(row) = line.trim().strip_prefix('|') else {
                continue;
            };
            let first = row.split('|').next().unwrap_or("");
            for key in first.split('`').skip(1).step_by(2) {
                if key.contains('.') {
                    keys.insert(key.to_string());
                }
            }
        }
        keys
    }

    #[test]
    fn the_walk_finds_tables_arrays_and_kinds() {
        let keys = all();
        for k in [
            "image.width",
            "camera.fov",
            "black_hole.mass",
            "object.kind",
            "object.radius",
            "object.material.kind",
            "object.material.color",
            "light.kind",
            "cloud.center",
            "animation.keyframe.time",
        ] {
            assert!(keys.contains(k), "{k} missing from {keys:?}");
        }
        // Tables are not leaves; kinds leave no mark.
        assert!(!keys.contains("image") && !keys.contains("object.material"));
        assert!(
            !keys
                .iter()
                .any(|k| k.contains("sphere") || k.contains(PROBE))
        );
    }

    #[test]
    fn the_guide_documents_every_scene_key_and_no_other() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/GUIDE.md");
        let guide = std::fs::read_to_string(path).expect("GUIDE.md");
        let documented = documented(&guide);
        let schema = all();
        let missing: Vec<_> = schema.difference(&documented).collect();
        let unknown: Vec<_> = documented.difference(&schema).collect();
        assert!(
            missing.is_empty() && unknown.is_empty(),
            "GUIDE.md's scene keys against the schema:\n  not documented: {missing:?}\n  documented but not keys: {unknown:?}"
        );
    }
}
