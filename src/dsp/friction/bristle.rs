//! Bristle friction: LuGre and elasto-plastic (Dupont et al. 2002), solved without delay by
//! the K-method and a safeguarded Newton-Raphson iteration, as in Serafin, Avanzini and
//! Rocchesso, "Bowed string simulation using an elasto-plastic friction model" (paper A,
//! docs/models.md §A).
//!
//! ```text
//! f   = sigma0 z + sigma1 zdot + sigma2 v                         friction force
//! zdot = v (1 - alpha(v, z) z / z_ss(v))                           bristle dynamics
//! z_ss(v) = sgn(v) (f_c + (f_s - f_c) exp(-(v / v_s)^2)) / sigma0  Stribeck steady state
//! ```
//!
//! LuGre is `alpha = 1`; elasto-plastic uses the adhesion map `alpha(v, z)`, zero while
//! `|z| <= z_ba` (purely elastic presliding) or when `z` and `v` disagree in sign, one
//! beyond `|z_ss(v)|`, a raised sine in between.
//!
//! **K-method.** The resonator offers a load line `v_s = v_h + Y F` (see the parent
//! module), so the relative velocity is `v = v_free - Y F` with `v_free = v_b - v_h`. The
//! bristle equation is discretised by the trapezoidal rule, `z(n) = z~ + (T/2) y` with
//! `y = zdot(n)` and `z~ = z(n-1) + (T/2) y(n-1)`. Substituting `F` gives
//! `v = v~ + k1 y`, `z = z~ + k2 y` with
//! `v~ = (v_free - Y sigma0 z~) / (1 + Y sigma2)`, `k1 = -Y (sigma0 T/2 + sigma1) / (1 + Y sigma2)`,
//! `k2 = T/2`, and the scalar equation `g(y) = f_NL(v~ + k1 y, z~ + k2 y) - y = 0`. No
//! unit delay enters the loop.
//!
//! **Solver.** Newton-Raphson with the analytic derivative, started from the tangent
//! predictor `y(n-1) - (f_v dv~ + f_z dz~) / g'` (the last root moved along the implicit
//! function by this sample's change of `v~` and `z~`, with the partials of the last
//! solve's final evaluation; from `y(n-1)` itself where that `g'` was above -1/2), each step damped
//! (halved up to [`MAX_DAMPING_HALVINGS`] times) until `|g|` falls. It stops when a full
//! Newton step is shorter than the tolerance (a damped step's length says nothing about
//! the distance to the root, so it never stops the iteration), and, where that step
//! crosses the kink of `g` at `v = 0`, only if `g` changes sign along it (the slope on one
//! side of the kink says nothing about the other's: it differs by up to `2 |k1|`, and a
//! short step from the steep side can leave the root many tolerances away on the flat
//! one); otherwise the iteration goes on from the far side. Every evaluation of `g` also
//! narrows a bracket `g(lo) > 0 > g(hi)` where it has seen both signs. Where no damped
//! step descends but a bracket is known (with a stiff bristle `g` is not monotone while
//! the contact slips: the falling Stribeck slope times `k1` outweighs the rest of `g'`,
//! and Newton heads for a minimum of `|g|` that is not a root), the iteration stays
//! inside the bracket: a full Newton step where it lands inside, goes down `g` and is
//! shorter than half the step before last (Numerical Recipes' `rtsafe`), else false
//! position with the Illinois weighting, until a Newton step or the bracket is shorter
//! than the tolerance. If it has not converged within `NEWTON_CAP - 1` iterations, no
//! damped step descends and no bracket is known (a kink: `|v|` at `v = 0`, the
//! adhesion map's corners), or a step is not finite, a bracketing fallback takes over: `g`
//! is positive for very negative `y` and negative for very positive `y` (there `alpha = 0`
//! and `g ~ (k1 - 1) y`), so a bracket is found by steps doubling from `|g| / (1 - k1)`
//! and narrowed by the same bracketed iteration (`rtsafe`'s Newton rule, else Illinois false
//! position). Either way the result is finite.
//! Iterations and fallbacks are counted in [`SolverStats`].
//!
//! | symbol | meaning | unit | source |
//! |---|---|---|---|
//! | `sigma0` | bristle stiffness | N/m | paper A (1e4 for modal objects) |
//! | `sigma1` | bristle damping | kg/s | paper A: 0.1 sqrt(sigma0) |
//! | `sigma2` | viscous friction | kg/s | paper A: 0.4 |
//! | `v_s` | Stribeck velocity | m/s | paper A: 0.1 |
//! | `mu_s`, `mu_d` | static and Coulomb coefficients: `f_s = mu_s F_N`, `f_c = mu_d F_N` | 1 | paper A: 0.4, 0.2 |
//! | `c` | breakaway ratio, `z_ba = c f_c / sigma0`, `0 <= c < 1` | 1 | paper A code: 0.7 |
//! | `T` | sample period | s | |
//!
//! ```
//! use colophony::dsp::friction::bristle::{BristleFriction, BristleLaw, BristleParams};
//! use colophony::dsp::friction::{BowInput, FrictionContact, LoadLine};
//! let mut contact =
//!     BristleFriction::new(BristleParams::modal_scenario(), BristleLaw::ElastoPlastic, 44_100.0)
//!         .unwrap();
//! let load = LoadLine { free_velocity_m_per_s: 0.0, admittance_s_per_kg: 0.01 };
//! let f = contact.solve(load, BowInput { velocity_m_per_s: 0.1, normal_force_n: 1.0 });
//! assert!(f.is_finite());
//! ```

use super::{BowInput, FrictionContact, LoadLine};
use crate::dsp::fastmath::{exp_nonpositive, sin_cos_quarter_turn};
use std::cell::Cell;

/// Partials that turn the tangent predictor off (`g' = 0`): the next solve starts from
/// `y(n-1)`.
const NO_TANGENT: [f64; 3] = [0.0, 0.0, 0.0];

/// A solve not converged within `NEWTON_CAP - 1` iterations goes to the bracketing
/// fallback, and counts in the histogram's last bin, `NEWTON_CAP`.
pub const NEWTON_CAP: u32 = 20;
/// Step halvings per Newton iteration when `|g|` does not fall.
pub const MAX_DAMPING_HALVINGS: u32 = 8;
/// Iterations the fallback's bracketed iteration may take (false position shrinks a
/// bracket of `1e300` to `1e-16` well within it).
const FALLBACK_CAP: u32 = 200;
/// Doublings the fallback's walk may take to find a sign change: from a step of `1e-6`,
/// 200 doublings pass any finite velocity.
const WALK_DOUBLINGS: u32 = 200;
/// Default convergence test: `|dy| <= Y_TOLERANCE_M_PER_S * max(1, |y|)` (see
/// [`BristleFriction::set_newton_tolerance`]).
pub const Y_TOLERANCE_M_PER_S: f64 = 1e-10;
/// The contact counts as sticking while `|v|` is below this fraction of `v_s`.
pub const STICK_FRACTION_OF_STRIBECK: f64 = 0.01;

