//! Presets and the plugin state's version.
//!
//! A preset is a readable JSON file naming parameter values by their ids (the ids of
//! [`crate::params`], a contract):
//!
//! ```json
//! { "name": "Cello legato",
//!   "description": "what it is for",
//!   "params": { "instrument": "cello", "bow_force": 1.5, "glide_time": 180.0 } }
//! ```
//!
//! Numbers are plain values in the parameter's unit (N, m/s, beta, ms, Hz, dB), choices
//! are the choice's id (`"elasto-plastic"`, `"iv"`). A parameter the file does not name
//! takes its default, so a preset is a whole sound, whatever was playing before. Values
//! outside a parameter's range are clamped to it, as a host does; an unknown parameter or
//! choice, a value of the wrong kind, or a broken file is an error that names the problem.
//!
//! The factory presets (`assets/presets/*.json`) are compiled in ([`factory`]); user
//! presets are files in [`user_dir`] (the editor saves there). The editor loads a preset
//! as a whole plugin state through the host ([`Preset::state_params`]); the offline
//! renderer applies it to a fresh parameter set ([`Preset::apply_to`]), so both read it
//! through the same parameter ranges.
//!
//! **State version.** The plugin state carries [`STATE_VERSION`] in its persisted field
//! `state-version`; [`migrate_state`] (the plugin's `filter_state`) brings an older state
//! up to date before the host's values are loaded. Version 0 is every state saved before
//! the field existed. Saved states of every version are test fixtures
//! (`tests/fixtures/state/`) that must load forever after.
//!
//! ```
//! use colophony::params::ColophonyParams;
//! use colophony::presets;
//! let preset = presets::find("cello-legato").unwrap();
//! let params = ColophonyParams::default();
//! preset.apply_to(&params).unwrap();
//! assert_eq!(params.bow_force.value(), 0.59);
//! ```

use crate::params::ColophonyParams;
use crate::params::{STATE_VERSION, STATE_VERSION_FIELD};
use nice_plug::params::InternalParamMut;
use nice_plug::plugin::{ParamValue, PluginState};
use nice_plug::prelude::{Param, ParamPtr, Params};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A named set of parameter values (see the module doc for the file format).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// The MIDI note the preset is made for (the renderer's default note), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<u8>,
    /// Parameter id -> plain value (a number, or a choice's id).
    pub params: BTreeMap<String, serde_json::Value>,
}

/// The factory presets: file stem and contents, in the order the editor lists them.
const FACTORY: &[(&str, &str)] = &[
    (
        "cello-legato",
        include_str!("../assets/presets/cello-legato.json"),
    ),
    (
        "cello-sul-ponticello",
        include_str!("../assets/presets/cello-sul-ponticello.json"),
    ),
    (
        "cello-down-bows",
        include_str!("../assets/presets/cello-down-bows.json"),
    ),
    (
        "violin-detache",
        include_str!("../assets/presets/violin-detache.json"),
    ),
    (
        "violin-sul-tasto",
        include_str!("../assets/presets/violin-sul-tasto.json"),
    ),
    (
        "viola-sul-tasto",
        include_str!("../assets/presets/viola-sul-tasto.json"),
    ),
    (
        "viola-stribeck",
        include_str!("../assets/presets/viola-stribeck.json"),
    ),
    (
        "double-bass-arco",
        include_str!("../assets/presets/double-bass-arco.json"),
    ),
    (
        "violin-con-sordino",
        include_str!("../assets/presets/violin-con-sordino.json"),
    ),
    (
        "cello-pizzicato",
        include_str!("../assets/presets/cello-pizzicato.json"),
    ),
    (
        "double-bass-pizzicato",
        include_str!("../assets/presets/double-bass-pizzicato.json"),
    ),
    (
        "violin-sautille",
        include_str!("../assets/presets/violin-sautille.json"),
    ),
    (
        "violin-harmonics",
        include_str!("../assets/presets/violin-harmonics.json"),
    ),
    (
        "cello-col-legno-tratto",
        include_str!("../assets/presets/cello-col-legno-tratto.json"),
    ),
    (
        "thermal-cello",
        include_str!("../assets/presets/thermal-cello.json"),
    ),
    (
        "paper-a-figure-7",
        include_str!("../assets/presets/paper-a-figure-7.json"),
    ),
    (
        "paper-a-lugre",
        include_str!("../assets/presets/paper-a-lugre.json"),
    ),
    (
        "paper-b-figure-6",
        include_str!("../assets/presets/paper-b-figure-6.json"),
    ),
    (
        "rubbed-paper-modal",
        include_str!("../assets/presets/rubbed-paper-modal.json"),
    ),
    (
        "rubbed-door-hinge",
        include_str!("../assets/presets/rubbed-door-hinge.json"),
    ),
    (
        "rubbed-chalk",
        include_str!("../assets/presets/rubbed-chalk.json"),
    ),
    (
        "rubbed-wine-glass",
        include_str!("../assets/presets/rubbed-wine-glass.json"),
    ),
    (
        "rubbed-brake-squeal",
        include_str!("../assets/presets/rubbed-brake-squeal.json"),
    ),
];

