//! The string of paper B without its bow: travelling velocity waves in both transverse
//! polarisations (horizontal `h`, the bowing direction, and vertical `v`), one sample per
//! node spacing, a loss filter and a Thiran fractional delay per polarisation for the
//! tuning, real 2x2 reflections at the ends, its stored energy and sleep.
//!
//! Layout: the left-going wave at position `x` (samples from the bridge) and time `t` is
//! `left[(t - (m - 1 - x)) & mask]`, the right-going one `right[(x - t) & mask]`; the
//! waves never move in memory, and both indices grow with `x`, so the bow's nodes read and
//! write contiguous slices ([`Waves::gather`], [`Waves::scatter`]).

use super::NodeReal;
use crate::dsp::delay::{DelayLine, PluckShape};
use crate::dsp::filters::{flush_tiny, Allpass1, OnePoleLoss};

/// Both polarisations' delay lines, end filters and reflections, and their sleep state.
#[derive(Debug, Clone)]
pub(super) struct Waves {
    /// Delay lines per polarisation: `[h, v]`, rings of a power-of-two length.
    right: [DelayLine; 2],
    left: [DelayLine; 2],
    t: usize,
    /// Samples along the string (bridge at 0, nut at m - 1).
    m: usize,
    loss: [OnePoleLoss; 2],
    /// Thiran fractional delay at the nut, per polarisation (tuning).
    fraction: [Allpass1; 2],
    nut_reflection: [[f64; 2]; 2],
    bridge_reflection: [[f64; 2]; 2],
    /// Polarisations put to sleep ([`Waves::sleep_quiet`]): their lines and filters hold
    /// zeros and are not computed.
    asleep: [bool; 2],
    /// Sum of the squared waves a sleeping polarisation was offered and dropped (at the
    /// bridge and from the other polarisation at the nut), m^2/s^2.
    dropped: [f64; 2],
    /// Energy of dropped waves that wakes a sleeping polarisation, in the same units
    /// (`threshold fs / Z`).
    wake_sum: f64,
    /// The stopping finger's share of the nut's reflection: 1 while it presses, less while
    /// it leaves the string (`ThermalString::set_finger_reflection`).
    finger: f64,
    /// A light finger touching the string (a harmonic), [`Touch`]; `k` 0 touches nothing.
    touch: Touch,
}

/// A light finger between two samples: at `x + w1` samples from the bridge (`x` whole,
/// `w1` in `[0, 1)`), sensing the string's velocity interpolated there,
/// `v^ = (1 - w1) v_x + w1 v_x+1`, and pressing back `-R v^` shared between the two
/// samples with the same weights (a rank-one damper: it takes `R v^2` out and nothing
/// else, and leaves a mode with its node at `x + w1` all but untouched). `k` is
/// `rho / (1 + rho ((1 - w1)^2 + w1^2))` with `rho = R / 2Z`: each sample's waves gain
/// `-k w v^f` from the free interpolated velocity `v^f`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Touch {
    x: usize,
    w1: f64,
    k: f64,
}

/// Where the bow's `n` nodes sit in the rings this sample.
#[derive(Debug, Clone, Copy)]
pub(super) struct Span {
    right: usize,
    left: usize,
    n: usize,
    /// Neither ring wraps under the bow: the nodes are contiguous slices.
    contiguous: bool,
}

impl Waves {
    /// Silent lines of at least `ring` samples with the ends' reflections.
    pub(super) fn new(
        ring: usize,
        nut_reflection: [[f64; 2]; 2],
        bridge_reflection: [[f64; 2]; 2],
    ) -> Self {
        let line = DelayLine::new(ring);
        Self {
            right: [line.clone(), line.clone()],
            left: [line.clone(), line],
            t: 0,
            m: 0,
            loss: [OnePoleLoss::default(); 2],
            fraction: [Allpass1::new(0.0); 2],
            nut_reflection,
            bridge_reflection,
            asleep: [false; 2],
            dropped: [0.0; 2],
            wake_sum: f64::INFINITY,
            finger: 1.0,
            touch: Touch::default(),
        }
    }

    /// `ring - 1`: the longest half-loop is a few samples less.
    #[inline(always)]
    pub(super) fn mask(&self) -> usize {
        self.right[0].mask()
    }

    /// Samples along the string.
    pub(super) fn len(&self) -> usize {
        self.m
    }

    /// A new loop (configuration): `m` samples, fresh loss and Thiran filters.
    pub(super) fn set_loop(&mut self, m: usize, loss: OnePoleLoss, thiran: f64) {
        self.m = m;
        self.touch = Touch::default();
        self.loss = [loss; 2];
        self.fraction = [Allpass1::new(thiran); 2];
    }

