//! The playing-space map: every friction model, instrument and note bowed across
//! Schelleng's window and the host rates, through the engines the plugin plays
//! (`colophony bench playing-space --out DIR [--quick]`).
//!
//! **Cells.** For each model (the four point laws on the waveguide instrument, paper B's
//! thermal instrument with its modal bridge), instrument, note (from the lowest open string
//! to two octaves above the highest) and host rate, the note is bowed with:
//! - `defaults`: the plugin's default bow (0.1 m/s, 1 N, beta 0.1), on the point laws'
//!   strings times the string's weight as the plugin plays it (String Weight on:
//!   [`InstrumentKind::string_weight`]);
//! - `middle`: beta 0.1 and the geometric middle `sqrt(F_min F_max)` of the note's window;
//! - the grid: beta 0.05, 0.08, 0.12, 0.18, each at `2 F_min`, `sqrt(F_min F_max)` and
//!   `F_max / 2`.
//!
//! The window is [`SchellengWindow`] for the string that plays the note, with the model's
//! own static and sliding friction coefficients ([`model_coefficients`]). The bow
//! velocity is 0.1 m/s, lowered (not below 0.05 m/s) where `F_max / 2` would exceed the
//! plugin's 10 N.
//!
//! **Measured** on the contact probe after [`SETTLE_S`] (Helmholtz motion must be
//! established by then): the regime by the editor's own classifier
//! ([`classify_regime`], so the map and the editor's display agree by construction), the
//! corner-to-corner slip fraction, slips per period and sticking velocity
//! ([`slip_stats`]), and the bowed pitch (the strongest peak within 100 cents of the note,
//! [`peak_frequency_hz`]) in cents from equal temperament at A4 = 440 Hz. A cell is
//! **Helmholtz** when the classifier says one slip per period, the string sticks at the bow
//! velocity (within 10 %) and the slip fraction is within 15 % of beta of what the motion
//! should slip: from the window's middle up, beta itself (Raman); in the `2 F_min` rows,
//! where the corners are rounded most, the slip fraction Cremer's corner rounding predicts
//! from the string's own loop and friction law ([`corner_prediction`],
//! [`colophony::measure::corner`]; paper B's thermal bow has no such prediction and keeps
//! beta).
//!
//! **Attack** (`--attack`). By default the bow lands at the cell's force ([`Attack::Landing`]):
//! the map asks whether a note bowed there *finds* Helmholtz motion within
//! [`SETTLE_S`]. With `--attack catch` ([`Attack::Catch`]) the bow lands at `F_max / 2`,
//! stays there until the probe slips regularly, and is lowered to the cell's force before
//! [`SETTLE_S`]: the map then asks whether the cell's force *holds* Helmholtz motion
//! (Schelleng's window is a stability limit). With `--attack performer`
//! ([`Attack::Performer`]) the bow starts as the plugin's performer starts a separate
//! note: from rest, up to the cell's speed over the stroke's ramp, with its accent, and
//! with the performer's catch where the cell's force lies lower in the window than the
//! defaults ([`colophony::performer::catch`]). The measurement is the same.

pub mod figure;

use colophony::analysis::{cents, peak_frequency_hz, slip_stats};
use colophony::dsp::engine::Engine;
use colophony::dsp::friction::bristle::BristleIntegrator;
use colophony::dsp::friction::BowInput;
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::instrument::Instrument;
use colophony::dsp::intonation::{self, IntonationTable};
use colophony::dsp::thermal::ThermalParams;
use colophony::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
use colophony::dsp::vocabulary::{
    midi_to_hz, BowControl, InstrumentKind, MAX_NOTE_BETA, MIN_NOTE_BETA, STRINGS,
};
use colophony::measure::contact::ContactSample;
use colophony::measure::corner::predicted_slip_fraction;
use colophony::measure::regime::{classify_regime, helmholtz_since, Regime};
use colophony::measure::window::{model_coefficients, SchellengWindow};
use colophony::performer::catch::{catches, Catch, CatchRule};
use colophony::performer::stroke::{Stroke, StrokeMode};
use colophony::performer::{bow_scale_at, guarded_bow};
use colophony::quality::{Quality, GOOD_NODES};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// Seconds a note has to settle before it is measured (Helmholtz motion within
/// 0.3 s of the bow landing).
pub const SETTLE_S: f64 = 0.3;
/// Bow positions of the grid.
pub const GRID_BETAS: [f64; 4] = [0.05, 0.08, 0.12, 0.18];
/// Helmholtz: slip fraction within this fraction of beta (Raman: slip fraction = beta).
pub const SLIP_FRACTION_TOLERANCE: f64 = 0.15;
/// Helmholtz: the string sticks at the bow velocity within this fraction of it.
pub const STICK_TOLERANCE: f64 = 0.1;
/// In tune at nominal bowing, cents (about the smallest mistuning a listener hears in a
/// held tone).
pub const NOMINAL_CENTS: f64 = 3.0;
/// In tune anywhere inside the window, cents (looser: pitch flattens toward `F_max`).
pub const WINDOW_CENTS: f64 = 10.0;
/// Highest bow force of the plugin's range, N.
const MAX_FORCE_N: f64 = 10.0;

/// A friction model as the plugin offers it: the registry the intonation table keys on.
pub use colophony::dsp::intonation::TunedModel as Model;

/// The window of the string that plays `note` (asked onto `string`) of `kind` at `beta`,
/// with `model`'s friction coefficients, in the string's own force (the map bows each
/// string with its force as given, the weight already in it).
fn cell_window(
    model: Model,
    kind: InstrumentKind,
    note: u8,
    string: Option<usize>,
    beta: f64,
) -> SchellengWindow {
    let index = kind.string_for_note_on(note, string).unwrap_or(0);
    SchellengWindow::for_model(kind, index, beta, model == Model::Thermal, false)
}