/// Bristle parameters in SI units (see the module's symbol table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BristleParams {
    pub sigma0_n_per_m: f64,
    pub sigma1_kg_per_s: f64,
    pub sigma2_kg_per_s: f64,
    pub stribeck_m_per_s: f64,
    pub mu_s: f64,
    pub mu_d: f64,
    /// `c` in `z_ba = c f_c / sigma0`.
    pub breakaway_ratio: f64,
}

impl BristleParams {
    /// Paper A's modal scenario (the authors' SMAC-03 script, docs/literature-values.md §1.7 row 1).
    pub fn modal_scenario() -> Self {
        Self {
            sigma0_n_per_m: 1e4,
            sigma1_kg_per_s: 0.1 * 1e4f64.sqrt(),
            sigma2_kg_per_s: 0.4,
            stribeck_m_per_s: 0.1,
            mu_s: 0.4,
            mu_d: 0.2,
            breakaway_ratio: 0.7,
        }
    }

    /// Values chosen for the waveguide string (paper A's cello D scenario). The modal set
    /// does not give Helmholtz motion there (docs/models.md, pitfalls): `sigma2 = 0.4 kg/s` lifts
    /// sliding friction at 1 m/s above the static level, and `sigma1 = 10 kg/s`, far above
    /// the string's `2 Z0 ~ 1 kg/s`, makes the contact chatter. Here `sigma2 = 0`; `sigma0`
    /// is raised to 1e5 N/m so presliding stays below a micrometre and the bristle time
    /// constant `2 Z0 / sigma0 ~ 10 us` is under a sample at 48 kHz; `sigma1` is the
    /// critical damping of the bristle against the string's load, `2 sqrt(sigma0 m)` with
    /// no mass, so it is set to a small fraction of `2 Z0` (0.1 kg/s) to damp presliding
    /// without taking over the contact.
    pub fn waveguide_string() -> Self {
        Self {
            sigma0_n_per_m: 1e5,
            sigma1_kg_per_s: 0.1,
            sigma2_kg_per_s: 0.0,
            stribeck_m_per_s: 0.1,
            mu_s: 0.4,
            mu_d: 0.2,
            breakaway_ratio: 0.7,
        }
    }

    /// The plugin's string (every instrument, every note): [`Self::waveguide_string`] with
    /// a bristle three times stiffer. Chosen by the playing-space map (docs/playing-space.md,
    /// "Bristle stiffness"): every third semitone at 48 kHz, with the intonation
    /// table re-fitted, LuGre / elasto-plastic nominal cells in tune 12 -> 27 and 25 -> 35 of
    /// 96 and window cells in Helmholtz motion 105 -> 119 and 109 -> 123 of 576.
    /// Its `g` is not monotone while the contact slips, which the solver's bracket handles
    /// (module doc). Paper A's scene keeps 1e5 N/m, its figures and iteration budget.
    pub fn plugin_string() -> Self {
        Self {
            sigma0_n_per_m: 3e5,
            ..Self::waveguide_string()
        }
    }

    /// Checks the physical domain: every value finite, `sigma0 > 0`, `sigma1, sigma2 >= 0`,
    /// `v_s > 0`, `0 <= mu_d <= mu_s`, `0 <= c < 1`.
    pub fn validate(&self) -> Result<(), String> {
        let all = [
            self.sigma0_n_per_m,
            self.sigma1_kg_per_s,
            self.sigma2_kg_per_s,
            self.stribeck_m_per_s,
            self.mu_s,
            self.mu_d,
            self.breakaway_ratio,
        ];
        if all.iter().any(|x| !x.is_finite()) {
            return Err("friction parameters must be finite".into());
        }
        if self.sigma0_n_per_m <= 0.0 {
            return Err(format!(
                "sigma0 must be positive, got {} N/m",
                self.sigma0_n_per_m
            ));
        }
        if self.sigma1_kg_per_s < 0.0 || self.sigma2_kg_per_s < 0.0 {
            return Err("sigma1 and sigma2 must be non-negative".into());
        }
        if self.stribeck_m_per_s <= 0.0 {
            return Err("the Stribeck velocity must be positive".into());
        }
        if !(0.0 <= self.mu_d && self.mu_d <= self.mu_s) {
            return Err(format!(
                "need 0 <= mu_d <= mu_s, got mu_d {} and mu_s {}",
                self.mu_d, self.mu_s
            ));
        }
        if !(0.0..1.0).contains(&self.breakaway_ratio) {
            return Err(format!(
                "the breakaway ratio c in z_ba = c f_c / sigma0 must satisfy 0 <= c < 1 (so \
                 that z_ba < |z_ss| always), got {}",
                self.breakaway_ratio
            ));
        }
        Ok(())
    }
}

/// How the bristle equation is discretised in time (the K-method's `z = z~ + k2 y`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BristleIntegrator {
    /// Paper A's trapezoidal rule: `z(n) = z(n-1) + (T/2) (y(n-1) + y(n))`. Second order,
    /// A-stable but not L-stable: a bristle relaxing much faster than a sample (slipping,
    /// `sigma0 |v| / h(v)` above `2 / T`) flips sign from sample to sample instead of
    /// settling.
    #[default]
    Trapezoid,
    /// Backward Euler: `z(n) = z(n-1) + T y(n)`. First order, L-stable: a bristle faster
    /// than a sample settles onto its steady state within the sample.
    BackwardEuler,
}

/// Which bristle law: LuGre (`alpha = 1`) or elasto-plastic (adhesion map).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BristleLaw {
    LuGre,
    ElastoPlastic,
}

/// Solver counters since the last [`SolverStats::clear`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolverStats {
    /// `histogram[k]`: samples that took `k` iterations (Newton steps, and inside a
    /// bracket false-position steps); the last bin, `NEWTON_CAP`, collects the samples
    /// that went on to the fallback.
    pub histogram: [u64; NEWTON_CAP as usize + 1],
    /// Samples solved by the bracketing fallback.
    pub fallbacks: u64,
    /// Evaluations of `g` the fallback made (beside the Newton iterations before it).
    pub fallback_evaluations: u64,
    /// Newton iterations on the last sample.
    pub last_iterations: u32,
}

impl SolverStats {
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    pub fn samples(&self) -> u64 {
        self.histogram.iter().sum()
    }

    /// Fraction of samples solved in at most `k` Newton iterations without fallback.
    pub fn fraction_within(&self, k: u32) -> f64 {
        let n = self.samples().max(1) as f64;
        let within: u64 = self.histogram[..=(k as usize).min(NEWTON_CAP as usize)]
            .iter()
            .sum();
        within as f64 / n
    }
}

