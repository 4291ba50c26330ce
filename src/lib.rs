//! Colophony: a physically modelled bowed-string instrument.
//!
//! This file is only the plugin glue (CLAP and VST3 through nice-plug): parameters and
//! MIDI in, the DSP core ([`dsp`]) in the middle, stereo out. The DSP core never imports the
//! plugin framework. [`render`] is the offline renderer behind the `colophony` binary and
//! [`analysis`] the signal measurements the tests and tools share.

pub mod admittance_fit;
pub mod analysis;
pub mod bench;
pub mod dsp;
pub mod editor;
pub mod figures;
pub mod intonation_fit;
pub mod params;
pub mod playing_space;
pub mod playing_space_figure;
pub mod precision;
pub mod quality;
pub mod render;

use dsp::instrument::{BowControl, Instrument, InstrumentKind, PITCH_BEND_SEMITONES};
use dsp::rubbed::{RubbedInstrument, RubbedPreset};
use dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};

/// The bow settings at which a rubbed preset plays at its own velocity and force.
const DEFAULT_BOW: BowControl = BowControl {
    velocity_m_per_s: 0.1,
    force_n: 1.0,
    position_beta: 0.1,
};
use nice_plug::midi::Key;
use nice_plug::prelude::*;
use params::ColophonyParams;
use quality::Quality;
use std::sync::Arc;

/// Samples between two tail estimates (see `Colophony::status`).
const TAIL_EVERY: usize = 2048;

/// What the notes play: the waveguide strings with one of paper A's laws, paper B's
/// thermal instrument of one kind (index into [`InstrumentKind::ALL`]), or a rubbed object.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    Strings,
    Thermal(usize),
    Rubbed(RubbedPreset),
}

pub struct Colophony {
    params: Arc<ColophonyParams>,
    instrument: Instrument,
    /// Paper B's instrument, one per kind (violin, viola, cello), allocated in `activate`:
    /// switching kind or model lets the one switched away from ring on.
    thermal: Vec<ThermalInstrument>,
    rubbed: RubbedInstrument,
    source: Source,
    /// Held notes, so a source switch can move them to the new source.
    held: [bool; 128],
    /// The last note the strings took; the editor draws its Schelleng window.
    last_note: Option<u8>,
    /// Written once per block for the editor (one relaxed atomic store).
    editor_link: Arc<editor::EditorLink>,
    /// The thermal node count `quality = auto` chose at the last note-on.
    auto_nodes: usize,
    sample_rate_hz: f64,
    /// The last tail estimate (samples left) and the samples processed since it: the
    /// estimate walks every delay line, so it is renewed only every [`TAIL_EVERY`] samples.
    tail: Option<(f64, usize)>,
    /// The thermal bow's nodes, summed for the editor while it listens.
    node_probe: editor::nodes::NodeProbe,
}

impl Default for Colophony {
    fn default() -> Self {
        let params = Arc::new(ColophonyParams::default());
        let kind: InstrumentKind = params.instrument.value().into();
        Self {
            instrument: Instrument::new(kind, 48_000.0),
            thermal: Vec::new(),
            rubbed: RubbedInstrument::new(48_000.0),
            source: Source::Strings,
            held: [false; 128],
            last_note: None,
            editor_link: Arc::new(editor::EditorLink::default()),
            auto_nodes: quality::GOOD_NODES,
            sample_rate_hz: 48_000.0,
            tail: None,
            node_probe: editor::nodes::NodeProbe::default(),
            params,
        }
    }
}

impl Colophony {
    fn note_on(&mut self, note: u8) {
        // A bow lands: whatever tail was estimated no longer holds.
        self.tail = None;
        match self.source {
            // Notes the instrument cannot play are ignored.
            Source::Strings => {
                if self.instrument.note_on(note).is_some() {
                    self.held[note as usize & 127] = true;
                    self.last_note = Some(note);
                }
            }
            Source::Thermal(k) => {
                self.choose_auto_nodes(note);
                let settings = self.thermal_settings();
                if let Some(engine) = self.thermal.get_mut(k) {
                    // A new node count fades the instrument out and lands the note after.
                    engine.set_settings(settings);
                    if engine.note_on(note).is_some() {
                        self.held[note as usize & 127] = true;
                        self.last_note = Some(note);
                    }
                }
            }
            Source::Rubbed(_) => {
                if !self.held[note as usize & 127] {
                    self.held[note as usize & 127] = true;
                    self.rubbed.note_on();
                }
            }
        }
    }