/// How a cell bows its note.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bowing {
    /// The plugin's defaults.
    Defaults,
    /// beta 0.1, the geometric middle of the window.
    Middle,
    /// `2 F_min` at this beta.
    TwiceMin(f64),
    /// `sqrt(F_min F_max)` at this beta.
    Centre(f64),
    /// `F_max / 2` at this beta.
    HalfMax(f64),
    /// A share of `F_max` at a beta (`OfMax(beta, share)`): the measured window's grid
    /// ([`crate::measured_window`]).
    OfMax(f64, f64),
}

impl Bowing {
    pub fn label(self) -> String {
        match self {
            Bowing::Defaults => "defaults".into(),
            Bowing::Middle => "middle".into(),
            Bowing::TwiceMin(b) => format!("2Fmin@{b}"),
            Bowing::Centre(b) => format!("mid@{b}"),
            Bowing::HalfMax(b) => format!("Fmax/2@{b}"),
            Bowing::OfMax(b, share) => format!("{share}Fmax@{b}"),
        }
    }

    /// Nominal bowing: the defaults and the window's middle.
    pub fn is_nominal(self) -> bool {
        matches!(self, Bowing::Defaults | Bowing::Middle)
    }

    /// Every bowing of a full map, or of a quick one (`2 F_min` and `F_max / 2` dropped
    /// but for beta 0.12: two forces).
    pub fn all(quick: bool) -> Vec<Bowing> {
        let mut v = vec![Bowing::Defaults, Bowing::Middle];
        for b in GRID_BETAS {
            if quick {
                if b == 0.12 {
                    v.push(Bowing::TwiceMin(b));
                    v.push(Bowing::HalfMax(b));
                }
            } else {
                v.extend([Bowing::TwiceMin(b), Bowing::Centre(b), Bowing::HalfMax(b)]);
            }
        }
        v
    }
}

/// One note bowed one way at one rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    pub model: Model,
    pub kind: InstrumentKind,
    pub note: u8,
    pub rate_hz: f64,
    pub bowing: Bowing,
    pub bow: BowControl,
    /// The window's limits at this velocity and beta, N.
    pub f_min_n: f64,
    pub f_max_n: f64,
    pub seconds: f64,
    /// The string the note is asked onto (`None`: the usual choice).
    pub string: Option<usize>,
    /// The intonation the engine tunes by (the shipped table unless a tool says otherwise).
    pub intonation: Option<&'static IntonationTable>,
    /// The bristle laws' time discretisation (the plugin's: the trapezoid).
    pub integrator: BristleIntegrator,
    /// The thermal contact's constants (the plugin's: [`ThermalParams::default`]).
    pub thermal: ThermalParams,
    /// How the note begins (the map's default: [`Attack::Landing`]).
    pub attack: Attack,
    /// The dynamics' expression the engine's intonation follows (1: full, as the map
    /// bows; [`Cell::at_expression`] also plays the bow the Dynamics Guard plays there).
    pub expression: f64,
    /// Whether [`Attack::Performer`] catches the note as the plugin does (the default); a
    /// research knob: what the catch does at each dynamic.
    pub performer_catch: bool,
    /// The most dispersion sections each point-bow string may fit (`None`: the plugin's
    /// [`colophony::dsp::waveguide::DEFAULT_DISPERSION_STAGES`]; 0: strings without
    /// stiffness). A research knob: what the strings' stiffness does to the map.
    pub dispersion_stages: Option<usize>,
    /// Whether the point-bow strings keep their torsion and the bow's hair (the plugin's:
    /// both). A research knob: what each does to the impedance the bow sees.
    pub torsion: bool,
    pub hair: bool,
}

/// How a cell's note begins.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Attack {
    /// The bow lands at its speed and the cell's force (over the engine's 20 ms ramp): the
    /// motion must find Helmholtz motion from there.
    #[default]
    Landing,
    /// The bow lands at `F_max / 2` where the cell's force is below it, is held there
    /// until the editor's classifier calls the probe's last [`CATCH_PERIODS`] periods
    /// Helmholtz motion (checked once a period) or for [`CATCH_HOLD_MAX_S`], then lowered geometrically over [`CATCH_FALL_S`] to the
    /// cell's force, which it has reached by [`SETTLE_S`]: whether the cell's force *holds*
    /// Helmholtz motion once established (the stability Schelleng's window describes),
    /// rather than whether a landing there finds it.
    Catch,
    /// The performer's own attack for a separate down-bow note of velocity
    /// [`PERFORMER_VELOCITY`] ([`Stroke`]): the bow starts from rest and reaches the
    /// cell's speed over the stroke's ramp, with its landing accent on the force and the
    /// performer's catch ([`Catch`]) where the cell's force is light; what the plugin
    /// plays when a note lands.
    Performer,
    /// Held: the bow lands at `F_max / 2`, stays there until the classifier calls the
    /// probe Helmholtz motion (as [`Attack::Catch`], but for up to [`HOLD_MAX_S`]), and
    /// then moves geometrically over [`HOLD_MOVE_S`] to the cell's force, lower or higher;
    /// the cell is measured from [`HOLD_SETTLE_S`]. Whether a force *holds* the motion
    /// once it is going, above `F_max / 2` as below: Schelleng's window as a stability
    /// limit, measured ([`crate::measured_window`]).
    Hold,
}

/// [`Attack::Performer`]: the note velocity (1..=127) the cells are played with.
pub const PERFORMER_VELOCITY: u8 = 100;

impl Attack {
    pub fn name(self) -> &'static str {
        match self {
            Attack::Landing => "landing",
            Attack::Catch => "catch",
            Attack::Performer => "performer",
            Attack::Hold => "hold",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        [
            Attack::Landing,
            Attack::Catch,
            Attack::Performer,
            Attack::Hold,
        ]
        .into_iter()
        .find(|a| a.name().eq_ignore_ascii_case(name))
    }
}

