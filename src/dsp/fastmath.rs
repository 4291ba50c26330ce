//! Inline `exp` and `sin`/`cos` for the bristle laws' Newton iteration, which evaluates
//! them at every evaluation of `g` (the Stribeck curve's `exp(-(v/v_s)^2)`, the
//! elasto-plastic adhesion map's raised sine): on paper A's cello D3 string at 48 kHz, 3.9
//! `exp` and 1.5 `sincos` calls a sample before the tangent predictor (callgrind). The C library's calls cost about 50
//! (`exp`, with its error-handling wrapper) and 115 (`sincos`) instructions each here;
//! these are straight-line polynomials of a few dozen, the same on every machine and C
//! library (so renders do not depend on the host's libm). Measured on paper A's string
//! with the tangent predictor (cello D3, elasto-plastic, good tolerance): 1128 -> 1054
//! instructions a sample (callgrind), but no faster as a whole process (120 s renders run
//! in pairs on the two cores: 0.96-1.13 s against 1.05-1.13 s with glibc's FMA code). They
//! are kept for the instructions and for renders that do not depend on the C library.
//!
//! Both are Taylor series (`exp` after a table of `2^(j/32)`), truncated where the first
//! dropped term is below 2e-17 of the result, evaluated by Horner's rule: the error is
//! rounding, about one unit in the last place (the tests bound it against `std` over the
//! whole range used).

/// `ln 2` split so that `k * LN2_HI` is exact for `|k| < 2^20` (Cody and Waite; fdlibm's
/// `ln2HI`, 32 trailing zero bits).
const LN2_HI: f64 = 0.693_147_180_369_123_816_49;
/// `ln 2 - LN2_HI` (fdlibm's `ln2LO`).
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;

/// `2^(j / 32)`, `j = 0..32`, each correctly rounded (computed to 50 digits with Python's
/// `decimal` and rounded once). Entry 16 is `sqrt 2`, written as the table computes it.
#[rustfmt::skip]
#[allow(clippy::approx_constant)]
const EXP2_TABLE: [f64; 32] = [
    1.0, 1.0218971486541166, 1.0442737824274138, 1.0671404006768237, 1.0905077326652577, 1.1143867425958924, 1.1387886347566916, 1.1637248587775775, 1.189207115002721, 1.215247359980469, 1.241857812073484, 1.2690509571917332, 1.2968395546510096, 1.3252366431597413, 1.3542555469368927, 1.383909881963832, 1.4142135623730951, 1.4451808069770467, 1.4768261459394993, 1.5091644275934228, 1.5422108254079407, 1.5759808451078865, 1.6104903319492543, 1.645755478153965, 1.681792830507429, 1.718619298122478, 1.7562521603732995, 1.7947090750031072, 1.8340080864093424, 1.8741676341103, 1.9152065613971474, 1.9571441241754002
];

/// `e^r`'s series from `r^6 / 6!` down to 1, for [`horner`].
const EXP_SERIES: [f64; 7] = [
    1.0 / 720.0,
    1.0 / 120.0,
    1.0 / 24.0,
    1.0 / 6.0,
    0.5,
    1.0,
    1.0,
];

/// `(theta - sin theta) / theta^3` as a series in `theta^2`, from `theta^18 / 21!` down to
/// `1 / 3!`: `sin theta = theta - theta^3 P(theta^2)`.
const SIN_SERIES: [f64; 10] = [
    -1.0 / 51_090_942_171_709_440_000.0,
    1.0 / 121_645_100_408_832_000.0,
    -1.0 / 355_687_428_096_000.0,
    1.0 / 1_307_674_368_000.0,
    -1.0 / 6_227_020_800.0,
    1.0 / 39_916_800.0,
    -1.0 / 362_880.0,
    1.0 / 5_040.0,
    -1.0 / 120.0,
    1.0 / 6.0,
];

/// `(cos theta - 1) / theta^2` as a series in `theta^2`, from `theta^18 / 20!` down to
/// `-1 / 2!`: `cos theta = 1 + theta^2 Q(theta^2)`.
const COS_SERIES: [f64; 10] = [
    1.0 / 2_432_902_008_176_640_000.0,
    -1.0 / 6_402_373_705_728_000.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 479_001_600.0,
    -1.0 / 3_628_800.0,
    1.0 / 40_320.0,
    -1.0 / 720.0,
    1.0 / 24.0,
    -0.5,
];

