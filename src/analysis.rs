//! Signal measurements shared by the tests and the tools: pitch of a partial to a
//! fraction of a cent, and the stick/slip statistics of Helmholtz motion.

use std::f64::consts::PI;

/// `1200 log2(f / reference)`.
pub fn cents(f: f64, reference: f64) -> f64 {
    1200.0 * (f / reference).log2()
}

/// Magnitude of the Hann-windowed DTFT of `x` at `freq_hz`.
fn windowed_dtft(x: &[f64], sample_rate_hz: f64, freq_hz: f64) -> f64 {
    let n = x.len() as f64;
    let w = 2.0 * PI * freq_hz / sample_rate_hz;
    let (mut re, mut im) = (0.0, 0.0);
    // rotate a phasor instead of calling sin/cos per sample; renormalise now and then
    let (c, s) = (w.cos(), w.sin());
    let (mut pr, mut pi) = (1.0f64, 0.0f64);
    for (i, &v) in x.iter().enumerate() {
        let hann = 0.5 - 0.5 * (2.0 * PI * i as f64 / n).cos();
        re += hann * v * pr;
        im -= hann * v * pi;
        let nr = pr * c - pi * s;
        pi = pr * s + pi * c;
        pr = nr;
        if i % 1024 == 1023 {
            let norm = (pr * pr + pi * pi).sqrt();
            pr /= norm;
            pi /= norm;
        }
    }
    (re * re + im * im).sqrt()
}

/// Amplitude of a sinusoid at `freq_hz` in `x`, from the Hann-windowed DTFT (exact for a
/// stationary sinusoid whose frequency is given, away from other partials).
pub fn partial_amplitude(x: &[f64], sample_rate_hz: f64, freq_hz: f64) -> f64 {
    // The Hann window's coherent gain is 1/2: a unit sinusoid gives N/4.
    4.0 * windowed_dtft(x, sample_rate_hz, freq_hz) / x.len().max(1) as f64
}

/// Frequency of the strongest spectral peak within `search_cents` of `guess_hz`: a scan
/// at 1-cent steps, then a golden-section refinement of the windowed DTFT magnitude.
/// With a second or more of signal the estimate is far inside 0.1 cent for a clean partial.
pub fn peak_frequency_hz(x: &[f64], sample_rate_hz: f64, guess_hz: f64, search_cents: f64) -> f64 {
    let at = |c: f64| guess_hz * 2f64.powf(c / 1200.0);
    let steps = (2.0 * search_cents).ceil() as i32;
    let mut best = (-search_cents, 0.0);
    for k in 0..=steps {
        let c = -search_cents + k as f64;
        let m = windowed_dtft(x, sample_rate_hz, at(c));
        if m > best.1 {
            best = (c, m);
        }
    }
    let (mut lo, mut hi) = (best.0 - 1.0, best.0 + 1.0);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..30 {
        let c1 = hi - r * (hi - lo);
        let c2 = lo + r * (hi - lo);
        if windowed_dtft(x, sample_rate_hz, at(c1)) > windowed_dtft(x, sample_rate_hz, at(c2)) {
            hi = c2;
        } else {
            lo = c1;
        }
    }
    at(0.5 * (lo + hi))
}

/// Stick/slip statistics of the string velocity at the bow point.
///
/// Two slip measures are given because the model's Helmholtz corners are rounded by the
/// string's frequency-dependent losses (Cremer's corner rounding, physical and stronger at
/// low bow force):
/// - `strict_slip_fraction` counts every sample where the string moves relative to the
///   bow, including the rounded flanks of each corner;
/// - `slip_fraction` is corner to corner: the time the velocity is beyond the midpoint of
///   the sticking velocity and the slip plateau velocity. A rounded corner's centre
///   travels at the wave speed, so this is the quantity Raman's theory predicts (= beta).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipStats {
    /// Corner-to-corner (half-jump) slip fraction of the time.
    pub slip_fraction: f64,
    /// Fraction of the time with any relative motion beyond the tolerance.
    pub strict_slip_fraction: f64,
    /// Corner-to-corner slips per period of `f0`.
    pub slips_per_period: f64,
    /// Median string velocity on the sticking side of the corners, m/s.
    pub stick_velocity_m_per_s: f64,
    /// Mean string velocity between the corners (the slip plateau), m/s.
    pub slip_velocity_m_per_s: f64,
    /// Sticking velocity minus the slip plateau velocity, m/s (Raman: v_b / beta).
    pub jump_m_per_s: f64,
}