/// [`Attack::Catch`]: periods of the probe the editor's classifier must call Helmholtz
/// motion (with half a period more) for the string to count as caught.
pub const CATCH_PERIODS: usize = 4;
/// [`Attack::Catch`]: the longest the catching force is held, s.
pub const CATCH_HOLD_MAX_S: f64 = 0.24;
/// [`Attack::Catch`]: how long the force takes to fall to the cell's, s
/// (`CATCH_HOLD_MAX_S + CATCH_FALL_S = SETTLE_S`).
pub const CATCH_FALL_S: f64 = 0.06;
/// [`Attack::Hold`]: the longest the catching force is held, s (the low strings near the
/// bridge take up to about a second to find the motion: docs/playing-space.md).
pub const HOLD_MAX_S: f64 = 1.0;
/// [`Attack::Hold`]: how long the force takes to move to the cell's, s (13 periods of
/// the cello's C string, more of every higher one).
pub const HOLD_MOVE_S: f64 = 0.2;
/// [`Attack::Hold`]: when the measurement starts, s (a tenth of a second after the
/// latest the force can arrive).
pub const HOLD_SETTLE_S: f64 = HOLD_MAX_S + HOLD_MOVE_S + 0.1;

impl Cell {
    pub fn new(
        model: Model,
        kind: InstrumentKind,
        note: u8,
        rate_hz: f64,
        bowing: Bowing,
        seconds: f64,
    ) -> Self {
        Self::on_string(model, kind, note, None, rate_hz, bowing, seconds)
    }

    /// A cell whose note is asked onto `string` (where that string can play it).
    pub fn on_string(
        model: Model,
        kind: InstrumentKind,
        note: u8,
        string: Option<usize>,
        rate_hz: f64,
        bowing: Bowing,
        seconds: f64,
    ) -> Self {
        let beta = match bowing {
            Bowing::Defaults | Bowing::Middle => 0.1,
            Bowing::TwiceMin(b) | Bowing::Centre(b) | Bowing::HalfMax(b) | Bowing::OfMax(b, _) => b,
        };
        let window = cell_window(model, kind, note, string, beta);
        let mut v = 0.1;
        if !matches!(bowing, Bowing::Defaults) {
            let half_max = 0.5 * window.max_force_n(v);
            if half_max > MAX_FORCE_N {
                v = (v * MAX_FORCE_N / half_max).max(0.05);
            }
        }
        let (f_min, f_max) = (window.min_force_n(v), window.max_force_n(v));
        let force = match bowing {
            // The plugin weights the strings by default (String Weight), each model against
            // its own reference.
            Bowing::Defaults => {
                let (reference, _, _) = model_coefficients(model == Model::Thermal);
                let index = kind.string_for_note_on(note, string).unwrap_or(0);
                kind.string_weight_for(index, reference)
            }
            Bowing::Middle | Bowing::Centre(_) => (f_min * f_max).sqrt(),
            Bowing::TwiceMin(_) => 2.0 * f_min,
            Bowing::HalfMax(_) => 0.5 * f_max,
            Bowing::OfMax(_, share) => share * f_max,
        };
        Self {
            model,
            kind,
            note,
            rate_hz,
            bowing,
            bow: BowControl {
                velocity_m_per_s: v,
                force_n: force,
                position_beta: beta,
            },
            f_min_n: f_min,
            f_max_n: f_max,
            seconds,
            string,
            intonation: Some(intonation::shipped()),
            integrator: BristleIntegrator::Trapezoid,
            attack: Attack::Landing,
            thermal: ThermalParams::default(),
            expression: 1.0,
            performer_catch: true,
            dispersion_stages: None,
            torsion: true,
            hair: true,
        }
    }

    /// The cell at the dynamics' `expression` (0..=1) as the performer plays it with the
    /// Dynamics Guard on: at the scale `10^(-range (1 - e) / 20)` ([`bow_scale_at`]),
    /// the bow's speed and force scaled and the bow moved from the bridge as
    /// [`guarded_bow`] says (no slower than the model's slowest bow), and the engine's
    /// intonation told the expression.
    pub fn at_expression(self, expression: f64) -> Self {
        let e = expression.clamp(0.0, 1.0);
        let scale = bow_scale_at(e);
        let law = match self.model {
            Model::Point(law) => Some(law),
            Model::Thermal => None,
        };
        let guarded = guarded_bow(law, self.kind, scale);
        let beta = (self.bow.position_beta * guarded.away).clamp(MIN_NOTE_BETA, MAX_NOTE_BETA);
        Self {
            bow: BowControl {
                velocity_m_per_s: self.bow.velocity_m_per_s * guarded.speed,
                force_n: self.bow.force_n * guarded.force,
                position_beta: beta,
            },
            expression: e,
            ..self
        }
    }

    /// When the cell's measurement starts, s: [`HOLD_SETTLE_S`] for [`Attack::Hold`],
    /// [`SETTLE_S`] otherwise.
    pub fn settle_s(&self) -> f64 {
        if self.attack == Attack::Hold {
            HOLD_SETTLE_S
        } else {
            SETTLE_S
        }
    }

    /// Whether the bow force lies inside the window (the defaults may not).
    pub fn inside_window(&self) -> bool {
        self.bow.force_n >= self.f_min_n && self.bow.force_n <= self.f_max_n
    }

    /// The note's equal-tempered frequency, A4 = 440 Hz.
    pub fn nominal_hz(&self) -> f64 {
        midi_to_hz(self.note as f64)
    }
}

