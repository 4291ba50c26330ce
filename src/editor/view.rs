//! The editor's contents, independent of the window: the selectors along the top, the XY
//! pad with the Schelleng window, and the side panel with the bow sliders and the window's
//! numbers. [`EditorUi::ui`] draws one frame into any `egui::Ui`, which is how the editor
//! tests drive it without a window.

use super::bridge::BridgeBar;
use super::live::{paint_friction_loop, paint_velocity_trace, SCOPE_LEN};
use super::midi_map_page::MidiMapPage;
use super::nodes::{paint_slip_image, paint_temperature_profile, NodeRecord, RING_LEN};
use super::pad::{format_force, format_velocity, XyPad, MAX_FORCE_COLOUR, MIN_FORCE_COLOUR};
use super::presets::PresetBar;
use super::{EditorLink, EditorSize};
use crate::dsp::intonation::TunedModel;
use crate::dsp::vocabulary::{midi_to_hz, InstrumentKind};
use crate::measure::contact::ContactSample;
use crate::measure::regime::{classify_regime, Regime};
use crate::measure::window::{measured, model_coefficients, SchellengWindow};
use crate::params::{ColophonyParams, FrictionChoice, QualityChoice, ResonatorChoice};
use egui::{vec2, Color32, Layout, RichText, Ui};
use nice_plug::context::gui::GuiContext;
use nice_plug::prelude::{Enum, EnumParam, ParamSetter};
use nice_plug_egui::resizable_window::ResizableWindow;
use nice_plug_egui::widgets::ParamSlider;
use std::sync::Arc;
use std::time::Duration;

/// The checkbox that shows the MIDI map page.
pub const MIDI_MAP_LABEL: &str = "MIDI map";
/// Width of the side panel, points.
const SIDE_WIDTH: f32 = 290.0;
/// Height of the live views' row, points.
const LIVE_HEIGHT: f32 = 170.0;
/// Height of the thermal bow's row (shown with the thermal model), points.
const THERMAL_HEIGHT: f32 = 150.0;
/// Node records the slip image shows (5 ms each: 0.64 s).
const SLIP_IMAGE_RECORDS: usize = 128;
/// Periods of the current note the velocity trace shows.
const TRACE_PERIODS: f32 = 3.0;
/// Periods of the current note the regime is detected from (the ring holds more than
/// five of the lowest note at 96 kHz, and [`Scope::copy_latest`] caps the count).
///
/// [`Scope::copy_latest`]: super::live::Scope::copy_latest
const REGIME_PERIODS: f32 = 8.0;
const HELMHOLTZ_COLOUR: Color32 = Color32::from_rgb(120, 210, 120);
/// How often the live views look for new samples.
const LIVE_REFRESH: Duration = Duration::from_millis(33);

/// One open editor's state: the parameters, the link to the audio thread, the host context
/// the gestures go to, and the pad.
pub struct EditorUi {
    params: Arc<ColophonyParams>,
    link: Arc<EditorLink>,
    context: GuiContext,
    pad: XyPad,
    /// Whether the live views are shown (and fed).
    pub live: bool,
    /// The live samples copied out of the scope, reused every frame.
    samples: Vec<ContactSample>,
    /// The regime detected from [`Self::samples`] (`None`: too few samples yet).
    detected: Option<Regime>,
    /// The thermal bow's node records copied out of the ring, reused every frame.
    records: Vec<NodeRecord>,
    /// The preset selector and "save as".
    presets: PresetBar,
    /// The instrument's bridge.
    bridge: BridgeBar,
    /// Whether the MIDI map page is shown in place of the pad.
    pub show_midi_map: bool,
    midi_map: MidiMapPage,
}

impl EditorUi {
    pub fn new(params: Arc<ColophonyParams>, link: Arc<EditorLink>, context: GuiContext) -> Self {
        Self {
            params,
            link,
            context,
            pad: XyPad::default(),
            live: true,
            samples: Vec::with_capacity(SCOPE_LEN),
            detected: None,
            records: Vec::with_capacity(RING_LEN),
            presets: PresetBar::default(),
            bridge: BridgeBar::default(),
            show_midi_map: false,
            midi_map: MidiMapPage::default(),
        }
    }

    /// The MIDI map page (its learn state and last message).
    pub fn midi_map_page(&self) -> &MidiMapPage {
        &self.midi_map
    }

