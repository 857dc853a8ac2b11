//! `--config FILE` and `--print-config`: an example's settings read from, and written as, TOML
//! or YAML.
//!
//! The settings are the library's own configuration structs (`GraphSlamConfig`, `IcpConfig`,
//! `NavigatorConfig`, ...) under a table each (`[slam]`, `[icp]`, `[navigator]`; in YAML a
//! mapping each, `slam:`), read with their `serde` feature. A file changes only the fields it
//! names: every other field, nested tables included, keeps the example's default (which may
//! differ from the struct's own `Default`: the `slam` example's `[slam]` starts from
//! `spot_adapter::pipelines::slam_config`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use serde::Serialize;
use serde::de::DeserializeOwned;

/// `--config FILE` and `--print-config`, flattened into an example's arguments.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct SettingsArgs {
    /// Settings from this TOML file (YAML when it ends in `.yaml` or `.yml`) over the defaults:
    /// fields it leaves out keep their defaults, and options given on the command line win
    /// over it (`--print-config` shows every field).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Print the settings (the defaults, with `--config` and the options given over them) and
    /// exit: as TOML, or as YAML with `--print-config yaml`.
    #[arg(
        long,
        value_name = "FORMAT",
        num_args = 0..=1,
        default_missing_value = "toml",
        value_enum
    )]
    pub print_config: Option<SettingsFormat>,
}

/// The formats of a settings file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SettingsFormat {
    /// TOML: a table a struct (`[slam]`).
    Toml,
    /// YAML: a mapping a struct (`slam:`).
    Yaml,
}

impl SettingsFormat {
    /// YAML for a file named `*.yaml` or `*.yml` (any case), TOML otherwise.
    #[must_use]
    pub fn of(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml") => {
                Self::Yaml
            }
            _ => Self::Toml,
        }
    }
}

impl SettingsArgs {
    /// `defaults` with the `--config` file's settings over them (`defaults` as they are
    /// without one).
    ///
    /// # Errors
    /// See [`load_settings`].
    pub fn load<T: Serialize + DeserializeOwned + Default>(&self, defaults: T) -> Result<T> {
        match &self.config {
            Some(path) => load_settings(path, &defaults),
            None => Ok(defaults),
        }
    }
}

/// `defaults` with the settings of the file at `path` over them: YAML when its name ends in
/// `.yaml` or `.yml`, TOML otherwise. A table (mapping) in the file changes only the fields it
/// names, nested tables alike; a table with a `kind` (the variant of an enum:
/// `kernel = { kind = "Tukey", k = 0.05 }`) replaces the default's whole.
///
/// `T`'s `Default` is what a file is checked against first (every struct read with
/// `serde(default)`), so the parser's own message names the line and the field of a mistake.
///
/// # Errors
/// The file cannot be read, is not TOML (YAML), names a field the settings do not have, or
/// gives a field a value of the wrong type: the file's name and the parser's message (line,
/// field).
pub fn load_settings<T: Serialize + DeserializeOwned + Default>(
    path: &Path,
    defaults: &T,
) -> Result<T> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the settings file {}", path.display()))?;
    let file: toml::Table = match SettingsFormat::of(path) {
        SettingsFormat::Toml => {
            let bad = |e: toml::de::Error| anyhow!("settings file {}: {e}", path.display());
            // The file on its own, for toml's messages with the line and the field.
            toml::from_str::<T>(&text).map_err(bad)?;
            toml::from_str(&text).map_err(bad)?
        }
        SettingsFormat::Yaml => {
            let bad = |e: serde_saphyr::Error| anyhow!("settings file {}: {e}", path.display());
            serde_saphyr::from_str::<T>(&text).map_err(bad)?;
            // An empty file (no document) changes nothing.
            serde_saphyr::from_str::<Option<toml::Table>>(&text)
                .map_err(bad)?
                .unwrap_or_default()
        }
    };
    let mut merged = toml::Table::try_from(defaults).context("the default settings as TOML")?;
    overlay(&mut merged, file);
    merged
        .try_into()
        .map_err(|e: toml::de::Error| anyhow!("settings file {}: {e}", path.display()))
}

/// Prints `settings` on stdout as `format`.
///
/// # Errors
/// When a setting has no TOML (YAML) form, or stdout fails.
pub fn print_settings<T: Serialize>(settings: &T, format: SettingsFormat) -> Result<()> {
    let text = match format {
        SettingsFormat::Toml => toml::to_string(settings).context("the settings as TOML")?,
        SettingsFormat::Yaml => {
            serde_saphyr::to_string(settings).context("the settings as YAML")?
        }
    };
    crate::out!("{}", text.trim_end())
}

/// `over`'s values in `base`: tables merged field by field, except an enum's (one with a
/// `kind`), which replaces the base's.
fn overlay(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(base)), toml::Value::Table(over))
                if !over.contains_key("kind") =>
            {
                overlay(base, over);
            }
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_in_part_keeps_the_other_fields_and_a_kind_replaces_the_whole() {
        let mut base: toml::Table =
            toml::from_str("a = 1\n[t]\nx = 1\ny = 2\n[e]\nkind = \"A\"\nk = 1\n").unwrap();
        let over: toml::Table = toml::from_str("[t]\ny = 3\n[e]\nkind = \"B\"\n").unwrap();
        overlay(&mut base, over);
        let want: toml::Table =
            toml::from_str("a = 1\n[t]\nx = 1\ny = 3\n[e]\nkind = \"B\"\n").unwrap();
        assert_eq!(base, want);
    }
}
