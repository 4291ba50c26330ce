//! Live views of paper B's thermal bow: the temperature across the bow and which nodes slip,
//! fed from the audio thread without locks or allocation.
//!
//! **Transport.** While an open editor listens and the thermal instrument plays, the audio
//! thread adds the probed string's node temperatures and slip states to a [`NodeProbe`]
//! (its own plain arrays, about a hundred additions a sample) and every
//! [`RECORD_INTERVAL_S`] publishes their means as one [`NodeRecord`] into the [`NodeRing`],
//! the telemetry ring every live view uses ([`crate::telemetry::Ring`]: seqlocked slots of
//! atomics, so a reader never sees a torn record and neither side waits). The probe takes
//! plain slices: the editor knows nothing of the thermal string.
//!
//! **Views.** [`paint_temperature_profile`] draws the newest record's temperatures across
//! the bow (K above ambient, the model's unit) over the band they spanned in the records
//! shown; [`paint_slip_image`] draws the slip fraction of every node over the last records,
//! a node x time image (bright: slipping all the record, dark: sticking).

use crate::telemetry::{Record, Ring};
use egui::{pos2, vec2, Align2, Color32, FontId, Mesh, Rect, Shape, Stroke, Ui};
use std::sync::atomic::{AtomicU32, Ordering};

/// Most nodes a record holds: the most the thermal bow has on any string.
pub const MAX_NODES: usize = crate::dsp::thermal_instrument::MAX_NODES;
/// Records in the ring (a power of two): 1.28 s at one record every 5 ms.
pub const RING_LEN: usize = 256;
/// Time over which one record averages, s: short enough to follow a bow stroke, long
/// enough that a record spans a period of the open strings down to 200 Hz.
pub const RECORD_INTERVAL_S: f32 = 0.005;

/// The mean state of the bow's nodes over one [`RECORD_INTERVAL_S`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeRecord {
    /// Nodes on the probed string (the first `count` entries below are used).
    pub count: usize,
    /// Mean temperature per node, K above ambient; node 0 is on the bridge side.
    pub temperature_kelvin: [f32; MAX_NODES],
    /// Fraction of the samples each node slipped, 0 .. 1.
    pub slip_fraction: [f32; MAX_NODES],
}

impl Default for NodeRecord {
    fn default() -> Self {
        Self {
            count: 0,
            temperature_kelvin: [0.0; MAX_NODES],
            slip_fraction: [0.0; MAX_NODES],
        }
    }
}

impl Record for NodeRecord {
    /// The node count, then every node's temperature and slip fraction.
    const WORDS: usize = 1 + 2 * MAX_NODES;

    fn store(&self, words: &[AtomicU32]) {
        let count = self.count.min(MAX_NODES);
        words[0].store(count as u32, Ordering::Relaxed);
        for i in 0..count {
            words[1 + i].store(self.temperature_kelvin[i].to_bits(), Ordering::Relaxed);
            words[1 + MAX_NODES + i].store(self.slip_fraction[i].to_bits(), Ordering::Relaxed);
        }
    }

    fn load(words: &[AtomicU32]) -> Self {
        let mut record = NodeRecord {
            count: (words[0].load(Ordering::Relaxed) as usize).min(MAX_NODES),
            ..NodeRecord::default()
        };
        for i in 0..record.count {
            record.temperature_kelvin[i] = f32::from_bits(words[1 + i].load(Ordering::Relaxed));
            record.slip_fraction[i] =
                f32::from_bits(words[1 + MAX_NODES + i].load(Ordering::Relaxed));
        }
        record
    }
}

/// The node records' ring ([`crate::telemetry::Ring`]), [`RING_LEN`] long.
pub type NodeRing = Ring<NodeRecord>;

/// A node ring of [`RING_LEN`] records.
pub fn node_ring() -> NodeRing {
    Ring::new(RING_LEN)
}

/// The audio thread's running sums for the next record (plain arrays, no allocation).
#[derive(Debug, Clone)]
pub struct NodeProbe {
    count: usize,
    samples: u32,
    temperature_sum: [f64; MAX_NODES],
    slipping: [u32; MAX_NODES],
}

impl Default for NodeProbe {
    fn default() -> Self {
        Self {
            count: 0,
            samples: 0,
            temperature_sum: [0.0; MAX_NODES],
            slipping: [0; MAX_NODES],
        }
    }
}

