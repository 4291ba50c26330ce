//! Paper B's bow hair under the string (eqs. 3-10; the module doc of [`super`]): the
//! nodes' state, structure of arrays, and their stick/slip solve for one sample, every
//! node independent within the sample, branch-free so the loop vectorises.
//!
//! Per node, vertically: a lumped junction loaded by the hair's mass on a parallel
//! spring-dashpot (trapezoid), giving the normal force `F_N = F_b + F_h^y`; horizontally:
//! the load line `v_s = v_s^p + F / (2 Z)` against the hair's compliance
//! `v_h = -a F + b`, sticking while `|F_stick| <= mu(T) F_N` (Friedlander's construction,
//! no iteration). [`super::ThermalString`] gathers the incoming waves into [`Nodes::vp`]
//! and [`Nodes::vp_y`], calls [`solve_nodes`] and scatters the forces.

use super::NodeReal;

/// Structure-of-arrays state of the contact nodes.
#[derive(Debug, Clone, Default)]
pub(super) struct Nodes {
    pub(super) hair_x: Vec<NodeReal>,
    pub(super) hair_v: Vec<NodeReal>,
    pub(super) vy: Vec<NodeReal>,
    pub(super) y: Vec<NodeReal>,
    pub(super) fy: Vec<NodeReal>,
    pub(super) force: Vec<NodeReal>,
    pub(super) v_delta: Vec<NodeReal>,
    pub(super) normal: Vec<NodeReal>,
    /// Incoming horizontal and vertical velocity per node (gathered each sample).
    pub(super) vp: Vec<NodeReal>,
    pub(super) vp_y: Vec<NodeReal>,
}

impl Nodes {
    pub(super) fn with_capacity(n: usize) -> Self {
        let v = || Vec::with_capacity(n);
        Self {
            hair_x: v(),
            hair_v: v(),
            vy: v(),
            y: v(),
            fy: v(),
            force: v(),
            v_delta: v(),
            normal: v(),
            vp: v(),
            vp_y: v(),
        }
    }

    /// `n` nodes at rest; never allocates within the capacity.
    pub(super) fn resize(&mut self, n: usize) {
        for v in [
            &mut self.hair_x,
            &mut self.hair_v,
            &mut self.vy,
            &mut self.y,
            &mut self.fy,
            &mut self.force,
            &mut self.v_delta,
            &mut self.normal,
            &mut self.vp,
            &mut self.vp_y,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
    }
}

/// Per-sample constants of the node solve (see [`super::ThermalString::tick_contact`]).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct NodeConsts {
    pub(super) dt: NodeReal,
    pub(super) a: NodeReal,
    pub(super) k_h: NodeReal,
    pub(super) k_y: NodeReal,
    pub(super) e_y: NodeReal,
    pub(super) inv_d_y: NodeReal,
    pub(super) inv_y_load: NodeReal,
    pub(super) inv_x_load: NodeReal,
    pub(super) half_y: NodeReal,
    pub(super) f_b: NodeReal,
    pub(super) v_b: NodeReal,
    pub(super) mu_cold: NodeReal,
    pub(super) mu_slope: NodeReal,
    pub(super) t_cold: NodeReal,
    pub(super) mu_lo: NodeReal,
    pub(super) mu_hi: NodeReal,
}

/// `a > b ? a : b`: one `maxpd` (`f64::max` adds NaN handling the solve does not need: its
/// inputs are finite, and a NaN would already have broken the string).
#[inline(always)]
fn max_fast(a: NodeReal, b: NodeReal) -> NodeReal {
    if a > b {
        a
    } else {
        b
    }
}

/// `a < b ? a : b`: one `minpd` (see [`max_fast`]).
#[inline(always)]
fn min_fast(a: NodeReal, b: NodeReal) -> NodeReal {
    if a < b {
        a
    } else {
        b
    }
}

/// The node state [`solve_nodes_body`] reads and writes, as separate slices: passed as
/// function arguments they are known not to overlap, so the vectorised loop needs no
/// run-time overlap checks before it starts.
#[inline(always)]
fn node_slices(nodes: &mut Nodes, n_b: usize) -> NodeSlices<'_> {
    NodeSlices {
        fy: &mut nodes.fy[..n_b],
        vy: &mut nodes.vy[..n_b],
        y: &mut nodes.y[..n_b],
        vp_y: &nodes.vp_y[..n_b],
        vp: &nodes.vp[..n_b],
        hair_x: &mut nodes.hair_x[..n_b],
        hair_v: &mut nodes.hair_v[..n_b],
        force: &mut nodes.force[..n_b],
        normal: &mut nodes.normal[..n_b],
        v_delta: &mut nodes.v_delta[..n_b],
    }
}

