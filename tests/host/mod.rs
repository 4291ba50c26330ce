//! A small headless CLAP host on clack-host 0.2, shared by the integration tests and by
//! `cargo xtask demo` (which includes this file with `#[path]`).
//!
//! It loads a CLAP library, instantiates its first plugin, finds parameters by name
//! through the params extension, activates at a given sample rate and maximum block size,
//! and renders N frames in blocks of a given size with note, pitch-bend and parameter
//! events at exact absolute sample positions.
//!
//! Threading: the instance is not `Send`, so everything (main-thread calls and
//! processing) happens on the thread that created the [`HostedPlugin`].
//!
//! Parameter values: nice-plug's CLAP wrapper exposes every parameter as its *normalised*
//! value multiplied by the step count (0..1 for float parameters, 0..n-1 for an enum with n
//! variants; see `ext_params_get_info`/`ext_params_get_value` in
//! `nice-plug/src/wrapper/clap/wrapper.rs`). Skewed ranges make that mapping non-linear, so
//! [`HostedPlugin::plain`] converts a plain value (0.5 N, 0.1 m/s) through the plugin's own
//! `text_to_value`, which parses the number and normalises it with the parameter's real range.

#![allow(dead_code)]

use clack_extensions::audio_ports::{AudioPortInfoBuffer, PluginAudioPorts};
use clack_extensions::latency::PluginLatency;
use clack_extensions::note_ports::{NoteDialects, NotePortInfoBuffer, PluginNotePorts};
use clack_extensions::params::{ParamInfoBuffer, PluginParams};
use clack_extensions::state::PluginState;
use clack_extensions::tail::{PluginTail, TailLength};
use clack_host::events::event_types::{
    MidiEvent, NoteExpressionEvent, NoteExpressionType, NoteOffEvent, NoteOnEvent, ParamValueEvent,
};
use clack_host::events::Match;
use clack_host::prelude::*;
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Host handler types. The host offers no extensions; it only records callback requests
/// so that [`HostedPlugin`] can run the plugin's main-thread callback between blocks.
pub struct TestHost;

pub struct TestHostShared {
    callback_requested: AtomicBool,
}

impl<'a> SharedHandler<'a> for TestHostShared {
    fn request_restart(&self) {}
    fn request_process(&self) {}
    fn request_callback(&self) {
        self.callback_requested.store(true, Ordering::Release);
    }
}

impl HostHandlers for TestHost {
    type Shared<'a> = TestHostShared;
    type MainThread<'a> = ();
    type AudioProcessor<'a> = ();
}

/// One parameter as the plugin describes it over CLAP.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamDesc {
    pub id: ClapId,
    pub name: String,
    /// CLAP range: 0..1 for continuous nice-plug parameters, 0..steps for stepped ones.
    pub min: f64,
    pub max: f64,
    pub default: f64,
}

/// What happens at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    NoteOn {
        key: u8,
        velocity: f64,
    },
    NoteOff {
        key: u8,
    },
    /// A MIDI control change: controller number and 7-bit value.
    Controller {
        cc: u8,
        value: u8,
    },
    /// Pitch-bend wheel position, -1 (down) ..= 1 (up), sent as a 14-bit MIDI pitch bend.
    PitchBend {
        amount: f64,
    },
    /// Any three-byte MIDI message (status with its channel, two data bytes).
    Midi([u8; 3]),
    /// A CLAP note expression: the tuning of `key`'s note, semitones.
    Tuning {
        key: u8,
        semitones: f64,
    },
    /// A CLAP note expression: the brightness of `key`'s note, 0 ..= 1.
    Brightness {
        key: u8,
        value: f64,
    },
    /// A parameter change in CLAP units (see [`HostedPlugin::plain`]).
    Param {
        id: ClapId,
        value: f64,
    },
}

impl Event {
    pub fn note_on(key: u8) -> Self {
        Event::NoteOn { key, velocity: 0.8 }
    }

    pub fn note_off(key: u8) -> Self {
        Event::NoteOff { key }
    }

    pub fn pitch_bend(amount: f64) -> Self {
        Event::PitchBend { amount }
    }
}

/// Events at absolute sample positions (counted from the start of a render call).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Score {
    events: Vec<(u64, Event)>,
}

