//! Work-precision benchmark, `colophony bench precision --out DIR [--quick]`: for each
//! scenario and model, the numerical error of cheaper settings against a refined reference
//! of the same model, beside the cost (real-time ratio) of each setting, measured in one
//! run; and the same cost for two peers (STK's `Bowed`, Faust's `pm.violinModel`), see
//! [`peers`].
//!
//! **Scenarios.** Paper A's cello D (147 Hz, v_b 0.1 m/s, F_N 1.1 N, beta 0.1) with each
//! friction law; a violin A string (A4, 440 Hz, 0.1 m/s, 0.5 N, beta 0.1) with each law;
//! paper B's Figure 6 bow on the cello open C (v_b 0.15 m/s, 300 N/m over 1 cm, beta 0.07,
//! and the same bow at beta 0.1) with the thermal string; the wine-glass preset
//! (elasto-plastic).
//!
//! **What is refined.** The waveguide models and the rubbed glass: the host rate
//! (22.05 to 384 kHz against a 768 kHz reference, the highest rate the renderer takes) and,
//! for the bristle laws, the Newton tolerance (1e-2 to 1e-10 m/s at 48 kHz, against
//! 1e-13). The thermal string: the hair node count N_B (3 to 60 against 120), which refines
//! space and time together (its internal rate is `c / dx`, `dx = w / N_B`). Not refined
//! here: the loop-filter orders (the dispersion all-pass count and the loss filter are
//! fitted per rate, with fixed caps) and the Newton iteration cap.
//!
//! **Metrics** ([`Measured`], [`Errors`]), all on a common 48 kHz grid: every signal is
//! converted by [`resample_whole_from`] (zero delay, a 64-zero-crossing Kaiser sinc cut off
//! at 0.475 of the lower rate, so a 22.05 kHz rendering keeps everything to 10.1 kHz and
//! loses what it cannot represent). The steady part is the second half of the render.
//! - f0: the strongest peak within 100 cents of the nominal pitch
//!   ([`peak_frequency_hz`]); error in cents against the reference's f0.
//! - harmonics: amplitudes at `k f0`, `k = 1..20` (Hann-windowed DTFT), in dB re the
//!   reference's strongest harmonic, each clamped at [`HARMONIC_FLOOR_DB`] (near-missing
//!   harmonics, such as every tenth at beta 0.1, would otherwise swamp the figure with
//!   noise); error = RMS over k of the level differences.
//! - slip fraction: corner to corner ([`slip_stats`]) of the velocity at the contact;
//!   error = absolute difference.
//! - time to Helmholtz motion: the first slip from which every slip-to-slip interval to the
//!   end is one period within [`PERIOD_TOLERANCE`]; error in ms. Empty when either
//!   signal has no such regime (the thermal bow at beta 0.07 slips twice per period).
//! - waveform: RMS of the difference over the first [`WAVEFORM_PERIODS`] nominal periods
//!   (the attack, before phase drift dominates) over the reference's RMS there, in dB.

use crate::render::{
    render_rubbed_with, render_thermal, render_with, thermal_string, RenderSettings, Rendered,
};
use colophony::analysis::{cents, partial_amplitude, peak_frequency_hz, rms, slip_stats};
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::resample::{resample_whole_from, Resampler};
use colophony::dsp::rubbed::RubbedPreset;
use colophony::dsp::vocabulary::{midi_to_hz, BowControl, InstrumentKind};
use colophony::dsp::waveguide::MAX_DISPERSION_STAGES;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

pub mod peers;

/// The common grid every metric is computed on, Hz.
pub const ANALYSIS_RATE_HZ: f64 = 48_000.0;
/// Harmonics compared.
pub const HARMONICS: usize = 20;
/// Harmonic levels below this (dB re the reference's strongest) count as this.
pub const HARMONIC_FLOOR_DB: f64 = -60.0;
/// Nominal periods from the start over which waveforms are compared.
pub const WAVEFORM_PERIODS: f64 = 20.0;
/// A slip-to-slip interval counts as one period within this fraction. Pitch differences
/// between settings are a few cents (0.3 %); a second slip per period halves an interval.
pub const PERIOD_TOLERANCE: f64 = 0.05;
/// Newton tolerance of the references, m/s (a thousandth of the default).
pub const TIGHT_TOLERANCE_M_PER_S: f64 = 1e-13;

/// What a group of configurations refines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Series {
    Rate,
    Tolerance,
    Nodes,
    /// The waveguide's dispersion allpass sections.
    Dispersion,
}

impl Series {
    pub fn name(self) -> &'static str {
        match self {
            Series::Rate => "rate",
            Series::Tolerance => "newton-tolerance",
            Series::Nodes => "nodes",
            Series::Dispersion => "dispersion-sections",
        }
    }
}

