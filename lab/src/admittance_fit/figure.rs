//! The bridge-fit figure, like paper B's Figure 5: magnitude (dB re 1 s/kg) and phase
//! (degrees) of data (dots) and model (line) for each entry, on a log frequency axis.

use super::bridge::{load_bridge_ports, Admittance, BridgeModes};
use super::data::{entry_position, read_admittance_csv, AdmittanceData};
use super::fit::fit_errors;
use plotters::prelude::*;
use std::path::Path;

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// Draws data against fit to `out` (PNG).
pub fn draw_figure(input: &Path, fit: &Path, out: &Path) -> Result<String, String> {
    let data = read_admittance_csv(input)?;
    let (bridge, ports) = load_bridge_ports(fit)?;
    if ports != data.ports() {
        return Err(format!(
            "{} is {p}x{p} but {} is {d}x{d}",
            fit.display(),
            input.display(),
            p = ports,
            d = data.ports()
        ));
    }
    let title = format!(
        "Bridge admittance: {} against the {}-mode fit {}",
        input.file_name().unwrap_or_default().to_string_lossy(),
        bridge.modes.len(),
        fit.file_name().unwrap_or_default().to_string_lossy()
    );
    draw(&data, &bridge, &title, out)?;
    Ok(format!("wrote {}", out.display()))
}

/// Draws the figure for `data` against `bridge`.
pub fn draw(
    data: &AdmittanceData,
    bridge: &BridgeModes,
    title: &str,
    out: &Path,
) -> Result<(), String> {
    crate::figures::fonts();
    let ports = data.ports();
    let columns = data.entries.len();
    let (width, height) = (520 * columns as u32 + 60, 900u32);
    let root = BitMapBackend::new(out, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let panels = root.split_evenly((2, columns));
    let f = &data.freq_hz;
    let (f_lo, f_hi) = (f[0], f[f.len() - 1]);
    // A dense log grid for the model line, so narrow peaks between data points show.
    let dense: Vec<f64> = (0..2000)
        .map(|k| f_lo * (f_hi / f_lo).powf(k as f64 / 1999.0))
        .collect();
    let model: Vec<_> = dense
        .iter()
        .map(|&x| bridge.admittance_s_per_kg(x))
        .collect();
    let errors = fit_errors(data, bridge);
    for (e, series) in data.entries.iter().enumerate() {
        let (i, j) = entry_position(ports, e);
        let name = data.entry_names()[e];
        let db = |y: nalgebra::Complex<f64>| 20.0 * y.norm().max(1e-300).log10();
        let data_db: Vec<(f64, f64)> = f.iter().zip(series).map(|(&x, &y)| (x, db(y))).collect();
        let model_db: Vec<(f64, f64)> = dense
            .iter()
            .zip(&model)
            .map(|(&x, y)| (x, db(y[i][j])))
            .collect();
        let finite = data_db
            .iter()
            .chain(&model_db)
            .map(|p| p.1)
            .filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        // Floor at 80 dB below the top: deep notches of the cross term would squash the rest.
        let lo = lo.max(hi - 80.0) - 3.0;
        let hi = hi + 3.0;
        let mut chart = ChartBuilder::on(&panels[e])
            .margin(12)
            .x_label_area_size(38)
            .y_label_area_size(62)
            .caption(
                format!(
                    "|Y_{name}| (error {:.2} dB RMS)",
                    errors[e].magnitude_db_rms
                ),
                ("sans-serif", 18),
            )
            .build_cartesian_2d((f_lo..f_hi).log_scale(), lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("frequency (Hz)")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_desc("magnitude (dB re 1 s/kg)")
            .draw()
            .map_err(err)?;
        chart
            .draw_series(
                data_db
                    .iter()
                    .filter(|p| p.1 >= lo)
                    .map(|&p| Circle::new(p, 2, BLUE.mix(0.5).filled())),
            )
            .map_err(err)?
            .label("data")
            .legend(|(x, y)| Circle::new((x + 10, y), 3, BLUE.filled()));
        chart
            .draw_series(LineSeries::new(
                model_db.iter().map(|&(x, v)| (x, v.max(lo))),
                RED.stroke_width(2),
            ))
            .map_err(err)?
            .label("passive modal fit")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(err)?;

        let phase = |y: nalgebra::Complex<f64>| y.arg().to_degrees();
        let mut chart = ChartBuilder::on(&panels[columns + e])
            .margin(12)
            .x_label_area_size(38)
            .y_label_area_size(62)
            .caption(
                format!(
                    "arg Y_{name} (error {:.1} deg RMS)",
                    errors[e].phase_deg_rms
                ),
                ("sans-serif", 18),
            )
            .build_cartesian_2d((f_lo..f_hi).log_scale(), -185.0..185.0)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("frequency (Hz)")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_desc("phase (degrees)")
            .draw()
            .map_err(err)?;
        chart
            .draw_series(
                f.iter()
                    .zip(series)
                    .map(|(&x, &y)| Circle::new((x, phase(y)), 2, BLUE.mix(0.5).filled())),
            )
            .map_err(err)?;
        // The model's phase as dots too: a line would draw a vertical stroke at every
        // wrap through +-180 degrees.
        chart
            .draw_series(
                dense
                    .iter()
                    .zip(&model)
                    .map(|(&x, y)| Circle::new((x, phase(y[i][j])), 1, RED.filled())),
            )
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}
