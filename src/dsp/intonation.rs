//! Intonation by the bowed sound: how many cents each stopped string is tuned away from
//! its equal-tempered free-decay pitch so that the *bowed* note sounds in tune.
//!
//! A bowed string does not sound at its free-decay fundamental. Helmholtz motion is
//! periodic, so the stick-slip locks every partial to an exact harmonic of one frequency,
//! and with a stiff string (partials stretched above the harmonic series) that frequency
//! lies a few cents above the first partial; the friction law adds its own shift, which
//! changes with force (the "flattening effect" toward the top of Schelleng's window).
//! Players tune by the bowed sound and place their fingers by ear, so a real instrument
//! plays its bowed notes in tune and its free decays a little off.
//!
//! The table does what the player's ear does, once, offline: for every friction model,
//! instrument, string and semitone above the open string (0..=
//! [`super::vocabulary::MAX_STOP_SEMITONES`]) it holds the cents the
//! note is moved so that bowing it at the plugin's defaults (0.1 m/s, 1 N on the knob,
//! String Weight on for the point laws, beta 0.1) sounds at equal temperament. It is
//! measured through the same engines the plugin plays by `colophony bench intonation`
//! (`lab/src/intonation_fit.rs`), written to `assets/intonation.csv` and compiled in.
//! Between semitones (pitch bend, vibrato) it is interpolated linearly. The change of
//! pitch with force and bow position is left as the physics gives it, but for the one a
//! player meets on every note: the dynamics. With the Dynamics Guard on, the expression
//! (CC11, CC2, pressure) scales the bow's speed and force and moves it from the bridge,
//! and the bowed pitch moves with it (a slower bow's corners are rounder; up to tens of
//! cents sharp on the Stribeck-type laws at mezzo piano). So the table also holds, for
//! the point laws, the correction at the softer expressions [`SOFT_EXPRESSIONS`], fitted
//! the same way with the bow the performer plays there; between the ones it holds, and
//! up to full expression, it is interpolated linearly, and a model with none (paper B's
//! thermal bow) takes the full expression's correction.
//!
//! A plucked or struck note sounds its free ring, not the bowed sound. The point-bow
//! strings ring where they are tuned; paper B's thermal strings, coupled through their
//! modal bridge, do not always, so the table holds one more row for them,
//! [`THERMAL_FREE_ROW`]: the cents each note is moved so that it rings in tune, measured
//! by `colophony bench intonation --free`.
//!
//! ```
//! use colophony::dsp::vocabulary::InstrumentKind;
//! use colophony::dsp::friction::FrictionModel;
//! use colophony::dsp::intonation::{shipped, TunedModel};
//! // How far the cello's D string is tuned from equal temperament for F#3 (4 semitones
//! // up) under the hyperbolic law, so that it sounds in tune bowed.
//! let row = TunedModel::Point(FrictionModel::Hyperbolic).row();
//! let c = shipped().correction_cents(row, InstrumentKind::Cello, 2, 4.0);
//! assert!(c.abs() < 50.0);
//! ```

use super::friction::FrictionModel;
use super::vocabulary::{InstrumentKind, MAX_CORRECTION_CENTS, MAX_STOP_SEMITONES, STRINGS};
use std::sync::OnceLock;

/// Semitones per string in the table: 0 (open) ..= [`MAX_STOP_SEMITONES`].
const SEMITONES: usize = MAX_STOP_SEMITONES as usize + 1;

/// The table's row for paper B's thermal strings ringing free (plucked, or struck with
/// the stick), after the bowed rows of [`TunedModel`]: the cents each stopped note is
/// moved so that its free ring sounds at equal temperament. A thermal string is tuned
/// by the modal bridge's phase delay at its pitch, and where the bridge's modes are
/// strong against the strings its resonance lands some cents away
/// (docs/articulations.md#pizzicato); the point-bow strings ring at their tuning and
/// have no such row.
pub const THERMAL_FREE_ROW: usize = TunedModel::COUNT;
/// [`THERMAL_FREE_ROW`]'s name in the table's file.
pub const THERMAL_FREE_NAME: &str = "thermal-free";
/// Rows in the table: every [`TunedModel`], then [`THERMAL_FREE_ROW`].
const ROWS: usize = TunedModel::COUNT + 1;