/// How one configuration renders.
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    /// A waveguide string at `settings.sample_rate_hz`, with a Newton tolerance for the
    /// bristle laws and a cap on the dispersion allpass sections (`None`: the defaults).
    String {
        settings: RenderSettings,
        tolerance_m_per_s: Option<f64>,
        dispersion_stages: Option<usize>,
    },
    /// Paper B's thermal string with `nodes` hair nodes, resampled to the host rate.
    Thermal {
        settings: RenderSettings,
        nodes: usize,
        width_m: f64,
    },
    /// A rubbed preset.
    Rubbed {
        preset: RubbedPreset,
        friction: FrictionModel,
        sample_rate_hz: f64,
        tolerance_m_per_s: Option<f64>,
    },
}

impl Model {
    fn render(&self, seconds: f64) -> Result<Rendered, String> {
        match self {
            Model::String {
                settings,
                tolerance_m_per_s,
                dispersion_stages,
            } => render_with(
                &RenderSettings {
                    seconds,
                    ..*settings
                },
                |i| {
                    if let Some(t) = tolerance_m_per_s {
                        i.set_newton_tolerance(*t);
                    }
                    if let Some(n) = dispersion_stages {
                        i.set_dispersion_cap(*n);
                    }
                },
            ),
            Model::Thermal {
                settings,
                nodes,
                width_m,
            } => render_thermal(
                &RenderSettings {
                    seconds,
                    ..*settings
                },
                *nodes,
                *width_m,
            ),
            Model::Rubbed {
                preset,
                friction,
                sample_rate_hz,
                tolerance_m_per_s,
            } => render_rubbed_with(*preset, *friction, seconds, *sample_rate_hz, |s| {
                if let Some(t) = tolerance_m_per_s {
                    s.set_newton_tolerance(*t);
                }
            }),
        }
        .map_err(|e| e.to_string())
    }

    pub fn host_rate_hz(&self) -> f64 {
        match self {
            Model::String { settings, .. } | Model::Thermal { settings, .. } => {
                settings.sample_rate_hz
            }
            Model::Rubbed { sample_rate_hz, .. } => *sample_rate_hz,
        }
    }

    /// How far the rendered signals lag the model, s (the thermal string's streaming
    /// resampler; the others render at the host rate directly).
    fn latency_s(&self) -> Result<f64, String> {
        match self {
            Model::Thermal {
                settings,
                nodes,
                width_m,
            } => {
                let internal = thermal_string(settings, *nodes, *width_m)
                    .map_err(|e| e.to_string())?
                    .internal_rate_hz();
                let fs = settings.sample_rate_hz;
                Ok(Resampler::new(internal, fs)?.latency_samples() / fs)
            }
            _ => Ok(0.0),
        }
    }

    /// The configuration in words: `48 kHz`, `48 kHz, tol 1e-6`, `N_B 10`.
    pub fn setting(&self) -> String {
        let khz = |fs: f64| format!("{} kHz", fs / 1e3);
        let tol = |t: &Option<f64>| t.map_or(String::new(), |t| format!(", tol {t:e} m/s"));
        match self {
            Model::String {
                settings,
                tolerance_m_per_s,
                dispersion_stages,
            } => format!(
                "{}{}{}",
                khz(settings.sample_rate_hz),
                tol(tolerance_m_per_s),
                dispersion_stages.map_or(String::new(), |n| format!(", {n} dispersion sections"))
            ),
            Model::Thermal { nodes, .. } => format!("N_B {nodes}"),
            Model::Rubbed {
                sample_rate_hz,
                tolerance_m_per_s,
                ..
            } => format!("{}{}", khz(*sample_rate_hz), tol(tolerance_m_per_s)),
        }
    }
}

/// One configuration: the model, what its series refines and the step `h` of that
/// refinement (`1 / rate`, the tolerance, `1 / N_B`), smaller is finer.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub series: Series,
    pub step: f64,
    pub model: Model,
}

/// What the metrics need to know about a scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario {
    pub name: &'static str,
    pub nominal_f0_hz: f64,
    /// Velocity of the bow (or exciter) against which slips are counted, m/s.
    pub bow_velocity_m_per_s: f64,
}

/// Configurations of one model on one scenario, with the reference they are measured
/// against (everything refined).
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub scenario: Scenario,
    pub model: String,
    pub reference: Config,
    pub configs: Vec<Config>,
}

/// The whole benchmark.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Rendered length, s (the steady part is the second half).
    pub seconds: f64,
    /// Timed renders per configuration; the fastest counts.
    pub timing_runs: usize,
    pub groups: Vec<Group>,
}

