//! The fit: pole frequencies and bandwidths by bounded nonlinear least squares (variable
//! projection, Levenberg-Marquardt), then every gain matrix by a convex fit with a PSD
//! constraint per mode (clarabel, second-order cones), so the result is passive.
//!
//! Error measure: every entry's residual is weighted by `1 / |Y_e(f)|` (floored at 1e-3 of
//! the largest magnitude in the file), so the fit minimises relative error, close to the
//! dB and degree errors it reports, and troughs count as much as peaks.

use super::bridge::{mode_response, nearest_psd, Admittance, BridgeMode, BridgeModes, C64};
use super::data::{entry_position, AdmittanceData};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus,
    SupportedConeT,
};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use std::f64::consts::TAU;

/// Each mode needs at least this many frequency points (two flanks and a peak fix its
/// frequency, bandwidth and gain), so `modes <= points / 4`.
pub const POINTS_PER_MODE: usize = 4;
/// Bandwidths stay within `freq / Q_MAX ..= freq / Q_MIN`: from barely resonant (Q 0.5,
/// critically damped) to far sharper than any wooden body mode.
const Q_MIN: f64 = 0.5;
const Q_MAX: f64 = 1e4;
/// Weight floor, relative to the largest magnitude in the file: points more than 60 dB
/// down (noise floor, a deep notch of the cross term) count no more than that.
const WEIGHT_FLOOR: f64 = 1e-3;
/// A local maximum of the peak indicator is a mode candidate if it stands this factor
/// above its higher saddle; 1 % noise makes bumps of a few per cent.
const MIN_PROMINENCE: f64 = 1.1;
/// Floor of the peak indicator relative to the magnitude.
const INDICATOR_FLOOR: f64 = 0.1;
/// Bandwidth guess, as Q, where no half-power width can be read off the data.
const DEFAULT_Q: f64 = 30.0;

/// The fit error of one entry over all frequency points.
#[derive(Clone, Debug, PartialEq)]
pub struct EntryError {
    /// `y`, or `hh`, `hv`, `vv`.
    pub entry: &'static str,
    /// RMS of `20 log10(|model| / |data|)` (dB).
    pub magnitude_db_rms: f64,
    /// RMS of the phase difference, wrapped to +-180 degrees (degrees).
    pub phase_deg_rms: f64,
}

/// A fitted bridge.
#[derive(Clone, Debug, PartialEq)]
pub struct BridgeFit {
    /// The modes, by increasing frequency; every gain PSD.
    pub bridge: BridgeModes,
    /// 1 for a 1x1 fit (gains `[[g, 0], [0, 0]]`), 2 for a 2x2 one.
    pub ports: usize,
    /// Fit error per entry.
    pub errors: Vec<EntryError>,
}

/// Fits `modes` passive modes to the data.
pub fn fit_bridge(data: &AdmittanceData, modes: usize) -> Result<BridgeFit, String> {
    let points = data.freq_hz.len();
    if modes == 0 {
        return Err("the number of modes must be at least 1".into());
    }
    if modes > points / POINTS_PER_MODE {
        return Err(format!(
            "the data cannot support {modes} modes: each needs {POINTS_PER_MODE} frequency \
             points and there are {points}, so at most {} modes",
            points / POINTS_PER_MODE
        ));
    }
    let spectrum = Spectrum::new(data)?;
    let mut poles = initial_poles(data, modes);
    let mut theta = spectrum.refine(&poles)?;
    while poles.len() < modes {
        poles = spectrum.poles(&theta);
        poles.push(spectrum.residual_peak(&theta)?);
        theta = spectrum.refine(&poles)?;
    }
    let poles = spectrum.poles(&theta);
    let gains = spectrum.passive_gains(&poles)?;
    let mut fitted: Vec<BridgeMode> = poles
        .iter()
        .zip(gains)
        .map(|(p, gain)| BridgeMode {
            freq_hz: p.freq_hz,
            bandwidth_hz: p.bandwidth_hz,
            gain,
        })
        .collect();
    fitted.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let bridge = BridgeModes { modes: fitted };
    let errors = fit_errors(data, &bridge);
    Ok(BridgeFit {
        bridge,
        ports: data.ports(),
        errors,
    })
}

