//! Band-limited sample-rate conversion from a model's internal rate to the host rate
//! (paper B runs each string at `c / dx`, hundreds of kHz).
//!
//! A windowed-sinc interpolator evaluated at arbitrary (irrational) ratios: output sample
//! `n` sits at input position `p = n fs_in / fs_out`; it is
//! `y(n) = sum_k x(k) g h(g (p - k))` with `g = fc / fs_in * 2`, `h` a Kaiser-windowed sinc
//! (beta 8, half-width [`HALF_WIDTH`] zero crossings of the cut-off; 10 rather than 16
//! halves the cost, about 400 -> 250 taps per output sample from 541.6 kHz, for aliases
//! at -73 dB instead of -94 dB) and the cut-off `fc`
//! 0.45 of the lower of the two rates (its -6 dB point; flat to 0.8 of it). The kernel is
//! tabulated by phase: [`PHASES`] rows per input sample, each row the kernel's taps at one
//! fractional position, so an output sample is two dot products over a contiguous window
//! (the rows either side of its position) and a linear interpolation between them. It
//! pulls input on demand, so the model runs exactly as many internal samples as the output
//! needs. No allocation after `new`.
//!
//! From more than twice the output rate (paper B's hundreds of kHz) a first stage decimates
//! by an integer `D = floor(fs_in / (2 fs_out))` with a short linear-phase Kaiser FIR
//! (its pass band reaches past the sinc's transition band, 1.25 of the cut-off; its stop
//! band starts where a component would fold back into it, `fs_in / D - 1.25 fc`; 90 dB),
//! computed only once per `D` input samples, so the sinc above runs at `fs_in / D`,
//! between 2 and 4 times the output rate, with about a fifth of the taps. From 541.6 kHz to
//! 48 kHz: 59 FIR taps per 108.3 kHz sample (about 133 multiply-adds per output sample) and
//! 50 sinc taps per output sample, against 250 sinc taps in one stage.
//! Measured: aliasing and pass-band error in `tests` below.
//!
//! ```
//! use colophony::dsp::resample::Resampler;
//! // A 1 kHz sine at 108.3 kHz, heard at 48 kHz.
//! let mut r = Resampler::new(108_300.0, 48_000.0).unwrap();
//! let mut n = 0u64;
//! let mut out = vec![0.0; 4800];
//! r.process(|| { n += 1; (2.0 * std::f64::consts::PI * 1000.0 * n as f64 / 108_300.0).sin() }, &mut out);
//! let late = &out[2400..];
//! let peak = late.iter().fold(0.0f64, |m, x| m.max(x.abs()));
//! assert!((peak - 1.0).abs() < 0.01);
//! ```

use std::f64::consts::PI;

/// Zero crossings of the kernel on each side.
pub const HALF_WIDTH: usize = 10;
/// Table points per zero crossing.
pub const TABLE_STEPS: usize = 256;
/// Kernel rows per input sample of [`Resampler::process`]'s phase table: at most
/// [`TABLE_STEPS`] points per zero crossing wherever the kernel has at most one zero
/// crossing per input sample (always: its cut-off is at most 0.45 of the input rate).
pub const PHASES: usize = 256;
const KAISER_BETA: f64 = 8.0;

fn bessel_i0(x: f64) -> f64 {
    let (mut sum, mut term, mut k) = (1.0, 1.0, 1.0);
    while term > 1e-17 * sum {
        term *= (x / (2.0 * k)).powi(2);
        sum += term;
        k += 1.0;
    }
    sum
}

/// The Kaiser-windowed sinc `h(u)` for `u` in zero crossings, tabulated at
/// [`TABLE_STEPS`] points per zero crossing from 0 to `half_width` (two zeros past the end
/// so linear interpolation may read one beyond).
fn kaiser_sinc_table(half_width: usize, beta: f64) -> Vec<f64> {
    let n = half_width * TABLE_STEPS;
    let i0b = bessel_i0(beta);
    (0..=n + 1)
        .map(|i| kaiser_sinc(i as f64 / TABLE_STEPS as f64, half_width, beta, i0b))
        .collect()
}

/// The Kaiser-windowed sinc at `u` zero crossings (`i0b` = `I0(beta)`), 0 beyond the half
/// width.
fn kaiser_sinc(u: f64, half_width: usize, beta: f64, i0b: f64) -> f64 {
    let u = u.abs();
    if u >= half_width as f64 {
        return 0.0;
    }
    let sinc = if u == 0.0 {
        1.0
    } else {
        (PI * u).sin() / (PI * u)
    };
    let r = u / half_width as f64;
    sinc * bessel_i0(beta * (1.0 - r * r).sqrt()) / i0b
}