const RATES_HZ: [f64; 6] = [22_050.0, 44_100.0, 48_000.0, 96_000.0, 192_000.0, 384_000.0];
const REFERENCE_RATE_HZ: f64 = 768_000.0;
const TOLERANCES_M_PER_S: [f64; 5] = [1e-2, 1e-4, 1e-6, 1e-8, 1e-10];
const NODES: [usize; 9] = [3, 6, 8, 10, 15, 20, 30, 40, 60];
/// The waveguide's filter-order series: dispersion allpass sections at 48 kHz (the default
/// is [`colophony::dsp::waveguide::DEFAULT_DISPERSION_STAGES`], the references use
/// [`MAX_DISPERSION_STAGES`]).
const DISPERSION_STAGES: [usize; 5] = [2, 4, 8, 16, 32];
const REFERENCE_NODES: usize = 120;
const FIG6_WIDTH_M: f64 = 0.01;

fn is_bristle(law: FrictionModel) -> bool {
    matches!(law, FrictionModel::LuGre | FrictionModel::ElastoPlastic)
}

fn string_group(
    scenario: Scenario,
    settings: RenderSettings,
    rates: &[f64],
    reference_rate: f64,
    tolerances: &[f64],
    dispersion_stages: &[usize],
) -> Group {
    let bristle = is_bristle(settings.friction);
    let with =
        |fs: f64, tolerance_m_per_s: Option<f64>, dispersion_stages: Option<usize>| Model::String {
            settings: RenderSettings {
                sample_rate_hz: fs,
                // The discretisation itself, not the plugin's fixed internal rate.
                native_rate: true,
                ..settings
            },
            tolerance_m_per_s,
            dispersion_stages,
        };
    let at = |fs: f64, tolerance_m_per_s: Option<f64>| with(fs, tolerance_m_per_s, None);
    let tight = bristle.then_some(TIGHT_TOLERANCE_M_PER_S);
    let tolerances = if bristle { tolerances } else { &[] };
    let mut configs = rate_and_tolerance_configs(at, rates, tolerances);
    // The filter order: the dispersion sections at the analysis rate (the reference
    // uses all of them).
    for &n in dispersion_stages {
        configs.push(Config {
            series: Series::Dispersion,
            step: 1.0 / n as f64,
            model: with(ANALYSIS_RATE_HZ, None, Some(n)),
        });
    }
    Group {
        scenario,
        model: settings.friction.name().into(),
        reference: Config {
            series: Series::Rate,
            step: 1.0 / reference_rate,
            model: with(reference_rate, tight, Some(MAX_DISPERSION_STAGES)),
        },
        configs,
    }
}

/// One configuration per host rate (default tolerance), then, if any tolerances are
/// given, one per tolerance and the tight one at [`ANALYSIS_RATE_HZ`].
fn rate_and_tolerance_configs(
    at: impl Fn(f64, Option<f64>) -> Model,
    rates: &[f64],
    tolerances: &[f64],
) -> Vec<Config> {
    let mut configs: Vec<Config> = rates
        .iter()
        .map(|&fs| Config {
            series: Series::Rate,
            step: 1.0 / fs,
            model: at(fs, None),
        })
        .collect();
    if !tolerances.is_empty() {
        for &t in tolerances.iter().chain([&TIGHT_TOLERANCE_M_PER_S]) {
            configs.push(Config {
                series: Series::Tolerance,
                step: t,
                model: at(ANALYSIS_RATE_HZ, Some(t)),
            });
        }
    }
    configs
}

fn rubbed_group(
    preset: RubbedPreset,
    rates: &[f64],
    reference_rate: f64,
    tolerances: &[f64],
) -> Group {
    let spec = preset.spec();
    let friction = FrictionModel::ElastoPlastic;
    let at = |sample_rate_hz: f64, tolerance_m_per_s: Option<f64>| Model::Rubbed {
        preset,
        friction,
        sample_rate_hz,
        tolerance_m_per_s,
    };
    Group {
        scenario: Scenario {
            name: "wine glass",
            nominal_f0_hz: spec.resonator[0].freq_hz,
            bow_velocity_m_per_s: spec.velocity_m_per_s,
        },
        model: friction.name().into(),
        reference: Config {
            series: Series::Rate,
            step: 1.0 / reference_rate,
            model: at(reference_rate, Some(TIGHT_TOLERANCE_M_PER_S)),
        },
        configs: rate_and_tolerance_configs(at, rates, tolerances),
    }
}

fn thermal_group(name: &'static str, beta: f64, nodes: &[usize], reference: usize) -> Group {
    let settings = RenderSettings {
        instrument: InstrumentKind::Cello,
        note: 36,
        bow: BowControl {
            velocity_m_per_s: 0.15,
            // 300 N/m over the 1 cm ribbon.
            force_n: 300.0 * FIG6_WIDTH_M,
            position_beta: beta,
        },
        sample_rate_hz: ANALYSIS_RATE_HZ,
        ..RenderSettings::default()
    };
    let at = |n: usize| Config {
        series: Series::Nodes,
        step: 1.0 / n as f64,
        model: Model::Thermal {
            settings: settings.clone(),
            nodes: n,
            width_m: FIG6_WIDTH_M,
        },
    };
    Group {
        scenario: Scenario {
            name,
            nominal_f0_hz: midi_to_hz(36.0),
            bow_velocity_m_per_s: 0.15,
        },
        model: "thermal".into(),
        reference: at(reference),
        configs: nodes.iter().map(|&n| at(n)).collect(),
    }
}