/// What one cell did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// The editor's classification of the probe after [`SETTLE_S`]; `None` if the note was
    /// refused (no sound at all).
    pub regime: Option<Regime>,
    pub slips_per_period: f64,
    pub slip_fraction: f64,
    pub stick_velocity_m_per_s: f64,
    /// Bowed pitch against equal temperament, cents.
    pub cents: f64,
    /// Helmholtz motion by the full criterion (see the module doc).
    pub helmholtz: bool,
    /// Peak output sample (the plugin's scale).
    pub peak: f64,
    /// When the note spoke, ms from its start: the first slip of the one-slip-a-period
    /// motion that lasts to the cell's end ([`helmholtz_since`]), `None` if it never does.
    pub speaks_ms: Option<f64>,
    /// The slip fraction Cremer's corner rounding predicts for the cell's string, bow and
    /// law ([`corner_prediction`]); `None` for paper B's thermal bow, or where the
    /// prediction finds no Helmholtz motion.
    pub corner_slip_fraction: Option<f64>,
}

/// Renders `cell` through the engine the plugin plays and returns (audio, probe), both at
/// the host rate.
pub fn render_cell(cell: &Cell) -> Result<(Vec<f64>, Vec<ContactSample>), String> {
    match cell.model {
        Model::Point(law) => Ok(play(cell, &mut point_engine(cell, law))),
        Model::Thermal => {
            let bridge = colophony::dsp::bridge_data::shipped_bridge(cell.kind);
            let settings = ThermalSettings {
                nodes: GOOD_NODES,
                width_m: 0.01,
            };
            let mut engine = ThermalInstrument::with_contact(
                cell.kind,
                &bridge.modes,
                cell.rate_hz,
                settings,
                cell.thermal,
            )?;
            engine.set_intonation(cell.intonation);
            engine.set_preferred_string(cell.string);
            engine.set_dynamics(cell.expression);
            Ok(play(cell, &mut engine))
        }
    }
}

/// The waveguide instrument the plugin plays for `cell`, with `law`.
fn point_engine(cell: &Cell, law: FrictionModel) -> Instrument {
    let mut engine = Instrument::new(cell.kind, cell.rate_hz);
    engine.set_friction_model(law);
    engine.set_newton_tolerance(Quality::Good.newton_tolerance_m_per_s());
    engine.set_intonation(cell.intonation);
    engine.set_preferred_string(cell.string);
    engine.set_bristle_integrator(cell.integrator);
    engine.set_dynamics(cell.expression);
    if let Some(stages) = cell.dispersion_stages {
        engine.set_dispersion_cap(stages);
    }
    if !cell.torsion {
        engine.set_torsion(false);
    }
    if !cell.hair {
        engine.set_bow_hair(false);
    }
    engine
}

/// Plays `cell`'s note on `engine` with the cell's bow (through its [`Attack`]) and
/// returns (audio, probe) at the host rate.
fn play(cell: &Cell, engine: &mut impl Engine) -> (Vec<f64>, Vec<ContactSample>) {
    let n = (cell.seconds * cell.rate_hz).round() as usize;
    let mut audio = Vec::with_capacity(n);
    let mut probe = Vec::with_capacity(n);
    // The plugin calls `update_sleep` at each block; 256-sample blocks here.
    const BLOCK: usize = 256;
    engine.note_on(cell.note);
    let mut catcher = Catcher::new(cell);
    for i in 0..n {
        if i % BLOCK == 0 {
            engine.update_sleep();
        }
        // The probe reads the contact against the bow as played (the stroke's ramp and the
        // catch's force), as the plugin's catch hears it.
        let bow = catcher.bow(i);
        let frame = engine.tick(bow);
        audio.push(frame.audio);
        probe.push(ContactSample::new(&frame, &bow));
        catcher.observe(&probe);
    }
    (audio, probe)
}

/// The bow of a cell sample by sample ([`Attack`]).
struct Catcher {
    bow: BowControl,
    /// [`Attack::Performer`]'s stroke, ticked once a sample, and its catch
    /// ([`colophony::performer::catch`]) while it presses.
    stroke: Option<Stroke>,
    performer_catch: Option<Catch>,
    /// The catching force, N (0: no catch).
    catch: f64,
    /// The note's period, host samples.
    period: f64,
    rate_hz: f64,
    f0_hz: f64,
    /// The probe's length at which the next check runs.
    next_check: usize,
    /// The sample the force starts to fall (`None`: not caught yet).
    fall_from: Option<usize>,
    max_hold: usize,
    fall: f64,
    /// [`Attack::Hold`]: the force moves to the cell's from above or below; otherwise the
    /// catch acts only where the cell's force is lighter than it.
    both_ways: bool,
}

impl Catcher {
    fn new(cell: &Cell) -> Self {
        let catch = match cell.attack {
            Attack::Landing | Attack::Performer => 0.0,
            Attack::Catch | Attack::Hold => 0.5 * cell.f_max_n,
        };
        let (hold, fall) = if cell.attack == Attack::Hold {
            (HOLD_MAX_S, HOLD_MOVE_S)
        } else {
            (CATCH_HOLD_MAX_S, CATCH_FALL_S)
        };
        let stroke = (cell.attack == Attack::Performer).then(|| {
            let mut stroke = Stroke::new(cell.rate_hz);
            stroke.start(StrokeMode::Down, PERFORMER_VELOCITY as f64 / 127.0);
            stroke
        });
        let period = cell.rate_hz / cell.nominal_hz();
        // The performer catches a note of velocity above mezzo on the cell's own window.
        let bow = cell.bow;
        let velocity = PERFORMER_VELOCITY as f64 / 127.0;
        let performer_catch = stroke
            .as_ref()
            .filter(|_| cell.performer_catch && catches(velocity))
            .and_then(|_| {
                Catch::new(
                    cell_window(
                        cell.model,
                        cell.kind,
                        cell.note,
                        cell.string,
                        bow.position_beta,
                    ),
                    CatchRule::for_law(match cell.model {
                        Model::Point(law) => Some(law),
                        Model::Thermal => None,
                    }),
                    cell.nominal_hz(),
                    cell.rate_hz,
                )
            });
        Self {
            bow: cell.bow,
            stroke,
            performer_catch,
            catch,
            period,
            rate_hz: cell.rate_hz,
            f0_hz: cell.nominal_hz(),
            next_check: Self::window(period),
            fall_from: None,
            max_hold: (hold * cell.rate_hz) as usize,
            fall: fall * cell.rate_hz,
            both_ways: cell.attack == Attack::Hold,
        }
    }

