//! Offline rendering straight from the DSP core (no plugin host), and WAV output.
//!
//! ```
//! use colophony_lab::render::{render, RenderSettings};
//! let settings = RenderSettings { seconds: 0.05, ..RenderSettings::default() };
//! let out = render(&settings).unwrap();
//! assert_eq!(out.audio.len(), (0.05f64 * 48_000.0).round() as usize);
//! ```

use colophony::dsp::friction::bristle::{BristleParams, SolverStats};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::instrument::Instrument;
use colophony::dsp::rubbed::{RubbedPreset, RubbedScene};
use colophony::dsp::vocabulary::{BowControl, Frame, InstrumentKind};
use std::fmt;
use std::path::Path;

/// Block length the renderer uses between sleep checks, as a plugin host would.
const BLOCK: usize = 256;

#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    pub instrument: InstrumentKind,
    pub note: u8,
    pub seconds: f64,
    pub bow: BowControl,
    pub sample_rate_hz: f64,
    /// Lift the bow at this time (s); `None` bows to the end.
    pub release_s: Option<f64>,
    pub friction: FrictionModel,
    /// Bristle parameters for the LuGre and elasto-plastic laws.
    pub bristle: BristleParams,
    /// Reference pitch A4, Hz (415..=466; the plugin's `reference_pitch`).
    pub reference_hz: f64,
    /// Whether the bow feels the string's torsion (the plugin's string; off for paper A's
    /// purely transverse string).
    pub torsion: bool,
    /// Whether the bow hair yields in the bowing direction (the plugin's bow; off for paper
    /// A's rigid point contact).
    pub bow_hair: bool,
    /// Whether notes are tuned by the bowed sound (the plugin's tuning,
    /// [`colophony::dsp::intonation`]); off, by the free decay (paper A's string).
    pub intonation: bool,
    /// Whether the strings run at `sample_rate_hz` itself ([`Instrument::native`]: paper
    /// A's discretisation, for the convergence studies) instead of the plugin's internal
    /// rate resampled to it ([`Instrument::new`]).
    pub native_rate: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            instrument: InstrumentKind::Cello,
            note: 50,
            seconds: 3.0,
            bow: BowControl::default(),
            sample_rate_hz: 48_000.0,
            release_s: None,
            friction: FrictionModel::Hyperbolic,
            bristle: BristleParams::plugin_string(),
            reference_hz: colophony::dsp::vocabulary::REFERENCE_HZ_DEFAULT,
            torsion: true,
            bow_hair: true,
            intonation: true,
            native_rate: false,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum RenderError {
    NoteOutOfRange {
        note: u8,
        instrument: InstrumentKind,
        low: u8,
        high: u8,
    },
    BadSetting(String),
    Io(String),
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoteOutOfRange {
                note,
                instrument,
                low,
                high,
            } => write!(
                f,
                "note {note} is out of range for the {}: playable notes are {low}..={high}",
                instrument.name()
            ),
            Self::BadSetting(s) => write!(f, "{s}"),
            Self::Io(s) => write!(f, "{s}"),
        }
    }
}

impl std::error::Error for RenderError {}

/// Audio plus the contact probe of the bowed string, one value per sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    pub sample_rate_hz: f64,
    pub audio: Vec<f64>,
    pub bow_point_velocity_m_per_s: Vec<f64>,
    pub friction_force_n: Vec<f64>,
    /// Newton statistics of the bowed string's contact (bristle models only).
    pub newton: SolverStats,
}

impl Rendered {
    fn with_capacity(sample_rate_hz: f64, frames: usize) -> Self {
        Self {
            sample_rate_hz,
            audio: Vec::with_capacity(frames),
            bow_point_velocity_m_per_s: Vec::with_capacity(frames),
            friction_force_n: Vec::with_capacity(frames),
            newton: SolverStats::default(),
        }
    }
}

