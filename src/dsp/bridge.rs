//! The bridge of paper B: a passive 2x2 driving-point admittance in modal form,
//! `Y(z) = sum_m H_m(z) R_m` with `H_m(z) = (1 - z^-2) / ((1 - p_m z^-1)(1 - p_m* z^-1))`
//! and every `R_m` symmetric positive semidefinite (eq. 11). Each `H_m` is positive real
//! for `|p_m| < 1`, so `Re Y(e^jw)` is PSD at every frequency: passive by construction.
//!
//! Data come as the continuous-time modes `colophony fit-bridge` writes,
//! `Y(s) = sum_m G_m s / (s^2 + 2 pi b_m s + w_m^2)` (`b_m` the half-power bandwidth), and
//! are mapped by the bilinear transform with `w_m` pre-warped (so each peak stays at its
//! frequency): with `K = 2 fs`, `D = K^2 + 2 pi b K + w^2`, the section is exactly
//! `H_m(z) R_m` with `R_m = G_m K / D`, `a1 = 2 (w^2 - K^2) / D`, `a2 = (K^2 - 2 pi b K + w^2) / D`.
//! Modes at or above Nyquist are dropped.
//!
//! [`solve_junction`] couples several strings (both polarisations) through it: every
//! string end moves with the bridge, `v_B = Y F_total`. `H_m` passes its input straight
//! through (`b0 = 1`), so the loop is delay free; it is solved exactly each sample as a
//! 2x2 linear system: with `v_in,i` the wave arriving on string `i` (impedance `Z_i`),
//! `F_i = 2 Z_i v_in,i - Z_i v_B` and `v_B = R_0 F_total + v_hist` give
//! `(I + R_0 sum Z_i) v_B = R_0 sum 2 Z_i v_in,i + v_hist`, `R_0 = sum R_m`. The wave leaving
//! string `i` is `v_B - v_in,i`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `f_m`, `b_m` | mode frequency, half-power bandwidth | Hz |
//! | `R_m` | modal gain (`[[hh, hv], [hv, vv]]`) | s/kg |
//! | `v_B` | bridge velocity `[h, v]` | m/s |
//!
//! ```
//! use colophony::dsp::bridge::{BridgeMode, ModalBridge};
//! // One mode coupling the two planes (a PSD gain): the bridge's admittance has a PSD
//! // real part at every frequency, so it never gives energy back to the strings.
//! let mode = BridgeMode { freq_hz: 2200.0, bandwidth_hz: 150.0, gain: [[2.0, 0.5], [0.5, 1.0]] };
//! let bridge = ModalBridge::new(&[mode], 48_000.0).unwrap();
//! for f in [100.0, 2200.0, 10_000.0] {
//!     let y = bridge.response(f);
//!     let (hh, hv, vv) = (y[0][0].0, y[0][1].0, y[1][1].0);
//!     assert!(hh >= 0.0 && vv >= 0.0 && hh * vv - hv * hv >= -1e-18);
//! }
//! ```

use super::filters::{flush_tiny, FLUSH_BELOW};
use std::f64::consts::PI;

/// One bridge mode as data (the format `colophony fit-bridge` writes): `gain` is the
/// continuous-time `G_m` in s/kg per second (peak admittance `G / (2 pi b)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BridgeMode {
    pub freq_hz: f64,
    pub bandwidth_hz: f64,
    pub gain: [[f64; 2]; 2],
}

impl BridgeMode {
    pub fn validate(&self) -> Result<(), String> {
        let g = self.gain;
        if !(self.freq_hz.is_finite() && self.freq_hz > 0.0) {
            return Err(format!(
                "mode frequency must be positive, got {}",
                self.freq_hz
            ));
        }
        if !(self.bandwidth_hz.is_finite() && self.bandwidth_hz > 0.0) {
            return Err(format!(
                "mode at {} Hz: bandwidth must be positive (a stable pole), got {}",
                self.freq_hz, self.bandwidth_hz
            ));
        }
        let scale = g[0][0].abs() + g[1][1].abs() + g[0][1].abs() + 1e-300;
        let psd = g.iter().flatten().all(|x| x.is_finite())
            && (g[0][1] - g[1][0]).abs() <= 1e-12 * scale
            && g[0][0] >= 0.0
            && g[1][1] >= 0.0
            && g[0][0] * g[1][1] - g[0][1] * g[1][0] >= -1e-12 * scale * scale;
        if !psd {
            return Err(format!(
                "mode at {} Hz: the gain {g:?} is not symmetric positive semidefinite",
                self.freq_hz
            ));
        }
        Ok(())
    }
}

