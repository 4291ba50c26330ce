//! The editor's MIDI map page: one row per mapping, with its controller (a
//! number, or **Learn**: click, then move a controller), its target, the target's value
//! at the controller's bottom and top, and the curve between; **Add mapping**, **Remove**
//! and **Default map**. Every change is written at once to the plugin's shared map
//! ([`crate::midi_learn::SharedMidiMap`]), which the audio thread picks up at its next
//! block and the project saves.

use crate::midi_learn::{LastController, SharedMidiMap};
use crate::performer::midi_map::{Mapping, MidiMap, Target, MAX_MAPPINGS};
use egui::Ui;
use std::time::Duration;

/// The button that learns a row's controller.
pub const LEARN_LABEL: &str = "Learn";
/// What the learn button says while it waits for a controller.
pub const LEARNING_LABEL: &str = "Move a controller";
/// The button that adds a mapping.
pub const ADD_MAPPING_LABEL: &str = "Add mapping";
/// The button that restores the default map.
pub const DEFAULT_MAP_LABEL: &str = "Default map";
/// A row's remove button.
pub const REMOVE_LABEL: &str = "Remove";

/// The page's own state: the row waiting for a controller, and the last message.
#[derive(Debug, Default)]
pub struct MidiMapPage {
    /// The slot learning, and the controller count when the learn began.
    learning: Option<(usize, u32)>,
    status: Option<String>,
}

impl MidiMapPage {
    /// The last message (what was learned).
    pub fn status(&self) -> Option<&str> {
        self.status.as_deref()
    }

    /// The slot waiting for a controller, if any.
    pub fn learning(&self) -> Option<usize> {
        self.learning.map(|(slot, _)| slot)
    }

    pub fn show(&mut self, ui: &mut Ui, shared: &SharedMidiMap, last: &LastController) {
        let mut map = shared.snapshot();
        let before = map;
        if let Some((slot, count)) = self.learning {
            let (now, cc) = last.get();
            if now != count {
                if let Some(mut m) = map.get(slot) {
                    m.cc = cc;
                    map.set(slot, Some(m));
                    self.status = Some(format!("{} learned CC {cc}", m.target.label()));
                }
                self.learning = None;
            } else {
                ui.ctx().request_repaint_after(Duration::from_millis(33));
            }
        }
        ui.label(
            "Each controller moves its targets from Min (controller at 0) to Max (at 127); \
             Curve bends the way between (0 straight). CC 6, 38, 100 and 101 set the \
             pitch-bend range (RPN 0) and MPE member channels play their own notes.",
        );
        // Narrower sliders than egui's default keep a row inside the editor's default
        // width (880) with room for the page's scroll bar.
        ui.spacing_mut().slider_width = 80.0;
        egui::Grid::new("midi-map")
            .striped(true)
            .num_columns(7)
            .show(ui, |ui| {
                // Each row's widgets are named by their column's header (screen readers,
                // and the tests, find them so).
                let header: Vec<egui::Id> = ["Controller", "", "Target", "Min", "Max", "Curve", ""]
                    .into_iter()
                    .map(|h| ui.strong(h).id)
                    .collect();
                ui.end_row();
                for slot in 0..MAX_MAPPINGS {
                    let Some(mut m) = map.get(slot) else {
                        continue;
                    };
                    let mut cc = m.cc as u32;
                    ui.add(egui::DragValue::new(&mut cc).range(0..=127).prefix("CC "))
                        .labelled_by(header[0]);
                    m.cc = cc as u8;
                    let learning = self.learning() == Some(slot);
                    let label = if learning {
                        LEARNING_LABEL
                    } else {
                        LEARN_LABEL
                    };
                    if ui.selectable_label(learning, label).clicked() {
                        self.learning = if learning {
                            None
                        } else {
                            Some((slot, last.get().0))
                        };
                    }
                    egui::ComboBox::from_id_salt(("midi-map-target", slot))
                        .selected_text(m.target.label())
                        .show_ui(ui, |ui| {
                            for t in Target::ALL {
                                ui.selectable_value(&mut m.target, t, t.label());
                            }
                        })
                        .response
                        .labelled_by(header[2]);
                    ui.add(egui::Slider::new(&mut m.min, 0.0..=1.0).fixed_decimals(2))
                        .labelled_by(header[3]);
                    ui.add(egui::Slider::new(&mut m.max, 0.0..=1.0).fixed_decimals(2))
                        .labelled_by(header[4]);
                    ui.add(egui::Slider::new(&mut m.curve, -1.0..=1.0).fixed_decimals(2))
                        .labelled_by(header[5]);
                    if ui.button(REMOVE_LABEL).clicked() {
                        map.set(slot, None);
                        if learning {
                            self.learning = None;
                        }
                    } else {
                        map.set(slot, Some(m));
                    }
                    ui.end_row();
                }
            });
        ui.horizontal(|ui| {
            let full = map.mappings().count() >= MAX_MAPPINGS;
            if ui
                .add_enabled(!full, egui::Button::new(ADD_MAPPING_LABEL))
                .clicked()
            {
                map.add(Mapping::new(1, Target::Dynamics));
            }
            if ui.button(DEFAULT_MAP_LABEL).clicked() {
                map = MidiMap::default();
                self.learning = None;
            }
            if let Some(status) = &self.status {
                ui.weak(status);
            }
        });
        if map != before {
            shared.store(&map);
        }
    }
}