impl NodeProbe {
    /// Audio thread, once per sample while listening to the thermal instrument: adds the
    /// probed string's node temperatures (K) and sliding velocities (m/s; a node slips
    /// where its velocity is not zero), and publishes a record into `link.nodes` when one
    /// is due.
    #[inline]
    pub fn add_from<T: Copy + Into<f64>, V: Copy + Into<f64>>(
        &mut self,
        temperatures: &[T],
        sliding: &[V],
        link: &super::EditorLink,
    ) {
        let interval = (link.scope.sample_rate() * RECORD_INTERVAL_S).max(1.0) as u32;
        self.add(temperatures, sliding, interval, &link.nodes);
    }

    /// Adds one sample of node temperatures (K) and sliding velocities (a node slips where
    /// its velocity is not zero); after `interval` samples publishes their means (the
    /// temperature, and the share of samples slipping) into `ring` and starts again. A
    /// change of node count drops the partial sums.
    #[inline]
    pub fn add<T: Copy + Into<f64>, V: Copy + Into<f64>>(
        &mut self,
        temperatures: &[T],
        sliding: &[V],
        interval: u32,
        ring: &NodeRing,
    ) {
        let count = temperatures.len().min(sliding.len()).min(MAX_NODES);
        if count != self.count {
            *self = Self {
                count,
                ..Self::default()
            };
        }
        for i in 0..count {
            self.temperature_sum[i] += temperatures[i].into();
            self.slipping[i] += (sliding[i].into() != 0.0) as u32;
        }
        self.samples += 1;
        if self.samples >= interval {
            let n = self.samples as f64;
            let mut record = NodeRecord {
                count,
                ..NodeRecord::default()
            };
            for i in 0..count {
                record.temperature_kelvin[i] = (self.temperature_sum[i] / n) as f32;
                record.slip_fraction[i] = (self.slipping[i] as f64 / n) as f32;
            }
            ring.push(&record);
            *self = Self {
                count,
                ..Self::default()
            };
        }
    }
}

const PROFILE: Color32 = Color32::from_rgb(250, 150, 80);
const SLIP: Color32 = Color32::from_rgb(250, 200, 90);

/// Frames `rect` with a title, the left axis labels and the x label below.
fn frame(ui: &Ui, rect: Rect, title: &str, top: &str, bottom: &str, x_label: &str) {
    let painter = ui.painter();
    let visuals = ui.visuals();
    let text = visuals.text_color();
    let small = FontId::proportional(11.0);
    painter.rect_filled(rect, 3.0, visuals.extreme_bg_color);
    painter.text(
        rect.left_top() + vec2(4.0, 2.0),
        Align2::LEFT_TOP,
        title,
        small.clone(),
        text,
    );
    painter.text(
        pos2(rect.left() - 3.0, rect.top()),
        Align2::RIGHT_TOP,
        top,
        small.clone(),
        text,
    );
    painter.text(
        pos2(rect.left() - 3.0, rect.bottom()),
        Align2::RIGHT_BOTTOM,
        bottom,
        small.clone(),
        text,
    );
    painter.text(
        pos2(rect.center().x, rect.bottom() + 2.0),
        Align2::CENTER_TOP,
        x_label,
        small,
        text,
    );
}

/// The x of node `i` of `count` (the middle of its share of the width).
fn node_x(rect: Rect, i: usize, count: usize) -> f32 {
    rect.left() + (i as f32 + 0.5) / count.max(1) as f32 * rect.width()
}

/// Temperature across the bow: the newest record as a line with a point per node, over
/// the band (lowest to highest) each node spanned in `records`.
pub fn paint_temperature_profile(ui: &Ui, rect: Rect, records: &[NodeRecord]) {
    let Some(newest) = records.last() else {
        return;
    };
    let count = newest.count;
    let same: Vec<&NodeRecord> = records.iter().filter(|r| r.count == count).collect();
    let peak = same
        .iter()
        .flat_map(|r| r.temperature_kelvin[..count].iter().copied())
        .fold(0.0f32, f32::max);
    let limit = super::live::nice_limit(std::iter::once(peak), 1.0);
    frame(
        ui,
        rect,
        "bow temperature above ambient",
        &format!("{limit} K"),
        "0 K",
        &format!("{count} nodes across the bow, bridge side left"),
    );
    if count == 0 {
        return;
    }
    // Below the title.
    let plot = Rect::from_min_max(pos2(rect.left(), rect.top() + 18.0), rect.max);
    let y = |t: f32| plot.bottom() - (t / limit).clamp(0.0, 1.0) * plot.height();
    let painter = ui.painter();
    let band = PROFILE.gamma_multiply(0.25);
    for i in 0..count {
        let (lo, hi) = same.iter().fold((f32::MAX, f32::MIN), |(lo, hi), r| {
            let t = r.temperature_kelvin[i];
            (lo.min(t), hi.max(t))
        });
        let x = node_x(rect, i, count);
        let half = (0.4 * rect.width() / count as f32).max(1.0);
        painter.rect_filled(
            Rect::from_min_max(
                pos2(x - half, y(hi)),
                pos2(x + half, y(lo).max(y(hi) + 1.0)),
            ),
            0.0,
            band,
        );
    }
    let points: Vec<_> = (0..count)
        .map(|i| pos2(node_x(rect, i, count), y(newest.temperature_kelvin[i])))
        .collect();
    for p in &points {
        painter.circle_filled(*p, 2.5, PROFILE);
    }
    if points.len() >= 2 {
        painter.add(Shape::line(points, Stroke::new(1.5, PROFILE)));
    }
}