/// One mode's coefficients and energy data (its state is in [`Lanes`]).
#[derive(Debug, Clone, Copy, Default)]
struct Section {
    a1: f64,
    a2: f64,
    gain: [[f64; 2]; 2],
    /// The section's stored energy times the sample rate is
    /// `sum_ij storage[i][j] z_i^T gain^+ z_j` (z_1, z_2 the state vectors over the
    /// channels): see [`ModalBridge::energy_j`].
    storage: [[f64; 2]; 2],
    /// Pseudo-inverse of `gain`.
    gain_pinv: [[f64; 2]; 2],
}

/// Sections per [`Lanes`] block.
const LANES: usize = 4;

/// Four `f64` lanes, one per section of a [`Lanes`] block (aligned for vector loads).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
struct F4([f64; LANES]);

/// `(a + b) + (c + d)`: how both paths of [`ModalBridge::tick`] end their lane sums.
#[inline(always)]
fn sum4(x: [f64; LANES]) -> f64 {
    (x[0] + x[1]) + (x[2] + x[3])
}

/// Four sections side by side (structure of arrays): what the per-sample loop reads and
/// writes, so that it runs on vector registers and its sums run as four independent
/// chains. Unused lanes have zero gains and states and stay zero.
#[derive(Debug, Clone, Copy, Default)]
struct Lanes {
    a1: F4,
    a2: F4,
    /// `gain[c][d]` of each section.
    gain: [[F4; 2]; 2],
    /// Transposed direct form II state per channel.
    z1: [F4; 2],
    z2: [F4; 2],
}

/// `[[s11, s12], [s12, s22]]` such that `S(z) = z^T S z` (z the section's two direct-form
/// states) is a storage of `H(z) = (1 - z^-2) / (1 + a1 z^-1 + a2 z^-2)` for the supply
/// `u y` (input times output, one sample): `S(n+1) - S(n) <= u(n) y(n)`.
///
/// `H` is `D / K` times the bilinear transform (`K = 2 fs`, `D = K^2 + bw K + w^2`) of the
/// unit-mass admittance `s / (s^2 + bw s + w^2)`, state `x = (position, velocity)`, energy
/// `x^T P x / 2` with `P = diag(w^2, 1)`. The bilinear transform in its Cayley form (state
/// `x~` with `x~(n+1) = (K - A)^-1 (K + A) x~(n) + sqrt(2K) (K - A)^-1 B u(n)`) keeps the
/// positive-real lemma with the same `P`: `x~^T P x~` grows by at most `2 u y` a sample.
/// The trapezoidal half-state `w = x~ / sqrt(K / 2)` then stores `K w^T P w / 4` for the
/// supply `u y`, and since both realisations are minimal, `w = O_w^-1 O_d zeta` for the
/// observability matrices `O = [C; C A]`. The direct-form states of `H` are `D / K` times
/// those of the unit-mass section, which gives `S = K^2 / (4 D) M^T P M`, `M = O_w^-1 O_d`.
fn section_storage(a1: f64, k: f64, bw: f64, w: f64) -> [[f64; 2]; 2] {
    let d = k * k + bw * k + w * w;
    // C_w = K C (K - A)^-1 and A_w = (K - A)^-1 (K + A), A = [[0, 1], [-w^2, -bw]].
    let c_w = [-k * w * w / d, k * k / d];
    let a_w = [
        [(k * k + k * bw - w * w) / d, 2.0 * k / d],
        [-2.0 * k * w * w / d, (k * k - k * bw - w * w) / d],
    ];
    let o_w = [
        c_w,
        [
            c_w[0] * a_w[0][0] + c_w[1] * a_w[1][0],
            c_w[0] * a_w[0][1] + c_w[1] * a_w[1][1],
        ],
    ];
    // O_d = [[1, 0], [-a1, 1]] (C_d = [1, 0], A_d = [[-a1, 1], [-a2, 0]]).
    let o_d = [[1.0, 0.0], [-a1, 1.0]];
    let det = o_w[0][0] * o_w[1][1] - o_w[0][1] * o_w[1][0];
    let inv = [
        [o_w[1][1] / det, -o_w[0][1] / det],
        [-o_w[1][0] / det, o_w[0][0] / det],
    ];
    let m: [[f64; 2]; 2] = std::array::from_fn(|i| {
        std::array::from_fn(|j| inv[i][0] * o_d[0][j] + inv[i][1] * o_d[1][j])
    });
    let p = [w * w, 1.0];
    let scale = k * k / (4.0 * d);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| scale * (p[0] * m[0][i] * m[0][j] + p[1] * m[1][i] * m[1][j]))
    })
}

