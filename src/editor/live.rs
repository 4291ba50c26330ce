//! Live views of the simulation, fed from the audio thread without locks or allocation.
//!
//! [`Scope`] is a [`crate::telemetry::Ring`] of the probed string's contact signals, one
//! entry per sample: the string velocity at the bow, the relative (string minus bow)
//! velocity and the friction coefficient `F / F_N` (friction force over bow force). The
//! audio thread writes with six atomic stores per sample (plain moves on x86), and only while
//! an editor that shows the live views is open ([`super::EditorLink::is_listening`], read
//! once per block); otherwise nothing is computed or written for them. The editor copies
//! the newest samples out and drops any the writer overwrote during the copy, so both sides
//! are wait-free.

use crate::measure::contact::ContactSample;
use crate::telemetry::{Record, Ring};
use egui::{pos2, vec2, Align2, Color32, FontId, Rect, Shape, Stroke, Ui};
use std::sync::atomic::{AtomicU32, Ordering};

/// Ring length, samples (a power of two): three periods of cello C at 96 kHz fit.
pub const SCOPE_LEN: usize = 1 << 13;

impl Record for ContactSample {
    const WORDS: usize = 3;

    #[inline]
    fn store(&self, words: &[AtomicU32]) {
        words[0].store(self.string_velocity.to_bits(), Ordering::Relaxed);
        words[1].store(self.relative_velocity.to_bits(), Ordering::Relaxed);
        words[2].store(self.mu.to_bits(), Ordering::Relaxed);
    }

    fn load(words: &[AtomicU32]) -> Self {
        let f = |i: usize| f32::from_bits(words[i].load(Ordering::Relaxed));
        Self {
            string_velocity: f(0),
            relative_velocity: f(1),
            mu: f(2),
        }
    }
}

/// The contact samples ([`crate::telemetry::Ring`]) and the rate they are written at.
#[derive(Debug)]
pub struct Scope {
    ring: Ring<ContactSample>,
    sample_rate_bits: AtomicU32,
}

impl Default for Scope {
    fn default() -> Self {
        Self {
            ring: Ring::new(SCOPE_LEN),
            sample_rate_bits: AtomicU32::new(48_000f32.to_bits()),
        }
    }
}

impl Scope {
    /// Audio thread (one writer only): appends one sample.
    #[inline]
    pub fn push(&self, sample: ContactSample) {
        self.ring.push(&sample);
    }

    /// Samples written so far.
    pub fn written(&self) -> u64 {
        self.ring.written()
    }

    /// Main thread: the rate the samples are written at (set on activation).
    pub fn set_sample_rate(&self, hz: f32) {
        self.sample_rate_bits.store(hz.to_bits(), Ordering::Relaxed);
    }

    pub fn sample_rate(&self) -> f32 {
        f32::from_bits(self.sample_rate_bits.load(Ordering::Relaxed))
    }

    /// Editor: replaces `out` with up to the `max` newest samples, oldest first; samples
    /// the writer overwrote while they were copied are left out.
    pub fn copy_latest(&self, max: usize, out: &mut Vec<ContactSample>) {
        self.ring.copy_latest(max, out);
    }
}

/// Symmetric plot limit for `values`: the largest magnitude, at least `floor`, rounded up to
/// a 1-2-5 step so the axis does not jitter every frame.
pub fn nice_limit(values: impl Iterator<Item = f32>, floor: f32) -> f32 {
    let peak = values
        .filter(|v| v.is_finite())
        .fold(floor, |acc, v| acc.max(v.abs()));
    let exponent = peak.log10().floor() as i32;
    // step * 10^exponent, divided rather than multiplied below 1 so 0.05 prints as 0.05.
    let scaled = |step: f32| {
        if exponent < 0 {
            step / 10f32.powi(-exponent)
        } else {
            step * 10f32.powi(exponent)
        }
    };
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(scaled)
        .find(|&limit| peak <= limit * 1.0001)
        .unwrap_or_else(|| scaled(10.0))
}

/// A framed plot area with a title and symmetric axes labelled with their units.
struct Axes {
    rect: Rect,
    x_lim: (f32, f32),
    y_lim: f32,
}