fn cello_d(law: FrictionModel) -> (Scenario, RenderSettings) {
    (
        Scenario {
            name: "cello D3 (paper A)",
            nominal_f0_hz: midi_to_hz(50.0),
            bow_velocity_m_per_s: 0.1,
        },
        RenderSettings {
            instrument: InstrumentKind::Cello,
            note: 50,
            bow: BowControl {
                velocity_m_per_s: 0.1,
                force_n: 1.1,
                position_beta: 0.1,
            },
            friction: law,
            ..RenderSettings::default()
        },
    )
}

fn violin_a(law: FrictionModel) -> (Scenario, RenderSettings) {
    (
        Scenario {
            name: "violin A4",
            nominal_f0_hz: midi_to_hz(69.0),
            bow_velocity_m_per_s: 0.1,
        },
        RenderSettings {
            instrument: InstrumentKind::Violin,
            note: 69,
            bow: BowControl {
                velocity_m_per_s: 0.1,
                force_n: 0.5,
                position_beta: 0.1,
            },
            friction: law,
            ..RenderSettings::default()
        },
    )
}

const FIG6: &str = "cello C2, paper B Fig. 6 (beta 0.07)";
const FIG6_BETA_01: &str = "cello C2, Fig. 6 bow at beta 0.1";
/// The same two scenes, the plugin's draft and good node counts against the exact `N_B` of
/// the reference quality (which `bench peers` times beside the good preset).
const FIG6_AGAINST_REFERENCE: &str =
    "cello C2, paper B Fig. 6 (beta 0.07), against the reference quality's N_B";
const FIG6_BETA_01_AGAINST_REFERENCE: &str =
    "cello C2, Fig. 6 bow at beta 0.1, against the reference quality's N_B";

impl Plan {
    /// Every scenario, every refinement (about four minutes of a release build on one core).
    pub fn full() -> Self {
        let mut groups = Vec::new();
        for law in FrictionModel::ALL {
            let (scenario, settings) = cello_d(law);
            groups.push(string_group(
                scenario,
                settings,
                &RATES_HZ,
                REFERENCE_RATE_HZ,
                &TOLERANCES_M_PER_S,
                &DISPERSION_STAGES,
            ));
        }
        for law in FrictionModel::ALL {
            let (scenario, settings) = violin_a(law);
            groups.push(string_group(
                scenario,
                settings,
                &RATES_HZ,
                REFERENCE_RATE_HZ,
                &[],
                &DISPERSION_STAGES,
            ));
        }
        groups.push(thermal_group(FIG6, 0.07, &NODES, REFERENCE_NODES));
        groups.push(thermal_group(FIG6_BETA_01, 0.1, &NODES, REFERENCE_NODES));
        {
            use colophony::quality::{DRAFT_NODES, GOOD_NODES, REFERENCE_NODES as EXACT};
            let presets = [DRAFT_NODES, GOOD_NODES];
            groups.push(thermal_group(FIG6_AGAINST_REFERENCE, 0.07, &presets, EXACT));
            groups.push(thermal_group(
                FIG6_BETA_01_AGAINST_REFERENCE,
                0.1,
                &presets,
                EXACT,
            ));
        }
        groups.push(rubbed_group(
            RubbedPreset::WineGlass,
            &RATES_HZ,
            REFERENCE_RATE_HZ,
            &TOLERANCES_M_PER_S,
        ));
        Self {
            seconds: 3.0,
            timing_runs: 3,
            groups,
        }
    }

    /// A few seconds of work: one second renders, one timing run, two refinements per
    /// series against a reference at twice the finest (192 kHz, N_B 24).
    pub fn quick() -> Self {
        let rates = [48_000.0, 96_000.0];
        let reference_rate = 192_000.0;
        let mut groups = Vec::new();
        for law in [FrictionModel::Hyperbolic, FrictionModel::ElastoPlastic] {
            let (scenario, settings) = cello_d(law);
            groups.push(string_group(
                scenario,
                settings,
                &rates,
                reference_rate,
                &[1e-3, 1e-6],
                &[4],
            ));
        }
        let (scenario, settings) = violin_a(FrictionModel::Hyperbolic);
        groups.push(string_group(
            scenario,
            settings,
            &rates,
            reference_rate,
            &[],
            &[],
        ));
        groups.push(thermal_group(FIG6_BETA_01, 0.1, &[6, 12], 24));
        groups.push(rubbed_group(
            RubbedPreset::WineGlass,
            &rates,
            reference_rate,
            &[1e-3],
        ));
        Self {
            seconds: 1.0,
            timing_runs: 1,
            groups,
        }
    }
}