    /// A new length (a stopped note): the filters' coefficients change, their states and
    /// the waves stay where they are.
    pub(super) fn retune(&mut self, m: usize, loss: OnePoleLoss, thiran: f64) {
        self.m = m;
        if self.touch.x + 2 >= m {
            self.touch = Touch::default();
        }
        for p in 0..2 {
            self.loss[p].retune(&loss);
            self.fraction[p].a = thiran;
        }
    }

    pub(super) fn nut_reflection(&self) -> [[f64; 2]; 2] {
        self.nut_reflection
    }

    /// The string grew from `old_m` samples to its present length (the finger left it):
    /// the new part, between the old stopping point and the nut, starts at rest.
    pub(super) fn rest_beyond(&mut self, old_m: usize) {
        let mask = self.mask();
        for p in 0..2 {
            for x in old_m..self.m {
                self.right[p][x.wrapping_sub(self.t) & mask] = 0.0;
                let i = self.left[p].back(self.t, x);
                self.left[p][i] = 0.0;
            }
        }
    }

    /// The stopping finger's share of the nut's reflection, 0..=1.
    pub(super) fn set_finger(&mut self, reflection: f64) {
        self.finger = reflection.clamp(0.0, 1.0);
    }

    /// A light finger at `at` samples from the bridge (between two samples, inside the
    /// string) of resistance `rho` times the string's two sides' `2 Z` ([`Touch`]), or
    /// none (`rho` 0).
    pub(super) fn set_touch(&mut self, at: f64, rho: f64) {
        let x = at.floor();
        self.touch = if rho > 0.0 && rho.is_finite() && x >= 1.0 && (x as usize) + 2 < self.m {
            let w1 = at - x;
            let w0 = 1.0 - w1;
            Touch {
                x: x as usize,
                w1,
                k: rho / (1.0 + rho * (w0 * w0 + w1 * w1)),
            }
        } else {
            Touch::default()
        };
    }

    /// Plucks the horizontal polarisation: adds the travelling waves of a string pulled
    /// aside into two straight lines meeting at `position_beta` of the delay lines'
    /// length (from the bridge), the kink rounded over `width` of it, and let go from
    /// rest. `slope_scale` is the displacement times the rate (m/s): the slopes `c y0'`
    /// are it over the distances to each end in samples. A displacement at rest is two
    /// waves of half its slope, `v_r = -c y0' / 2` and `v_l = c y0' / 2` (d'Alembert):
    /// they cancel in the string's velocity and carry its shape. The shape closes on the
    /// lines (the end filters' few samples of delay hold none of it). False (nothing
    /// added) if the lines are too short for the pluck.
    pub(super) fn pluck(&mut self, slope_scale: f64, position_beta: f64, width: f64) -> bool {
        let lines = self.m as f64;
        let Some(shape) = PluckShape::new(lines, lines, position_beta, width, slope_scale) else {
            return false;
        };
        let mask = self.mask();
        for k in 0..self.m {
            let slope = shape.slope(k);
            self.right[0][k.wrapping_sub(self.t) & mask] -= 0.5 * slope;
            let i = self.left[0].back(self.t, self.m - 1 - k);
            self.left[0][i] += 0.5 * slope;
        }
        self.asleep[0] = false;
        true
    }

    /// Where a finger touches, samples from the bridge (`None`: no finger).
    pub(super) fn touch_at(&self) -> Option<f64> {
        (self.touch.k > 0.0).then_some(self.touch.x as f64 + self.touch.w1)
    }

    pub(super) fn bridge_reflection(&self) -> [[f64; 2]; 2] {
        self.bridge_reflection
    }

    /// The ring positions of `n` nodes from position `start` (samples from the bridge).
    #[inline(always)]
    pub(super) fn span(&self, start: usize, n: usize) -> Span {
        let right = start.wrapping_sub(self.t) & self.mask();
        let left = self.left[0].back(self.t, self.m - 1 - start);
        Span {
            right,
            left,
            n,
            contiguous: right + n <= self.mask() + 1 && left + n <= self.mask() + 1,
        }
    }