/// A LuGre or elasto-plastic contact (see the module doc).
#[derive(Debug, Clone)]
pub struct BristleFriction {
    params: BristleParams,
    law: BristleLaw,
    half_period_s: f64,
    integrator: BristleIntegrator,
    /// Mean bristle displacement `z(n-1)`, m.
    z_m: f64,
    /// `zdot(n-1)`, m/s.
    y_m_per_s: f64,
    /// The last solve's `v~` and `z~`, and `(df/dv, df/dz, g')` at its last evaluation:
    /// the next solve starts from the tangent `y(n-1) - (f_v dv~ + f_z dz~) / g'`.
    last_tilde: (f64, f64),
    last_partials: [f64; 3],
    /// Relative velocity `v(n-1)`, m/s.
    v_m_per_s: f64,
    /// Newton stops once a step moves `y` by at most this times `max(1, |y|)`, m/s.
    newton_tolerance_m_per_s: f64,
    pub stats: SolverStats,
}

/// Normal-force-dependent constants for one sample.
#[derive(Debug, Clone, Copy)]
struct Curve {
    sigma0: f64,
    f_c: f64,
    f_s: f64,
    v_s: f64,
    z_ba: f64,
    elasto_plastic: bool,
    /// `1 / v_s` and `1 / sigma0`, for [`Curve::eval`] with `RECIPROCALS`.
    inv_v_s: f64,
    inv_sigma0: f64,
}

/// A contact whose Newton tolerance is looser than this (m/s) evaluates its curve with
/// reciprocals ([`Curve::eval`]'s `RECIPROCALS`): a division and a multiplication by the
/// reciprocal differ by an ulp or two, ten orders of magnitude below such a tolerance.
/// The reference tolerance ([`Y_TOLERANCE_M_PER_S`]) divides.
pub const RECIPROCALS_ABOVE_M_PER_S: f64 = 1e-6;

impl Curve {
    /// The root of `g(y) = f(v~ + k1 y, z~ + k2 y) - y` where it lies in the
    /// elasto-plastic bristle's elastic region, in closed form: there `f = v`, so `g` is
    /// linear and its root is `y = v~ / (1 - k1)` (`k1 < 0`), exact where the point it
    /// gives is elastic (against the slip, or at most the breakaway displacement). `None`
    /// for LuGre (no elastic region) or a root outside the region.
    #[inline(always)]
    fn elastic_root(&self, v_tilde: f64, k1: f64, z_tilde: f64, k2: f64) -> Option<f64> {
        if !self.elasto_plastic {
            return None;
        }
        let y = v_tilde / (1.0 - k1);
        let (v, z) = (v_tilde + k1 * y, z_tilde + k2 * y);
        let elastic = !(v * z > 0.0) || z.abs() <= self.z_ba;
        (elastic && y.is_finite()).then_some(y)
    }

    /// `f_NL(v, z)` and its partial derivatives `(f, df/dv, df/dz)`. With `RECIPROCALS`
    /// two divisions stand for the nine (by `v_s` and `sigma0` through their reciprocals,
    /// by `h` and the transition's width once each): the same function to an ulp or two,
    /// and a shorter chain of latencies in the Newton iteration.
    #[inline(always)]
    fn eval<const RECIPROCALS: bool>(&self, v: f64, z: f64) -> (f64, f64, f64) {
        let az = z.abs();
        let same_sign = v * z > 0.0;
        // The elasto-plastic bristle below its breakaway (or against the slip) is purely
        // elastic: alpha = 0 whatever the Stribeck curve, so it is not evaluated.
        if self.elasto_plastic && (!same_sign || az <= self.z_ba) {
            return (v, 1.0, 0.0);
        }
        // Stribeck: h(v) = f_c + (f_s - f_c) e^{-(v/v_s)^2}, |z_ss| = h / sigma0.
        let r = if RECIPROCALS {
            v * self.inv_v_s
        } else {
            v / self.v_s
        };
        let e = exp_nonpositive(-(r * r));
        let h = self.f_c + (self.f_s - self.f_c) * e;
        if h <= 0.0 {
            // No normal force: no bristle resistance.
            return (v, 1.0, 0.0);
        }
        let (dh, zss) = if RECIPROCALS {
            (
                (self.f_s - self.f_c) * e * (-2.0 * r * self.inv_v_s),
                h * self.inv_sigma0,
            )
        } else {
            (
                (self.f_s - self.f_c) * e * (-2.0 * r / self.v_s),
                h / self.sigma0,
            )
        };
        // alpha and its partials
        let (alpha, dalpha_dz, dalpha_dv) = if !self.elasto_plastic || az >= zss {
            (1.0, 0.0, 0.0)
        } else {
            let width = zss - self.z_ba;
            let pi = std::f64::consts::PI;
            let (theta, dtheta_dabsz, dtheta_dzss) = if RECIPROCALS {
                let inv_width = 1.0 / width;
                (
                    pi * (az - 0.5 * (zss + self.z_ba)) * inv_width,
                    pi * inv_width,
                    pi * (self.z_ba - az) * (inv_width * inv_width),
                )
            } else {
                (
                    pi * (az - 0.5 * (zss + self.z_ba)) / width,
                    pi / width,
                    pi * (self.z_ba - az) / (width * width),
                )
            };
            let (sin, c) = sin_cos_quarter_turn(theta);
            let dalpha_dv = if RECIPROCALS {
                0.5 * c * dtheta_dzss * dh * self.inv_sigma0
            } else {
                0.5 * c * dtheta_dzss * dh / self.sigma0
            };
            (
                0.5 * (1.0 + sin),
                0.5 * c * dtheta_dabsz * z.signum(),
                dalpha_dv,
            )
        };
        if alpha == 0.0 {
            return (v, 1.0, 0.0);
        }
        // f = v - alpha z |v| sigma0 / h   (z_ss carries the sign of v)
        let (phi, dphi_dv) = if RECIPROCALS {
            let inv_h = 1.0 / h;
            (
                v.abs() * self.sigma0 * inv_h,
                self.sigma0 * (v.signum() * h - v.abs() * dh) * (inv_h * inv_h),
            )
        } else {
            (
                v.abs() * self.sigma0 / h,
                self.sigma0 * (v.signum() * h - v.abs() * dh) / (h * h),
            )
        };
        let f = v - alpha * z * phi;
        let df_dz = -(dalpha_dz * z + alpha) * phi;
        let df_dv = 1.0 - z * (dalpha_dv * phi + alpha * dphi_dv);
        (f, df_dv, df_dz)
    }
}

