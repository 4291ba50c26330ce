//! Where the sound leaves the instrument: its radiation below the body's lowest resonance.
//!
//! A violin-family body is a box with holes: below its air resonance A0 (the Helmholtz
//! resonance of the cavity through the f-holes) the air in the holes moves against the
//! plates and their volume velocities cancel, as in a vented loudspeaker box below its
//! port tuning. The vented-box theory (Thiele) gives a pressure that falls as the fourth
//! power of frequency there (24 dB an octave); the measured fall is steeper: Bissinger's
//! radiation per unit of bridge velocity of a violin (2002, fig. 1) falls by about 20 dB
//! from its A0 peak to 220 Hz, 45-50 dB an octave, and the four recorded instruments of
//! the timbre benchmark (docs/timbre.md) give their lowest string's fundamentals, below
//! A0, 14-19 dB under what a fourth-order fall leaves. The bodies' modes
//! ([`super::body`], paper B's bridge) give the bridge's motion; this stage turns it into
//! what a microphone in front of the instrument hears: an eighth-order Butterworth
//! high-pass at the instrument's A0 (its body's first mode), 48 dB an octave below it.
//! The order is the one choice made against the recordings (fourth, sixth and eighth were
//! compared, docs/timbre.md).
//!
//! ```
//! use colophony::dsp::radiation::Radiation;
//! let mut r = Radiation::new(275.0, 48_000.0);
//! // Far below A0 almost nothing passes once the onset has rung out: (50 / 275)^8.
//! let out: Vec<f64> = (0..48_000)
//!     .map(|i| r.tick((2.0 * std::f64::consts::PI * 50.0 * i as f64 / 48e3).sin()))
//!     .collect();
//! let low = out[24_000..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
//! assert!(low < 1e-5);
//! ```

use std::f64::consts::PI;

/// One second-order high-pass section without its gain: numerator `(1 - z^-1)^2`,
/// transposed direct form II (the stage applies the sections' gains once, at its input,
/// so a section costs two multiplications).
#[derive(Debug, Clone, Copy, Default)]
struct Section {
    a: [f64; 2],
    s: [f64; 2],
}

impl Section {
    /// A second-order high-pass at `f_hz` with quality `q` (bilinear, pre-warped), and
    /// the gain its numerator leaves out.
    fn high_pass(f_hz: f64, q: f64, fs: f64) -> (Self, f64) {
        let w = 2.0 * PI * (f_hz / fs).min(0.45);
        let (sin, cos) = w.sin_cos();
        let alpha = sin / (2.0 * q);
        let a0 = 1.0 + alpha;
        let section = Self {
            a: [-2.0 * cos / a0, (1.0 - alpha) / a0],
            s: [0.0; 2],
        };
        (section, (1.0 + cos) / 2.0 / a0)
    }

    #[inline(always)]
    fn tick(&mut self, x: f64) -> f64 {
        let y = x + self.s[0];
        self.s[0] = self.s[1] - 2.0 * x - self.a[0] * y;
        self.s[1] = x - self.a[1] * y;
        y
    }
}

/// The radiation stage (see the module doc).
#[derive(Debug, Clone, Copy, Default)]
pub struct Radiation {
    sections: [Section; SECTIONS],
    /// The sections' gains, multiplied together.
    gain: f64,
    /// AVX2 detected at run time ([`Radiation::block`]).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    wide_simd: bool,
}

/// Second-order sections of the stage: an eighth-order high-pass.
const SECTIONS: usize = 4;

/// The quality factor of section `k` of an eighth-order Butterworth filter: its poles lie
/// at angles `(2k + 1) pi / 16` from the imaginary axis, `Q = 1 / (2 sin(angle))`.
fn butterworth_q(k: usize) -> f64 {
    0.5 / (((2 * k + 1) as f64) * PI / (4.0 * SECTIONS as f64)).sin()
}

impl Radiation {
    /// The radiation of a body whose air resonance is `a0_hz`, at `sample_rate_hz`.
    pub fn new(a0_hz: f64, sample_rate_hz: f64) -> Self {
        let mut gain = 1.0;
        let sections = std::array::from_fn(|k| {
            let (section, g) = Section::high_pass(a0_hz, butterworth_q(k), sample_rate_hz);
            gain *= g;
            section
        });
        Self {
            sections,
            gain,
            wide_simd: super::detect_wide_simd(),
        }
    }

    /// Moves the stage to another body's A0, keeping what it holds, so that a sound
    /// going on through it goes on smoothly.
    pub fn retune(&mut self, a0_hz: f64, sample_rate_hz: f64) {
        let held = self.sections.map(|s| s.s);
        *self = Self::new(a0_hz, sample_rate_hz);
        for (section, s) in self.sections.iter_mut().zip(held) {
            section.s = s;
        }
    }