    fn note_off(&mut self, note: u8) {
        let was_held = std::mem::replace(&mut self.held[note as usize & 127], false);
        match self.source {
            Source::Strings => self.instrument.note_off(note),
            Source::Thermal(k) => {
                if let Some(engine) = self.thermal.get_mut(k) {
                    engine.note_off(note);
                }
            }
            Source::Rubbed(_) if was_held => self.rubbed.note_off(),
            Source::Rubbed(_) => {}
        }
    }

    fn all_notes_off(&mut self) {
        self.held = [false; 128];
        self.instrument.all_notes_off();
        for engine in &mut self.thermal {
            engine.all_notes_off();
        }
        self.rubbed.all_notes_off();
    }

    /// The source the parameters ask for.
    fn wanted_source(&self) -> Source {
        let p = &self.params;
        match (
            p.resonator.value().preset(),
            p.friction_model.value().point_law(),
        ) {
            (Some(preset), _) => Source::Rubbed(preset),
            (None, Some(_)) => Source::Strings,
            (None, None) => {
                let kind: InstrumentKind = p.instrument.value().into();
                let k = InstrumentKind::ALL.iter().position(|x| *x == kind);
                Source::Thermal(k.unwrap_or(0))
            }
        }
    }

    /// Applies the block's source: held notes move to the new source (its bow lands over
    /// the usual ramp) and the old one rings on, so there is no click.
    fn apply_source(&mut self, choice: Source) {
        if choice == self.source {
            return;
        }
        let held = self.held;
        self.all_notes_off();
        self.source = choice;
        if let Source::Rubbed(preset) = choice {
            self.rubbed.set_preset(preset);
        }
        for (note, down) in held.iter().enumerate() {
            if *down {
                self.note_on(note as u8);
            }
        }
    }

    fn thermal_settings(&self) -> ThermalSettings {
        let p = &self.params;
        let nodes = match p.quality.value().preset() {
            None => p.bow_nodes.value().max(1) as usize,
            Some(Quality::Auto) => self.auto_nodes,
            Some(q) => q.fixed_thermal_nodes().unwrap_or(quality::GOOD_NODES),
        };
        ThermalSettings {
            nodes,
            width_m: p.bow_width_mm.value() as f64 * 1e-3,
        }
    }

    /// What the host hears about this block (CLAP process status and tail extension, VST3
    /// `getTailSamples`):
    /// - `KeepAlive` while a bow or an exciter is on;
    /// - `Tail(samples)` while lifted strings or rubbed objects ring out (the waveguide
    ///   body's last blocks after its strings slept count as one sample, renewed while it
    ///   rings);
    /// - `Normal` once silent, so a CLAP host may stop calling `process` until input.
    fn status(&mut self, block: usize) -> ProcessStatus {
        if let Some((left, since)) = self.tail {
            if since + block < TAIL_EVERY {
                let left = (left - block as f64).max(1.0);
                self.tail = Some((left, since + block));
                return ProcessStatus::Tail(left as u32);
            }
        }
        self.tail = None;
        let mut tail_s = 0.0f64;
        let mut sounding = false;
        if self.rubbed.is_sounding() {
            sounding = true;
            match self.rubbed.ring_out_samples() {
                Some(n) => tail_s = n / self.sample_rate_hz,
                None => return ProcessStatus::KeepAlive,
            }
        }
        let engines = std::iter::once(
            self.instrument
                .is_ringing()
                .then(|| self.instrument.ring_out_s()),
        )
        .chain(
            self.thermal
                .iter()
                .map(|e| e.is_sounding().then(|| e.ring_out_s())),
        );
        for engine in engines.flatten() {
            sounding = true;
            match engine {
                Some(s) => tail_s = tail_s.max(s),
                None => return ProcessStatus::KeepAlive,
            }
        }
        if !sounding {
            return ProcessStatus::Normal;
        }
        // At least one sample while anything rings; below CLAP's "infinite" (i32::MAX).
        let samples = (tail_s * self.sample_rate_hz)
            .ceil()
            .clamp(1.0, (i32::MAX - 1) as f64);
        self.tail = Some((samples, 0));
        ProcessStatus::Tail(samples as u32)
    }

