//! Direct bow controls by MIDI controller: CC21 the bow speed, CC22 the bow force, CC23
//! the bow position, each with the curve of the plugin's own knob (so a controller and the
//! knob move the same way).
//!
//! **Precedence: the last to move wins.** A controller takes its bow control over from
//! the host parameter (`bow_velocity`, `bow_force`, `bow_position`) when it moves; the
//! parameter takes it back as soon as its value changes (automation or the knob). Until
//! then the controller's value holds, smoothed over [`DIRECT_SMOOTHING_S`] so 7-bit
//! steps do not zipper. The dynamics (CC11, CC2, pressure) and the bow stroke act on the
//! result either way. The bow's direction always comes from the parameter's sign and the
//! stroke: CC21 sets the speed.
//!
//! ```
//! use colophony::performer::direct::{DirectBow, CC_BOW_FORCE};
//! use colophony::dsp::vocabulary::BowControl;
//! let mut direct = DirectBow::new(48_000.0);
//! let knob = BowControl::default(); // 1 N
//! assert!(direct.set_controller(CC_BOW_FORCE, 1.0)); // the controller's top: 10 N
//! for _ in 0..48_000 {
//!     direct.apply(knob);
//! }
//! assert!((direct.apply(knob).force_n - 10.0).abs() < 1e-6);
//! // The knob moves: it has the force back at once.
//! let moved = BowControl { force_n: 2.0, ..knob };
//! assert_eq!(direct.apply(moved).force_n, 2.0);
//! ```

use crate::dsp::vocabulary::BowControl;

/// The controller that sets the bow speed.
pub const CC_BOW_VELOCITY: u8 = 21;
/// The controller that sets the bow force.
pub const CC_BOW_FORCE: u8 = 22;
/// The controller that sets the bow position.
pub const CC_BOW_POSITION: u8 = 23;
/// Time constant of a controller's smoothing, s.
pub const DIRECT_SMOOTHING_S: f64 = 0.01;

/// The bow speed at a controller value `x` (0..=1), m/s: `1.5 x^2` (fine steps at the
/// speeds played most: CC 33 gives 0.1 m/s).
pub fn speed_at(x: f64) -> f64 {
    1.5 * x * x
}

/// The bow force at a controller value `x`, N: `10 x^4`, the Bow Force knob's skew
/// (CC 71 gives 1 N).
pub fn force_at(x: f64) -> f64 {
    10.0 * x.powi(4)
}

/// The bow position (beta) at a controller value `x`: 0.02..=0.5, linear, as the knob.
pub fn position_at(x: f64) -> f64 {
    0.02 + 0.48 * x
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Held {
    /// The controller's value in SI units, and the smoothed value now.
    target: f64,
    now: f64,
    /// The parameter's value when the controller took over (`NaN` until the first
    /// sample: the parameter is read then).
    parameter: f64,
}

/// The three direct bow controls (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectBow {
    /// Velocity (speed), force, position.
    held: [Option<Held>; 3],
    smoothing: f64,
}

impl DirectBow {
    pub fn new(sample_rate_hz: f64) -> Self {
        let fs = super::usable_rate(sample_rate_hz);
        Self {
            held: [None; 3],
            smoothing: 1.0 - (-1.0 / (DIRECT_SMOOTHING_S * fs)).exp(),
        }
    }

    /// Controller `cc` at `value` (0..=1); `true` if it is one of the bow's.
    pub fn set_controller(&mut self, cc: u8, value: f64) -> bool {
        let (slot, target) = match cc {
            CC_BOW_VELOCITY => (0, speed_at(value)),
            CC_BOW_FORCE => (1, force_at(value)),
            CC_BOW_POSITION => (2, position_at(value)),
            _ => return false,
        };
        self.held[slot] = Some(match self.held[slot] {
            // Still held: the parameter it took over from stays the reference.
            Some(h) => Held { target, ..h },
            None => Held {
                target,
                now: f64::NAN,
                parameter: f64::NAN,
            },
        });
        true
    }

    /// Whether no controller holds a bow control (then [`DirectBow::apply`] returns the
    /// parameters' bow unchanged).
    #[inline]
    pub fn is_idle(&self) -> bool {
        self.held.iter().all(Option::is_none)
    }

