//! Figures as PNG (plotters, bitmap backend; text with egui's bundled Ubuntu font, so no
//! system fonts are needed).
//!
//! - `serafin-fig7`: paper A's Figure 7 reproduced: the elasto-plastic bow on the waveguide
//!   cello D string (147 Hz, Q 500, v_b 0.1 m/s, F_N 1.1 N, beta 0.1): string velocity at the
//!   bow point (Helmholtz motion) and the friction coefficient against relative velocity
//!   (the hysteresis loop).
//! - `serafin-modal`: paper A's modal scenario (the authors' script): a 50 g bow pushed
//!   into two 140/280 Hz modes: velocities, friction force, bristle state.

use crate::render::{render, RenderSettings};
use colophony::dsp::friction::bristle::BristleParams;
use colophony::dsp::friction::FrictionModel;
use colophony::dsp::rubbed::{RubbedPreset, RubbedScene};
use colophony::dsp::vocabulary::{BowControl, InstrumentKind};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::Once;

const WIDTH: u32 = 1400;
const HEIGHT: u32 = 560;

/// Registers the bundled font for plotters (once per process).
pub(crate) fn fonts() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        // Only fails for invalid font data; the bundled font is valid.
        let _ = register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// Draws the figure called `name` to `out`.
pub fn draw(name: &str, out: &Path) -> Result<String, String> {
    match name {
        "serafin-fig7" => serafin_fig7(out),
        "serafin-modal" => serafin_modal(out),
        "maestre-fig6" => maestre_fig6(out),
        "maestre-fig7" => maestre_fig7(out),
        "maestre-fig8" => maestre_fig8(out),
        other => Err(format!(
            "unknown figure '{other}': choose serafin-fig7, serafin-modal, maestre-fig6, maestre-fig7, maestre-fig8, bridge-fit or measured-window"
        )),
    }
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

fn range(x: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = x.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-12);
    (lo - pad, hi + pad)
}

/// Paper A, Figure 7.
pub fn serafin_fig7(out: &Path) -> Result<String, String> {
    fonts();
    let fs = 48_000.0;
    let settings = RenderSettings {
        instrument: InstrumentKind::Cello,
        note: 50,
        seconds: 2.6,
        bow: BowControl {
            velocity_m_per_s: 0.1,
            force_n: 1.1,
            position_beta: 0.1,
        },
        sample_rate_hz: fs,
        friction: FrictionModel::ElastoPlastic,
        bristle: BristleParams::waveguide_string(),
        // Paper A's string is purely transverse, bowed by a rigid point, tuned by its free
        // decay.
        torsion: false,
        bow_hair: false,
        intonation: false,
        ..RenderSettings::default()
    };
    let r = render(&settings).map_err(err)?;
    let start = (1.5 * fs) as usize;
    let shown = (4.0 * fs / 146.83) as usize; // four periods
    let t: Vec<f64> = (0..shown).map(|i| 1e3 * i as f64 / fs).collect();
    let v = &r.bow_point_velocity_m_per_s[start..start + shown];
    let root = BitMapBackend::new(out, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            "Paper A, Fig. 7: elasto-plastic bow on the cello D string (v_b 0.1 m/s, F_N 1.1 N, beta 0.1)",
            ("sans-serif", 22),
        )
        .map_err(err)?;
    let (left, right) = root.split_horizontally(WIDTH / 2);
    let (vlo, vhi) = range(v.iter().copied());
    let mut chart = ChartBuilder::on(&left)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .caption("String velocity at the bow", ("sans-serif", 18))
        .build_cartesian_2d(0.0..t[shown - 1], vlo..vhi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (ms)")
        .y_desc("velocity (m/s)")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            t.iter().copied().zip(v.iter().copied()),
            &BLUE,
        ))
        .map_err(err)?;

    // Hysteresis: friction coefficient F / F_N against relative velocity v_b - v_s, over
    // one second of steady bowing.
    let pts: Vec<(f64, f64)> = r.bow_point_velocity_m_per_s[start..start + fs as usize]
        .iter()
        .zip(&r.friction_force_n[start..start + fs as usize])
        .map(|(vs, f)| (0.1 - vs, f / 1.1))
        .collect();
    let (xlo, xhi) = range(pts.iter().map(|p| p.0));
    let (ylo, yhi) = range(pts.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(&right)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .caption(
            "Friction coefficient against relative velocity",
            ("sans-serif", 18),
        )
        .build_cartesian_2d(xlo..xhi, ylo.min(0.0)..yhi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("relative velocity v_b - v_s (m/s)")
        .y_desc("F / F_N")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), &RED.mix(0.6)))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(format!("wrote {}", out.display()))
}