/// What is measured on one rendering (on the analysis grid).
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// `None` for a silent rendering.
    pub f0_hz: Option<f64>,
    /// Amplitudes at `k f0`, `k = 1..=HARMONICS`.
    pub harmonics: Vec<f64>,
    pub slip_fraction: Option<f64>,
    pub slips_per_period: Option<f64>,
    /// Start of Helmholtz motion (one slip per period to the end), s.
    pub helmholtz_s: Option<f64>,
    /// The audio over the first [`WAVEFORM_PERIODS`] nominal periods.
    pub attack: Vec<f64>,
}

/// Errors of a rendering against a reference; `None` where not comparable.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Errors {
    pub f0_cents: Option<f64>,
    pub harmonics_db: Option<f64>,
    pub slip_fraction: Option<f64>,
    pub helmholtz_ms: Option<f64>,
    /// RMS difference over the attack / the reference's RMS there (linear).
    pub waveform_relative: Option<f64>,
}

fn db(x: f64) -> f64 {
    20.0 * x.max(1e-300).log10()
}

/// Measures a rendering of `scenario` that lags the model by `latency_s`.
pub fn measure(
    rendered: &Rendered,
    scenario: &Scenario,
    latency_s: f64,
) -> Result<Measured, String> {
    let fs = ANALYSIS_RATE_HZ;
    let audio = resample_whole_from(&rendered.audio, rendered.sample_rate_hz, fs, latency_s)?;
    let velocity = resample_whole_from(
        &rendered.bow_point_velocity_m_per_s,
        rendered.sample_rate_hz,
        fs,
        latency_s,
    )?;
    let half = audio.len() / 2;
    let steady = &audio[half..];
    let attack_len = ((WAVEFORM_PERIODS / scenario.nominal_f0_hz) * fs).round() as usize;
    let attack = audio[..attack_len.min(audio.len())].to_vec();
    // Silence: nothing to measure a pitch or slips on (1e-9 is far below any bowed note,
    // whose output is of order 0.1).
    if rms(steady) < 1e-9 {
        return Ok(Measured {
            f0_hz: None,
            harmonics: Vec::new(),
            slip_fraction: None,
            slips_per_period: None,
            helmholtz_s: None,
            attack,
        });
    }
    let f0 = peak_frequency_hz(steady, fs, scenario.nominal_f0_hz, 100.0);
    let harmonics = (1..=HARMONICS)
        .map(|k| partial_amplitude(steady, fs, k as f64 * f0))
        .collect();
    // 1 mm/s: far below the slip velocities (v_b / beta ~ 1 m/s), above the ripple.
    let stats = slip_stats(
        &velocity[half..],
        scenario.bow_velocity_m_per_s,
        fs,
        f0,
        1e-3,
    );
    let midpoint = 0.5 * (stats.stick_velocity_m_per_s + stats.slip_velocity_m_per_s);
    let helmholtz_s = helmholtz_onset_s(&velocity, fs, f0, midpoint, scenario.bow_velocity_m_per_s);
    Ok(Measured {
        f0_hz: Some(f0),
        harmonics,
        slip_fraction: Some(stats.slip_fraction),
        slips_per_period: Some(stats.slips_per_period),
        helmholtz_s,
        attack,
    })
}

/// Start of the final run of one-period slip intervals (see the module doc), if the run
/// covers at least the second half of the signal.
fn helmholtz_onset_s(
    velocity: &[f64],
    fs: f64,
    f0_hz: f64,
    midpoint: f64,
    bow_velocity: f64,
) -> Option<f64> {
    // The string slips against the bow direction.
    let sign = if bow_velocity >= 0.0 { -1.0 } else { 1.0 };
    let beyond: Vec<bool> = velocity
        .iter()
        .map(|v| sign * (v - midpoint) > 0.0)
        .collect();
    let onsets: Vec<usize> = (1..beyond.len())
        .filter(|&i| !beyond[i - 1] && beyond[i])
        .collect();
    let period = fs / f0_hz;
    let regular = |a: usize, b: usize| ((b - a) as f64 - period).abs() <= PERIOD_TOLERANCE * period;
    let last = *onsets.last()?;
    // No slip for more than a period at the end: the motion stopped.
    if (velocity.len() - last) as f64 > (1.0 + PERIOD_TOLERANCE) * period {
        return None;
    }
    let mut start = onsets.len() - 1;
    while start > 0 && regular(onsets[start - 1], onsets[start]) {
        start -= 1;
    }
    (onsets[start] <= velocity.len() / 2).then(|| onsets[start] as f64 / fs)
}