    /// `quality = auto`: the node count for a new note at the current bow position, kept
    /// if the current one is close enough ([`quality::auto_needs_rebuild`]).
    fn choose_auto_nodes(&mut self, note: u8) {
        let p = &self.params;
        if p.quality.value() != params::QualityChoice::Auto {
            return;
        }
        let wanted = quality::auto_nodes(
            p.instrument.value().into(),
            dsp::instrument::midi_to_hz(note as f64),
            p.bow_position.value() as f64,
            p.bow_width_mm.value() as f64 * 1e-3,
        );
        if quality::auto_needs_rebuild(self.auto_nodes, wanted) {
            self.auto_nodes = wanted;
        }
    }

    fn handle_event(&mut self, event: NoteEvent<()>) {
        match event {
            NoteEvent::NoteOn {
                key: Key::Number(note),
                ..
            } => self.note_on(note),
            NoteEvent::NoteOff {
                key: Key::Number(note),
                ..
            } => self.note_off(note),
            NoteEvent::NoteOff {
                key: Key::Wildcard, ..
            }
            | NoteEvent::Choke { .. } => self.all_notes_off(),
            NoteEvent::MidiPitchBend { value, .. } => {
                let semitones = (value as f64 - 0.5) * 2.0 * PITCH_BEND_SEMITONES;
                self.instrument.set_pitch_bend(semitones);
                for engine in &mut self.thermal {
                    engine.set_pitch_bend(semitones);
                }
            }
            _ => {}
        }
    }
}

impl Plugin for Colophony {
    const NAME: &'static str = "Colophony";
    const VENDOR: &'static str = "Colophony";
    const URL: &'static str = "https://example.invalid/colophony";
    const EMAIL: &'static str = "colophony@example.invalid";
    const VERSION: &'static str = env!("CARGO_PKG_VERSION");

    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = &[AudioIOLayout {
        main_input_channels: None,
        main_output_channels: NonZeroU32::new(2),
        ..AudioIOLayout::const_default()
    }];

    // `MidiCCs`: pitch bend arrives as `MidiPitchBend` only at this level.
    const MIDI_INPUT: MidiConfig = MidiConfig::MidiCCs;
    const SAMPLE_ACCURATE_AUTOMATION: bool = true;

    type Editor = editor::ColophonyEditor;
    type SysExMessage = ();
    type BackgroundTask = ();

    fn params(&self) -> Arc<dyn Params> {
        self.params.clone()
    }

    fn editor(&mut self, _async_executor: AsyncExecutor<Self>) -> Option<Self::Editor> {
        Some(editor::ColophonyEditor::new(
            self.params.clone(),
            self.editor_link.clone(),
        ))
    }

    fn activate(
        &mut self,
        _audio_io_layout: &AudioIOLayout,
        buffer_config: &BufferConfig,
        _context: &mut impl ActivateContext<Self>,
    ) -> bool {
        // Every buffer is sized here, never in `process`.
        let kind: InstrumentKind = self.params.instrument.value().into();
        let fs = buffer_config.sample_rate as f64;
        self.instrument = Instrument::new(kind, fs);
        let settings = self.thermal_settings();
        self.thermal.clear();
        for kind in InstrumentKind::ALL {
            let bridge = match kind {
                InstrumentKind::Cello => admittance_fit::shipped_cello_bridge(),
                // The viola borrows the violin's generic bridge (no viola data shipped).
                InstrumentKind::Violin | InstrumentKind::Viola => {
                    admittance_fit::shipped_violin_bridge()
                }
            };
            match ThermalInstrument::new(kind, &bridge.modes, fs, settings) {
                Ok(engine) => self.thermal.push(engine),
                Err(e) => {
                    nice_log!("cannot build the thermal {}: {e}", kind.name());
                    return false;
                }
            }
        }
        self.rubbed = RubbedInstrument::new(fs);
        self.source = Source::Strings;
        self.held = [false; 128];
        self.editor_link.scope.set_sample_rate(fs as f32);
        self.sample_rate_hz = fs;
        self.tail = None;
        true
    }