impl Axes {
    fn to_screen(&self, x: f32, y: f32) -> egui::Pos2 {
        let tx = (x - self.x_lim.0) / (self.x_lim.1 - self.x_lim.0);
        let ty = 0.5 - 0.5 * y / self.y_lim;
        pos2(
            self.rect.left() + tx.clamp(0.0, 1.0) * self.rect.width(),
            self.rect.top() + ty.clamp(0.0, 1.0) * self.rect.height(),
        )
    }

    fn frame(&self, ui: &Ui, title: &str, x_label: &str, y_unit: &str) {
        let painter = ui.painter();
        let visuals = ui.visuals();
        let text = visuals.text_color();
        let grid = visuals.widgets.noninteractive.bg_stroke.color;
        let small = FontId::proportional(11.0);
        painter.rect_filled(self.rect, 3.0, visuals.extreme_bg_color);
        painter.hline(
            self.rect.x_range(),
            self.rect.center().y,
            Stroke::new(1.0, grid),
        );
        painter.text(
            self.rect.left_top() + vec2(4.0, 2.0),
            Align2::LEFT_TOP,
            title,
            small.clone(),
            text,
        );
        painter.text(
            pos2(self.rect.left() - 3.0, self.rect.top()),
            Align2::RIGHT_TOP,
            format!("{:+} {y_unit}", self.y_lim),
            small.clone(),
            text,
        );
        painter.text(
            pos2(self.rect.left() - 3.0, self.rect.bottom()),
            Align2::RIGHT_BOTTOM,
            format!("{:+} {y_unit}", -self.y_lim),
            small.clone(),
            text,
        );
        painter.text(
            pos2(self.rect.center().x, self.rect.bottom() + 2.0),
            Align2::CENTER_TOP,
            x_label,
            small,
            text,
        );
    }
}

const TRACE: Color32 = Color32::from_rgb(120, 210, 160);
const BOW_LINE: Color32 = Color32::from_rgb(250, 225, 90);

/// String velocity at the bow against time, with the bow velocity as a line (the string
/// sticks to the bow where the trace meets it).
pub fn paint_velocity_trace(
    ui: &Ui,
    rect: Rect,
    samples: &[ContactSample],
    sample_rate: f32,
    bow_velocity: f32,
) {
    let duration_ms = samples.len() as f32 * 1000.0 / sample_rate;
    let y_lim = nice_limit(
        samples
            .iter()
            .map(|s| s.string_velocity)
            .chain([bow_velocity]),
        0.05,
    );
    let axes = Axes {
        rect,
        x_lim: (-duration_ms.max(1e-3), 0.0),
        y_lim,
    };
    axes.frame(
        ui,
        "string velocity at the bow",
        &format!("time, last {duration_ms:.1} ms"),
        "m/s",
    );
    let painter = ui.painter();
    let bow = axes.to_screen(0.0, bow_velocity).y;
    painter.hline(
        rect.x_range(),
        bow,
        Stroke::new(1.0, BOW_LINE.gamma_multiply(0.7)),
    );
    let n = samples.len();
    if n >= 2 {
        let points = samples
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let t = (i as f32 - (n - 1) as f32) * 1000.0 / sample_rate;
                axes.to_screen(t, s.string_velocity)
            })
            .collect();
        painter.add(Shape::line(points, Stroke::new(1.2, TRACE)));
    }
}