/// Zero crossings each side of the offline kernel of [`resample_whole`]: a long kernel
/// for a narrow transition band (analysis, not real time).
pub const WHOLE_HALF_WIDTH: usize = 64;
/// Cut-off of [`resample_whole`] as a fraction of the lower rate.
pub const WHOLE_CUTOFF: f64 = 0.475;
const WHOLE_KAISER_BETA: f64 = 10.0;

/// Converts a whole recorded signal to `output_rate_hz` with no delay: output sample `n` is
/// the band-limited input at time `n / output_rate_hz` exactly (the kernel is centred, the
/// samples before the start and after the end count as zero). For analysis: it compares
/// signals rendered at different rates on one time grid, so it may look ahead, and it uses
/// a long Kaiser-windowed sinc ([`WHOLE_HALF_WIDTH`] zero crossings each side, beta 10,
/// cut-off [`WHOLE_CUTOFF`] of the lower rate) whose transition band is about 3 % of the
/// cut-off wide: a 22.05 kHz signal keeps everything to 10.1 kHz.
pub fn resample_whole(
    input: &[f64],
    input_rate_hz: f64,
    output_rate_hz: f64,
) -> Result<Vec<f64>, String> {
    resample_whole_from(input, input_rate_hz, output_rate_hz, 0.0)
}

/// [`resample_whole`] with output sample `n` at input time `start_s + n / output_rate_hz`
/// (a signal known to lag by `start_s` comes out aligned).
pub fn resample_whole_from(
    input: &[f64],
    input_rate_hz: f64,
    output_rate_hz: f64,
    start_s: f64,
) -> Result<Vec<f64>, String> {
    if !(input_rate_hz.is_finite() && output_rate_hz.is_finite())
        || input_rate_hz <= 0.0
        || output_rate_hz <= 0.0
    {
        return Err(format!("invalid rates {input_rate_hz} -> {output_rate_hz}"));
    }
    let table = kaiser_sinc_table(WHOLE_HALF_WIDTH, WHOLE_KAISER_BETA);
    let ratio = input_rate_hz / output_rate_hz;
    // Zero crossings per input sample, and the kernel's reach in input samples.
    let g = 2.0 * WHOLE_CUTOFF * input_rate_hz.min(output_rate_hz) / input_rate_hz;
    let reach = WHOLE_HALF_WIDTH as f64 / g;
    if input.is_empty() || !start_s.is_finite() {
        return Ok(Vec::new());
    }
    let start = start_s * input_rate_hz;
    let frames = ((input.len() as f64 - start.max(0.0)) / ratio)
        .floor()
        .max(0.0) as usize;
    let steps = TABLE_STEPS as f64;
    let table_end = (WHOLE_HALF_WIDTH * TABLE_STEPS) as f64;
    Ok((0..frames)
        .map(|n| {
            let p = start + n as f64 * ratio;
            let first = (p - reach).ceil().max(0.0) as usize;
            let last = ((p + reach).floor() as usize).min(input.len() - 1);
            let mut acc = 0.0;
            for (k, x) in input.iter().enumerate().take(last + 1).skip(first) {
                let ax = (g * (p - k as f64)).abs() * steps;
                if ax < table_end {
                    let i = ax as usize;
                    let f = ax - i as f64;
                    acc += x * (table[i] + f * (table[i + 1] - table[i]));
                }
            }
            acc * g
        })
        .collect())
}