/// Classifies each sample of the string velocity at the bow `v_s` (a steady stretch of
/// whole periods) as sticking when it moves with the bow within `tolerance_m_per_s`, and
/// measures the slips (see [`SlipStats`]).
pub fn slip_stats(
    v_s: &[f64],
    bow_velocity_m_per_s: f64,
    sample_rate_hz: f64,
    f0_hz: f64,
    tolerance_m_per_s: f64,
) -> SlipStats {
    let n = v_s.len().max(1) as f64;
    let strict = v_s
        .iter()
        .filter(|v| (**v - bow_velocity_m_per_s).abs() > tolerance_m_per_s)
        .count();
    // The string slips against the bow direction.
    let sign = if bow_velocity_m_per_s >= 0.0 {
        -1.0
    } else {
        1.0
    };
    let mut sorted: Vec<f64> = v_s.to_vec();
    sorted.sort_by(f64::total_cmp);
    // Start from the bow velocity and the 1st percentile on the slipping side, then
    // alternate: split at the midpoint, slip level = mean beyond it, stick level = median
    // on the sticking side (robust to ripple while sticking).
    let mut stick = bow_velocity_m_per_s;
    let mut slip = if sorted.is_empty() {
        stick
    } else if sign < 0.0 {
        sorted[sorted.len() / 100]
    } else {
        sorted[sorted.len() - 1 - sorted.len() / 100]
    };
    let mut beyond = vec![false; v_s.len()];
    for _ in 0..4 {
        let midpoint = 0.5 * (stick + slip);
        for (b, v) in beyond.iter_mut().zip(v_s) {
            *b = sign * (v - midpoint) > 0.0;
        }
        let (sum, count) = v_s
            .iter()
            .zip(&beyond)
            .filter(|(_, b)| **b)
            .fold((0.0, 0usize), |(a, c), (v, _)| (a + v, c + 1));
        if count == 0 || count == v_s.len() {
            break;
        }
        slip = sum / count as f64;
        let mut sticking: Vec<f64> = v_s
            .iter()
            .zip(&beyond)
            .filter(|(_, b)| !**b)
            .map(|(v, _)| *v)
            .collect();
        sticking.sort_by(f64::total_cmp);
        stick = sticking[sticking.len() / 2];
    }
    let corner = beyond.iter().filter(|b| **b).count();
    let onsets = beyond.windows(2).filter(|w| !w[0] && w[1]).count();
    let periods = v_s.len() as f64 * f0_hz / sample_rate_hz;
    SlipStats {
        slip_fraction: corner as f64 / n,
        strict_slip_fraction: strict as f64 / n,
        slips_per_period: onsets as f64 / periods,
        stick_velocity_m_per_s: stick,
        slip_velocity_m_per_s: slip,
        jump_m_per_s: stick - slip,
    }
}

/// The n-th partial's amplitude at the bridge of a string pulled aside at `beta` of its
/// length from the bridge and let go (the pulled triangle's force on the bridge), up to a
/// common factor: the displacement's `sin(n pi beta) / n^2` times the slope's `n` at the
/// bridge, times `sinc(n pi w / 2)` for a finger that rounds the kink over `width` of the
/// length (`width > 0`).
pub fn plucked_bridge_partial(n: f64, beta: f64, width: f64) -> f64 {
    let x = n * PI * width / 2.0;
    ((n * PI * beta).sin() / n * x.sin() / x).abs()
}

/// Root-mean-square level.
pub fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peak_frequency_finds_a_sine_to_a_hundredth_of_a_cent() {
        let fs = 48_000.0;
        let f = 146.83 * 2f64.powf(3.3 / 1200.0);
        let x: Vec<f64> = (0..48_000)
            .map(|i| (2.0 * PI * f * i as f64 / fs).sin())
            .collect();
        let est = peak_frequency_hz(&x, fs, 146.83, 30.0);
        // One second of a clean sine: the refined peak of its Hann-windowed DTFT lies far
        // inside 0.01 cent (as half a second does in lab/tests/precision.rs).
        assert!(cents(est, f).abs() < 0.01, "error {} cents", cents(est, f));
    }
}
