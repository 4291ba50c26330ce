//! The XY pad: bow velocity across, bow force up (log), with the Schelleng window behind.
//!
//! **Gestures.** While the primary button is held on the pad the pad owns both parameters:
//! on the press it calls `begin_set_parameter` for Bow Velocity and Bow Force, on every
//! pointer move `set_parameter` for both, and on the release (or when the editor closes,
//! [`XyPad::release`]) `end_set_parameter` for both, so a host records the stroke as
//! automation. The press is detected with `is_pointer_button_down_on`, not `drag_started`,
//! which egui only reports after the pointer has moved past its drag threshold (too late for
//! the `begin`). A press and release within one frame (a quick click) sends the three calls
//! at once.
//!
//! **Following the host.** When not dragged the handle sits at the parameters' current
//! values, so host automation and other controls move it. While dragged it sits where the
//! pointer put it (a CLAP host applies a GUI change only at its next flush).

use super::mapping::PadMapping;
use crate::measure::window::SchellengWindow;
use egui::{
    pos2, vec2, Align2, Color32, FontId, Mesh, Rect, Response, Sense, Shape, Stroke, Ui, Vec2,
};
use nice_plug::prelude::{FloatParam, ParamSetter};

/// Accessible label of the pad (the editor tests find it by this name).
pub const PAD_LABEL: &str = "Bow velocity and force pad";
/// Margin left of the pad for the force tick labels, points.
const LEFT_MARGIN: f32 = 46.0;
/// Margin below the pad for the velocity tick labels, points.
const BOTTOM_MARGIN: f32 = 34.0;

pub const MAX_FORCE_COLOUR: Color32 = Color32::from_rgb(235, 140, 60);
pub const MIN_FORCE_COLOUR: Color32 = Color32::from_rgb(90, 170, 235);
const WINDOW_FILL: Color32 = Color32::from_rgba_premultiplied(40, 90, 45, 90);
const HANDLE_COLOUR: Color32 = Color32::from_rgb(250, 225, 90);
/// The ring marking the bow as played.
/// Where the model was measured to hold Helmholtz motion at no force of the window.
pub const NO_WINDOW_TEXT: &str = "no force measured to hold Helmholtz motion";
const PLAYED_COLOUR: Color32 = Color32::from_rgb(120, 200, 255);

/// State of one pad across frames.
#[derive(Debug, Clone, Default)]
pub struct XyPad {
    pub mapping: PadMapping,
    dragging: bool,
    /// The values last sent while dragging (velocity m/s, force N).
    sent: Option<(f32, f32)>,
    /// The played bow the last frame marked (velocity m/s, force N), if any.
    played: Option<(f32, f32)>,
    /// The played bow to mark at the next [`XyPad::show`].
    played_in: Option<(f32, f32)>,
}

impl XyPad {
    /// The bow as played (velocity m/s, force N; `None`: no bow on a string) for the next
    /// [`XyPad::show`] to mark.
    pub fn mark_played(&mut self, bow: Option<(f32, f32)>) {
        self.played_in = bow;
    }

    /// The bow as played that the last frame marked on the pad (velocity m/s, force N):
    /// `None` while no bow is on a string or while it sits on the handle.
    pub fn played_marker(&self) -> Option<(f32, f32)> {
        self.played
    }

    /// Whether a gesture is open (begin sent, end not yet).
    pub fn is_dragging(&self) -> bool {
        self.dragging
    }