    #[inline(always)]
    pub fn tick(&mut self, x: f64) -> f64 {
        let mut y = self.gain * x;
        for section in &mut self.sections {
            y = section.tick(y);
        }
        super::filters::flush_tiny(y)
    }

    /// Each sample of `out` times `gain` through the stage, in place (the samples of
    /// [`Radiation::tick`]); stops at the first output that is not finite and returns its
    /// index (that sample and the rest are left as they were; the stage's state is then
    /// the caller's to reset). With AVX2 where the CPU has it, the sections run in four
    /// lanes ([`block_avx2`]): no FMA, the same bits.
    pub fn block(&mut self, gain: f64, out: &mut [f64]) -> Option<usize> {
        #[cfg(target_arch = "x86_64")]
        if self.wide_simd {
            // SAFETY: `wide_simd` is true only where AVX2 was detected at run time.
            return unsafe { block_avx2(self, gain, out) };
        }
        self.block_portable(gain, out)
    }

    #[inline(always)]
    fn block_portable(&mut self, gain: f64, out: &mut [f64]) -> Option<usize> {
        for (k, sample) in out.iter_mut().enumerate() {
            let audio = self.tick(*sample * gain);
            if !audio.is_finite() {
                return Some(k);
            }
            *sample = audio;
        }
        None
    }

    pub fn reset(&mut self) {
        for s in &mut self.sections {
            s.s = [0.0; 2];
        }
    }
}

