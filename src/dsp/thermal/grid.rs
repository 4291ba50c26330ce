//! Paper B's thermal grid (eq. 1): the temperature of the string under and around the
//! bow, `dT/dt = alpha d2T/dx2 - C_C T |v_D| + C_H |f v_D|`, here with two terms paper B
//! does not have (both off when their parameters are zero, see [`ThermalParams`]): a
//! bulk cooling `- T / tau_b` and the heating referred to a reference load. By forward
//! Euler in time and centred differences in space (FTCS), on nodes `dx` apart covering
//! the bow plus a margin
//! each side, `T = 0` beyond. Stable only if `alpha dt / dx^2 < 1/2` (eq. 2): the
//! configuration sub-steps the update (`ceil(r / 0.45)` steps of `dt / n`), so it never
//! runs unstable.
//!
//! ```
//! use colophony::dsp::thermal::{HairParams, ThermalBowControl, ThermalParams};
//! use colophony::dsp::thermal::{ThermalString, ThermalStringSpec};
//! let mut s = ThermalString::new(ThermalStringSpec::cello_c(), 10, 0.01,
//!     ThermalParams::default(), HairParams::default()).unwrap();
//! let bow = ThermalBowControl { velocity_m_per_s: 0.15, force_n_per_m: 300.0, position_beta: 0.07 };
//! for _ in 0..2000 { s.tick(bow); }
//! // The slips heated the contact; the grid never goes below ambient.
//! assert!(s.temperature_grid().iter().any(|t| *t > 0.0));
//! assert!(s.temperature_grid().iter().all(|t| *t >= 0.0));
//! ```

use super::{NodeReal, ThermalParams};
use crate::dsp::filters::FLUSH_BELOW;

/// The temperature grid (margin, bow nodes, margin) and its update's constants. Allocated
/// once for a capacity; changing the layout never allocates.
#[derive(Debug, Clone)]
pub(super) struct ThermalGrid {
    temperature: Vec<NodeReal>,
    next: Vec<NodeReal>,
    capacity: usize,
    /// Grid nodes beyond each edge of the bow.
    margin: usize,
    /// FTCS sub-steps per sample.
    substeps: usize,
    consts: FtcsConsts,
    /// The heating constant at paper B's eq. (1) as written, before the load scaling.
    heat_per_load: NodeReal,
    /// Whether the heating is referred to a load (see [`ThermalParams::heating_scale`]).
    scales_with_load: bool,
    /// The load the current heating constant was scaled for, N/m.
    load: f64,
}

impl ThermalGrid {
    pub(super) fn with_capacity(capacity: usize) -> Self {
        Self {
            temperature: Vec::with_capacity(capacity),
            next: Vec::with_capacity(capacity),
            capacity,
            margin: 0,
            substeps: 1,
            consts: FtcsConsts::default(),
            heat_per_load: 0.0,
            scales_with_load: false,
            load: 0.0,
        }
    }

    /// Grid points allocated.
    pub(super) fn capacity(&self) -> usize {
        self.capacity
    }

    /// Sets the margin and the sub-step count (checked by the caller against the capacity
    /// and the FTCS bound); call [`ThermalGrid::cover`] and [`ThermalGrid::set_constants`]
    /// next.
    pub(super) fn set_layout(&mut self, margin: usize, substeps: usize) {
        self.margin = margin;
        self.substeps = substeps;
    }

    pub(super) fn substeps(&self) -> usize {
        self.substeps
    }

    /// Covers `n_b` bow nodes plus the margins, all at ambient. Never allocates within the
    /// capacity.
    pub(super) fn cover(&mut self, n_b: usize) {
        let grid = n_b + 2 * self.margin;
        for v in [&mut self.temperature, &mut self.next] {
            v.clear();
            v.resize(grid, 0.0);
        }
    }