    /// Draws the pad in `outer` (tick labels included) and handles the pointer. `window` is
    /// the Schelleng window to draw behind, if the bow is on a string, with the shares of
    /// its `F_max` between which the model was measured to hold Helmholtz motion
    /// (`played`: `None` where no force held it).
    #[allow(clippy::too_many_arguments)]
    pub fn show(
        &mut self,
        ui: &mut Ui,
        outer: Rect,
        setter: &ParamSetter,
        velocity: &FloatParam,
        force: &FloatParam,
        window: Option<&SchellengWindow>,
        played: Option<(f64, f64)>,
    ) -> Response {
        let rect = Rect::from_min_max(
            pos2(outer.left() + LEFT_MARGIN, outer.top()),
            pos2(outer.right() - 4.0, outer.bottom() - BOTTOM_MARGIN),
        );
        ui.allocate_rect(outer, Sense::hover());
        let response = ui.interact(
            rect,
            ui.make_persistent_id("xy_pad"),
            Sense::click_and_drag(),
        );
        self.handle_pointer(&response, rect, setter, velocity, force);

        let (v, f) = match (self.dragging, self.sent) {
            (true, Some(sent)) => sent,
            _ => (velocity.value(), force.value()),
        };
        // The handle's values are the pad's accessible value (the tests read them there).
        response.widget_info(|| {
            let mut info =
                egui::WidgetInfo::labeled(egui::Role::Slider, ui.is_enabled(), PAD_LABEL);
            info.current_text_value = Some(pad_value_text(v, f));
            info
        });
        self.paint(ui, rect, window, played, v, f);
        // The bow as the performer plays it (the strokes, the dynamics and the MIDI
        // controllers move it away from the parameters): a ring where it differs from the
        // handle by more than a couple of pixels.
        self.played = self.played_in.filter(|&(pv, pf)| {
            let (a, b) = (
                self.mapping.values_to_pos(rect, pv, pf),
                self.mapping.values_to_pos(rect, v, f),
            );
            a.distance(b) > 2.0 && pv.is_finite() && pf.is_finite()
        });
        if let Some((pv, pf)) = self.played {
            let p = self.mapping.values_to_pos(rect, pv, pf.max(0.0));
            ui.painter()
                .circle_stroke(p, 7.0, Stroke::new(2.0, PLAYED_COLOUR));
        }
        if let Some(hover) = response.hover_pos() {
            let (hv, hf) = self.mapping.pos_to_values(rect, hover);
            response
                .clone()
                .on_hover_text_at_pointer(pad_value_text(hv, hf));
        }
        response
    }

    fn handle_pointer(
        &mut self,
        response: &Response,
        rect: Rect,
        setter: &ParamSetter,
        velocity: &FloatParam,
        force: &FloatParam,
    ) {
        let down = response.is_pointer_button_down_on();
        if down {
            if !self.dragging {
                setter.begin_set_parameter(velocity);
                setter.begin_set_parameter(force);
                self.dragging = true;
                self.sent = None;
            }
            if let Some(pos) = response.interact_pointer_pos() {
                self.send(
                    setter,
                    velocity,
                    force,
                    self.mapping.pos_to_values(rect, pos),
                );
            }
        } else if self.dragging {
            // Released: the last move may have come with the release.
            if let Some(pos) = response.interact_pointer_pos() {
                self.send(
                    setter,
                    velocity,
                    force,
                    self.mapping.pos_to_values(rect, pos),
                );
            }
            self.release(setter, velocity, force);
        } else if response.clicked() {
            if let Some(pos) = response.interact_pointer_pos() {
                setter.begin_set_parameter(velocity);
                setter.begin_set_parameter(force);
                self.dragging = true;
                self.send(
                    setter,
                    velocity,
                    force,
                    self.mapping.pos_to_values(rect, pos),
                );
                self.release(setter, velocity, force);
            }
        }
    }

    fn send(
        &mut self,
        setter: &ParamSetter,
        velocity: &FloatParam,
        force: &FloatParam,
        values: (f32, f32),
    ) {
        if self.sent == Some(values) {
            return;
        }
        setter.set_parameter(velocity, values.0);
        setter.set_parameter(force, values.1);
        self.sent = Some(values);
    }

    /// Ends an open gesture (pointer released, or the editor closing mid-drag).
    pub fn release(&mut self, setter: &ParamSetter, velocity: &FloatParam, force: &FloatParam) {
        if self.dragging {
            setter.end_set_parameter(velocity);
            setter.end_set_parameter(force);
            self.dragging = false;
        }
    }

