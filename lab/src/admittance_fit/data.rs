//! Measured admittance as CSV: `freq_hz,yhh_re,yhh_im,yhv_re,yhv_im,yvv_re,yvv_im` (2x2,
//! symmetric, so `yvh = yhv`) or `freq_hz,y_re,y_im` (1x1), values in s/kg, frequencies
//! strictly increasing. Blank lines are skipped; nothing else is.

use super::bridge::{write_atomically, C64};
use std::fmt::Write as _;
use std::path::Path;

/// The 2x2 header.
pub const HEADER_2X2: &str = "freq_hz,yhh_re,yhh_im,yhv_re,yhv_im,yvv_re,yvv_im";
/// The 1x1 header.
pub const HEADER_1X1: &str = "freq_hz,y_re,y_im";

/// Admittance samples: one complex series per matrix entry, `hh, hv, vv` for 2x2 data or
/// the single `y` for 1x1 data.
#[derive(Clone, Debug, PartialEq)]
pub struct AdmittanceData {
    /// Strictly increasing, positive (Hz).
    pub freq_hz: Vec<f64>,
    /// `entries[e][k]`: entry `e` at `freq_hz[k]` (s/kg).
    pub entries: Vec<Vec<C64>>,
}

impl AdmittanceData {
    /// 1 for a 1x1 admittance, 2 for a 2x2 one.
    pub fn ports(&self) -> usize {
        if self.entries.len() == 1 {
            1
        } else {
            2
        }
    }

    /// The entries' names, in order: `["y"]` or `["hh", "hv", "vv"]`.
    pub fn entry_names(&self) -> &'static [&'static str] {
        entry_names(self.ports())
    }
}

/// The entry names for a 1x1 (`ports` 1) or 2x2 admittance.
pub fn entry_names(ports: usize) -> &'static [&'static str] {
    if ports == 1 {
        &["y"]
    } else {
        &["hh", "hv", "vv"]
    }
}

/// The (row, column) of the gain matrix that entry `e` of a `ports`-port admittance reads.
pub fn entry_position(ports: usize, e: usize) -> (usize, usize) {
    match (ports, e) {
        (1, _) | (_, 0) => (0, 0),
        (_, 1) => (0, 1),
        _ => (1, 1),
    }
}

/// Reads and validates an admittance CSV file.
pub fn read_admittance_csv(path: &Path) -> Result<AdmittanceData, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_admittance_csv(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// [`read_admittance_csv`] on the file's text.
pub fn parse_admittance_csv(text: &str) -> Result<AdmittanceData, String> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let Some((_, header)) = lines.next() else {
        return Err("the file is empty".into());
    };
    let header: String = header.chars().filter(|c| !c.is_whitespace()).collect();
    let columns = if header == HEADER_2X2 {
        7
    } else if header == HEADER_1X1 {
        3
    } else {
        return Err(format!(
            "the header must be `{HEADER_2X2}` (2x2) or `{HEADER_1X1}` (1x1), found `{header}`"
        ));
    };
    let entries = (columns - 1) / 2;
    let mut data = AdmittanceData {
        freq_hz: Vec::new(),
        entries: vec![Vec::new(); entries],
    };
    let mut values = Vec::with_capacity(columns);
    for (line, row) in lines {
        values.clear();
        for field in row.split(',') {
            let field = field.trim();
            let v: f64 = field
                .parse()
                .map_err(|_| format!("line {line}: `{field}` is not a number"))?;
            if !v.is_finite() {
                return Err(format!("line {line}: `{field}` is not a finite number"));
            }
            values.push(v);
        }
        if values.len() != columns {
            return Err(format!(
                "line {line}: expected {columns} columns as in the header, found {}",
                values.len()
            ));
        }
        let f = values[0];
        if f <= 0.0 {
            return Err(format!("line {line}: frequency {f} Hz is not positive"));
        }
        if let Some(&prev) = data.freq_hz.last() {
            if f == prev {
                return Err(format!("line {line}: duplicate frequency {f} Hz"));
            }
            if f < prev {
                return Err(format!(
                    "line {line}: frequency {f} Hz follows {prev} Hz; frequencies must increase"
                ));
            }
        }
        data.freq_hz.push(f);
        for (e, series) in data.entries.iter_mut().enumerate() {
            series.push(C64::new(values[1 + 2 * e], values[2 + 2 * e]));
        }
    }
    if data.freq_hz.is_empty() {
        return Err("the file has a header but no data rows".into());
    }
    Ok(data)
}

/// The data as CSV text (frequencies in shortest round-trip decimal, values in
/// shortest round-trip scientific notation).
pub fn admittance_csv(data: &AdmittanceData) -> String {
    let mut text = String::new();
    text.push_str(if data.ports() == 1 {
        HEADER_1X1
    } else {
        HEADER_2X2
    });
    text.push('\n');
    for (k, f) in data.freq_hz.iter().enumerate() {
        let _ = write!(text, "{f}");
        for series in &data.entries {
            let _ = write!(text, ",{:e},{:e}", series[k].re, series[k].im);
        }
        text.push('\n');
    }
    text
}

/// Writes the data as CSV through a temporary file renamed at the end.
pub fn write_admittance_csv(path: &Path, data: &AdmittanceData) -> Result<(), String> {
    write_atomically(path, admittance_csv(data).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn admittance_csv_round_trips_exactly() {
        let data = AdmittanceData {
            freq_hz: vec![50.0, 61.25, 1e4],
            entries: (0..3)
                .map(|e| {
                    (0..3)
                        .map(|k| C64::new(1e-3 / (k + e + 1) as f64, -0.1 / 3.0))
                        .collect()
                })
                .collect(),
        };
        assert_eq!(parse_admittance_csv(&admittance_csv(&data)).unwrap(), data);
    }

    #[test]
    fn admittance_csv_accepts_spaces_crlf_and_blank_lines() {
        let text = "freq_hz, y_re, y_im\r\n\r\n100, 1e-2, -3e-3\r\n200,0.5,0\r\n";
        let data = parse_admittance_csv(text).unwrap();
        assert_eq!(data.freq_hz, vec![100.0, 200.0]);
        assert_eq!(data.entries[0][0], C64::new(1e-2, -3e-3));
    }
}
