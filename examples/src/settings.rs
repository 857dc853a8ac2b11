//! `--config FILE` and `--print-config`: an example's settings read from, and written as, TOML.
//!
//! The settings are the library's own configuration structs (`GraphSlamConfig`, `IcpConfig`,
//! `NavigatorConfig`, ...) under a table each (`[slam]`, `[icp]`, `[navigator]`), read with
//! their `serde` feature. A file changes only the fields it names: every other field, nested
//! tables included, keeps the example's default (which may differ from the struct's own
//! `Default`: the `slam` example's `[slam]` starts from `spot_adapter::pipelines::slam_config`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use serde::Serialize;
use serde::de::DeserializeOwned;

/// `--config FILE` and `--print-config`, flattened into an example's arguments.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct SettingsArgs {
    /// Settings from this TOML file over the defaults: fields it leaves out keep their
    /// defaults, and options given on the command line win over it (`--print-config` shows
    /// every field).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Print the settings as TOML (the defaults, with `--config` and the options given over
    /// them) and exit.
    #[arg(long)]
    pub print_config: bool,
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

/// `defaults` with the settings of the TOML file at `path` over them. A table in the file
/// changes only the fields it names, nested tables alike; a table with a `kind` (the variant of
/// an enum: `kernel = { kind = "Tukey", k = 0.05 }`) replaces the default's whole.
///
/// `T`'s `Default` is what a file is checked against first (every struct read with
/// `serde(default)`), so toml's own message names the line and the field of a mistake.
///
/// # Errors
/// The file cannot be read, is not TOML, names a field the settings do not have, or gives a
/// field a value of the wrong type: the file's name and toml's message (line, field).
pub fn load_settings<T: Serialize + DeserializeOwned + Default>(
    path: &Path,
    defaults: &T,
) -> Result<T> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the settings file {}", path.display()))?;
    let bad = |e: toml::de::Error| anyhow!("settings file {}: {e}", path.display());
    let file: toml::Table = toml::from_str(&text).map_err(bad)?;
    // The file on its own, for toml's messages with the line and the field.
    toml::from_str::<T>(&text).map_err(bad)?;
    let mut merged = toml::Table::try_from(defaults).context("the default settings as TOML")?;
    overlay(&mut merged, file);
    merged.try_into().map_err(bad)
}

/// Prints `settings` as TOML on stdout.
///
/// # Errors
/// When a setting has no TOML form, or stdout fails.
pub fn print_settings<T: Serialize>(settings: &T) -> Result<()> {
    let text = toml::to_string(settings).context("the settings as TOML")?;
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
