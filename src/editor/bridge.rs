//! The editor's bridge row (with the strings): the bridge the current instrument plays,
//! a file to load in its place, and the way back to the shipped one
//! ([`crate::user_bridges`]). A new bridge asks the host to restart the plugin, which
//! rebuilds the thermal instruments on it and the point-bow body from its passive
//! reduction ([`crate::dsp::body::body_from_bridge`]).

use crate::dsp::instrument::InstrumentKind;
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

/// The path typed and the last message.
#[derive(Debug, Default)]
pub struct BridgeBar {
    path: String,
    status: Option<String>,
}

impl BridgeBar {
    /// The last message (an error, or what was loaded).
    pub fn status(&self) -> Option<&str> {
        self.status.as_deref()
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
    }
}