    /// Whether the catching force acts on this cell at all.
    fn catching(&self) -> bool {
        self.catch > 0.0 && (self.catch > self.bow.force_n || self.both_ways)
    }

    /// Samples the classifier reads: [`CATCH_PERIODS`] periods and a half.
    fn window(period: f64) -> usize {
        ((CATCH_PERIODS as f64 + 0.5) * period).ceil() as usize
    }

    /// The bow for sample `i` (called once a sample, in order).
    fn bow(&mut self, i: usize) -> BowControl {
        if let Some(stroke) = &mut self.stroke {
            let (speed, force) = stroke.tick();
            let mut force_n = self.bow.force_n * force;
            if let Some(catch) = &mut self.performer_catch {
                let bow = self.bow;
                match catch.force(bow.force_n, bow.velocity_m_per_s, bow.position_beta) {
                    Some(f) => force_n = force_n.max(f),
                    None => self.performer_catch = None,
                }
            }
            return BowControl {
                velocity_m_per_s: self.bow.velocity_m_per_s * speed,
                force_n,
                ..self.bow
            };
        }
        let target = self.bow.force_n;
        if !self.catching() {
            return self.bow;
        }
        let start = self.fall_from.unwrap_or(self.max_hold).min(self.max_hold);
        let force = if i < start {
            self.catch
        } else {
            let x = ((i - start) as f64 / self.fall).min(1.0);
            self.catch * (target / self.catch).powf(x)
        };
        BowControl {
            force_n: force,
            ..self.bow
        }
    }

    /// Once a period, asks the editor's classifier ([`classify_regime`], the map's own)
    /// about the probe's last [`CATCH_PERIODS`] and a half periods; Helmholtz motion there
    /// is caught, and the force starts to fall at the next sample.
    fn observe(&mut self, probe: &[ContactSample]) {
        if let (Some(catch), Some(last)) = (&mut self.performer_catch, probe.last()) {
            catch.observe(last);
        }
        if !self.catching() || self.fall_from.is_some() || probe.len() < self.next_check {
            return;
        }
        self.next_check += self.period.round().max(1.0) as usize;
        let recent = &probe[probe.len() - Self::window(self.period)..];
        if classify_regime(recent, self.rate_hz as f32, self.f0_hz as f32)
            == Some(Regime::Helmholtz)
        {
            self.fall_from = Some(probe.len());
        }
    }
}

/// Renders and measures one cell.
pub fn measure(cell: &Cell) -> Result<Measured, String> {
    let (audio, probe) = render_cell(cell)?;
    let fs = cell.rate_hz;
    let f0 = cell.nominal_hz();
    let start = ((cell.settle_s() * fs) as usize).min(audio.len());
    let period = fs / f0;
    // Whole periods of the note for the slip statistics.
    let periods = ((audio.len() - start) as f64 / period).floor();
    let end = start + (periods * period) as usize;
    let steady = &probe[start..end.max(start)];
    let peak = audio.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let regime = classify_regime(steady, fs as f32, f0 as f32);
    let v: Vec<f64> = steady.iter().map(|s| s.string_velocity as f64).collect();
    let v_b = cell.bow.velocity_m_per_s;
    let stats = slip_stats(&v, v_b, fs, f0, 0.05 * v_b.abs());
    let bowed = peak_frequency_hz(&audio[start..], fs, f0, 100.0);
    let beta = cell.bow.position_beta;
    let corner_slip_fraction = corner_prediction(cell);
    // Below the window's middle the slip is measured against Cremer's corner rounding
    // (where it can be predicted), from the middle up against Raman's beta.
    let expected = match (cell.bowing, corner_slip_fraction) {
        (Bowing::TwiceMin(_), Some(predicted)) => predicted,
        _ => beta,
    };
    let helmholtz = regime == Some(Regime::Helmholtz)
        && (stats.slip_fraction - expected).abs() <= SLIP_FRACTION_TOLERANCE * beta
        && (stats.stick_velocity_m_per_s - v_b).abs() <= STICK_TOLERANCE * v_b.abs();
    let speaks_ms = helmholtz_since(&probe, fs as f32, f0 as f32).map(|k| k as f64 / fs * 1e3);
    Ok(Measured {
        regime: if peak > 0.0 { regime } else { None },
        slips_per_period: stats.slips_per_period,
        slip_fraction: stats.slip_fraction,
        stick_velocity_m_per_s: stats.stick_velocity_m_per_s,
        cents: cents(bowed, f0),
        helmholtz,
        peak,
        speaks_ms,
        corner_slip_fraction,
    })
}

/// The slip fraction of Helmholtz motion with the corner rounded by the cell's string's
/// own loop and sharpened by its friction law at the cell's bow
/// ([`colophony::measure::corner`]): the string and contact the plugin plays for the
/// cell's note; `None` for paper B's thermal bow, or where the prediction finds no
/// Helmholtz motion.
pub fn corner_prediction(cell: &Cell) -> Option<f64> {
    let Model::Point(law) = cell.model else {
        return None;
    };
    let mut engine = point_engine(cell, law);
    engine.note_on(cell.note);
    // A few samples with the bow resting (no force) stop the string and place the bow.
    let resting = BowControl {
        force_n: 0.0,
        ..cell.bow
    };
    for _ in 0..4 {
        engine.tick(resting);
    }
    let index = cell.kind.string_for_note_on(cell.note, cell.string)?;
    let mut contact = engine.contact(index).clone();
    predicted_slip_fraction(
        engine.string(index),
        &mut contact,
        BowInput {
            velocity_m_per_s: cell.bow.velocity_m_per_s,
            normal_force_n: cell.bow.force_n,
        },
    )
}