impl BristleFriction {
    /// A contact for `sample_rate_hz`; rejects parameters outside the physical domain
    /// (notably `c >= 1`) with a clear error.
    pub fn new(
        params: BristleParams,
        law: BristleLaw,
        sample_rate_hz: f64,
    ) -> Result<Self, String> {
        params.validate()?;
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(format!("invalid sample rate {sample_rate_hz}"));
        }
        Ok(Self {
            params,
            law,
            half_period_s: 0.5 / sample_rate_hz,
            integrator: BristleIntegrator::Trapezoid,
            z_m: 0.0,
            y_m_per_s: 0.0,
            last_tilde: (0.0, 0.0),
            last_partials: NO_TANGENT,
            v_m_per_s: 0.0,
            newton_tolerance_m_per_s: Y_TOLERANCE_M_PER_S,
            stats: SolverStats::default(),
        })
    }

    /// Runs the contact at `sample_rate_hz` from now on (real-time safe; the state is
    /// reset). A rate that is not finite and positive is ignored.
    pub fn set_sample_rate(&mut self, sample_rate_hz: f64) {
        if sample_rate_hz.is_finite() && sample_rate_hz > 0.0 {
            self.half_period_s = 0.5 / sample_rate_hz;
            self.reset();
        }
    }

    /// Chooses the time discretisation of the bristle equation (real-time safe; the state
    /// carries over).
    pub fn set_integrator(&mut self, integrator: BristleIntegrator) {
        self.integrator = integrator;
    }

    pub fn integrator(&self) -> BristleIntegrator {
        self.integrator
    }

    /// Sets the Newton convergence tolerance on the step (m/s, relative above 1 m/s;
    /// default [`Y_TOLERANCE_M_PER_S`]); a tolerance that is not finite and positive is
    /// ignored. Looser tolerances trade accuracy for iterations (`colophony bench
    /// precision` measures both).
    pub fn set_newton_tolerance(&mut self, tolerance_m_per_s: f64) {
        if tolerance_m_per_s.is_finite() && tolerance_m_per_s > 0.0 {
            self.newton_tolerance_m_per_s = tolerance_m_per_s;
        }
    }

    pub fn newton_tolerance_m_per_s(&self) -> f64 {
        self.newton_tolerance_m_per_s
    }

    pub fn params(&self) -> BristleParams {
        self.params
    }

    pub fn law(&self) -> BristleLaw {
        self.law
    }

    pub fn set_law(&mut self, law: BristleLaw) {
        self.law = law;
    }

    /// Mean bristle displacement, m.
    pub fn bristle_displacement_m(&self) -> f64 {
        self.z_m
    }

    /// Relative (sliding) velocity `v_b - v_s` on the last sample, m/s.
    pub fn relative_velocity_m_per_s(&self) -> f64 {
        self.v_m_per_s
    }

    /// Breakaway displacement for a normal force, m.
    pub fn breakaway_displacement_m(&self, normal_force_n: f64) -> f64 {
        self.params.breakaway_ratio * self.params.mu_d * normal_force_n / self.params.sigma0_n_per_m
    }

    /// Takes over from another contact that was pushing with `force_n`: the bristles start
    /// deflected so that `sigma0 z = force_n` and at rest, so the force does not jump.
    pub fn take_over(&mut self, force_n: f64) {
        self.z_m = if force_n.is_finite() {
            force_n / self.params.sigma0_n_per_m
        } else {
            0.0
        };
        self.y_m_per_s = 0.0;
        self.last_partials = NO_TANGENT;
    }

    fn curve(&self, normal_force_n: f64) -> Curve {
        let p = &self.params;
        Curve {
            sigma0: p.sigma0_n_per_m,
            f_c: p.mu_d * normal_force_n,
            f_s: p.mu_s * normal_force_n,
            v_s: p.stribeck_m_per_s,
            z_ba: p.breakaway_ratio * p.mu_d * normal_force_n / p.sigma0_n_per_m,
            elasto_plastic: self.law == BristleLaw::ElastoPlastic,
            inv_v_s: 1.0 / p.stribeck_m_per_s,
            inv_sigma0: 1.0 / p.sigma0_n_per_m,
        }
    }

    /// Solves `g(y) = 0` (see the module doc); returns `y` and the Newton iteration count,
    /// or the fallback's evaluations of `g` if it was used.
    fn solve_y<const RECIPROCALS: bool>(
        &self,
        curve: &Curve,
        v_tilde: f64,
        k1: f64,
        z_tilde: f64,
        k2: f64,
        start: f64,
        partials: &Cell<[f64; 3]>,
    ) -> (f64, Result<u32, u32>) {
        let g = |y: f64| {
            let (f, dfv, dfz) = curve.eval::<RECIPROCALS>(v_tilde + k1 * y, z_tilde + k2 * y);
            let dg = dfv * k1 + dfz * k2 - 1.0;
            partials.set([dfv, dfz, dg]);
            (f - y, dg)
        };
        // Whether a step from `a` to `b` crosses the kink of `g` at `v = 0` (where `|v|`
        // and the adhesion map's sign test change the slope of `f` by up to `2 k1`).
        let crosses_kink = |a: f64, b: f64| (v_tilde + k1 * a) * (v_tilde + k1 * b) <= 0.0;
        // The bracket kept from every evaluation.
        let mut bracket = Bracket::default();
        let (gy, dg) = g(start);
        bracket.note(start, gy);
        let tolerance = self.newton_tolerance_m_per_s;
        let (y, gy) = match iterate(
            &g,
            &crosses_kink,
            tolerance,
            &mut bracket,
            (start, gy, dg),
            false,
            NEWTON_CAP,
        ) {
            Iterated::Root(y, iterations, _) => return (y, Ok(iterations)),
            Iterated::Stuck(y, gy, _) => (y, gy),
        };
        let first_step = gy.abs() / (1.0 - k1).max(1.0);
        let (root, evaluations) = bracketed_root(&g, &crosses_kink, y, first_step, tolerance);
        (root, Err(evaluations))
    }
}

/// How [`iterate`] ended.
enum Iterated {
    /// A root, after this many iterations and evaluations of `g`.
    Root(f64, u32, u32),
    /// No root within the cap, a step that is not finite, or (outside a bracket) no
    /// descent and no bracket: the last iterate, `g` there, and the evaluations spent.
    Stuck(f64, f64, u32),
}