/// Friction coefficient against relative velocity: the stick/slip hysteresis loop.
pub fn paint_friction_loop(ui: &Ui, rect: Rect, samples: &[ContactSample]) {
    let x_lim = nice_limit(samples.iter().map(|s| s.relative_velocity), 0.05);
    let y_lim = nice_limit(samples.iter().map(|s| s.mu), 0.5);
    let axes = Axes {
        rect,
        x_lim: (-x_lim, x_lim),
        y_lim,
    };
    axes.frame(
        ui,
        "friction F/F_N vs relative velocity",
        &format!("string - bow velocity, -{x_lim} .. +{x_lim} m/s"),
        "",
    );
    let painter = ui.painter();
    let grid = ui.visuals().widgets.noninteractive.bg_stroke.color;
    painter.vline(rect.center().x, rect.y_range(), Stroke::new(1.0, grid));
    if samples.len() >= 2 {
        let points = samples
            .iter()
            .map(|s| axes.to_screen(s.relative_velocity, s.mu))
            .collect();
        painter.add(Shape::line(points, Stroke::new(1.0, TRACE)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::vocabulary::{BowControl, Frame};

    fn sample(x: f32) -> ContactSample {
        ContactSample {
            string_velocity: x,
            relative_velocity: -x,
            mu: 2.0 * x,
        }
    }

    #[test]
    fn scope_returns_the_newest_samples_in_order() {
        let scope = Scope::default();
        let mut out = Vec::new();
        scope.copy_latest(100, &mut out);
        assert!(out.is_empty());
        for i in 0..10 {
            scope.push(sample(i as f32));
        }
        scope.copy_latest(4, &mut out);
        assert_eq!(out, (6..10).map(|i| sample(i as f32)).collect::<Vec<_>>());
        scope.copy_latest(100, &mut out);
        assert_eq!(out.len(), 10);
    }

    #[test]
    fn scope_wraps_and_never_returns_more_than_it_holds() {
        let scope = Scope::default();
        let total = 3 * SCOPE_LEN + 17;
        for i in 0..total {
            scope.push(sample(i as f32));
        }
        let mut out = Vec::new();
        scope.copy_latest(usize::MAX, &mut out);
        // Every slot holds a whole sample (a slot turns stale only while the writer marks
        // it), so the whole ring comes back, and no more.
        assert_eq!(out.len(), SCOPE_LEN);
        assert_eq!(out.last().unwrap().string_velocity, (total - 1) as f32);
        for pair in out.windows(2) {
            assert_eq!(pair[1].string_velocity - pair[0].string_velocity, 1.0);
        }
    }

    #[test]
    fn scope_reader_sees_only_whole_consistent_samples_while_written() {
        let scope = std::sync::Arc::new(Scope::default());
        let writer = {
            let scope = scope.clone();
            std::thread::spawn(move || {
                for i in 0..400_000u32 {
                    scope.push(sample(i as f32));
                }
            })
        };
        let mut out = Vec::new();
        while !writer.is_finished() {
            scope.copy_latest(2048, &mut out);
            for s in &out {
                assert_eq!(s.relative_velocity, -s.string_velocity);
                assert_eq!(s.mu, 2.0 * s.string_velocity);
            }
            for pair in out.windows(2) {
                assert_eq!(pair[1].string_velocity - pair[0].string_velocity, 1.0);
            }
        }
        writer.join().unwrap();
    }

    #[test]
    fn contact_sample_is_relative_to_the_bow_and_normalised_by_its_force() {
        let frame = Frame {
            audio: 0.0,
            bow_point_velocity_m_per_s: -0.8,
            friction_force_n: 0.4,
        };
        let bow = BowControl {
            velocity_m_per_s: 0.1,
            force_n: 2.0,
            position_beta: 0.1,
        };
        let s = ContactSample::new(&frame, &bow);
        assert_eq!(s.string_velocity, -0.8);
        // The sample holds f32: an ulp near 1 is 1.2e-7.
        assert!((s.relative_velocity + 0.9).abs() < 1e-6);
        assert!((s.mu - 0.2).abs() < 1e-6);
        let lifted = BowControl {
            force_n: 0.0,
            ..bow
        };
        assert_eq!(ContactSample::new(&frame, &lifted).mu, 0.0);
    }

    #[test]
    fn plot_limits_snap_to_one_two_five() {
        assert_eq!(nice_limit([0.3f32, -0.7].into_iter(), 0.05), 1.0);
        assert_eq!(nice_limit([0.15f32].into_iter(), 0.05), 0.2);
        assert_eq!(nice_limit([0.01f32].into_iter(), 0.05), 0.05);
        assert_eq!(nice_limit([f32::NAN, 3.0].into_iter(), 0.5), 5.0);
    }
}
