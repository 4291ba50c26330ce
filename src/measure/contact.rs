//! One sample of the bow-string contact, as the probe records it: what the regime
//! classifier ([`super::regime`]) reads and the editor's live views draw.

use crate::dsp::vocabulary::{BowControl, Frame};

/// One sample of the probed string's contact.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactSample {
    /// String velocity at the bow point, m/s.
    pub string_velocity: f32,
    /// String velocity minus bow velocity, m/s.
    pub relative_velocity: f32,
    /// Friction force over bow force.
    pub mu: f32,
}

impl ContactSample {
    /// From one instrument tick and the bow that drove it (`mu` is 0 with the bow lifted).
    #[inline]
    pub fn new(frame: &Frame, bow: &BowControl) -> Self {
        let mu = if bow.force_n > 1e-9 {
            frame.friction_force_n / bow.force_n
        } else {
            0.0
        };
        Self {
            string_velocity: frame.bow_point_velocity_m_per_s as f32,
            relative_velocity: (frame.bow_point_velocity_m_per_s - bow.velocity_m_per_s) as f32,
            mu: mu as f32,
        }
    }
}
