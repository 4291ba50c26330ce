//! The bouncing bow (spiccato, sautillé): the bow at its contact point as a mass on a spring (the
//! hair and the stick's bending, with some damping), pulled toward the string by its
//! weight and the player's hand, dropped onto the string from a height. While the hair is
//! pressed into the string it pushes back (the normal force the string feels); it leaves
//! the string with a fraction of the speed it landed with and flies until the pull brings
//! it back. Askenfelt and Guettler measured a violin bow's bounce at 8-20 Hz depending on
//! where along the bow it meets the string ("The bouncing bow: an experimental study",
//! Catgut Acoust. Soc. J. 3(6), 1998); [`BounceParams::default`] sits within that.
//!
//! In sautillé the hand drives the bounce instead of dropping the bow: it pushes the bow
//! toward the string and lets it up once a stroke ([`BouncingBow::driven`]), at the
//! bow's own bouncing frequency (the player plays at the point along the bow where it
//! bounces at the stroke's rate), so a small push keeps a large bounce going.
//!
//! ```
//! use colophony::dsp::bounce::{BounceParams, BouncingBow};
//! let mut bow = BouncingBow::new(BounceParams::default(), 0.3, 48_000.0);
//! bow.drop_from(0.005);
//! let force: Vec<f64> = (0..96_000).map(|_| bow.tick()).collect();
//! // It lands, bounces, and comes to rest on the string pressing with the pull.
//! assert!(force.iter().any(|&f| f > 0.6));
//! assert!((force[95_999] - 0.3).abs() < 0.01);
//! ```

use std::f64::consts::PI;

/// The bow at the contact point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BounceParams {
    /// The bow's effective mass at the contact point, kg.
    pub mass_kg: f64,
    /// The frequency of the bow bouncing on the string (mass on the hair's spring), Hz.
    pub bounce_hz: f64,
    /// The share of its landing speed the bow leaves the string with.
    pub restitution: f64,
}

impl Default for BounceParams {
    /// A violin-size bow near its balance point: 30 g effective, bouncing at 12 Hz, leaving
    /// with 60 % of its landing speed (choices within Askenfelt and Guettler's range).
    fn default() -> Self {
        Self {
            mass_kg: 0.03,
            bounce_hz: 12.0,
            restitution: 0.6,
        }
    }
}

impl BounceParams {
    /// The hair's stiffness, N/m: `m (2 pi f)^2`.
    pub fn stiffness_n_per_m(&self) -> f64 {
        self.mass_kg * (2.0 * PI * self.bounce_hz).powi(2)
    }

    /// The damping ratio whose half-cycle of contact returns `restitution` of the speed:
    /// `e = exp(-pi zeta / sqrt(1 - zeta^2))`.
    pub fn damping_ratio(&self) -> f64 {
        let l = -self.restitution.clamp(1e-3, 1.0).ln();
        l / (PI * PI + l * l).sqrt()
    }

    /// How long one contact lasts, s: half a period of the damped spring, `pi / w_d`.
    pub fn contact_s(&self) -> f64 {
        let w = 2.0 * PI * self.bounce_hz;
        let zeta = self.damping_ratio();
        PI / (w * (1.0 - zeta * zeta).sqrt())
    }
}

/// The bouncing bow's state (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BouncingBow {
    mass_kg: f64,
    stiffness: f64,
    damping: f64,
    /// The pull toward the string (weight and hand), N: the force it rests with.
    pull_n: f64,
    dt: f64,
    /// The hair's height over the string, m (below 0: pressed into it).
    height_m: f64,
    /// Upward velocity, m/s.
    velocity_m_per_s: f64,
}

impl BouncingBow {
    /// A bow of `params` resting on the string with `pull_n`, stepped at `sample_rate_hz`.
    pub fn new(params: BounceParams, pull_n: f64, sample_rate_hz: f64) -> Self {
        let stiffness = params.stiffness_n_per_m();
        let damping = 2.0 * params.damping_ratio() * (stiffness * params.mass_kg).sqrt();
        let pull_n = pull_n.max(0.0);
        Self {
            mass_kg: params.mass_kg,
            stiffness,
            damping,
            pull_n,
            dt: 1.0 / sample_rate_hz,
            height_m: -pull_n / stiffness,
            velocity_m_per_s: 0.0,
        }
    }

    /// The bow held `height_m` over the string and let fall.
    pub fn drop_from(&mut self, height_m: f64) {
        self.height_m = height_m.max(0.0);
        self.velocity_m_per_s = 0.0;
    }

    /// The bow meeting the string now, as it would after falling from `height_m`
    /// (landing at `sqrt(2 g_eff h)` with `g_eff = pull / m`).
    pub fn land_from(&mut self, height_m: f64) {
        self.height_m = 0.0;
        self.velocity_m_per_s = -(2.0 * self.pull_n / self.mass_kg * height_m.max(0.0)).sqrt();
    }

