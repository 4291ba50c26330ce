//! `colophony`: the offline renderer and tools.

use clap::{Parser, Subcommand};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::rubbed::RubbedPreset;
use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
use colophony::quality::Quality;
use colophony_lab::render::{
    check, parse_note, render_blocks, render_frames, write_wav, RenderSettings, WavOut,
};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "colophony",
    version,
    about = "Physically modelled bowed strings: offline renderer and tools"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Bow one note and write it to a WAV file.
    Render {
        /// Output WAV file.
        #[arg(long)]
        out: PathBuf,
        /// violin, viola, cello or double-bass.
        #[arg(long, default_value = "cello", value_parser = parse_instrument)]
        instrument: InstrumentKind,
        /// MIDI number or note name (C4 = 60); default D3 (50), or the preset's note.
        #[arg(long, value_parser = parse_note)]
        note: Option<u8>,
        #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
        seconds: f64,
        /// m/s, signed (sign = bow direction).
        #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
        bow_velocity: f64,
        /// N.
        #[arg(long, default_value_t = 1.0)]
        bow_force: f64,
        /// Distance from the bridge over the vibrating length.
        #[arg(long, default_value_t = 0.1)]
        bow_position: f64,
        #[arg(long, default_value_t = 48_000.0)]
        sample_rate: f64,
        /// Reference pitch A4, Hz (415 .. 466).
        #[arg(long, default_value_t = 440.0)]
        reference_pitch: f64,
        /// Lift the bow after this many seconds and let the string ring.
        #[arg(long)]
        release: Option<f64>,
        /// Write a 32-bit float WAV: channel 0 audio, 1 string velocity at the bow (m/s),
        /// 2 friction force (N).
        #[arg(long)]
        probe: bool,
        /// Print, on standard error, the fastest third of a second's render time a sample
        /// (`floor_ns_per_sample X`): a floor other load on the machine cannot raise, as
        /// `bench peers` reads it. Bowed notes of the point-bow strings only.
        #[arg(long)]
        timing: bool,
        /// Friction law: hyperbolic, static (Stribeck), lugre, elasto-plastic, or thermal
        /// (paper B's finite-width bow; see --nodes and --bow-width).
        #[arg(long, default_value = "hyperbolic", value_parser = parse_friction)]
        friction: FrictionArg,
        /// Thermal bow: hair nodes across the bow (ignored with --quality).
        #[arg(long, default_value_t = 10)]
        nodes: usize,
        /// Solver preset from the work-precision benchmark: draft, good, reference or auto
        /// (sets the Newton tolerance and the thermal node count; see src/quality.rs).
        /// Without it: --nodes, and the reference's tolerance for one bare note; the
        /// plugin's own (good's) through the performer (--midi, --bridge).
        #[arg(long, value_parser = parse_quality)]
        quality: Option<Quality>,
        /// Thermal bow: width of the hair ribbon, m (the force is spread over it; the
        /// plugin's Bow Width is the same in mm).
        #[arg(long, default_value_t = 0.01)]
        bow_width: f64,
        /// Play a preset through the plugin's performer: a factory preset's id or name,
        /// a user preset, or a preset .json file (`colophony presets` lists them). It sets
        /// every parameter as the plugin would; --note (default: the preset's), --seconds,
        /// --release, --midi, --track and --sample-rate still apply, the other bow and
        /// model options are the preset's. The bare names paper-modal, door-hinge, chalk,
        /// wine-glass and brake-squeal rub that object alone at its own bow.
        #[arg(long)]
        preset: Option<String>,
        /// Play a standard MIDI file (notes, pitch bend, controllers and channel pressure,
        /// with its tempo map) through the plugin's performer at the plugin's defaults and
        /// the bow given; --note, --seconds and --release are then unused.
        #[arg(long)]
        midi: Option<PathBuf>,
        /// With --midi: only this track (0 = the first in the file); default all.
        #[arg(long)]
        track: Option<usize>,
        /// With --midi: the longest ring-out after the last event, s (0 .. 10; default 10,
        /// or sooner once the output has stayed below -100 dBFS for a quarter second).
        #[arg(long)]
        tail: Option<f64>,
        /// Play the instrument on this bridge (JSON, as `colophony fit-bridge` writes)
        /// instead of the shipped one, through the plugin's performer: the thermal
        /// model on the modal bridge itself, a point law with the bridge's passive
        /// reduction (its strongest modes in the bowing direction) as the body.
        #[arg(long)]
        bridge: Option<PathBuf>,
    },
    /// Draw a figure as PNG: serafin-fig7, serafin-modal, maestre-fig6, maestre-fig7, maestre-fig8, bridge-fit,
    /// measured-window (--in the measured window's file).
    Figure {
        name: String,
        #[arg(long)]
        out: PathBuf,
        /// Measured admittance CSV (bridge-fit); the measured window's file (measured-window).
        #[arg(long = "in")]
        input: Option<PathBuf>,
        /// Fitted bridge JSON (bridge-fit).
        #[arg(long)]
        fit: Option<PathBuf>,
    },
    /// Print real-time ratios (run a release build): `friction` times 10 s of cello D at
    /// 48 kHz with each friction law; `table1` times paper B's thermal bow per node count;
    /// `precision --out DIR [--quick]` writes the work-precision benchmark (errors against
    /// refined references beside the cost, and the STK and Faust peers) to DIR; `peers
    /// [--seconds S] [--out DIR]` times whole processes rendering cello D3 against STK's
    /// Bowed (needs libstk-dev and g++); `thermal-constants` bows paper B's contact with
    /// candidate constant sets on probe notes across the window; `scenes` times what
    /// skipping silent strings saves; `playing-space --out DIR` maps Helmholtz motion over
    /// the bowing window (see its options); `window --out FILE [--models ..] [--instruments
    /// ..]` measures the forces that hold Helmholtz motion on every string (the shipped
    /// file: assets/measured-window.csv); `intonation --out FILE` measures the bowed
    /// intonation table (`--free`: the thermal strings' plucked rows); `timbre --out DIR [--models ..] [--rates ..] [--instruments ..]`
    /// compares each instrument's played notes with a real player's, band by band (default
    /// the hyperbolic law at 48 kHz; STK's Bowed on the same notes where libstk-dev is
    /// installed).
    Bench {
        what: String,
        /// Output directory (precision).
        #[arg(long)]
        out: Option<PathBuf>,
        /// A one-minute variant with fewer configurations (precision), or the coarse
        /// subset of the map (playing-space).
        #[arg(long)]
        quick: bool,
        /// playing-space: host rates in Hz, comma-separated (default: 44100, 48000, 88200,
        /// 96000, 176400, 192000; with --quick 44100, 96000).
        #[arg(long, value_delimiter = ',')]
        rates: Vec<f64>,
        /// playing-space: every Nth semitone (default 1; with --quick 5).
        #[arg(long)]
        step: Option<usize>,
        /// playing-space, intonation, timbre: friction models, comma-separated (default all
        /// five; timbre: hyperbolic).
        #[arg(long, value_delimiter = ',')]
        models: Vec<String>,
        /// playing-space, intonation: instruments, comma-separated (default all four;
        /// the intonation fit then rewrites only their rows).
        #[arg(long, value_delimiter = ',')]
        instruments: Vec<String>,
        /// intonation: measuring passes (default 2).
        #[arg(long)]
        passes: Option<usize>,
        /// intonation: also fit the point laws' corrections at the soft dynamics (as many
        /// passes again for each; the shipped table has them).
        #[arg(long)]
        dynamics: bool,
        /// intonation --dynamics: fit only these soft expressions (0..1, comma-separated;
        /// default every one the table holds), the others kept as shipped.
        #[arg(long, value_delimiter = ',')]
        expressions: Vec<f64>,
        /// intonation: fit paper B's thermal strings' plucked notes instead (the table's
        /// thermal-free rows: each note moved so that it rings in tune).
        #[arg(long)]
        free: bool,
        /// peers: seconds each process renders (default 300).
        #[arg(long)]
        seconds: Option<f64>,
        /// playing-space: how each note begins: `performer` (the default: the plugin's
        /// attack for a separate note at velocity 100, the bow from rest with the stroke's
        /// ramp and accent), `landing` (the bow lands at its speed and the cell's force)
        /// `catch` (at `F_max / 2` until the string slips regularly, then lowered to the
        /// cell's force by 0.3 s: whether that force holds Helmholtz motion) or `hold` (as
        /// `catch`, held up to 1 s and moved up as well as down, measured from 1.3 s: what
        /// `bench window` plays).
        #[arg(long, default_value = "performer")]
        attack: String,
        /// playing-space: the point-bow strings' most dispersion sections (default the
        /// plugin's 8; 0: strings without stiffness), to measure what the strings'
        /// stiffness does to the map. The intonation table stays the one fitted for the
        /// stiff strings, so the pitches move with it.
        #[arg(long)]
        dispersion_stages: Option<usize>,
    },
    /// List the presets: the factory set and the user presets (in the folder the editor
    /// saves to; COLOPHONY_PRESET_DIR overrides it).
    Presets,
    /// Fit a passive modal bridge admittance to measured data (CSV in, JSON out).
    FitBridge {
        input: PathBuf,
        /// Number of modes.
        #[arg(long)]
        modes: usize,
        #[arg(long)]
        out: PathBuf,
    },
}