/// The safeguarded Newton iteration of [`BristleFriction::solve_y`] (see the module doc)
/// from `(y, g(y), g'(y))`, for at most `cap - 1` iterations, narrowing `bracket` with
/// every evaluation. With `bracketing` it starts inside a known bracket (the fallback,
/// [`bracketed_root`]); otherwise it switches to the bracket where damped Newton finds no
/// descent and a bracket is known.
#[inline(always)]
fn iterate(
    g: &impl Fn(f64) -> (f64, f64),
    crosses_kink: &impl Fn(f64, f64) -> bool,
    tolerance_m_per_s: f64,
    bracket: &mut Bracket,
    (mut y, mut gy, mut dg): (f64, f64, f64),
    mut bracketing: bool,
    cap: u32,
) -> Iterated {
    let tolerance = |y: f64| tolerance_m_per_s * y.abs().max(1.0);
    // The last two steps' lengths inside the bracket.
    let (mut step_before, mut step_last) = (f64::INFINITY, f64::INFINITY);
    let mut evaluations = 0;
    for iteration in 1..cap {
        if !(gy.is_finite() && dg.is_finite()) {
            break;
        }
        if gy == 0.0 {
            return Iterated::Root(y, iteration, evaluations);
        }
        if dg == 0.0 {
            break;
        }
        let step = -gy / dg;
        let landed = y + step;
        if step.abs() <= tolerance(y) {
            // Converged: the full step is what the damped loop below accepts here
            // (near the root `|g|` falls along it), without evaluating `g` there;
            // unless it crosses the kink, where this side's slope says nothing about
            // the other's: the root is within the step only if `g` changes sign along
            // it, else the iteration goes on from the other side.
            if !crosses_kink(y, landed) {
                return Iterated::Root(landed, iteration, evaluations);
            }
            let (gl, dl) = g(landed);
            evaluations += 1;
            if gl == 0.0 || gl.signum() != gy.signum() {
                return Iterated::Root(landed, iteration, evaluations);
            }
            bracket.note(landed, gl);
            y = landed;
            gy = gl;
            dg = dl;
            continue;
        }
        if bracketing {
            let (lo, hi) = (bracket.lo, bracket.hi);
            // Bracketed: a full Newton step where it stays inside the bracket, goes
            // down `g` and is shorter than half the step before last (Numerical
            // Recipes' `rtsafe` rule), else false position with the Illinois
            // weighting. Newton climbs where `g` increases (the falling Stribeck slope
            // times `k1` can outweigh the rest of `g'` while the contact slips), and
            // damped steps there only find a minimum of `|g|`. False position, not
            // bisection: a bracket found by an overshooting first step (at a slip
            // onset) took up to ten halvings. A bracket as narrow as the tolerance
            // holds the root.
            let newton =
                dg < 0.0 && landed >= lo && landed <= hi && 2.0 * step.abs() <= step_before;
            let next = if newton {
                landed
            } else {
                let mid = 0.5 * (lo + hi);
                if hi - lo <= tolerance(mid) || mid == lo || mid == hi {
                    return Iterated::Root(mid, iteration, evaluations);
                }
                bracket.false_position()
            };
            step_before = step_last;
            step_last = (next - y).abs();
            y = next;
            (gy, dg) = g(y);
            evaluations += 1;
            bracket.note(y, gy);
            continue;
        }
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..=MAX_DAMPING_HALVINGS {
            let candidate = y + t * step;
            let (gc, dc) = g(candidate);
            evaluations += 1;
            if gc.is_finite() {
                bracket.note(candidate, gc);
                if gc.abs() < gy.abs() {
                    accepted = Some((candidate, gc, dc));
                    break;
                }
            }
            t *= 0.5;
        }
        let Some((candidate, gc, dc)) = accepted else {
            if bracket.known() {
                // No descent, but the evaluations so far bracket a root: narrow that
                // bracket from here on (below).
                bracketing = true;
                continue;
            }
            // No descent along a Newton step longer than the tolerance, and no
            // bracket yet: a kink; the bracketing fallback finds the root. (A short
            // damped step says nothing about the distance to the root: taking it for
            // convergence let the bristle drift by up to 2^9 tolerances a sample.)
            break;
        };
        let moved = (candidate - y).abs();
        // A step across the kink along which `g` kept its sign has not bracketed the
        // root, however short.
        let settles = gc.signum() != gy.signum() || !crosses_kink(y, candidate);
        y = candidate;
        gy = gc;
        dg = dc;
        // Only a full Newton step measures the remaining error; after a damped one the
        // next iteration's step does.
        if (t == 1.0 && settles && moved <= tolerance(y)) || gy == 0.0 {
            return Iterated::Root(y, iteration, evaluations);
        }
    }
    Iterated::Stuck(y, gy, evaluations)
}

/// A bracket of a root of `g`: `g(lo) > 0 > g(hi)`, `lo < hi` (infinite until both signs
/// have been seen in that order), narrowed by every evaluation of `g` inside it.
#[derive(Debug, Clone, Copy)]
struct Bracket {
    lo: f64,
    hi: f64,
    /// `g` at the ends as false position weighs them (Illinois: an end's value is halved
    /// each time the other end moves again).
    g_lo: f64,
    g_hi: f64,
    /// The end the last narrowing moved: -1 `lo`, 1 `hi`, 0 none yet.
    moved: i8,
}

impl Default for Bracket {
    fn default() -> Self {
        Self {
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
            g_lo: 0.0,
            g_hi: 0.0,
            moved: 0,
        }
    }
}

impl Bracket {
    /// Narrows the bracket with `g(y) = gy` (finite) where `y` lies inside it.
    #[inline(always)]
    fn note(&mut self, y: f64, gy: f64) {
        if !(y > self.lo && y < self.hi) {
            return;
        }
        if gy > 0.0 {
            if self.moved == -1 {
                self.g_hi *= 0.5;
            }
            (self.lo, self.g_lo, self.moved) = (y, gy, -1);
        } else if gy < 0.0 {
            if self.moved == 1 {
                self.g_lo *= 0.5;
            }
            (self.hi, self.g_hi, self.moved) = (y, gy, 1);
        }
    }