/// Errors of `m` against `reference` (see the module doc).
pub fn errors(m: &Measured, reference: &Measured) -> Errors {
    let both = |a: Option<f64>, b: Option<f64>| a.zip(b);
    let f0_cents = both(m.f0_hz, reference.f0_hz).map(|(a, b)| cents(a, b));
    let harmonics_db = (m.harmonics.len() == HARMONICS && reference.harmonics.len() == HARMONICS)
        .then(|| {
            let top = reference.harmonics.iter().fold(0.0f64, |a, &b| a.max(b));
            let level = |a: f64| db(a / top).max(HARMONIC_FLOOR_DB);
            let sum: f64 = m
                .harmonics
                .iter()
                .zip(&reference.harmonics)
                .map(|(a, b)| (level(*a) - level(*b)).powi(2))
                .sum();
            (sum / HARMONICS as f64).sqrt()
        });
    let slip_fraction = both(m.slip_fraction, reference.slip_fraction).map(|(a, b)| (a - b).abs());
    let helmholtz_ms = both(m.helmholtz_s, reference.helmholtz_s).map(|(a, b)| 1e3 * (a - b).abs());
    let n = m.attack.len().min(reference.attack.len());
    let reference_rms = rms(&reference.attack[..n]);
    let waveform_relative = (n > 0 && reference_rms > 0.0).then(|| {
        let diff: Vec<f64> = m.attack[..n]
            .iter()
            .zip(&reference.attack[..n])
            .map(|(a, b)| a - b)
            .collect();
        rms(&diff) / reference_rms
    });
    Errors {
        f0_cents,
        harmonics_db,
        slip_fraction,
        helmholtz_ms,
        waveform_relative,
    }
}

/// One configuration's line in the results.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub scenario: String,
    pub model: String,
    pub series: String,
    pub setting: String,
    pub host_rate_hz: Option<f64>,
    pub realtime_ratio: Option<f64>,
    pub measured: Option<Measured>,
    /// Against the group's reference.
    pub errors: Errors,
    pub note: String,
}

/// One line of a convergence table: a series member against the finest of its series.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceRow {
    pub scenario: String,
    pub model: String,
    pub series: Series,
    pub setting: String,
    pub step: f64,
    pub errors: Errors,
    /// Observed order `ln(e_k / e_k+1) / ln(h_k / h_k+1)` to the next finer member, for
    /// the f0, harmonic and waveform errors.
    pub orders: [Option<f64>; 3],
}

/// The results of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub rows: Vec<Row>,
    pub convergence: Vec<ConvergenceRow>,
}

struct Done {
    config: Config,
    measured: Measured,
    realtime_ratio: f64,
}

fn run_config(config: &Config, plan: &Plan, scenario: &Scenario) -> Result<Done, String> {
    let mut best = f64::MAX;
    let mut rendered = None;
    for _ in 0..plan.timing_runs.max(1) {
        let t = Instant::now();
        let r = config.model.render(plan.seconds)?;
        best = best.min(t.elapsed().as_secs_f64());
        rendered = Some(r);
    }
    let rendered = rendered.expect("at least one run");
    Ok(Done {
        config: config.clone(),
        measured: measure(&rendered, scenario, config.model.latency_s()?)?,
        realtime_ratio: plan.seconds / best,
    })
}

/// Renders, times and measures every configuration of `plan`; `progress` hears about each
/// one as it finishes.
pub fn compute(plan: &Plan, mut progress: impl FnMut(&str)) -> Result<Report, String> {
    let mut rows = Vec::new();
    let mut convergence = Vec::new();
    for group in &plan.groups {
        let s = &group.scenario;
        let reference = run_config(&group.reference, plan, s)?;
        let mut done = Vec::new();
        for config in &group.configs {
            done.push(run_config(config, plan, s)?);
            progress(&format!(
                "{} / {} / {}",
                s.name,
                group.model,
                config.model.setting()
            ));
        }
        for d in done.iter().chain([&reference]) {
            let is_reference = std::ptr::eq(d, &reference);
            let m = &d.measured;
            let mut notes = Vec::new();
            if is_reference {
                notes.push("reference".to_string());
            }
            if m.f0_hz.is_some() && m.helmholtz_s.is_none() {
                notes.push(format!(
                    "no one-slip-per-period regime ({:.2} slips per period)",
                    m.slips_per_period.unwrap_or(0.0)
                ));
            } else if m.f0_hz.is_some() && reference.measured.helmholtz_s.is_none() {
                notes.push("reference has no one-slip-per-period regime".into());
            }
            rows.push(Row {
                scenario: s.name.into(),
                model: group.model.clone(),
                series: d.config.series.name().into(),
                setting: d.config.model.setting(),
                host_rate_hz: Some(d.config.model.host_rate_hz()),
                realtime_ratio: Some(d.realtime_ratio),
                measured: Some(m.clone()),
                errors: errors(m, &reference.measured),
                note: notes.join("; "),
            });
        }
        for series in [
            Series::Rate,
            Series::Tolerance,
            Series::Nodes,
            Series::Dispersion,
        ] {
            let mut members: Vec<&Done> = done
                .iter()
                .chain([&reference])
                .filter(|d| d.config.series == series)
                .collect();
            if members.len() < 2 {
                continue;
            }
            members.sort_by(|a, b| b.config.step.total_cmp(&a.config.step));
            let finest = members.last().expect("two or more");
            let errs: Vec<Errors> = members
                .iter()
                .map(|d| errors(&d.measured, &finest.measured))
                .collect();
            for (k, d) in members.iter().enumerate() {
                let order = |f: fn(&Errors) -> Option<f64>| {
                    let next = errs.get(k + 1).filter(|_| k + 2 < members.len())?;
                    let (a, b) = (f(&errs[k])?.abs(), f(next)?.abs());
                    let h = d.config.step / members[k + 1].config.step;
                    (a > 0.0 && b > 0.0).then(|| (a / b).ln() / h.ln())
                };
                convergence.push(ConvergenceRow {
                    scenario: s.name.into(),
                    model: group.model.clone(),
                    series,
                    setting: d.config.model.setting(),
                    step: d.config.step,
                    errors: errs[k],
                    orders: [
                        order(|e| e.f0_cents),
                        order(|e| e.harmonics_db),
                        order(|e| e.waveform_relative),
                    ],
                });
            }
        }
    }
    Ok(Report { rows, convergence })
}