/// Every row with its name in the file, in row order.
fn rows() -> impl Iterator<Item = (usize, &'static str)> {
    TunedModel::all()
        .map(|m| (m.row(), m.name()))
        .chain(std::iter::once((THERMAL_FREE_ROW, THERMAL_FREE_NAME)))
}

/// The expressions below full (1) the table may hold corrections for: the dynamics at 0,
/// then every twelfth from a quarter, and 17/24 between two thirds and three quarters
/// (CC11 0, 32, 42, 53, 64, 74, 85, 90, 95, 106, 116). The Stribeck-type laws' bowed
/// pitch moves by up to 30 cents between a third and two thirds and not along a line
/// (docs/testing.md, "Dynamics"), so they are fitted at every level; between CC11 85 and
/// 95 the Dynamics Guard lets their force go from 0.31 of the speed's to all of it, and
/// with no row between, the static law's notes at CC11 88-92 sat 5-19 cents off the line
/// the two rows interpolate, hence 17/24. The hyperbolic law's pitch moves little and is fitted
/// at 0, 1/3 and 2/3 only. Below a quarter the Stribeck laws' guard holds the violin's
/// and viola's bow at its slowest (`STRIBECK_SLOWEST_SCALE`), so nothing lies between 0
/// and 1/4 to fit.
pub const SOFT_EXPRESSIONS: [f64; 11] = [
    0.0,
    3.0 / 12.0,
    4.0 / 12.0,
    5.0 / 12.0,
    6.0 / 12.0,
    7.0 / 12.0,
    8.0 / 12.0,
    17.0 / 24.0,
    9.0 / 12.0,
    10.0 / 12.0,
    11.0 / 12.0,
];

/// A model the table holds corrections for: one of paper A's point laws on the waveguide
/// strings ([`FrictionModel::ALL`], each by its `name()`), or paper B's thermal bow
/// ("thermal"). Its row in the table follows [`FrictionModel::ALL`], the thermal bow last:
/// a new friction law gets its row from the registry, with no table to keep in step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TunedModel {
    Point(FrictionModel),
    Thermal,
}

impl TunedModel {
    /// How many models the table covers.
    pub const COUNT: usize = FrictionModel::ALL.len() + 1;

    /// Every model, in row order: the point laws of [`FrictionModel::ALL`], then the
    /// thermal bow.
    pub const ALL: [TunedModel; Self::COUNT] = {
        let mut all = [TunedModel::Thermal; Self::COUNT];
        let mut i = 0;
        while i < FrictionModel::ALL.len() {
            all[i] = TunedModel::Point(FrictionModel::ALL[i]);
            i += 1;
        }
        all
    };

    /// Every model, in row order.
    pub fn all() -> impl Iterator<Item = TunedModel> {
        Self::ALL.into_iter()
    }

    /// Its point-bow friction law, `None` for paper B's thermal bow (the performer's
    /// [`crate::performer::Setup::point_law`]).
    pub const fn point_law(self) -> Option<FrictionModel> {
        match self {
            TunedModel::Point(law) => Some(law),
            TunedModel::Thermal => None,
        }
    }

    /// Its row in the table.
    pub const fn row(self) -> usize {
        match self {
            TunedModel::Point(law) => law.index(),
            TunedModel::Thermal => FrictionModel::ALL.len(),
        }
    }

    /// Its name in the table's file (the friction law's `name()`, or "thermal").
    pub fn name(self) -> &'static str {
        match self {
            TunedModel::Point(law) => law.name(),
            TunedModel::Thermal => "thermal",
        }
    }

    /// The model named `name`, `None` for no model the table covers.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::all().find(|m| m.name() == name)
    }
}