/// Paper A's modal scenario.
pub fn serafin_modal(out: &Path) -> Result<String, String> {
    fonts();
    let fs = 44_100.0;
    let mut scene = RubbedScene::new(RubbedPreset::PaperModal, fs).map_err(err)?;
    let n = (0.25 * fs) as usize;
    let mut t = Vec::with_capacity(n);
    let (mut vr, mut vb, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        let frame = scene.tick(scene.preset_bow());
        t.push(1e3 * i as f64 / fs);
        vr.push(frame.contact.resonator_velocity_m_per_s);
        vb.push(frame.contact.exciter_velocity_m_per_s);
        f.push(frame.contact.friction_force_n);
    }
    let root = BitMapBackend::new(out, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            "Paper A, modal scenario: 50 g bow pushed to 0.5 m/s into 140/280 Hz modes (F_N 1 N)",
            ("sans-serif", 22),
        )
        .map_err(err)?;
    let (left, right) = root.split_horizontally(WIDTH / 2);
    let (lo, hi) = range(vr.iter().chain(&vb).copied());
    let mut chart = ChartBuilder::on(&left)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .caption(
            "Velocities: bow (green), resonator (blue)",
            ("sans-serif", 18),
        )
        .build_cartesian_2d(0.0..t[n - 1], lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (ms)")
        .y_desc("velocity (m/s)")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            t.iter().copied().zip(vb.iter().copied()),
            &GREEN,
        ))
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            t.iter().copied().zip(vr.iter().copied()),
            &BLUE,
        ))
        .map_err(err)?;
    let (lo, hi) = range(f.iter().copied());
    let mut chart = ChartBuilder::on(&right)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .caption("Friction force", ("sans-serif", 18))
        .build_cartesian_2d(0.0..t[n - 1], lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (ms)")
        .y_desc("force (N)")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            t.iter().copied().zip(f.iter().copied()),
            &RED,
        ))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(format!("wrote {}", out.display()))
}