fn report(result: Result<String, String>) -> ExitCode {
    match result {
        Ok(message) => {
            println!("{message}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum FrictionArg {
    Point(FrictionModel),
    Thermal,
}

fn parse_friction(s: &str) -> Result<FrictionArg, String> {
    if s == "thermal" {
        return Ok(FrictionArg::Thermal);
    }
    FrictionModel::from_name(s).map(FrictionArg::Point).ok_or_else(|| {
        format!(
            "unknown friction model '{s}': choose hyperbolic, static, lugre, elasto-plastic or thermal"
        )
    })
}

fn parse_quality(s: &str) -> Result<Quality, String> {
    Quality::from_name(s)
        .ok_or_else(|| format!("unknown quality '{s}': choose draft, good, reference or auto"))
}

fn parse_instrument(s: &str) -> Result<InstrumentKind, String> {
    InstrumentKind::from_name(s).ok_or_else(|| {
        format!("unknown instrument '{s}': choose violin, viola, cello or double-bass")
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Render {
            out,
            instrument,
            note,
            seconds,
            bow_velocity,
            bow_force,
            bow_position,
            sample_rate,
            reference_pitch,
            release,
            probe,
            timing,
            friction,
            nodes,
            bow_width,
            quality,
            preset,
            midi,
            track,
            tail,
            bridge,
        } => {
            let rubbed = preset.as_deref().and_then(RubbedPreset::from_name);
            if let (Some(name), None) = (&preset, rubbed) {
                let score = match midi {
                    Some(midi) => PresetScore::File(midi, track, tail),
                    None => PresetScore::Note(note, seconds, release),
                };
                return report(render_preset(name, score, &out, sample_rate));
            }
            let note = note.unwrap_or(DEFAULT_NOTE);
            let bridge = match bridge {
                None => None,
                Some(path) => match colophony::dsp::bridge_data::load_bridge(&path) {
                    Ok(b) => Some(b),
                    Err(e) => return report(Err(e)),
                },
            };
            let bow = BowControl {
                velocity_m_per_s: bow_velocity,
                force_n: bow_force,
                position_beta: bow_position,
            };
            let source = match (midi, bridge.is_some()) {
                (Some(midi), _) => Some(Score::File(midi, track, tail)),
                // A note on a chosen bridge plays through the plugin's performer.
                (None, true) => Some(Score::Note {
                    note,
                    seconds,
                    release,
                }),
                (None, false) => None,
            };
            if let Some(source) = source {
                return report(render_performed(
                    source, &out, instrument, friction, quality, nodes, bow_width, bow,
                    sample_rate, reference_pitch, bridge,
                ));
            }
            let tolerance = quality.map(|q| q.newton_tolerance_m_per_s());
            // The renderer's thermal string runs at its own rate (its nodes, its wave speed).
            let nodes = match (quality, instrument.string_for_note(note)) {
                (Some(Quality::Auto), Some(i)) => colophony::quality::auto_nodes_at_speed(
                    2.0 * instrument.string_length_m() * instrument.strings()[i].open_hz,
                    colophony::dsp::vocabulary::midi_to_hz(note as f64),
                    bow_position,
                    bow_width,
                ),
                (Some(q), _) => q
                    .fixed_thermal_nodes()
                    .unwrap_or(colophony::quality::GOOD_NODES),
                (None, _) => nodes,
            };
            let thermal = friction == FrictionArg::Thermal;
            let friction = match friction {
                FrictionArg::Point(model) => model,
                FrictionArg::Thermal => FrictionModel::Hyperbolic,
            };
            if let Some(preset) = rubbed {
                if thermal {
                    return report(Err(
                        "the thermal bow plays strings, not the rubbed presets".into()
                    ));
                }
                return report(
                    colophony_lab::render::render_rubbed_with(
                        preset,
                        friction_or_default(friction),
                        seconds,
                        sample_rate,
                        |scene| {
                            if let Some(t) = tolerance {
                                scene.set_newton_tolerance(t);
                            }
                        },
                    )
                    .and_then(|r| write_wav(&out, &r, probe))
                    .map(|()| format!("wrote {} ({} preset)", out.display(), preset.name()))
                    .map_err(|e| e.to_string()),
                );
            }
            let settings = RenderSettings {
                instrument,
                note,
                seconds,
                bow: BowControl {
                    velocity_m_per_s: bow_velocity,
                    force_n: bow_force,
                    position_beta: bow_position,
                },
                sample_rate_hz: sample_rate,
                release_s: release,
                friction,
                reference_hz: reference_pitch,
                ..RenderSettings::default()
            };
            let started = std::time::Instant::now();
            let written = if thermal {
                colophony_lab::render::render_thermal(&settings, nodes, bow_width)
                    .and_then(|r| write_wav(&out, &r, probe))
            } else {
                // Streamed to the file: nothing of the render is kept in memory.
                check(&settings)
                    .and_then(|()| WavOut::create(&out, settings.sample_rate_hz, probe))
                    .and_then(|mut wav| {
                        let configure = |instrument: &mut colophony::dsp::instrument::Instrument| {
                            if let Some(t) = tolerance {
                                instrument.set_newton_tolerance(t);
                            }
                        };
                        let mut floor = colophony_lab::timing::Floor::new();
                        if probe {
                            render_frames(&settings, configure, |frame| {
                                floor.advance(1);
                                wav.push(frame)
                            })?;
                        } else {
                            render_blocks(&settings, configure, |audio| {
                                floor.advance(audio.len());
                                wav.push_audio(audio)
                            })?;
                        }
                        if timing && floor.ns_per_sample().is_some() {
                            eprintln!("{}", floor.line());
                        }
                        wav.finish()
                    })
            };
            match written {
                Ok(()) => {
                    let took = started.elapsed().as_secs_f64();
                    println!(
                        "wrote {} ({seconds} s in {took:.3} s, {:.1}x real time)",
                        out.display(),
                        seconds / took
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Figure {
            name,
            out,
            input,
            fit,
        } => report(match name.as_str() {
            "measured-window" => match input {
                Some(input) => std::fs::read_to_string(&input)
                    .map_err(|e| format!("cannot read {}: {e}", input.display()))
                    .and_then(|text| colophony_lab::measured_window::draw(&text, &out))
                    .map(|()| format!("wrote {}", out.display())),
                None => Err("measured-window needs --in FILE (assets/measured-window.csv)".into()),
            },
            "bridge-fit" => match (input, fit) {
                (Some(input), Some(fit)) => {
                    colophony_lab::admittance_fit::draw_figure(&input, &fit, &out)
                }
                _ => Err("bridge-fit needs --in DATA.csv and --fit FIT.json".into()),
            },
            other => colophony_lab::figures::draw(other, &out),
        }),
        Command::Bench {
            what,
            out,
            quick,
            rates,
            step,
            models,
            instruments,
            passes,
            dynamics,
            expressions,
            free,
            seconds,
            attack,
            dispersion_stages,
        } => report(match what.as_str() {
            "friction" => colophony_lab::bench::friction_table(),
            "table1" => colophony_lab::bench::table1(),
            "scenes" => colophony_lab::bench::scenes(),
            "peers" => colophony_lab::bench::peers(
                seconds.unwrap_or(300.0),
                &out.unwrap_or_else(|| std::env::temp_dir().join("colophony-peers")),
            ),
            scene if scene.starts_with("peer-scene:") => colophony_lab::bench::peer_scene(
                &scene["peer-scene:".len()..],
                seconds.unwrap_or(10.0),
            ),
            "precision" => match out {
                Some(dir) => colophony_lab::precision::run(&dir, quick),
                None => Err("bench precision needs --out DIR".into()),
            },
            "playing-space" => match out {
                Some(dir) => colophony_lab::playing_space::Plan::from_options(quick, &rates, step, &models, &instruments)
                    .and_then(|mut plan| {
                        plan.attack = colophony_lab::playing_space::Attack::from_name(&attack)
                            .ok_or_else(|| format!("unknown attack '{attack}': choose performer, landing, catch or hold"))?;
                        plan.dispersion_stages = dispersion_stages;
                        colophony_lab::playing_space::run(&dir, &plan)
                    }),
                None => Err("bench playing-space needs --out DIR".into()),
            },
            "intonation" => match out {
                Some(file) => colophony_lab::playing_space::Plan::from_options(false, &rates, None, &models, &instruments)
                    .and_then(|plan| {
                        let rate = if rates.is_empty() { 48_000.0 } else { plan.rates_hz[0] };
                        colophony_lab::intonation_fit::run(&file, &plan.models, &plan.kinds, rate, passes.unwrap_or(2), dynamics, &expressions, free)
                    }),
                None => Err("bench intonation needs --out FILE (the shipped one: assets/intonation.csv)".into()),
            },
            "window" => match out {
                Some(file) => colophony_lab::playing_space::Plan::from_options(false, &[], None, &models, &instruments)
                    .and_then(|plan| colophony_lab::measured_window::run(&file, &plan.models, &plan.kinds)),
                None => Err("bench window needs --out FILE (the shipped one: assets/measured-window.csv)".into()),
            },
            "guard-window" => match out {
                Some(file) => colophony_lab::playing_space::Plan::from_options(false, &[], None, &models, &instruments)
                    .and_then(|plan| colophony_lab::measured_window::run_guard(&file, &plan.models, &plan.kinds)),
                None => Err("bench guard-window needs --out FILE (the shipped one: assets/guard-window.csv)".into()),
            },
            "thermal-constants" => colophony_lab::thermal_constants::run(),
            "timbre" => match out {
                // One model (the default law) at 48 kHz unless asked for more.
                Some(dir) => colophony_lab::playing_space::Plan::from_options(false, &rates, None, &models, &instruments)
                    .and_then(|plan| {
                        let models = if models.is_empty() { vec![colophony_lab::playing_space::Model::ALL[0]] } else { plan.models };
                        let rates = if rates.is_empty() { vec![48_000.0] } else { plan.rates_hz };
                        colophony_lab::timbre::run(&dir, &models, &rates, &plan.kinds)
                    }),
                None => Err("bench timbre needs --out DIR".into()),
            },
            other => Err(format!(
                "unknown bench '{other}': choose friction, table1, scenes, peers, precision, playing-space, window, guard-window, intonation, timbre or thermal-constants"
            )),
        }),
        Command::Presets => {
            println!("factory presets (colophony render --preset ID):");
            for (id, p) in colophony::presets::factory() {
                println!("  {id:<22} {}", p.name);
            }
            match colophony::presets::user_dir() {
                None => println!("user presets: no folder (set COLOPHONY_PRESET_DIR)"),
                Some(dir) => {
                    println!("user presets in {}:", dir.display());
                    for (stem, p) in colophony::presets::user_presets(&dir) {
                        match p {
                            Ok(p) => println!("  {stem:<22} {}", p.name),
                            Err(e) => println!("  {stem:<22} (cannot be read: {e})"),
                        }
                    }
                }
            }
            ExitCode::SUCCESS
        }
        Command::FitBridge { input, modes, out } => {
            report(colophony_lab::admittance_fit::run_cli(&input, modes, &out))
        }
    }
}

/// `colophony render --midi`: the plugin's default setup with the command line's
/// instrument, law, quality, reference pitch and bow.
#[allow(clippy::too_many_arguments)]
/// What [`render_performed`] plays.
enum Score {
    /// A MIDI file, all tracks or one, and the longest ring-out (s).
    File(PathBuf, Option<usize>, Option<f64>),
    /// One note held for `seconds` (lifted at `release` if given).
    Note {
        note: u8,
        seconds: f64,
        release: Option<f64>,
    },
}

/// Plays a MIDI file or one note through the plugin's performer and writes the WAV.
#[allow(clippy::too_many_arguments)]
fn render_performed(
    score: Score,
    out: &std::path::Path,
    instrument: InstrumentKind,
    friction: FrictionArg,
    quality: Option<Quality>,
    nodes: usize,
    bow_width: f64,
    bow: BowControl,
    sample_rate: f64,
    reference_pitch: f64,
    bridge: Option<colophony::dsp::bridge_data::BridgeModes>,
) -> Result<String, String> {
    use colophony::performer::ThermalNodes;
    colophony_lab::render::check(&RenderSettings {
        instrument,
        note: instrument.note_range().0,
        bow,
        sample_rate_hz: sample_rate,
        reference_hz: reference_pitch,
        ..RenderSettings::default()
    })
    .map_err(|e| e.to_string())?;
    use colophony::dsp::thermal_instrument::{MAX_WIDTH_M, MIN_WIDTH_M};
    if !(bow_width.is_finite() && (MIN_WIDTH_M..=MAX_WIDTH_M).contains(&bow_width)) {
        return Err(format!(
            "--bow-width must be within {MIN_WIDTH_M}..={MAX_WIDTH_M} m (the plugin's range), got {bow_width}"
        ));
    }
    let params = colophony::params::ColophonyParams::default();
    let mut setup = params.setup();
    setup.instrument = instrument;
    setup.reference_hz = reference_pitch;
    setup.bow_width_m = bow_width;
    setup.bow_position_beta = bow.position_beta;
    setup.point_law = match friction {
        FrictionArg::Point(model) => Some(model),
        FrictionArg::Thermal => None,
    };
    setup.thermal_nodes = match quality {
        Some(Quality::Auto) => ThermalNodes::Auto,
        Some(q) => ThermalNodes::Fixed(
            q.fixed_thermal_nodes()
                .unwrap_or(colophony::quality::GOOD_NODES),
        ),
        None => ThermalNodes::Fixed(nodes.max(1)),
    };
    if let Some(q) = quality {
        setup.newton_tolerance_m_per_s = q.newton_tolerance_m_per_s();
    }
    let how = colophony_lab::midi_file::Performance {
        setup,
        bow,
        gain: nice_plug::util::db_to_gain(params.gain.value()) as f64,
        sample_rate_hz: sample_rate,
        block: 512,
        bridge,
    };
    match score {
        Score::File(midi, track, tail) => {
            colophony_lab::midi_file::render_file(&midi, track, tail, &how, out)
        }
        Score::Note {
            note,
            seconds,
            release,
        } => play_note(&how, note, seconds, release, out).map(|(written, peak)| {
            format!(
                "wrote {} ({written:.1} s, peak {:.1} dBFS, the plugin's {} {} on the given bridge)",
                out.display(),
                20.0 * (peak.max(1e-30) as f64).log10(),
                if friction == FrictionArg::Thermal { "thermal" } else { "point-bow" },
                instrument.name()
            )
        }),
    }
}

/// The note `colophony render` plays when none is given: D3, the cello's D string.
const DEFAULT_NOTE: u8 = 50;

/// What `render --preset` plays.
enum PresetScore {
    /// A MIDI file, its track and the longest ring-out (s).
    File(PathBuf, Option<usize>, Option<f64>),
    /// Note (default the preset's), seconds, release.
    Note(Option<u8>, f64, Option<f64>),
}

/// `colophony render --preset`: every parameter from the preset, applied to the plugin's
/// parameter set (so its ranges and defaults hold), played through the performer.
fn render_preset(
    name: &str,
    score: PresetScore,
    out: &std::path::Path,
    sample_rate: f64,
) -> Result<String, String> {
    let preset = colophony::presets::find(name)?;
    let params = colophony::params::ColophonyParams::default();
    preset.apply_to(&params)?;
    let setup = params.setup();
    colophony_lab::render::check(&RenderSettings {
        instrument: setup.instrument,
        note: setup.instrument.note_range().0,
        sample_rate_hz: sample_rate,
        ..RenderSettings::default()
    })
    .map_err(|e| e.to_string())?;
    let how = colophony_lab::midi_file::Performance {
        setup,
        bow: params.bow(),
        gain: nice_plug::util::db_to_gain(params.gain.value()) as f64,
        sample_rate_hz: sample_rate,
        block: 512,
        bridge: None,
    };
    match score {
        PresetScore::File(midi, track, tail) => {
            colophony_lab::midi_file::render_file(&midi, track, tail, &how, out)
        }
        PresetScore::Note(note, seconds, release) => {
            let note = note.or(preset.note).unwrap_or(DEFAULT_NOTE);
            play_note(&how, note, seconds, release, out).map(|(written, peak)| {
                format!(
                    "wrote {} ({written:.1} s, peak {:.1} dBFS, preset '{}')",
                    out.display(),
                    20.0 * (peak.max(1e-30) as f64).log10(),
                    preset.name
                )
            })
        }
    }
}

/// One note held for `seconds` (lifted at `release`) through the performer; the seconds
/// written and the peak.
fn play_note(
    how: &colophony_lab::midi_file::Performance,
    note: u8,
    seconds: f64,
    release: Option<f64>,
    out: &std::path::Path,
) -> Result<(f64, f32), String> {
    use colophony_lab::midi_file::{one_note, render_events};
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(format!("--seconds must be within 0..=3600, got {seconds}"));
    }
    let instrument = how.setup.instrument;
    if how.setup.rubbed.is_none() && instrument.string_for_note(note).is_none() {
        let (lo, hi) = instrument.note_range();
        return Err(format!(
            "the {} plays MIDI notes {lo}..={hi}; {note} is outside",
            instrument.name()
        ));
    }
    let at = |t: f64| (t * how.sample_rate_hz).round() as u64;
    let lift = release.unwrap_or(seconds).clamp(0.0, seconds);
    let events = one_note(note, 100, at(lift));
    let frames = at(seconds) as usize;
    render_events(&events, how, Some(frames), out)
}

/// `--friction` defaults to hyperbolic for strings; rubbed presets use elasto-plastic
/// unless another bristle or static law is asked for.
fn friction_or_default(friction: FrictionModel) -> FrictionModel {
    if friction == FrictionModel::Hyperbolic {
        FrictionModel::ElastoPlastic
    } else {
        friction
    }
}