/// The notes a map covers on `kind`: the lowest open string to two octaves above the
/// highest, every `step` semitones (the highest note always included).
pub fn notes(kind: InstrumentKind, step: usize) -> Vec<u8> {
    let open = kind.open_notes();
    let (lo, hi) = (open[0], open[STRINGS - 1] + 24);
    let mut v: Vec<u8> = (lo..=hi).step_by(step.max(1)).collect();
    if v.last() != Some(&hi) {
        v.push(hi);
    }
    v
}

/// What a run covers.
#[derive(Debug, Clone)]
pub struct Plan {
    pub models: Vec<Model>,
    pub kinds: Vec<InstrumentKind>,
    pub note_step: usize,
    pub bowings: Vec<Bowing>,
    pub rates_hz: Vec<f64>,
    pub seconds: f64,
    /// How every cell's note begins.
    pub attack: Attack,
    /// The point-bow strings' most dispersion sections ([`Cell::dispersion_stages`]).
    pub dispersion_stages: Option<usize>,
}

impl Plan {
    /// The full map: every semitone, the whole grid, the six usual host rates.
    pub fn full() -> Self {
        Self {
            models: Model::ALL.to_vec(),
            kinds: InstrumentKind::ALL.to_vec(),
            note_step: 1,
            bowings: Bowing::all(false),
            rates_hz: vec![44_100.0, 48_000.0, 88_200.0, 96_000.0, 176_400.0, 192_000.0],
            seconds: 1.0,
            attack: Attack::Landing,
            dispersion_stages: None,
        }
    }

    /// The coarse subset: every fifth semitone, two grid forces at one beta, two rates.
    pub fn quick() -> Self {
        Self {
            note_step: 5,
            bowings: Bowing::all(true),
            rates_hz: vec![44_100.0, 96_000.0],
            seconds: 0.8,
            ..Self::full()
        }
    }

    /// The full or quick plan with the command line's overrides: host rates (Hz), note
    /// step, model names.
    pub fn from_options(
        quick: bool,
        rates_hz: &[f64],
        step: Option<usize>,
        models: &[String],
        instruments: &[String],
    ) -> Result<Self, String> {
        let mut plan = if quick { Self::quick() } else { Self::full() };
        if !instruments.is_empty() {
            plan.kinds = instruments
                .iter()
                .map(|name| {
                    InstrumentKind::from_name(&name.to_ascii_lowercase()).ok_or_else(|| {
                        format!("unknown instrument '{name}': choose from violin, viola, cello")
                    })
                })
                .collect::<Result<_, _>>()?;
        }
        if !rates_hz.is_empty() {
            if let Some(bad) = rates_hz
                .iter()
                .find(|r| !(r.is_finite() && **r >= 8000.0 && **r <= 384_000.0))
            {
                return Err(format!("rate {bad} Hz is outside 8000 .. 384000"));
            }
            plan.rates_hz = rates_hz.to_vec();
        }
        if let Some(step) = step {
            plan.note_step = step.max(1);
        }
        if !models.is_empty() {
            plan.models = models
                .iter()
                .map(|name| {
                    Model::ALL
                        .into_iter()
                        .find(|m| m.name().eq_ignore_ascii_case(name))
                        .ok_or_else(|| {
                            let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
                            format!("unknown model '{name}': choose from {}", names.join(", "))
                        })
                })
                .collect::<Result<_, _>>()?;
        }
        Ok(plan)
    }

    pub fn cells(&self) -> Vec<Cell> {
        let mut cells = Vec::new();
        for &model in &self.models {
            for &rate in &self.rates_hz {
                for &kind in &self.kinds {
                    for note in notes(kind, self.note_step) {
                        for &bowing in &self.bowings {
                            let mut cell = Cell::new(model, kind, note, rate, bowing, self.seconds);
                            cell.attack = self.attack;
                            // A held cell is measured from HOLD_SETTLE_S: half a second
                            // after it at least.
                            if self.attack == Attack::Hold {
                                cell.seconds = cell.seconds.max(HOLD_SETTLE_S + 0.5);
                            }
                            cell.dispersion_stages = self.dispersion_stages;
                            cells.push(cell);
                        }
                    }
                }
            }
        }
        cells
    }
}

/// Measures every cell of `plan` in parallel (rayon), with a progress bar on standard error
/// when `progress` is set.
pub fn run_plan(plan: &Plan, progress: bool) -> Result<Vec<(Cell, Measured)>, String> {
    let cells = plan.cells();
    let measured = measure_cells(&cells, progress)?;
    Ok(cells.into_iter().zip(measured).collect())
}

/// Measures `cells` in parallel (rayon), in their order, with a progress bar on standard
/// error when `progress` is set.
pub fn measure_cells(cells: &[Cell], progress: bool) -> Result<Vec<Measured>, String> {
    let bar = if progress {
        indicatif::ProgressBar::new(cells.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} cells, eta {eta}",
        )
        .map_err(|e| e.to_string())?,
    );
    // Longest cells first, so the cores finish together.
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by(|&a, &b| cost(&cells[b]).total_cmp(&cost(&cells[a])));
    let mut results: Vec<(usize, Result<Measured, String>)> = order
        .into_par_iter()
        .map(|i| {
            let r = measure(&cells[i]);
            bar.inc(1);
            (i, r)
        })
        .collect();
    bar.finish_and_clear();
    results.sort_by_key(|r| r.0);
    results.into_iter().map(|(_, r)| r).collect()
}

