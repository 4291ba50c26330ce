//! `colophony bench thermal-constants`: paper B's thermal contact with candidate constant
//! sets, bowed on probe notes of every instrument across its Schelleng window, through the
//! engine the plugin plays (the four-string thermal instrument with its modal bridge and
//! resampler, 48 kHz, Good's 10 nodes over 1 cm). Paper B publishes none of the
//! constants (docs/literature-values.md §1.3); this is the measurement the choice rests on
//! (docs/playing-space.md, "Choosing the thermal constants").
//!
//! Per set, note and force: the regime on the contact probe after 0.3 s (`H` Helmholtz by
//! the map's full criterion, `h` one slip per period failing the slip-fraction or
//! sticking criterion, `m` several slips, `r` raucous, `s` sliding) and the bowed pitch
//! in cents from equal temperament with the free-decay tuning (no intonation table), so
//! the column shows the physical change of pitch with force. Forces: the plugin's
//! default 1 N, then `F_max / 16, / 8, / 4, / 2` at beta 0.1 and 0.1 m/s, `F_max` with
//! the set's own `mu_cold` and `mu_hot`.

use crate::playing_space::{measure, Bowing, Cell, Model};
use colophony::dsp::thermal::{bulk_cooled, ThermalParams};
use colophony::dsp::vocabulary::InstrumentKind;
use colophony::measure::regime::Regime;
use colophony::measure::window::SchellengWindow;
use rayon::prelude::*;
use std::fmt::Write as _;

/// The probe notes: each instrument's lowest string and its upper strings' high positions.
pub const PROBES: [(InstrumentKind, u8); 13] = [
    (InstrumentKind::Cello, 36),
    (InstrumentKind::Cello, 50),
    (InstrumentKind::Cello, 61),
    (InstrumentKind::Cello, 76),
    (InstrumentKind::Viola, 48),
    (InstrumentKind::Viola, 69),
    (InstrumentKind::Viola, 84),
    (InstrumentKind::Violin, 55),
    (InstrumentKind::Violin, 69),
    (InstrumentKind::Violin, 76),
    (InstrumentKind::Violin, 83),
    (InstrumentKind::Violin, 88),
    (InstrumentKind::Violin, 93),
];

/// Fractions of `F_max` bowed besides the default 1 N.
pub const FRACTIONS: [f64; 4] = [1.0 / 16.0, 1.0 / 8.0, 0.25, 0.5];

/// The candidate sets: paper B's eq. (1) as written, the bulk-cooled set, and
/// faster-cooling sets with the heating per contact area, the default among them
/// (docs/playing-space.md).
pub fn candidates() -> Vec<(&'static str, ThermalParams)> {
    let fast = |tau_b_s: f64, c_c: f64, c_h: f64, mu_hot: f64| ThermalParams {
        c_c_per_m: c_c,
        c_h_kelvin_m_per_j: c_h,
        bulk_cooling_per_s: 1.0 / tau_b_s,
        heating_reference_load_n_per_m: 300.0,
        mu_hot,
        ..ThermalParams::paper_b_eq1()
    };
    vec![
        ("eq. 1 as written", ThermalParams::paper_b_eq1()),
        ("bulk-cooled 0.3 ms", bulk_cooled()),
        ("33 us, 15000, 4500", fast(33e-6, 15000.0, 4500.0, 0.3)),
        (
            "17 us, 15000, 9000",
            fast(1.0 / 60_000.0, 15000.0, 9000.0, 0.3),
        ),
        (
            "33 us, 15000, 4500, mu_hot 0.5 (the default)",
            ThermalParams::default(),
        ),
        (
            "17 us, 15000, 9000, mu_hot 0.55",
            fast(1.0 / 60_000.0, 15000.0, 9000.0, 0.55),
        ),
        (
            "10 us, 15000, 15000, mu_hot 0.55",
            fast(1e-5, 15000.0, 15000.0, 0.55),
        ),
    ]
}

/// One probe cell: `fraction` of `F_max` (0: the plugin's default 1 N).
fn cell(kind: InstrumentKind, note: u8, fraction: f64, thermal: ThermalParams) -> Cell {
    let bowing = if fraction == 0.0 {
        Bowing::Defaults
    } else {
        Bowing::HalfMax(0.1)
    };
    let mut c = Cell::new(Model::Thermal, kind, note, 48_000.0, bowing, 1.0);
    c.intonation = None;
    c.thermal = thermal;
    let index = kind.string_for_note_on(note, None).unwrap_or(0);
    let window = SchellengWindow {
        mu_s: thermal.mu_cold,
        mu_d: thermal.mu_hot,
        ..SchellengWindow::for_string(kind, index, 0.1)
    };
    c.bow.velocity_m_per_s = 0.1;
    c.f_min_n = window.min_force_n(0.1);
    c.f_max_n = window.max_force_n(0.1);
    if fraction > 0.0 {
        c.bow.force_n = fraction * c.f_max_n;
    }
    c
}

fn tag(regime: Option<Regime>, helmholtz: bool) -> char {
    match regime {
        Some(Regime::Helmholtz) if helmholtz => 'H',
        Some(Regime::Helmholtz) => 'h',
        Some(Regime::Sliding) => 's',
        Some(Regime::Raucous) => 'r',
        Some(Regime::MultipleSlips(_)) => 'm',
        Some(Regime::Silent) | None => '0',
    }
}

/// Runs every candidate set on the probes (in parallel across cores) and returns the
/// report: per set, a row per note and a summary line.
pub fn run() -> Result<String, String> {
    let mut report = String::new();
    for (name, thermal) in candidates() {
        thermal.validate()?;
        let mut cells = Vec::new();
        for &(kind, note) in &PROBES {
            for fraction in std::iter::once(0.0).chain(FRACTIONS) {
                cells.push(cell(kind, note, fraction, thermal));
            }
        }
        let results = cells
            .par_iter()
            .map(|c| measure(c).map(|m| (*c, m)))
            .collect::<Result<Vec<_>, _>>()?;
        let _ = writeln!(report, "== {name}: {thermal:?}");
        let _ = writeln!(
            report,
            "note        | 1 N (default)  | F_max/16       | F_max/8        | F_max/4        | F_max/2"
        );
        let (mut helmholtz, mut one_slip, mut sliding, mut default_ok) = (0, 0, 0, 0);
        for (row, chunk) in results.chunks(1 + FRACTIONS.len()).enumerate() {
            let (kind, note) = PROBES[row];
            let mut line = format!("{:<6} {:>3} ", kind.name(), note);
            for (i, (c, m)) in chunk.iter().enumerate() {
                let _ = write!(
                    line,
                    "| {:5.3} N {}{:+6.1} ",
                    c.bow.force_n,
                    tag(m.regime, m.helmholtz),
                    m.cents
                );
                let one = m.regime == Some(Regime::Helmholtz);
                if i == 0 {
                    default_ok += (one && m.cents.abs() <= 25.0) as usize;
                } else {
                    helmholtz += m.helmholtz as usize;
                    one_slip += one as usize;
                    sliding += (m.regime == Some(Regime::Sliding)) as usize;
                }
            }
            let _ = writeln!(report, "{line}");
        }
        let window_cells = PROBES.len() * FRACTIONS.len();
        let _ = writeln!(
            report,
            "window cells: Helmholtz {helmholtz}, one slip per period {one_slip}, sliding {sliding} (of {window_cells}); \
             at 1 N one slip per period within 25 cents: {default_ok} of {}\n",
            PROBES.len()
        );
    }
    Ok(report)
}