/// Checks the command line's settings: every bound the renderer and the plugin share.
pub fn check(settings: &RenderSettings) -> Result<(), RenderError> {
    let bad = |s: String| Err(RenderError::BadSetting(s));
    let b = &settings.bow;
    if !(settings.seconds.is_finite() && settings.seconds > 0.0 && settings.seconds <= 600.0) {
        return bad(format!(
            "--seconds must be in (0, 600], got {}",
            settings.seconds
        ));
    }
    if !(settings.sample_rate_hz.is_finite()
        && (1000.0..=768_000.0).contains(&settings.sample_rate_hz))
    {
        return bad(format!(
            "--sample-rate must be 1000..=768000 Hz, got {}",
            settings.sample_rate_hz
        ));
    }
    use colophony::dsp::vocabulary::{REFERENCE_HZ_MAX, REFERENCE_HZ_MIN};
    if !(settings.reference_hz.is_finite()
        && (REFERENCE_HZ_MIN..=REFERENCE_HZ_MAX).contains(&settings.reference_hz))
    {
        return bad(format!(
            "--reference-pitch must be {REFERENCE_HZ_MIN}..={REFERENCE_HZ_MAX} Hz, got {}",
            settings.reference_hz
        ));
    }
    if !(b.velocity_m_per_s.is_finite() && b.velocity_m_per_s.abs() <= 1.5) {
        return bad(format!(
            "--bow-velocity must be within -1.5..=1.5 m/s, got {}",
            b.velocity_m_per_s
        ));
    }
    if !(b.force_n.is_finite() && (0.0..=10.0).contains(&b.force_n)) {
        return bad(format!(
            "--bow-force must be within 0..=10 N, got {}",
            b.force_n
        ));
    }
    if !(b.position_beta.is_finite() && (0.02..=0.5).contains(&b.position_beta)) {
        return bad(format!(
            "--bow-position must be within 0.02..=0.5, got {}",
            b.position_beta
        ));
    }
    let (low, high) = settings.instrument.note_range();
    if !(low..=high).contains(&settings.note) {
        return Err(RenderError::NoteOutOfRange {
            note: settings.note,
            instrument: settings.instrument,
            low,
            high,
        });
    }
    Ok(())
}

/// Bows one note for `seconds` (lifting the bow at `release_s` if set).
pub fn render(settings: &RenderSettings) -> Result<Rendered, RenderError> {
    render_with(settings, |_| {})
}

/// [`render`], with `configure` called on the instrument once it is set up and before the
/// note starts (solver settings such as
/// [`Instrument::set_newton_tolerance`]).
pub fn render_with(
    settings: &RenderSettings,
    configure: impl FnOnce(&mut Instrument),
) -> Result<Rendered, RenderError> {
    let fs = settings.sample_rate_hz;
    let mut out = Rendered::with_capacity(fs, (settings.seconds * fs).round().max(0.0) as usize);
    out.newton = render_frames(settings, configure, |frame| {
        out.audio.push(frame.audio);
        out.bow_point_velocity_m_per_s
            .push(frame.bow_point_velocity_m_per_s);
        out.friction_force_n.push(frame.friction_force_n);
        Ok(())
    })?;
    Ok(out)
}

/// The instrument `settings` bows, set up (`configure` last) with its note on; the
/// frames to render and the frame where the bow lifts.
fn prepare(
    settings: &RenderSettings,
    configure: impl FnOnce(&mut Instrument),
) -> Result<(Instrument, usize, Option<usize>), RenderError> {
    check(settings)?;
    let fs = settings.sample_rate_hz;
    let frames = (settings.seconds * fs).round() as usize;
    let release = settings.release_s.map(|s| (s * fs).round() as usize);
    let mut instrument = if settings.native_rate {
        Instrument::native(settings.instrument, fs)
    } else {
        Instrument::new(settings.instrument, fs)
    };
    instrument
        .set_bristle_params(settings.bristle)
        .map_err(RenderError::BadSetting)?;
    instrument.set_friction_model(settings.friction);
    instrument.set_torsion(settings.torsion);
    instrument.set_bow_hair(settings.bow_hair);
    instrument.set_intonation(
        settings
            .intonation
            .then(colophony::dsp::intonation::shipped),
    );
    instrument.set_reference_pitch(settings.reference_hz);
    configure(&mut instrument);
    instrument.note_on(settings.note);
    Ok((instrument, frames, release))
}

