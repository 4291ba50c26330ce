//! Bridge data: the modal bridge's modes and their JSON file format
//! (`{"modes": [{"freq_hz", "bandwidth_hz", "gain"}]}`) with a validating loader, and the
//! shipped bridges the thermal instrument plays. The fitter that writes such files and
//! the admittance responses it compares are in the tools crate (`colophony-lab`,
//! `admittance_fit`).
//!
//! ```
//! use colophony::dsp::bridge_data::{parse_bridge, shipped_bridge};
//! use colophony::dsp::vocabulary::InstrumentKind;
//! let cello = shipped_bridge(InstrumentKind::Cello);
//! assert!(!cello.modes.is_empty());
//! let (one, ports) = parse_bridge(
//!     r#"{"modes": [{"freq_hz": 300, "bandwidth_hz": 20, "gain": [[0.5]]}]}"#,
//! )
//! .unwrap();
//! assert_eq!((one.modes.len(), ports), (1, 1));
//! ```

use super::vocabulary::InstrumentKind;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One mode of the bridge's driving-point admittance,
/// `gain * s / (s^2 + 2 pi bandwidth_hz s + (2 pi freq_hz)^2)`: the DSP core's type, which
/// the physical bridge ([`crate::dsp::bridge::ModalBridge`]) runs.
pub use super::bridge::BridgeMode;

/// A bridge: its modes, as loaded by [`load_bridge`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BridgeModes {
    pub modes: Vec<BridgeMode>,
}

/// Eigenvalues (ascending) of the symmetric 2x2 matrix `[[a, b], [b, c]]`.
pub fn symmetric_eigenvalues(a: f64, b: f64, c: f64) -> [f64; 2] {
    let mean = 0.5 * (a + c);
    let radius = (0.5 * (a - c)).hypot(b);
    [mean - radius, mean + radius]
}

