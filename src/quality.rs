//! Quality presets: solver settings chosen from the work-precision benchmark's Pareto
//! fronts (`colophony bench precision`, docs/precision.md), shared by the plugin's
//! `quality` parameter and the renderer's `--quality`.
//!
//! Two settings trade cost for error today:
//!
//! * the Newton tolerance of the bristle laws (LuGre, elasto-plastic) on the waveguide
//!   strings and the rubbed objects;
//! * the thermal bow's node count N_B (space and time together: the internal rate is
//!   `c_low N_B / w`).
//!
//! The waveguide's rate is not a quality setting: in the benchmark its pitch sits within
//! about a cent of the 768 kHz reference at every rate from 22.05 to 384 kHz without a
//! trend, and its attack does not converge (docs/precision.md). Every preset runs the
//! point strings at the instrument's internal rate (48 kHz; the violin's and viola's
//! strings and the cello's A string at 96 kHz, [`InstrumentKind::point_oversampling`]),
//! with the default dispersion filter order (8 sections).
//!
//! Measured by the work-precision benchmark (docs/precision.md and docs/precision.csv:
//! cello D3 at 48 kHz, each tolerance against 1e-13 at the same rate; thermal: paper B's
//! Fig. 6 bow at beta 0.07 and 0.1 against N_B 120; speed ratios from one run's timings).
//! The draft tolerance's cello D3 rows for LuGre and elasto-plastic sit at a regime
//! boundary, so small changes of the solver's path move them between runs; the table
//! gives one run's figures.
//!
//! | preset | Newton tolerance | thermal N_B | measured |
//! |---|---|---|---|
//! | draft | 1e-2 m/s | 8 | attack waveform against 1e-13: LuGre -4.6 dB, elasto-plastic -1.7 dB (the scene sits at a regime boundary: the loose solve slips 1.9 times a period where the tight one is in Helmholtz motion), the wine glass (elasto-plastic) -107 dB; LuGre 1.6x faster than 1e-10, elasto-plastic 1.1x (its Newton start, the tangent predictor, leaves little for a loose tolerance to save); thermal: f0 -0.4 to -0.6 cents, harmonics 0.4-0.9 dB, attack -14 to -17 dB, 32-34x real time |
//! | good | 1e-4 m/s | 10 | LuGre -93 dB, elasto-plastic -5.1 dB (the same steady state, f0 within 0.01 cents and harmonics 0.1 dB, but the attack takes another path at the same boundary), wine glass -152 dB; LuGre 1.5x faster than 1e-10, elasto-plastic 1.1x; thermal: f0 -0.3 to -0.4 cents, harmonics 0.3-0.4 dB, attack -16 to -17 dB, 25-26x |
//! | reference | 1e-10 m/s | 60 | below -200 dB; thermal: f0 -0.03 to -0.05 cents, harmonics 0.04-0.17 dB, attack -29 to -34 dB, 4.3-5.0x |
//! | auto | 1e-4 m/s | per note: [`auto_nodes`] | good's error at every note and bow position |
//!
//! `auto` keeps good's error target where the error grows: a slip lasts `beta / f0`
//! seconds, so higher notes and bow positions nearer the bridge resolve the slip with
//! fewer internal samples at a fixed node count. Auto chooses the node count that gives the
//! slip as many internal samples as good has in the benchmark's scenario (cello open C,
//! beta 0.1, 1 cm: about 138), within 3..=[`MAX_NODES`]. This is a rule calibrated on one
//! measured point of the front, not a measurement at every note.

use crate::dsp::thermal_instrument::MAX_NODES;
use crate::dsp::vocabulary::InstrumentKind;

/// A preset; `Auto` depends on the note and the bow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    Draft,
    Good,
    Reference,
    Auto,
}

/// Draft's hair nodes: the fewest that keep paper B's Figure 6 scene (cello open C, beta
/// 0.07) in Helmholtz motion with the default thermal constants; 6 and fewer double-slip
/// there (docs/precision.md).
pub const DRAFT_NODES: usize = 8;
pub const GOOD_NODES: usize = 10;
pub const REFERENCE_NODES: usize = 60;
/// The fewest nodes `auto` uses (the coarsest setting the benchmark measured).
pub const AUTO_MIN_NODES: usize = 3;