/// The factory presets' ids (file stems), in order.
pub fn factory_ids() -> impl Iterator<Item = &'static str> {
    FACTORY.iter().map(|(id, _)| *id)
}

/// The factory presets with their ids. A broken factory file is a build defect (tested).
pub fn factory() -> Vec<(&'static str, Preset)> {
    FACTORY
        .iter()
        .filter_map(|(id, text)| Preset::parse(text).ok().map(|p| (*id, p)))
        .collect()
}

impl Preset {
    /// Parses and checks a preset file's text.
    pub fn parse(text: &str) -> Result<Preset, String> {
        let preset: Preset =
            serde_json::from_str(text).map_err(|e| format!("not a preset file: {e}"))?;
        if preset.name.trim().is_empty() {
            return Err("the preset has no name".into());
        }
        preset.state_params()?;
        Ok(preset)
    }

    /// Reads and checks a preset file.
    pub fn load(path: &Path) -> Result<Preset, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read preset {}: {e}", path.display()))?;
        Preset::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// The preset as a complete set of plain parameter values (every parameter: the
    /// preset's value, clamped to its range, or the default), as a plugin state holds them.
    pub fn state_params(&self) -> Result<BTreeMap<String, ParamValue>, String> {
        let params = ColophonyParams::default();
        self.apply_to(&params)?;
        Ok(plain_values(&params))
    }

    /// Sets the preset's values on `params` (a parameter set not attached to a host: the
    /// offline renderer's). Parameters the preset does not name are left as they are.
    pub fn apply_to(&self, params: &ColophonyParams) -> Result<(), String> {
        let map = params.param_map();
        for (id, value) in &self.params {
            let Some((_, ptr, _)) = map.iter().find(|(name, _, _)| name == id) else {
                return Err(format!("unknown parameter '{id}'"));
            };
            set_plain(*ptr, id, value)?;
        }
        Ok(())
    }

    /// A preset holding every parameter of a plugin state (the editor's "save").
    pub fn from_state(name: &str, description: &str, state: &PluginState) -> Preset {
        let params = state
            .params
            .iter()
            .filter_map(|(id, value)| {
                let json = match value {
                    // f32's shortest decimal form, so 0.1 is written 0.1.
                    ParamValue::F32(v) => serde_json::Number::from_f64(
                        format!("{v}").parse::<f64>().unwrap_or(*v as f64),
                    )
                    .map(serde_json::Value::Number)?,
                    ParamValue::I32(v) => serde_json::Value::from(*v),
                    ParamValue::Bool(v) => serde_json::Value::from(*v),
                    ParamValue::String(v) => serde_json::Value::from(v.clone()),
                };
                Some((id.clone(), json))
            })
            .collect();
        Preset {
            name: name.to_owned(),
            description: description.to_owned(),
            note: None,
            params,
        }
    }

    /// The file text (pretty JSON, ids sorted).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default() + "\n"
    }
}