    /// Whether the hair touches the string.
    pub fn in_contact(&self) -> bool {
        self.height_m < 0.0
    }

    /// A bow of `params` pulled with `pull_n` and pushed toward the string by the hand's
    /// `amplitude_n sin(2 pi drive_hz t)` (sautillé), in the linear motion's steady state at
    /// `t = 0`: the hair pressed in as far as a bow that never leaves the string would be
    /// there, moving as it would. `m y'' + c y' + k y = -pull - A sin(w t)` has the steady
    /// state `y = -pull / k - A |H| sin(w t - phi)`, `H = 1 / (k - m w^2 + i c w)`; at
    /// resonance (`phi = pi / 2`) the bow is highest at `t = 0`, where the push turns from
    /// lifting to pressing. Stepped with [`BouncingBow::tick_pushed`].
    pub fn driven(
        params: BounceParams,
        pull_n: f64,
        amplitude_n: f64,
        drive_hz: f64,
        sample_rate_hz: f64,
    ) -> Self {
        let mut bow = Self::new(params, pull_n, sample_rate_hz);
        let w = 2.0 * PI * drive_hz;
        let re = bow.stiffness - bow.mass_kg * w * w;
        let im = bow.damping * w;
        let gain = amplitude_n / re.hypot(im);
        let phi = im.atan2(re);
        bow.height_m = -bow.pull_n / bow.stiffness + gain * phi.sin();
        bow.velocity_m_per_s = -gain * w * phi.cos();
        bow
    }

    /// One sample (semi-implicit Euler: the velocity, then the height with it); returns
    /// the force pressing the hair onto the string, N (0 in the air).
    #[inline]
    pub fn tick(&mut self) -> f64 {
        self.tick_pushed(0.0)
    }