    /// The velocity the incoming waves give each node, `[h, v]` into `vp` and `vp_y`.
    #[inline(always)]
    pub(super) fn gather(&self, s: Span, vp: &mut [NodeReal], vp_y: &mut [NodeReal]) {
        let n = s.n;
        if s.contiguous {
            let (r0, r1) = (
                &self.right[0][s.right..s.right + n],
                &self.right[1][s.right..s.right + n],
            );
            let (l0, l1) = (
                &self.left[0][s.left..s.left + n],
                &self.left[1][s.left..s.left + n],
            );
            for (((v, a), b), (vy, (c, d))) in vp[..n]
                .iter_mut()
                .zip(r0)
                .zip(l0)
                .zip(vp_y[..n].iter_mut().zip(r1.iter().zip(l1)))
            {
                *v = (a + b) as NodeReal;
                *vy = (c + d) as NodeReal;
            }
        } else {
            let (mut ir, mut il) = (s.right, s.left);
            for i in 0..n {
                vp[i] = (self.right[0][ir] + self.left[0][il]) as NodeReal;
                vp_y[i] = (self.right[1][ir] + self.left[1][il]) as NodeReal;
                ir = (ir + 1) & self.mask();
                il = (il + 1) & self.mask();
            }
        }
    }

    /// Adds each node's force to both travelling waves leaving it: `F / 2Z` each way
    /// (`half_y = 1 / 2Z`), horizontal `force`, vertical `force_y`.
    #[inline(always)]
    pub(super) fn scatter(
        &mut self,
        s: Span,
        force: &[NodeReal],
        force_y: &[NodeReal],
        half_y: f64,
    ) {
        let n = s.n;
        if s.contiguous {
            let [r0, r1] = &mut self.right;
            let [l0, l1] = &mut self.left;
            for (forces, r, l) in [(force, r0, l0), (force_y, r1, l1)] {
                let r = &mut r[s.right..s.right + n];
                let l = &mut l[s.left..s.left + n];
                for ((f, a), b) in forces[..n].iter().zip(r).zip(l) {
                    let dv = f64::from(*f) * half_y;
                    *a += dv;
                    *b += dv;
                }
            }
        } else {
            let (mut ir, mut il) = (s.right, s.left);
            for i in 0..n {
                let dv = f64::from(force[i]) * half_y;
                let dv_y = f64::from(force_y[i]) * half_y;
                self.right[0][ir] += dv;
                self.left[0][il] += dv;
                self.right[1][ir] += dv_y;
                self.left[1][il] += dv_y;
                ir = (ir + 1) & self.mask();
                il = (il + 1) & self.mask();
            }
        }
    }

    /// The horizontal velocity at position `x` (no bow there).
    #[inline(always)]
    pub(super) fn velocity_h(&self, x: usize) -> f64 {
        self.right[0][x.wrapping_sub(self.t) & self.mask()]
            + self.left[0][self.left[0].back(self.t, self.m - 1 - x)]
    }

    /// Adds `dv` (m/s) to both horizontal travelling waves leaving position `x`: a point
    /// force `F` there gives `F / 2Z` each way.
    pub(super) fn push_h(&mut self, x: usize, dv: f64) {
        let jr = x.wrapping_sub(self.t) & self.mask();
        let jl = self.left[0].back(self.t, self.m - 1 - x);
        self.right[0][jr] += dv;
        self.left[0][jl] += dv;
    }

    /// The `[h, v]` velocity waves arriving at the bridge this sample (after the loss
    /// filter). Once per sample, before [`Waves::finish_sample`].
    #[inline(always)]
    pub(super) fn arriving_at_bridge(&mut self) -> [f64; 2] {
        let i = self.left[0].back(self.t, self.m - 1);
        let mut out = [0.0; 2];
        for (p, out) in out.iter_mut().enumerate() {
            if !self.asleep[p] {
                *out = self.loss[p].tick(self.left[p][i]);
            }
        }
        out
    }

    /// Ends the sample: writes the waves leaving the bridge, reflects at the nut, and
    /// advances time.
    #[inline(always)]
    pub(super) fn finish_sample(&mut self, leaving_bridge: [f64; 2]) {
        let j = (self.m - 1).wrapping_sub(self.t) & self.mask();
        let mut at_nut = [0.0; 2];
        for p in 0..2 {
            if !self.asleep[p] {
                at_nut[p] = self.fraction[p].tick(self.right[p][j]);
            }
        }
        let rn = self.nut_reflection;
        let next = (self.t + 1) & self.mask();
        let bridge_end = 0usize.wrapping_sub(next) & self.mask();
        for p in 0..2 {
            let from_bridge = flush_tiny(leaving_bridge[p]);
            let from_nut = flush_tiny((rn[p][0] * at_nut[0] + rn[p][1] * at_nut[1]) * self.finger);
            if self.asleep[p] {
                // Dropped (the lines stay zero) until the dropped waves add up to the
                // wake threshold; this sample's waves then go in.
                self.dropped[p] += from_bridge * from_bridge + from_nut * from_nut;
                if self.dropped[p] < self.wake_sum {
                    continue;
                }
                self.asleep[p] = false;
            }
            self.right[p][bridge_end] = from_bridge;
            self.left[p][next] = from_nut;
        }
        self.t = next;
    }