/// `--release` lifts the bow only: the finger stays down and the stopped string rings
/// on at its pitch (its free decay, which the tools measure).
fn lift_bow(instrument: &mut Instrument, note: u8) {
    instrument.set_fingers_held(true);
    instrument.note_off(note);
}

/// Bows `settings` on the point-bow instrument frame by frame (audio and probe), handing
/// each frame to `each`; returns the probed string's solver statistics.
pub fn render_frames(
    settings: &RenderSettings,
    configure: impl FnOnce(&mut Instrument),
    mut each: impl FnMut(&Frame) -> Result<(), RenderError>,
) -> Result<SolverStats, RenderError> {
    let (mut instrument, frames, release) = prepare(settings, configure)?;
    for i in 0..frames {
        if i % BLOCK == 0 {
            instrument.update_sleep();
        }
        if Some(i) == release {
            lift_bow(&mut instrument, settings.note);
        }
        each(&instrument.tick(settings.bow))?;
    }
    Ok(instrument.probed_solver_stats())
}

/// [`render_frames`]' audio a block at a time (the same samples, without the probe):
/// what `colophony render` writes to a 16-bit file.
pub fn render_blocks(
    settings: &RenderSettings,
    configure: impl FnOnce(&mut Instrument),
    mut each: impl FnMut(&[f64]) -> Result<(), RenderError>,
) -> Result<SolverStats, RenderError> {
    let (mut instrument, frames, release) = prepare(settings, configure)?;
    let mut block = [0.0; BLOCK];
    for start in (0..frames).step_by(BLOCK) {
        let end = (start + BLOCK).min(frames);
        instrument.update_sleep();
        // The bow lifts within this block: the samples before it, then the rest.
        let split = release
            .filter(|r| (start..end).contains(r))
            .unwrap_or(start);
        if split > start {
            instrument.process(settings.bow, &mut block[..split - start]);
        }
        if release == Some(split) {
            lift_bow(&mut instrument, settings.note);
        }
        instrument.process(settings.bow, &mut block[split - start..end - start]);
        each(&block[..end - start])?;
    }
    Ok(instrument.probed_solver_stats())
}

/// Paper B's finite-width thermal bow on the string that plays `settings.note` (stopped
/// to its pitch: the vibrating length shortens), at its internal rate, resampled to the
/// output rate. The bow force in N is spread over `width_m` (force per length
/// `F / w`). The probe's channel 1 is the string velocity at the bow's middle node and
/// channel 2 the total friction force, both resampled.
pub fn render_thermal(
    settings: &RenderSettings,
    nodes: usize,
    width_m: f64,
) -> Result<Rendered, RenderError> {
    use colophony::dsp::resample::Resampler;
    use colophony::dsp::thermal::ThermalBowControl;
    let mut string = thermal_string(settings, nodes, width_m)?;
    let fs = settings.sample_rate_hz;
    let mut resampler =
        Resampler::new(string.internal_rate_hz(), fs).map_err(RenderError::BadSetting)?;
    let frames = (settings.seconds * fs).round() as usize;
    let release = settings.release_s.map(|s| (s * fs).round() as usize);
    let mut out = Rendered::with_capacity(fs, frames);
    // Three signals through three resamplers would triple the cost; the probe channels
    // share the audio's resampler by running the string once per block into buffers.
    let mut probe_resamplers = [resampler.clone(), resampler.clone()];
    let bow = settings.bow;
    let scale = 0.1 / string.z0_kg_per_s();
    let block = 256;
    let mut internal: Vec<(f64, f64, f64)> = Vec::new();
    let mut buf = [vec![0.0; block], vec![0.0; block], vec![0.0; block]];
    let mut done = 0;
    while done < frames {
        let n = block.min(frames - done);
        let lifted = release.is_some_and(|r| done >= r);
        let control = ThermalBowControl {
            velocity_m_per_s: bow.velocity_m_per_s,
            force_n_per_m: if lifted { 0.0 } else { bow.force_n / width_m },
            position_beta: bow.position_beta,
        };
        internal.clear();
        resampler.process(
            || {
                let f = string.tick(control);
                internal.push((
                    f.bridge_force_n,
                    f.string_velocity_m_per_s,
                    f.friction_force_n,
                ));
                f.bridge_force_n * scale
            },
            &mut buf[0][..n],
        );
        for (c, r) in probe_resamplers.iter_mut().enumerate() {
            let mut pos = 0;
            let source = &internal;
            r.process(
                || {
                    // Pulls follow exactly the same schedule as the audio's.
                    let v = source
                        .get(pos)
                        .map_or(0.0, |s| if c == 0 { s.1 } else { s.2 });
                    pos += 1;
                    v
                },
                &mut buf[c + 1][..n],
            );
        }
        out.audio.extend_from_slice(&buf[0][..n]);
        out.bow_point_velocity_m_per_s
            .extend_from_slice(&buf[1][..n]);
        out.friction_force_n.extend_from_slice(&buf[2][..n]);
        done += n;
    }
    Ok(out)
}

