//! Synthetic admittance with known modes: the ground truth of the fit tests, and the
//! source of the shipped generic bridges (`assets/bridges/`). Generic, not measured: the
//! mode tables below are plausible values seeded from published signature-mode
//! frequencies (docs/models.md §B, docs/literature-values.md §2), not any instrument's data.

use super::bridge::{Admittance, BridgeMode, BridgeModes, C64};
use super::data::{entry_position, AdmittanceData};
use std::f64::consts::TAU;

/// SplitMix64: a tiny, well-mixed, seeded generator, so the synthetic data is the same
/// on every machine.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box-Muller).
    pub fn gaussian(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]: the log stays finite
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
    }
}

/// `n` frequencies spaced evenly in log frequency from `lo_hz` to `hi_hz`.
pub fn log_grid_hz(lo_hz: f64, hi_hz: f64, n: usize) -> Vec<f64> {
    let ratio = (hi_hz / lo_hz).ln();
    let mut grid: Vec<f64> = (0..n)
        .map(|k| lo_hz * (ratio * k as f64 / (n - 1).max(1) as f64).exp())
        .collect();
    if n > 1 {
        grid[n - 1] = hi_hz; // exactly, not to rounding
    }
    grid
}

/// The bridge's admittance sampled at `freq_hz`, as 1x1 (`ports` 1: the hh entry) or
/// 2x2 data.
pub fn sample(bridge: &BridgeModes, ports: usize, freq_hz: &[f64]) -> AdmittanceData {
    let entries = if ports == 1 { 1 } else { 3 };
    let y: Vec<[[C64; 2]; 2]> = freq_hz
        .iter()
        .map(|&f| bridge.admittance_s_per_kg(f))
        .collect();
    AdmittanceData {
        freq_hz: freq_hz.to_vec(),
        entries: (0..entries)
            .map(|e| {
                let (i, j) = entry_position(ports, e);
                y.iter().map(|m| m[i][j]).collect()
            })
            .collect(),
    }
}

/// Multiplies every value by `1 + level (n_re + j n_im) / sqrt 2` with standard normal
/// `n`: complex noise of RMS `level` relative to the local value (1 % for `level` 0.01).
pub fn add_relative_noise(data: &mut AdmittanceData, level: f64, seed: u64) {
    let mut rng = SplitMix64::new(seed);
    let a = level / 2f64.sqrt();
    for y in data.entries.iter_mut().flatten() {
        let n = C64::new(rng.gaussian(), rng.gaussian()) * a;
        *y *= C64::new(1.0, 0.0) + n;
    }
}

/// `count` random modes in `lo_hz..hi_hz`: one per equal slot of log frequency (in the
/// middle 60 % of it, so neighbours are at least 40 % of a slot apart and none sits on a
/// band edge), Q uniform in 15..60, random PSD gains `L L^T` (L lower triangular) scaled
/// so the larger diagonal peak is log-uniform in 0.02..0.1 s/kg. `ports` 1 gives 1x1
/// gains `[[g, 0], [0, 0]]`.
pub fn random_modes(seed: u64, count: usize, ports: usize, lo_hz: f64, hi_hz: f64) -> BridgeModes {
    let mut rng = SplitMix64::new(seed);
    let slot = (hi_hz / lo_hz).ln() / count as f64;
    let modes = (0..count)
        .map(|i| {
            let freq_hz = lo_hz * (slot * (i as f64 + rng.range(0.2, 0.8))).exp();
            let bandwidth_hz = freq_hz / rng.range(15.0, 60.0);
            let peak_s_per_kg = (rng.range(0.02f64.ln(), 0.1f64.ln())).exp();
            let gain = if ports == 1 {
                [[1.0, 0.0], [0.0, 0.0]]
            } else {
                let (l11, l21, l22) = (
                    rng.range(0.3, 1.0),
                    rng.range(-0.8, 0.8),
                    rng.range(0.3, 1.0),
                );
                [[l11 * l11, l11 * l21], [l11 * l21, l21 * l21 + l22 * l22]]
            };
            // Peak of a diagonal entry: g / (2 pi b).
            let g = peak_s_per_kg * TAU * bandwidth_hz / gain[0][0].max(gain[1][1]);
            BridgeMode {
                freq_hz,
                bandwidth_hz,
                gain: gain.map(|row| row.map(|x| x * g)),
            }
        })
        .collect();
    BridgeModes { modes }
}

/// One row of a generic bridge table.
#[derive(Clone, Copy, Debug)]
pub struct GenericMode {
    pub freq_hz: f64,
    pub q: f64,
    /// Peak of the mode's dominant direction, `g / (2 pi b)` (s/kg).
    pub peak_s_per_kg: f64,
    /// Direction of motion at the bridge top from horizontal (degrees): 0 is the bowing
    /// direction (bridge rocking), +-90 vertical (body breathing); the sign sets the sign
    /// of the cross term.
    pub angle_deg: f64,
}

const fn row(freq_hz: f64, q: f64, peak_s_per_kg: f64, angle_deg: f64) -> GenericMode {
    GenericMode {
        freq_hz,
        q,
        peak_s_per_kg,
        angle_deg,
    }
}