/// Pseudo-inverse of a symmetric positive semidefinite 2x2 matrix (eigenvalues below
/// 1e-12 of the largest count as zero: the states along them are that much smaller).
fn psd_pinv(g: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let (p, q, r) = (g[0][0], g[0][1], g[1][1]);
    let mean = 0.5 * (p + r);
    let radius = (0.25 * (p - r) * (p - r) + q * q).sqrt();
    let largest = mean + radius;
    if !(largest > 0.0) {
        return [[0.0; 2]; 2];
    }
    if radius <= 1e-15 * largest {
        // A multiple of the identity.
        return [[1.0 / mean, 0.0], [0.0, 1.0 / mean]];
    }
    // Eigenvector of the larger eigenvalue, from the row whose entry cannot vanish
    // (`(l - p)(l - r) = q^2`, and one of `l - p`, `l - r` is at least `radius`); the
    // other eigenvector is perpendicular.
    let (x, y) = if p >= r {
        (0.5 * (p - r) + radius, q)
    } else {
        (q, 0.5 * (r - p) + radius)
    };
    let norm = (x * x + y * y).sqrt();
    let (x, y) = (x / norm, y / norm);
    let mut pinv = [[0.0; 2]; 2];
    for (lambda, v) in [(largest, [x, y]), (mean - radius, [-y, x])] {
        if lambda > 1e-12 * largest {
            for i in 0..2 {
                for j in 0..2 {
                    pinv[i][j] += v[i] * v[j] / lambda;
                }
            }
        }
    }
    pinv
}

impl Section {
    /// `mode` at `sample_rate_hz` by the bilinear transform; `None` at or above Nyquist.
    fn of(mode: &BridgeMode, sample_rate_hz: f64) -> Option<Self> {
        if mode.freq_hz >= 0.5 * sample_rate_hz {
            return None;
        }
        let k = 2.0 * sample_rate_hz;
        let w = k * (PI * mode.freq_hz / sample_rate_hz).tan();
        let bw = 2.0 * PI * mode.bandwidth_hz;
        let d = k * k + bw * k + w * w;
        let mut gain = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                gain[i][j] = mode.gain[i][j] * k / d;
            }
        }
        let a1 = 2.0 * (w * w - k * k) / d;
        Some(Section {
            a1,
            a2: (k * k - bw * k + w * w) / d,
            gain,
            storage: section_storage(a1, k, bw, w),
            gain_pinv: psd_pinv(gain),
        })
    }
}

/// `Y(z)` at one sample rate (see the module doc).
#[derive(Debug, Clone)]
pub struct ModalBridge {
    /// The continuous-time modes, validated (kept to rebuild the sections at a new rate).
    modes: Vec<BridgeMode>,
    /// The modes as built, before [`ModalBridge::transform_modes`] changed them.
    built: Vec<BridgeMode>,
    sections: Vec<Section>,
    /// The sections' coefficients and states, four to a block (section `i` in block
    /// `i / 4`, lane `i % 4`).
    lanes: Vec<Lanes>,
    /// `v_hist`: the sum of the sections' `z1`, kept by [`ModalBridge::tick`].
    hist: [f64; 2],
    /// AVX2 (hence AVX) available ([`super::detect_wide_simd`], once, at construction).
    wide_simd: bool,
    r0: [[f64; 2]; 2],
    sample_rate_hz: f64,
}