/// Paper B, Figure 6: cello open C, v_b 0.15 m/s, beta 0.07, 300 N/m, 60 nodes over 1 cm,
/// two periods from [`crate::playing_space::SETTLE_S`] on.
pub fn maestre_fig6(out: &Path) -> Result<String, String> {
    const SETTLE_S: f64 = 1.5;
    use colophony::dsp::thermal::{
        HairParams, ThermalBowControl, ThermalParams, ThermalString, ThermalStringSpec,
    };
    fonts();
    let nodes = 60;
    let mut s = ThermalString::new(
        ThermalStringSpec::cello_c(),
        nodes,
        0.01,
        ThermalParams::default(),
        HairParams::default(),
    )?;
    let bow = ThermalBowControl {
        velocity_m_per_s: 0.15,
        force_n_per_m: 300.0,
        position_beta: 0.07,
    };
    let fs = s.internal_rate_hz();
    // The bow starts in a double-slip regime and settles into Helmholtz motion after about
    // a second (lab/tests/paper_b.rs): two periods of the steady motion from 1.5 s.
    for _ in 0..(SETTLE_S * fs) as usize {
        s.tick(bow);
    }
    let shown = (2.0 * fs / 65.41) as usize;
    let columns = 700usize;
    let every = (shown / columns).max(1);
    let (mut t, mut vs, mut ff, mut vh, mut fnn) = (vec![], vec![], vec![], vec![], vec![]);
    let mut slip_map: Vec<Vec<bool>> = Vec::new();
    let mut temp_map: Vec<Vec<f64>> = Vec::new();
    let mut loop_pts: Vec<(f64, f64, usize)> = Vec::new();
    for k in 0..shown {
        let f = s.tick(bow);
        let ms = 1e3 * k as f64 / fs;
        t.push(ms);
        vs.push(f.string_velocity_m_per_s);
        ff.push(f.friction_force_n);
        vh.push(f.hair_velocity_m_per_s);
        fnn.push(f.normal_force_n);
        if k % every == 0 {
            slip_map.push(s.slipping().collect::<Vec<_>>());
            temp_map.push(
                s.node_temperatures()
                    .iter()
                    .map(|t| f64::from(*t))
                    .collect(),
            );
            // Nut-side half of the contact: higher node indices are nearer the nut.
            for i in nodes / 2..nodes {
                let dv = f64::from(s.node_sliding_velocities()[i]);
                let f = f64::from(s.node_forces()[i]) / (300.0 * 0.01 / nodes as f64);
                loop_pts.push((dv, f, i));
            }
        }
    }
    let (w, h) = (1400u32, 1700u32);
    let root = BitMapBackend::new(out, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            "Paper B, Fig. 6: cello open C, v_b 0.15 m/s, beta 0.07, 300 N/m, 60 nodes over 1 cm",
            ("sans-serif", 24),
        )
        .map_err(err)?;
    let panels = root.split_evenly((4, 2));
    let t_end = t[shown - 1];
    let line = |area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
                title: &str,
                unit: &str,
                y: &[f64],
                color: RGBColor|
     -> Result<(), String> {
        let (lo, hi) = range(y.iter().copied());
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .caption(title, ("sans-serif", 18))
            .build_cartesian_2d(0.0..t_end, lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (ms)")
            .y_desc(unit)
            .draw()
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(
                t.iter().copied().zip(y.iter().copied()),
                &color,
            ))
            .map_err(err)?;
        Ok(())
    };
    line(
        &panels[0],
        "String horizontal velocity (middle node)",
        "m/s",
        &vs,
        BLUE,
    )?;
    line(&panels[1], "Friction force (whole bow)", "N", &ff, RED)?;
    line(
        &panels[2],
        "Hair relative velocity (middle node)",
        "m/s",
        &vh,
        GREEN,
    )?;
    line(
        &panels[3],
        "Effective bow force (whole bow)",
        "N",
        &fnn,
        BLACK,
    )?;
    let cols = slip_map.len();
    let map = |area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
               title: &str,
               colour: &dyn Fn(usize, usize) -> RGBColor|
     -> Result<(), String> {
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .caption(title, ("sans-serif", 18))
            .build_cartesian_2d(0.0..t_end, 0.0..nodes as f64)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (ms)")
            .y_desc("node (bridge side at 0)")
            .disable_mesh()
            .draw()
            .map_err(err)?;
        let dt = t_end / cols as f64;
        chart
            .draw_series((0..cols).flat_map(|c| {
                (0..nodes).map(move |i| {
                    Rectangle::new(
                        [
                            (c as f64 * dt, i as f64),
                            ((c + 1) as f64 * dt, (i + 1) as f64),
                        ],
                        colour(c, i).filled(),
                    )
                })
            }))
            .map_err(err)?;
        Ok(())
    };
    map(
        &panels[4],
        "Friction map (slip: white, stick: black)",
        &|c, i| {
            if slip_map[c][i] {
                WHITE
            } else {
                BLACK
            }
        },
    )?;
    let tmax = temp_map.iter().flatten().cloned().fold(1e-9, f64::max);
    map(
        &panels[5],
        &format!("Temperature (0 to {tmax:.1} K above ambient)"),
        &|c, i| {
            let u = (temp_map[c][i] / tmax).clamp(0.0, 1.0);
            RGBColor(
                (255.0 * u) as u8,
                (80.0 * u) as u8,
                (255.0 * (1.0 - u)) as u8,
            )
        },
    )?;
    // Friction against sliding velocity, nut-side half (darker: towards the bow middle).
    let (xlo, xhi) = range(loop_pts.iter().map(|p| p.0));
    let (ylo, yhi) = range(loop_pts.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(&panels[6])
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .caption(
            "Friction coefficient against sliding velocity (nut-side half)",
            ("sans-serif", 18),
        )
        .build_cartesian_2d(xlo..xhi, ylo..yhi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("sliding velocity v_s - (v_b + v_h) (m/s)")
        .y_desc("F / F_b")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(loop_pts.iter().map(|(x, y, i)| {
            let shade = (200.0 * (*i - nodes / 2) as f64 / (nodes / 2) as f64) as u8;
            Circle::new((*x, *y), 1, RGBColor(shade, shade, shade).filled())
        }))
        .map_err(err)?;
    // Temperature profile across the grid at the end.
    let grid: Vec<f64> = s.temperature_grid().iter().map(|t| f64::from(*t)).collect();
    let (lo, hi) = range(grid.iter().copied());
    let mut chart = ChartBuilder::on(&panels[7])
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .caption(
            "Temperature across the grid (bow plus 2 mm margins), last sample",
            ("sans-serif", 18),
        )
        .build_cartesian_2d(0.0..grid.len() as f64, lo.min(0.0)..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("grid point")
        .y_desc("K")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            grid.iter().enumerate().map(|(i, v)| (i as f64, *v)),
            &RED,
        ))
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(format!("wrote {}", out.display()))
}

/// One value per node, as f64.
fn widen(x: &[colophony::dsp::thermal::NodeReal]) -> Vec<f64> {
    x.iter().map(|v| f64::from(*v)).collect()
}

/// A white PNG of `size` titled `title`, split into `rows` panels stacked down.
fn titled_rows<'a>(
    out: &'a Path,
    size: (u32, u32),
    title: &str,
    rows: usize,
) -> Result<Vec<DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>>, String> {
    let root = BitMapBackend::new(out, size).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    Ok(root.split_evenly((rows, 1)))
}