/// The polynomial with `coeffs` (highest power first) at `x`, by Horner's rule.
#[inline(always)]
fn horner(x: f64, coeffs: &[f64]) -> f64 {
    let mut p = coeffs[0];
    for &c in &coeffs[1..] {
        p = p * x + c;
    }
    p
}

/// `exp(x)` for `x <= 0`: zero below -708 (where the result would be subnormal or
/// underflow; the bristle laws only add it to a positive constant), `exp(x)` otherwise.
/// NaN gives NaN.
///
/// `x = (32 m + j) ln 2 / 32 + r` with `|r| <= ln 2 / 64`; `exp(x) = 2^m 2^(j/32) e^r`,
/// `e^r` to `r^6 / 6!` (the first dropped term, `(ln 2 / 64)^7 / 7!`, is 3.5e-18).
#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    if !(x >= -708.0) {
        return if x.is_nan() { x } else { 0.0 };
    }
    // Nearest integer to x 32 / ln 2 (x <= 0: truncating y - 1/2 rounds y; a conversion
    // instruction, where `round` is a library call without SSE4.1).
    let k = (x * (32.0 * std::f64::consts::LOG2_E) - 0.5) as i64;
    let kf = k as f64;
    let r = (x - kf * (LN2_HI / 32.0)) - kf * (LN2_LO / 32.0);
    let p = horner(r, &EXP_SERIES);
    // 2^m 2^(j/32): m added to the table entry's exponent (its result stays normal for
    // x >= -708, m >= -1022).
    let t = EXP2_TABLE[(k & 31) as usize];
    let scale = f64::from_bits(t.to_bits().wrapping_add(((k >> 5) as u64) << 52));
    p * scale
}

/// `(sin theta, cos theta)` for `|theta| <= pi / 2` (larger arguments lose accuracy; the
/// adhesion map's phase stays within it).
#[inline(always)]
pub fn sin_cos_quarter_turn(theta: f64) -> (f64, f64) {
    let t2 = theta * theta;
    // sin to theta^21 / 21!, cos to theta^20 / 20! (first dropped terms at pi / 2:
    // 1.2e-18 and 1.8e-17).
    let sin = theta - theta * t2 * horner(t2, &SIN_SERIES);
    let cos = 1.0 + t2 * horner(t2, &COS_SERIES);
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between `a` and the reference `b`.
    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        (a - b).abs() / (b.abs() * f64::EPSILON).max(f64::MIN_POSITIVE)
    }

    #[test]
    fn exp_nonpositive_is_within_two_ulps_of_std_over_its_range() {
        // Two ulps: the Cody-Waite reduction and Horner's rule each round a few times;
        // std's exp is itself within one ulp, so the two may differ by about two.
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -708.0 * (i as f64 / 200_000.0).powi(3);
            worst = worst.max(ulps(exp_nonpositive(x), x.exp()));
        }
        // The Stribeck curve's own range, finely: -(v / v_s)^2 from 0 to -50.
        for i in 0..=200_000 {
            let x = -50.0 * i as f64 / 200_000.0;
            worst = worst.max(ulps(exp_nonpositive(x), x.exp()));
        }
        println!("exp_nonpositive: worst {worst} ulps");
        assert!(worst <= 2.0, "worst {worst} ulps");
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-1000.0), 0.0);
        assert_eq!(exp_nonpositive(f64::NEG_INFINITY), 0.0);
        assert!(exp_nonpositive(f64::NAN).is_nan());
    }

    #[test]
    fn sin_cos_quarter_turn_is_within_three_ulps_of_one_of_std() {
        // Absolute error against 1 (the functions' scale here): the adhesion map uses
        // 0.5 (1 + sin) and cos times a slope, so error relative to 1 is what reaches it.
        let mut worst = 0.0f64;
        let half_pi = std::f64::consts::FRAC_PI_2;
        for i in -200_000..=200_000 {
            let t = half_pi * i as f64 / 200_000.0;
            let (s, c) = sin_cos_quarter_turn(t);
            worst = worst.max((s - t.sin()).abs()).max((c - t.cos()).abs());
        }
        println!("sin_cos_quarter_turn: worst {:e}", worst);
        assert!(worst <= 3.0 * f64::EPSILON, "worst {:e}", worst);
        assert_eq!(sin_cos_quarter_turn(0.0), (0.0, 1.0));
    }
}