/// The nearest (Frobenius) positive semidefinite matrix to `[[a, b], [b, c]]`: negative
/// eigenvalues set to zero.
pub fn nearest_psd(a: f64, b: f64, c: f64) -> [[f64; 2]; 2] {
    let [lo, hi] = symmetric_eigenvalues(a, b, c);
    if lo >= 0.0 {
        return [[a, b], [b, c]];
    }
    if hi <= 0.0 {
        return [[0.0; 2]; 2];
    }
    // Rank one: hi * v v^T, v the unit eigenvector of hi.
    let (vx, vy) = if b != 0.0 {
        (b, hi - a)
    } else if a >= c {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    let n2 = vx * vx + vy * vy;
    let g12 = hi * vx * vy / n2;
    [[hi * vx * vx / n2, g12], [g12, hi * vy * vy / n2]]
}

#[derive(Serialize, Deserialize)]
struct BridgeFile {
    modes: Vec<ModeFile>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModeFile {
    freq_hz: f64,
    bandwidth_hz: f64,
    gain: Vec<Vec<f64>>,
}

/// Relative tolerance for symmetry and for negative eigenvalues of a gain: rounding only.
const PSD_TOLERANCE: f64 = 1e-12;

/// Reads and validates a bridge JSON file (1x1 or 2x2 gains). Every frequency and
/// bandwidth must be finite and positive (a stable, causal pole pair), every gain square,
/// symmetric and positive semidefinite (to a relative 1e-12), all of one size.
pub fn load_bridge(path: &Path) -> Result<BridgeModes, String> {
    load_bridge_ports(path).map(|(modes, _)| modes)
}

/// [`load_bridge`], also telling whether the file holds 1x1 (`1`) or 2x2 (`2`) gains.
pub fn load_bridge_ports(path: &Path) -> Result<(BridgeModes, usize), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_bridge(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// [`load_bridge_ports`] on JSON text.
pub fn parse_bridge(text: &str) -> Result<(BridgeModes, usize), String> {
    let file: BridgeFile =
        serde_json::from_str(text).map_err(|e| format!("not a bridge JSON file: {e}"))?;
    if file.modes.is_empty() {
        return Err("the bridge has no modes".into());
    }
    let mut ports = 0;
    let mut modes = Vec::with_capacity(file.modes.len());
    for (i, m) in file.modes.iter().enumerate() {
        let n = i + 1;
        if !(m.freq_hz.is_finite() && m.freq_hz > 0.0) {
            return Err(format!(
                "mode {n}: freq_hz must be finite and positive, found {}",
                m.freq_hz
            ));
        }
        if !(m.bandwidth_hz.is_finite() && m.bandwidth_hz > 0.0) {
            return Err(format!(
                "mode {n}: bandwidth_hz must be finite and positive (a stable pole), found {}",
                m.bandwidth_hz
            ));
        }
        let size = m.gain.len();
        if !(size == 1 || size == 2) || m.gain.iter().any(|row| row.len() != size) {
            return Err(format!("mode {n}: gain must be a 1x1 or a 2x2 matrix"));
        }
        if ports == 0 {
            ports = size;
        } else if size != ports {
            return Err(format!(
                "mode {n}: gain is {size}x{size} but earlier modes' are {ports}x{ports}"
            ));
        }
        if m.gain.iter().flatten().any(|g| !g.is_finite()) {
            return Err(format!("mode {n}: gain has a non-finite entry"));
        }
        let gain = if size == 1 {
            [[m.gain[0][0], 0.0], [0.0, 0.0]]
        } else {
            [[m.gain[0][0], m.gain[0][1]], [m.gain[1][0], m.gain[1][1]]]
        };
        let scale = gain.iter().flatten().fold(0.0f64, |s, g| s.max(g.abs()));
        if (gain[0][1] - gain[1][0]).abs() > PSD_TOLERANCE * scale {
            return Err(format!(
                "mode {n}: gain is not symmetric ({} vs {})",
                gain[0][1], gain[1][0]
            ));
        }
        let [lowest, _] = symmetric_eigenvalues(gain[0][0], gain[0][1], gain[1][1]);
        if lowest < -PSD_TOLERANCE * scale {
            return Err(format!(
                "mode {n}: gain is not positive semidefinite (eigenvalue {lowest:e}), so the \
                 bridge would not be passive"
            ));
        }
        modes.push(BridgeMode {
            freq_hz: m.freq_hz,
            bandwidth_hz: m.bandwidth_hz,
            gain,
        });
    }
    Ok((BridgeModes { modes }, ports))
}

/// The bridge as JSON text in the file format; `ports` 1 writes `"gain": [[g11]]`.
pub fn bridge_json(bridge: &BridgeModes, ports: usize) -> String {
    // One mode a line: readable, and a refit shows as a clean diff.
    let lines: Vec<String> = bridge
        .modes
        .iter()
        .map(|m| {
            let mode = ModeFile {
                freq_hz: m.freq_hz,
                bandwidth_hz: m.bandwidth_hz,
                gain: if ports == 1 {
                    vec![vec![m.gain[0][0]]]
                } else {
                    m.gain.iter().map(|row| row.to_vec()).collect()
                },
            };
            serde_json::to_string(&mode).expect("finite plain data serialises")
        })
        .collect();
    format!(
        "{{\n  \"modes\": [\n    {}\n  ]\n}}\n",
        lines.join(",\n    ")
    )
}

/// Writes the bridge JSON to `path` through a temporary file renamed at the end, so a
/// failure never leaves a partial file.
pub fn write_bridge(path: &Path, bridge: &BridgeModes, ports: usize) -> Result<(), String> {
    write_atomically(path, bridge_json(bridge, ports).as_bytes())
}

/// Writes `bytes` to a temporary file beside `path`, then renames it to `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file path", path.display()))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_viola_has_a_bridge_of_its_own_below_the_violins() {
        // A larger body: its air mode (the lowest) below the violin's, above the cello's.
        let lowest = |b: BridgeModes| b.modes.iter().map(|m| m.freq_hz).fold(f64::MAX, f64::min);
        let (violin, viola, cello) = (
            lowest(shipped_bridge(InstrumentKind::Violin)),
            lowest(shipped_bridge(InstrumentKind::Viola)),
            lowest(shipped_bridge(InstrumentKind::Cello)),
        );
        assert!(cello < viola && viola < violin, "{cello} {viola} {violin}");
    }

    use super::*;

    #[test]
    fn admittance_loader_reads_both_sizes_and_round_trips() {
        let two = BridgeModes {
            modes: vec![BridgeMode {
                freq_hz: 200.0,
                bandwidth_hz: 8.0,
                gain: [[2.0, -0.5], [-0.5, 1.0]],
            }],
        };
        assert_eq!(parse_bridge(&bridge_json(&two, 2)).unwrap(), (two, 2));
        let one = r#"{"modes": [{"freq_hz": 100, "bandwidth_hz": 5, "gain": [[3]]}]}"#;
        let (bridge, ports) = parse_bridge(one).unwrap();
        assert_eq!(ports, 1);
        assert_eq!(bridge.modes[0].gain, [[3.0, 0.0], [0.0, 0.0]]);
    }

    #[test]
    fn admittance_loader_refuses_unstable_asymmetric_or_active_modes() {
        let with = |f: &str, b: &str, g: &str| {
            parse_bridge(&format!(
                r#"{{"modes": [{{"freq_hz": {f}, "bandwidth_hz": {b}, "gain": {g}}}]}}"#
            ))
        };
        assert!(with("100", "5", "[[1, 0], [0, 1]]").is_ok());
        assert!(with("-100", "5", "[[1]]").unwrap_err().contains("freq_hz"));
        assert!(with("100", "0", "[[1]]").unwrap_err().contains("stable"));
        assert!(with("100", "5", "[[-1]]")
            .unwrap_err()
            .contains("semidefinite"));
        assert!(with("100", "5", "[[1, 2], [2, 1]]")
            .unwrap_err()
            .contains("semidefinite"));
        assert!(with("100", "5", "[[1, 0.5], [0.4, 1]]")
            .unwrap_err()
            .contains("symmetric"));
        assert!(with("100", "5", "[[1, 0]]").unwrap_err().contains("2x2"));
        assert!(parse_bridge(r#"{"modes": []}"#)
            .unwrap_err()
            .contains("no modes"));
        assert!(parse_bridge("[1, 2]").unwrap_err().contains("not a bridge"));
    }

    #[test]
    fn admittance_nearest_psd_keeps_psd_and_clips_the_rest() {
        assert_eq!(nearest_psd(2.0, 0.5, 1.0), [[2.0, 0.5], [0.5, 1.0]]);
        let g = nearest_psd(1.0, 2.0, 1.0);
        let [lo, hi] = symmetric_eigenvalues(g[0][0], g[0][1], g[1][1]);
        // The eigenvalues of [[1, 2], [2, 1]] are 3 and -1, clipped to 0: f64 rounding at
        // size 3.
        assert!(lo.abs() < 1e-12 && (hi - 3.0).abs() < 1e-12, "{lo} {hi}");
        assert_eq!(nearest_psd(-1.0, 0.0, -2.0), [[0.0; 2]; 2]);
    }
}

/// Each instrument's shipped bridge file, in [`InstrumentKind::ALL`]'s order: generic
/// (designed, not measured) bridges in `assets/bridges/`, embedded in the binary.
const SHIPPED_BRIDGES: [&str; InstrumentKind::COUNT] = [
    include_str!("../../assets/bridges/violin-generic.json"),
    include_str!("../../assets/bridges/viola-generic.json"),
    include_str!("../../assets/bridges/cello-generic.json"),
    include_str!("../../assets/bridges/double-bass-generic.json"),
];

/// `kind`'s shipped bridge (`assets/bridges/<name>-generic.json`), validated.
pub fn shipped_bridge(kind: InstrumentKind) -> BridgeModes {
    parse_bridge(SHIPPED_BRIDGES[kind.index()])
        .unwrap_or_else(|e| panic!("the shipped {} bridge is invalid: {e}", kind.name()))
        .0
}