impl Score {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `event` at absolute sample `sample`. Events at the same sample keep the order
    /// they were added in.
    pub fn at(mut self, sample: u64, event: Event) -> Self {
        self.push(sample, event);
        self
    }

    pub fn push(&mut self, sample: u64, event: Event) {
        let index = self.events.partition_point(|(s, _)| *s <= sample);
        self.events.insert(index, (sample, event));
    }

    pub fn events(&self) -> &[(u64, Event)] {
        &self.events
    }
}

/// How long a render took, for real-time ratios.
#[derive(Debug, Clone, Copy)]
pub struct RenderStats {
    pub frames: usize,
    pub sample_rate: f64,
    pub wall: Duration,
}

impl RenderStats {
    /// Audio duration over wall time (greater than 1 is faster than real time).
    pub fn realtime_ratio(&self) -> f64 {
        (self.frames as f64 / self.sample_rate) / self.wall.as_secs_f64().max(1e-12)
    }
}

struct Activation {
    processor: StartedPluginAudioProcessor<TestHost>,
    sample_rate: f64,
    max_block: usize,
}

/// A loaded, instantiated plugin. Create, [`activate`](Self::activate), then
/// [`render`](Self::render) as often as needed: renders continue from the current state.
pub struct HostedPlugin {
    // Field order matters for drop: the activation is torn down in `Drop` first.
    activation: Option<Activation>,
    instance: PluginInstance<TestHost>,
    params: Vec<ParamDesc>,
    output_channels: usize,
    note_port: u16,
    clap_notes: bool,
    steady_time: u64,
    pub plugin_id: String,
    pub plugin_name: String,
    pub path: PathBuf,
    pub last_render: Option<RenderStats>,
}

impl HostedPlugin {
    /// Loads the CLAP library at `path` and instantiates its first plugin.
    pub fn load(path: &Path) -> Self {
        // SAFETY: loading a shared library runs its initialisers; we only load our own
        // plugin builds.
        let entry = unsafe { PluginEntry::load(path) }
            .unwrap_or_else(|e| panic!("loading CLAP entry {}: {e:?}", path.display()));
        // Never unload the library: threads that ran plugin code (the test threads) run the
        // plugin's thread-local destructors when they exit, and those must still be mapped.
        std::mem::forget(entry.clone());
        let factory = entry
            .get_plugin_factory()
            .expect("the CLAP entry has no plugin factory");
        let descriptor = factory
            .plugin_descriptors()
            .next()
            .expect("the CLAP entry has no plugins");
        let id = descriptor.id().expect("plugin without an id").to_owned();
        let plugin_id = id.to_string_lossy().into_owned();
        let plugin_name = descriptor
            .name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let host_info = HostInfo::new(
            "colophony-test-host",
            "Colophony",
            "https://example.invalid/colophony",
            "0.1.0",
        )
        .unwrap();
        let mut instance = PluginInstance::<TestHost>::new(
            |_| TestHostShared {
                callback_requested: AtomicBool::new(false),
            },
            |_| (),
            &entry,
            &id,
            &host_info,
        )
        .unwrap_or_else(|e| panic!("instantiating {plugin_id}: {e:?}"));

        let handle = instance.plugin_handle();
        let params = match handle.get_extension::<PluginParams>() {
            Some(ext) => {
                let mut buffer = ParamInfoBuffer::new();
                (0..ext.count(&handle))
                    .filter_map(|i| {
                        ext.get_info(&handle, i, &mut buffer).map(|info| ParamDesc {
                            id: info.id,
                            name: String::from_utf8_lossy(info.name).into_owned(),
                            min: info.min_value,
                            max: info.max_value,
                            default: info.default_value,
                        })
                    })
                    .collect()
            }
            None => Vec::new(),
        };
        let output_channels = handle
            .get_extension::<PluginAudioPorts>()
            .and_then(|ext| {
                let mut buffer = AudioPortInfoBuffer::new();
                ext.get(&handle, 0, false, &mut buffer)
                    .map(|info| info.channel_count as usize)
            })
            .unwrap_or(2);
        let (note_port, clap_notes) = handle
            .get_extension::<PluginNotePorts>()
            .and_then(|ext| {
                let mut buffer = NotePortInfoBuffer::new();
                ext.get(&handle, 0, true, &mut buffer)
                    .map(|info| (0u16, info.supported_dialects.contains(NoteDialects::CLAP)))
            })
            .unwrap_or((0, false));

        Self {
            activation: None,
            instance,
            params,
            output_channels,
            note_port,
            clap_notes,
            steady_time: 0,
            plugin_id,
            plugin_name,
            path: path.to_owned(),
            last_render: None,
        }
    }

