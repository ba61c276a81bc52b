//! Reading a scene file: the text (a regular file of sane size), the
//! overrides applied, every schema problem at once, paths made absolute,
//! outputs following an `image.png` from the command line; and the saved
//! form of a changed scene.

use super::errors::{describe, span_of};
use super::overrides::{Override, from_cli};
use super::warnings::{implausible_units, inert_settings};
use super::{ConfigError, MaterialConfig, ObjectConfig, SceneConfig, humanize, problems};
use std::path::{Path, PathBuf};

/// Expands a leading `~` or `~/` to the home folder, as a shell would.
fn expand_home(key: &str, p: &Path) -> Result<PathBuf, ConfigError> {
    let text = p.to_string_lossy();
    let err = |message: &str| ConfigError::Path {
        key: key.to_string(),
        path: p.to_path_buf(),
        message: message.to_string(),
    };
    if !text.starts_with('~') {
        return Ok(p.to_path_buf());
    }
    let rest = match text.strip_prefix('~') {
        Some("") => "",
        Some(r) if r.starts_with('/') => &r[1..],
        _ => {
            return Err(err(
                "only ~ and ~/ are expanded (to $HOME); write the full path",
            ));
        }
    };
    let home = std::env::var_os("HOME")
        .filter(|h| !h.is_empty())
        .ok_or_else(|| err("~ means $HOME, which is not set; write the full path"))?;
    Ok(PathBuf::from(home).join(rest))
}

impl SceneConfig {
    /// Reads a scene file, applies overrides (in the order given), and
    /// makes every path absolute: paths from the file against the file's
    /// folder, paths from overrides against the current directory, `~/`
    /// as the home folder. When `image.png` comes from the command line,
    /// the EXR and the animation's video (unless named there too) move
    /// beside the PNG with the same stem, so every output follows it.
    pub fn load(path: &Path, overrides: &[Override]) -> Result<SceneConfig, ConfigError> {
        let text = read_scene_text(path)?;
        SceneConfig::from_text(&text, path, overrides)
    }

    /// [`SceneConfig::load`] of scene text that `path` names (in messages;
    /// its folder is the one the text's relative paths start from), for
    /// scenes that come from a program rather than a file.
    pub fn from_text(
        text: &str,
        path: &Path,
        overrides: &[Override],
    ) -> Result<SceneConfig, ConfigError> {
        if text.len() as u64 > MAX_SCENE_BYTES {
            return Err(ConfigError::Read {
                path: path.to_path_buf(),
                cause: std::io::Error::other(format!(
                    "{} bytes: a scene is TOML text of at most {} MiB",
                    text.len(),
                    MAX_SCENE_BYTES >> 20
                )),
            });
        }
        let parse_err = |e: toml::de::Error| ConfigError::Parse {
            path: path.to_path_buf(),
            message: humanize(&e.to_string()),
        };
        let file: toml::Table = toml::from_str(text).map_err(parse_err)?;
        let mut table = file.clone();
        for o in overrides {
            o.apply(&mut table)?;
        }
        let mut config = problems::check(&table).map_err(|mut list| {
            // In the file's order within each kind.
            list.sort_by_key(|p| {
                let at = span_of(text, &p.parts).map_or(usize::MAX, |s| s.0);
                (p.kind.rank(), at)
            });
            ConfigError::Schema {
                path: path.to_path_buf(),
                problems: list.iter().map(|p| describe(p, text, overrides)).collect(),
            }
        })?;
        let base = path.parent().unwrap_or(Path::new(""));
        // In the browser, paths given beside the file (the page's address)
        // are from the site's root, as a command line's are from the
        // repository's.
        let cwd = if cfg!(target_arch = "wasm32") {
            PathBuf::from("/")
        } else {
            std::env::current_dir().unwrap_or_default()
        };
        let base = if base.is_absolute() {
            base.to_path_buf()
        } else {
            cwd.join(base)
        };
        for (key, p) in config.paths_mut() {
            let cli = from_cli(overrides, &key);
            // Joined to a folder it would read as that folder.
            if p.as_os_str().is_empty() {
                return Err(ConfigError::Path {
                    key: key.clone(),
                    path: p.clone(),
                    message: "an empty path; expected a file name".into(),
                });
            }
            *p = expand_home(&key, p)?;
            if p.is_relative() {
                *p = normalize(&if cli { cwd.join(&*p) } else { base.join(&*p) });
            }
        }
        if from_cli(overrides, "image.png") {
            let png = config.image.png.clone();
            if !from_cli(overrides, "image.exr") && config.image.exr.is_some() {
                config.image.exr = Some(png.with_extension("exr"));
            }
            if let Some(a) = config.animation.as_mut()
                && !from_cli(overrides, "animation.video")
                && let Some(v) = a.video.as_mut()
            {
                let ext = v.extension().unwrap_or_default().to_os_string();
                *v = png.with_extension(ext);
            }
        }
        config.warnings = inert_settings(&table, &config);
        config.warnings.extend(implausible_units(&config));
        Ok(config)
    }