impl ModalBridge {
    pub fn new(modes: &[BridgeMode], sample_rate_hz: f64) -> Result<Self, String> {
        for mode in modes {
            mode.validate()?;
        }
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(format!("invalid bridge sample rate {sample_rate_hz}"));
        }
        let mut bridge = Self {
            modes: modes.to_vec(),
            built: modes.to_vec(),
            sections: Vec::with_capacity(modes.len()),
            lanes: Vec::with_capacity(modes.len().div_ceil(LANES)),
            hist: [0.0; 2],
            wide_simd: super::detect_wide_simd(),
            r0: [[0.0; 2]; 2],
            sample_rate_hz,
        };
        bridge.set_sample_rate(sample_rate_hz);
        Ok(bridge)
    }

    /// Maps the modes to `sample_rate_hz` (dropping those at or above Nyquist) and clears
    /// the state. Never allocates. A rate that is not finite and positive is ignored.
    pub fn set_sample_rate(&mut self, sample_rate_hz: f64) {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return;
        }
        self.sample_rate_hz = sample_rate_hz;
        self.sections.clear();
        let mut r0 = [[0.0; 2]; 2];
        for mode in &self.modes {
            if let Some(section) = Section::of(mode, sample_rate_hz) {
                for (i, row) in r0.iter_mut().enumerate() {
                    for (j, r) in row.iter_mut().enumerate() {
                        *r += section.gain[i][j];
                    }
                }
                self.sections.push(section);
            }
        }
        self.r0 = r0;
        self.lanes.clear();
        for block in self.sections.chunks(LANES) {
            let mut lanes = Lanes::default();
            for (l, s) in block.iter().enumerate() {
                lanes.a1.0[l] = s.a1;
                lanes.a2.0[l] = s.a2;
                for c in 0..2 {
                    for d in 0..2 {
                        lanes.gain[c][d].0[l] = s.gain[c][d];
                    }
                }
            }
            self.lanes.push(lanes);
        }
        self.hist = [0.0; 2];
    }

    /// Rebuilds the bridge from its modes as built, each passed through `change` (a mute's
    /// mass on the bridge: [`super::body::muted`]; the identity takes it off), keeping
    /// the sections' ringing state where every mode keeps its section. Never allocates.
    pub fn transform_modes(&mut self, change: impl Fn(BridgeMode) -> BridgeMode) {
        for (mode, built) in self.modes.iter_mut().zip(&self.built) {
            *mode = change(*built);
        }
        let fs = self.sample_rate_hz;
        let kept = self.modes.iter().filter(|m| m.freq_hz < 0.5 * fs).count();
        if kept != self.sections.len() {
            self.set_sample_rate(fs);
            return;
        }
        let mut r0 = [[0.0; 2]; 2];
        let mut k = 0;
        for mode in &self.modes {
            let Some(section) = Section::of(mode, fs) else {
                continue;
            };
            let lanes = &mut self.lanes[k / LANES];
            let l = k % LANES;
            lanes.a1.0[l] = section.a1;
            lanes.a2.0[l] = section.a2;
            for c in 0..2 {
                for d in 0..2 {
                    lanes.gain[c][d].0[l] = section.gain[c][d];
                    r0[c][d] += section.gain[c][d];
                }
            }
            self.sections[k] = section;
            k += 1;
        }
        self.r0 = r0;
    }

    /// Section `i`'s states `(z1, z2)`, each over the two channels.
    fn state(&self, i: usize) -> ([f64; 2], [f64; 2]) {
        let (b, l) = (&self.lanes[i / LANES], i % LANES);
        ([b.z1[0].0[l], b.z1[1].0[l]], [b.z2[0].0[l], b.z2[1].0[l]])
    }

    /// Whether every section's state is below `threshold` (m/s): the bridge has rung out.
    pub fn is_quiet(&self, threshold: f64) -> bool {
        self.lanes.iter().all(|b| {
            b.z1.iter()
                .chain(&b.z2)
                .flat_map(|z| z.0)
                .all(|z| z.abs() < threshold)
        })
    }

    /// Energy the bridge holds, J: for every section, the storage of its scalar filter
    /// (`section_storage`) in the eigen-directions of its gain `R = Q L Q^T`. The input
    /// `R F` gives the outputs `Q L H(Q^T F)` and the supply `F . v = sum_k l_k xi_k H(xi_k)`
    /// (`xi = Q^T F`), while the states along `Q` are `l_k` times those of `H` driven by
    /// `xi_k`; so the storage is `sum_k S(Q^T z)_k / l_k`, the quadratic form in `R^+`.
    /// With the force on it `F` and its velocity `v`, it grows by at most `F . v / fs` a
    /// sample: the strings around a passive bridge lose what it gains.
    pub fn energy_j(&self) -> f64 {
        let quad = |g: &[[f64; 2]; 2], a: [f64; 2], b: [f64; 2]| {
            a[0] * (g[0][0] * b[0] + g[0][1] * b[1]) + a[1] * (g[1][0] * b[0] + g[1][1] * b[1])
        };
        let joules: f64 = self
            .sections
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let g = &s.gain_pinv;
                let (z1, z2) = self.state(i);
                s.storage[0][0] * quad(g, z1, z1)
                    + 2.0 * s.storage[0][1] * quad(g, z1, z2)
                    + s.storage[1][1] * quad(g, z2, z2)
            })
            .sum();
        joules / self.sample_rate_hz
    }

    pub fn mode_count(&self) -> usize {
        self.sections.len()
    }

    pub fn reset(&mut self) {
        for b in &mut self.lanes {
            b.z1 = [F4::default(); 2];
            b.z2 = [F4::default(); 2];
        }
        self.hist = [0.0; 2];
    }

    /// `Y(e^jw)` at `freq_hz` as a complex 2x2 matrix `[(re, im); 4]` in the order hh, hv,
    /// vh, vv.
    pub fn response(&self, freq_hz: f64) -> [[(f64, f64); 2]; 2] {
        let w = 2.0 * PI * freq_hz / self.sample_rate_hz;
        let (c1, s1) = (w.cos(), -w.sin());
        let (c2, s2) = ((2.0 * w).cos(), -(2.0 * w).sin());
        let mut y = [[(0.0, 0.0); 2]; 2];
        for s in &self.sections {
            // (1 - z^-2) / (1 + a1 z^-1 + a2 z^-2) at z = e^jw
            let num = (1.0 - c2, -s2);
            let den = (1.0 + s.a1 * c1 + s.a2 * c2, s.a1 * s1 + s.a2 * s2);
            let d = den.0 * den.0 + den.1 * den.1;
            let h = (
                (num.0 * den.0 + num.1 * den.1) / d,
                (num.1 * den.0 - num.0 * den.1) / d,
            );
            for i in 0..2 {
                for j in 0..2 {
                    y[i][j].0 += h.0 * s.gain[i][j];
                    y[i][j].1 += h.1 * s.gain[i][j];
                }
            }
        }
        y
    }

    /// The part of this sample's bridge velocity that does not depend on this sample's
    /// force (the sections' states), `v_hist`.
    fn history(&self) -> [f64; 2] {
        self.hist
    }

    /// Advances every section with this sample's total force; returns `v_B` (and keeps
    /// the next sample's `v_hist`). The sections run four to a block, each lane with its
    /// own sums; with AVX the four lanes are one vector (the same bits as the scalar path:
    /// the same operations in the same order, no FMA).
    #[inline(always)]
    fn tick(&mut self, force: [f64; 2]) -> [f64; 2] {
        #[cfg(target_arch = "x86_64")]
        if self.wide_simd {
            // SAFETY: `wide_simd` is true only where AVX2 (a superset of AVX) was detected.
            return unsafe { self.tick_avx(force) };
        }
        let mut v = [[0.0; LANES]; 2];
        let mut hist = [[0.0; LANES]; 2];
        for c in 0..2 {
            for b in &mut self.lanes {
                for l in 0..LANES {
                    let u = b.gain[c][0].0[l] * force[0] + b.gain[c][1].0[l] * force[1];
                    let y = u + b.z1[c].0[l];
                    let z1 = flush_tiny(-b.a1.0[l] * y + b.z2[c].0[l]);
                    b.z2[c].0[l] = flush_tiny(-u - b.a2.0[l] * y);
                    b.z1[c].0[l] = z1;
                    v[c][l] += y;
                    hist[c][l] += z1;
                }
            }
        }
        self.hist = [sum4(hist[0]), sum4(hist[1])];
        [sum4(v[0]), sum4(v[1])]
    }

    /// [`ModalBridge::tick`] on AVX vectors, lane for lane the scalar path's arithmetic.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn tick_avx(&mut self, force: [f64; 2]) -> [f64; 2] {
        use std::arch::x86_64::*;
        let f = [_mm256_set1_pd(force[0]), _mm256_set1_pd(force[1])];
        let sign = _mm256_set1_pd(-0.0);
        let tiny = _mm256_set1_pd(FLUSH_BELOW);
        // flush_tiny: zero where |x| < FLUSH_BELOW (NaN compares false and stays).
        let flush = |x: __m256d| {
            let small = _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_andnot_pd(sign, x), tiny);
            _mm256_andnot_pd(small, x)
        };
        // SAFETY: `F4` is 32-byte aligned and four f64 long.
        let load = |x: &F4| unsafe { _mm256_load_pd(x.0.as_ptr()) };
        let store = |x: &mut F4, v: __m256d| unsafe { _mm256_store_pd(x.0.as_mut_ptr(), v) };
        let mut out = [0.0; 2];
        for c in 0..2 {
            let mut v = _mm256_setzero_pd();
            let mut h = _mm256_setzero_pd();
            for b in &mut self.lanes {
                let u = _mm256_add_pd(
                    _mm256_mul_pd(load(&b.gain[c][0]), f[0]),
                    _mm256_mul_pd(load(&b.gain[c][1]), f[1]),
                );
                let y = _mm256_add_pd(u, load(&b.z1[c]));
                let neg_a1 = _mm256_xor_pd(load(&b.a1), sign);
                let z1 = flush(_mm256_add_pd(_mm256_mul_pd(neg_a1, y), load(&b.z2[c])));
                let neg_u = _mm256_xor_pd(u, sign);
                let z2 = flush(_mm256_sub_pd(neg_u, _mm256_mul_pd(load(&b.a2), y)));
                store(&mut b.z1[c], z1);
                store(&mut b.z2[c], z2);
                v = _mm256_add_pd(v, y);
                h = _mm256_add_pd(h, z1);
            }
            let (mut vs, mut hs) = (F4::default(), F4::default());
            store(&mut vs, v);
            store(&mut hs, h);
            out[c] = sum4(vs.0);
            self.hist[c] = sum4(hs.0);
        }
        out
    }
}