    fn paint(
        &self,
        ui: &Ui,
        rect: Rect,
        window: Option<&SchellengWindow>,
        played: Option<(f64, f64)>,
        v: f32,
        f: f32,
    ) {
        let m = &self.mapping;
        let visuals = ui.visuals();
        let painter = ui.painter();
        let text_colour = visuals.text_color();
        let grid = visuals.widgets.noninteractive.bg_stroke.color;
        let small = FontId::proportional(11.0);
        painter.rect_filled(rect, 3.0, visuals.extreme_bg_color);

        if let Some(w) = window {
            self.paint_window(ui, rect, w, played);
        }

        // Velocity grid every 0.5 m/s, the zero line stronger.
        let mut tick = (m.velocity_min / 0.5).ceil() * 0.5;
        while tick <= m.velocity_max + 1e-4 {
            let x = m.velocity_to_x(rect, tick);
            let stroke = if tick.abs() < 1e-4 {
                Stroke::new(1.5, text_colour.gamma_multiply(0.5))
            } else {
                Stroke::new(1.0, grid)
            };
            painter.vline(x, rect.y_range(), stroke);
            painter.text(
                pos2(x, rect.bottom() + 3.0),
                Align2::CENTER_TOP,
                format!("{tick:.1}"),
                small.clone(),
                text_colour,
            );
            tick += 0.5;
        }
        painter.text(
            pos2(rect.center().x, rect.bottom() + 17.0),
            Align2::CENTER_TOP,
            "bow velocity (m/s; negative = up-bow)",
            small.clone(),
            text_colour,
        );

        // Force grid: decades labelled, 2 and 5 faint. The log floor shares the bottom
        // edge with 0 N, which is the label there.
        for exponent in -4..=3 {
            let decade = 10f32.powi(exponent);
            if decade > m.force_max * 1.0001 {
                break;
            }
            for sub in [2.0, 5.0] {
                let fs = decade * sub;
                if fs > m.force_log_min && fs < m.force_max {
                    let ys = m.force_to_y(rect, fs);
                    painter.hline(
                        rect.x_range(),
                        ys,
                        Stroke::new(0.5, grid.gamma_multiply(0.5)),
                    );
                }
            }
            if decade <= m.force_log_min * 1.0001 {
                continue;
            }
            let y = m.force_to_y(rect, decade);
            painter.hline(rect.x_range(), y, Stroke::new(1.0, grid));
            painter.text(
                pos2(rect.left() - 4.0, y),
                Align2::RIGHT_CENTER,
                format!("{} N", format_decade(exponent)),
                small.clone(),
                text_colour,
            );
        }
        painter.text(
            pos2(rect.left() - 4.0, rect.bottom()),
            Align2::RIGHT_BOTTOM,
            "0 N",
            small.clone(),
            text_colour,
        );

        // The handle: cross hairs and a dot.
        let p = m.values_to_pos(rect, v, f);
        let hair = Stroke::new(1.0, HANDLE_COLOUR.gamma_multiply(0.5));
        painter.vline(p.x, rect.y_range(), hair);
        painter.hline(rect.x_range(), p.y, hair);
        painter.circle(p, 6.0, HANDLE_COLOUR, Stroke::new(1.5, Color32::BLACK));
        painter.text(
            rect.left_top() + vec2(6.0, 4.0),
            Align2::LEFT_TOP,
            pad_value_text(v, f),
            FontId::monospace(12.0),
            text_colour,
        );
    }