    /// Builds the plugin for tests (once per process, see [`test_plugin_path`]) and loads it.
    pub fn load_test_build() -> Self {
        Self::load(test_plugin_path())
    }

    /// [`HostedPlugin::load_test_build`], activated at `sample_rate` for blocks of up to
    /// `max_block` frames.
    pub fn active_test_build(sample_rate: f64, max_block: usize) -> Self {
        let mut plugin = Self::load_test_build();
        plugin.activate(sample_rate, max_block);
        plugin
    }

    pub fn params(&self) -> &[ParamDesc] {
        &self.params
    }

    pub fn output_channels(&self) -> usize {
        self.output_channels
    }

    /// The parameter called `name` (its display name, e.g. "Bow Force").
    pub fn param(&self, name: &str) -> &ParamDesc {
        self.params
            .iter()
            .find(|p| p.name == name)
            .unwrap_or_else(|| {
                let names: Vec<_> = self.params.iter().map(|p| p.name.as_str()).collect();
                panic!("no parameter named {name:?}; the plugin has {names:?}")
            })
    }

    /// CLAP value of `text` for parameter `name`, parsed by the plugin itself.
    pub fn text_to_clap(&mut self, name: &str, text: &str) -> f64 {
        let id = self.param(name).id;
        let handle = self.instance.plugin_handle();
        let ext = handle
            .get_extension::<PluginParams>()
            .expect("no params extension");
        let text_c = CString::new(text).unwrap();
        ext.text_to_value(&handle, id, &text_c)
            .unwrap_or_else(|| panic!("the plugin cannot parse {text:?} for {name:?}"))
    }

    /// The plugin's display text for a CLAP value of parameter `name`.
    pub fn clap_to_text(&mut self, name: &str, value: f64) -> String {
        let id = self.param(name).id;
        let handle = self.instance.plugin_handle();
        let ext = handle
            .get_extension::<PluginParams>()
            .expect("no params extension");
        let mut buffer = [0u8; 256];
        let text = ext
            .value_to_text(&handle, id, value, &mut buffer)
            .expect("value_to_text failed");
        String::from_utf8_lossy(text).into_owned()
    }

    /// Current CLAP value of parameter `name`.
    pub fn clap_value(&mut self, name: &str) -> f64 {
        let id = self.param(name).id;
        let handle = self.instance.plugin_handle();
        let ext = handle
            .get_extension::<PluginParams>()
            .expect("no params extension");
        ext.get_value(&handle, id).expect("get_value failed")
    }

    /// The tail the plugin reports now (CLAP tail extension, asked on the audio thread
    /// between blocks, as hosts do).
    #[allow(dead_code)]
    pub fn tail(&mut self) -> TailLength {
        let ext = self
            .instance
            .plugin_handle()
            .get_extension::<PluginTail>()
            .expect("no tail extension");
        let activation = self.activation.as_mut().expect("activate first");
        ext.get(&activation.processor.plugin_handle())
    }

    /// The latency the plugin reports, samples (CLAP latency extension, asked on the main
    /// thread after activation, as hosts do).
    #[allow(dead_code)]
    pub fn latency(&mut self) -> u32 {
        let mut handle = self.instance.plugin_handle();
        let ext = handle
            .get_extension::<PluginLatency>()
            .expect("no latency extension");
        ext.get(&mut handle)
    }

    /// The plugin's saved state (CLAP state extension).
    pub fn save_state(&mut self) -> Vec<u8> {
        let handle = self.instance.plugin_handle();
        let ext = handle
            .get_extension::<PluginState>()
            .expect("no state extension");
        let mut bytes = Vec::new();
        ext.save(&handle, &mut bytes).expect("saving state failed");
        bytes
    }

    /// Loads a saved state; `Err` if the plugin refuses it.
    pub fn load_state(&mut self, bytes: &[u8]) -> Result<(), String> {
        let handle = self.instance.plugin_handle();
        let ext = handle
            .get_extension::<PluginState>()
            .expect("no state extension");
        let mut reader = bytes;
        ext.load(&handle, &mut reader).map_err(|e| format!("{e:?}"))
    }

