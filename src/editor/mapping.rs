//! Pure functions behind the editor: the XY pad's pixel <-> parameter mapping (the
//! Schelleng window drawn behind it is [`crate::measure::window`]). Nothing here touches
//! egui state or the plugin, so all of it is unit tested.
//!
//! **Pad.** x is the bow velocity, signed (the sign is the bow direction), linear over the
//! `bow_velocity` parameter's range: left edge -1.5 m/s, centre 0, right edge +1.5 m/s.
//! y is the bow force on a log scale from [`FORCE_LOG_MIN_N`] just above the bottom edge
//! to the `bow_force` maximum (10 N) at the top edge. The bottom edge itself is 0 N (the bow
//! lifted); forces between 0 and [`FORCE_LOG_MIN_N`] all sit on the bottom edge, where a
//! log scale cannot show them.
//!

use crate::params::{bow_force_range, bow_velocity_range};
use egui::{pos2, Pos2, Rect};
use nice_plug::prelude::FloatRange;

/// Lowest force on the pad's log scale, N (the row just above the bottom edge).
pub const FORCE_LOG_MIN_N: f32 = 0.01;

/// The pad's axes: bow velocity (m/s, linear) across, bow force (N, log) up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadMapping {
    pub velocity_min: f32,
    pub velocity_max: f32,
    /// Force just above the bottom edge, N (> 0).
    pub force_log_min: f32,
    /// Force at the top edge, N.
    pub force_max: f32,
}

impl Default for PadMapping {
    /// The plugin's parameter ranges: -1.5 .. 1.5 m/s, 0.01 .. 10 N.
    fn default() -> Self {
        let (velocity_min, velocity_max) = range_limits(&bow_velocity_range());
        let (_, force_max) = range_limits(&bow_force_range());
        Self {
            velocity_min,
            velocity_max,
            force_log_min: FORCE_LOG_MIN_N,
            force_max,
        }
    }
}

/// The lower and upper limits of a parameter range.
fn range_limits(range: &FloatRange) -> (f32, f32) {
    match range {
        FloatRange::Linear { min, max }
        | FloatRange::Skewed { min, max, .. }
        | FloatRange::SymmetricalSkewed { min, max, .. } => (*min, *max),
        FloatRange::Reversed(inner) => range_limits(inner),
    }
}

impl PadMapping {
    /// Bow velocity (m/s) at pixel column `x` of the pad `rect`, clamped to the range.
    pub fn x_to_velocity(&self, rect: Rect, x: f32) -> f32 {
        let t = ((x - rect.left()) / rect.width()).clamp(0.0, 1.0);
        self.velocity_min + t * (self.velocity_max - self.velocity_min)
    }

    /// Pixel column of bow velocity `v` (m/s), clamped to the pad.
    pub fn velocity_to_x(&self, rect: Rect, v: f32) -> f32 {
        let t = ((v - self.velocity_min) / (self.velocity_max - self.velocity_min)).clamp(0.0, 1.0);
        rect.left() + t * rect.width()
    }

    /// Height above the bottom edge, 0..1, of force `f` (N): 0 for `f <= force_log_min`.
    fn force_to_height(&self, f: f32) -> f32 {
        if f.is_nan() || f <= self.force_log_min {
            return 0.0;
        }
        ((f / self.force_log_min).ln() / (self.force_max / self.force_log_min).ln()).min(1.0)
    }

    /// Bow force (N) at pixel row `y` of the pad `rect`: 0 at (or below) the bottom edge,
    /// log from `force_log_min` just above it to `force_max` at the top edge.
    pub fn y_to_force(&self, rect: Rect, y: f32) -> f32 {
        let height = ((rect.bottom() - y) / rect.height()).min(1.0);
        if height.is_nan() || height <= 0.0 {
            return 0.0;
        }
        self.force_log_min * (self.force_max / self.force_log_min).powf(height)
    }

    /// Pixel row of bow force `f` (N), clamped to the pad (bottom edge for `f <= force_log_min`).
    pub fn force_to_y(&self, rect: Rect, f: f32) -> f32 {
        rect.bottom() - self.force_to_height(f) * rect.height()
    }

    /// (velocity m/s, force N) under the pointer at `pos`.
    pub fn pos_to_values(&self, rect: Rect, pos: Pos2) -> (f32, f32) {
        (
            self.x_to_velocity(rect, pos.x),
            self.y_to_force(rect, pos.y),
        )
    }