/// Per-node values over time: `rows[k][i]` is node `i` at column `k`.
struct NodeMovie {
    rows: Vec<Vec<f64>>,
    t_end_ms: f64,
}

/// Runs paper B's Figure 6 bow (cello open C, v_b 0.15 m/s, beta 0.07, 300 N/m, 60 nodes
/// over 1 cm) with `hair`, settles for 1.5 s, then records two periods of each per-node
/// quantity `take` returns (one value per node), and the total normal force.
fn fig6_movie(
    hair: colophony::dsp::thermal::HairParams,
    takes: &[&dyn Fn(&colophony::dsp::thermal::ThermalString) -> Vec<f64>],
) -> Result<(Vec<NodeMovie>, Vec<(f64, f64)>), String> {
    use colophony::dsp::thermal::{
        ThermalBowControl, ThermalParams, ThermalString, ThermalStringSpec,
    };
    let mut s = ThermalString::new(
        ThermalStringSpec::cello_c(),
        60,
        0.01,
        ThermalParams::default(),
        hair,
    )?;
    let bow = ThermalBowControl {
        velocity_m_per_s: 0.15,
        force_n_per_m: 300.0,
        position_beta: 0.07,
    };
    let fs = s.internal_rate_hz();
    for _ in 0..(1.5 * fs) as usize {
        s.tick(bow);
    }
    let shown = (2.0 * fs / 65.41) as usize;
    let every = (shown / 600).max(1);
    let mut movies: Vec<NodeMovie> = takes
        .iter()
        .map(|_| NodeMovie {
            rows: Vec::new(),
            t_end_ms: 1e3 * shown as f64 / fs,
        })
        .collect();
    let mut total = Vec::new();
    for k in 0..shown {
        let f = s.tick(bow);
        total.push((1e3 * k as f64 / fs, f.normal_force_n));
        if k % every == 0 {
            for (movie, take) in movies.iter_mut().zip(takes) {
                movie.rows.push(take(&s));
            }
        }
    }
    Ok((movies, total))
}

/// A node-time map with the nut side at the top: blue negative, white zero, red
/// positive, scaled to the largest magnitude.
fn node_map(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    title: &str,
    movie: &NodeMovie,
) -> Result<(), String> {
    let nodes = movie.rows.first().map_or(1, |r| r.len());
    let peak = movie
        .rows
        .iter()
        .flatten()
        .fold(1e-30, |m: f64, v| m.max(v.abs()));
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .caption(
            format!("{title} (colour scale +-{peak:.2e})"),
            ("sans-serif", 18),
        )
        .build_cartesian_2d(0.0..movie.t_end_ms, 0.0..nodes as f64)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (ms)")
        .y_desc("node (nut side at the top)")
        .disable_mesh()
        .draw()
        .map_err(err)?;
    let cols = movie.rows.len();
    let dt = movie.t_end_ms / cols as f64;
    chart
        .draw_series(movie.rows.iter().enumerate().flat_map(|(c, row)| {
            row.iter().enumerate().map(move |(i, v)| {
                let u = (v / peak).clamp(-1.0, 1.0);
                let colour = if u >= 0.0 {
                    RGBColor(255, (255.0 * (1.0 - u)) as u8, (255.0 * (1.0 - u)) as u8)
                } else {
                    RGBColor((255.0 * (1.0 + u)) as u8, (255.0 * (1.0 + u)) as u8, 255)
                };
                // Higher node indices are nearer the nut: drawn at the top.
                Rectangle::new(
                    [
                        (c as f64 * dt, i as f64),
                        ((c + 1) as f64 * dt, (i + 1) as f64),
                    ],
                    colour.filled(),
                )
            })
        }))
        .map_err(err)?;
    Ok(())
}