    /// A parameter change to the plain value `plain` in the parameter's own unit (0.5 for
    /// 0.5 N of bow force). The plugin converts it (clamping to its range).
    pub fn plain(&mut self, name: &str, plain: f64) -> Event {
        let value = self.text_to_clap(name, &format!("{plain}"));
        Event::Param {
            id: self.param(name).id,
            value,
        }
    }

    /// A parameter change to the value the plugin displays as `text` (e.g. "Violin").
    pub fn text(&mut self, name: &str, text: &str) -> Event {
        let value = self.text_to_clap(name, text);
        Event::Param {
            id: self.param(name).id,
            value,
        }
    }

    /// (Re)activates at `sample_rate` for blocks of up to `max_block` frames and starts
    /// processing. The plugin is reset.
    pub fn activate(&mut self, sample_rate: f64, max_block: usize) {
        self.deactivate();
        let config = PluginAudioConfiguration {
            sample_rate,
            min_frames_count: 1,
            max_frames_count: max_block as u32,
        };
        let stopped = self
            .instance
            .activate(|_, _| (), config)
            .unwrap_or_else(|e| panic!("activating at {sample_rate} Hz: {e:?}"));
        let processor = stopped
            .start_processing()
            .unwrap_or_else(|_| panic!("the plugin refused to start processing"));
        self.activation = Some(Activation {
            processor,
            sample_rate,
            max_block,
        });
        self.steady_time = 0;
    }

    pub fn deactivate(&mut self) {
        if let Some(activation) = self.activation.take() {
            let stopped = activation.processor.stop_processing();
            self.instance.deactivate(stopped);
        }
    }

    pub fn sample_rate(&self) -> f64 {
        self.activation
            .as_ref()
            .expect("the plugin is not active")
            .sample_rate
    }

    /// Renders `frames` frames in blocks of `block` frames (the last one may be shorter),
    /// delivering each event of `score` in the block that contains its absolute sample, at
    /// the matching in-block offset. Returns one `Vec` per output channel.
    pub fn render(&mut self, frames: usize, block: usize, score: &Score) -> Vec<Vec<f32>> {
        let channels = self.output_channels;
        let clap_notes = self.clap_notes;
        let note_port = self.note_port;
        let activation = self
            .activation
            .as_mut()
            .expect("activate the plugin before rendering");
        assert!(
            block >= 1 && block <= activation.max_block,
            "block size {block} outside 1..={}",
            activation.max_block
        );
        if let Some((last, _)) = score.events.last() {
            assert!(
                (*last as usize) < frames,
                "event at sample {last} is past the end of a {frames}-frame render"
            );
        }

        let mut out: Vec<Vec<f32>> = (0..channels).map(|_| Vec::with_capacity(frames)).collect();
        let mut buffers = vec![vec![0.0f32; block]; channels];
        let mut ports = AudioPorts::with_capacity(channels, 1);
        let mut in_events = EventBuffer::with_capacity(64);
        let mut out_events = EventBuffer::with_capacity(64);
        let events = score.events();
        let mut next = 0;
        let mut pos = 0usize;
        let started = Instant::now();
        while pos < frames {
            let n = block.min(frames - pos);
            in_events.clear();
            while next < events.len() && (events[next].0 as usize) < pos + n {
                let (at, event) = events[next];
                let t = (at as usize - pos) as u32;
                push_event(&mut in_events, t, event, note_port, clap_notes);
                next += 1;
            }
            for b in &mut buffers {
                // The plugin must overwrite every sample; NaN shows any it leaves.
                b[..n].fill(f32::NAN);
            }
            let mut outputs = ports.with_output_buffers([AudioPortBuffer {
                latency: 0,
                channels: AudioPortBufferType::f32_output_only(
                    buffers.iter_mut().map(|b| &mut b[..n]),
                ),
            }]);
            activation
                .processor
                .process(
                    &InputAudioBuffers::empty(),
                    &mut outputs,
                    &in_events.as_input(),
                    &mut out_events.as_output(),
                    Some(self.steady_time),
                    None,
                )
                .unwrap_or_else(|e| panic!("process failed at frame {pos}: {e:?}"));
            out_events.clear();
            for (o, b) in out.iter_mut().zip(&buffers) {
                o.extend_from_slice(&b[..n]);
            }
            pos += n;
            self.steady_time += n as u64;
            let requested = self
                .instance
                .access_shared_handler(|s| s.callback_requested.swap(false, Ordering::AcqRel));
            if requested {
                self.instance.call_on_main_thread_callback();
            }
        }
        self.last_render = Some(RenderStats {
            frames,
            sample_rate: activation.sample_rate,
            wall: started.elapsed(),
        });
        out
    }
}