    #[inline(always)]
    fn known(&self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// The false-position point, or the middle where rounding puts it outside.
    fn false_position(&self) -> f64 {
        let x = self.lo + self.g_lo * (self.hi - self.lo) / (self.g_lo - self.g_hi);
        if x > self.lo && x < self.hi {
            x
        } else {
            0.5 * (self.lo + self.hi)
        }
    }
}

/// Bracketing fallback: `g` is positive for very negative `y` and negative for very
/// positive `y` (see the module doc), so walking from `start` in the direction of the sign
/// of `g`, in steps that double from `first_step`, finds a bracket `g(lo) > 0 >= g(hi)`.
/// Inside it, [`iterate`]'s bracketed iteration (Numerical Recipes' `rtsafe` rule for a
/// Newton step, else Illinois false position) from the end with the smaller `|g|`. Always
/// returns a finite value; also returns the evaluations of `g`.
fn bracketed_root(
    g: &impl Fn(f64) -> (f64, f64),
    crosses_kink: &impl Fn(f64, f64) -> bool,
    start: f64,
    first_step: f64,
    tolerance: f64,
) -> (f64, u32) {
    let start = if start.is_finite() { start } else { 0.0 };
    let (g0, d0) = g(start);
    let mut evaluations = 1;
    if g0 == 0.0 {
        return (start, evaluations);
    }
    // Walk in the direction of the sign of g (g > 0: the root is above).
    let dir = if g0 > 0.0 { 1.0 } else { -1.0 };
    let mut step = if first_step.is_finite() {
        first_step.max(1e-6)
    } else {
        1e-6
    };
    let (mut near, mut g_near, mut d_near) = (start, g0, d0);
    let mut far = None;
    for _ in 0..WALK_DOUBLINGS {
        let x = start + dir * step;
        let (gx, dx) = g(x);
        evaluations += 1;
        if !gx.is_finite() {
            break;
        }
        if gx * g0 <= 0.0 {
            far = Some((x, gx, dx));
            break;
        }
        (near, g_near, d_near) = (x, gx, dx);
        step *= 2.0;
    }
    let Some((far, g_far, d_far)) = far else {
        return (0.0, evaluations);
    };
    if g_far == 0.0 {
        return (far, evaluations);
    }
    // g(lo) > 0 > g(hi): the bracketed iteration from the end nearer the root by its
    // residual.
    let (lo, hi, g_lo, g_hi) = if dir > 0.0 {
        (near, far, g_near, g_far)
    } else {
        (far, near, g_far, g_near)
    };
    let mut bracket = Bracket {
        lo,
        hi,
        g_lo,
        g_hi,
        moved: 0,
    };
    let from = if g_near.abs() <= g_far.abs() {
        (near, g_near, d_near)
    } else {
        (far, g_far, d_far)
    };
    match iterate(
        g,
        crosses_kink,
        tolerance,
        &mut bracket,
        from,
        true,
        FALLBACK_CAP,
    ) {
        Iterated::Root(root, _, spent) => (root, evaluations + spent),
        // Only a step that is not finite ends here: the bracket's middle.
        Iterated::Stuck(_, _, spent) => (0.5 * (bracket.lo + bracket.hi), evaluations + spent),
    }
}

impl FrictionContact for BristleFriction {
    fn solve(&mut self, load: LoadLine, bow: BowInput) -> f64 {
        let f_n = bow.normal_force_n;
        let admittance = load.admittance_s_per_kg;
        let v_free = bow.velocity_m_per_s - load.free_velocity_m_per_s;
        if !(f_n > 0.0) || !v_free.is_finite() || !(admittance >= 0.0) {
            // Bow off the string: the bristles let go.
            self.z_m = 0.0;
            self.y_m_per_s = 0.0;
            self.last_partials = NO_TANGENT;
            self.v_m_per_s = if v_free.is_finite() { v_free } else { 0.0 };
            self.stats.last_iterations = 0;
            return 0.0;
        }
        let p = self.params;
        let curve = self.curve(f_n);
        let (k2, z_tilde) = match self.integrator {
            BristleIntegrator::Trapezoid => (
                self.half_period_s,
                self.z_m + self.half_period_s * self.y_m_per_s,
            ),
            BristleIntegrator::BackwardEuler => (2.0 * self.half_period_s, self.z_m),
        };
        let denominator = 1.0 + admittance * p.sigma2_kg_per_s;
        let v_tilde = (v_free - admittance * p.sigma0_n_per_m * z_tilde) / denominator;
        let k1 = -admittance * (p.sigma0_n_per_m * k2 + p.sigma1_kg_per_s) / denominator;
        // Tangent predictor: the last root moved along the implicit function's slope by
        // the change of `v~` and `z~` (`g = 0` gives `dy = -(f_v dv~ + f_z dz~) / g'`);
        // only where `g'` is clearly negative (`g` monotone there), else `y(n-1)`.
        let [f_v, f_z, slope] = self.last_partials;
        let previous = if self.y_m_per_s.is_finite() {
            self.y_m_per_s
        } else {
            0.0
        };
        let tangent = previous
            - (f_v * (v_tilde - self.last_tilde.0) + f_z * (z_tilde - self.last_tilde.1)) / slope;
        let start = if slope < -0.5 && tangent.is_finite() {
            tangent
        } else {
            previous
        };
        let partials = Cell::new(NO_TANGENT);
        let quick = self.newton_tolerance_m_per_s > RECIPROCALS_ABOVE_M_PER_S;
        let (y, iterations) = if !quick {
            self.solve_y::<false>(&curve, v_tilde, k1, z_tilde, k2, start, &partials)
        } else if let Some(y) = curve.elastic_root(v_tilde, k1, z_tilde, k2) {
            partials.set([1.0, 0.0, k1 - 1.0]);
            (y, Ok(1))
        } else {
            self.solve_y::<true>(&curve, v_tilde, k1, z_tilde, k2, start, &partials)
        };
        self.last_partials = partials.get();
        self.last_tilde = (v_tilde, z_tilde);
        match iterations {
            Ok(k) => {
                self.stats.histogram[(k as usize).min(NEWTON_CAP as usize)] += 1;
                self.stats.last_iterations = k;
            }
            Err(evaluations) => {
                self.stats.histogram[NEWTON_CAP as usize] += 1;
                self.stats.fallbacks += 1;
                self.stats.fallback_evaluations += u64::from(evaluations);
                self.stats.last_iterations = NEWTON_CAP;
            }
        }
        let v = v_tilde + k1 * y;
        let z = z_tilde + k2 * y;
        self.z_m = super::super::filters::flush_tiny(z);
        self.y_m_per_s = super::super::filters::flush_tiny(y);
        self.v_m_per_s = v;
        p.sigma0_n_per_m * z + p.sigma1_kg_per_s * y + p.sigma2_kg_per_s * v
    }

    fn is_sticking(&self) -> bool {
        self.v_m_per_s.abs() < STICK_FRACTION_OF_STRIBECK * self.params.stribeck_m_per_s
    }