    /// The bridge row's last message (an error, or what was loaded).
    pub fn bridge_status(&self) -> Option<&str> {
        self.bridge.status()
    }

    /// The bridge row (its path field and picker).
    pub fn bridge_mut(&mut self) -> &mut BridgeBar {
        &mut self.bridge
    }

    /// The preset selector and "save as" (to choose another user preset folder).
    pub fn presets_mut(&mut self) -> &mut PresetBar {
        &mut self.presets
    }

    pub fn pad(&self) -> &XyPad {
        &self.pad
    }

    /// The regime detected from the live samples on the last frame (`None` while the
    /// live views are off or hold too few samples).
    pub fn detected_regime(&self) -> Option<Regime> {
        self.detected
    }

    /// Stops the audio thread feeding the live views (the editor closing).
    pub fn stop_listening(&self) {
        self.link.set_listening(false);
    }

    /// Ends a pad gesture left open (the editor closing mid-drag).
    pub fn end_gestures(&mut self) {
        let setter = self.context.param_setter();
        self.pad
            .release(&setter, &self.params.bow_velocity, &self.params.bow_force);
    }

    /// The note the Schelleng window is drawn for: the last note the strings played, or
    /// (before any) the instrument's third string open (cello and viola D, violin A).
    pub fn window_note(&self, kind: InstrumentKind) -> u8 {
        self.link
            .note()
            .filter(|&n| kind.string_for_note(n).is_some())
            .unwrap_or(kind.open_notes()[2])
    }

    /// The string (0 = the lowest) that plays `note` with the String parameter's choice.
    /// A note keeps its string if the choice changes while it sounds; the window follows
    /// the choice at once.
    fn window_string(&self, kind: InstrumentKind, note: u8) -> usize {
        kind.string_for_note_on(note, self.params.string.value().index())
            .unwrap_or(0)
    }

    /// What the strings multiply the force parameter by on `string` (String Weight; 1
    /// when it is off): the string's impedance over the model's reference.
    fn string_weight(&self, kind: InstrumentKind, string: usize) -> f64 {
        if !self.params.string_weight.value() {
            return 1.0;
        }
        let (reference, _, _) = model_coefficients(self.thermal());
        kind.string_weight_for(string, reference)
    }

    /// Whether the friction model is paper B's thermal bow.
    fn thermal(&self) -> bool {
        self.params.friction_model.value() == FrictionChoice::Thermal
    }

    /// The Schelleng window for the current note and bow position, `None` while the bow
    /// rubs a modal resonator instead of the strings.
    pub fn window(&self) -> Option<SchellengWindow> {
        if self.params.resonator.value() != ResonatorChoice::Strings {
            return None;
        }
        let kind: InstrumentKind = self.params.instrument.value().into();
        let beta = self.params.bow_position.value() as f64;
        let string = self.window_string(kind, self.window_note(kind));
        // Weighted strings: the window in the force parameter's units (the string is
        // bowed with the parameter times its weight, against each model's reference).
        Some(SchellengWindow::for_model(
            kind,
            string,
            beta,
            self.thermal(),
            self.params.string_weight.value(),
        ))
    }

    /// The shares of `window`'s `F_max` between which the chosen model was measured to
    /// hold Helmholtz motion on the window's string ([`measured`]; docs/playing-space.md),
    /// `None` where no force held it.
    pub fn played_shares(&self, window: &SchellengWindow) -> Option<(f64, f64)> {
        let kind: InstrumentKind = self.params.instrument.value().into();
        let string = self.window_string(kind, self.window_note(kind));
        let model = self
            .params
            .friction_model
            .value()
            .point_law()
            .map_or(TunedModel::Thermal, TunedModel::Point);
        measured().shares(model, kind, string, window.beta)
    }

    /// Draws one frame.
    pub fn ui(&mut self, ui: &mut Ui) {
        self.link.set_listening(self.live);
        ResizableWindow::new("colophony-editor")
            .min_size(vec2(EditorSize::MIN.width, EditorSize::MIN.height))
            .show(ui, |ui| {
                egui::Frame::new()
                    .inner_margin(egui::Margin::symmetric(8, 6))
                    .show(ui, |ui| self.contents(ui));
            });
    }