/// [`Radiation::block`] compiled for AVX2, its four sections run as a wavefront: one
/// vector holds the four sections, lane `k` working on sample `t - k` at step `t` (the
/// first section's output of one step is the second's input at the next), so a step
/// advances every section with the same operations a sample at a time would do, in four
/// lanes at once: the same bits. A lane with no sample of this block to work on keeps its
/// state (the first three and last three steps of a block).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_avx2(radiation: &mut Radiation, gain: f64, out: &mut [f64]) -> Option<usize> {
    use std::arch::x86_64::*;
    let n = out.len();
    let lanes = |f: &dyn Fn(&Section) -> f64| {
        let v = [0, 1, 2, 3].map(|k| f(&radiation.sections[k]));
        // SAFETY: `v` holds four f64.
        unsafe { _mm256_loadu_pd(v.as_ptr()) }
    };
    let (a0, a1) = (lanes(&|s| s.a[0]), lanes(&|s| s.a[1]));
    let (mut s0, mut s1) = (lanes(&|s| s.s[0]), lanes(&|s| s.s[1]));
    let two = _mm256_set1_pd(2.0);
    // Each section's output of the step before, lane k.
    let mut y = _mm256_setzero_pd();
    let mut result = None;
    for t in 0..n + SECTIONS - 1 {
        // Lane 0 takes the block's next input, lane k the output of lane k - 1.
        let input = if t < n {
            radiation.gain * (out[t] * gain)
        } else {
            0.0
        };
        let x = _mm256_blend_pd::<0b0001>(
            _mm256_permute4x64_pd::<0b10_01_00_00>(y),
            _mm256_set1_pd(input),
        );
        let y_new = _mm256_add_pd(x, s0);
        let s0_new = _mm256_sub_pd(
            _mm256_sub_pd(s1, _mm256_mul_pd(two, x)),
            _mm256_mul_pd(a0, y_new),
        );
        let s1_new = _mm256_sub_pd(x, _mm256_mul_pd(a1, y_new));
        if t >= SECTIONS - 1 && t < n {
            (y, s0, s1) = (y_new, s0_new, s1_new);
        } else {
            // Lane k works on sample t - k only where that is in the block.
            let active = [0, 1, 2, 3].map(|k: usize| if t >= k && t - k < n { -1i64 } else { 0 });
            // SAFETY: `active` holds four i64.
            let mask = _mm256_castsi256_pd(unsafe { _mm256_loadu_si256(active.as_ptr().cast()) });
            y = _mm256_blendv_pd(y, y_new, mask);
            s0 = _mm256_blendv_pd(s0, s0_new, mask);
            s1 = _mm256_blendv_pd(s1, s1_new, mask);
        }
        if t >= SECTIONS - 1 {
            let j = t - (SECTIONS - 1);
            let audio = super::filters::flush_tiny(_mm256_cvtsd_f64(_mm256_permute4x64_pd::<
                0b11_11_11_11,
            >(y)));
            if !audio.is_finite() {
                result = Some(j);
                break;
            }
            out[j] = audio;
        }
    }
    let mut held = [[0.0; 4]; 2];
    // SAFETY: each row holds four f64.
    unsafe {
        _mm256_storeu_pd(held[0].as_mut_ptr(), s0);
        _mm256_storeu_pd(held[1].as_mut_ptr(), s1);
    }
    for (k, section) in radiation.sections.iter_mut().enumerate() {
        section.s = [held[0][k], held[1][k]];
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stage is an eighth-order Butterworth high-pass at A0 at every rate: -3 dB at
    /// A0, `-10 log10(1 + 2^16)` = -48.2 dB an octave below and -96.3 dB two octaves
    /// below, unity three octaves above. Tolerance 0.5 dB: the bilinear transform matches
    /// the analogue filter exactly only at A0.
    #[test]
    fn the_radiation_falls_48_db_an_octave_below_a0_and_passes_above() {
        for fs in [8_000.0, 44_100.0, 48_000.0, 192_000.0] {
            for a0 in [63.0, 115.0, 275.0] {
                for (f, expected_db) in [
                    (a0, -3.01),
                    (a0 / 2.0, -48.2),
                    (a0 / 4.0, -96.3),
                    (a0 * 8.0, 0.0),
                ] {
                    if f > 0.4 * fs {
                        continue;
                    }
                    let mut r = Radiation::new(a0, fs);
                    let n = (fs * (4.0 + 40.0 / f)) as usize;
                    let y: Vec<f64> = (0..n)
                        .map(|i| r.tick((2.0 * PI * f * i as f64 / fs).sin()))
                        .collect();
                    let tail = &y[n / 2..];
                    let peak = tail.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    let db = 20.0 * peak.log10();
                    assert!(
                        (db - expected_db).abs() < 0.5,
                        "fs {fs}, A0 {a0}, {f} Hz: {db:.2} dB"
                    );
                }
            }
        }
    }

    /// A block through the stage gives the bits of ticking it sample by sample, for
    /// blocks shorter than the four sections, of each length around them and long ones
    /// (the wavefront's first and last steps), with AVX2 where the CPU has it; and a
    /// sample that is not finite stops the block at its index.
    #[test]
    fn a_block_gives_the_samples_of_ticking_the_stage() {
        let fs = 48_000.0;
        // A broadband chaotic input with a ramp under it, loud enough to use every bit.
        let mut c = 0.321_f64;
        let input: Vec<f64> = (0..6_000)
            .map(|n| {
                c = 3.99 * c * (1.0 - c);
                (c - 0.5) + 1e-4 * n as f64
            })
            .collect();
        let gain = 0.75;
        let mut ticked = Radiation::new(115.0, fs);
        let want: Vec<u64> = input
            .iter()
            .map(|&x| ticked.tick(x * gain).to_bits())
            .collect();
        for block in [1, 2, 3, 4, 5, 7, 37, 512] {
            let mut r = Radiation::new(115.0, fs);
            let mut got = Vec::with_capacity(input.len());
            for chunk in input.chunks(block) {
                let mut out = chunk.to_vec();
                assert_eq!(r.block(gain, &mut out), None);
                got.extend(out.iter().map(|x| x.to_bits()));
            }
            assert!(got == want, "blocks of {block}");
        }
        let mut r = Radiation::new(115.0, fs);
        let mut out = input[..100].to_vec();
        out[61] = f64::NAN;
        assert_eq!(r.block(gain, &mut out), Some(61));
        assert!(out[..61].iter().zip(&want).all(|(x, w)| x.to_bits() == *w));
    }

    /// Retuned to another body while a sound goes on (the violin's A0 to the cello's), the
    /// stage keeps what it holds: the output's largest step between samples over the
    /// switch stays near the sound's own (a 440 Hz sine plus a steady push of 0.5: measured
    /// 1.24 times the sine's largest step; the stage rebuilt from rest there steps by the
    /// push, 0.66), and retuned to the same A0 it gives the same bits.
    #[test]
    fn a_retuned_stage_goes_on_smoothly() {
        let fs = 48_000.0;
        let x = |n: usize| 0.5 + (2.0 * PI * 440.0 * n as f64 / fs).sin();
        let run = |switch: Option<f64>, rebuild: bool| -> Vec<f64> {
            let mut r = Radiation::new(275.0, fs);
            (0..9_600)
                .map(|n| {
                    if n == 4_800 {
                        if let Some(a0) = switch {
                            if rebuild {
                                r = Radiation::new(a0, fs);
                            } else {
                                r.retune(a0, fs);
                            }
                        }
                    }
                    r.tick(x(n))
                })
                .collect()
        };
        assert_eq!(run(None, false), run(Some(275.0), false));
        let largest_step = |y: &[f64]| {
            y[4_700..4_900]
                .windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .fold(0.0, f64::max)
        };
        let sine_step = 2.0 * PI * 440.0 / fs;
        let (kept, rebuilt) = (
            largest_step(&run(Some(116.0), false)),
            largest_step(&run(Some(116.0), true)),
        );
        // 1.5: the held state belongs to the old coefficients, so the switch adds a small
        // transient (measured 24 %); a click is the push's whole step, eight times the
        // sine's.
        assert!(kept < 1.5 * sine_step, "{kept} against {sine_step}");
        assert!(rebuilt > 0.4, "{rebuilt}");
    }
}
