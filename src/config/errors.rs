//! Errors of a scene file and their wording: serde's type names rewritten
//! in the file's terms, and each schema problem as a line that says where
//! it is (the file's line and column, or the override).

use super::overrides::{Override, Part, key_text};
use super::problems;
use std::path::PathBuf;
use thiserror::Error;

/// A failure to read or parse a scene file.
#[derive(Debug, Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read scene file {path}: {cause}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// The file is not valid TOML or does not match the schema.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What and where (line and column), in the scene file's terms.
        message: String,
    },
    /// Keys the schema does not take, values of the wrong type, missing
    /// keys: every one of them, one line each.
    #[error("{path}: {}", schema_text(.problems))]
    Schema {
        /// The file.
        path: PathBuf,
        /// Each problem, with its line or the override it comes from.
        problems: Vec<String>,
    },
    /// A `--set` or `--unset` is malformed or does not fit the schema.
    #[error("{flag}: {message}")]
    Override {
        /// The option as given, e.g. `--set image.width=wide`.
        flag: String,
        /// What is wrong.
        message: String,
    },
    /// A path cannot be resolved.
    #[error("{key} = {path:?}: {message}")]
    Path {
        /// Dotted key.
        key: String,
        /// The path as written.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

fn schema_text(problems: &[String]) -> String {
    match problems {
        [one] => one.clone(),
        all => format!("{} problems:\n  {}", all.len(), all.join("\n  ")),
    }
}

/// Rewrites serde's type names in a schema error as the scene file's
/// words ("u32" -> "a whole number", "struct ImageConfig" -> "a table").
pub fn humanize(message: &str) -> String {
    let mut out = message.trim_end().to_string();
    for t in [
        "u8", "u16", "u32", "u64", "usize", "i8", "i16", "i32", "i64", "isize",
    ] {
        out = replace_word(&out, &format!("expected {t}"), "expected a whole number");
    }
    for t in ["f32", "f64"] {
        out = replace_word(&out, &format!("expected {t}"), "expected a number");
    }
    // "expected struct ImageConfig": the name after it is Rust's.
    for (from, to) in [
        (
            "expected internally tagged enum ",
            "expected a table with a `kind`",
        ),
        ("expected struct ", "expected a table"),
        ("expected enum ", "expected one of its names"),
    ] {
        while let Some(i) = out.find(from) {
            let rest = &out[i + from.len()..];
            let name = rest
                .find(|c: char| !c.is_alphanumeric() && c != '_')
                .unwrap_or(rest.len());
            out = format!("{}{to}{}", &out[..i], &rest[name..]);
        }
    }
    for (from, to) in [
        ("expected a sequence", "expected an array"),
        ("invalid type: sequence", "invalid type: array"),
        ("invalid type: map", "invalid type: table"),
        ("expected a map", "expected a table"),
        ("floating point", "number"),
    ] {
        out = out.replace(from, to);
    }
    out
}

/// Replaces `from` where it is not followed by a letter or digit.
fn replace_word(text: &str, from: &str, to: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(from) {
        let after = &rest[i + from.len()..];
        out += &rest[..i];
        if after.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
            out += from;
        } else {
            out += to;
        }
        rest = after;
    }
    out + rest
}

/// One schema problem as a line: where it is (the file's line and column,
/// or the override it comes from), the key and what is wrong.
pub(super) fn describe(p: &problems::Problem, text: &str, overrides: &[Override]) -> String {
    use problems::Kind;
    let key = key_text(&p.parts);
    // The override that set this key or a table above it, or below it
    // (`--set image={...}` for image.width; `--set image.zoom=2` for an
    // unknown image.zoom).
    let flag = overrides.iter().rev().find(|o| {
        o.value.is_some() && (p.parts.starts_with(&o.parts) || o.parts.starts_with(&p.parts))
    });
    // Removing a list entry renumbers the rest: the file's lines would
    // then point at the wrong entry.
    let renumbered = overrides.iter().any(|o| {
        o.value.is_none()
            && matches!(o.parts.last(), Some(Part::Index(_)))
            && p.parts.starts_with(&o.parts[..o.parts.len() - 1])
    });
    let place = match flag {
        Some(o) => format!("{}: ", o.flag),
        None if renumbered => String::new(),
        None => match (&p.kind, span_of(text, &p.parts)) {
            (Kind::Missing, _) | (_, None) => String::new(),
            (Kind::Unknown(_), Some((key_at, _))) => format!("{}: ", line_col(text, key_at)),
            (Kind::Invalid(_), Some((_, value_at))) => format!("{}: ", line_col(text, value_at)),
        },
    };
    match &p.kind {
        Kind::Unknown(names) => {
            let (last, up) = p.parts.split_last().expect("a key");
            let name = key_text(std::slice::from_ref(last));
            let table = match up {
                [] => "the top level".to_string(),
                [Part::Key(t)] => format!("[{t}]"),
                up => key_text(up),
            };
            let hint = match problems::nearest(&name, names) {
                Some(n) => format!("did you mean `{n}`?"),
                None if names.is_empty() => "it takes no keys".to_string(),
                None => format!("it takes {}", names.join(", ")),
            };
            format!("{place}unknown key `{name}` in {table} ({hint})")
        }
        Kind::Invalid(message) => format!("{place}{key}: {message}"),
        Kind::Missing => {
            let what = match p.parts.as_slice() {
                [Part::Key(t)] => format!("[{t}]"),
                _ => key,
            };
            format!("{place}missing {what}")
        }
    }
}

/// Byte offsets of the key and of the value at `parts` in the document.
pub(super) fn span_of(text: &str, parts: &[Part]) -> Option<(usize, usize)> {
    use toml::de::{DeTable, DeValue};
    let doc = DeTable::parse(text).ok()?;
    let mut table: &DeTable = doc.get_ref();
    let mut found = None;
    let mut i = 0;
    while i < parts.len() {
        let Part::Key(k) = &parts[i] else {
            return None;
        };
        let (key, value) = table.get_key_value(k.as_str())?;
        found = Some((key.span().start, value.span().start));
        let mut v: &DeValue = value.get_ref();
        if let Some(Part::Index(n)) = parts.get(i + 1) {
            let entry = v.as_array()?.get(*n)?;
            found = Some((entry.span().start, entry.span().start));
            v = entry.get_ref();
            i += 1;
        }
        i += 1;
        if i < parts.len() {
            table = v.as_table()?;
        }
    }
    found
}

/// "line L, column C" of a byte offset (both from 1).
fn line_col(text: &str, at: usize) -> String {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("line {line}, column {col}")
}
