//! The modal bridge's admittance response (complex, s/kg), for the fitter and its figure.
//! The bridge's data types and its JSON file format are the plugin's
//! ([`colophony::dsp::bridge_data`]), so the plugin loads bridges without the fitter.

use nalgebra::Complex;
use std::f64::consts::TAU;

pub use colophony::dsp::bridge_data::{
    bridge_json, load_bridge, load_bridge_ports, nearest_psd, parse_bridge, shipped_bridge,
    symmetric_eigenvalues, write_atomically, write_bridge, BridgeMode, BridgeModes,
};

/// A complex admittance value (s/kg).
pub type C64 = Complex<f64>;

/// The response of one mode per unit gain at `freq_hz`:
/// `s / (s^2 + 2 pi b s + (2 pi f)^2)` at `s = j 2 pi freq_hz`, in seconds (times a gain in
/// 1/kg gives s/kg).
pub fn mode_response(mode_freq_hz: f64, bandwidth_hz: f64, freq_hz: f64) -> C64 {
    let w = TAU * freq_hz;
    let w0 = TAU * mode_freq_hz;
    let beta = TAU * bandwidth_hz;
    C64::new(0.0, w) / C64::new(w0 * w0 - w * w, w * beta)
}

/// The driving-point admittance of a modal bridge.
pub trait Admittance {
    /// The 2x2 admittance matrix Y(j 2 pi freq_hz) in s/kg, (horizontal, vertical).
    fn admittance_s_per_kg(&self, freq_hz: f64) -> [[C64; 2]; 2];
}

impl Admittance for BridgeModes {
    fn admittance_s_per_kg(&self, freq_hz: f64) -> [[C64; 2]; 2] {
        let mut y = [[C64::new(0.0, 0.0); 2]; 2];
        for mode in &self.modes {
            let h = mode_response(mode.freq_hz, mode.bandwidth_hz, freq_hz);
            for (row, gain_row) in y.iter_mut().zip(&mode.gain) {
                for (yij, gij) in row.iter_mut().zip(gain_row) {
                    *yij += h * *gij;
                }
            }
        }
        y
    }
}