    /// Whether every held control has reached its controller's value (so a sample of
    /// [`DirectBow::apply`] with an unchanged parameter changes nothing).
    pub fn is_settled(&self) -> bool {
        self.held
            .iter()
            .flatten()
            .all(|h| h.now == h.target && !h.parameter.is_nan())
    }

    /// Lets every control go back to its parameter.
    pub fn release(&mut self) {
        self.held = [None; 3];
    }

    /// The bow with the held controls in place of the parameters' (`bow`), one sample.
    #[inline]
    pub fn apply(&mut self, bow: BowControl) -> BowControl {
        if self.is_idle() {
            return bow;
        }
        let params = [bow.velocity_m_per_s, bow.force_n, bow.position_beta];
        let mut out = params;
        for (slot, held) in self.held.iter_mut().enumerate() {
            let Some(h) = held else { continue };
            let param = params[slot];
            if h.parameter.is_nan() {
                // First sample under the controller: glide from where the parameter was.
                h.parameter = param;
                h.now = if slot == 0 { param.abs() } else { param };
            } else if param != h.parameter {
                // The parameter moved: it has its control back.
                *held = None;
                continue;
            }
            h.now += self.smoothing * (h.target - h.now);
            // Within a millionth (-120 dB) the glide is over: about 14 time constants.
            if (h.now - h.target).abs() <= 1e-6 * h.target.abs().max(1e-3) {
                h.now = h.target;
            }
            out[slot] = if slot == 0 {
                // The speed; the direction stays the parameter's.
                if param < 0.0 {
                    -h.now
                } else {
                    h.now
                }
            } else {
                h.now
            };
        }
        BowControl {
            velocity_m_per_s: out[0],
            force_n: out[1],
            position_beta: out[2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curves_match_the_knobs_ends_and_the_defaults() {
        assert_eq!((speed_at(0.0), speed_at(1.0)), (0.0, 1.5));
        assert_eq!((force_at(0.0), force_at(1.0)), (0.0, 10.0));
        assert_eq!((position_at(0.0), position_at(1.0)), (0.02, 0.5));
        // The defaults are reachable near the documented controller values, within one
        // 7-bit step of each curve there (3 x / 127 = 0.006 m/s, 40 x^3 / 127 = 0.055 N):
        // 1.5 (33/127)^2 = 0.101 m/s, 10 (71/127)^4 = 0.98 N.
        assert!((speed_at(33.0 / 127.0) - 0.1).abs() < 0.005);
        assert!((force_at(71.0 / 127.0) - 1.0).abs() < 0.05);
    }

    #[test]
    fn a_controller_takes_its_control_and_the_parameter_takes_it_back() {
        let fs = 48_000.0;
        let mut d = DirectBow::new(fs);
        let bow = BowControl {
            velocity_m_per_s: -0.1,
            force_n: 1.0,
            position_beta: 0.1,
        };
        assert_eq!(d.apply(bow), bow);
        d.set_controller(CC_BOW_VELOCITY, 1.0);
        d.set_controller(CC_BOW_POSITION, 0.5);
        // Smoothed: one time constant reaches 63 % of the step.
        let mut last = bow;
        for _ in 0..(DIRECT_SMOOTHING_S * fs) as usize {
            last = d.apply(bow);
        }
        let share = (last.velocity_m_per_s + 0.1) / (-1.5 + 0.1);
        // 1 - e^-1 = 0.632 after 480 samples; a sample more or less moves it by 0.0008.
        assert!((share - 0.632).abs() < 0.01, "{share}");
        for _ in 0..(0.2 * fs) as usize {
            last = d.apply(bow);
        }
        // The speed is the controller's, the direction the parameter's (up-bow).
        assert_eq!(last.velocity_m_per_s, -1.5);
        assert_eq!(last.position_beta, position_at(0.5));
        assert_eq!(last.force_n, 1.0, "the force stays the parameter's");
        // The position parameter moves: it has the position back; the speed stays held.
        let moved = BowControl {
            position_beta: 0.2,
            ..bow
        };
        let now = d.apply(moved);
        assert_eq!((now.position_beta, now.velocity_m_per_s), (0.2, -1.5));
        assert!(d.set_controller(CC_BOW_VELOCITY, 0.0));
        assert!(!d.set_controller(24, 0.5), "not a bow controller");
        d.release();
        assert!(d.is_idle());
    }
}