impl Drop for HostedPlugin {
    fn drop(&mut self) {
        self.deactivate();
    }
}

fn push_event(buffer: &mut EventBuffer, t: u32, event: Event, port: u16, clap_notes: bool) {
    match event {
        Event::NoteOn { key, velocity } if clap_notes => buffer.push(&NoteOnEvent::new(
            t,
            Pckn::new(port, 0u16, key as u16, Match::All),
            velocity,
        )),
        Event::NoteOff { key } if clap_notes => buffer.push(&NoteOffEvent::new(
            t,
            Pckn::new(port, 0u16, key as u16, Match::All),
            0.0,
        )),
        Event::NoteOn { key, velocity } => {
            let v = (velocity.clamp(0.0, 1.0) * 127.0).round().max(1.0) as u8;
            buffer.push(&MidiEvent::new(t, port, [0x90, key & 0x7f, v]))
        }
        Event::NoteOff { key } => buffer.push(&MidiEvent::new(t, port, [0x80, key & 0x7f, 0])),
        Event::Controller { cc, value } => {
            buffer.push(&MidiEvent::new(t, port, [0xb0, cc & 0x7f, value & 0x7f]))
        }
        Event::PitchBend { amount } => {
            let v = (8192.0 + amount * 8192.0).round().clamp(0.0, 16383.0) as u16;
            buffer.push(&MidiEvent::new(
                t,
                port,
                [0xe0, (v & 0x7f) as u8, (v >> 7) as u8],
            ))
        }
        Event::Param { id, value } => {
            buffer.push(&ParamValueEvent::new(t, id, Pckn::match_all(), value))
        }
        Event::Midi(bytes) => buffer.push(&MidiEvent::new(t, port, bytes)),
        Event::Tuning { key, semitones } => buffer.push(&NoteExpressionEvent::new(
            t,
            Pckn::new(port, 0u16, key as u16, Match::All),
            NoteExpressionType::Tuning,
            semitones,
        )),
        Event::Brightness { key, value } => buffer.push(&NoteExpressionEvent::new(
            t,
            Pckn::new(port, 0u16, key as u16, Match::All),
            NoteExpressionType::Brightness,
            value,
        )),
    }
}

/// Channel `c` of a render as `f64` (the analysis functions take `f64`).
pub fn channel_f64(out: &[Vec<f32>], c: usize) -> Vec<f64> {
    out[c].iter().map(|&x| x as f64).collect()
}

/// The workspace root: the nearest directory with a `Cargo.lock` above the manifest of
/// the crate these tests belong to (the plugin's, or the tools' in `lab/`).
pub fn workspace_root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .ancestors()
        .find(|d| d.join("Cargo.lock").exists())
        .unwrap_or(manifest)
        .to_path_buf()
}

/// The workspace's target directory: `CARGO_TARGET_DIR` if set, else `target/` at the
/// workspace root.
pub fn target_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CARGO_TARGET_DIR") {
        return PathBuf::from(dir);
    }
    workspace_root().join("target")
}

