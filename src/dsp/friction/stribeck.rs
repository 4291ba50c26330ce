//! The static Stribeck curve: friction as a function of the sliding velocity alone,
//! `mu(v) = mu_d + (mu_s - mu_d) exp(-(v / v_s)^2)`, the limit of the bristle models
//! ([`super::bristle`]) as `sigma0` goes to infinity with `sigma1 = sigma2 = 0`.
//!
//! Solved exactly each sample by Friedlander's construction: stick if the sticking force
//! `v_free / Y` is within `mu_s F_N`, else the sliding crossing of the load line
//! `v = v_free - Y F` with `F = sgn(v) mu(|v|) F_N`, i.e. a root `u = |v|` of
//! `q(u) = u + Y F_N mu(u) - |v_free|` in `(0, |v_free|]` (no root lies beyond: there
//! `q > 0`). With three crossings the hysteresis rule is the one of
//! [`super::HyperbolicFriction`]: a sticking contact keeps sticking while it can; a slipping
//! one takes the outer (largest `u`) crossing, found by scanning `q` down from
//! `|v_free|` on a grid and bisecting the first sign change to rounding.
//!
//! | symbol | meaning | unit | source |
//! |---|---|---|---|
//! | `mu_s`, `mu_d` | static and dynamic coefficients | 1 | paper A: 0.4, 0.2 |
//! | `v_s` | Stribeck velocity | m/s | paper A: 0.1 |
//!
//! ```
//! use colophony::dsp::friction::stribeck::StribeckFriction;
//! use colophony::dsp::friction::{BowInput, FrictionContact, LoadLine};
//! let mut contact = StribeckFriction::default();
//! let bow = BowInput { velocity_m_per_s: 0.1, normal_force_n: 1.0 };
//! // The string would move 1 m/s against the bow: it slides, and the friction lies
//! // between mu_d F_N and mu_s F_N, along the bow's motion.
//! let load = LoadLine { free_velocity_m_per_s: -1.0, admittance_s_per_kg: 0.1 };
//! let f = contact.solve(load, bow);
//! assert!(f >= contact.mu_d * 1.0 && f <= contact.mu_s * 1.0);
//! ```

use super::{BowInput, FrictionContact, LoadLine};

/// Grid cells used to scan for the outer crossing.
const SCAN_CELLS: usize = 32;

#[derive(Debug, Clone, Copy)]
pub struct StribeckFriction {
    pub mu_s: f64,
    pub mu_d: f64,
    pub stribeck_m_per_s: f64,
    sticking: bool,
}

impl Default for StribeckFriction {
    fn default() -> Self {
        Self {
            mu_s: 0.4,
            mu_d: 0.2,
            stribeck_m_per_s: 0.1,
            sticking: false,
        }
    }
}

impl StribeckFriction {
    pub fn mu(&self, abs_v: f64) -> f64 {
        let r = abs_v / self.stribeck_m_per_s;
        self.mu_d + (self.mu_s - self.mu_d) * (-(r * r)).exp()
    }

    /// Sets the sticking state (for a hand-over from another contact).
    pub fn set_sticking(&mut self, sticking: bool) {
        self.sticking = sticking;
    }

    fn outer_root(&self, abs_free: f64, admittance: f64, f_n: f64) -> Option<f64> {
        let q = |u: f64| u + admittance * f_n * self.mu(u) - abs_free;
        // q(abs_free) > 0 always; scan down for the first non-positive value.
        let mut hi = abs_free;
        for k in (0..SCAN_CELLS).rev() {
            let lo = abs_free * k as f64 / SCAN_CELLS as f64;
            if q(lo) <= 0.0 {
                let (mut a, mut b) = (lo, hi);
                // Bisect to 1e-12 relative (about 40 halvings of a grid cell).
                while b - a > 1e-12 * b {
                    let mid = 0.5 * (a + b);
                    if mid == a || mid == b {
                        break;
                    }
                    if q(mid) <= 0.0 {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                let u = 0.5 * (a + b);
                return (u > 0.0).then_some(u);
            }
            hi = lo;
        }
        None
    }
}

impl FrictionContact for StribeckFriction {
    fn solve(&mut self, load: LoadLine, bow: BowInput) -> f64 {
        let f_n = bow.normal_force_n;
        let admittance = load.admittance_s_per_kg;
        let v_free = bow.velocity_m_per_s - load.free_velocity_m_per_s;
        if !(f_n > 0.0 && admittance > 0.0 && v_free.is_finite()) {
            self.sticking = false;
            return 0.0;
        }
        let f_stick = v_free / admittance;
        let can_stick = f_stick.abs() <= self.mu_s * f_n;
        let slip = if can_stick && self.sticking {
            None
        } else {
            self.outer_root(v_free.abs(), admittance, f_n)
        };
        match slip {
            Some(u) => {
                self.sticking = false;
                v_free.signum() * f_n * self.mu(u)
            }
            None => {
                self.sticking = true;
                // Without a sliding crossing q(0) > 0, so the sticking force is in range.
                f_stick.clamp(-self.mu_s * f_n, self.mu_s * f_n)
            }
        }
    }

    fn is_sticking(&self) -> bool {
        self.sticking
    }

    fn reset(&mut self) {
        self.sticking = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sliding_force_lies_on_the_curve_and_the_load_line() {
        let mut c = StribeckFriction::default();
        let y = 1.0 / (2.0 * 0.506);
        for &v_h in &[-1.0, -0.5, 0.6, 1.3] {
            let load = LoadLine {
                free_velocity_m_per_s: v_h,
                admittance_s_per_kg: y,
            };
            let bow = BowInput {
                velocity_m_per_s: 0.1,
                normal_force_n: 1.1,
            };
            let f = c.solve(load, bow);
            assert!(!c.is_sticking());
            let v = 0.1 - v_h - y * f;
            // bisection to rounding
            assert!(
                (f - v.signum() * 1.1 * c.mu(v.abs())).abs() < 1e-9,
                "v_h {v_h}"
            );
        }
    }
}