/// Sets one parameter from a plain JSON value, through the parameter's own range.
fn set_plain(ptr: ParamPtr, id: &str, value: &serde_json::Value) -> Result<(), String> {
    let number = || {
        value
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("'{id}' needs a number, got {value}"))
    };
    // SAFETY: `ptr` comes from the `param_map` of a parameter set the caller holds alive.
    unsafe {
        match ptr {
            // In range: the plain value itself (a round trip through the normalised value
            // would move it by an ulp on skewed ranges); outside: the range's end.
            ParamPtr::FloatParam(p) => {
                let plain = number()? as f32;
                match in_range(ptr, plain) {
                    Ok(()) => (*p)._internal_set_plain_value(plain),
                    Err(end) => ptr._internal_set_normalized_value(end),
                };
            }
            ParamPtr::IntParam(p) => {
                let plain = number()?;
                if plain.fract() != 0.0 {
                    return Err(format!("'{id}' needs a whole number, got {value}"));
                }
                let plain = plain.clamp(i32::MIN as f64, i32::MAX as f64);
                match in_range(ptr, plain as f32) {
                    Ok(()) => (*p)._internal_set_plain_value(plain as i32),
                    Err(end) => ptr._internal_set_normalized_value(end),
                };
            }
            ParamPtr::BoolParam(_) => {
                let b = value
                    .as_bool()
                    .ok_or_else(|| format!("'{id}' needs true or false, got {value}"))?;
                ptr._internal_set_normalized_value(if b { 1.0 } else { 0.0 });
            }
            ParamPtr::EnumParam(p) => {
                let choice = value
                    .as_str()
                    .ok_or_else(|| format!("'{id}' needs a choice's id, got {value}"))?;
                if !(*p).set_from_id(choice) {
                    return Err(format!("'{id}' has no choice '{choice}'"));
                }
            }
        }
    }
    Ok(())
}

/// `Ok` if `plain` lies within the parameter's range, else the normalised end it is
/// beyond (0 or 1).
///
/// # Safety
/// `ptr` must point into a live parameter set.
unsafe fn in_range(ptr: ParamPtr, plain: f32) -> Result<(), f32> {
    let n = unsafe { ptr.preview_normalized(plain) };
    if n <= 0.0 && plain != unsafe { ptr.preview_plain(0.0) } {
        Err(0.0)
    } else if n >= 1.0 && plain != unsafe { ptr.preview_plain(1.0) } {
        Err(1.0)
    } else {
        Ok(())
    }
}

/// Every parameter's plain value, as nice-plug writes a plugin state.
fn plain_values(params: &ColophonyParams) -> BTreeMap<String, ParamValue> {
    params
        .param_map()
        .into_iter()
        .map(|(id, ptr, _)| {
            // SAFETY: as in `set_plain`.
            let value = unsafe {
                match ptr {
                    ParamPtr::FloatParam(p) => ParamValue::F32((*p).unmodulated_plain_value()),
                    ParamPtr::IntParam(p) => ParamValue::I32((*p).unmodulated_plain_value()),
                    ParamPtr::BoolParam(p) => ParamValue::Bool((*p).unmodulated_plain_value()),
                    ParamPtr::EnumParam(p) => match (*p).unmodulated_plain_id() {
                        Some(choice) => ParamValue::String(choice.to_owned()),
                        None => ParamValue::I32((*p).unmodulated_plain_value()),
                    },
                }
            };
            (id, value)
        })
        .collect()
}

/// Where user presets live: `COLOPHONY_PRESET_DIR` if set, else the platform's user data
/// folder (`~/.local/share/colophony/presets` or `$XDG_DATA_HOME/colophony/presets` on
/// Linux, `~/Library/Application Support/Colophony/Presets` on macOS,
/// `%APPDATA%\Colophony\Presets` on Windows). `None` when none of these is known.
pub fn user_dir() -> Option<PathBuf> {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(dir) = env("COLOPHONY_PRESET_DIR") {
        return Some(dir);
    }
    if cfg!(target_os = "windows") {
        return env("APPDATA").map(|d| d.join("Colophony").join("Presets"));
    }
    if cfg!(target_os = "macos") {
        return env("HOME").map(|d| {
            d.join("Library/Application Support")
                .join("Colophony")
                .join("Presets")
        });
    }
    env("XDG_DATA_HOME")
        .or_else(|| env("HOME").map(|h| h.join(".local/share")))
        .map(|d| d.join("colophony").join("presets"))
}

/// The user presets in `dir`, sorted by file name: each file's stem and its preset, or
/// the reason it cannot be read (a broken file is listed, not skipped silently).
pub fn user_presets(dir: &Path) -> Vec<(String, Result<Preset, String>)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            (stem, Preset::load(&p))
        })
        .collect()
}

