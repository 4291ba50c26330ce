//! The Colophony editor in nice-plug's standalone wrapper, bowing a note from the start so
//! the live views move: the program behind `docs/editor.png` (`scripts/editor-screenshot.sh`
//! runs it under Xvfb with the dummy audio backend and takes the screenshot).
//!
//! ```text
//! cargo run --release --features standalone --example editor_standalone -- --backend dummy
//! ```
//!
//! `COLOPHONY_DEMO_NOTE` picks the MIDI note (default 50, cello D3).
//! `COLOPHONY_DEMO_SET` sets parameters before the first block, as `id=value` pairs
//! separated by `;`, each value as the parameter displays it (for example
//! `friction_model=Thermal (paper B);bow_force=2`). The wrapper plugin only adds these and
//! the note-on before the host's first event; everything else is Colophony's.

use colophony::Colophony;
use nice_plug::midi::{Channel, Key, VoiceID};
use nice_plug::prelude::*;
use std::sync::Arc;

#[derive(Default)]
struct Demo {
    inner: Colophony,
    note: u8,
    note_sent: bool,
}

/// Colophony's view of the standalone's process context, with one note-on in front.
struct NoteFirst<'a, C> {
    outer: &'a mut C,
    pending: Option<NoteEvent<()>>,
}

impl<C: ProcessContext<Demo>> ProcessContext<Colophony> for NoteFirst<'_, C> {
    fn plugin_api(&self) -> PluginApi {
        self.outer.plugin_api()
    }

    fn execute_background(&self, task: ()) {
        self.outer.execute_background(task)
    }

    fn execute_gui(&self, task: ()) {
        self.outer.execute_gui(task)
    }

    fn transport(&self) -> &Transport {
        self.outer.transport()
    }

    fn next_event(&mut self) -> Option<NoteEvent<()>> {
        self.pending.take().or_else(|| self.outer.next_event())
    }

    fn try_send_event(
        &mut self,
        event: NoteEvent<()>,
    ) -> Result<(), (NoteEvent<()>, nice_plug::context::process::SendEventError)> {
        self.outer.try_send_event(event)
    }

    fn set_latency_samples(&self, samples: u32) {
        self.outer.set_latency_samples(samples)
    }

    fn request_restart(&self) {
        self.outer.request_restart()
    }

    fn set_current_voice_capacity(&self, capacity: u32) {
        self.outer.set_current_voice_capacity(capacity)
    }
}

struct Activate<'a, C>(&'a mut C);

impl<C: ActivateContext<Demo>> ActivateContext<Colophony> for Activate<'_, C> {
    fn plugin_api(&self) -> PluginApi {
        self.0.plugin_api()
    }

    fn execute(&self, task: ()) {
        self.0.execute(task)
    }

    fn set_latency_samples(&self, samples: u32) {
        self.0.set_latency_samples(samples)
    }

    fn set_current_voice_capacity(&self, capacity: u32) {
        self.0.set_current_voice_capacity(capacity)
    }
}

/// Applies `COLOPHONY_DEMO_SET` (see the module doc) to `params`; unknown ids and values
/// are reported and skipped.
fn apply_demo_settings(params: &dyn Params) {
    let Ok(settings) = std::env::var("COLOPHONY_DEMO_SET") else {
        return;
    };
    let map = params.param_map();
    for pair in settings.split(';').filter(|p| !p.trim().is_empty()) {
        let Some((id, value)) = pair.split_once('=') else {
            eprintln!("COLOPHONY_DEMO_SET: expected id=value, got {pair:?}");
            continue;
        };
        let Some((_, param, _)) = map.iter().find(|(i, _, _)| i == id.trim()) else {
            eprintln!("COLOPHONY_DEMO_SET: no parameter {id:?}");
            continue;
        };
        // SAFETY: the pointers come from `params`, which outlives this call, and the audio
        // thread has not started (called from `activate`, before the first block).
        unsafe {
            match param.string_to_normalized_value(value.trim()) {
                Some(normalized) => {
                    param._internal_set_normalized_value(normalized);
                }
                None => eprintln!("COLOPHONY_DEMO_SET: {id} cannot be {value:?}"),
            }
        }
    }
}

fn demo_note() -> u8 {
    std::env::var("COLOPHONY_DEMO_NOTE")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(50)
}

impl Plugin for Demo {
    const NAME: &'static str = Colophony::NAME;
    const VENDOR: &'static str = Colophony::VENDOR;
    const URL: &'static str = Colophony::URL;
    const EMAIL: &'static str = Colophony::EMAIL;
    const VERSION: &'static str = Colophony::VERSION;
    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = Colophony::AUDIO_IO_LAYOUTS;
    const MIDI_INPUT: MidiConfig = Colophony::MIDI_INPUT;
    const SAMPLE_ACCURATE_AUTOMATION: bool = Colophony::SAMPLE_ACCURATE_AUTOMATION;

    type Editor = <Colophony as Plugin>::Editor;
    type SysExMessage = ();
    type BackgroundTask = ();

    fn params(&self) -> Arc<dyn Params> {
        self.inner.params()
    }

    fn editor(&mut self, _async_executor: AsyncExecutor<Self>) -> Option<Self::Editor> {
        let nothing: Arc<dyn Fn(()) + Send + Sync> = Arc::new(|_| {});
        self.inner
            .editor(AsyncExecutor::new(nothing.clone(), nothing))
    }

    fn activate(
        &mut self,
        audio_io_layout: &AudioIOLayout,
        buffer_config: &BufferConfig,
        context: &mut impl ActivateContext<Self>,
    ) -> bool {
        self.note = demo_note();
        self.note_sent = false;
        apply_demo_settings(&*self.inner.params());
        self.inner
            .activate(audio_io_layout, buffer_config, &mut Activate(context))
    }

    fn reset(&mut self) {
        self.inner.reset();
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        let pending = (!self.note_sent).then_some(NoteEvent::NoteOn {
            timing: 0,
            voice_id: VoiceID::Wildcard,
            channel: Channel::Number(0),
            key: Key::Number(self.note),
            velocity: 0.8,
        });
        self.note_sent = true;
        let mut context = NoteFirst {
            outer: context,
            pending,
        };
        self.inner.process(buffer, aux, &mut context)
    }
}

fn main() {
    nice_export_standalone::<Demo>();
}