    fn contents(&mut self, ui: &mut Ui) {
        let params = self.params.clone();
        let context = self.context.clone();
        let setter = context.param_setter();
        // Wraps onto a second line in a narrow window.
        ui.horizontal_wrapped(|ui| {
            ui.heading("Colophony");
            ui.add_space(12.0);
            enum_selector(ui, "Instrument", &params.instrument, &setter);
            enum_selector(ui, "String", &params.string, &setter);
            enum_selector(ui, "Friction model", &params.friction_model, &setter);
            enum_selector(ui, "Quality", &params.quality, &setter);
            enum_selector(ui, "Resonator", &params.resonator, &setter);
            ui.checkbox(&mut self.live, "Live views");
            ui.checkbox(&mut self.show_midi_map, MIDI_MAP_LABEL);
        });
        ui.horizontal_wrapped(|ui| self.presets.show(ui, &context));
        // Every string model plays a chosen bridge: the thermal model on the bridge
        // itself, the point laws with its reduction as the body.
        if params.resonator.value() == ResonatorChoice::Strings {
            ui.horizontal_wrapped(|ui| self.bridge.show(ui, &params, &context));
        }
        ui.separator();
        if self.show_midi_map {
            // Both ways: a narrow window still reaches every row's last column.
            egui::ScrollArea::both().show(ui, |ui| {
                self.midi_map
                    .show(ui, &params.midi_map, &params.last_controller)
            });
            return;
        }

        if self.live {
            self.refresh_live(ui);
        } else {
            self.detected = None;
        }
        let window = self.window();
        let played = window.as_ref().and_then(|w| self.played_shares(w));
        let available = ui.available_size();
        let thermal_height = if self.thermal_shown() {
            THERMAL_HEIGHT
        } else {
            0.0
        };
        let live_height = if self.live { LIVE_HEIGHT } else { 0.0 } + thermal_height;
        ui.horizontal_top(|ui| {
            let pad_size = vec2(
                (available.x - SIDE_WIDTH - 12.0).max(200.0),
                (available.y - live_height - 8.0).max(200.0),
            );
            let (outer, _) = ui.allocate_exact_size(pad_size, egui::Sense::hover());
            let mut pad_ui = ui.new_child(egui::UiBuilder::new().max_rect(outer));
            self.pad.mark_played(self.link.played_bow());
            self.pad.show(
                &mut pad_ui,
                outer,
                &setter,
                &params.bow_velocity,
                &params.bow_force,
                window.as_ref(),
                played,
            );
            ui.add_space(8.0);
            ui.allocate_ui_with_layout(
                vec2(SIDE_WIDTH, pad_size.y),
                Layout::top_down(egui::Align::Min),
                |ui| {
                    ui.set_width(SIDE_WIDTH);
                    // Scrolls rather than spill over the live views in a short window.
                    egui::ScrollArea::vertical()
                        .max_height(pad_size.y)
                        .auto_shrink([false, true])
                        .show(ui, |ui| {
                            self.side_panel(ui, &setter, window.as_ref(), played)
                        });
                },
            );
        });
        if self.live {
            self.live_views(ui, vec2(available.x, LIVE_HEIGHT - 8.0));
        }
        if thermal_height > 0.0 {
            self.thermal_views(ui, vec2(available.x, THERMAL_HEIGHT - 8.0));
        }
    }

    /// The fundamental of the note the strings play (or the window's default note).
    fn note_hz(&self) -> f32 {
        let kind: InstrumentKind = self.params.instrument.value().into();
        midi_to_hz(self.window_note(kind) as f64) as f32
    }

    /// Copies the newest samples out of the scope and detects the regime from them.
    fn refresh_live(&mut self, ui: &Ui) {
        let scope = &self.link.scope;
        let f0 = self.note_hz();
        let sample_rate = scope.sample_rate();
        let wanted = (REGIME_PERIODS * sample_rate / f0).ceil() as usize;
        scope.copy_latest(wanted, &mut self.samples);
        self.detected = classify_regime(&self.samples, sample_rate, f0);
        if self.thermal_shown() {
            self.link
                .nodes
                .copy_latest(SLIP_IMAGE_RECORDS, &mut self.records);
        }
        ui.ctx().request_repaint_after(LIVE_REFRESH);
    }