/// A file stem for a preset name: lower case letters, digits and dashes.
pub fn file_stem_for(name: &str) -> String {
    let mut stem = String::new();
    for c in name.trim().chars() {
        if c.is_alphanumeric() {
            stem.extend(c.to_lowercase());
        } else if !stem.ends_with('-') && !stem.is_empty() {
            stem.push('-');
        }
    }
    let stem = stem.trim_end_matches('-').to_owned();
    if stem.is_empty() {
        "preset".into()
    } else {
        stem
    }
}

/// Writes `preset` into `dir` (created if missing) as `<stem>.json`, replacing a file of
/// the same name whole (never a half-written file). Returns the path.
pub fn save_user(preset: &Preset, dir: &Path) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("cannot create preset folder {}: {e}", dir.display()))?;
    let path = dir.join(format!("{}.json", file_stem_for(&preset.name)));
    crate::dsp::bridge_data::write_atomically(&path, preset.to_json().as_bytes())?;
    Ok(path)
}

/// Finds a preset by what a user types: a path to a preset file, a factory preset's id or
/// name, or a user preset's file stem or name (case-insensitive).
pub fn find(what: &str) -> Result<Preset, String> {
    let path = Path::new(what);
    if path.extension().is_some_and(|x| x == "json") || path.components().count() > 1 {
        return Preset::load(path);
    }
    let wanted = what.trim().to_lowercase();
    let matches = |id: &str, p: &Preset| id == wanted || p.name.to_lowercase() == wanted;
    if let Some((_, p)) = factory().into_iter().find(|(id, p)| matches(id, p)) {
        return Ok(p);
    }
    if let Some(dir) = user_dir() {
        for (stem, p) in user_presets(&dir) {
            if let Ok(p) = p {
                if matches(&stem, &p) {
                    return Ok(p);
                }
            }
        }
    }
    let ids: Vec<&str> = factory_ids().collect();
    Err(format!(
        "no preset '{what}' (factory presets: {}; or give a .json file)",
        ids.join(", ")
    ))
}

/// Brings a saved plugin state up to [`STATE_VERSION`] before its values are loaded (the
/// plugin's `filter_state`):
/// - version 0 -> 1: no parameter was renamed or re-ranged; the version is recorded.
/// - version 1 -> 2: String Weight (new, on by default) is set off where the state does
///   not hold it, so a project saved before it plays as it did.
/// - any version: a float that is not finite (a damaged file) is dropped, so the
///   parameter keeps its value instead of becoming NaN; a number outside its
///   parameter's range is brought to the range's end.
///
/// A state from a newer version loads what this build knows (unknown ids are ignored).
pub fn migrate_state(state: &mut PluginState) {
    state.params.retain(|_, v| match v {
        ParamValue::F32(x) => x.is_finite(),
        _ => true,
    });
    // nice-plug loads a state's plain values as they are: a value outside its range (a
    // damaged or hand-edited file) is brought to the range's end here.
    let params = ColophonyParams::default();
    for (id, ptr, _) in params.param_map() {
        let Some(value) = state.params.get_mut(&id) else {
            continue;
        };
        // SAFETY: `ptr` points into `params`, alive for the loop.
        unsafe {
            match (ptr, &mut *value) {
                (ParamPtr::FloatParam(_), ParamValue::F32(x)) => {
                    if let Err(end) = in_range(ptr, *x) {
                        *x = ptr.preview_plain(end);
                    }
                }
                (ParamPtr::IntParam(_), ParamValue::I32(x)) => {
                    if let Err(end) = in_range(ptr, *x as f32) {
                        *x = ptr.preview_plain(end).round() as i32;
                    }
                }
                _ => {}
            }
        }
    }
    let version = state_version(state);
    if version < 2 {
        state
            .params
            .entry("string_weight".into())
            .or_insert(ParamValue::Bool(false));
    }
    if version < STATE_VERSION {
        state
            .fields
            .insert(STATE_VERSION_FIELD.into(), STATE_VERSION.to_string());
    }
}