/// The free-decay pitch, Hz, that `string` of `kind` is stopped at to play MIDI `note`
/// bent by `bend_semitones` under a reference `reference` semitones from A4 = 440 Hz, at
/// the dynamics' `expression` (0..=1): equal temperament moved by `table`'s correction
/// for `row` at the bent note's place on the string (`None`: tuned by the free decay).
/// Both string instruments tune by it.
#[allow(clippy::too_many_arguments)]
pub fn tuned_hz(
    table: Option<&IntonationTable>,
    row: usize,
    kind: InstrumentKind,
    string: usize,
    note: u8,
    bend_semitones: f64,
    reference: f64,
    expression: f64,
) -> f64 {
    let open = kind.open_notes()[string.min(STRINGS - 1)] as f64;
    // A bend slides the finger as far as the string reaches: down to a detuned open string,
    // up past the end of the fingerboard by as much (the delay lines and the thermal rate
    // floor are sized for these ends).
    let margin = super::vocabulary::PITCH_BEND_SEMITONES;
    let top = open + MAX_STOP_SEMITONES as f64;
    let played = (note as f64 + bend_semitones).clamp(open - margin, top + margin);
    let correction = table.map_or(0.0, |t| {
        t.correction_at(row, kind, string, played - open, expression)
    });
    super::vocabulary::midi_to_hz(played + reference - correction / 100.0)
}

/// Corrections for every model, instrument, string and semitone, cents: at full
/// expression, and at each of [`SOFT_EXPRESSIONS`] (NaN where not fitted).
#[derive(Debug, Clone)]
pub struct IntonationTable {
    cents: Vec<f64>,
    soft: Vec<f64>,
}

/// Equal entries, an entry the table does not hold (NaN) equal to another it does not.
impl PartialEq for IntonationTable {
    fn eq(&self, other: &Self) -> bool {
        let same = |a: &[f64], b: &[f64]| {
            a.len() == b.len()
                && a.iter()
                    .zip(b)
                    .all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
        };
        same(&self.cents, &other.cents) && same(&self.soft, &other.soft)
    }
}

fn index(model: usize, kind: InstrumentKind, string: usize, semitone: usize) -> usize {
    ((model * InstrumentKind::COUNT + kind.index()) * STRINGS + string) * SEMITONES + semitone
}

/// The place of `expression` among [`SOFT_EXPRESSIONS`], if it is one of them (within
/// 0.001).
pub fn soft_level(expression: f64) -> Option<usize> {
    SOFT_EXPRESSIONS
        .iter()
        .position(|&e| (e - expression).abs() < 1e-3)
}

impl IntonationTable {
    /// A table of zeros: every string tuned by its free decay, at every expression.
    pub fn zero() -> Self {
        let n = ROWS * InstrumentKind::COUNT * STRINGS * SEMITONES;
        Self {
            cents: vec![0.0; n],
            soft: vec![f64::NAN; n * SOFT_EXPRESSIONS.len()],
        }
    }

    /// The correction of one entry at soft expression `level` (an index into
    /// [`SOFT_EXPRESSIONS`]), cents; NaN where the table does not hold one.
    pub fn get_soft(
        &self,
        model: usize,
        kind: InstrumentKind,
        string: usize,
        semitone: usize,
        level: usize,
    ) -> f64 {
        self.soft[index(model, kind, string, semitone) * SOFT_EXPRESSIONS.len() + level]
    }

    /// Sets one entry at soft expression `level` (clamped as [`IntonationTable::set`]; a
    /// NaN clears it: the full expression's correction is taken there).
    pub fn set_soft(
        &mut self,
        model: usize,
        kind: InstrumentKind,
        string: usize,
        semitone: usize,
        level: usize,
        cents: f64,
    ) {
        let c = if cents.is_nan() {
            f64::NAN
        } else {
            cents.clamp(-MAX_CORRECTION_CENTS, MAX_CORRECTION_CENTS)
        };
        self.soft[index(model, kind, string, semitone) * SOFT_EXPRESSIONS.len() + level] = c;
    }

