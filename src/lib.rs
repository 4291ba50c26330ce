//! Colophony: a physically modelled bowed-string instrument.
//!
//! This file is only the plugin glue (CLAP and VST3 through nice-plug): parameters and
//! MIDI in, the DSP core ([`dsp`]) in the middle, stereo out. The DSP core never imports the
//! plugin framework. [`render`] is the offline renderer behind the `colophony` binary and
//! [`analysis`] the signal measurements the tests and tools share.

pub mod admittance_fit;
pub mod analysis;
pub mod dsp;
pub mod figures;
pub mod params;
pub mod render;

use dsp::instrument::{BowControl, Instrument, InstrumentKind, PITCH_BEND_SEMITONES};
use nice_plug::midi::Key;
use nice_plug::prelude::*;
use params::ColophonyParams;
use std::sync::Arc;

pub struct Colophony {
    params: Arc<ColophonyParams>,
    instrument: Instrument,
}

impl Default for Colophony {
    fn default() -> Self {
        let params = Arc::new(ColophonyParams::default());
        let kind: InstrumentKind = params.instrument.value().into();
        Self {
            instrument: Instrument::new(kind, 48_000.0),
            params,
        }
    }
}

impl Colophony {
    fn handle_event(&mut self, event: NoteEvent<()>) {
        match event {
            NoteEvent::NoteOn {
                key: Key::Number(note),
                ..
            } => {
                // Notes the instrument cannot play are ignored.
                let _ = self.instrument.note_on(note);
            }
            NoteEvent::NoteOff {
                key: Key::Number(note),
                ..
            } => self.instrument.note_off(note),
            NoteEvent::NoteOff {
                key: Key::Wildcard, ..
            }
            | NoteEvent::Choke { .. } => self.instrument.all_notes_off(),
            NoteEvent::MidiPitchBend { value, .. } => self
                .instrument
                .set_pitch_bend((value as f64 - 0.5) * 2.0 * PITCH_BEND_SEMITONES),
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

    type Editor = ();
    type SysExMessage = ();
    type BackgroundTask = ();

    fn params(&self) -> Arc<dyn Params> {
        self.params.clone()
    }

    fn activate(
        &mut self,
        _audio_io_layout: &AudioIOLayout,
        buffer_config: &BufferConfig,
        _context: &mut impl ActivateContext<Self>,
    ) -> bool {
        // Every buffer is sized here, never in `process`.
        let kind: InstrumentKind = self.params.instrument.value().into();
        self.instrument = Instrument::new(kind, buffer_config.sample_rate as f64);
        true
    }

    fn reset(&mut self) {
        self.instrument.reset();
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
        self.instrument
            .set_kind(self.params.instrument.value().into());
        self.instrument.update_sleep();
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
            let out = dsp::filters::flush_tiny(self.instrument.tick(bow).audio * gain) as f32;
            for s in channels.iter_mut() {
                *s = out;
            }
        }
        // Events at or after the block's end (none should be) are still applied.
        while let Some(event) = next_event {
            self.handle_event(event);
            next_event = context.next_event();
        }
        if self.instrument.is_sounding() {
            ProcessStatus::KeepAlive
        } else {
            ProcessStatus::Normal
        }
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
