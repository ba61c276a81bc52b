//! The command line's changes to a scene: `--set key=value` and `--unset
//! key`, dotted keys with list indices (`object.0.radius`).

use super::ConfigError;

/// One part of a dotted key: a table key or an index into an array of
/// tables (`object.0.radius`).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Part {
    Key(String),
    Index(usize),
}

/// A `--set key=value` or `--unset key` from the command line.
#[derive(Clone, Debug)]
pub struct Override {
    /// Dotted key, e.g. `image.width` or `object.0.radius`.
    pub key: String,
    /// Value as TOML (a bare word that is not TOML counts as a string);
    /// `None` removes the key.
    pub value: Option<toml::Value>,
    pub(super) parts: Vec<Part>,
    pub(super) flag: String,
}

impl Override {
    /// Parses `key=value` (the argument of `--set`).
    pub fn parse(assignment: &str) -> Result<Override, ConfigError> {
        let flag = format!("--set {assignment}");
        let err = |message: &str| ConfigError::Override {
            flag: flag.clone(),
            message: message.to_string(),
        };
        let (key, raw) = assignment
            .split_once('=')
            .ok_or_else(|| err("expected key=value, e.g. image.width=256"))?;
        let raw = raw.trim();
        let value = toml::from_str::<toml::Table>(&format!("v = {raw}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(raw.to_string()));
        Override::named(flag, key, Some(value))
    }

    /// Parses the argument of `--unset`.
    pub fn unset(key: &str) -> Result<Override, ConfigError> {
        Override::named(format!("--unset {key}"), key, None)
    }

    /// The override of `key` (dotted) to `value` (None: removed), named
    /// `flag` in messages.
    fn named(flag: String, key: &str, value: Option<toml::Value>) -> Result<Override, ConfigError> {
        let (key, parts) = parse_key(key).map_err(|message| ConfigError::Override {
            flag: flag.clone(),
            message,
        })?;
        Ok(Override {
            key,
            value,
            parts,
            flag,
        })
    }

    /// Sets `key` (dotted, as for `--set`) to `value`: for programs that
    /// change a config, such as the viewer.
    pub fn value(key: &str, value: toml::Value) -> Override {
        Override::try_value(key, value).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`Override::value`] of a key that may be malformed (from a user,
    /// not from a command-line flag): named `key=value` in messages.
    pub fn try_value(key: &str, value: toml::Value) -> Result<Override, ConfigError> {
        Override::named(format!("{key}={value}"), key, Some(value))
    }

    /// The option as given on the command line.
    pub fn flag(&self) -> &str {
        &self.flag
    }

    pub(super) fn apply(&self, table: &mut toml::Table) -> Result<(), ConfigError> {
        let err = |message: String| ConfigError::Override {
            flag: self.flag.clone(),
            message,
        };
        let name = |upto: usize| key_text(&self.parts[..upto]);
        let (last, parents) = self.parts.split_last().expect("keys are checked non-empty");
        let set = self.value.is_some();
        let mut node = TomlSlot::Table(table);
        for (i, p) in parents.iter().enumerate() {
            node = match (node, p) {
                (TomlSlot::Table(t), Part::Key(k)) => {
                    if !t.contains_key(k) {
                        if !set {
                            return Err(err(format!("`{}` is not set", name(i + 1))));
                        }
                        // A list when an index follows (`object.0` on a
                        // scene without objects), else a table.
                        let empty = match self.parts[i + 1] {
                            Part::Index(_) => toml::Value::Array(Vec::new()),
                            Part::Key(_) => toml::Value::Table(toml::Table::new()),
                        };
                        t.insert(k.clone(), empty);
                    }
                    TomlSlot::from_value(t.get_mut(k).expect("present"))
                        .ok_or_else(|| err(format!("`{}` is not a table", name(i + 1))))?
                }
                (TomlSlot::Array(a), Part::Index(n)) => {
                    let len = a.len();
                    let v = a.get_mut(*n).ok_or_else(|| {
                        err(format!("`{}` has {len} entries: no index {n}", name(i)))
                    })?;
                    TomlSlot::from_value(v)
                        .ok_or_else(|| err(format!("`{}` is not a table", name(i + 1))))?
                }
                (TomlSlot::Table(_), Part::Index(_)) => {
                    return Err(err(format!(
                        "`{}` is a table, not a list: give a key after `{}`",
                        name(i),
                        name(i)
                    )));
                }
                (TomlSlot::Array(_), Part::Key(_)) => {
                    return Err(err(format!(
                        "`{}` is a list: give an entry's index, e.g. {}.0",
                        name(i),
                        name(i)
                    )));
                }
            };
        }
        match (node, last, &self.value) {
            (TomlSlot::Table(t), Part::Key(k), Some(v)) => {
                t.insert(k.clone(), v.clone());
            }
            (TomlSlot::Table(t), Part::Key(k), None) => {
                t.remove(k)
                    .ok_or_else(|| err(format!("`{}` is not set", self.key)))?;
            }
            (TomlSlot::Array(a), Part::Index(n), value) => {
                let len = a.len();
                match value {
                    Some(v) if *n < len => a[*n] = v.clone(),
                    // One past the end appends an entry.
                    Some(v) if *n == len => a.push(v.clone()),
                    None if *n < len => {
                        a.remove(*n);
                    }
                    _ => {
                        return Err(err(format!(
                            "`{}` has {len} entries: no index {n}",
                            name(self.parts.len() - 1)
                        )));
                    }
                }
            }
            (TomlSlot::Array(_), Part::Key(_), _) => {
                let n = name(self.parts.len() - 1);
                return Err(err(format!(
                    "`{n}` is a list: give an entry's index, e.g. {n}.0"
                )));
            }
            (TomlSlot::Table(_), Part::Index(_), _) => {
                let n = name(self.parts.len() - 1);
                return Err(err(format!("`{n}` is a table, not a list")));
            }
        }
        Ok(())
    }
}

/// A place in a TOML document that keys or indices lead into.
enum TomlSlot<'a> {
    Table(&'a mut toml::Table),
    Array(&'a mut Vec<toml::Value>),
}

impl<'a> TomlSlot<'a> {
    fn from_value(v: &'a mut toml::Value) -> Option<TomlSlot<'a>> {
        match v {
            toml::Value::Table(t) => Some(TomlSlot::Table(t)),
            toml::Value::Array(a) => Some(TomlSlot::Array(a)),
            _ => None,
        }
    }
}

/// Splits a dotted key into table keys and (numeric) list indices.
pub(super) fn parse_key(key: &str) -> Result<(String, Vec<Part>), String> {
    let words: Vec<&str> = key.split('.').map(str::trim).collect();
    if words.iter().any(|w| w.is_empty()) {
        return Err("the key must be a dotted name such as image.width or object.0.radius".into());
    }
    let parts: Vec<Part> = words
        .iter()
        .map(|w| match w.parse::<usize>() {
            Ok(n) if w.bytes().all(|b| b.is_ascii_digit()) => Part::Index(n),
            _ => Part::Key(w.to_string()),
        })
        .collect();
    if let Some(Part::Index(_)) = parts.first() {
        return Err("the key must start with a table's name, e.g. object.0.radius".into());
    }
    Ok((words.join("."), parts))
}

pub(super) fn key_text(parts: &[Part]) -> String {
    parts
        .iter()
        .map(|p| match p {
            Part::Key(k) => k.clone(),
            Part::Index(n) => n.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// Whether `key` (e.g. `image.png`, `object.0.file`) was set from the
/// command line: the key itself, or a table or entry above it.
pub fn from_cli(overrides: &[Override], key: &str) -> bool {
    overrides.iter().any(|o| {
        o.value.is_some()
            && (o.key == key
                || key
                    .strip_prefix(o.key.as_str())
                    .is_some_and(|r| r.starts_with('.')))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn override_values_are_typed() {
        assert_eq!(
            Override::parse("image.width=256").unwrap().value,
            Some(toml::Value::Integer(256))
        );
        assert_eq!(
            Override::parse("a.b = 1e3").unwrap().value,
            Some(toml::Value::Float(1e3))
        );
        assert_eq!(
            Override::parse("image.png=out/x.png").unwrap().value,
            Some(toml::Value::String("out/x.png".into()))
        );
        assert!(matches!(
            Override::parse("camera.position=[1, 2, 3.5]")
                .unwrap()
                .value,
            Some(toml::Value::Array(_))
        ));
        assert!(Override::parse("image.width").is_err());
        assert!(Override::parse("image..width=3").is_err());
    }

    #[test]
    fn override_keys_are_normalised() {
        assert_eq!(
            Override::parse("image . png = x.png").unwrap().key,
            "image.png"
        );
    }

    #[test]
    fn override_into_scalar_is_an_error() {
        let mut t: toml::Table = toml::from_str("[image]\nwidth = 3\n").unwrap();
        let e = Override::parse("image.width.x=1")
            .unwrap()
            .apply(&mut t)
            .unwrap_err();
        assert!(
            e.to_string().contains("`image.width` is not a table"),
            "{e}"
        );
    }
}