    /// One entry at `expression` (0..=1): linear between the levels of
    /// [`SOFT_EXPRESSIONS`] the table holds for it and full expression (the levels it does
    /// not hold are passed over; below the lowest it holds, that one's correction).
    fn entry_at(
        &self,
        model: usize,
        kind: InstrumentKind,
        string: usize,
        semitone: usize,
        expression: f64,
    ) -> f64 {
        let full = self.get(model, kind, string, semitone);
        if expression >= 1.0 {
            return full;
        }
        let e = expression.max(0.0);
        let held = |level: usize| {
            let c = self.get_soft(model, kind, string, semitone, level);
            (!c.is_nan()).then_some((SOFT_EXPRESSIONS[level], c))
        };
        // The nearest held levels either side of `e` (full expression above them all).
        let below = (0..SOFT_EXPRESSIONS.len())
            .rev()
            .filter(|&l| SOFT_EXPRESSIONS[l] <= e)
            .find_map(held);
        let above = (0..SOFT_EXPRESSIONS.len())
            .filter(|&l| SOFT_EXPRESSIONS[l] > e)
            .find_map(held)
            .unwrap_or((1.0, full));
        match below {
            Some((lo, a)) => a + (e - lo) / (above.0 - lo) * (above.1 - a),
            None => above.1,
        }
    }

    /// The correction of one table entry, cents.
    pub fn get(&self, model: usize, kind: InstrumentKind, string: usize, semitone: usize) -> f64 {
        self.cents[index(model, kind, string, semitone)]
    }

    /// Sets one entry (clamped to +-[`MAX_CORRECTION_CENTS`]; a NaN is 0).
    pub fn set(
        &mut self,
        model: usize,
        kind: InstrumentKind,
        string: usize,
        semitone: usize,
        cents: f64,
    ) {
        let c = if cents.is_nan() {
            0.0
        } else {
            cents.clamp(-MAX_CORRECTION_CENTS, MAX_CORRECTION_CENTS)
        };
        self.cents[index(model, kind, string, semitone)] = c;
    }

    /// The correction for `model` (a [`TunedModel::row`]) on `string` of `kind`,
    /// `semitones` (fractional) above the open string, cents: linear between semitones,
    /// the end values beyond them.
    pub fn correction_cents(
        &self,
        model: usize,
        kind: InstrumentKind,
        string: usize,
        semitones: f64,
    ) -> f64 {
        self.correction_at(model, kind, string, semitones, 1.0)
    }

    /// [`IntonationTable::correction_cents`] at the dynamics' `expression` (0..=1; see
    /// [`SOFT_EXPRESSIONS`]).
    pub fn correction_at(
        &self,
        model: usize,
        kind: InstrumentKind,
        string: usize,
        semitones: f64,
        expression: f64,
    ) -> f64 {
        if model >= ROWS || string >= STRINGS || !semitones.is_finite() || !expression.is_finite() {
            return 0.0;
        }
        let s = semitones.clamp(0.0, (SEMITONES - 1) as f64);
        let lo = (s.floor() as usize).min(SEMITONES - 2);
        let t = s - lo as f64;
        let a = self.entry_at(model, kind, string, lo, expression);
        let b = self.entry_at(model, kind, string, lo + 1, expression);
        a + t * (b - a)
    }