    /// The scene file at `path` with `overrides` applied, as TOML text
    /// that loads to the same config wherever it is written: every path
    /// in it absolute, or with `relative` relative to `path`'s folder (a
    /// view saved from the web page, whose absolute paths are the site's).
    /// (Comments and the file's layout are not kept.)
    pub fn saved_text(
        path: &Path,
        overrides: &[Override],
        relative: bool,
    ) -> Result<String, ConfigError> {
        let mut config = SceneConfig::load(path, overrides)?;
        let text = read_scene_text(path)?;
        let mut table: toml::Table = toml::from_str(&text).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            message: humanize(&e.to_string()),
        })?;
        for o in overrides {
            o.apply(&mut table)?;
        }
        let folder = path.parent().map(normalize).unwrap_or_default();
        for (key, p) in config.paths_mut() {
            let p = if relative {
                relative_path(&folder, p)
            } else {
                p.clone()
            };
            Override::value(&key, p.display().to_string().into()).apply(&mut table)?;
        }
        let text = toml::to_string_pretty(&table).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Ok(tidy_floats(&text))
    }

    /// Every path-valued key with its dotted name.
    pub fn paths_mut(&mut self) -> Vec<(String, &mut PathBuf)> {
        let mut v: Vec<(String, &mut PathBuf)> = vec![("image.png".into(), &mut self.image.png)];
        if let Some(p) = self.image.exr.as_mut() {
            v.push(("image.exr".into(), p));
        }
        if let Some(d) = self.disk.as_mut() {
            if let Some(p) = d.texture.as_mut() {
                v.push(("disk.texture".into(), p));
            }
            if let Some(p) = d.spectrum.as_mut() {
                v.push(("disk.spectrum".into(), p));
            }
        }
        if let Some(p) = self.sky.texture.as_mut() {
            v.push(("sky.texture".into(), p));
        }
        if let Some(crate::config::MediumConfig::Grmhd(g)) = self.medium.as_mut()
            && let Some(d) = g.dump.as_mut()
        {
            v.push(("medium.dump".into(), d));
        }
        if let Some(p) = self.sky.stars.as_mut() {
            v.push(("sky.stars".into(), p));
        }
        if let Some(p) = self.animation.as_mut().and_then(|a| a.video.as_mut()) {
            v.push(("animation.video".into(), p));
        }
        for (i, o) in self.objects.iter_mut().enumerate() {
            let (file, mat) = match o {
                ObjectConfig::Sphere(s) => (None, &mut s.material),
                ObjectConfig::Rectangle(r) => (None, &mut r.material),
                ObjectConfig::Mesh(m) => (Some(&mut m.file), &mut m.material),
            };
            if let Some(f) = file {
                v.push((format!("object.{i}.file"), f));
            }
            let (MaterialConfig::Color(s) | MaterialConfig::Mirror(s) | MaterialConfig::Lit(s)) =
                mat;
            if let Some(t) = s.texture.as_mut() {
                v.push((format!("object.{i}.material.texture"), t));
            }
        }
        v
    }
}