/// The plugin library the tests load, with nice-plug's allocation checker in it: found or
/// built once per process.
///
/// The package lists itself as a dev-dependency with `assert_process_allocs`, so the
/// workspace's test build (`cargo test`, debug assertions on) compiles the library, cdylib
/// included, with the checker, and leaves the cdylib in `deps/` beside the test binary:
/// that one is loaded, with no second build. Where that library lacks the checker (a
/// release test build, where the checker is compiled out, or `cargo test -p
/// colophony-lab`, which does not unify the plugin's dev-dependencies), this runs `$CARGO
/// build -p colophony --lib --features assert_process_allocs` (dev profile, in
/// `target/host-plugin/`) and loads `target/host-plugin/debug/libcolophony.so`. Either
/// way, any allocation inside the plugin's `process` aborts the test process.
pub fn test_plugin_path() -> &'static Path {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let name = format!(
            "{}colophony{}",
            std::env::consts::DLL_PREFIX,
            std::env::consts::DLL_SUFFIX
        );
        if cfg!(debug_assertions) {
            let exe = std::env::current_exe().expect("the test binary's path");
            if let Some(beside) = exe.parent().map(|deps| deps.join(&name)) {
                if has_allocation_checker(&beside) {
                    return beside;
                }
            }
        }
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let root = workspace_root();
        // A target directory of its own: this feature set's `libcolophony` beside the
        // workspace's would leave two candidates for the tools crate's doctests (E0460),
        // and one build would overwrite the other's unhashed output.
        let target = target_dir().join("host-plugin");
        let status = Command::new(&cargo)
            .current_dir(&root)
            .args([
                "build",
                "-p",
                "colophony",
                "--lib",
                "--features",
                "assert_process_allocs",
            ])
            .arg("--manifest-path")
            .arg(root.join("Cargo.toml"))
            .arg("--target-dir")
            .arg(&target)
            .status()
            .unwrap_or_else(|e| panic!("running {cargo:?}: {e}"));
        assert!(status.success(), "building the plugin library failed");
        let path = target.join("debug").join(name);
        assert!(path.exists(), "{} was not built", path.display());
        // cargo gives this crate's lib and cdylib outputs no hash suffix, so a build of
        // another feature set can overwrite them while leaving this one's fingerprint fresh;
        // make sure the library really contains the allocation checker.
        assert!(
            has_allocation_checker(&path),
            "{} was built without assert_process_allocs (a build with other features \
             overwrote it); touch src/lib.rs and run the tests again",
            path.display()
        );
        path
    })
}

/// Whether the library at `path` exists and carries nice-plug's allocation checker.
fn has_allocation_checker(path: &Path) -> bool {
    let Ok(bytes) = std::fs::read(path) else {
        return false;
    };
    let needle = b"nice_assert_no_alloc";
    bytes.windows(needle.len()).any(|w| w == needle)
}

/// Writes `channels` as a 32-bit float WAV at `path` (creating its directory).
pub fn write_wav_to(path: &Path, sample_rate: f64, channels: &[Vec<f32>]) -> PathBuf {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).unwrap();
    }
    let spec = hound::WavSpec {
        channels: channels.len() as u16,
        sample_rate: sample_rate.round() as u32,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut writer = hound::WavWriter::create(path, spec)
        .unwrap_or_else(|e| panic!("creating {}: {e}", path.display()));
    let frames = channels.iter().map(Vec::len).min().unwrap_or(0);
    for i in 0..frames {
        for c in channels {
            writer.write_sample(c[i]).unwrap();
        }
    }
    writer.finalize().unwrap();
    path.to_owned()
}

/// Writes `channels` to `target/host-renders/<name>.wav` and returns the path.
pub fn write_wav(name: &str, sample_rate: f64, channels: &[Vec<f32>]) -> PathBuf {
    let path = target_dir()
        .join("host-renders")
        .join(format!("{name}.wav"));
    write_wav_to(&path, sample_rate, channels)
}

/// A 64-bit FNV-1a hash of the samples' bits (golden renders and state fixtures).
pub fn fnv1a(samples: &[f32]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for s in samples {
        for b in s.to_bits().to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// The CPU features that choose the math library's code paths.
pub fn machine() -> String {
    #[cfg(target_arch = "x86_64")]
    {
        format!(
            "# machine: x86_64 fma={} avx2={}",
            std::is_x86_feature_detected!("fma"),
            std::is_x86_feature_detected!("avx2")
        )
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        format!("# machine: {}", std::env::consts::ARCH)
    }
}

/// A saved CLAP state from its JSON: nice-plug's CLAP wrapper puts the length (u64,
/// little-endian) before it.
pub fn clap_state(json: &[u8]) -> Vec<u8> {
    let mut bytes = (json.len() as u64).to_le_bytes().to_vec();
    bytes.extend_from_slice(json);
    bytes
}

/// The first sample that is not finite or is subnormal (what clap-validator fails), if
/// any.
pub fn first_unsafe_sample(out: &[Vec<f32>]) -> Option<f32> {
    out.iter()
        .flatten()
        .copied()
        .find(|x| !(x.is_finite() && (*x == 0.0 || x.is_normal())))
}