/// Generic cello: A0 ~ 100 Hz, the main wood modes 180-220 Hz, a bridge hill of
/// horizontally rocking modes at 1.5-2.5 kHz; peaks 1e-2..1e-1 s/kg.
pub const CELLO_GENERIC: [GenericMode; 14] = [
    row(98.0, 30.0, 0.015, 70.0),   // A0 (air)
    row(145.0, 35.0, 0.025, -60.0), // lower corpus mode
    row(185.0, 30.0, 0.05, 50.0),   // B1- like
    row(218.0, 35.0, 0.08, 35.0),   // B1+ like
    row(290.0, 30.0, 0.03, -55.0),
    row(390.0, 30.0, 0.035, 40.0),
    row(520.0, 25.0, 0.03, -60.0),
    row(700.0, 25.0, 0.03, 30.0),
    row(930.0, 20.0, 0.025, 50.0),
    row(1250.0, 18.0, 0.03, -20.0),
    row(1650.0, 12.0, 0.05, 10.0), // bridge hill
    row(2050.0, 10.0, 0.09, -5.0), // bridge rocking, main
    row(2600.0, 10.0, 0.05, 15.0),
    row(3400.0, 10.0, 0.02, -40.0),
];

/// Generic violin: A0 ~ 275 Hz, CBR ~ 405 Hz, B1- ~ 470 Hz, B1+ ~ 540 Hz, a bridge hill
/// at 2-3 kHz; peaks 1e-1..1 s/kg.
pub const VIOLIN_GENERIC: [GenericMode; 14] = [
    row(275.0, 25.0, 0.1, 70.0),   // A0 (air)
    row(405.0, 30.0, 0.15, -45.0), // CBR
    row(470.0, 30.0, 0.5, 50.0),   // B1-
    row(540.0, 35.0, 0.7, 35.0),   // B1+
    row(650.0, 30.0, 0.2, -60.0),
    row(800.0, 25.0, 0.25, 40.0),
    row(1000.0, 25.0, 0.2, -55.0),
    row(1250.0, 20.0, 0.25, 30.0),
    row(1550.0, 18.0, 0.3, -45.0),
    row(1900.0, 12.0, 0.5, 20.0),
    row(2350.0, 10.0, 0.9, 5.0), // bridge hill: bridge rocking, main
    row(2800.0, 10.0, 0.7, -10.0),
    row(3500.0, 10.0, 0.4, 25.0),
    row(4500.0, 8.0, 0.2, -40.0),
];

/// Generic viola: the violin's table with every frequency times 0.84 and every peak
/// admittance times 0.7 (a body about 15 % longer and heavier: A0 ~ 230 Hz, B1- ~ 395 Hz,
/// B1+ ~ 455 Hz, the bridge hill near 2 kHz); chosen, not measured, like the others.
pub const VIOLA_GENERIC: [GenericMode; 14] = {
    let mut table = VIOLIN_GENERIC;
    let mut i = 0;
    while i < table.len() {
        table[i].freq_hz *= VIOLA_FREQUENCY_SCALE;
        table[i].peak_s_per_kg *= VIOLA_ADMITTANCE_SCALE;
        i += 1;
    }
    table
};
/// The viola's frequencies over the violin's.
pub const VIOLA_FREQUENCY_SCALE: f64 = 0.84;
/// The viola's peak admittances over the violin's.
pub const VIOLA_ADMITTANCE_SCALE: f64 = 0.7;

/// A table as modes: gain `g (0.9 u u^T + 0.1 I)` with `u` the unit direction, so every
/// gain is PSD with a 10 % isotropic part, and `g = peak 2 pi b`, so that the admittance
/// along `u` (`u^T G u / (2 pi b)` at resonance) peaks at `peak_s_per_kg`.
pub fn generic_modes(table: &[GenericMode]) -> BridgeModes {
    BridgeModes {
        modes: table
            .iter()
            .map(|r| {
                let bandwidth_hz = r.freq_hz / r.q;
                let g = r.peak_s_per_kg * TAU * bandwidth_hz;
                let (s, c) = r.angle_deg.to_radians().sin_cos();
                let g12 = 0.9 * g * c * s;
                BridgeMode {
                    freq_hz: r.freq_hz,
                    bandwidth_hz,
                    gain: [
                        [g * (0.9 * c * c + 0.1), g12],
                        [g12, g * (0.9 * s * s + 0.1)],
                    ],
                }
            })
            .collect(),
    }
}

/// A generic instrument's synthetic measurement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GenericInstrument {
    Cello,
    Violin,
    Viola,
}

impl GenericInstrument {
    /// The file stem under `assets/bridges/`: `cello`, `violin` or `viola`.
    pub fn name(self) -> &'static str {
        match self {
            GenericInstrument::Cello => "cello",
            GenericInstrument::Violin => "violin",
            GenericInstrument::Viola => "viola",
        }
    }

    /// The true modes.
    pub fn modes(self) -> BridgeModes {
        match self {
            GenericInstrument::Cello => generic_modes(&CELLO_GENERIC),
            GenericInstrument::Violin => generic_modes(&VIOLIN_GENERIC),
            GenericInstrument::Viola => generic_modes(&VIOLA_GENERIC),
        }
    }

    /// The synthetic 2x2 measurement: 800 log-spaced points (cello 50-5000 Hz, violin
    /// 150-8000 Hz, viola 120-7000 Hz) with 1 % complex noise (seed 1 for the cello, 2 for
    /// the violin, 3 for the viola).
    pub fn synthetic_data(self) -> AdmittanceData {
        let (lo, hi, seed) = match self {
            GenericInstrument::Cello => (50.0, 5000.0, 1),
            GenericInstrument::Violin => (150.0, 8000.0, 2),
            GenericInstrument::Viola => (120.0, 7000.0, 3),
        };
        let mut data = sample(&self.modes(), 2, &log_grid_hz(lo, hi, 800));
        add_relative_noise(&mut data, 0.01, seed);
        data
    }
}
