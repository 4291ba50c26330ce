//! The editor's bridge row (with the strings): the bridge the current instrument plays,
//! a file to load in its place (typed, or chosen with the row's own picker: **Browse**
//! lists a folder's subfolders and `.json` files), and the way back to the shipped one
//! ([`crate::user_bridges`]). A new bridge asks the host to restart the plugin, which
//! rebuilds the thermal instruments on it and the point-bow body from its passive
//! reduction ([`crate::dsp::body::body_from_bridge`]).

use crate::dsp::vocabulary::InstrumentKind;
use crate::params::ColophonyParams;
use crate::user_bridges;
use egui::Ui;
use nice_plug::context::gui::GuiContext;
use std::path::Path;

/// The path field's label.
pub const BRIDGE_FILE_LABEL: &str = "Bridge file";
/// The load button's label.
pub const LOAD_BRIDGE_LABEL: &str = "Load bridge";
/// The button that goes back to the shipped bridge.
pub const SHIPPED_BRIDGE_LABEL: &str = "Shipped bridge";

/// The button that opens (and closes) the file picker.
pub const BROWSE_LABEL: &str = "Browse";
/// Most entries the picker lists in one folder.
const MAX_ENTRIES: usize = 200;

/// The path typed, whether the picker is open, and the last message.
#[derive(Debug, Default)]
pub struct BridgeBar {
    path: String,
    browsing: bool,
    status: Option<String>,
}

/// A folder's subfolders and bridge files (`.json`), folders first, each sorted by name;
/// at most `MAX_ENTRIES`. An unreadable folder lists nothing.
pub fn bridge_entries(folder: &Path) -> Vec<(std::path::PathBuf, bool)> {
    let Ok(read) = std::fs::read_dir(folder) else {
        return Vec::new();
    };
    let mut entries: Vec<(std::path::PathBuf, bool)> = read
        .flatten()
        .filter_map(|e| {
            let path = e.path();
            let is_dir = path.is_dir();
            let json = path
                .extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("json"));
            let hidden = e.file_name().to_string_lossy().starts_with('.');
            (!hidden && (is_dir || json)).then_some((path, is_dir))
        })
        .collect();
    entries.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    entries.truncate(MAX_ENTRIES);
    entries
}

impl BridgeBar {
    /// The last message (an error, or what was loaded).
    pub fn status(&self) -> Option<&str> {
        self.status.as_deref()
    }

    /// The path in the field.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Puts `path` in the field (where the picker starts: its folder, or itself).
    pub fn set_path(&mut self, path: &str) {
        self.path = path.to_owned();
    }

    /// The folder the picker shows: the typed path if it is a folder, else its parent,
    /// else the home folder.
    fn browse_folder(&self) -> std::path::PathBuf {
        let typed = Path::new(self.path.trim());
        if typed.is_dir() {
            return typed.to_path_buf();
        }
        match typed.parent() {
            Some(parent) if parent.is_dir() => parent.to_path_buf(),
            _ => std::env::var_os("HOME")
                .map(std::path::PathBuf::from)
                .unwrap_or_else(|| std::path::PathBuf::from(".")),
        }
    }

    /// The picker: the folder's parent, subfolders and bridge files; a folder opens, a
    /// file goes into the field (then **Load bridge**).
    fn show_picker(&mut self, ui: &mut Ui) {
        let folder = self.browse_folder();
        ui.end_row();
        ui.weak(folder.display().to_string());
        if let Some(parent) = folder.parent() {
            if ui.button("..").clicked() {
                self.path = parent.display().to_string();
            }
        }
        for (path, is_dir) in bridge_entries(&folder) {
            let name = path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            let label = if is_dir { format!("{name}/") } else { name };
            if ui.button(label).clicked() {
                self.path = path.display().to_string();
                if !is_dir {
                    self.browsing = false;
                }
            }
        }
    }

    pub fn show(&mut self, ui: &mut Ui, params: &ColophonyParams, context: &GuiContext) {
        let kind: InstrumentKind = params.instrument.value().into();
        let chosen = user_bridges::chosen_name(&params.user_bridges, kind);
        ui.label(format!(
            "{} bridge: {}",
            kind.name(),
            chosen.as_deref().unwrap_or("shipped (generic)")
        ));
        let label = ui.label(BRIDGE_FILE_LABEL).id;
        ui.add(
            egui::TextEdit::singleline(&mut self.path)
                .hint_text("bridge .json (colophony fit-bridge)")
                .desired_width(220.0),
        )
        .labelled_by(label);
        if ui.selectable_label(self.browsing, BROWSE_LABEL).clicked() {
            self.browsing = !self.browsing;
        }
        let path = self.path.trim().to_owned();
        if ui
            .add_enabled(!path.is_empty(), egui::Button::new(LOAD_BRIDGE_LABEL))
            .clicked()
        {
            self.status = Some(
                match user_bridges::choose_file(&params.user_bridges, kind, Path::new(&path)) {
                    Ok(name) => {
                        context.request_restart();
                        format!("{name}: kept in the project, playing after the restart")
                    }
                    Err(e) => e,
                },
            );
        }
        if ui
            .add_enabled(chosen.is_some(), egui::Button::new(SHIPPED_BRIDGE_LABEL))
            .clicked()
        {
            user_bridges::forget(&params.user_bridges, kind);
            context.request_restart();
            self.status = Some("the shipped bridge, after the restart".into());
        }
        if let Some(status) = &self.status {
            ui.weak(status);
        }
        if self.browsing {
            self.show_picker(ui);
        }
    }
}