/// A rough relative cost of a cell, for scheduling only.
fn cost(cell: &Cell) -> f64 {
    // Relative cost of one second: a point law scales with the host rate; the thermal
    // instrument runs at its own rate (about twenty hyperbolic strings at 48 kHz).
    let per_second = match cell.model {
        Model::Point(FrictionModel::Hyperbolic) => cell.rate_hz,
        Model::Point(_) => 4.0 * cell.rate_hz,
        Model::Thermal => 20.0 * 48_000.0,
    };
    cell.seconds * per_second
}

/// Shares of one model at one rate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Shares {
    pub nominal_cells: usize,
    /// Nominal cells within [`NOMINAL_CENTS`] (and Helmholtz).
    pub nominal_in_tune: usize,
    pub window_cells: usize,
    /// Window cells within [`WINDOW_CENTS`] (and Helmholtz).
    pub window_in_tune: usize,
    /// Window cells in Helmholtz motion.
    pub window_helmholtz: usize,
    /// Nominal cells' median bowed pitch, cents (Helmholtz cells only).
    pub nominal_median_cents: f64,
    /// When the window cells in Helmholtz motion spoke ([`Measured::speaks_ms`]), ms:
    /// the 90th percentile and the latest (NaN if none is).
    pub speaks_p90_ms: f64,
    pub speaks_worst_ms: f64,
}

impl Shares {
    pub fn of(results: &[(Cell, Measured)], model: Model, rate_hz: f64) -> Self {
        let mut s = Shares::default();
        let mut nominal_cents = Vec::new();
        let mut speaks = Vec::new();
        for (c, m) in results
            .iter()
            .filter(|(c, _)| c.model == model && c.rate_hz == rate_hz)
        {
            if c.bowing.is_nominal() {
                s.nominal_cells += 1;
                if m.helmholtz {
                    nominal_cents.push(m.cents);
                    if m.cents.abs() <= NOMINAL_CENTS {
                        s.nominal_in_tune += 1;
                    }
                }
            } else {
                s.window_cells += 1;
                if m.helmholtz {
                    s.window_helmholtz += 1;
                    // A cell in Helmholtz motion whose run began after the cell's end is
                    // impossible; one the watch could not time counts as the latest.
                    speaks.push(m.speaks_ms.unwrap_or(f64::INFINITY));
                    if m.cents.abs() <= WINDOW_CENTS {
                        s.window_in_tune += 1;
                    }
                }
            }
        }
        nominal_cents.sort_by(f64::total_cmp);
        s.nominal_median_cents = nominal_cents
            .get(nominal_cents.len() / 2)
            .copied()
            .unwrap_or(f64::NAN);
        speaks.sort_by(f64::total_cmp);
        s.speaks_p90_ms = speaks
            .get((speaks.len() * 9).div_ceil(10).saturating_sub(1))
            .copied()
            .unwrap_or(f64::NAN);
        s.speaks_worst_ms = speaks.last().copied().unwrap_or(f64::NAN);
        s
    }
}

fn percent(part: usize, whole: usize) -> f64 {
    100.0 * part as f64 / whole.max(1) as f64
}

/// The CSV of every cell.
pub fn csv(results: &[(Cell, Measured)]) -> String {
    let mut s = String::from(
        "model,instrument,note,rate_hz,bowing,velocity_m_per_s,force_n,beta,f_min_n,f_max_n,regime,slips_per_period,slip_fraction,stick_velocity_m_per_s,cents,helmholtz,peak,attack,speaks_ms,corner_slip_fraction\n",
    );
    for (c, m) in results {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.4},{:.5},{},{:.5},{:.5},{},{:.3},{:.4},{:.4},{:.2},{},{:.4},{},{},{}",
            c.model.name(),
            c.kind.name(),
            c.note,
            c.rate_hz,
            c.bowing.label(),
            c.bow.velocity_m_per_s,
            c.bow.force_n,
            c.bow.position_beta,
            c.f_min_n,
            c.f_max_n,
            regime_name(m.regime),
            m.slips_per_period,
            m.slip_fraction,
            m.stick_velocity_m_per_s,
            m.cents,
            m.helmholtz,
            m.peak,
            c.attack.name(),
            m.speaks_ms.map_or(String::new(), |t| format!("{t:.1}")),
            m.corner_slip_fraction
                .map_or(String::new(), |f| format!("{f:.4}"))
        );
    }
    s
}

pub fn regime_name(r: Option<Regime>) -> String {
    match r {
        None => "refused".into(),
        Some(Regime::Silent) => "silent".into(),
        Some(Regime::Sliding) => "sliding".into(),
        Some(Regime::Helmholtz) => "helmholtz".into(),
        Some(Regime::MultipleSlips(n)) => format!("slips{n}"),
        Some(Regime::Raucous) => "raucous".into(),
    }
}

/// The summary table (markdown): per model and rate, the shares.
pub fn summary(plan: &Plan, results: &[(Cell, Measured)]) -> String {
    let mut s = String::from(
        "| model | rate (kHz) | nominal in tune (±3 c) | nominal median (c) | window in tune (±10 c) | window Helmholtz | spoke by (ms): p90, latest |\n|---|---|---|---|---|---|---|\n",
    );
    for &model in &plan.models {
        for &rate in &plan.rates_hz {
            let sh = Shares::of(results, model, rate);
            let _ = writeln!(
                s,
                "| {} | {} | {:.0} % ({}/{}) | {} | {:.0} % ({}/{}) | {:.0} % ({}/{}) | {:.0}, {:.0} |",
                model.name(),
                rate / 1000.0,
                percent(sh.nominal_in_tune, sh.nominal_cells),
                sh.nominal_in_tune,
                sh.nominal_cells,
                // No nominal cell in Helmholtz motion: no median.
                if sh.nominal_median_cents.is_finite() {
                    format!("{:+.1}", sh.nominal_median_cents)
                } else {
                    "-".into()
                },
                percent(sh.window_in_tune, sh.window_cells),
                sh.window_in_tune,
                sh.window_cells,
                percent(sh.window_helmholtz, sh.window_cells),
                sh.window_helmholtz,
                sh.window_cells,
                sh.speaks_p90_ms,
                sh.speaks_worst_ms,
            );
        }
    }
    s
}