/// The version a state was saved with (0: before versions were recorded).
pub fn state_version(state: &PluginState) -> u32 {
    state
        .fields
        .get(STATE_VERSION_FIELD)
        .and_then(|v| serde_json::from_str::<u32>(v).ok())
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_factory_file_is_compiled_in_and_parses() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/presets");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "json"))
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        on_disk.sort();
        let mut compiled: Vec<String> = factory_ids().map(String::from).collect();
        compiled.sort();
        assert_eq!(on_disk, compiled);
        for (id, text) in FACTORY {
            Preset::parse(text).unwrap_or_else(|e| panic!("{id}: {e}"));
        }
        // The factory set's specified minimum: at least 12 musical and research presets
        // (20 ship; the comparison above checks which).
        assert!(FACTORY.len() >= 12);
    }

    #[test]
    fn a_preset_is_a_whole_sound_over_the_defaults() {
        let preset = find("violin-detache").unwrap();
        let values = preset.state_params().unwrap();
        let defaults = plain_values(&ColophonyParams::default());
        assert_eq!(values.len(), defaults.len());
        assert!(matches!(&values["instrument"], ParamValue::String(s) if s == "violin"));
        // Not named by the preset: the default.
        assert!(matches!(&values["reference_pitch"], ParamValue::F32(x) if *x == 440.0));
    }

    #[test]
    fn out_of_range_values_clamp_to_the_parameter_range() {
        let preset =
            Preset::parse(r#"{"name": "x", "params": {"bow_force": 50.0, "bow_position": -1}}"#)
                .unwrap();
        let params = ColophonyParams::default();
        preset.apply_to(&params).unwrap();
        assert_eq!(params.bow_force.value(), 10.0);
        assert_eq!(params.bow_position.value(), 0.02);
    }

    #[test]
    fn broken_presets_say_what_is_wrong() {
        let cases = [
            ("{", "not a preset file"),
            (
                r#"{"name": "x", "params": {"bow_pressure": 1.0}}"#,
                "unknown parameter 'bow_pressure'",
            ),
            (
                r#"{"name": "x", "params": {"instrument": "lute"}}"#,
                "no choice 'lute'",
            ),
            (
                r#"{"name": "x", "params": {"bow_force": "loud"}}"#,
                "needs a number",
            ),
            (
                r#"{"name": "x", "params": {"bow_nodes": 10.5}}"#,
                "whole number",
            ),
            (
                r#"{"name": "x", "params": {}, "colour": 3}"#,
                "unknown field",
            ),
            (r#"{"name": " ", "params": {}}"#, "no name"),
        ];
        for (text, expected) in cases {
            let err = Preset::parse(text).unwrap_err();
            assert!(err.contains(expected), "{text}: {err}");
            assert!(!err.contains('\n'), "one line: {err}");
        }
    }

    #[test]
    fn a_saved_preset_loads_back_the_same_values() {
        let dir = std::env::temp_dir().join(format!("colophony-presets-{}", std::process::id()));
        let original = find("paper-b-figure-6").unwrap();
        let state = PluginState {
            version: String::new(),
            params: original.state_params().unwrap(),
            fields: BTreeMap::new(),
        };
        let saved = Preset::from_state("My Figure 6 / take 2", "", &state);
        let path = save_user(&saved, &dir).unwrap();
        assert_eq!(path.file_name().unwrap(), "my-figure-6-take-2.json");
        let listed = user_presets(&dir);
        assert_eq!(listed.len(), 1);
        let loaded = listed[0].1.clone().unwrap();
        assert_eq!(loaded.state_params().unwrap().len(), state.params.len());
        for (id, value) in loaded.state_params().unwrap() {
            assert_eq!(
                format!("{value:?}"),
                format!("{:?}", state.params[&id]),
                "{id}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unversioned_state_is_migrated_and_damaged_floats_dropped() {
        let mut state = PluginState {
            version: "0.1.0".into(),
            params: BTreeMap::from([
                ("bow_force".to_owned(), ParamValue::F32(f32::NAN)),
                ("bow_velocity".to_owned(), ParamValue::F32(0.2)),
                ("bow_position".to_owned(), ParamValue::F32(7.0)),
                ("bow_nodes".to_owned(), ParamValue::I32(-3)),
            ]),
            fields: BTreeMap::new(),
        };
        assert_eq!(state_version(&state), 0);
        migrate_state(&mut state);
        assert_eq!(state_version(&state), STATE_VERSION);
        assert!(!state.params.contains_key("bow_force"));
        assert!(matches!(state.params["bow_velocity"], ParamValue::F32(x) if x == 0.2));
        assert!(matches!(state.params["bow_position"], ParamValue::F32(x) if x == 0.5));
        assert!(matches!(state.params["bow_nodes"], ParamValue::I32(1)));
    }
}
