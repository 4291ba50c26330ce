//! What the performer's tests share: a cello performer at 48 kHz, spans between events,
//! the probe's sticking velocity.

use super::*;

pub(super) const FS: f64 = 48_000.0;

/// `(start, length)` of the spans of at most `size` samples that cover
/// `0..marks.last()` without crossing a mark (an event's sample).
pub(super) fn spans(marks: &[usize], size: usize) -> Vec<(usize, usize)> {
    let end = marks.last().copied().unwrap_or(0);
    let mut v = Vec::new();
    let mut at = 0;
    while at < end {
        let next = marks.iter().copied().find(|&m| m > at).unwrap_or(end);
        let n = size.min(next - at);
        v.push((at, n));
        at += n;
    }
    v
}

pub(super) fn cello() -> Performer {
    cello_with(&Setup::default())
}

/// A cello performer activated at `FS` and configured with `setup`.
pub(super) fn cello_with(setup: &Setup) -> Performer {
    let mut p = Performer::new(InstrumentKind::Cello);
    p.activate(setup, FS).unwrap();
    p.configure(setup);
    p
}

/// The probe's velocity while the string sticks to the bow, averaged over samples
/// `from..to` of a render where `events` happen at their samples.
pub(super) fn stick_velocity(p: &mut Performer, from: usize, to: usize) -> f64 {
    let bow = BowControl::default();
    let mut sum = 0.0;
    let mut n = 0;
    for i in 0..to {
        let frame = p.tick(bow);
        let rel = frame.bow_point_velocity_m_per_s - p.bow().velocity_m_per_s;
        // Within 10 % of the bow: the playing-space map's sticking criterion
        // (docs/playing-space.md).
        if i >= from && rel.abs() < 0.1 * bow.velocity_m_per_s {
            sum += frame.bow_point_velocity_m_per_s;
            n += 1;
        }
    }
    sum / n.max(1) as f64
}
