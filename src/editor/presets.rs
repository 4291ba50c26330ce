//! The editor's preset bar: a selector of the factory and user presets, and "save as" to
//! the user folder ([`crate::presets`]).
//!
//! Choosing a preset hands the host a whole plugin state (the current one with the
//! preset's parameter values: every parameter the preset does not name at its default),
//! through nice-plug's `GuiContext::set_state`, so the host sees one state change, the
//! undo history and automation stay the host's, and the window size is kept. Saving
//! writes the current state's values as a preset file and lists it at once.

use crate::presets::{self, Preset};
use egui::Ui;
use nice_plug::context::gui::GuiContext;
use std::path::PathBuf;

/// The selector's accessible label.
pub const PRESET_LABEL: &str = "Preset";
/// The name field's label.
pub const PRESET_NAME_LABEL: &str = "Save as";
/// The save button's label.
pub const SAVE_LABEL: &str = "Save preset";

/// One preset the bar lists.
#[derive(Debug, Clone)]
struct Entry {
    preset: Preset,
    user: bool,
}

/// The bar's state: the listed presets, the last chosen, the name typed for saving and
/// the last message (an error or where a preset was saved).
#[derive(Debug)]
pub struct PresetBar {
    entries: Vec<Entry>,
    chosen: Option<String>,
    save_name: String,
    status: Option<String>,
    user_dir: Option<PathBuf>,
}

impl Default for PresetBar {
    fn default() -> Self {
        let mut bar = Self {
            entries: Vec::new(),
            chosen: None,
            save_name: String::new(),
            status: None,
            user_dir: presets::user_dir(),
        };
        bar.rescan();
        bar
    }
}

impl PresetBar {
    /// Lists the factory presets and the readable user presets again.
    pub fn rescan(&mut self) {
        self.entries = presets::factory()
            .into_iter()
            .map(|(_, preset)| Entry {
                preset,
                user: false,
            })
            .collect();
        if let Some(dir) = &self.user_dir {
            for (_, preset) in presets::user_presets(dir) {
                if let Ok(preset) = preset {
                    self.entries.push(Entry { preset, user: true });
                }
            }
        }
    }

    /// Lists and saves user presets in `dir` instead of [`presets::user_dir`].
    pub fn set_user_dir(&mut self, dir: Option<PathBuf>) {
        self.user_dir = dir;
        self.rescan();
    }

    /// The last message (an error, or where a preset was saved).
    pub fn status(&self) -> Option<&str> {
        self.status.as_deref()
    }

    pub fn show(&mut self, ui: &mut Ui, context: &GuiContext) {
        let label_id = ui.label(PRESET_LABEL).id;
        let mut picked = None;
        egui::ComboBox::from_id_salt(PRESET_LABEL)
            .selected_text(self.chosen.as_deref().unwrap_or("(none)"))
            .width(170.0)
            .show_ui(ui, |ui| {
                let mut user_heading = false;
                for (i, entry) in self.entries.iter().enumerate() {
                    if entry.user && !user_heading {
                        ui.separator();
                        ui.weak("user");
                        user_heading = true;
                    }
                    let chosen = self.chosen.as_deref() == Some(entry.preset.name.as_str());
                    if ui
                        .selectable_label(chosen, &entry.preset.name)
                        .on_hover_text(&entry.preset.description)
                        .clicked()
                    {
                        picked = Some(i);
                    }
                }
            })
            .response
            .labelled_by(label_id);
        if let Some(i) = picked {
            let preset = self.entries[i].preset.clone();
            match load(context, &preset) {
                Ok(()) => {
                    self.chosen = Some(preset.name.clone());
                    self.status = None;
                }
                Err(e) => self.status = Some(format!("{}: {e}", preset.name)),
            }
        }
        let label = ui.label(PRESET_NAME_LABEL).id;
        ui.add(
            egui::TextEdit::singleline(&mut self.save_name)
                .hint_text("name")
                .desired_width(110.0),
        )
        .labelled_by(label);
        let can_save = !self.save_name.trim().is_empty() && self.user_dir.is_some();
        if ui
            .add_enabled(can_save, egui::Button::new(SAVE_LABEL))
            .on_disabled_hover_text(match self.user_dir {
                None => "no user preset folder: set COLOPHONY_PRESET_DIR",
                Some(_) => "type a name first",
            })
            .clicked()
        {
            self.save(context);
        }
        if let Some(status) = &self.status {
            ui.weak(status);
        }
    }

    fn save(&mut self, context: &GuiContext) {
        let Some(dir) = self.user_dir.clone() else {
            return;
        };
        let name = self.save_name.trim().to_owned();
        let preset = Preset::from_state(&name, "saved from the editor", &context.get_state());
        match presets::save_user(&preset, &dir) {
            Ok(path) => {
                self.status = Some(format!("saved {}", path.display()));
                self.chosen = Some(name);
                self.save_name.clear();
                self.rescan();
            }
            Err(e) => self.status = Some(e),
        }
    }
}

/// Hands the host the current state with the preset's values.
fn load(context: &GuiContext, preset: &Preset) -> Result<(), String> {
    let params = preset.state_params()?;
    let mut state = context.get_state();
    state.params = params;
    context.set_state(state);
    Ok(())
}