/// The error of `bridge` against `data`, per entry. Points where the data or the model
/// is exactly zero (no level to compare) are skipped.
pub fn fit_errors(data: &AdmittanceData, bridge: &BridgeModes) -> Vec<EntryError> {
    let ports = data.ports();
    let model: Vec<[[C64; 2]; 2]> = data
        .freq_hz
        .iter()
        .map(|&f| bridge.admittance_s_per_kg(f))
        .collect();
    data.entries
        .iter()
        .enumerate()
        .map(|(e, series)| {
            let (i, j) = entry_position(ports, e);
            let (mut db2, mut deg2, mut n) = (0.0, 0.0, 0usize);
            for (y, m) in series.iter().zip(&model) {
                let ratio = m[i][j] / y;
                if y.norm() > 0.0 && ratio.norm() > 0.0 && ratio.is_finite() {
                    db2 += (20.0 * ratio.norm().log10()).powi(2);
                    deg2 += ratio.arg().to_degrees().powi(2);
                    n += 1;
                }
            }
            let n = n.max(1) as f64;
            EntryError {
                entry: data.entry_names()[e],
                magnitude_db_rms: (db2 / n).sqrt(),
                phase_deg_rms: (deg2 / n).sqrt(),
            }
        })
        .collect()
}

/// A pole pair: frequency and half-power bandwidth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pole {
    pub freq_hz: f64,
    pub bandwidth_hz: f64,
}

/// Mode candidates by peak picking on `sum of Re Y_ii` (positive for a passive bridge,
/// a Lorentzian-like bump at each mode), most prominent first, at most `modes`.
/// Bandwidths from the half-power width where the bump shows one.
pub(crate) fn initial_poles(data: &AdmittanceData, modes: usize) -> Vec<Pole> {
    let ports = data.ports();
    let n = data.freq_hz.len();
    let diagonal: Vec<usize> = (0..data.entries.len())
        .filter(|&e| {
            let (i, j) = entry_position(ports, e);
            i == j
        })
        .collect();
    // Off resonance Re Y is a small part of |Y| and relative noise swamps it: floor the
    // indicator at a tenth of the magnitude there, so noise makes no peaks.
    let p: Vec<f64> = (0..n)
        .map(|k| {
            let re: f64 = diagonal.iter().map(|&e| data.entries[e][k].re).sum();
            let magnitude: f64 = diagonal.iter().map(|&e| data.entries[e][k].norm()).sum();
            re.max(INDICATOR_FLOOR * magnitude).max(f64::MIN_POSITIVE)
        })
        .collect();
    let mut candidates: Vec<(f64, usize)> = Vec::new();
    for k in 1..n.saturating_sub(1) {
        if !(p[k] > p[k - 1] && p[k] >= p[k + 1]) {
            continue;
        }
        // The saddle on each side: the lowest point before the data rises above p[k].
        let saddle = |range: &mut dyn Iterator<Item = usize>| {
            let mut low = p[k];
            for j in range {
                if p[j] > p[k] {
                    break;
                }
                low = low.min(p[j]);
            }
            low
        };
        let left = saddle(&mut (0..k).rev());
        let right = saddle(&mut (k + 1..n));
        let prominence = p[k] / left.max(right);
        if prominence > MIN_PROMINENCE {
            candidates.push((prominence, k));
        }
    }
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    if candidates.is_empty() {
        let k = (0..n).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap_or(0);
        candidates.push((1.0, k.clamp(1, n.saturating_sub(2))));
    }
    candidates
        .iter()
        .take(modes)
        .map(|&(_, k)| {
            let f = data.freq_hz[k];
            let half = 0.5 * p[k];
            // Walk down each flank to the half-power point (linear interpolation); give up
            // where the flank rises again before that.
            let mut right = None;
            for j in k + 1..n {
                if p[j] > p[j - 1] {
                    break;
                }
                if p[j] <= half {
                    let t = (p[j - 1] - half) / (p[j - 1] - p[j]);
                    right = Some(data.freq_hz[j - 1] + t * (data.freq_hz[j] - data.freq_hz[j - 1]));
                    break;
                }
            }
            let mut left = None;
            for j in (0..k).rev() {
                if p[j] > p[j + 1] {
                    break;
                }
                if p[j] <= half {
                    let t = (p[j + 1] - half) / (p[j + 1] - p[j]);
                    left = Some(data.freq_hz[j + 1] - t * (data.freq_hz[j + 1] - data.freq_hz[j]));
                    break;
                }
            }
            let width = match (left, right) {
                (Some(l), Some(r)) => r - l,
                (Some(l), None) => 2.0 * (f - l),
                (None, Some(r)) => 2.0 * (r - f),
                (None, None) => f / DEFAULT_Q,
            };
            Pole {
                freq_hz: f,
                bandwidth_hz: width.clamp(f / 1e3, f / 2.0),
            }
        })
        .collect()
}