/// The thermal string [`render_thermal`] bows: the open string under `settings.note`,
/// stopped to its pitch (the vibrating length shortens), with the default thermal and
/// hair constants.
pub fn thermal_string(
    settings: &RenderSettings,
    nodes: usize,
    width_m: f64,
) -> Result<colophony::dsp::thermal::ThermalString, RenderError> {
    use colophony::dsp::thermal::{HairParams, ThermalParams, ThermalString, ThermalStringSpec};
    check(settings)?;
    let kind = settings.instrument;
    let index = kind
        .string_for_note(settings.note)
        .expect("check() accepted the note");
    let open = kind.strings()[index];
    let f0 = colophony::dsp::vocabulary::midi_to_hz(
        settings.note as f64
            + colophony::dsp::vocabulary::reference_semitones(settings.reference_hz),
    );
    let spec = ThermalStringSpec {
        f0_hz: f0,
        z0_kg_per_s: open.z0_kg_per_s,
        length_m: kind.string_length_m() * open.open_hz / f0,
        ..ThermalStringSpec::cello_c()
    };
    ThermalString::new(
        spec,
        nodes,
        width_m,
        ThermalParams::default(),
        HairParams::default(),
    )
    .map_err(RenderError::BadSetting)
}

/// Rubs one of the modal presets for `seconds` with the given friction law. The probe
/// channels hold the resonator velocity at the contact and the friction force.
pub fn render_rubbed(
    preset: RubbedPreset,
    friction: FrictionModel,
    seconds: f64,
    sample_rate_hz: f64,
) -> Result<Rendered, RenderError> {
    render_rubbed_with(preset, friction, seconds, sample_rate_hz, |_| {})
}

/// [`render_rubbed`], with `configure` called on the scene before the first sample.
pub fn render_rubbed_with(
    preset: RubbedPreset,
    friction: FrictionModel,
    seconds: f64,
    sample_rate_hz: f64,
    configure: impl FnOnce(&mut RubbedScene),
) -> Result<Rendered, RenderError> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 600.0) {
        return Err(RenderError::BadSetting(format!(
            "--seconds must be in (0, 600], got {seconds}"
        )));
    }
    if !(sample_rate_hz.is_finite() && (1000.0..=768_000.0).contains(&sample_rate_hz)) {
        return Err(RenderError::BadSetting(format!(
            "--sample-rate must be 1000..=768000 Hz, got {sample_rate_hz}"
        )));
    }
    let mut scene = RubbedScene::from_spec(preset.spec(), friction, sample_rate_hz)
        .map_err(RenderError::BadSetting)?;
    configure(&mut scene);
    let frames = (seconds * sample_rate_hz).round() as usize;
    let mut out = Rendered::with_capacity(sample_rate_hz, frames);
    for _ in 0..frames {
        let frame = scene.tick(scene.preset_bow());
        out.audio.push(frame.audio);
        out.bow_point_velocity_m_per_s
            .push(frame.contact.resonator_velocity_m_per_s);
        out.friction_force_n.push(frame.contact.friction_force_n);
    }
    out.newton = scene.solver_stats();
    Ok(out)
}