/// Paper B, Figure 7: the friction force and the hair's relative (sliding) velocity over
/// the bow's width and two periods of the Figure 6 motion, seen from the nut side.
pub fn maestre_fig7(out: &Path) -> Result<String, String> {
    use colophony::dsp::thermal::{HairParams, ThermalString};
    fonts();
    let force = |s: &ThermalString| widen(s.node_forces());
    let sliding = |s: &ThermalString| widen(s.node_sliding_velocities());
    let (movies, _) = fig6_movie(HairParams::default(), &[&force, &sliding])?;
    let panels = titled_rows(
        out,
        (1400, 900),
        "Paper B, Fig. 7: cello open C, Fig. 6 bow; friction force and hair relative velocity per node, from the nut side",
        2,
    )?;
    node_map(&panels[0], "Friction force per node (N)", &movies[0])?;
    node_map(
        &panels[1],
        "Sliding velocity of string over hair per node (m/s)",
        &movies[1],
    )?;
    panels[0].present().map_err(err)?;
    Ok(format!("wrote {}", out.display()))
}

/// Paper B, Figure 8: the normal (vertical) force per node over two periods of the
/// Figure 6 motion, with the default hair and with ten times its vertical damping, and
/// the total normal force of both.
pub fn maestre_fig8(out: &Path) -> Result<String, String> {
    use colophony::dsp::thermal::{HairParams, ThermalString};
    fonts();
    let normal = |s: &ThermalString| widen(s.node_normal_forces());
    let default_hair = HairParams::default();
    let damped = HairParams {
        vertical_c_kg_per_s_per_m: 10.0 * default_hair.vertical_c_kg_per_s_per_m,
        ..default_hair
    };
    let (mut a, total_a) = fig6_movie(default_hair, &[&normal])?;
    let (mut b, total_b) = fig6_movie(damped, &[&normal])?;
    // The bow's static share (about 0.05 N a node) would hide the motion: the maps show
    // each node's departure from its own mean over the two periods.
    for movie in [&mut a[0], &mut b[0]] {
        let nodes = movie.rows.first().map_or(0, |r| r.len());
        let cols = movie.rows.len().max(1) as f64;
        for i in 0..nodes {
            let mean = movie.rows.iter().map(|r| r[i]).sum::<f64>() / cols;
            for r in &mut movie.rows {
                r[i] -= mean;
            }
        }
    }
    let panels = titled_rows(
        out,
        (1400, 1200),
        "Paper B, Fig. 8: normal force per node, Fig. 6 bow; default hair and ten times its vertical damping",
        3,
    )?;
    node_map(
        &panels[0],
        "Normal force per node minus its mean, default hair (N)",
        &a[0],
    )?;
    node_map(
        &panels[1],
        "Normal force per node minus its mean, 10x vertical hair damping (N)",
        &b[0],
    )?;
    let (lo, hi) = range(total_a.iter().chain(&total_b).map(|p| p.1));
    let t_end = total_a.last().map_or(1.0, |p| p.0);
    let mut chart = ChartBuilder::on(&panels[2])
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .caption(
            "Total normal force (black default, red 10x damping)",
            ("sans-serif", 18),
        )
        .build_cartesian_2d(0.0..t_end, lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (ms)")
        .y_desc("N")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(total_a.iter().copied(), &BLACK))
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(total_b.iter().copied(), &RED))
        .map_err(err)?;
    panels[0].present().map_err(err)?;
    Ok(format!("wrote {}", out.display()))
}