struct NodeSlices<'a> {
    fy: &'a mut [NodeReal],
    vy: &'a mut [NodeReal],
    y: &'a mut [NodeReal],
    vp_y: &'a [NodeReal],
    vp: &'a [NodeReal],
    hair_x: &'a mut [NodeReal],
    hair_v: &'a mut [NodeReal],
    force: &'a mut [NodeReal],
    normal: &'a mut [NodeReal],
    v_delta: &'a mut [NodeReal],
}

/// Every node's vertical junction and horizontal stick/slip solve for one sample: the
/// nodes are independent within a sample, so the loop runs over equal-length slices,
/// branch-free, and vectorises.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn solve_nodes_body(
    k: NodeConsts,
    fy_s: &mut [NodeReal],
    vy_s: &mut [NodeReal],
    y_s: &mut [NodeReal],
    vp_y: &[NodeReal],
    vp: &[NodeReal],
    hx: &mut [NodeReal],
    hv: &mut [NodeReal],
    force_s: &mut [NodeReal],
    normal_s: &mut [NodeReal],
    vd_s: &mut [NodeReal],
    temps: &[NodeReal],
) {
    let n_b = temps.len();
    let (fy_s, vy_s, y_s, vp_y, vp) = (
        &mut fy_s[..n_b],
        &mut vy_s[..n_b],
        &mut y_s[..n_b],
        &vp_y[..n_b],
        &vp[..n_b],
    );
    let (hx, hv, force_s, normal_s, vd_s) = (
        &mut hx[..n_b],
        &mut hv[..n_b],
        &mut force_s[..n_b],
        &mut normal_s[..n_b],
        &mut vd_s[..n_b],
    );
    for i in 0..n_b {
        // Vertical junction: the string and the hair mass move together.
        let rhs = -0.5 * fy_s[i] + k.e_y * vy_s[i] - k.k_y * y_s[i];
        let fy = (rhs * k.inv_d_y - vp_y[i]) * k.inv_y_load;
        let vy = vp_y[i] + fy * k.half_y;
        y_s[i] += 0.5 * k.dt * (vy + vy_s[i]);
        vy_s[i] = vy;
        fy_s[i] = fy;
        let f_n = max_fast(k.f_b + fy, 0.0);
        // Horizontal: Friedlander with the hair's compliance; the clamp is the stick/slip
        // decision (slip exactly when |F_stick| > mu F_N). mu(T) is ThermalParams::mu
        // written out with min/max.
        let b = -k.a * k.k_h * (hx[i] + 0.5 * k.dt * hv[i]);
        let mu = min_fast(
            max_fast(k.mu_cold + k.mu_slope * (temps[i] - k.t_cold), k.mu_lo),
            k.mu_hi,
        );
        let limit = mu * f_n;
        let f_stick = (k.v_b + b - vp[i]) * k.inv_x_load;
        let force = min_fast(max_fast(f_stick, -limit), limit);
        let v_h = -k.a * force + b;
        hx[i] += 0.5 * k.dt * (v_h + hv[i]);
        hv[i] = v_h;
        force_s[i] = force;
        normal_s[i] = f_n;
        // v_s - (v_b + v_h) = (F - F_stick)(1 / 2Z + a): exactly 0 while sticking.
        vd_s[i] = (force - f_stick) * (k.half_y + k.a);
    }
}

/// The same loop compiled for AVX2 (four lanes of f64 instead of SSE2's two); chosen at
/// run time. No FMA contraction happens (Rust keeps `a * b + c` as two roundings), so both
/// paths give bit-identical results.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn solve_nodes_avx2(k: NodeConsts, s: NodeSlices<'_>, temps: &[NodeReal]) {
    solve_nodes_body(
        k, s.fy, s.vy, s.y, s.vp_y, s.vp, s.hair_x, s.hair_v, s.force, s.normal, s.v_delta, temps,
    )
}

#[inline]
pub(super) fn solve_nodes(
    wide_simd: bool,
    k: NodeConsts,
    nodes: &mut Nodes,
    temps: &[NodeReal],
    n_b: usize,
) {
    let s = node_slices(nodes, n_b);
    let temps = &temps[..n_b];
    #[cfg(target_arch = "x86_64")]
    if wide_simd {
        // SAFETY: `wide_simd` is true only where AVX2 was detected at run time.
        unsafe { solve_nodes_avx2(k, s, temps) };
        return;
    }
    let _ = wide_simd;
    solve_nodes_body(
        k, s.fy, s.vy, s.y, s.vp_y, s.vp, s.hair_x, s.hair_v, s.force, s.normal, s.v_delta, temps,
    )
}

/// A sum in four interleaved partial sums (independent chains, so it vectorises instead
/// of waiting on one addition after another); deterministic for the same input.
#[inline]
pub(super) fn sum_lanes(x: &[NodeReal]) -> f64 {
    let mut acc = [0.0; 4];
    let chunks = x.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().map(|x| f64::from(*x)).sum();
    for c in chunks {
        for k in 0..4 {
            acc[k] += f64::from(c[k]);
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + rest
}