fn opt(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    x.map_or(String::new(), f)
}

/// The CSV header of `precision.csv`.
pub const CSV_HEADER: &str = "scenario,model,series,setting,host_rate_hz,realtime_ratio,f0_hz,\
f0_error_cents,harmonic_error_db,slip_fraction,slip_fraction_error,helmholtz_s,\
helmholtz_time_error_ms,waveform_error_db,note";

/// `precision.csv`: [`CSV_HEADER`] and one row per configuration (empty cells where a
/// metric is not comparable; the note says why).
pub fn csv(rows: &[Row]) -> String {
    let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for r in rows {
        let m = r.measured.as_ref();
        let e = &r.errors;
        let g = |x: f64| format!("{x:.6e}");
        let cells = [
            q(&r.scenario),
            q(&r.model),
            q(&r.series),
            q(&r.setting),
            opt(r.host_rate_hz, |x| format!("{x}")),
            opt(r.realtime_ratio, g),
            opt(m.and_then(|m| m.f0_hz), g),
            opt(e.f0_cents, g),
            opt(e.harmonics_db, g),
            opt(m.and_then(|m| m.slip_fraction), g),
            opt(e.slip_fraction, g),
            opt(m.and_then(|m| m.helmholtz_s), g),
            opt(e.helmholtz_ms, g),
            opt(e.waveform_relative, |x| g(db(x))),
            q(&r.note),
        ];
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// The results as a markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut out = String::from(
        "| scenario | model | setting | x real time | f0 error (cents) | harmonics (dB RMS) | slip fraction error | Helmholtz time error (ms) | waveform error (dB) | note |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.scenario,
            r.model,
            r.setting,
            opt(r.realtime_ratio, |x| format!("{x:.3}")),
            opt(e.f0_cents, |x| format!("{x:+.4}")),
            opt(e.harmonics_db, |x| format!("{x:.3}")),
            opt(e.slip_fraction, |x| format!("{x:.4}")),
            opt(e.helmholtz_ms, |x| format!("{x:.1}")),
            opt(e.waveform_relative, |x| if x > 0.0 {
                format!("{:.1}", db(x))
            } else {
                "identical".into()
            }),
            r.note
        );
    }
    out
}

/// The convergence tables as markdown.
pub fn convergence_markdown(rows: &[ConvergenceRow]) -> String {
    let mut out = String::from(
        "| scenario | model | series | setting | f0 error (cents) | order | harmonics (dB) | order | waveform error (dB) | order |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let p = |x: Option<f64>| opt(x, |x| format!("{x:.2}"));
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.scenario,
            r.model,
            r.series.name(),
            r.setting,
            opt(e.f0_cents, |x| format!("{x:+.2e}")),
            p(r.orders[0]),
            opt(e.harmonics_db, |x| format!("{x:.2e}")),
            p(r.orders[1]),
            opt(e.waveform_relative, |x| if x > 0.0 {
                format!("{:.1}", db(x))
            } else {
                "finest".into()
            }),
            p(r.orders[2]),
        );
    }
    out
}