    /// Whether the thermal bow's views are shown: live views on, the thermal model chosen
    /// and the bow on the strings.
    pub fn thermal_shown(&self) -> bool {
        self.live && self.thermal() && self.params.resonator.value() == ResonatorChoice::Strings
    }

    /// Two plot areas side by side in `rect`, with room for the axis labels.
    fn plot_pair(rect: egui::Rect) -> [egui::Rect; 2] {
        let margin_left = 52.0;
        let gap = 16.0;
        let margin_right = 8.0;
        let width = (rect.width() - 2.0 * margin_left - gap - margin_right) / 2.0;
        [0.0, 1.0].map(|i| {
            let left = rect.left() + margin_left + i * (width + margin_left + gap);
            egui::Rect::from_min_size(
                egui::pos2(left, rect.top() + 4.0),
                vec2(width, rect.height() - 22.0),
            )
        })
    }

    /// The temperature across the bow and the slip image side by side.
    fn thermal_views(&self, ui: &mut Ui, size: egui::Vec2) {
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::hover());
        // The newest record in words: the views' accessible value (the tests read it).
        response.widget_info(|| {
            let mut info =
                egui::WidgetInfo::labeled(egui::Role::Image, ui.is_enabled(), THERMAL_LABEL);
            info.current_text_value = Some(
                self.records
                    .last()
                    .map_or_else(|| "waiting for audio".to_owned(), describe_record),
            );
            info
        });
        if self.records.is_empty() {
            paint_waiting(ui, rect, "Thermal bow: waiting for audio");
            return;
        }
        let [left, right] = Self::plot_pair(rect);
        paint_temperature_profile(ui, left, &self.records);
        paint_slip_image(ui, right, &self.records);
    }

    /// The velocity trace and the friction loop side by side.
    fn live_views(&mut self, ui: &mut Ui, size: egui::Vec2) {
        let sample_rate = self.link.scope.sample_rate();
        let shown = (TRACE_PERIODS * sample_rate / self.note_hz()).ceil() as usize;
        let samples = &self.samples[self.samples.len().saturating_sub(shown)..];

        let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
        if samples.is_empty() {
            paint_waiting(ui, rect, "Live views: waiting for audio (play a note)");
            return;
        }
        paint_velocity_trace(
            ui,
            Self::plot_pair(rect)[0],
            samples,
            sample_rate,
            self.params.bow_velocity.value(),
        );
        paint_friction_loop(ui, Self::plot_pair(rect)[1], samples);
    }

    /// `played`: the window's measured shares ([`Self::played_shares`]), looked up once a
    /// frame.
    fn side_panel(
        &self,
        ui: &mut Ui,
        setter: &ParamSetter,
        window: Option<&SchellengWindow>,
        played: Option<(f64, f64)>,
    ) {
        let p = &self.params;
        ui.label(RichText::new("Bow").strong());
        egui::Grid::new("bow-sliders")
            .num_columns(2)
            .spacing(vec2(8.0, 4.0))
            .show(ui, |ui| {
                ui.label("Velocity");
                ui.add(ParamSlider::for_param(&p.bow_velocity, setter).with_width(100.0));
                ui.end_row();
                ui.label("Force");
                ui.add(ParamSlider::for_param(&p.bow_force, setter).with_width(100.0));
                ui.end_row();
                ui.label("Position");
                ui.add(ParamSlider::for_param(&p.bow_position, setter).with_width(100.0));
                ui.end_row();
                ui.label("Output gain");
                ui.add(ParamSlider::for_param(&p.gain, setter).with_width(100.0));
                ui.end_row();
                // The thermal bow's discretisation: shown only while that model plays; the
                // node count is the Quality preset's unless the quality is custom.
                if p.friction_model.value() == FrictionChoice::Thermal {
                    ui.label("Bow nodes");
                    if p.quality.value() == QualityChoice::Custom {
                        ui.add(ParamSlider::for_param(&p.bow_nodes, setter).with_width(100.0));
                    } else {
                        ui.label(RichText::new("set by Quality").weak());
                    }
                    ui.end_row();
                    ui.label("Bow width");
                    ui.add(ParamSlider::for_param(&p.bow_width_mm, setter).with_width(100.0));
                    ui.end_row();
                }
            });
        ui.add_space(4.0);
        ui.separator();
        let Some(w) = window else {
            ui.label(RichText::new("Schelleng window").strong());
            ui.label(format!(
                "Not shown: the bow rubs the {} resonator, not a string.",
                ResonatorChoice::variants()[p.resonator.value().to_index()].to_lowercase()
            ));
            return;
        };
        ui.label(RichText::new("Regime").strong());
        self.regime_lines(ui, w, played);
        ui.add_space(4.0);
        ui.separator();
        ui.label(RichText::new("Schelleng window").strong());
        let kind: InstrumentKind = p.instrument.value().into();
        let note = self.window_note(kind);
        let string = self.window_string(kind, note);
        let open = kind.open_notes()[string];
        // The string's own impedance and bridge resistance; the limits below are in the
        // force parameter's units, divided by the string's weight where it is weighted.
        let weight = self.string_weight(kind, string);
        let heard = if self.link.note().is_some() {
            "last note"
        } else {
            "no note yet"
        };
        let v = p.bow_velocity.value();
        let f = p.bow_force.value();
        let (f_min, f_max) = (w.min_force_n(v as f64), w.max_force_n(v as f64));
        egui::Grid::new("schelleng-numbers")
            .num_columns(2)
            .spacing(vec2(8.0, 3.0))
            .show(ui, |ui| {
                ui.label("Note");
                ui.label(format!(
                    "{} ({heard}), {:.1} Hz",
                    note_name(note),
                    midi_to_hz(note as f64)
                ));
                ui.end_row();
                ui.label("String");
                ui.label(format!("{} string", pitch_class(open)));
                ui.end_row();
                ui.label("Articulation");
                ui.label(self.link.articulation().name());
                ui.end_row();
                ui.label("Z0");
                ui.label(format!("{:.3} kg/s", w.z0_kg_per_s * weight));
                ui.end_row();
                ui.label("Bridge R");
                ui.label(format!(
                    "{:.0} kg/s (2 Q1 Z0 / pi)",
                    w.bridge_r_kg_per_s * weight
                ));
                ui.end_row();
                if (weight - 1.0).abs() > 1e-9 {
                    ui.label("String weight");
                    ui.label(format!(
                        "x {weight:.2} (the force below is the parameter's)"
                    ));
                    ui.end_row();
                }
                ui.label("mu_s, mu_d");
                ui.label(format!("{:.2}, {:.2}", w.mu_s, w.mu_d));
                ui.end_row();
                ui.label("At");
                ui.label(format!("{}, beta {:.3}", format_velocity(v), w.beta));
                ui.end_row();
                ui.label(RichText::new("F_max").color(MAX_FORCE_COLOUR));
                ui.label(format!("{f_max:.3} N"));
                ui.end_row();
                ui.label(RichText::new("F_min").color(MIN_FORCE_COLOUR));
                ui.label(format!("{f_min:.4} N"));
                ui.end_row();
                ui.label("Measured");
                ui.label(match played {
                    Some((lo, hi)) => format!(
                        "{:.3} to {:.3} N hold Helmholtz motion",
                        lo * f_max,
                        hi * f_max
                    ),
                    None => "no force held Helmholtz motion".into(),
                });
                ui.end_row();
                ui.label("Bow");
                ui.label(format_force(f));
                ui.end_row();
            });
    }

    /// The regime the window predicts for the bow and the one detected in the simulation.
    fn regime_lines(&self, ui: &mut Ui, window: &SchellengWindow, played: Option<(f64, f64)>) {
        let v = self.params.bow_velocity.value() as f64;
        let f = self.params.bow_force.value() as f64;
        let f_max = window.max_force_n(v);
        let (text, colour) = match played {
            Some((lo, hi)) => predicted_regime(v, f, lo * f_max, hi * f_max),
            None => (
                "no force measured to hold Helmholtz motion here",
                MAX_FORCE_COLOUR,
            ),
        };
        ui.label(RichText::new(format!("Predicted: {text}")).color(colour));
        let weak = ui.visuals().weak_text_color();
        let (text, colour) = match (self.live, self.detected) {
            (false, _) => ("(live views off)".to_owned(), weak),
            (true, None) => ("(waiting for audio)".to_owned(), weak),
            (true, Some(regime)) => (regime.describe(), regime_colour(regime)),
        };
        ui.label(RichText::new(format!("Detected: {text}")).color(colour));
    }
}