/// Removes `.` and `name/..` pairs without touching the file system, so
/// `text` (TOML) with every float of 1e16 and above, or below 1e-4, in
/// scientific notation (`8.57e36`, not 37 digits), the shortest that
/// reads back as the same number.
fn tidy_floats(text: &str) -> String {
    use toml::de::{DeTable, DeValue};
    fn walk(v: &toml::Spanned<DeValue>, out: &mut Vec<(std::ops::Range<usize>, String)>) {
        match v.get_ref() {
            DeValue::Float(f) => {
                if let Ok(x) = f.as_str().replace('_', "").parse::<f64>()
                    && x.is_finite()
                    && x != 0.0
                    && !(1e-4..1e16).contains(&x.abs())
                {
                    out.push((v.span(), format!("{x:e}")));
                }
            }
            DeValue::Array(a) => a.iter().for_each(|e| walk(e, out)),
            DeValue::Table(t) => t.values().for_each(|e| walk(e, out)),
            _ => {}
        }
    }
    let Ok(doc) = DeTable::parse(text) else {
        return text.to_string();
    };
    let mut edits = Vec::new();
    doc.get_ref().values().for_each(|v| walk(v, &mut edits));
    edits.sort_by_key(|e| e.0.start);
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (span, repl) in edits {
        out += &text[at..span.start];
        out += &repl;
        at = span.end;
    }
    out + &text[at..]
}

/// `to` relative to the folder `from` (both absolute and normalized).
fn relative_path(from: &Path, to: &Path) -> PathBuf {
    let (a, b): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out: PathBuf = a[common..].iter().map(|_| "..").collect();
    out.extend(&b[common..]);
    out
}

/// Largest scene file read (bytes): scenes are a few kilobytes.
const MAX_SCENE_BYTES: u64 = 16 << 20;

/// The text of a scene file: a regular file of sane size (not a device,
/// a pipe or a folder, which could hang or exhaust memory).
fn read_scene_text(path: &Path) -> Result<String, ConfigError> {
    let read = |cause| ConfigError::Read {
        path: path.to_path_buf(),
        cause,
    };
    let len = crate::inputs::file_len(path).map_err(read)?;
    let other = |why: String| read(std::io::Error::other(why));
    let Some(len) = len else {
        return Err(other(
            "not a regular file (a scene is a TOML text file)".into(),
        ));
    };
    if len > MAX_SCENE_BYTES {
        return Err(other(format!(
            "{len} bytes: a scene file is TOML text of at most {} MiB",
            MAX_SCENE_BYTES >> 20
        )));
    }
    crate::inputs::read_to_string(path).map_err(read)
}

/// messages show `/a/img/x.png` rather than `/a/configs/../img/x.png`.
fn normalize(p: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_go_up_to_the_common_folder() {
        let r = |from: &str, to: &str| relative_path(Path::new(from), Path::new(to));
        assert_eq!(
            r("/configs", "/spectral_assets/sky.png"),
            Path::new("../spectral_assets/sky.png")
        );
        assert_eq!(
            r("/configs", "/configs/quick_view.png"),
            Path::new("quick_view.png")
        );
        assert_eq!(r("/a/b/c", "/a/x.png"), Path::new("../../x.png"));
        assert_eq!(r("/configs", "/x.png"), Path::new("../x.png"));
        // Read back from the folder, it is the path again.
        assert_eq!(
            normalize(&Path::new("/a/b/c").join(r("/a/b/c", "/a/x/y.png"))),
            Path::new("/a/x/y.png")
        );
    }

    #[test]
    fn saved_floats_are_short() {
        let text = "a = 8570000000000000000000000000000000000.0\nb = [0.00001, 2.5, 1e300]\n[c]\nd = { e = -3e20 }\n";
        let tidy = tidy_floats(text);
        assert_eq!(
            tidy,
            "a = 8.57e36\nb = [1e-5, 2.5, 1e300]\n[c]\nd = { e = -3e20 }\n"
        );
        let (a, b): (toml::Table, toml::Table) = (
            toml::from_str(text).unwrap(),
            toml::from_str(&tidy).unwrap(),
        );
        assert_eq!(a, b);
    }

    #[test]
    fn normalize_is_lexical() {
        assert_eq!(
            normalize(Path::new("/a/b/../c/./d.png")),
            PathBuf::from("/a/c/d.png")
        );
        assert_eq!(normalize(Path::new("../x")), PathBuf::from("../x"));
    }
}