/// The benchmark's thermal scenario, on which `auto` is calibrated.
const CALIBRATION_BETA: f64 = 0.1;
const CALIBRATION_WIDTH_M: f64 = 0.01;

impl Quality {
    pub const ALL: [Quality; 4] = [Self::Draft, Self::Good, Self::Reference, Self::Auto];

    pub fn name(self) -> &'static str {
        match self {
            Self::Draft => "draft",
            Self::Good => "good",
            Self::Reference => "reference",
            Self::Auto => "auto",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    /// Newton tolerance on the bristle velocity step, m/s.
    pub fn newton_tolerance_m_per_s(self) -> f64 {
        match self {
            Self::Draft => 1e-2,
            Self::Good | Self::Auto => 1e-4,
            Self::Reference => 1e-10,
        }
    }

    /// Thermal nodes on the lowest string for a note at `f0_hz` bowed at `beta` with a
    /// bow `width_m` wide.
    pub fn thermal_nodes(self, kind: InstrumentKind, f0_hz: f64, beta: f64, width_m: f64) -> usize {
        self.fixed_thermal_nodes()
            .unwrap_or_else(|| auto_nodes(kind, f0_hz, beta, width_m))
    }

    /// The node count of a preset that does not depend on the note (`None` for auto).
    pub fn fixed_thermal_nodes(self) -> Option<usize> {
        match self {
            Self::Draft => Some(DRAFT_NODES),
            Self::Good => Some(GOOD_NODES),
            Self::Reference => Some(REFERENCE_NODES),
            Self::Auto => None,
        }
    }
}

/// Wave speed of the instrument's lowest string, m/s (it sets the internal rate).
fn lowest_wave_speed(kind: InstrumentKind) -> f64 {
    2.0 * kind.string_length_m() * kind.strings()[0].open_hz
}

/// Internal samples during one slip (`beta / f0` seconds) at `nodes` nodes on the lowest
/// string of `kind` over `width_m`.
pub fn samples_per_slip(
    kind: InstrumentKind,
    nodes: usize,
    f0_hz: f64,
    beta: f64,
    width_m: f64,
) -> f64 {
    let rate = lowest_wave_speed(kind) * nodes as f64 / width_m;
    rate * beta / f0_hz
}

/// Samples per slip that `good` gives in the benchmark's thermal scenario (cello open C,
/// beta 0.1, 1 cm): `auto`'s target.
pub fn auto_target_samples_per_slip() -> f64 {
    let kind = InstrumentKind::Cello;
    samples_per_slip(
        kind,
        GOOD_NODES,
        kind.strings()[0].open_hz,
        CALIBRATION_BETA,
        CALIBRATION_WIDTH_M,
    )
}

/// The fewest nodes that give the slip [`auto_target_samples_per_slip`] internal
/// samples, within [`AUTO_MIN_NODES`]..=[`MAX_NODES`], counted on the lowest string of
/// `kind` (which sets the instrument's internal rate). Absurd inputs (zero, negative or
/// not finite) give the good preset's count.
pub fn auto_nodes(kind: InstrumentKind, f0_hz: f64, beta: f64, width_m: f64) -> usize {
    auto_nodes_at_speed(lowest_wave_speed(kind), f0_hz, beta, width_m)
}

/// [`auto_nodes`] for a string whose wave speed (m/s) sets the internal rate: the
/// renderer's single thermal string.
pub fn auto_nodes_at_speed(wave_speed: f64, f0_hz: f64, beta: f64, width_m: f64) -> usize {
    let valid = |x: f64| x.is_finite() && x > 0.0;
    if !(valid(wave_speed) && valid(f0_hz) && valid(beta) && valid(width_m)) {
        return GOOD_NODES;
    }
    let per_node = wave_speed / width_m * beta / f0_hz;
    // The tolerance keeps an exact ratio (the calibration point itself) from rounding up.
    let nodes = (auto_target_samples_per_slip() / per_node - 1e-9).ceil();
    (nodes.min(MAX_NODES as f64) as usize).clamp(AUTO_MIN_NODES, MAX_NODES)
}

/// Whether `auto` should rebuild the grid for a new note: only if the current count
/// misses the target or exceeds it by more than half (each rebuild fades the instrument
/// out for 10 ms, so notes close in pitch keep the grid).
pub fn auto_needs_rebuild(current: usize, wanted: usize) -> bool {
    current < wanted || current * 2 > wanted * 3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_reproduces_the_good_preset_in_the_calibration_scenario() {
        let c = InstrumentKind::Cello;
        let open_c = c.strings()[0].open_hz;
        assert_eq!(auto_nodes(c, open_c, 0.1, 0.01), GOOD_NODES);
        // About 138 samples per slip (c = 2 * 0.69 m * 65.4 Hz, 10 nodes per cm).
        let s = auto_target_samples_per_slip();
        // From the figures above: 90.25 m/s x 1000 nodes/m x beta 0.1 / 65.41 Hz = 137.98.
        assert!((s - 138.0).abs() < 1.0, "{s}");
    }

    #[test]
    fn auto_adds_nodes_for_higher_notes_and_bows_nearer_the_bridge() {
        let c = InstrumentKind::Cello;
        let open_c = c.strings()[0].open_hz;
        let octave_up = auto_nodes(c, 2.0 * open_c, 0.1, 0.01);
        let nearer = auto_nodes(c, open_c, 0.05, 0.01);
        assert_eq!(octave_up, 2 * GOOD_NODES);
        assert_eq!(nearer, 2 * GOOD_NODES);
        // Far up the A string the cap holds.
        assert_eq!(auto_nodes(c, 880.0, 0.05, 0.01), MAX_NODES);
        // Half way along a wide bow on open C: 138 / 34.5 samples per node = 4 nodes.
        assert_eq!(auto_nodes(c, open_c, 0.5, 0.02), 4);
        // Two octaves lower still, one node would do: the floor holds.
        assert_eq!(auto_nodes(c, open_c / 4.0, 0.5, 0.02), AUTO_MIN_NODES);
    }

    #[test]
    fn auto_meets_its_target_wherever_the_cap_allows() {
        for kind in InstrumentKind::ALL {
            for f0 in [60.0, 100.0, 196.0, 440.0, 1000.0] {
                for beta in [0.02, 0.05, 0.1, 0.2, 0.5] {
                    let n = auto_nodes(kind, f0, beta, 0.01);
                    let s = samples_per_slip(kind, n, f0, beta, 0.01);
                    if n < MAX_NODES {
                        // 1e-9: f64 rounding of the samples-per-slip arithmetic.
                        assert!(s >= auto_target_samples_per_slip() - 1e-9);
                    }
                    if n > AUTO_MIN_NODES {
                        // One node fewer would miss it: the fewest that meet it.
                        let fewer = samples_per_slip(kind, n - 1, f0, beta, 0.01);
                        assert!(fewer < auto_target_samples_per_slip());
                    }
                }
            }
        }
    }

    #[test]
    fn absurd_bow_settings_give_the_good_node_count() {
        let c = InstrumentKind::Cello;
        for (f0, beta) in [
            (0.0, 0.1),
            (65.0, 0.0),
            (f64::NAN, 0.1),
            (65.0, f64::INFINITY),
        ] {
            assert_eq!(auto_nodes(c, f0, beta, 0.01), GOOD_NODES);
        }
    }

    #[test]
    fn auto_keeps_the_grid_for_nearby_notes_and_never_runs_below_target() {
        assert!(!auto_needs_rebuild(10, 10));
        assert!(!auto_needs_rebuild(14, 10));
        assert!(auto_needs_rebuild(16, 10));
        assert!(auto_needs_rebuild(10, 11));
    }

    #[test]
    fn presets_get_finer_from_draft_to_reference() {
        let c = InstrumentKind::Cello;
        let tol: Vec<f64> = [Quality::Draft, Quality::Good, Quality::Reference]
            .iter()
            .map(|q| q.newton_tolerance_m_per_s())
            .collect();
        assert!(tol[0] > tol[1] && tol[1] > tol[2]);
        let nodes: Vec<usize> = [Quality::Draft, Quality::Good, Quality::Reference]
            .iter()
            .map(|q| q.thermal_nodes(c, 65.4, 0.1, 0.01))
            .collect();
        assert!(nodes[0] < nodes[1] && nodes[1] < nodes[2]);
        for q in Quality::ALL {
            assert_eq!(Quality::from_name(q.name()), Some(q));
        }
    }
}
