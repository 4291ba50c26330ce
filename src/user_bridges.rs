//! The bridges the player chose, kept in the plugin state: paper B's thermal
//! instruments play on them, the point-bow instrument takes their passive reduction as
//! its body: the bridge file's text is saved with the project, so a project
//! reopens with its bridge even when the file has moved or gone.
//!
//! The editor reads a file the player names ([`choose_file`]: the fitter's JSON,
//! validated as the fitter's output is), keeps its text under the instrument's name and
//! asks the host to restart the plugin; [`crate::Colophony`]'s `activate` builds the
//! thermal instruments on the saved bridges ([`saved_modes`]). A broken, non-passive or
//! missing file is refused with a one-line error and the bridge that was playing stays;
//! a saved bridge that no longer parses (a damaged state) plays the shipped one.

use crate::dsp::bridge_data::{parse_bridge, BridgeModes};
use crate::dsp::vocabulary::InstrumentKind;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Mutex;

/// One chosen bridge: the file's name (for the editor) and its text.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedBridge {
    pub name: String,
    pub json: String,
}

/// The persisted field: instrument name (`violin`, `viola`, `cello`) -> its bridge.
pub type UserBridges = Mutex<BTreeMap<String, SavedBridge>>;

/// Reads and validates a bridge file for `kind`'s thermal instrument and keeps it in
/// `bridges`; returns the name it is listed under. On error nothing changes.
pub fn choose_file(
    bridges: &UserBridges,
    kind: InstrumentKind,
    path: &Path,
) -> Result<String, String> {
    let json = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read bridge {}: {e}", path.display()))?;
    parse_bridge(&json).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut map = bridges
        .lock()
        .map_err(|_| "the bridge list is poisoned".to_owned())?;
    map.insert(
        kind.name().to_owned(),
        SavedBridge {
            name: name.clone(),
            json,
        },
    );
    Ok(name)
}

/// Goes back to the shipped bridge for `kind`.
pub fn forget(bridges: &UserBridges, kind: InstrumentKind) {
    if let Ok(mut map) = bridges.lock() {
        map.remove(kind.name());
    }
}

/// The name of `kind`'s chosen bridge, `None` for the shipped one.
pub fn chosen_name(bridges: &UserBridges, kind: InstrumentKind) -> Option<String> {
    bridges
        .lock()
        .ok()?
        .get(kind.name())
        .map(|b| b.name.clone())
}

/// Every instrument's saved bridge as modes (`None`: the shipped one), with a message for
/// each saved bridge that does not parse (it plays the shipped one).
pub fn saved_modes(
    bridges: &UserBridges,
) -> ([Option<BridgeModes>; InstrumentKind::COUNT], Vec<String>) {
    let map = bridges.lock().map(|m| m.clone()).unwrap_or_default();
    let mut problems = Vec::new();
    let modes = InstrumentKind::ALL.map(|kind| {
        let saved = map.get(kind.name())?;
        match parse_bridge(&saved.json) {
            Ok((modes, _)) => Some(modes),
            Err(e) => {
                problems.push(format!(
                    "the saved {} bridge '{}' is unusable ({e}): playing the shipped one",
                    kind.name(),
                    saved.name
                ));
                None
            }
        }
    });
    (modes, problems)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str, text: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("colophony-user-bridges-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn a_valid_file_is_kept_and_a_bad_one_changes_nothing() {
        let bridges = UserBridges::default();
        let good = scratch(
            "fitted.json",
            include_str!("../assets/bridges/violin-generic.json"),
        );
        assert_eq!(
            choose_file(&bridges, InstrumentKind::Cello, &good).unwrap(),
            "fitted.json"
        );
        assert_eq!(
            chosen_name(&bridges, InstrumentKind::Cello).as_deref(),
            Some("fitted.json")
        );
        let before = bridges.lock().unwrap().clone();
        // A gain that is not positive semidefinite: not passive.
        let active =
            r#"{"modes": [{"freq_hz": 200, "bandwidth_hz": 5, "gain": [[1, 0], [0, -1]]}]}"#;
        for (name, text) in [("broken.json", "{"), ("active.json", active)] {
            let err =
                choose_file(&bridges, InstrumentKind::Cello, &scratch(name, text)).unwrap_err();
            assert!(err.contains(name) && !err.contains('\n'), "{err}");
        }
        let missing = choose_file(
            &bridges,
            InstrumentKind::Cello,
            Path::new("/no/such/bridge.json"),
        );
        assert!(missing.unwrap_err().contains("cannot read"));
        assert_eq!(*bridges.lock().unwrap(), before, "the playing bridge stays");
        let (modes, problems) = saved_modes(&bridges);
        assert!(modes[2].is_some() && modes[0].is_none() && problems.is_empty());
        forget(&bridges, InstrumentKind::Cello);
        assert_eq!(chosen_name(&bridges, InstrumentKind::Cello), None);
    }

    #[test]
    fn a_damaged_saved_bridge_plays_the_shipped_one_and_says_so() {
        let bridges = UserBridges::default();
        bridges.lock().unwrap().insert(
            "viola".into(),
            SavedBridge {
                name: "old.json".into(),
                json: "not json".into(),
            },
        );
        let (modes, problems) = saved_modes(&bridges);
        assert!(modes.iter().all(Option::is_none));
        assert_eq!(problems.len(), 1);
        assert!(problems[0].contains("viola") && problems[0].contains("old.json"));
    }
}
