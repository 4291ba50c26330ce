//! Fitting a passive modal bridge admittance to measured data, after Maestre,
//! Scavone & Smith, "Digital modeling of bridge driving-point admittances from
//! measurements on violin-family instruments" (SMAC 2013), as used by paper B (Maestre,
//! Spa & Smith, finite-width thermal friction; docs/models.md §B, docs/literature-values.md §2).
//!
//! The model is the continuous-time driving-point admittance at the bridge top,
//!
//! ```text
//! Y(s) = sum_m G_m * s / (s^2 + 2 pi b_m s + (2 pi f_m)^2)
//! ```
//!
//! with every gain `G_m` symmetric positive semidefinite. Each `s / (s^2 + ...)` is
//! positive real for `b_m > 0`, so `Re Y(j w) = sum_m G_m Re(...) >= 0`: the bridge is
//! passive by construction. The bridge model maps each mode to paper B's discrete
//! `H_m(z) R_m`.
//!
//! The fit ([`fit_bridge`]):
//! 1. Peak picking on `sum_i Re Y_ii` gives starting frequencies and half-power
//!    bandwidths; if fewer clear peaks than modes are found, modes are added one at a
//!    time where the residual is largest.
//! 2. Frequencies and bandwidths by Levenberg-Marquardt (the `levenberg-marquardt`
//!    crate) with variable projection: the gains are eliminated by unconstrained linear
//!    least squares at every step (Kaufman's Jacobian). Frequencies are kept inside the
//!    data band and Q within 0.5..1e4 by a sigmoid parametrisation of `ln f` and
//!    `ln (b / f)`.
//! 3. All gains at once by a convex quadratic fit with each `G_m` constrained PSD
//!    (`clarabel`): `[[a, b], [b, c]]` is PSD iff `(a + c, a - c, 2b)` is in the
//!    second-order cone, so no SDP solver is needed; 1x1 gains are just `g >= 0`.
//!
//! Residuals are relative (weight `1 / |Y|`), matching the reported errors: RMS of the
//! magnitude ratio in dB and of the phase difference in degrees, per entry.
//!
//! | symbol | meaning | unit | in code |
//! |---|---|---|---|
//! | `Y_hh, Y_hv, Y_vv` | driving-point admittance: horizontal (bowing direction), cross, vertical | s/kg | [`AdmittanceData::entries`] |
//! | `f_m` | undamped natural frequency of mode m | Hz | [`BridgeMode::freq_hz`] |
//! | `b_m` | half-power bandwidth of mode m (`Q = f / b`) | Hz | [`BridgeMode::bandwidth_hz`] |
//! | `G_m` (`R_m` in paper B) | modal gain matrix, symmetric PSD | 1/kg | [`BridgeMode::gain`] |
//! | `s = j 2 pi f` | Laplace variable on the frequency axis | rad/s | |
//!
//! Files: input CSV `freq_hz,yhh_re,yhh_im,yhv_re,yhv_im,yvv_re,yvv_im` (or
//! `freq_hz,y_re,y_im`), output JSON
//! `{"modes": [{"freq_hz": f, "bandwidth_hz": b, "gain": [[g11, g12], [g12, g22]]}]}`; a
//! 1x1 fit writes `"gain": [[g]]` and [`load_bridge`] reads it as `[[g, 0], [0, 0]]`.
//! The shipped generic bridges (`assets/bridges/`) are in this format; see
//! `assets/bridges/README.md`.
//!
//! ```no_run
//! use colophony_lab::admittance_fit::{
//!     fit_bridge, load_bridge, read_admittance_csv, write_bridge, Admittance,
//! };
//! use std::path::Path;
//!
//! let data = read_admittance_csv(Path::new("measured.csv"))?;
//! let fit = fit_bridge(&data, 15)?; // paper B's cello uses 15 modes
//! for e in &fit.errors {
//!     println!("{}: {:.2} dB, {:.1} deg", e.entry, e.magnitude_db_rms, e.phase_deg_rms);
//! }
//! write_bridge(Path::new("bridge.json"), &fit.bridge, fit.ports)?;
//! let bridge = load_bridge(Path::new("bridge.json"))?;
//! let y = bridge.admittance_s_per_kg(440.0); // 2x2 complex, s/kg
//! # let _ = y;
//! # Ok::<(), String>(())
//! ```

mod bridge;
mod data;
mod figure;
mod fit;
pub mod synthetic;

pub use bridge::{
    bridge_json, load_bridge, load_bridge_ports, mode_response, parse_bridge, shipped_bridge,
    symmetric_eigenvalues, write_bridge, Admittance, BridgeMode, BridgeModes, C64,
};
pub use data::{
    admittance_csv, entry_names, entry_position, parse_admittance_csv, read_admittance_csv,
    write_admittance_csv, AdmittanceData, HEADER_1X1, HEADER_2X2,
};
pub use figure::draw;
pub use fit::{fit_bridge, fit_errors, BridgeFit, EntryError, POINTS_PER_MODE};

use std::fmt::Write as _;
use std::path::Path;

/// `colophony fit-bridge IN.csv --modes M --out OUT.json`: fits, writes the JSON (through
/// a temporary file, so an error leaves nothing) and returns the report.
pub fn run_cli(input: &Path, modes: usize, out: &Path) -> Result<String, String> {
    let data = read_admittance_csv(input)?;
    let fit = fit_bridge(&data, modes)?;
    write_bridge(out, &fit.bridge, fit.ports)?;
    Ok(report(&data, &fit, out))
}

/// The text `run_cli` prints: the modes and the fit error per entry.
pub fn report(data: &AdmittanceData, fit: &BridgeFit, out: &Path) -> String {
    let f = &data.freq_hz;
    let mut text = format!(
        "fitted {} passive modes to {} points of {p}x{p} admittance, {:.1} to {:.1} Hz\n",
        fit.bridge.modes.len(),
        f.len(),
        f[0],
        f[f.len() - 1],
        p = fit.ports,
    );
    let _ = writeln!(
        text,
        "{:>4} {:>10} {:>12} {:>7} {:>11} {:>11} {:>11}",
        "mode", "freq_hz", "bandwidth_hz", "Q", "g11 (1/kg)", "g12", "g22"
    );
    for (i, m) in fit.bridge.modes.iter().enumerate() {
        let _ = write!(
            text,
            "{:>4} {:>10.2} {:>12.3} {:>7.1} {:>11.4e}",
            i + 1,
            m.freq_hz,
            m.bandwidth_hz,
            m.freq_hz / m.bandwidth_hz,
            m.gain[0][0]
        );
        if fit.ports == 2 {
            let _ = write!(text, " {:>11.4e} {:>11.4e}", m.gain[0][1], m.gain[1][1]);
        }
        text.push('\n');
    }
    text.push_str("fit error (RMS over frequency):\n");
    for e in &fit.errors {
        let _ = writeln!(
            text,
            "  {:>2}: magnitude {:.3} dB, phase {:.2} deg",
            e.entry, e.magnitude_db_rms, e.phase_deg_rms
        );
    }
    let _ = write!(text, "wrote {}", out.display());
    text
}

/// `colophony figure bridge-fit --in IN.csv --fit OUT.json --out FILE.png`.
pub fn draw_figure(input: &Path, fit: &Path, out: &Path) -> Result<String, String> {
    figure::draw_figure(input, fit, out)
}