/// Slip fraction per node against time: one column per record (newest right), one row per
/// node (bridge side at the top).
pub fn paint_slip_image(ui: &Ui, rect: Rect, records: &[NodeRecord]) {
    let duration_ms = records.len() as f32 * RECORD_INTERVAL_S * 1000.0;
    frame(
        ui,
        rect,
        "slipping per node (bright: slips)",
        "bridge",
        "nut",
        &format!("time, last {duration_ms:.0} ms"),
    );
    let Some(newest) = records.last() else {
        return;
    };
    let count = newest.count;
    if count == 0 {
        return;
    }
    let inner = rect.shrink2(vec2(2.0, 14.0)).translate(vec2(0.0, 6.0));
    let column = inner.width() / records.len() as f32;
    let row = inner.height() / count as f32;
    let dark = ui.visuals().extreme_bg_color;
    let mut mesh = Mesh::default();
    for (k, record) in records.iter().enumerate() {
        if record.count != count {
            continue;
        }
        for i in 0..count {
            let cell = Rect::from_min_size(
                pos2(
                    inner.left() + k as f32 * column,
                    inner.top() + i as f32 * row,
                ),
                vec2(column.max(1.0), row),
            );
            let colour = lerp_colour(dark, SLIP, record.slip_fraction[i].clamp(0.0, 1.0));
            mesh.add_colored_rect(cell, colour);
        }
    }
    ui.painter().add(Shape::mesh(mesh));
}