/// Runs the benchmark (the quick plan with `quick`), measures the peers, and writes
/// `precision.csv`, `precision.md` and `precision.png` into `out_dir`. Returns the
/// markdown.
pub fn run(out_dir: &Path, quick: bool) -> Result<String, String> {
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    let plan = if quick { Plan::quick() } else { Plan::full() };
    let started = Instant::now();
    let mut report = compute(&plan, |what| {
        eprintln!("[{:6.1} s] {what}", started.elapsed().as_secs_f64());
    })?;
    let peer_rows = peers::measure_peers(out_dir, if quick { 1.0 } else { plan.seconds });
    report.rows.extend(peer_rows);
    // The peers' pitch is against the note asked for; ours, for comparison, likewise.
    let ours = report
        .rows
        .iter()
        .find(|r| r.scenario == "violin A4" && r.model == "hyperbolic" && r.setting == "48 kHz")
        .and_then(|r| r.measured.as_ref()?.f0_hz)
        .map_or(String::new(), |f0| {
            format!(
                "Colophony's violin A4 (hyperbolic, 48 kHz) against 440 Hz, as the peers: {:+.2} cents.\n\n",
                cents(f0, midi_to_hz(69.0))
            )
        });
    let write = |name: &str, text: &str| {
        let path = out_dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    write("precision.csv", &csv(&report.rows))?;
    let md = format!(
        "# Work-precision ({})\n\n{} s renders, best of {} timing runs; errors against each \
         group's reference (its last row).\n\n{}\n{ours}## Convergence (each series against its finest member)\n\n{}",
        if quick { "quick" } else { "full" },
        plan.seconds,
        plan.timing_runs,
        markdown(&report.rows),
        convergence_markdown(&report.convergence)
    );
    write("precision.md", &md)?;
    figure(&report.rows, &out_dir.join("precision.png"))?;
    Ok(md)
}

/// Points not beaten on both axes (faster and more precise), sorted by cost.
fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut sorted = points.to_vec();
    // Fastest first; keep each point more precise than every faster one.
    sorted.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in sorted {
        if front.last().is_none_or(|last| p.1 < last.1) {
            front.push(p);
        }
    }
    front
}

/// `precision.png`: |f0 error| and waveform error against the real-time ratio, log-log,
/// one colour per scenario with its Pareto front; the peers' pitch errors (against the
/// pitch they were asked for, not a refined reference) as black crosses.
pub fn figure(rows: &[Row], out: &Path) -> Result<(), String> {
    use plotters::prelude::*;
    crate::figures::fonts();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let root = BitMapBackend::new(out, (1500, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(
            "Work-precision: error against a refined reference vs real-time ratio",
            ("sans-serif", 22),
        )
        .map_err(|e| err(&e))?;
    let (left, right) = root.split_horizontally(750);
    let mut scenarios: Vec<&str> = Vec::new();
    for r in rows {
        if !r.model.starts_with("peer") && !scenarios.contains(&r.scenario.as_str()) {
            scenarios.push(&r.scenario);
        }
    }
    let palette = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
        RGBColor(23, 190, 207),
    ];
    type Metric = fn(&Row) -> Option<f64>;
    let panels: [(&DrawingArea<BitMapBackend, _>, &str, Metric); 2] = [
        (&left, "|f0 error| (cents)", |r| {
            r.errors.f0_cents.map(f64::abs)
        }),
        (
            &right,
            "waveform error over the attack (relative RMS)",
            |r| r.errors.waveform_relative,
        ),
    ];
    for (area, label, metric) in panels {
        let points: Vec<(usize, bool, f64, f64)> = rows
            .iter()
            .filter_map(|r| {
                let y = metric(r).filter(|y| *y > 0.0)?;
                let x = r.realtime_ratio.filter(|x| *x > 0.0)?;
                let peer = r.model.starts_with("peer");
                let s = scenarios.iter().position(|s| *s == r.scenario).unwrap_or(0);
                Some((s, peer, x, y))
            })
            .collect();
        if points.is_empty() {
            continue;
        }
        let (xlo, xhi) = points
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.2), b.max(p.2)));
        let (ylo, yhi) = points
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.3), b.max(p.3)));
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(75)
            .build_cartesian_2d(
                (xlo / 1.5..xhi * 1.5).log_scale(),
                (ylo / 3.0..yhi * 3.0).log_scale(),
            )
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("real-time ratio (audio time / compute time, one core)")
            .y_desc(label)
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(|e| err(&e))?;
        for (i, name) in scenarios.iter().enumerate() {
            let colour = palette[i % palette.len()];
            let mine: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.0 == i && !p.1)
                .map(|p| (p.2, p.3))
                .collect();
            if mine.is_empty() {
                continue;
            }
            chart
                .draw_series(
                    mine.iter()
                        .map(|&p| Circle::new(p, 4, colour.mix(0.7).filled())),
                )
                .map_err(|e| err(&e))?
                .label(*name)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
            chart
                .draw_series(LineSeries::new(pareto_front(&mine), colour.stroke_width(2)))
                .map_err(|e| err(&e))?;
        }
        let peers: Vec<(f64, f64)> = points.iter().filter(|p| p.1).map(|p| (p.2, p.3)).collect();
        if !peers.is_empty() {
            chart
                .draw_series(
                    peers
                        .iter()
                        .map(|&p| Cross::new(p, 7, BLACK.stroke_width(2))),
                )
                .map_err(|e| err(&e))?
                .label("peers: pitch vs the note asked for")
                .legend(|(x, y)| Cross::new((x + 8, y), 5, BLACK.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .position(SeriesLabelPosition::LowerLeft)
            .draw()
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