    /// One sample with the hand pushing the bow toward the string with `push_n` besides
    /// the pull (negative: lifting it); returns the force pressing the hair onto the
    /// string, N.
    #[inline]
    pub fn tick_pushed(&mut self, push_n: f64) -> f64 {
        let force = if self.height_m < 0.0 {
            (-self.stiffness * self.height_m - self.damping * self.velocity_m_per_s).max(0.0)
        } else {
            0.0
        };
        self.velocity_m_per_s += (force - self.pull_n - push_n) / self.mass_kg * self.dt;
        self.height_m += self.velocity_m_per_s * self.dt;
        force
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The contact of a bow with no pull, from the damped spring's solution: landing at
    /// `v0`, `y(t) = -(v0 / w_d) exp(-sigma t) sin(w_d t)`; it leaves when the hair's
    /// force `-k y - c y'` falls to zero. Returns (contact time, exit speed).
    fn analytic_contact(p: &BounceParams, v0: f64) -> (f64, f64) {
        let w = 2.0 * PI * p.bounce_hz;
        let sigma = p.damping_ratio() * w;
        let wd = w * (1.0 - p.damping_ratio().powi(2)).sqrt();
        let (k, c) = (p.stiffness_n_per_m(), 2.0 * sigma * p.mass_kg);
        let y = |t: f64| -(v0 / wd) * (-sigma * t).exp() * (wd * t).sin();
        let v = |t: f64| {
            -(v0 / wd) * (-sigma * t).exp() * (wd * (wd * t).cos() - sigma * (wd * t).sin())
        };
        let force = |t: f64| -k * y(t) - c * v(t);
        let (mut lo, mut hi) = (0.5 * PI / wd, PI / wd);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if force(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (lo, v(lo))
    }

    /// One bounce as the damped spring's solution says (a bow with next to no pull): the
    /// contact's length and the speed it leaves with, within 2 % (the sample grid: 0.4 ms
    /// at 8 kHz on a 40 ms contact); then, pulled by half a violin bow's weight, it flies
    /// `2 v / g_eff` between leaving and meeting the string's surface (`g_eff = pull / m`,
    /// a ball's flight), within 2 %; at 8, 48 and 192 kHz.
    #[test]
    fn a_dropped_bow_bounces_as_a_damped_spring_and_flies_as_a_ball() {
        let p = BounceParams::default();
        for fs in [8_000.0, 48_000.0, 192_000.0] {
            for pull in [1e-6, 0.3] {
                let mut bow = BouncingBow::new(p, pull, fs);
                bow.drop_from(0.0);
                bow.velocity_m_per_s = -0.3;
                let (mut edges, mut was) = (Vec::new(), false);
                let mut exit_speed = 0.0;
                for i in 0..(2.0 * fs) as usize {
                    // Pressing (with no pull), or below the string's surface (the flight
                    // is timed between crossings of it).
                    let pressing = bow.tick() > 0.0;
                    let now = if pull < 1e-3 {
                        pressing
                    } else {
                        bow.in_contact()
                    };
                    if now != was {
                        edges.push(i as f64 / fs);
                        if !now && exit_speed == 0.0 {
                            exit_speed = bow.velocity_m_per_s;
                        }
                    }
                    was = now;
                }
                if pull < 1e-3 {
                    let (contact, exit) = analytic_contact(&p, 0.3);
                    let measured = edges[1] - edges[0];
                    assert!(
                        (measured / contact - 1.0).abs() < 0.02,
                        "fs {fs}: contact {measured:.4} s against {contact:.4}"
                    );
                    assert!(
                        (exit_speed / exit - 1.0).abs() < 0.02,
                        "fs {fs}: exit {exit_speed:.4} m/s against {exit:.4}"
                    );
                } else {
                    assert!(edges.len() >= 3, "fs {fs}: {edges:?}");
                    let flight = edges[2] - edges[1];
                    let ballistic = 2.0 * exit_speed / (pull / p.mass_kg);
                    assert!(
                        (flight / ballistic - 1.0).abs() < 0.02,
                        "fs {fs}: flight {flight:.4} s against {ballistic:.4}"
                    );
                }
            }
        }
    }

    /// A bow driven by the hand's sinusoidal push, small enough that the hair never leaves
    /// the string, is a linear driven oscillator: started in [`BouncingBow::driven`]'s
    /// steady state, the hair's force swings at once (no transient to wait for) by
    /// `A |k + i c w| / |k - m w^2 + i c w|` about the pull, at resonance and an octave's
    /// worth either side, at 8, 48 and 192 kHz. Within 1 %: the semi-implicit step's
    /// phase error at 8 kHz (w dt = 0.01 at 12 Hz).
    #[test]
    fn a_driven_bow_that_stays_on_the_string_swings_as_the_linear_oscillator() {
        let p = BounceParams::default();
        let pull = 0.3;
        for fs in [8_000.0, 48_000.0, 192_000.0] {
            for drive_hz in [0.7 * p.bounce_hz, p.bounce_hz, 1.4 * p.bounce_hz] {
                let (m, k) = (p.mass_kg, p.stiffness_n_per_m());
                let c = 2.0 * p.damping_ratio() * (k * m).sqrt();
                let w = 2.0 * PI * drive_hz;
                let gain = k.hypot(c * w) / (k - m * w * w).hypot(c * w);
                // Half the push that would lift the hair.
                let amplitude = 0.5 * pull / gain;
                let mut bow = BouncingBow::driven(p, pull, amplitude, drive_hz, fs);
                let period = fs / drive_hz;
                let n = (3.0 * period) as usize;
                let force: Vec<f64> = (0..n)
                    .map(|i| bow.tick_pushed(amplitude * (w * i as f64 / fs).sin()))
                    .collect();
                assert!(force.iter().all(|&f| f > 0.0), "the hair stays on");
                for cycle in force.chunks_exact(period as usize) {
                    let (lo, hi) = cycle
                        .iter()
                        .fold((f64::MAX, f64::MIN), |(a, b), &f| (a.min(f), b.max(f)));
                    let swing = 0.5 * (hi - lo);
                    let mean = 0.5 * (hi + lo);
                    assert!(
                        (swing / (amplitude * gain) - 1.0).abs() < 0.01,
                        "fs {fs}, {drive_hz} Hz: swing {swing} N against {}",
                        amplitude * gain
                    );
                    assert!((mean / pull - 1.0).abs() < 0.01, "about the pull: {mean}");
                }
            }
        }
    }

    /// The bounces die away: the bow comes to rest on the string pressing with its pull,
    /// and its energy (kinetic, the hair's spring, and the pull's potential) never grows.
    #[test]
    fn the_bounces_die_away_to_the_resting_force() {
        let p = BounceParams::default();
        let mut bow = BouncingBow::new(p, 0.3, 48_000.0);
        bow.drop_from(0.01);
        let energy = |b: &BouncingBow| {
            let spring = if b.height_m < 0.0 {
                0.5 * b.stiffness * b.height_m * b.height_m
            } else {
                0.0
            };
            0.5 * b.mass_kg * b.velocity_m_per_s.powi(2) + spring + b.pull_n * b.height_m
        };
        let mut last = energy(&bow);
        for _ in 0..96_000 {
            bow.tick();
            let e = energy(&bow);
            // The semi-implicit step's own error per sample (no dissipation to hide it in
            // while flying): far under the energy a bounce loses.
            assert!(e <= last + 1e-7, "{last} -> {e}");
            last = e;
        }
        // The hair damps a bounce at zeta w = 12 /s (restitution 0.6 at 12 Hz): what is
        // left after 2 s is far under 1e-3 N of the 0.3 N pull.
        assert!((bow.tick() - 0.3).abs() < 1e-3);
    }
}
