//! Colophony: a physically modelled bowed-string instrument.
//!
//! This file is only the plugin glue (CLAP and VST3 through nice-plug): parameters
//! ([`params`], read once per block into a [`performer::Setup`]) and MIDI events in, the
//! framework-free [`performer`] in the middle (source switching, held keys, dynamics and
//! vibrato, the host tail) driving the engines of [`dsp`], stereo out. Neither the
//! performer nor the DSP core imports the plugin framework. [`analysis`] holds the signal
//! measurements the tests and tools share. The tools (the `colophony` command: the
//! offline renderer, MIDI files, figures, benches, the precision bench and the
//! playing-space map, bridge fitting) are the workspace's other crate, `colophony-lab`
//! (`lab/`), which plays through this crate's performer and engines.

pub mod analysis;
pub mod dsp;
pub mod editor;
pub mod editor_state;
mod host_event;
pub mod measure;
pub mod midi_learn;
pub mod params;
pub mod performer;
pub mod presets;
pub mod quality;
pub mod telemetry;
pub mod user_bridges;

use dsp::vocabulary::{BowControl, InstrumentKind};
use nice_plug::prelude::*;
use params::ColophonyParams;
use performer::{Performer, Status};
use std::sync::Arc;

pub struct Colophony {
    params: Arc<ColophonyParams>,
    /// The engines, the source switching, the held keys and the tail ([`performer`]).
    performer: Performer,
    /// Written once per block for the editor (one relaxed atomic store).
    editor_link: Arc<editor::EditorLink>,
    /// The thermal bow's nodes, summed for the editor while it listens.
    node_probe: editor::nodes::NodeProbe,
    /// The MIDI map's sequence number the performer has ([`midi_learn::SharedMidiMap`]).
    midi_map_seen: u32,
}

impl Default for Colophony {
    fn default() -> Self {
        let params = Arc::new(ColophonyParams::default());
        let kind: InstrumentKind = params.instrument.value().into();
        Self {
            performer: Performer::new(kind),
            editor_link: Arc::new(editor::EditorLink::default()),
            node_probe: editor::nodes::NodeProbe::default(),
            midi_map_seen: 0,
            params,
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
    /// Room for every event a host may send in one block, allocated at construction.
    /// nice-plug's VST3 wrapper turns every point of its 16 x 130 hidden MIDI-controller
    /// parameters (`MidiConfig::MidiCCs`: 128 CCs, channel pressure and pitch bend per
    /// channel) into a note event, and keeps the block's events in a buffer of this
    /// capacity (its default 1024). A host that sends more than that in one block (a flush
    /// of all 2080, say; in Ardour the wrapper logged "Input note event buffer filled up!"
    /// four times in 6 s, what it sent there is not measured here) makes the wrapper
    /// allocate on the audio thread. 8192 holds a full flush three times over with our own
    /// parameters' automation and the notes.
    const INPUT_EVENT_CAPACITY: usize = 8192;

    type Editor = editor::ColophonyEditor;
    type SysExMessage = ();
    type BackgroundTask = ();

    fn filter_state(state: &mut PluginState) {
        presets::migrate_state(state);
    }

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
        context: &mut impl ActivateContext<Self>,
    ) -> bool {
        // Every buffer is sized here, never in `process`.
        let fs = buffer_config.sample_rate as f64;
        // The bridges saved with the project (a damaged one plays the shipped bridge).
        let (bridges, problems) = user_bridges::saved_modes(&self.params.user_bridges);
        for problem in problems {
            nice_log!("{problem}");
        }
        for (kind, bridge) in InstrumentKind::ALL.into_iter().zip(bridges) {
            self.performer.set_user_bridge(kind, bridge);
        }
        match self.performer.activate_or_shipped(&self.params.setup(), fs) {
            Ok(None) => {}
            Ok(Some(given_up)) => nice_log!("{given_up}"),
            Err(e) => {
                nice_log!("{e}");
                return false;
            }
        }
        self.editor_link.scope.set_sample_rate(fs as f32);
        // The playing source's resampler delay (0.23-0.25 ms; 1 ms at 8 kHz). Reported here only: a
        // report from `process` makes the wrapper wake the host's main thread from the
        // audio thread, and a CLAP host may only take a new latency while deactivated; a
        // source switched while playing keeps the reported value until the next activation.
        context.set_latency_samples(self.performer.latency_samples());
        true
    }

    fn reset(&mut self) {
        self.performer.reset();
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
        let mut setup = self.params.setup();
        setup.tempo_bpm = context.transport().tempo;
        self.performer.configure(&setup);
        // The editor or a loaded state changed the MIDI map (a read that overlaps a write
        // waits for the next block).
        if let Some(map) = self
            .params
            .midi_map
            .read_if_changed(&mut self.midi_map_seen)
        {
            self.performer.set_midi_map(&map);
        }
        // The editor's live views are fed only while an editor shows them.
        let Self {
            params,
            performer,
            editor_link,
            node_probe,
            ..
        } = self;
        let mut feed =
            |frame: &dsp::vocabulary::Frame, played: &BowControl, performer: &Performer| {
                editor_link
                    .scope
                    .push(measure::contact::ContactSample::new(frame, played));
                if let Some(string) = performer.probed_thermal_string() {
                    node_probe.add_from(
                        string.node_temperatures(),
                        string.node_sliding_velocities(),
                        editor_link,
                    );
                }
            };
        let live: Option<&mut dyn FnMut(&_, &_, &_)> = if editor_link.is_listening() {
            Some(&mut feed)
        } else {
            None
        };
        let status = performer.render_block(
            buffer.as_slice(),
            || loop {
                let event = context.next_event()?;
                let at = event.timing() as usize;
                if let NoteEvent::MidiCC { cc, .. } = event {
                    params.last_controller.record(cc);
                }
                if let Some(event) = host_event::performer_event(event) {
                    return Some((at, event));
                }
            },
            || next_controls(params),
            || settled(params),
            live,
        );
        self.editor_link.set_note(self.performer.last_note());
        self.editor_link.set_played_bow(self.performer.bowed_bow());
        self.editor_link
            .set_articulation(self.performer.articulation());
        host_status(status)
    }
}

/// Whether no bow parameter and not the gain is still smoothing (a settled smoother
/// returns its target on every call).
fn settled(p: &ColophonyParams) -> bool {
    !(p.bow_velocity.smoothed.is_smoothing()
        || p.bow_force.smoothed.is_smoothing()
        || p.bow_position.smoothed.is_smoothing()
        || p.gain.smoothed.is_smoothing())
}

/// The next sample's bow and output gain from the (smoothed) parameters.
#[inline]
fn next_controls(p: &ColophonyParams) -> (BowControl, f64) {
    let bow = BowControl {
        velocity_m_per_s: p.bow_velocity.smoothed.next() as f64,
        force_n: p.bow_force.smoothed.next() as f64,
        position_beta: p.bow_position.smoothed.next() as f64,
    };
    (bow, util::db_to_gain(p.gain.smoothed.next()) as f64)
}

/// The performer's status in nice-plug's words.
fn host_status(status: Status) -> ProcessStatus {
    match status {
        Status::KeepAlive => ProcessStatus::KeepAlive,
        Status::Tail(samples) => ProcessStatus::Tail(samples),
        Status::Normal => ProcessStatus::Normal,
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