/// A faint note in the middle of an empty view.
fn paint_waiting(ui: &Ui, rect: egui::Rect, text: &str) {
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        text,
        egui::FontId::proportional(13.0),
        ui.visuals().weak_text_color(),
    );
}

/// Accessible label of the thermal bow's views.
pub const THERMAL_LABEL: &str = "Thermal bow: temperature and slipping per node";

/// A node record in words: the hottest node and the share of node-samples slipping.
pub fn describe_record(record: &NodeRecord) -> String {
    let nodes = &record.temperature_kelvin[..record.count];
    let hottest = nodes.iter().copied().fold(0.0f32, f32::max);
    let slipping =
        record.slip_fraction[..record.count].iter().sum::<f32>() / record.count.max(1) as f32;
    format!(
        "{} nodes, hottest {hottest:.1} K above ambient, slipping {:.0} % of the time",
        record.count,
        100.0 * slipping
    )
}

/// Where the bow sits relative to the window (`f_min` .. `f_max`: the forces measured to
/// hold Helmholtz motion), as Schelleng's diagram names the regions.
fn predicted_regime(v: f64, f: f64, f_min: f64, f_max: f64) -> (&'static str, Color32) {
    if f <= 0.0 {
        ("silent (bow lifted)", Color32::GRAY)
    } else if v == 0.0 {
        ("silent (bow at rest)", Color32::GRAY)
    } else if f > f_max {
        ("raucous (above the measured window)", MAX_FORCE_COLOUR)
    } else if f < f_min {
        (
            "multiple slips (below the measured window)",
            MIN_FORCE_COLOUR,
        )
    } else {
        ("Helmholtz motion", HELMHOLTZ_COLOUR)
    }
}