    /// Parses the CSV written by [`IntonationTable::to_csv`]. Lines starting with `#` are
    /// comments; entries not in the file stay 0.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut table = Self::zero();
        let mut lines = text
            .lines()
            .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty());
        let header = lines.next().ok_or("empty intonation table")?;
        // Without the expression column every entry is at full expression.
        let columns = match header.trim() {
            "model,instrument,string,semitone,cents" => 5,
            "model,instrument,string,semitone,expression,cents" => 6,
            _ => return Err(format!("unexpected intonation header '{header}'")),
        };
        for (n, line) in lines.enumerate() {
            let f: Vec<&str> = line.split(',').map(str::trim).collect();
            let bad = || format!("intonation table line {}: '{line}'", n + 2);
            if f.len() != columns {
                return Err(bad());
            }
            let model = rows().find(|&(_, name)| name == f[0]).ok_or_else(bad)?.0;
            let kind = InstrumentKind::from_name(f[1]).ok_or_else(bad)?;
            let string: usize = f[2].parse().map_err(|_| bad())?;
            let semitone: usize = f[3].parse().map_err(|_| bad())?;
            let expression: f64 = if columns == 6 {
                f[4].parse().map_err(|_| bad())?
            } else {
                1.0
            };
            let cents: f64 = f[columns - 1].parse().map_err(|_| bad())?;
            if string >= STRINGS || semitone >= SEMITONES || !cents.is_finite() {
                return Err(bad());
            }
            if (expression - 1.0).abs() < 1e-3 {
                table.set(model, kind, string, semitone, cents);
            } else {
                let level = soft_level(expression).ok_or_else(bad)?;
                table.set_soft(model, kind, string, semitone, level, cents);
            }
        }
        Ok(table)
    }

    /// The table as CSV (header `model,instrument,string,semitone,expression,cents`):
    /// every entry at full expression (1), then those it holds at soft expressions.
    pub fn to_csv(&self) -> String {
        let mut s = String::from("model,instrument,string,semitone,expression,cents\n");
        for (m, name) in rows() {
            for kind in InstrumentKind::ALL {
                for string in 0..STRINGS {
                    for semitone in 0..SEMITONES {
                        s.push_str(&format!(
                            "{name},{},{string},{semitone},1,{:.2}\n",
                            kind.name(),
                            self.get(m, kind, string, semitone)
                        ));
                    }
                }
            }
        }
        for (level, expression) in SOFT_EXPRESSIONS.iter().enumerate() {
            for (m, name) in rows() {
                for kind in InstrumentKind::ALL {
                    for string in 0..STRINGS {
                        for semitone in 0..SEMITONES {
                            let c = self.get_soft(m, kind, string, semitone, level);
                            if c.is_finite() {
                                s.push_str(&format!(
                                    "{name},{},{string},{semitone},{expression:.4},{c:.2}\n",
                                    kind.name(),
                                ));
                            }
                        }
                    }
                }
            }
        }
        s
    }
}