/// Solves the bridge junction for strings whose arriving waves are `arriving[i]` and
/// impedances `z[i]`; writes the leaving waves into `leaving` and returns the bridge
/// velocity and the total force on the bridge `[h, v]`. Inlined, so that it runs with the
/// caller's instruction set (the thermal instrument's AVX2 sample).
#[inline(always)]
pub fn solve_junction(
    bridge: &mut ModalBridge,
    arriving: &[[f64; 2]],
    z: &[f64],
    leaving: &mut [[f64; 2]],
) -> ([f64; 2], [f64; 2]) {
    let hist = bridge.history();
    let z_sum: f64 = z.iter().sum();
    let mut drive = [0.0; 2];
    for (a, zi) in arriving.iter().zip(z) {
        drive[0] += 2.0 * zi * a[0];
        drive[1] += 2.0 * zi * a[1];
    }
    let r0 = bridge.r0;
    // (I + R0 z_sum) v = R0 drive + hist
    let m = [
        [1.0 + r0[0][0] * z_sum, r0[0][1] * z_sum],
        [r0[1][0] * z_sum, 1.0 + r0[1][1] * z_sum],
    ];
    let rhs = [
        r0[0][0] * drive[0] + r0[0][1] * drive[1] + hist[0],
        r0[1][0] * drive[0] + r0[1][1] * drive[1] + hist[1],
    ];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let v = [
        (m[1][1] * rhs[0] - m[0][1] * rhs[1]) / det,
        (m[0][0] * rhs[1] - m[1][0] * rhs[0]) / det,
    ];
    let force = [drive[0] - z_sum * v[0], drive[1] - z_sum * v[1]];
    let v_check = bridge.tick(force);
    debug_assert!((v_check[0] - v[0]).abs() <= 1e-9 * (1.0 + v[0].abs()));
    for (out, a) in leaving.iter_mut().zip(arriving) {
        *out = [v[0] - a[0], v[1] - a[1]];
    }
    (v, force)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A few hand-made modes for the unit tests (the shipped bridges are data in assets/).
    fn generic_cello_bridge() -> Vec<BridgeMode> {
        // Peak admittances (s/kg) per mode, [[hh, hv], [hv, vv]], turned into G = peak 2 pi b.
        let mode = |f: f64, q: f64, hh: f64, hv: f64, vv: f64| {
            let b = f / q;
            let g = 2.0 * PI * b;
            BridgeMode {
                freq_hz: f,
                bandwidth_hz: b,
                gain: [[hh * g, hv * g], [hv * g, vv * g]],
            }
        };
        vec![
            mode(102.0, 25.0, 0.02, 0.006, 0.03),
            mode(185.0, 30.0, 0.03, -0.008, 0.02),
            mode(220.0, 30.0, 0.025, 0.005, 0.04),
            mode(410.0, 25.0, 0.02, 0.004, 0.015),
            mode(560.0, 20.0, 0.015, -0.003, 0.02),
            mode(1100.0, 15.0, 0.02, 0.005, 0.01),
            mode(2000.0, 8.0, 0.04, 0.01, 0.02),
            mode(3200.0, 8.0, 0.02, 0.005, 0.015),
        ]
    }

    #[test]
    fn the_vector_bridge_gives_the_same_bits_as_the_scalar_one() {
        // 14 modes: three full blocks of four and a half-empty one.
        let mut modes = generic_cello_bridge();
        modes.extend(generic_cello_bridge().iter().take(6).map(|m| BridgeMode {
            freq_hz: m.freq_hz * 1.37,
            ..*m
        }));
        assert_eq!(modes.len(), 14);
        let mut scalar = ModalBridge::new(&modes, 541_600.0).unwrap();
        scalar.wide_simd = false;
        let mut vector = ModalBridge::new(&modes, 541_600.0).unwrap();
        let mut x = 0.321_f64;
        for n in 0..50_000 {
            // Broadband forces for 20 000 samples, then none: the ring-out flushes to zero.
            x = 3.99 * x * (1.0 - x);
            let f = if n < 20_000 {
                [x - 0.5, 0.3 - x]
            } else {
                [0.0; 2]
            };
            let (a, b) = (scalar.tick(f), vector.tick(f));
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "sample {n}");
            assert_eq!(
                scalar.history().map(f64::to_bits),
                vector.history().map(f64::to_bits)
            );
        }
        assert_eq!(scalar.energy_j().to_bits(), vector.energy_j().to_bits());
    }

    /// Moving the modes keeps the bridge ringing: the identity changes no bit of what
    /// follows, and a mute put on and taken off again gives back the bridge as built
    /// (its response at every mode, to the bit), its state carried through.
    #[test]
    fn transforming_the_modes_keeps_the_state_and_the_identity_changes_nothing() {
        let modes = generic_cello_bridge();
        let mut touched = ModalBridge::new(&modes, 96_000.0).unwrap();
        let mut x = 0.321_f64;
        let mut force = || {
            x = 3.99 * x * (1.0 - x);
            [x - 0.5, 0.3 - x]
        };
        for _ in 0..1000 {
            touched.tick(force());
        }
        let mut left = touched.clone();
        touched.transform_modes(|m| m);
        for n in 0..1000 {
            let f = force();
            let (a, b) = (touched.tick(f), left.tick(f));
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "sample {n}");
        }
        let before = touched.energy_j();
        // A mass on the upper modes: half the frequency and bandwidth, a quarter of the gain.
        touched.transform_modes(|m| {
            if m.freq_hz < 1500.0 {
                return m;
            }
            BridgeMode {
                freq_hz: 0.5 * m.freq_hz,
                bandwidth_hz: 0.5 * m.bandwidth_hz,
                gain: m.gain.map(|row| row.map(|g| 0.25 * g)),
            }
        });
        assert!(touched.energy_j() > 0.0, "still ringing");
        assert!(before > 0.0);
        touched.transform_modes(|m| m);
        for m in &modes {
            assert_eq!(touched.response(m.freq_hz), left.response(m.freq_hz));
        }
    }

    #[test]
    fn the_bridge_stores_at_most_what_the_force_puts_in_and_a_lossless_mode_all_of_it() {
        // Broadband forces in (-0.5, 0.5) N on both axes (the logistic map).
        let mut x = 0.123_f64;
        let mut next = || {
            x = 3.99 * x * (1.0 - x);
            x - 0.5
        };
        for fs in [48_000.0, 541_600.0] {
            let mut bridge = ModalBridge::new(&generic_cello_bridge(), fs).unwrap();
            let mut put_in = 0.0;
            for n in 0..20_000 {
                let f = [next(), next()];
                let before = bridge.energy_j();
                let v = bridge.tick(f);
                let supplied = (f[0] * v[0] + f[1] * v[1]) / fs;
                let gained = bridge.energy_j() - before;
                // Rounding only: a few hundred products, each within 2^-53 of the energy.
                let rounding = 1e-12 * (before.abs() + supplied.abs());
                assert!(
                    gained <= supplied + rounding,
                    "{fs} Hz, sample {n}: gained {gained:e} J, supplied {supplied:e} J"
                );
                put_in += supplied;
            }
            assert!(bridge.energy_j() > 0.0 && bridge.energy_j() < put_in);
        }
        // A mode with (almost) no damping stores exactly what goes in.
        let lossless = BridgeMode {
            freq_hz: 300.0,
            bandwidth_hz: 1e-9,
            gain: [[0.5, 0.1], [0.1, 0.2]],
        };
        let fs = 48_000.0;
        let mut bridge = ModalBridge::new(&[lossless], fs).unwrap();
        let mut balance = 0.0;
        for _ in 0..5_000 {
            let f = [next(), next()];
            let before = bridge.energy_j();
            let v = bridge.tick(f);
            balance += bridge.energy_j() - before - (f[0] * v[0] + f[1] * v[1]) / fs;
        }
        // The 1e-9 Hz bandwidth dissipates about 2 pi 1e-9 / 300 of the energy a period.
        assert!(
            balance.abs() < 1e-6 * bridge.energy_j(),
            "lossless mode: stored minus supplied {balance:e} J of {:e} J",
            bridge.energy_j()
        );
    }

    #[test]
    fn psd_pseudo_inverse_inverts_on_the_range_and_ignores_the_null_space() {
        let mul = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| -> [[f64; 2]; 2] {
            std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
        };
        for g in [
            [[2.0, 0.0], [0.0, 2.0]],
            [[3.0, 0.0], [0.0, 1.0]],
            [[1.0, 0.0], [0.0, 3.0]],
            [[0.5, 0.1], [0.1, 0.2]],
            [[0.2, -0.1], [-0.1, 0.5]],
            // Rank one: g = u u^T, u = (0.6, 0.8).
            [[0.36, 0.48], [0.48, 0.64]],
        ] {
            let pinv = psd_pinv(g);
            // Moore-Penrose: g pinv g = g; 1e-12 is rounding on entries of order 1.
            let back = mul(mul(g, pinv), g);
            for i in 0..2 {
                for j in 0..2 {
                    assert!((back[i][j] - g[i][j]).abs() < 1e-12, "{g:?}: {back:?}");
                }
            }
        }
    }

    #[test]
    fn the_generic_bridge_is_passive_on_a_dense_grid() {
        let bridge = ModalBridge::new(&generic_cello_bridge(), 48_000.0).unwrap();
        let mut worst = f64::MAX;
        for k in 1..24_000 {
            let y = bridge.response(k as f64);
            // Eigenvalues of the symmetric real part.
            let (a, b, d) = (y[0][0].0, 0.5 * (y[0][1].0 + y[1][0].0), y[1][1].0);
            let mean = 0.5 * (a + d);
            let rad = (0.25 * (a - d) * (a - d) + b * b).sqrt();
            worst = worst.min(mean - rad);
        }
        println!("smallest eigenvalue of Re Y over 1 Hz..24 kHz: {worst:e}");
        // Rounding only: each section's real part is >= 0 analytically.
        assert!(worst > -1e-12);
    }

    #[test]
    fn each_mode_peaks_at_its_frequency_with_the_continuous_time_height() {
        for fs in [48_000.0, 541_600.0] {
            for mode in generic_cello_bridge() {
                let bridge = ModalBridge::new(&[mode], fs).unwrap();
                let y = bridge.response(mode.freq_hz);
                let expected = mode.gain[0][0] / (2.0 * PI * mode.bandwidth_hz);
                // Pre-warped bilinear: the peak is real and exact at f_m. 1e-7: rounding, from
                // the cancellation in 1 - e^-2jw at w ~ 1e-3 rad.
                assert!(
                    (y[0][0].0 / expected - 1.0).abs() < 1e-7,
                    "{fs} Hz, {mode:?}: {y:?}"
                );
                assert!(
                    y[0][0].1.abs() < 1e-7 * expected,
                    "{fs} Hz, {mode:?}: {y:?}"
                );
            }
        }
    }

    #[test]
    fn non_psd_gains_and_unstable_poles_are_refused() {
        let bad = [
            BridgeMode {
                freq_hz: 100.0,
                bandwidth_hz: 5.0,
                gain: [[1.0, 2.0], [2.0, 1.0]],
            },
            BridgeMode {
                freq_hz: 100.0,
                bandwidth_hz: -5.0,
                gain: [[1.0, 0.0], [0.0, 1.0]],
            },
            BridgeMode {
                freq_hz: 100.0,
                bandwidth_hz: 5.0,
                gain: [[1.0, 0.5], [0.4, 1.0]],
            },
            BridgeMode {
                freq_hz: f64::NAN,
                bandwidth_hz: 5.0,
                gain: [[1.0, 0.0], [0.0, 1.0]],
            },
        ];
        for mode in bad {
            let err = ModalBridge::new(&[mode], 48_000.0).unwrap_err();
            println!("{err}");
        }
    }
}