/// The colour of the region of Schelleng's diagram a detected regime belongs to.
fn regime_colour(regime: Regime) -> Color32 {
    match regime {
        Regime::Silent | Regime::Sliding => Color32::GRAY,
        Regime::Helmholtz => HELMHOLTZ_COLOUR,
        Regime::MultipleSlips(_) => MIN_FORCE_COLOUR,
        Regime::Raucous => MAX_FORCE_COLOUR,
    }
}

/// A labelled drop-down for an enum parameter; a choice is one begin/set/end gesture.
fn enum_selector<T: Enum + PartialEq + Copy + 'static>(
    ui: &mut Ui,
    label: &str,
    param: &EnumParam<T>,
    setter: &ParamSetter,
) {
    let current = param.value().to_index();
    let names = T::variants();
    let mut selected = current;
    let label_id = ui.label(label).id;
    egui::ComboBox::from_id_salt(label)
        .selected_text(names[current])
        .show_ui(ui, |ui| {
            for (index, name) in names.iter().enumerate() {
                ui.selectable_value(&mut selected, index, *name);
            }
        })
        .response
        .labelled_by(label_id);
    if selected != current {
        setter.begin_set_parameter(param);
        setter.set_parameter(param, T::from_index(selected));
        setter.end_set_parameter(param);
    }
}

const PITCH_CLASSES: [&str; 12] = [
    "C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B",
];

fn pitch_class(note: u8) -> &'static str {
    PITCH_CLASSES[note as usize % 12]
}

/// Scientific pitch name (MIDI 60 = C4).
pub fn note_name(note: u8) -> String {
    format!("{}{}", pitch_class(note), note as i32 / 12 - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn note_names_are_scientific_pitch() {
        assert_eq!(note_name(60), "C4");
        assert_eq!(note_name(50), "D3");
        assert_eq!(note_name(36), "C2");
        assert_eq!(note_name(69), "A4");
    }

    #[test]
    fn predicted_regime_follows_the_window() {
        let (lo, hi) = (0.04, 5.0);
        assert!(predicted_regime(0.1, 1.0, lo, hi)
            .0
            .starts_with("Helmholtz"));
        assert!(predicted_regime(0.1, 6.0, lo, hi).0.starts_with("raucous"));
        assert!(predicted_regime(0.1, 0.01, lo, hi)
            .0
            .starts_with("multiple"));
        assert!(predicted_regime(0.1, 0.0, lo, hi).0.starts_with("silent"));
    }
}