    /// Where the pad draws its handle for velocity `v` and force `f`.
    pub fn values_to_pos(&self, rect: Rect, v: f32, f: f32) -> Pos2 {
        pos2(self.velocity_to_x(rect, v), self.force_to_y(rect, f))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pad() -> (PadMapping, Rect) {
        (
            PadMapping::default(),
            Rect::from_min_size(pos2(20.0, 40.0), egui::vec2(400.0, 300.0)),
        )
    }

    #[test]
    fn pad_axes_follow_the_parameter_ranges() {
        let (m, _) = pad();
        assert_eq!((m.velocity_min, m.velocity_max), (-1.5, 1.5));
        assert_eq!(m.force_max, 10.0);
        assert_eq!(m.force_log_min, 0.01);
    }

    #[test]
    fn pixel_to_value_to_pixel_round_trips() {
        let (m, r) = pad();
        for i in 0..=400 {
            let x = r.left() + i as f32;
            let back = m.velocity_to_x(r, m.x_to_velocity(r, x));
            // f32 on coordinates up to 420 px: an ulp there is 3e-5 px.
            assert!((back - x).abs() < 1e-3, "x {x} came back as {back}");
        }
        for j in 0..=300 {
            let y = r.top() + j as f32;
            let back = m.force_to_y(r, m.y_to_force(r, y));
            // f32 through powf and ln: a relative ulp of the force moves the row by
            // 300 / ln(1000) x 1.2e-7 = 5e-6 px, the coordinates' own ulp is 3e-5 px.
            assert!((back - y).abs() < 1e-2, "y {y} came back as {back}");
        }
    }

    #[test]
    fn value_to_pixel_to_value_round_trips_inside_the_log_range() {
        let (m, r) = pad();
        for v in [-1.5f32, -0.7, -0.01, 0.0, 0.1, 1.2, 1.5] {
            let back = m.x_to_velocity(r, m.velocity_to_x(r, v));
            // f32: an ulp of 1.5 m/s is 1.2e-7, of the 420 px it passes through 3e-5 px
            // (2e-7 m/s).
            assert!((back - v).abs() < 1e-5, "v {v} came back as {back}");
        }
        for f in [0.011f32, 0.1, 0.5, 1.0, 3.3, 10.0] {
            let back = m.y_to_force(r, m.force_to_y(r, f));
            // f32 through powf and ln: a relative ulp (1.2e-7) times ln(1000) = 6.9, and
            // the pixel's own.
            assert!((back / f - 1.0).abs() < 1e-4, "f {f} came back as {back}");
        }
    }

    #[test]
    fn velocity_is_linear_and_centred_on_zero() {
        let (m, r) = pad();
        assert_eq!(m.x_to_velocity(r, r.left()), -1.5);
        assert_eq!(m.x_to_velocity(r, r.right()), 1.5);
        // f32 rounding of values up to 1.5.
        assert!(m.x_to_velocity(r, r.center().x).abs() < 1e-6);
        let quarter = m.x_to_velocity(r, r.left() + 0.75 * r.width());
        assert!((quarter - 0.75).abs() < 1e-6);
    }

    #[test]
    fn force_is_log_with_zero_at_the_bottom_edge() {
        let (m, r) = pad();
        assert_eq!(m.y_to_force(r, r.bottom()), 0.0);
        assert_eq!(m.y_to_force(r, r.bottom() + 5.0), 0.0);
        // f32 powf: an ulp of 10 N is 1e-6.
        assert!((m.y_to_force(r, r.top()) - 10.0).abs() < 1e-4);
        // Three decades over the height: the middle is 0.01 * 1000^0.5 = 0.316 N.
        let mid = m.y_to_force(r, r.center().y);
        // f32 rounding, and the constant written to seven digits.
        assert!((mid - 0.316_227_8).abs() < 1e-4, "mid {mid}");
        // One pixel above the bottom edge is just above the log floor: one row of 300 is
        // 0.01 x 1000^(1/300) = 0.01023 N.
        let above = m.y_to_force(r, r.bottom() - 1.0);
        assert!(above > 0.01 && above < 0.0105, "above {above}");
        // Forces the log scale cannot show sit on the bottom edge.
        assert_eq!(m.force_to_y(r, 0.0), r.bottom());
        assert_eq!(m.force_to_y(r, 0.005), r.bottom());
        assert_eq!(m.force_to_y(r, -1.0), r.bottom());
    }

    #[test]
    fn mappings_are_monotone_and_clamped() {
        let (m, r) = pad();
        let mut last_v = f32::NEG_INFINITY;
        let mut last_f = f32::NEG_INFINITY;
        for i in -50..=450 {
            let v = m.x_to_velocity(r, r.left() + i as f32);
            assert!(v >= last_v && (-1.5..=1.5).contains(&v));
            last_v = v;
            // Rows counted upwards from below the bottom edge to above the top edge.
            let f = m.y_to_force(r, r.bottom() - i as f32 * 0.75);
            assert!(
                f >= last_f && (0.0..=10.0).contains(&f),
                "f {f} after {last_f}"
            );
            last_f = f;
        }
        let mut last_y = f32::INFINITY;
        for k in 0..=200 {
            let f = 10f32.powf(-3.0 + k as f32 * 0.025);
            let y = m.force_to_y(r, f);
            assert!(y <= last_y && y >= r.top() && y <= r.bottom());
            last_y = y;
        }
    }

    #[test]
    fn positions_and_values_round_trip_together() {
        let (m, r) = pad();
        let p = m.values_to_pos(r, 0.1, 1.0);
        let (v, f) = m.pos_to_values(r, p);
        // f32 rounding through the pixel and back, as in the round trips above.
        assert!((v - 0.1).abs() < 1e-5 && (f - 1.0).abs() < 1e-4);
    }
}