    /// The Schelleng window: both of its curves drawn thin, and the band the model was
    /// measured to hold Helmholtz motion in (`played`, shares of `F_max`) filled between
    /// its own two edges.
    fn paint_window(&self, ui: &Ui, rect: Rect, w: &SchellengWindow, played: Option<(f64, f64)>) {
        let m = &self.mapping;
        let painter = ui.painter();
        let columns = (rect.width() / 2.0).ceil().max(2.0) as usize;
        let mut mesh = Mesh::default();
        let mut upper = Vec::with_capacity(columns + 1);
        let mut lower = Vec::with_capacity(columns + 1);
        let mut played_upper = Vec::with_capacity(columns + 1);
        let mut played_lower = Vec::with_capacity(columns + 1);
        for i in 0..=columns {
            let x = rect.left() + rect.width() * i as f32 / columns as f32;
            let vb = m.x_to_velocity(rect, x) as f64;
            let f_max = w.max_force_n(vb);
            upper.push(pos2(x, m.force_to_y(rect, f_max as f32)));
            lower.push(pos2(x, m.force_to_y(rect, w.min_force_n(vb) as f32)));
            if let Some((lo, hi)) = played {
                let y_hi = m.force_to_y(rect, (hi * f_max) as f32);
                let y_lo = m.force_to_y(rect, (lo * f_max) as f32);
                played_upper.push(pos2(x, y_hi));
                played_lower.push(pos2(x, y_lo));
                mesh.colored_vertex(pos2(x, y_hi), WINDOW_FILL);
                mesh.colored_vertex(pos2(x, y_lo), WINDOW_FILL);
                if i > 0 {
                    let k = 2 * i as u32;
                    mesh.add_triangle(k - 2, k - 1, k);
                    mesh.add_triangle(k - 1, k + 1, k);
                }
            }
        }
        painter.add(Shape::mesh(mesh));
        painter.add(Shape::line(upper, Stroke::new(1.0, MAX_FORCE_COLOUR)));
        painter.add(Shape::line(lower, Stroke::new(1.0, MIN_FORCE_COLOUR)));
        if played.is_some() {
            painter.add(Shape::line(
                played_upper,
                Stroke::new(2.0, MAX_FORCE_COLOUR),
            ));
            painter.add(Shape::line(
                played_lower,
                Stroke::new(2.0, MIN_FORCE_COLOUR),
            ));
        }

        // Curve and region names on the right half, where the curves are apart.
        let font = FontId::proportional(12.0);
        let label_v = m.velocity_max * 0.8;
        let at = |f: f64| m.values_to_pos(rect, label_v, f as f32);
        let f_max = w.max_force_n(label_v as f64);
        let f_min = w.min_force_n(label_v as f64);
        let top = rect.top() + 14.0;
        let bottom = rect.bottom() - 14.0;
        let y_max = at(f_max).y;
        let y_min = at(f_min).y;
        if y_max > top {
            painter.text(
                at(f_max) - Vec2::new(0.0, 4.0),
                Align2::CENTER_BOTTOM,
                "F_max",
                font.clone(),
                MAX_FORCE_COLOUR,
            );
            if y_max > top + 16.0 {
                painter.text(
                    pos2(at(f_max).x, (rect.top() + y_max) * 0.5),
                    Align2::CENTER_CENTER,
                    "raucous",
                    font.clone(),
                    ui.visuals().weak_text_color(),
                );
            }
        }
        if y_min < bottom {
            painter.text(
                at(f_min) + Vec2::new(0.0, 4.0),
                Align2::CENTER_TOP,
                "F_min",
                font.clone(),
                MIN_FORCE_COLOUR,
            );
            if y_min < bottom - 16.0 {
                painter.text(
                    pos2(at(f_min).x, (rect.bottom() + y_min) * 0.5),
                    Align2::CENTER_CENTER,
                    "multiple slips",
                    font.clone(),
                    ui.visuals().weak_text_color(),
                );
            }
        }
        match played {
            Some((lo, hi)) => {
                let (y_hi, y_lo) = (at(hi * f_max).y, at(lo * f_max).y);
                if y_lo - y_hi > 30.0 {
                    painter.text(
                        pos2(at(f_max).x, (y_hi + y_lo) * 0.5),
                        Align2::CENTER_CENTER,
                        "Helmholtz",
                        font,
                        ui.visuals().strong_text_color(),
                    );
                }
            }
            None => {
                painter.text(
                    pos2(at(f_max).x, (y_max + y_min) * 0.5),
                    Align2::CENTER_CENTER,
                    NO_WINDOW_TEXT,
                    font,
                    ui.visuals().weak_text_color(),
                );
            }
        }
    }
}

/// `10^exponent` written out (0.1, 1, 10), without binary rounding noise.
fn format_decade(exponent: i32) -> String {
    if exponent >= 0 {
        format!("{}", 10u32.pow(exponent as u32))
    } else {
        format!("0.{}1", "0".repeat((-exponent - 1) as usize))
    }
}

/// The pad's value as text: velocity and force with their units.
pub fn pad_value_text(v: f32, f: f32) -> String {
    format!("{}   {}", format_velocity(v), format_force(f))
}

pub fn format_velocity(v: f32) -> String {
    format!("v_b {v:+.3} m/s")
}

pub fn format_force(f: f32) -> String {
    if f < 0.1 {
        format!("F {f:.4} N")
    } else {
        format!("F {f:.3} N")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decade_labels_have_no_rounding_noise() {
        assert_eq!(format_decade(-2), "0.01");
        assert_eq!(format_decade(-1), "0.1");
        assert_eq!(format_decade(0), "1");
        assert_eq!(format_decade(1), "10");
    }
}