    fn reset(&mut self) {
        self.z_m = 0.0;
        self.y_m_per_s = 0.0;
        self.last_partials = NO_TANGENT;
        self.v_m_per_s = 0.0;
        self.stats.last_iterations = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(elasto_plastic: bool) -> Curve {
        let p = BristleParams::modal_scenario();
        Curve {
            sigma0: p.sigma0_n_per_m,
            f_c: 0.2,
            f_s: 0.4,
            v_s: 0.1,
            z_ba: 0.7 * 0.2 / p.sigma0_n_per_m,
            elasto_plastic,
            inv_v_s: 1.0 / 0.1,
            inv_sigma0: 1.0 / p.sigma0_n_per_m,
        }
    }

    /// The curve and its partials, dividing (`false`) or through reciprocals (`true`).
    fn eval(c: &Curve, reciprocals: bool, v: f64, z: f64) -> (f64, f64, f64) {
        if reciprocals {
            c.eval::<true>(v, z)
        } else {
            c.eval::<false>(v, z)
        }
    }

    #[test]
    fn analytic_derivatives_match_finite_differences() {
        for (ep, reciprocals) in [(false, false), (true, false), (false, true), (true, true)] {
            let c = curve(ep);
            for &(v, z) in &[
                (0.05, 2.5e-5),
                (0.3, 1.8e-5),
                (-0.2, -3e-5),
                (0.01, 3.9e-5),
                (0.5, 1e-6),
            ] {
                let (_, dv, dz) = eval(&c, reciprocals, v, z);
                let hv = 1e-7;
                let hz = 1e-11;
                let f = |v, z| eval(&c, reciprocals, v, z).0;
                let nv = (f(v + hv, z) - f(v - hv, z)) / (2.0 * hv);
                let nz = (f(v, z + hz) - f(v, z - hz)) / (2.0 * hz);
                // 1e-5 relative: central differences in f64 at these steps
                assert!(
                    (dv - nv).abs() <= 1e-5 * nv.abs().max(1.0),
                    "ep {ep} v {v} z {z}: {dv} vs {nv}"
                );
                assert!(
                    (dz - nz).abs() <= 1e-5 * nz.abs().max(1.0),
                    "ep {ep} v {v} z {z}: {dz} vs {nz}"
                );
            }
        }
    }

    /// Over a grid of load lines (free slip velocity `v~`, predicted displacement `z~`, the
    /// string's admittance at 48 kHz), the elastic region's closed-form root is the root
    /// the dividing Newton iteration finds at the reference tolerance, to 1e-12 m/s (the
    /// iteration's own tolerance is 1e-10 relative), wherever it gives one; and wherever
    /// that root lies in the elastic region, the closed form gives it (it misses none).
    #[test]
    fn the_elastic_regions_closed_form_root_is_newtons_root() {
        let contact = BristleFriction::new(
            BristleParams::modal_scenario(),
            BristleLaw::ElastoPlastic,
            48e3,
        )
        .unwrap();
        let p = contact.params;
        let curve = contact.curve(1.0);
        let admittance = 1.0 / (2.0 * 0.55);
        let k2 = contact.half_period_s;
        let denominator = 1.0 + admittance * p.sigma2_kg_per_s;
        let k1 = -admittance * (p.sigma0_n_per_m * k2 + p.sigma1_kg_per_s) / denominator;
        let (mut closed, mut elastic_roots) = (0, 0);
        for i in -30..=30 {
            let v_tilde = 0.6 * f64::from(i) / 30.0;
            for j in -30..=30 {
                let z_tilde = 1.5 * curve.z_ba * f64::from(j) / 30.0;
                let partials = Cell::new(NO_TANGENT);
                let (newton, _) =
                    contact.solve_y::<false>(&curve, v_tilde, k1, z_tilde, k2, 0.0, &partials);
                let (v, z) = (v_tilde + k1 * newton, z_tilde + k2 * newton);
                // Clearly inside the region (not within rounding of its edge).
                let inside = !(v * z > 0.0) || z.abs() < curve.z_ba * (1.0 - 1e-9);
                match curve.elastic_root(v_tilde, k1, z_tilde, k2) {
                    Some(y) => {
                        closed += 1;
                        assert!(
                            (y - newton).abs() <= 1e-12,
                            "v~ {v_tilde}, z~ {z_tilde}: {y} against {newton}"
                        );
                    }
                    None => assert!(!inside, "v~ {v_tilde}, z~ {z_tilde}: missed {newton}"),
                }
                elastic_roots += usize::from(inside);
            }
        }
        // The grid reaches both regions.
        assert!(
            closed > 100 && closed < 61 * 61 - 100,
            "{closed} closed-form roots"
        );
        assert!(elastic_roots <= closed);
    }

    /// Over a grid of slip velocities and bristle displacements through every branch (the
    /// elastic region, the transition, the plastic side, both signs), the curve through
    /// reciprocals is the dividing one to rounding: each of the value and its partials
    /// within 1e-13 of the size of the terms it is made of (a few ulps of each of a dozen
    /// operations; `f = v - alpha z phi` and `df/dv = 1 - z (...)` are differences, so their
    /// terms, not the difference, set the scale). The good quality's Newton tolerance is
    /// 1e-4 m/s.
    #[test]
    fn the_curve_through_reciprocals_is_the_dividing_curve_to_rounding() {
        for ep in [false, true] {
            let c = curve(ep);
            let z_max = 1.5 * c.f_s / c.sigma0;
            let mut worst = [0.0f64; 3];
            for i in -40..=40 {
                let v = 0.5 * f64::from(i) / 40.0;
                for j in -40..=40 {
                    let z = z_max * f64::from(j) / 40.0;
                    let exact = eval(&c, false, v, z);
                    let quick = eval(&c, true, v, z);
                    let scales = [
                        v.abs() + (exact.0 - v).abs(),
                        1.0 + (exact.1 - 1.0).abs(),
                        exact.2.abs(),
                    ];
                    let differences = [
                        (exact.0 - quick.0).abs(),
                        (exact.1 - quick.1).abs(),
                        (exact.2 - quick.2).abs(),
                    ];
                    for k in 0..3 {
                        if differences[k] > 0.0 {
                            worst[k] = worst[k].max(differences[k] / scales[k]);
                        }
                    }
                }
            }
            println!(
                "ep {ep}: worst differences over the terms' size (f, df/dv, df/dz) {:.1e} {:.1e} {:.1e}",
                worst[0], worst[1], worst[2]
            );
            assert!(worst.iter().all(|&w| w < 1e-13), "{worst:?}");
        }
    }

    #[test]
    fn breakaway_ratio_of_one_or_more_is_rejected() {
        let p = BristleParams {
            breakaway_ratio: 1.0,
            ..BristleParams::modal_scenario()
        };
        let err = BristleFriction::new(p, BristleLaw::ElastoPlastic, 44_100.0).unwrap_err();
        assert!(err.contains("0 <= c < 1"), "{err}");
    }

    #[test]
    fn a_bristle_faster_than_a_sample_settles_with_backward_euler_and_rings_with_the_trapezoid() {
        // LuGre sliding steadily at 0.5 m/s against a stiff load (no string motion): the
        // bristle relaxes in h / (sigma0 |v|) = 4 us, a fifth of a sample at 48 kHz. Its
        // steady state is z_ss = h / sigma0; the trapezoid overshoots and alternates about
        // it (its factor for a relaxation faster than 2/T is negative), backward Euler
        // approaches it from one side.
        let deviations = |integrator| {
            let mut c = BristleFriction::new(
                BristleParams::waveguide_string(),
                BristleLaw::LuGre,
                48_000.0,
            )
            .unwrap();
            c.set_integrator(integrator);
            let load = LoadLine {
                free_velocity_m_per_s: 0.0,
                admittance_s_per_kg: 1e-6,
            };
            let bow = BowInput {
                velocity_m_per_s: 0.5,
                normal_force_n: 1.0,
            };
            let z_ss = 0.2 / 1e5; // h(0.5 m/s) = f_c (the Stribeck term is e^-25), / sigma0
            (0..8)
                .map(|_| {
                    c.solve(load, bow);
                    c.z_m / z_ss - 1.0
                })
                .collect::<Vec<f64>>()
        };
        let trapezoid = deviations(BristleIntegrator::Trapezoid);
        let backward = deviations(BristleIntegrator::BackwardEuler);
        println!("trapezoid {trapezoid:?}\nbackward Euler {backward:?}");
        // Per sample the deviation is multiplied by 1 / (1 + x) for backward Euler and by
        // (1 - x/2) / (1 + x/2) for the trapezoid, x = T sigma0 |v| / h ~ 5.2 here: backward
        // Euler decays monotonically by more than 5x a sample; the trapezoid flips sign
        // every sample (and would tend to -1, undamped, as x grows).
        for w in backward.windows(2) {
            assert!(w[0] * w[1] > 0.0 && w[1].abs() < 0.2 * w[0].abs(), "{w:?}");
        }
        for w in trapezoid.windows(2) {
            assert!(w[0] * w[1] < 0.0, "{w:?}");
        }
    }

    #[test]
    fn the_solution_satisfies_the_discretised_bristle_equation() {
        for integrator in [
            BristleIntegrator::Trapezoid,
            BristleIntegrator::BackwardEuler,
        ] {
            solution_satisfies_the_discretised_equation(integrator);
        }
    }

    #[test]
    fn every_solve_lands_within_its_tolerance_of_the_root() {
        // The stop must bound the distance to the root, at every tolerance the quality
        // presets use, through sticking (where |v| puts a kink in g at v = 0), the adhesion
        // map's corners and slipping, down to the light forces of a bow landing. Each
        // sample is also solved from the same state with a 1e-13 m/s tolerance, and the
        // two are compared in units of the tolerance (times max(1, |y|), the stop's own
        // scale). Where g is smooth over the last step, a step shorter than the tolerance
        // leaves an error of the order of its square; across the kink the stop accepts a
        // step only if g changes sign along it, so the root lies within it; the bisection
        // stops at a bracket one tolerance wide. So one tolerance, and the bound, 2, leaves
        // room for g's curvature within a step near the adhesion map's corners (measured:
        // 0.48 tolerances; 0.76 with a bristle three times stiffer). Without the kink test,
        // a stop that trusts a short step from the steep side of the kink, where the slope
        // is up to 2 |k1| steeper than on the other, misses by 4.6 tolerances at 1e-2 m/s,
        // and 50 with the stiffer bristle; one that takes a short damped step for
        // convergence misses by 80 to 460 tolerances at 1e-4 m/s, enough for the bristle
        // to drift and grow a violin E7 bowed at 0.15 N to a peak of 375.
        let mut worst = 0.0f64;
        for (law, params) in [BristleLaw::LuGre, BristleLaw::ElastoPlastic]
            .into_iter()
            .flat_map(|law| {
                [
                    BristleParams::waveguide_string(),
                    BristleParams::plugin_string(),
                ]
                .map(|p| (law, p))
            })
        {
            for integrator in [
                BristleIntegrator::Trapezoid,
                BristleIntegrator::BackwardEuler,
            ] {
                for tolerance in [1e-2, 1e-4, 1e-10] {
                    for (force_n, swing_m_per_s) in [
                        (0.02, 0.05),
                        (0.05, 0.1),
                        (0.15, 0.05),
                        (0.15, 0.4),
                        (1.1, 0.8),
                        (3.0, 0.2),
                    ] {
                        let mut c = BristleFriction::new(params, law, 48_000.0).unwrap();
                        c.set_integrator(integrator);
                        c.set_newton_tolerance(tolerance);
                        let bow = BowInput {
                            velocity_m_per_s: 0.1,
                            normal_force_n: force_n,
                        };
                        for n in 0..4000 {
                            let load = LoadLine {
                                free_velocity_m_per_s: swing_m_per_s * (n as f64 * 0.013).sin(),
                                admittance_s_per_kg: 1.0 / (2.0 * 0.18),
                            };
                            let mut reference = c.clone();
                            reference.set_newton_tolerance(1e-13);
                            reference.solve(load, bow);
                            c.solve(load, bow);
                            let y = c.y_m_per_s;
                            let error = (y - reference.y_m_per_s).abs() / y.abs().max(1.0);
                            worst = worst.max(error / tolerance);
                            assert!(
                                error <= 2.0 * tolerance,
                                "{law:?} sigma0 {} {integrator:?} tol {tolerance} F {force_n} \
                                 swing {swing_m_per_s}, sample {n}: |dy| {error:e}",
                                params.sigma0_n_per_m
                            );
                        }
                    }
                }
            }
        }
        println!("worst error: {worst:.2} tolerances");
    }

    fn solution_satisfies_the_discretised_equation(integrator: BristleIntegrator) {
        let mut c = BristleFriction::new(
            BristleParams::waveguide_string(),
            BristleLaw::ElastoPlastic,
            48_000.0,
        )
        .unwrap();
        c.set_integrator(integrator);
        let load_y = 1.0 / (2.0 * 0.506);
        for n in 0..2000 {
            let v_h = 0.8 * (n as f64 * 0.01).sin();
            let z_prev = c.z_m;
            let y_prev = c.y_m_per_s;
            let bow = BowInput {
                velocity_m_per_s: 0.1,
                normal_force_n: 1.1,
            };
            let f = c.solve(
                LoadLine {
                    free_velocity_m_per_s: v_h,
                    admittance_s_per_kg: load_y,
                },
                bow,
            );
            // the integrator, force law and load line all hold to rounding
            let p = c.params;
            let z = c.z_m;
            let y = c.y_m_per_s;
            let v = c.v_m_per_s;
            let step = match integrator {
                BristleIntegrator::Trapezoid => c.half_period_s * (y_prev + y),
                BristleIntegrator::BackwardEuler => 2.0 * c.half_period_s * y,
            };
            assert!((z - (z_prev + step)).abs() < 1e-15);
            let curve = c.curve(1.1);
            assert!((curve.eval::<false>(v, z).0 - y).abs() < 1e-8, "sample {n}");
            assert!(
                (f - (p.sigma0_n_per_m * z + p.sigma1_kg_per_s * y + p.sigma2_kg_per_s * v)).abs()
                    < 1e-12
            );
            assert!((v - (0.1 - v_h - load_y * f)).abs() < 1e-9, "sample {n}");
        }
    }
}