    /// Eq. (1)'s sub-step constants at the internal rate `fs`, spacing `dx` and the
    /// current sub-step count.
    pub(super) fn set_constants(&mut self, p: &ThermalParams, dx: f64, fs: f64) {
        let h = 1.0 / fs / self.substeps as f64;
        let r = p.diffusivity_m2_per_s * h / (dx * dx);
        // The bulk loss's exact decay over one sub-step, capped so that no grid point
        // takes a negative weight of its old temperature (see [`FtcsConsts`]).
        let bulk = (-(-h * p.bulk_cooling_per_s).exp_m1()).min((1.0 - 2.0 * r).max(0.0));
        self.heat_per_load = (h * p.c_h_kelvin_m_per_j / dx) as NodeReal;
        self.scales_with_load = p.heating_reference_load_n_per_m > 0.0;
        self.load = 0.0;
        self.consts = FtcsConsts {
            r: r as NodeReal,
            heat: self.heat_per_load,
            cool: (h * p.c_c_per_m) as NodeReal,
            bulk: bulk as NodeReal,
            max_cool: (1.0 - 2.0 * r - bulk).max(0.0) as NodeReal,
        };
    }

    /// Refers the heating to the bow's load per metre `load` (N/m, positive) when the
    /// parameters ask for it: the heating constant times [`ThermalParams::heating_scale`],
    /// so the heat per unit of real contact area does not grow with the load. Divides only
    /// when the load changes; a compare when the heating is not referred to a load.
    #[inline(always)]
    pub(super) fn set_load(&mut self, p: &ThermalParams, load: f64) {
        if self.scales_with_load && load != self.load {
            self.load = load;
            self.consts.heat = (f64::from(self.heat_per_load) * p.heating_scale(load)) as NodeReal;
        }
    }

    /// The whole grid, K above ambient.
    pub(super) fn all(&self) -> &[NodeReal] {
        &self.temperature
    }

    /// The `n_b` points under the bow.
    #[inline(always)]
    pub(super) fn under_bow(&self, n_b: usize) -> &[NodeReal] {
        &self.temperature[self.margin..self.margin + n_b]
    }

    /// Back to ambient.
    pub(super) fn clear(&mut self) {
        self.temperature.fill(0.0);
    }

    /// Whether any point is above ambient.
    pub(super) fn any_warm(&self) -> bool {
        self.temperature.iter().any(|t| *t != 0.0)
    }

    /// One sample of eq. (1) by FTCS with the sub-steps the stability bound asks for:
    /// diffusion over the whole grid (branch-free interior), then the friction source and
    /// convective loss on the bow's nodes (`v_delta` and `force`, one per bow node).
    #[inline(always)]
    pub(super) fn update(&mut self, wide_simd: bool, v_delta: &[NodeReal], force: &[NodeReal]) {
        #[cfg(target_arch = "x86_64")]
        if wide_simd {
            // SAFETY: `wide_simd` is true only where AVX2 was detected at run time.
            unsafe { self.update_avx2(v_delta, force) };
            return;
        }
        let _ = wide_simd;
        self.update_body(v_delta, force)
    }

    /// [`ThermalGrid::update`] compiled for AVX2 (bit-identical: no FMA).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn update_avx2(&mut self, v_delta: &[NodeReal], force: &[NodeReal]) {
        self.update_body(v_delta, force)
    }

    #[inline(always)]
    fn update_body(&mut self, v_delta: &[NodeReal], force: &[NodeReal]) {
        for _ in 0..self.substeps {
            ftcs_step(
                self.consts,
                &self.temperature,
                &mut self.next,
                self.margin,
                v_delta,
                force,
            );
            std::mem::swap(&mut self.temperature, &mut self.next);
        }
    }
}

/// The per-sub-step constants of eq. (1) (set with the configuration): the FTCS ratio
/// `r = alpha h / dx^2`, the heating `h C_H / dx`, the cooling `h C_C` and the bulk
/// cooling `h / tau_b`, `h` the sub-step.
///
/// The losses `h C_C |v| T` and `h T / tau_b` are explicit: once `h C_C |v| + h / tau_b`
/// passes `1 - 2 r`, a node's new temperature would take a negative weight of its old one
/// (it would lose more heat than it holds, and beyond 2 the loss grows without bound: fast
/// slips on a coarse grid, a few m/s at N_B 1). The convective factor is therefore capped
/// at `max_cool = 1 - 2 r - h / tau_b`,
/// which keeps every weight of the update non-negative and their sum at most 1: the grid
/// obeys the maximum principle (never below ambient, never above what the heating put
/// in) at any slip velocity. Below the cap, which is every sample of ordinary playing,
/// the update is unchanged.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FtcsConsts {
    pub(super) r: NodeReal,
    pub(super) heat: NodeReal,
    pub(super) cool: NodeReal,
    pub(super) bulk: NodeReal,
    pub(super) max_cool: NodeReal,
}