    fn reset(&mut self) {
        self.instrument.reset();
        for engine in &mut self.thermal {
            engine.reset();
        }
        self.rubbed.reset();
        self.held = [false; 128];
        let p = &self.params;
        p.bow_velocity.smoothed.reset(p.bow_velocity.value());
        p.bow_force.smoothed.reset(p.bow_force.value());
        p.bow_position.smoothed.reset(p.bow_position.value());
        p.gain.smoothed.reset(p.gain.value());
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        _aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        let p = &self.params;
        // The waveguide strings change instrument at once (silenced) only while they are
        // what the notes play; ringing on behind another source, they finish first.
        let wanted = self.wanted_source();
        if wanted == Source::Strings || !self.instrument.is_sounding() {
            self.instrument.set_kind(p.instrument.value().into());
        }
        // The rubbed objects keep the last point law while the thermal model is chosen.
        if let Some(friction) = p.friction_model.value().point_law() {
            self.instrument.set_friction_model(friction);
            self.rubbed.set_friction_model(friction);
        }
        // Custom quality solves the bristle laws to the reference's tolerance.
        let tolerance = p
            .quality
            .value()
            .preset()
            .unwrap_or(Quality::Reference)
            .newton_tolerance_m_per_s();
        self.instrument.set_newton_tolerance(tolerance);
        self.rubbed.set_newton_tolerance(tolerance);
        let reference = p.reference_pitch.value() as f64;
        self.instrument.set_reference_pitch(reference);
        for engine in &mut self.thermal {
            engine.set_reference_pitch(reference);
        }
        let preferred = p.string.value().index();
        self.instrument.set_preferred_string(preferred);
        for engine in &mut self.thermal {
            engine.set_preferred_string(preferred);
        }
        let settings = self.thermal_settings();
        for engine in &mut self.thermal {
            engine.set_settings(settings);
        }
        self.apply_source(wanted);
        self.instrument.update_sleep();
        for engine in &mut self.thermal {
            engine.update_sleep();
        }
        self.rubbed.update_sleep();
        // The editor's live views are fed only while an editor shows them.
        let live = self.editor_link.is_listening();
        let mut next_event = context.next_event();
        for (sample, mut channels) in buffer.iter_samples().enumerate() {
            while let Some(event) = next_event {
                if event.timing() > sample as u32 {
                    break;
                }
                self.handle_event(event);
                next_event = context.next_event();
            }
            let p = &self.params;
            let bow = BowControl {
                velocity_m_per_s: p.bow_velocity.smoothed.next() as f64,
                force_n: p.bow_force.smoothed.next() as f64,
                position_beta: p.bow_position.smoothed.next() as f64,
            };
            let gain = util::db_to_gain(p.gain.smoothed.next()) as f64;
            // Every source ticks while it sounds: the one just switched away from rings on.
            let mut frame = self.instrument.tick(bow);
            for (k, engine) in self.thermal.iter_mut().enumerate() {
                if engine.is_sounding() {
                    let f = engine.tick(bow);
                    frame.audio += f.audio;
                    if self.source == Source::Thermal(k) {
                        frame.bow_point_velocity_m_per_s = f.bow_point_velocity_m_per_s;
                        frame.friction_force_n = f.friction_force_n;
                    }
                }
            }
            if live {
                self.editor_link
                    .scope
                    .push(editor::live::ContactSample::new(&frame, &bow));
                if let Source::Thermal(k) = self.source {
                    if let Some(engine) = self.thermal.get(k) {
                        self.node_probe
                            .add_string(engine.probed_string(), &self.editor_link);
                    }
                }
            }
            let mut audio = frame.audio;
            if self.rubbed.is_sounding() {
                audio += self.rubbed.tick(
                    bow.velocity_m_per_s / DEFAULT_BOW.velocity_m_per_s,
                    bow.force_n / DEFAULT_BOW.force_n,
                );
            }
            let out = dsp::filters::safety_limit(dsp::filters::flush_tiny(audio * gain)) as f32;
            for s in channels.iter_mut() {
                *s = out;
            }
        }
        // Events at or after the block's end (none should be) are still applied.
        while let Some(event) = next_event {
            self.handle_event(event);
            next_event = context.next_event();
        }
        self.editor_link.set_note(self.last_note);
        self.status(buffer.samples())
    }
}

impl ClapPlugin for Colophony {
    const CLAP_ID: &'static str = "org.colophony.bowed-string";
    const CLAP_DESCRIPTION: Option<&'static str> = Some("Physically modelled bowed strings");
    const CLAP_MANUAL_URL: Option<&'static str> = None;
    const CLAP_SUPPORT_URL: Option<&'static str> = None;
    const CLAP_FEATURES: &'static [ClapFeature] = &[
        ClapFeature::Instrument,
        ClapFeature::Synthesizer,
        ClapFeature::Stereo,
    ];
}

impl Vst3Plugin for Colophony {
    const VST3_CLASS_ID: [u8; 16] = *b"ColophonyBowedSt";
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] =
        &[Vst3SubCategory::Instrument, Vst3SubCategory::Synth];
}

nice_export_clap!(Colophony);
nice_export_vst3!(Colophony);