/// `sum x_i h_i` in four partial sums (the compiler vectorises them; a fixed order, so
/// the result is the same bits every run).
#[inline(always)]
fn dot(window: &[f64], taps: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let mut chunks = window.chunks_exact(4).zip(taps.chunks_exact(4));
    for (x, h) in &mut chunks {
        for l in 0..4 {
            acc[l] += x[l] * h[l];
        }
    }
    let tail = taps.len() / 4 * 4;
    let mut rest = 0.0;
    for (x, h) in window[tail..].iter().zip(&taps[tail..]) {
        rest += x * h;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + rest
}

/// `(sum x_i a_i, sum x_i b_i)` in one pass over `window`, four partial sums each (a
/// fixed order: the same bits every run).
#[inline(always)]
fn dot2(window: &[f64], a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = window.len().min(a.len()).min(b.len());
    let (window, a, b) = (&window[..n], &a[..n], &b[..n]);
    let mut acc_a = [0.0; 4];
    let mut acc_b = [0.0; 4];
    let tail = n / 4 * 4;
    for ((x, ha), hb) in window
        .chunks_exact(4)
        .zip(a.chunks_exact(4))
        .zip(b.chunks_exact(4))
    {
        for l in 0..4 {
            acc_a[l] += x[l] * ha[l];
            acc_b[l] += x[l] * hb[l];
        }
    }
    let (mut rest_a, mut rest_b) = (0.0, 0.0);
    for i in tail..n {
        rest_a += window[i] * a[i];
        rest_b += window[i] * b[i];
    }
    (
        (acc_a[0] + acc_a[1]) + (acc_a[2] + acc_a[3]) + rest_a,
        (acc_b[0] + acc_b[1]) + (acc_b[2] + acc_b[3]) + rest_b,
    )
}

/// Stage-1 stop-band attenuation, dB.
const DECIMATOR_ATTENUATION_DB: f64 = 90.0;
/// Stage-2 transition band, as a fraction of its cut-off, that stage 1 keeps flat.
const DECIMATOR_PASS: f64 = 1.25;

/// Stage 1: an integer decimator, a linear-phase FIR evaluated once per `factor` inputs.
#[derive(Debug, Clone)]
struct Decimator {
    /// `D`; 1 means no first stage.
    factor: usize,
    /// Taps in use (odd), at most `taps.len()`.
    len: usize,
    taps: Vec<f64>,
    /// Input ring stored twice (`i` and `i + ring`), so the newest `len` samples are one
    /// contiguous slice.
    ring: usize,
    history: Vec<f64>,
    pos: usize,
    /// Inputs taken since the last output.
    phase: usize,
}

impl Decimator {
    fn with_capacity(max_taps: usize) -> Self {
        let ring = max_taps.next_power_of_two().max(1);
        Self {
            factor: 1,
            len: 1,
            taps: vec![0.0; max_taps.max(1)],
            ring,
            history: vec![0.0; 2 * ring],
            pos: 0,
            phase: 0,
        }
    }

    /// Factor and taps for these rates (1 and 1 when one stage does).
    fn geometry(input_rate_hz: f64, output_rate_hz: f64) -> (usize, usize, f64, f64) {
        let factor = (input_rate_hz / (2.0 * output_rate_hz)).floor();
        if !(factor >= 2.0) {
            return (1, 1, 0.0, 0.0);
        }
        let stage2_rate = input_rate_hz / factor;
        let pass = DECIMATOR_PASS * 0.45 * output_rate_hz;
        let stop = stage2_rate - pass;
        // Kaiser's estimate of the length for this attenuation and transition width.
        let width = 2.0 * PI * (stop - pass) / input_rate_hz;
        let n = ((DECIMATOR_ATTENUATION_DB - 8.0) / (2.285 * width)).ceil() as usize + 1;
        let n = n | 1;
        (factor as usize, n, (pass + stop) / 2.0, input_rate_hz)
    }

    /// The most taps any input rate up to `max_input_rate_hz` needs (at every factor the
    /// stage-2 rate is at least twice the output, so the transition is at least
    /// 0.875 of the output rate wide).
    fn max_taps(max_input_rate_hz: f64, output_rate_hz: f64) -> usize {
        let width = 2.0 * PI * 0.875 * output_rate_hz / max_input_rate_hz;
        ((DECIMATOR_ATTENUATION_DB - 8.0) / (2.285 * width)).ceil() as usize + 3
    }

    /// Designs the FIR for these rates in place (no allocation); false if it needs more taps
    /// than allocated.
    fn configure(&mut self, input_rate_hz: f64, output_rate_hz: f64) -> bool {
        let (factor, len, cutoff, fs) = Self::geometry(input_rate_hz, output_rate_hz);
        if len > self.taps.len() || len > self.ring {
            return false;
        }
        self.factor = factor;
        self.len = len;
        if factor > 1 {
            let beta = 0.1102 * (DECIMATOR_ATTENUATION_DB - 8.7);
            let i0b = bessel_i0(beta);
            let half = (len - 1) as f64 / 2.0;
            let wc = 2.0 * cutoff / fs;
            let mut sum = 0.0;
            for (k, tap) in self.taps[..len].iter_mut().enumerate() {
                let u = k as f64 - half;
                let sinc = if u == 0.0 {
                    1.0
                } else {
                    (PI * wc * u).sin() / (PI * wc * u)
                };
                let r = u / half;
                *tap = wc * sinc * bessel_i0(beta * (1.0 - r * r).max(0.0).sqrt()) / i0b;
                sum += *tap;
            }
            // Unit gain at DC.
            for tap in &mut self.taps[..len] {
                *tap /= sum;
            }
        }
        self.reset();
        true
    }

    fn reset(&mut self) {
        self.history.fill(0.0);
        self.pos = 0;
        self.phase = 0;
    }

    /// Delay of stage 1 in input samples: output `j` is the filtered input at
    /// `j D - delay()` (it reads the `D` newest inputs, up to index `j D + D - 1`, and the
    /// FIR's centre lies `(len - 1) / 2` behind the newest).
    fn delay(&self) -> f64 {
        if self.factor > 1 {
            (self.len - 1) as f64 / 2.0 - (self.factor - 1) as f64
        } else {
            0.0
        }
    }

    /// One stage-1 output from the next `factor` inputs.
    #[inline(always)]
    fn next(&mut self, input: &mut impl FnMut() -> f64) -> f64 {
        if self.factor == 1 {
            return input();
        }
        let ring = self.ring;
        for _ in 0..self.factor {
            let x = input();
            self.pos = (self.pos + 1) & (ring - 1);
            self.history[self.pos] = x;
            self.history[self.pos + ring] = x;
        }
        // The newest `len` inputs, oldest first, end at `pos + ring`.
        let end = self.pos + ring + 1;
        let window = &self.history[end - self.len..end];
        // Four partial sums: the taps are symmetric, so order matters only for rounding.
        dot(window, &self.taps[..self.len])
    }
}

#[derive(Debug, Clone)]
pub struct Resampler {
    /// Stage 1 (see the module doc); the fields below are stage 2, whose input rate is
    /// the input rate over the decimation factor.
    decimator: Decimator,
    ratio: f64,
    /// Kernel scale: zero crossings per input sample.
    g: f64,
    /// The kernel by zero crossings ([`TABLE_STEPS`] points each), from which `rows` are
    /// built when the rate changes.
    table: Vec<f64>,
    /// `PHASES + 1` rows of `taps` coefficients (the gain `g` folded in): row `r` holds
    /// the kernel at taps `j = 0..taps` for an output whose position lies `r / PHASES`
    /// of an input sample before its window's first input.
    rows: Vec<f64>,
    taps: usize,
    /// Input ring stored twice (`i` and `i + ring`), so every window is one slice.
    ring: usize,
    history: Vec<f64>,
    /// Input samples pulled so far.
    pulled: u64,
    /// Output samples produced so far.
    produced: u64,
    half_in: f64,
    output_rate_hz: f64,
    /// Precomputed kernels for a fixed rational ratio ([`Resampler::fixed`]).
    poly: Option<Polyphase>,
}

/// Most output phases [`Resampler::fixed`] precomputes (48 -> 44.1 kHz needs 147).
const MAX_PHASES: usize = 1024;

/// Stage 2 for a ratio `p / q` (stage-2 input over output samples) with `q` small: output
/// `n` has its kernel's fractional position at phase `n mod q`, so each phase's taps are
/// computed once, exactly (no table interpolation), and an output sample is one dot
/// product over a contiguous window.
#[derive(Debug, Clone)]
struct Polyphase {
    p: u64,
    q: usize,
    taps: usize,
    /// `q` rows of `taps` coefficients, the gain `g` folded in.
    coeffs: Vec<f64>,
    /// First input of each phase's window, from the phase's base.
    offsets: Vec<u64>,
    /// Input ring stored twice (`i` and `i + len`).
    ring: Vec<f64>,
    len: usize,
    phase: usize,
    base: u64,
}

impl Polyphase {
    /// The kernels of ratio `p / q` for the scale `g` and half-width `half_in` (input
    /// samples), as [`Resampler::process`] would evaluate them.
    fn new(p: u64, q: usize, g: f64, half_in: f64) -> Self {
        let taps = (2.0 * half_in).floor() as usize + 2;
        let i0b = bessel_i0(KAISER_BETA);
        let h = |u: f64| kaiser_sinc(u, HALF_WIDTH, KAISER_BETA, i0b);
        let mut coeffs = vec![0.0; q * taps];
        let mut offsets = vec![0u64; q];
        for j in 0..q {
            // Output n = m q + j sits at input m p + j p / q; its window starts at the
            // first input at or after it.
            let first = (j as u64 * p).div_ceil(q as u64);
            offsets[j] = first;
            let frac = j as f64 * p as f64 / q as f64 - first as f64;
            for k in 0..taps {
                coeffs[j * taps + k] = g * h(g * (frac + half_in - k as f64));
            }
        }
        let len = taps.next_power_of_two();
        Self {
            p,
            q,
            taps,
            coeffs,
            offsets,
            ring: vec![0.0; 2 * len],
            len,
            phase: 0,
            base: 0,
        }
    }

    fn reset(&mut self) {
        self.ring.fill(0.0);
        self.phase = 0;
        self.base = 0;
    }
}

/// `(p, q)` with `ratio = p / q`, `q <= MAX_PHASES`, if there is one (to 1e-9).
fn rational(ratio: f64) -> Option<(u64, usize)> {
    (1..=MAX_PHASES).find_map(|q| {
        let p = (ratio * q as f64).round();
        ((ratio * q as f64 - p).abs() < 1e-9 * p.max(1.0) && p >= 1.0).then_some((p as u64, q))
    })
}

impl Resampler {
    pub fn new(input_rate_hz: f64, output_rate_hz: f64) -> Result<Self, String> {
        Self::with_capacity(input_rate_hz, output_rate_hz, input_rate_hz)
    }

    /// A resampler for one fixed pair of rates: where their ratio (after stage 1) is a
    /// fraction with a denominator up to `MAX_PHASES` (every pair of the usual rates),
    /// the kernel of each output phase is precomputed and an output sample costs one dot
    /// product (half of [`Resampler::new`]'s two over the phase table). The same output to
    /// the table's interpolation error.
    pub fn fixed(input_rate_hz: f64, output_rate_hz: f64) -> Result<Self, String> {
        let mut r = Self::new(input_rate_hz, output_rate_hz)?;
        if let Some((p, q)) = rational(r.ratio) {
            r.poly = Some(Polyphase::new(p, q, r.g, r.half_in));
        }
        Ok(r)
    }

    /// A resampler whose input rate may later change, without allocating, to any rate up
    /// to `max_input_rate_hz` ([`Resampler::set_input_rate`]).
    pub fn with_capacity(
        input_rate_hz: f64,
        output_rate_hz: f64,
        max_input_rate_hz: f64,
    ) -> Result<Self, String> {
        let valid = |r: f64| r.is_finite() && r > 0.0;
        if !(valid(input_rate_hz) && valid(output_rate_hz) && valid(max_input_rate_hz))
            || input_rate_hz > max_input_rate_hz
        {
            return Err(format!("invalid rates {input_rate_hz} -> {output_rate_hz}"));
        }
        let table = kaiser_sinc_table(HALF_WIDTH, KAISER_BETA);
        // The kernel spans the most input samples at the highest single-stage input rate:
        // below four times the output rate (above it stage 1 brings the rate under that).
        let (_, _, widest) =
            Self::geometry(max_input_rate_hz.min(4.0 * output_rate_hz), output_rate_hz);
        let max_taps = Self::taps(widest);
        let ring = max_taps.next_power_of_two();
        let mut r = Self {
            decimator: Decimator::with_capacity(Decimator::max_taps(
                max_input_rate_hz,
                output_rate_hz,
            )),
            ratio: 1.0,
            g: 1.0,
            table,
            rows: vec![0.0; (PHASES + 1) * max_taps],
            taps: max_taps,
            ring,
            history: vec![0.0; 2 * ring],
            pulled: 0,
            produced: 0,
            half_in: 1.0,
            output_rate_hz,
            poly: None,
        };
        r.set_input_rate(input_rate_hz)?;
        Ok(r)
    }

    /// Taps of a window for a kernel `half_in` input samples wide each side: its inputs
    /// lie within `half_in` of the output's position, `floor(2 half_in) + 1` of them at
    /// most.
    fn taps(half_in: f64) -> usize {
        (2.0 * half_in).floor() as usize + 1
    }

    /// Ratio, kernel scale and half-width in input samples for these rates.
    fn geometry(input_rate_hz: f64, output_rate_hz: f64) -> (f64, f64, f64) {
        let ratio = input_rate_hz / output_rate_hz;
        let cutoff = 0.45 * input_rate_hz.min(output_rate_hz);
        let g = 2.0 * cutoff / input_rate_hz;
        (ratio, g, HALF_WIDTH as f64 / g)
    }

    /// Changes the input rate and clears the history. Never allocates; refuses a rate whose
    /// kernel would not fit the history allocated by [`Resampler::with_capacity`].
    pub fn set_input_rate(&mut self, input_rate_hz: f64) -> Result<(), &'static str> {
        if !(input_rate_hz.is_finite() && input_rate_hz > 0.0) {
            return Err("invalid input rate");
        }
        let (factor, ..) = Decimator::geometry(input_rate_hz, self.output_rate_hz);
        let stage2_rate = input_rate_hz / factor as f64;
        let (ratio, g, half_in) = Self::geometry(stage2_rate, self.output_rate_hz);
        let taps = Self::taps(half_in);
        if taps > self.ring
            || (PHASES + 1) * taps > self.rows.len()
            || !self.decimator.configure(input_rate_hz, self.output_rate_hz)
        {
            return Err("input rate beyond the resampler's capacity");
        }
        self.ratio = ratio;
        self.g = g;
        self.half_in = half_in;
        self.taps = taps;
        // Each coefficient from the zero-crossing table, linearly interpolated (about
        // 25 000 lookups at the widest kernel: no Bessel function on the audio thread).
        let steps = TABLE_STEPS as f64;
        let table_end = (HALF_WIDTH * TABLE_STEPS) as f64;
        for (r, row) in self.rows[..(PHASES + 1) * taps]
            .chunks_exact_mut(taps)
            .enumerate()
        {
            let frac = r as f64 / PHASES as f64;
            for (j, c) in row.iter_mut().enumerate() {
                let ax = (g * (half_in - j as f64 - frac)).abs() * steps;
                *c = if ax < table_end {
                    let i = ax as usize;
                    let f = ax - i as f64;
                    g * (self.table[i] + f * (self.table[i + 1] - self.table[i]))
                } else {
                    0.0
                };
            }
        }
        // Precomputed kernels belong to one ratio (only `fixed` makes them).
        self.poly = None;
        self.reset();
        Ok(())
    }

    /// How far the model runs ahead of the output, in output samples: output `n` is the
    /// band-limited input at output time `n + latency_samples()`. The sinc pulls its
    /// input half its width ahead; stage 1's linear-phase FIR gives back its own delay.
    pub fn latency_samples(&self) -> f64 {
        let stage1_in_stage2_samples = self.decimator.delay() / self.decimator.factor as f64;
        (self.half_in - stage1_in_stage2_samples) / self.ratio
    }

    pub fn reset(&mut self) {
        self.decimator.reset();
        self.history.fill(0.0);
        self.pulled = 0;
        self.produced = 0;
        if let Some(poly) = &mut self.poly {
            poly.reset();
        }
    }

    /// Fills `out`, pulling input samples from `input` as needed (the model runs
    /// [`Self::latency_samples`] ahead of the output).
    #[inline(always)]
    pub fn process(&mut self, mut input: impl FnMut() -> f64, out: &mut [f64]) {
        if let Some(poly) = &mut self.poly {
            let mask = poly.len - 1;
            for y in out {
                let first = poly.base + poly.offsets[poly.phase];
                let end = first + poly.taps as u64;
                while self.pulled < end {
                    let x = self.decimator.next(&mut input);
                    let i = self.pulled as usize & mask;
                    poly.ring[i] = x;
                    poly.ring[i + poly.len] = x;
                    self.pulled += 1;
                }
                let start = first as usize & mask;
                let window = &poly.ring[start..start + poly.taps];
                let row = &poly.coeffs[poly.phase * poly.taps..(poly.phase + 1) * poly.taps];
                *y = super::filters::flush_tiny(dot(window, row));
                poly.phase += 1;
                if poly.phase == poly.q {
                    poly.phase = 0;
                    poly.base += poly.p;
                }
                self.produced += 1;
            }
            return;
        }
        let (ring, taps) = (self.ring, self.taps);
        let mask = ring - 1;
        let phases = PHASES as f64;
        for y in out {
            // This output's position in input samples, delayed by the half-width so the
            // kernel never needs the future: its window is the `taps` inputs from the
            // first at or after `p`.
            let p = self.produced as f64 * self.ratio;
            let first = p.ceil();
            // In [0, PHASES): `first - p` is below one sample.
            let phase = (first - p) * phases;
            let first = first as u64;
            // The newest input the kernel reaches; the window's last tap lies one past it
            // where `first - p` exceeds the fraction of `2 half_in`, and reads zero there.
            let newest = (p + 2.0 * self.half_in).floor() as u64;
            while self.pulled <= newest {
                let x = self.decimator.next(&mut input);
                let i = self.pulled as usize & mask;
                self.history[i] = x;
                self.history[i + ring] = x;
                self.pulled += 1;
            }
            if self.pulled < first + taps as u64 {
                let i = self.pulled as usize & mask;
                self.history[i] = 0.0;
                self.history[i + ring] = 0.0;
            }
            let r = phase as usize;
            let f = phase - r as f64;
            let start = first as usize & mask;
            let window = &self.history[start..start + taps];
            let (a, b) = dot2(
                window,
                &self.rows[r * taps..(r + 1) * taps],
                &self.rows[(r + 1) * taps..(r + 2) * taps],
            );
            *y = super::filters::flush_tiny(a + f * (b - a));
            self.produced += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tone_through(fs_in: f64, fs_out: f64, f: f64) -> f64 {
        let mut r = Resampler::new(fs_in, fs_out).unwrap();
        let mut n = 0u64;
        let mut out = vec![0.0; 8192];
        r.process(
            || {
                let x = (2.0 * PI * f * n as f64 / fs_in).sin();
                n += 1;
                x
            },
            &mut out,
        );
        let tail = &out[1024..];
        (tail.iter().map(|x| x * x).sum::<f64>() / tail.len() as f64).sqrt() * 2f64.sqrt()
    }

    /// The precomputed kernels of `fixed` are the phase table's kernels evaluated exactly:
    /// the outputs agree to the tables' linear interpolation error (256 points per zero
    /// crossing, then 256 rows a sample: 5e-6 to 1e-5 of this signal of peak 1.5
    /// measured, 3e-5 allowed, the bound of the test above with room), at every
    /// pair of rates the point strings meet, stage 1 included (8 kHz).
    #[test]
    fn the_fixed_resampler_gives_the_phase_tables_output() {
        for out_rate in [
            8_000.0, 22_050.0, 44_100.0, 88_200.0, 96_000.0, 176_400.0, 192_000.0, 384_000.0,
        ] {
            let mut table = Resampler::new(48_000.0, out_rate).unwrap();
            let mut fixed = Resampler::fixed(48_000.0, out_rate).unwrap();
            assert!(
                fixed.poly.is_some(),
                "{out_rate}: 48 kHz over it is a small fraction"
            );
            assert_eq!(table.latency_samples(), fixed.latency_samples());
            let signal = |n: u64| (0.37 * n as f64).sin() + 0.5 * (0.013 * n as f64).cos();
            let (mut a, mut b) = (vec![0.0; 4000], vec![0.0; 4000]);
            let mut n = 0;
            table.process(
                || {
                    n += 1;
                    signal(n)
                },
                &mut a,
            );
            let mut n = 0;
            fixed.process(
                || {
                    n += 1;
                    signal(n)
                },
                &mut b,
            );
            let worst = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            println!("48000 -> {out_rate}: outputs differ by {worst:.2e}");
            assert!(worst < 3e-5, "{out_rate}: outputs differ by {worst}");
        }
        // An irrational ratio keeps the phase table.
        assert!(Resampler::fixed(48_000.0, 44_100.0 * 2f64.sqrt())
            .unwrap()
            .poly
            .is_none());
    }

    /// The phase table's output against the kernel's definition,
    /// `y(n) = g sum_k x(k) h(g (n ratio + half_in - k))` with `h` evaluated exactly, at
    /// one-stage ratios down (the thermal cello's 90.3 kHz, 96 kHz) and up (27 kHz, an
    /// irrational 62.2 kHz) to 48 and 44.1 kHz.
    #[test]
    fn the_phase_table_gives_the_kernels_definition() {
        let i0b = bessel_i0(KAISER_BETA);
        let signal = |k: u64| (0.37 * k as f64).sin() + 0.5 * (0.013 * k as f64).cos();
        for (fs_in, fs_out) in [
            (90_316.0, 48_000.0),
            (96_000.0, 44_100.0),
            (27_000.0, 48_000.0),
            (44_100.0 * 2f64.sqrt(), 48_000.0),
        ] {
            let mut r = Resampler::new(fs_in, fs_out).unwrap();
            assert_eq!(r.decimator.factor, 1, "{fs_in}: one stage");
            let mut k = 0;
            let mut out = vec![0.0; 3000];
            r.process(
                || {
                    let x = signal(k);
                    k += 1;
                    x
                },
                &mut out,
            );
            let (g, half_in) = (r.g, r.half_in);
            let worst = out
                .iter()
                .enumerate()
                .map(|(n, y)| {
                    let centre = n as f64 * r.ratio + half_in;
                    let lo = (centre - half_in).ceil() as u64;
                    let hi = (centre + half_in).floor() as u64;
                    let exact: f64 = (lo..=hi)
                        .map(|k| {
                            signal(k)
                                * g
                                * kaiser_sinc(g * (centre - k as f64), HALF_WIDTH, KAISER_BETA, i0b)
                        })
                        .sum();
                    (y - exact).abs()
                })
                .fold(0.0, f64::max);
            println!("{fs_in} -> {fs_out}: worst {worst:.2e}");
            // Each coefficient passes two linear interpolations (the zero-crossing table,
            // 256 points a crossing, then the rows, 256 a sample): each is off by at most
            // `max |h''| d^2 / 8`, about 1.5e-5 of the kernel's peak at d = 1/256 of a
            // crossing, and the errors of 20-40 taps mostly cancel. 2e-5 of this signal
            // (peak 1.5) is -97 dB; measured 1.5e-6 to 7.9e-6.
            assert!(worst < 2e-5, "{fs_in} -> {fs_out}: {worst:.2e}");
        }
    }

    #[test]
    fn whole_signal_resampling_has_no_delay_and_a_flat_pass_band() {
        // A 22.05 kHz and a 384 kHz rendering of the same tones land on one 48 kHz grid.
        for fs_in in [22_050.0, 384_000.0] {
            let tones = [(147.0, 0.3), (2_000.0, 1.1), (9_500.0, 2.0)];
            let at = |t: f64| {
                tones
                    .iter()
                    .map(|(f, ph)| (2.0 * PI * f * t + ph).sin())
                    .sum()
            };
            let input: Vec<f64> = (0..(0.2 * fs_in) as usize)
                .map(|i| at(i as f64 / fs_in))
                .collect();
            let out = resample_whole(&input, fs_in, 48_000.0).unwrap();
            // Away from the ends, where the kernel runs off the signal.
            let worst = out[2000..out.len() - 2000]
                .iter()
                .enumerate()
                .map(|(i, y)| (y - at((i + 2000) as f64 / 48_000.0)).abs())
                .fold(0.0, f64::max);
            // Three unit tones: 1e-3 is -70 dB re one tone; the beta-10 Kaiser ripple and
            // the linear table interpolation are both below it, a delay of even a tenth of
            // a sample at 9.5 kHz would give 0.12.
            assert!(worst < 1e-3, "{fs_in} Hz: worst error {worst}");
        }
    }

    #[test]
    fn every_rate_pair_passes_in_band_tones_shifted_by_exactly_its_latency_and_rejects_aliases() {
        // One stage (27 and 90 kHz in), two stages with factors 2 to 135.
        for (fs_in, fs_out) in [
            (27_000.0, 48_000.0),
            (90_000.0, 48_000.0),
            (192_000.0, 48_000.0),
            (541_595.0, 44_100.0),
            (1_083_190.0, 48_000.0),
            (1_083_190.0, 8_000.0),
        ] {
            let mut r = Resampler::new(fs_in, fs_out).unwrap();
            let latency = r.latency_samples();
            let f = 0.2 * f64::min(fs_in, fs_out);
            let mut n = 0u64;
            let mut out = vec![0.0; 4096];
            r.process(
                || {
                    let x = (2.0 * PI * f * n as f64 / fs_in).sin();
                    n += 1;
                    x
                },
                &mut out,
            );
            // The output is the input tone `latency` output samples ahead.
            let worst = out[1024..]
                .iter()
                .enumerate()
                .map(|(i, y)| {
                    let t = ((i + 1024) as f64 + latency) / fs_out;
                    (y - (2.0 * PI * f * t).sin()).abs()
                })
                .fold(0.0, f64::max);
            println!("{fs_in} -> {fs_out}: latency {latency:.3}, worst error {worst:.2e}");
            // 1e-3 (-60 dB): a latency wrong by 1 % of a sample would already give 2.5e-3
            // at 0.2 of the rate; the pass-band ripple is below 0.05 dB (6e-3 would be).
            assert!(worst < 1e-3, "{fs_in} -> {fs_out}: {worst:.2e}");
            if fs_in > 2.0 * fs_out {
                // Tones that would fold into the pass band: just past the sinc's transition,
                // and near the first multiple of the stage-1 output rate.
                for alias in [
                    0.45 * 1.5 * fs_out,
                    fs_in / (fs_in / (2.0 * fs_out)).floor(),
                ] {
                    if alias < fs_in / 2.0 {
                        let db = 20.0 * tone_through(fs_in, fs_out, alias).log10();
                        println!("  {alias:.0} Hz would alias: {db:.1} dB");
                        // The design target: aliases of a full-scale tone at or below
                        // -70 dB.
                        assert!(db < -70.0, "{fs_in} -> {fs_out}: {alias} Hz at {db:.1} dB");
                    }
                }
            }
        }
    }

    #[test]
    fn passband_is_flat_and_aliases_are_rejected() {
        let fs_in = 541_595.0;
        let fs_out = 48_000.0;
        // Pass band to 0.8 of the cut-off (17.3 kHz at 48 kHz): the cut-off itself is the
        // kernel's -6 dB point and 20 zero crossings leave a transition of about +-4 kHz.
        for f in [100.0, 1000.0, 10_000.0, 17_000.0] {
            let gain_db = 20.0 * tone_through(fs_in, fs_out, f).log10();
            println!("{f} Hz: {gain_db:+.4} dB");
            // 0.05 dB: the Kaiser ripple is far smaller; the RMS estimate over whole
            // and partial periods adds a little.
            assert!(gain_db.abs() < 0.05, "{f} Hz: {gain_db} dB");
        }
        for f in [27_000.0, 30_000.0, 50_000.0, 100_000.0] {
            let alias_db = 20.0 * tone_through(fs_in, fs_out, f).log10();
            println!("{f} Hz (would alias): {alias_db:.1} dB");
            // The design target: aliases of a full-scale tone at or below -70 dB. 27 kHz sits
            // at the edge of the transition band (21.6 kHz +- about 5 kHz).
            assert!(alias_db < -70.0, "{f} Hz leaks at {alias_db} dB");
        }
    }
}