    /// The touching finger, one sample ([`Touch`]): in both polarisations (a fingertip
    /// resists every way), each of its two samples' travelling waves gain `-k w v^f`, so
    /// the string there moves at `v + F / 2Z` with the finger's force `F`. It only takes
    /// energy out. Once per sample, before [`Waves::finish_sample`]; nothing without a
    /// finger.
    pub(super) fn touch_junction(&mut self) {
        let Touch { x, w1, k } = self.touch;
        if k == 0.0 {
            return;
        }
        let w0 = 1.0 - w1;
        let mask = self.mask();
        let (r0, r1) = (
            x.wrapping_sub(self.t) & mask,
            (x + 1).wrapping_sub(self.t) & mask,
        );
        let l0 = self.left[0].back(self.t, self.m - 1 - x);
        let l1 = self.left[0].back(self.t, self.m - 2 - x);
        for p in 0..2 {
            if !self.asleep[p] {
                let v_free = w0 * (self.right[p][r0] + self.left[p][l0])
                    + w1 * (self.right[p][r1] + self.left[p][l1]);
                let dv = -k * v_free;
                self.right[p][r0] += w0 * dv;
                self.left[p][l0] += w0 * dv;
                self.right[p][r1] += w1 * dv;
                self.left[p][l1] += w1 * dv;
            }
        }
    }

    /// Energy of each polarisation's waves and end filters, `[h, v]`, J, on a string of
    /// impedance `z` at rate `fs`.
    pub(super) fn energies_j(&self, z: f64, fs: f64) -> [f64; 2] {
        let mut out = [0.0; 2];
        for (p, out) in out.iter_mut().enumerate() {
            if !self.asleep[p] {
                *out = self.energy_until(p, z / fs, f64::INFINITY);
            }
        }
        out
    }

    /// Polarisation `p`'s energy, `scale` times the sum of the squares of its waves and
    /// its filter states, or a partial sum of at least `enough` as soon as the walk along
    /// the line reaches it (its terms are squares, and floating-point sums and products of
    /// non-negative numbers never fall: a comparison with `enough` decides as the whole sum
    /// would; a ringing string is known loud after a few samples).
    fn energy_until(&self, p: usize, scale: f64, enough: f64) -> f64 {
        let mask = self.mask();
        let mut sum = 0.0;
        for x in 0..self.m {
            let a = self.right[p][x.wrapping_sub(self.t) & mask];
            let b = self.left[p][self.left[p].back(self.t, self.m - 1 - x)];
            sum += a * a + b * b;
            if scale * sum >= enough {
                return scale * sum;
            }
        }
        sum += self.loss[p].stored_energy() + self.fraction[p].stored_energy();
        scale * sum
    }

    /// Puts each polarisation whose waves hold less than `threshold_j / 2` to sleep (see
    /// [`super::ThermalString::sleep_quiet_polarisations`]).
    pub(super) fn sleep_quiet(&mut self, threshold_j: f64, z: f64, fs: f64) {
        self.wake_sum = 0.5 * threshold_j * fs / z;
        for p in 0..2 {
            if !self.asleep[p]
                && self.energy_until(p, z / fs, 0.5 * threshold_j) < 0.5 * threshold_j
            {
                self.right[p].fill(0.0);
                self.left[p].fill(0.0);
                self.loss[p].reset();
                self.fraction[p].reset();
                self.asleep[p] = true;
                self.dropped[p] = 0.0;
            }
        }
    }

    /// `[h, v]`: which polarisations sleep.
    pub(super) fn asleep(&self) -> [bool; 2] {
        self.asleep
    }

    /// Both polarisations awake (a landing bow).
    #[inline(always)]
    pub(super) fn wake(&mut self) {
        self.asleep = [false; 2];
    }

    /// Silence: zero waves and filter states, both polarisations awake.
    pub(super) fn reset(&mut self) {
        for p in 0..2 {
            self.right[p].fill(0.0);
            self.left[p].fill(0.0);
            self.loss[p].reset();
            self.fraction[p].reset();
        }
        self.asleep = [false; 2];
        self.dropped = [0.0; 2];
    }
}