fn lerp_colour(a: Color32, b: Color32, t: f32) -> Color32 {
    let mix = |x: u8, y: u8| (x as f32 + (y as f32 - x as f32) * t).round() as u8;
    Color32::from_rgb(mix(a.r(), b.r()), mix(a.g(), b.g()), mix(a.b(), b.b()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record whose every value follows from `n`, so a torn one shows.
    fn record(n: u64) -> NodeRecord {
        let count = 1 + (n % MAX_NODES as u64) as usize;
        let mut r = NodeRecord {
            count,
            ..NodeRecord::default()
        };
        for i in 0..count {
            r.temperature_kelvin[i] = (n + i as u64) as f32;
            r.slip_fraction[i] = -((n + i as u64) as f32);
        }
        r
    }

    fn first_value(r: &NodeRecord) -> u64 {
        r.temperature_kelvin[0] as u64
    }

    #[test]
    fn node_ring_returns_the_newest_records_in_order() {
        let ring = node_ring();
        let mut out = Vec::new();
        ring.copy_latest(100, &mut out);
        assert!(out.is_empty());
        for n in 0..10 {
            ring.push(&record(n));
        }
        ring.copy_latest(4, &mut out);
        assert_eq!(out, (6..10).map(record).collect::<Vec<_>>());
        ring.copy_latest(100, &mut out);
        assert_eq!(out.len(), 10);
    }

    #[test]
    fn node_ring_wraps_and_keeps_the_last_ring_length() {
        let ring = node_ring();
        let total = 3 * RING_LEN as u64 + 17;
        for n in 0..total {
            ring.push(&record(n));
        }
        let mut out = Vec::new();
        ring.copy_latest(usize::MAX, &mut out);
        assert_eq!(out.len(), RING_LEN);
        assert_eq!(
            out,
            (total - RING_LEN as u64..total)
                .map(record)
                .collect::<Vec<_>>()
        );
    }

    #[test]
    fn node_ring_reader_sees_only_whole_records_in_order_while_written() {
        let ring = std::sync::Arc::new(node_ring());
        let writer = {
            let ring = ring.clone();
            std::thread::spawn(move || {
                for n in 0..300_000 {
                    ring.push(&record(n));
                }
            })
        };
        let mut out = Vec::new();
        let mut copies = 0;
        while !writer.is_finished() {
            ring.copy_latest(RING_LEN, &mut out);
            for r in &out {
                assert_eq!(*r, record(first_value(r)), "torn record");
            }
            for pair in out.windows(2) {
                assert!(
                    first_value(&pair[1]) > first_value(&pair[0]),
                    "out of order"
                );
            }
            copies += 1;
        }
        writer.join().unwrap();
        assert!(copies > 0);
    }

    #[test]
    fn node_probe_publishes_means_every_interval() {
        let ring = node_ring();
        let mut probe = NodeProbe::default();
        // Node 0 slips on every other sample, node 1 never; temperatures 1, 2, 3, 4 K.
        for k in 0..4 {
            let slip = if k % 2 == 0 { 0.3 } else { 0.0 };
            probe.add(&[k as f64 + 1.0, 10.0], &[slip, 0.0], 4, &ring);
        }
        let mut out = Vec::new();
        ring.copy_latest(10, &mut out);
        assert_eq!(out.len(), 1);
        let r = out[0];
        assert_eq!(r.count, 2);
        assert_eq!(&r.temperature_kelvin[..2], &[2.5, 10.0]);
        assert_eq!(&r.slip_fraction[..2], &[0.5, 0.0]);
        // Three more samples: not yet due.
        for _ in 0..3 {
            probe.add(&[0.0, 0.0], &[-0.1, 0.2], 4, &ring);
        }
        assert_eq!(ring.written(), 1);
    }

    #[test]
    fn thermal_cello_in_helmholtz_motion_warms_the_bow_and_every_node_sticks_and_slips() {
        use crate::dsp::thermal::ThermalParams;
        use crate::dsp::thermal_instrument::{ThermalInstrument, ThermalSettings};
        use crate::dsp::vocabulary::{BowControl, InstrumentKind};
        let fs = 48_000.0;
        let bridge = crate::dsp::bridge_data::shipped_bridge(InstrumentKind::Cello).modes;
        let settings = ThermalSettings::default();
        let mut cello =
            ThermalInstrument::new(InstrumentKind::Cello, &bridge, fs, settings).unwrap();
        let link = super::super::EditorLink::default();
        link.scope.set_sample_rate(fs as f32);
        let mut probe = NodeProbe::default();
        // D3 at 0.1 m/s, 1 N, beta 0.1: Helmholtz motion (see `super::super::regime`).
        cello.note_on(50);
        let bow = BowControl::default();
        for i in 0..(fs as usize) {
            if i % 256 == 0 {
                cello.update_sleep();
            }
            cello.tick(bow);
            probe.add_from(
                cello.probed_string().node_temperatures(),
                cello.probed_string().node_sliding_velocities(),
                &link,
            );
        }
        // One record per 5 ms: 200 in a second.
        assert_eq!(link.nodes.written(), 200);
        let mut out = Vec::new();
        link.nodes.copy_latest(40, &mut out);
        let nodes = cello.probed_string().nodes();
        let mean =
            |f: &dyn Fn(&NodeRecord) -> f32| out.iter().map(f).sum::<f32>() / out.len() as f32;
        let slip: Vec<f32> = (0..nodes).map(|i| mean(&|r| r.slip_fraction[i])).collect();
        let temperature: Vec<f32> = (0..nodes)
            .map(|i| mean(&|r| r.temperature_kelvin[i]))
            .collect();
        println!("{nodes} nodes over the last 0.2 s: slip fraction {slip:?}, temperature {temperature:?} K");
        assert!(out.iter().all(|r| r.count == nodes));
        // Stick-slip: over 0.2 s (29 periods) every node spends part of the time in each.
        assert!(slip.iter().all(|f| *f > 0.0 && *f < 1.0), "{slip:?}");
        // Friction warms the bow, but less than continuous sliding would: its equilibrium
        // (ThermalParams::sliding_equilibrium_kelvin) with mu at most mu_cold, at a speed
        // (1 km/s) above any slip, where it is highest.
        let th = ThermalParams::default();
        let load = bow.force_n / settings.width_m;
        let sliding_eq = th.sliding_equilibrium_kelvin(th.mu_cold * load, load, 1e3);
        assert!(
            temperature
                .iter()
                .all(|t| *t > 0.0 && (*t as f64) < sliding_eq),
            "{temperature:?} against {sliding_eq} K"
        );
    }

    #[test]
    fn node_probe_starts_again_when_the_node_count_changes() {
        let ring = node_ring();
        let mut probe = NodeProbe::default();
        probe.add(&[100.0; 3], &[0.1; 3], 2, &ring);
        probe.add(&[1.0; 5], &[0.0; 5], 2, &ring);
        probe.add(&[3.0; 5], &[-0.1; 5], 2, &ring);
        let mut out = Vec::new();
        ring.copy_latest(10, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].count, 5);
        assert_eq!(&out[0].temperature_kelvin[..5], &[2.0; 5]);
        assert_eq!(&out[0].slip_fraction[..5], &[0.5; 5]);
    }
}