/// `colophony bench playing-space --out DIR [--quick]`.
pub fn run(out: &Path, plan: &Plan) -> Result<String, String> {
    let plan = plan.clone();
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let t = std::time::Instant::now();
    let results = run_plan(&plan, true)?;
    let csv_path = out.join("playing-space.csv");
    std::fs::write(&csv_path, csv(&results))
        .map_err(|e| format!("cannot write {}: {e}", csv_path.display()))?;
    let mut pngs = Vec::new();
    for &model in &plan.models {
        let path = out.join(format!("playing-space-{}.png", model.name()));
        figure::draw(&plan, &results, model, &path)?;
        pngs.push(path.display().to_string());
    }
    Ok(format!(
        "{} cells in {:.0} s, attack: {}\n\n{}\nwrote {} and {}",
        results.len(),
        t.elapsed().as_secs_f64(),
        plan.attack.name(),
        summary(&plan, &results),
        csv_path.display(),
        pngs.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(attack: Attack) -> Cell {
        let mut c = Cell::new(
            Model::Point(FrictionModel::Hyperbolic),
            InstrumentKind::Cello,
            50,
            48_000.0,
            Bowing::TwiceMin(0.1),
            1.0,
        );
        c.attack = attack;
        c
    }

    /// Feeds `catcher` a string velocity sample by sample (as the probe of a bow in contact
    /// at the cell's velocity) and returns the force it asked for at each.
    fn forces(catcher: &mut Catcher, n: usize, v_s: impl Fn(usize) -> f64) -> Vec<f64> {
        let mut probe = Vec::with_capacity(n);
        (0..n)
            .map(|i| {
                let bow = catcher.bow(i);
                let frame = colophony::dsp::vocabulary::Frame {
                    bow_point_velocity_m_per_s: v_s(i),
                    friction_force_n: 0.3 * bow.force_n,
                    ..Default::default()
                };
                probe.push(ContactSample::new(&frame, &catcher.bow));
                catcher.observe(&probe);
                bow.force_n
            })
            .collect()
    }

    /// The catch holds `F_max / 2` until the probe shows regular slips, then lowers the
    /// force to the cell's, which it has reached (to rounding) by the time the map starts
    /// measuring: the map measures the cell's force, whatever the attack.
    #[test]
    fn a_caught_attack_is_at_the_cells_force_when_the_map_measures() {
        let c = cell(Attack::Catch);
        let target = c.bow.force_n;
        let catch = 0.5 * c.f_max_n;
        assert!(catch > 10.0 * target, "2 F_min lies far below F_max / 2");
        let settle = (SETTLE_S * c.rate_hz) as usize;
        let period = c.rate_hz / c.nominal_hz();
        let (v_b, beta) = (c.bow.velocity_m_per_s, c.bow.position_beta);
        // Ideal Helmholtz motion from the first sample: sticking at v_b, slipping for
        // beta of each period at v_b - v_b / beta.
        let helmholtz = |i: usize| {
            if (i as f64 / period).fract() < beta {
                v_b - v_b / beta
            } else {
                v_b
            }
        };
        let mut catcher = Catcher::new(&c);
        let f = forces(&mut catcher, settle + 10, helmholtz);
        let fall = catcher.fall_from.expect("regular slips are caught");
        // Caught at the first check whose window holds Helmholtz motion: the first, once
        // the probe spans the classifier's CATCH_PERIODS and a half periods.
        assert_eq!(fall, Catcher::window(period), "fall at {fall}");
        assert!(f[..=fall].iter().all(|&x| x == catch));
        assert!(
            f[fall..].windows(2).all(|w| w[1] <= w[0]),
            "the force only falls"
        );
        let done = fall + (CATCH_FALL_S * c.rate_hz).ceil() as usize;
        assert!(f[done..].iter().all(|&x| (x / target - 1.0).abs() < 1e-12));

        // A probe that never slips: held for the longest hold, at the cell's force by the
        // measurement's start all the same.
        let mut catcher = Catcher::new(&c);
        let f = forces(&mut catcher, settle + 10, |_| v_b);
        assert_eq!(catcher.fall_from, None);
        let hold = (CATCH_HOLD_MAX_S * c.rate_hz) as usize;
        assert!(f[..hold].iter().all(|&x| x == catch));
        assert!(f[settle..]
            .iter()
            .all(|&x| (x / target - 1.0).abs() < 1e-12));
    }

    /// A landing plays the cell's bow from the first sample, and a catch does not touch a
    /// force already above `F_max / 2`.
    #[test]
    fn a_landing_and_a_catch_above_half_f_max_play_the_cells_bow() {
        let c = cell(Attack::Landing);
        let mut catcher = Catcher::new(&c);
        assert!(forces(&mut catcher, 1000, |_| 0.0)
            .iter()
            .all(|&f| f == c.bow.force_n));
        let mut above = cell(Attack::Catch);
        above.bow.force_n = 0.75 * above.f_max_n;
        let mut catcher = Catcher::new(&above);
        assert!(forces(&mut catcher, 1000, |_| 0.0)
            .iter()
            .all(|&f| f == above.bow.force_n));
    }
}