/// Writes `rendered` as WAV: 16-bit mono audio, or with `probe` a 32-bit float file whose
/// channel 0 is the audio, 1 the string velocity at the bow (m/s), 2 the friction force
/// (N). The file appears whole or not at all (written beside it, then renamed).
pub fn write_wav(path: &Path, rendered: &Rendered, probe: bool) -> Result<(), RenderError> {
    let mut w = WavOut::create(path, rendered.sample_rate_hz, probe)?;
    for i in 0..rendered.audio.len() {
        w.push(&Frame {
            audio: rendered.audio[i],
            // Renders without a probe (the performer's) leave these empty.
            bow_point_velocity_m_per_s: rendered
                .bow_point_velocity_m_per_s
                .get(i)
                .copied()
                .unwrap_or(0.0),
            friction_force_n: rendered.friction_force_n.get(i).copied().unwrap_or(0.0),
        })?;
    }
    w.finish()
}

/// A WAV file written frame by frame: 16-bit mono audio, or with `probe` three 32-bit
/// float channels (audio, string velocity at the bow, friction force). Written under a
/// `.partial` name and renamed by [`WavOut::finish`], so a failed render leaves no file
/// that looks whole.
pub struct WavOut {
    writer: Option<hound::WavWriter<std::io::BufWriter<std::fs::File>>>,
    probe: bool,
    path: std::path::PathBuf,
    tmp: std::path::PathBuf,
    /// 16-bit samples not yet handed to the writer: written a block at a time through
    /// hound's buffered 16-bit writer (a sample-by-sample `write_sample` checks and
    /// dispatches on the format every call, about a tenth of the default string's cost).
    pending: Vec<i16>,
}

/// 16-bit samples [`WavOut`] collects before writing them.
const WAV_BLOCK: usize = 4096;

impl WavOut {
    pub fn create(path: &Path, sample_rate_hz: f64, probe: bool) -> Result<Self, RenderError> {
        let spec = if probe {
            hound::WavSpec {
                channels: 3,
                sample_rate: sample_rate_hz as u32,
                bits_per_sample: 32,
                sample_format: hound::SampleFormat::Float,
            }
        } else {
            hound::WavSpec {
                channels: 1,
                sample_rate: sample_rate_hz as u32,
                bits_per_sample: 16,
                sample_format: hound::SampleFormat::Int,
            }
        };
        let mut tmp_name = path
            .file_name()
            .ok_or_else(|| io_error(path, &"not a file path"))?
            .to_os_string();
        tmp_name.push(".partial");
        let tmp = path.with_file_name(tmp_name);
        let writer = hound::WavWriter::create(&tmp, spec).map_err(|e| io_error(path, &e))?;
        Ok(Self {
            writer: Some(writer),
            probe,
            path: path.to_path_buf(),
            tmp,
            pending: Vec::with_capacity(if probe { 0 } else { WAV_BLOCK }),
        })
    }

    /// Writes the collected 16-bit samples.
    fn write_pending(&mut self) -> Result<(), RenderError> {
        let Some(w) = self.writer.as_mut() else {
            return Ok(());
        };
        if self.pending.is_empty() {
            return Ok(());
        }
        let mut block = w.get_i16_writer(self.pending.len() as u32);
        for &x in &self.pending {
            block.write_sample(x);
        }
        self.pending.clear();
        block.flush().map_err(|e| io_error(&self.path, &e))
    }