/// [`flush_tiny`] (same threshold) for the grid's float type.
#[inline(always)]
fn flush_tiny_node(x: NodeReal) -> NodeReal {
    if x.abs() < FLUSH_BELOW as NodeReal {
        0.0
    } else {
        x
    }
}

/// One FTCS sub-step from `t` into `next` (the grid and the bow's `n_b` nodes from `off`);
/// slices as arguments, so the vectorised loops need no overlap checks.
#[inline(always)]
fn ftcs_step(
    k: FtcsConsts,
    t: &[NodeReal],
    next: &mut [NodeReal],
    off: usize,
    vd: &[NodeReal],
    force: &[NodeReal],
) {
    let FtcsConsts {
        r,
        heat,
        cool,
        bulk,
        max_cool,
    } = k;
    let n = t.len();
    let next = &mut next[..n];
    if n == 1 {
        next[0] = flush_tiny_node(t[0] * (1.0 - 2.0 * r) - bulk * t[0]);
    } else {
        next[0] = flush_tiny_node(t[0] + r * (t[1] - 2.0 * t[0]) - bulk * t[0]);
        // Tiny values are flushed to zero inside the loop (a select, which vectorises),
        // so no later step computes with subnormals.
        for (out, w) in next[1..n - 1].iter_mut().zip(t.windows(3)) {
            *out = flush_tiny_node(w[1] + r * (w[0] - 2.0 * w[1] + w[2]) - bulk * w[1]);
        }
        next[n - 1] = flush_tiny_node(t[n - 1] + r * (t[n - 2] - 2.0 * t[n - 1]) - bulk * t[n - 1]);
    }
    let n_b = vd.len();
    let bow = &mut next[off..off + n_b];
    let t_bow = &t[off..off + n_b];
    for (((out, tj), vd), f) in bow.iter_mut().zip(t_bow).zip(vd).zip(&force[..n_b]) {
        let v = vd.abs();
        *out = flush_tiny_node(*out + heat * f.abs() * v - (cool * v).min(max_cool) * tj);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The capped convective loss (see [`FtcsConsts`]): at a slip far beyond the cap (here
    /// `h C_C |v|` = 50) a hot node cools at most to ambient in one sub-step and never
    /// goes negative or grows; below the cap the loss is the explicit `h C_C |v| T`.
    #[test]
    fn the_convective_loss_never_takes_a_node_below_ambient() {
        let k = FtcsConsts {
            r: 0.2,
            heat: 0.0,
            cool: 0.5,
            bulk: 0.0,
            max_cool: 0.6,
        };
        let t = [0.0, 10.0, 10.0, 10.0, 0.0];
        let mut next = [0.0; 5];
        for (v, want_middle) in [
            // 0.5 * 0.1 = 0.05 below the cap: 10 + 0.2 * (10 - 20 + 10) - 0.05 * 10.
            (0.1, 9.5),
            // Capped at 0.6: 10 - 0.6 * 10 = 4 (uncapped: 10 - 50 * 10 = -490).
            (100.0, 4.0),
        ] {
            ftcs_step(k, &t, &mut next, 1, &[v; 3], &[1.0; 3]);
            // The grid is NodeReal (f32): an ulp at 10 K is 1e-6.
            assert!((next[2] - want_middle).abs() < 1e-5, "v {v}: {}", next[2]);
            assert!(
                next.iter().all(|x| *x >= 0.0 && *x <= 10.0),
                "v {v}: {next:?}"
            );
        }
    }
}