/// The shipped table (`assets/intonation.csv`), parsed once. Call it off the audio thread
/// first (the instruments do, when built); later calls are a load.
pub fn shipped() -> &'static IntonationTable {
    static TABLE: OnceLock<IntonationTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        IntonationTable::parse(include_str!("../../assets/intonation.csv"))
            .expect("the shipped intonation table parses (tested)")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_table_parses_and_stays_within_its_bound() {
        let t = shipped();
        assert!(t.cents.iter().all(|c| c.abs() <= MAX_CORRECTION_CENTS));
    }

    #[test]
    fn every_model_has_its_own_row_and_its_name_finds_it() {
        let rows: Vec<usize> = TunedModel::all().map(TunedModel::row).collect();
        assert_eq!(rows, (0..TunedModel::COUNT).collect::<Vec<_>>());
        for model in TunedModel::all() {
            assert_eq!(TunedModel::from_name(model.name()), Some(model));
        }
        for (i, law) in FrictionModel::ALL.into_iter().enumerate() {
            assert_eq!(law.index(), i);
        }
        // An unknown model is refused, never read as another's row.
        assert_eq!(TunedModel::from_name("coulomb"), None);
        assert!(IntonationTable::parse(
            "model,instrument,string,semitone,cents\ncoulomb,cello,0,1,3.0\n"
        )
        .is_err());
    }

    #[test]
    fn a_table_round_trips_through_csv() {
        let mut t = IntonationTable::zero();
        t.set(2, InstrumentKind::Viola, 3, 17, -4.25);
        t.set(4, InstrumentKind::Cello, 0, 0, 12.5);
        let third = soft_level(1.0 / 3.0).unwrap();
        t.set_soft(0, InstrumentKind::Cello, 2, 4, third, 7.75);
        t.set(THERMAL_FREE_ROW, InstrumentKind::DoubleBass, 1, 9, 8.5);
        assert_eq!(IntonationTable::parse(&t.to_csv()).unwrap(), t);
        // The table without the expression column is read at full expression.
        let old = "model,instrument,string,semitone,cents\nstatic,violin,1,3,2.5\n";
        let read = IntonationTable::parse(old).unwrap();
        assert_eq!(read.get(1, InstrumentKind::Violin, 1, 3), 2.5);
        assert!(read.get_soft(1, InstrumentKind::Violin, 1, 3, 0).is_nan());
    }

    #[test]
    fn corrections_interpolate_across_the_held_dynamics_and_fall_back_to_full_expression() {
        let mut t = IntonationTable::zero();
        let k = InstrumentKind::Cello;
        t.set(0, k, 2, 4, 2.0);
        t.set_soft(0, k, 2, 4, soft_level(0.0).unwrap(), 20.0);
        t.set_soft(0, k, 2, 4, soft_level(1.0 / 3.0).unwrap(), 14.0);
        // No other level is held: the line runs from 0 to a third, then on to full
        // expression's 2 cents.
        assert_eq!(t.correction_at(0, k, 2, 4.0, 1.0), 2.0);
        assert_eq!(t.correction_at(0, k, 2, 4.0, 0.0), 20.0);
        assert_eq!(t.correction_at(0, k, 2, 4.0, 1.0 / 3.0), 14.0);
        // Halfway from 0 to a third (past the quarter, not held), and from a third to
        // full (1e-9: rounding).
        assert!((t.correction_at(0, k, 2, 4.0, 1.0 / 6.0) - 17.0).abs() < 1e-9);
        assert!((t.correction_at(0, k, 2, 4.0, 2.0 / 3.0) - 8.0).abs() < 1e-9);
        // A level held above a third takes over from full expression there.
        t.set_soft(0, k, 2, 4, soft_level(0.5).unwrap(), 26.0);
        assert!((t.correction_at(0, k, 2, 4.0, 5.0 / 12.0) - 20.0).abs() < 1e-9);
        assert!((t.correction_at(0, k, 2, 4.0, 0.75) - 14.0).abs() < 1e-9);
        // A model with no soft entries keeps its full correction at every expression.
        t.set(4, k, 2, 4, -3.0);
        assert_eq!(t.correction_at(4, k, 2, 4.0, 0.2), -3.0);
        assert_eq!(t.correction_at(0, k, 2, 4.0, f64::NAN), 0.0);
    }

    #[test]
    fn corrections_interpolate_between_semitones_and_hold_beyond_the_ends() {
        let mut t = IntonationTable::zero();
        let k = InstrumentKind::Violin;
        t.set(0, k, 1, 4, 2.0);
        t.set(0, k, 1, 5, 6.0);
        t.set(0, k, 1, SEMITONES - 1, -3.0);
        assert_eq!(t.correction_cents(0, k, 1, 4.25), 3.0);
        assert_eq!(t.correction_cents(0, k, 1, 100.0), -3.0);
        assert_eq!(t.correction_cents(0, k, 1, -2.0), 0.0);
        assert_eq!(t.correction_cents(0, k, 1, f64::NAN), 0.0);
    }

    #[test]
    fn broken_tables_are_refused_with_the_line() {
        for bad in [
            "",
            "nope\n",
            "model,instrument,string,semitone,cents\nhyperbolic,cello,9,0,1\n",
            "model,instrument,string,semitone,cents\nhyperbolic,lute,0,0,1\n",
            "model,instrument,string,semitone,cents\nhyperbolic,cello,0,0,NaN\n",
            "model,instrument,string,semitone,expression,cents\nhyperbolic,cello,0,0,0.1,1\n",
            "model,instrument,string,semitone,expression,cents\nhyperbolic,cello,0,0,1\n",
        ] {
            assert!(IntonationTable::parse(bad).is_err(), "{bad:?}");
        }
    }
}