    pub fn push(&mut self, frame: &Frame) -> Result<(), RenderError> {
        let Some(w) = self.writer.as_mut() else {
            return Ok(());
        };
        if !self.probe {
            self.pending.push(to_i16(frame.audio));
            if self.pending.len() >= WAV_BLOCK {
                return self.write_pending();
            }
            return Ok(());
        }
        w.write_sample(frame.audio as f32)
            .and_then(|()| w.write_sample(frame.bow_point_velocity_m_per_s as f32))
            .and_then(|()| w.write_sample(frame.friction_force_n as f32))
            .map_err(|e| io_error(&self.path, &e))
    }

    /// Appends mono audio (a file made without the probe).
    pub fn push_audio(&mut self, audio: &[f64]) -> Result<(), RenderError> {
        debug_assert!(!self.probe, "push_audio writes the 16-bit mono file");
        let Some(w) = self.writer.as_mut() else {
            return Ok(());
        };
        let mut block = w.get_i16_writer(audio.len() as u32);
        for &x in audio {
            block.write_sample(to_i16(x));
        }
        block.flush().map_err(|e| io_error(&self.path, &e))
    }

    /// Completes the file and gives it its name.
    pub fn finish(mut self) -> Result<(), RenderError> {
        self.write_pending()?;
        let Some(w) = self.writer.take() else {
            return Ok(());
        };
        w.finalize()
            .map_err(|e| io_error(&self.path, &e))
            .and_then(|()| {
                std::fs::rename(&self.tmp, &self.path).map_err(|e| io_error(&self.path, &e))
            })
    }
}

impl Drop for WavOut {
    /// An unfinished file (an error on the way) is removed.
    fn drop(&mut self) {
        if self.writer.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

fn io_error(path: &Path, e: &dyn fmt::Display) -> RenderError {
    RenderError::Io(format!("cannot write {}: {e}", path.display()))
}

/// A sample in -1..=1 as 16-bit PCM, rounded half away from zero (what `f64::round`
/// does, without its library call: the baseline x86-64 target has no rounding
/// instruction).
fn to_i16(x: f64) -> i16 {
    let y = x.clamp(-1.0, 1.0) * 32767.0;
    (y + 0.5f64.copysign(y)) as i16
}

/// Parses a note as a MIDI number (`50`) or a name with octave (`D3`, `F#4`, `Bb2`;
/// C4 = 60).
pub fn parse_note(text: &str) -> Result<u8, String> {
    let err = || {
        format!("cannot read note '{text}': give a MIDI number (50) or a name like D3, F#4, Bb2")
    };
    if let Ok(n) = text.parse::<u8>() {
        return if n <= 127 { Ok(n) } else { Err(err()) };
    }
    let mut chars = text.chars();
    let letter = chars.next().ok_or_else(err)?.to_ascii_uppercase();
    let base: i32 = match letter {
        'C' => 0,
        'D' => 2,
        'E' => 4,
        'F' => 5,
        'G' => 7,
        'A' => 9,
        'B' => 11,
        _ => return Err(err()),
    };
    let rest: String = chars.collect();
    let (accidental, octave) = match rest.chars().next() {
        Some('#') => (1, &rest[1..]),
        Some('b') => (-1, &rest[1..]),
        _ => (0, rest.as_str()),
    };
    let octave: i32 = octave.parse().map_err(|_| err())?;
    let midi = 12 * (octave + 1) + base + accidental;
    u8::try_from(midi)
        .ok()
        .filter(|m| *m <= 127)
        .ok_or_else(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn note_names_and_numbers_parse() {
        assert_eq!(parse_note("50"), Ok(50));
        assert_eq!(parse_note("D3"), Ok(50));
        assert_eq!(parse_note("C4"), Ok(60));
        assert_eq!(parse_note("F#4"), Ok(66));
        assert_eq!(parse_note("Bb2"), Ok(46));
        assert!(parse_note("H2").is_err());
        assert!(parse_note("200").is_err());
    }
}