/// The data prepared for the fit: angular frequencies, weights and weighted targets.
struct Spectrum {
    omega: Vec<f64>,
    /// `weights[e][k]`: `1 / max(|Y_e(f_k)|, floor)`.
    weights: Vec<Vec<f64>>,
    /// Per entry, `[w Re y; w Im y]` (length 2N).
    targets: Vec<DVector<f64>>,
    freq_hz: Vec<f64>,
    /// Bounds of `ln f`: the data band.
    log_f: (f64, f64),
    /// Bounds of `ln (b / f)`.
    log_q: (f64, f64),
    ports: usize,
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

fn logit(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

/// The nonlinear parameters for one evaluation, with the chain-rule factors.
struct PoleParams {
    omega0: Vec<f64>,
    beta: Vec<f64>,
    /// `d omega0 / du`.
    d_omega0_du: Vec<f64>,
    /// `d beta / dv` (beta depends on v only through q).
    d_beta_dv: Vec<f64>,
    /// `q = b / f = beta / omega0`.
    q: Vec<f64>,
}

/// One evaluation of the projected problem.
struct Evaluation {
    residuals: DVector<f64>,
    /// `basis[m][k]`: mode m's unit response at point k.
    basis: Vec<Vec<C64>>,
    /// Per entry: the orthonormal range basis of the weighted design matrix and the
    /// unconstrained least-squares gains.
    projections: Vec<(DMatrix<f64>, DVector<f64>)>,
}

impl Spectrum {
    fn new(data: &AdmittanceData) -> Result<Self, String> {
        let largest = data
            .entries
            .iter()
            .flatten()
            .fold(0.0f64, |m, y| m.max(y.norm()));
        // Finite data (the CSV reader refuses anything else), so only zero is left.
        if largest == 0.0 {
            return Err("the admittance is zero at every frequency".into());
        }
        let floor = WEIGHT_FLOOR * largest;
        let weights: Vec<Vec<f64>> = data
            .entries
            .iter()
            .map(|s| s.iter().map(|y| 1.0 / y.norm().max(floor)).collect())
            .collect();
        let targets = data
            .entries
            .iter()
            .zip(&weights)
            .map(|(s, w)| {
                let n = s.len();
                DVector::from_fn(2 * n, |r, _| {
                    if r < n {
                        w[r] * s[r].re
                    } else {
                        w[r - n] * s[r - n].im
                    }
                })
            })
            .collect();
        let f = &data.freq_hz;
        Ok(Spectrum {
            omega: f.iter().map(|f| TAU * f).collect(),
            weights,
            targets,
            freq_hz: f.clone(),
            log_f: (f[0].ln(), f[f.len() - 1].ln()),
            log_q: ((1.0 / Q_MAX).ln(), (1.0 / Q_MIN).ln()),
            ports: data.ports(),
        })
    }

    fn points(&self) -> usize {
        self.omega.len()
    }

    /// `theta = [u_1..u_M, v_1..v_M]` with `ln f = lo + (hi - lo) sigmoid(u)` and
    /// `ln (b / f) = lo + (hi - lo) sigmoid(v)`: frequencies inside the band, bandwidths
    /// positive, whatever the optimiser tries.
    fn params(&self, poles: &[Pole]) -> DVector<f64> {
        let m = poles.len();
        let squeeze =
            |x: f64, (lo, hi): (f64, f64)| logit(((x - lo) / (hi - lo)).clamp(1e-6, 1.0 - 1e-6));
        DVector::from_fn(2 * m, |r, _| {
            if r < m {
                squeeze(poles[r].freq_hz.ln(), self.log_f)
            } else {
                let p = poles[r - m];
                squeeze((p.bandwidth_hz / p.freq_hz).ln(), self.log_q)
            }
        })
    }

    fn pole_params(&self, theta: &DVector<f64>) -> PoleParams {
        let m = theta.len() / 2;
        let (f0, f1) = self.log_f;
        let (q0, q1) = self.log_q;
        let mut p = PoleParams {
            omega0: Vec::with_capacity(m),
            beta: Vec::with_capacity(m),
            d_omega0_du: Vec::with_capacity(m),
            d_beta_dv: Vec::with_capacity(m),
            q: Vec::with_capacity(m),
        };
        for i in 0..m {
            let su = sigmoid(theta[i]);
            let sv = sigmoid(theta[m + i]);
            let omega0 = TAU * (f0 + (f1 - f0) * su).exp();
            let q = (q0 + (q1 - q0) * sv).exp();
            p.omega0.push(omega0);
            p.beta.push(omega0 * q);
            p.d_omega0_du.push(omega0 * (f1 - f0) * su * (1.0 - su));
            p.d_beta_dv.push(omega0 * q * (q1 - q0) * sv * (1.0 - sv));
            p.q.push(q);
        }
        p
    }

    fn poles(&self, theta: &DVector<f64>) -> Vec<Pole> {
        let p = self.pole_params(theta);
        (0..p.omega0.len())
            .map(|i| Pole {
                freq_hz: p.omega0[i] / TAU,
                bandwidth_hz: p.beta[i] / TAU,
            })
            .collect()
    }

    /// The weighted real design matrix of entry `e`: column m is `[w Re h_m; w Im h_m]`.
    fn design(&self, basis: &[Vec<C64>], e: usize) -> DMatrix<f64> {
        let n = self.points();
        let w = &self.weights[e];
        DMatrix::from_fn(2 * n, basis.len(), |r, m| {
            if r < n {
                w[r] * basis[m][r].re
            } else {
                w[r - n] * basis[m][r - n].im
            }
        })
    }

    fn basis(&self, p: &PoleParams) -> Vec<Vec<C64>> {
        (0..p.omega0.len())
            .map(|m| {
                self.freq_hz
                    .iter()
                    .map(|&f| mode_response(p.omega0[m] / TAU, p.beta[m] / TAU, f))
                    .collect()
            })
            .collect()
    }

    /// Variable projection: the best unconstrained gains for these poles (SVD least
    /// squares, rank-revealing so coincident poles do not blow up) and the residuals.
    fn evaluate(&self, theta: &DVector<f64>) -> Option<Evaluation> {
        let p = self.pole_params(theta);
        let basis = self.basis(&p);
        let n = self.points();
        let mut residuals = DVector::zeros(2 * n * self.targets.len());
        let mut projections = Vec::with_capacity(self.targets.len());
        for (e, y) in self.targets.iter().enumerate() {
            let a = self.design(&basis, e);
            let svd = a.svd(true, true);
            let (u, v_t) = (svd.u?, svd.v_t?);
            let s = &svd.singular_values;
            let largest = s.max();
            // Directions 1e-10 below the largest are numerically absent.
            let kept: Vec<usize> = (0..s.len()).filter(|&i| s[i] > 1e-10 * largest).collect();
            let u_r = DMatrix::from_fn(2 * n, kept.len(), |r, c| u[(r, kept[c])]);
            let uy = u_r.transpose() * y;
            let mut gains = DVector::zeros(basis.len());
            for (c, &i) in kept.iter().enumerate() {
                gains += v_t.row(i).transpose() * (uy[c] / s[i]);
            }
            let r = &u_r * &uy - y;
            residuals.rows_mut(2 * n * e, 2 * n).copy_from(&r);
            projections.push((u_r, gains));
        }
        residuals
            .iter()
            .all(|r| r.is_finite())
            .then_some(Evaluation {
                residuals,
                basis,
                projections,
            })
    }

    /// Kaufman's approximation of the projected Jacobian: column k is
    /// `P_perp (dA/dtheta_k) c` (the term that vanishes with the residual is dropped).
    fn jacobian(&self, theta: &DVector<f64>, ev: &Evaluation) -> DMatrix<f64> {
        let p = self.pole_params(theta);
        let m = p.omega0.len();
        let n = self.points();
        // dh_m/du and dh_m/dv at every point.
        let mut dh_du = vec![vec![C64::new(0.0, 0.0); n]; m];
        let mut dh_dv = vec![vec![C64::new(0.0, 0.0); n]; m];
        for i in 0..m {
            for k in 0..n {
                let w = self.omega[k];
                let jw = C64::new(0.0, w);
                let d = C64::new(p.omega0[i] * p.omega0[i] - w * w, w * p.beta[i]);
                let h_over_d = ev.basis[i][k] / d;
                // dh/domega0 = -h 2 omega0 / D, dh/dbeta = -h j omega / D, beta = q omega0.
                dh_du[i][k] = -h_over_d * (jw * p.q[i] + 2.0 * p.omega0[i]) * p.d_omega0_du[i];
                dh_dv[i][k] = -h_over_d * jw * p.d_beta_dv[i];
            }
        }
        let mut jac = DMatrix::zeros(2 * n * self.targets.len(), 2 * m);
        for (e, (u_r, gains)) in ev.projections.iter().enumerate() {
            let w = &self.weights[e];
            let d = DMatrix::from_fn(2 * n, 2 * m, |r, c| {
                let (series, mode) = if c < m {
                    (&dh_du[c], c)
                } else {
                    (&dh_dv[c - m], c - m)
                };
                let value = if r < n {
                    w[r] * series[r].re
                } else {
                    w[r - n] * series[r - n].im
                };
                value * gains[mode]
            });
            let projected = &d - u_r * (u_r.transpose() * &d);
            jac.rows_mut(2 * n * e, 2 * n).copy_from(&projected);
        }
        jac
    }

    /// Levenberg-Marquardt from these poles; returns the parameters.
    fn refine(&self, poles: &[Pole]) -> Result<DVector<f64>, String> {
        let theta = self.params(poles);
        let state = self.evaluate(&theta);
        let problem = Projected {
            spectrum: self,
            theta,
            state,
        };
        if problem.state.is_none() {
            return Err("the initial poles give a non-finite residual".into());
        }
        // Stop when a step lowers the cost by less than 1e-7 of itself (or moves the
        // parameters by less than 1e-8): far below what 1 % data noise can resolve, and
        // it stops surplus modes from creeping for thousands of steps. Patience bounds the
        // work on hard data.
        let (problem, _report) = LevenbergMarquardt::new()
            .with_ftol(1e-7)
            .with_xtol(1e-8)
            .with_gtol(1e-8)
            .with_patience(20)
            .minimize(problem);
        if problem.state.is_none() {
            return Err("the pole fit diverged to a non-finite residual".into());
        }
        Ok(problem.theta)
    }

    /// Where the current fit is worst: the residual energy summed over entries, smoothed
    /// over three points, at its maximum. A new pole goes there.
    fn residual_peak(&self, theta: &DVector<f64>) -> Result<Pole, String> {
        let ev = self
            .evaluate(theta)
            .ok_or("the pole fit gives a non-finite residual")?;
        let n = self.points();
        let energy: Vec<f64> = (0..n)
            .map(|k| {
                (0..self.targets.len())
                    .map(|e| {
                        let base = 2 * n * e;
                        ev.residuals[base + k].powi(2) + ev.residuals[base + n + k].powi(2)
                    })
                    .sum()
            })
            .collect();
        let smooth = |k: usize| {
            energy[k.saturating_sub(1)..(k + 2).min(n)]
                .iter()
                .sum::<f64>()
        };
        let k = (1..n - 1)
            .max_by(|&a, &b| smooth(a).total_cmp(&smooth(b)))
            .unwrap_or(n / 2);
        let f = self.freq_hz[k];
        Ok(Pole {
            freq_hz: f,
            bandwidth_hz: f / DEFAULT_Q,
        })
    }

    /// All gains at once for fixed poles: minimise the weighted squared error over every
    /// entry subject to each mode's gain being PSD. For 2x2, `[[a, b], [b, c]]` is PSD iff
    /// `(a + c, a - c, 2b)` lies in the second-order cone; for 1x1, iff `g >= 0`.
    fn passive_gains(&self, poles: &[Pole]) -> Result<Vec<[[f64; 2]; 2]>, String> {
        let m = poles.len();
        let basis: Vec<Vec<C64>> = poles
            .iter()
            .map(|p| {
                self.freq_hz
                    .iter()
                    .map(|&f| mode_response(p.freq_hz, p.bandwidth_hz, f))
                    .collect()
            })
            .collect();
        let entries = self.targets.len();
        let (grams, projections): (Vec<DMatrix<f64>>, Vec<DVector<f64>>) = (0..entries)
            .map(|e| {
                let a_t = self.design(&basis, e).transpose();
                (&a_t * a_t.transpose(), a_t * &self.targets[e])
            })
            .unzip();
        let total: f64 = self.targets.iter().map(|y| y.norm_squared()).sum();
        // One scale per mode (shared by its entries, so the cone is unchanged) makes the
        // columns of unit size; dividing by the data energy makes the cost of order one.
        let scale: Vec<f64> = (0..m)
            .map(|i| {
                let mean = grams.iter().map(|g| g[(i, i)]).sum::<f64>() / entries as f64;
                if mean > 0.0 {
                    1.0 / mean.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        let var = |mode: usize, e: usize| mode * entries + e;
        let n_var = m * entries;
        let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
        let mut q = vec![0.0; n_var];
        for e in 0..entries {
            for i in 0..m {
                q[var(i, e)] = -scale[i] * projections[e][i] / total;
                for j in i..m {
                    rows.push(var(i, e));
                    cols.push(var(j, e));
                    vals.push(scale[i] * scale[j] * grams[e][(i, j)] / total);
                }
            }
        }
        let p_mat = CscMatrix::new_from_triplets(n_var, n_var, rows, cols, vals);
        let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
        let cones: Vec<SupportedConeT<f64>> = if entries == 1 {
            for i in 0..m {
                rows.push(i);
                cols.push(i);
                vals.push(-1.0);
            }
            vec![NonnegativeConeT(m)]
        } else {
            // s = -A x with s = (a + c, a - c, 2b) per mode.
            for i in 0..m {
                let (a, b, c) = (var(i, 0), var(i, 1), var(i, 2));
                for (row, col, val) in [
                    (0, a, -1.0),
                    (0, c, -1.0),
                    (1, a, -1.0),
                    (1, c, 1.0),
                    (2, b, -2.0),
                ] {
                    rows.push(3 * i + row);
                    cols.push(col);
                    vals.push(val);
                }
            }
            vec![SecondOrderConeT(3); m]
        };
        let n_con = if entries == 1 { m } else { 3 * m };
        let a_mat = CscMatrix::new_from_triplets(n_con, n_var, rows, cols, vals);
        let b = vec![0.0; n_con];
        let settings = DefaultSettings {
            verbose: false,
            ..DefaultSettings::default()
        };
        let mut solver = DefaultSolver::new(&p_mat, &q, &a_mat, &b, &cones, settings)
            .map_err(|e| format!("gain fit: {e:?}"))?;
        solver.solve();
        let status = solver.solution.status;
        if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
            return Err(format!("the PSD gain fit failed: {status:?}"));
        }
        let x = &solver.solution.x;
        Ok((0..m)
            .map(|i| {
                let g = |e: usize| scale[i] * x[var(i, e)];
                if self.ports == 1 {
                    [[g(0).max(0.0), 0.0], [0.0, 0.0]]
                } else {
                    // Interior-point solutions sit on the cone up to the solver tolerance;
                    // the projection makes them PSD to rounding.
                    nearest_psd(g(0), g(1), g(2))
                }
            })
            .collect())
    }
}

/// The projected problem as Levenberg-Marquardt sees it.
struct Projected<'a> {
    spectrum: &'a Spectrum,
    theta: DVector<f64>,
    state: Option<Evaluation>,
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Projected<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.theta.copy_from(x);
        self.state = self.spectrum.evaluate(x);
    }

    fn params(&self) -> DVector<f64> {
        self.theta.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.state.as_ref().map(|s| s.residuals.clone())
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        self.state
            .as_ref()
            .map(|s| self.spectrum.jacobian(&self.theta, s))
    }
}
