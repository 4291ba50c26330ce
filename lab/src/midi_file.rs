//! Standard MIDI files offline (`colophony render --midi FILE.mid`): the notes and pitch
//! bends of a file, timed by its tempo map, played through the plugin's own performer
//! ([`colophony::performer`]) with the plugin's defaults, block by block as a host would call
//! the plugin. Fed the same events at the same block size, the plugin gives the same bits
//! (`tests/plugin_host.rs`).
//!
//! Controllers reach the performer's performance layer as they would the plugin: CC11,
//! CC2 and channel pressure set the dynamics, CC1 the vibrato depth. The bow's own
//! velocity, force and position are the constants given.

use colophony::dsp::friction::FrictionModel;
use colophony::dsp::vocabulary::{BowControl, Frame, InstrumentKind};
use colophony::measure::contact::ContactSample;
use colophony::performer::{Event, Performer, Setup, Status};
use midly::{MetaMessage, MidiMessage, Smf, Timing, TrackEventKind};

/// What a MIDI file asks of the performer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MidiEvent {
    /// Key and 7-bit velocity.
    NoteOn(u8, u8),
    NoteOff(u8),
    /// The raw 14-bit value, 8192 = centre.
    PitchBend(u16),
    /// Controller number and 7-bit value.
    Controller(u8, u8),
    /// Channel pressure, 7-bit.
    Pressure(u8),
    /// The file's tempo from here on, microseconds a beat (metrical files only; the
    /// performer takes it as a host's transport tempo, block by block).
    Tempo(u32),
}

/// An event at an output sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timed {
    pub sample: u64,
    /// MIDI channel, 0..=15 (MPE: a note's member channel carries its own expression).
    pub channel: u8,
    pub event: MidiEvent,
}

/// One note on channel 0: `note` at `velocity` from sample 0, released at sample
/// `release`.
pub fn one_note(note: u8, velocity: u8, release: u64) -> [Timed; 2] {
    [
        Timed {
            sample: 0,
            channel: 0,
            event: MidiEvent::NoteOn(note, velocity),
        },
        Timed {
            sample: release,
            channel: 0,
            event: MidiEvent::NoteOff(note),
        },
    ]
}

/// `note` at `velocity` played alone through the performer at the plugin's defaults
/// ([`Performance::plugin_defaults`] with `law`, `None` for paper B's thermal model) and
/// released after `held_s`: the audio of those `held_s` seconds.
pub fn one_note_audio(
    kind: InstrumentKind,
    law: Option<FrictionModel>,
    note: u8,
    velocity: u8,
    held_s: f64,
    sample_rate_hz: f64,
) -> Vec<f64> {
    let how = Performance::plugin_defaults(kind, law, sample_rate_hz);
    one_note_performed(&how, note, velocity, held_s)
}

/// [`one_note_audio`] as `how` plays it (another setup than the defaults: a mute, say).
pub fn one_note_performed(how: &Performance, note: u8, velocity: u8, held_s: f64) -> Vec<f64> {
    let held = (held_s * how.sample_rate_hz) as u64;
    perform(&one_note(note, velocity, held), how, |_, _| {})
        .expect("one note plays")
        .into_iter()
        .map(f64::from)
        .take(held as usize)
        .collect()
}

/// The longest ring-out rendered after the last event, s.
pub const MAX_TAIL_S: f64 = 10.0;
/// The ring-out ends once the output has stayed below this for [`QUIET_S`] (-100 dBFS:
/// below a 24-bit file's noise floor after dither, far below hearing)...
pub const QUIET_LEVEL: f32 = 1e-5;
/// ... seconds.
pub const QUIET_S: f64 = 0.25;

/// Reads the note and pitch-bend events of `bytes` (a standard MIDI file) at
/// `sample_rate_hz`: every track merged, or only track `track` (0 = the first in the
/// file). Tempo changes from any track time every track. Errors name what is wrong in one
/// line.
pub fn read_events(
    bytes: &[u8],
    track: Option<usize>,
    sample_rate_hz: f64,
) -> Result<Vec<Timed>, String> {
    let smf = Smf::parse(bytes).map_err(|e| format!("not a standard MIDI file: {e}"))?;
    if let Some(t) = track {
        if t >= smf.tracks.len() {
            return Err(format!(
                "the file has {} track(s) (0..={}); there is no track {t}",
                smf.tracks.len(),
                smf.tracks.len().saturating_sub(1)
            ));
        }
    }
    // (tick, track, order in track, what): tempo changes from every track, notes from the
    // chosen ones.
    enum Item {
        Tempo(u32),
        Event(u8, MidiEvent),
    }
    let mut items: Vec<(u64, usize, usize, Item)> = Vec::new();
    for (t, events) in smf.tracks.iter().enumerate() {
        let wanted = track.is_none_or(|w| w == t);
        let mut tick = 0u64;
        for (k, e) in events.iter().enumerate() {
            tick += e.delta.as_int() as u64;
            let item = match e.kind {
                TrackEventKind::Meta(MetaMessage::Tempo(us)) => Some(Item::Tempo(us.as_int())),
                TrackEventKind::Midi { channel, message } if wanted => match message {
                    MidiMessage::NoteOn { key, vel } if vel.as_int() > 0 => Some(Item::Event(
                        channel.as_int(),
                        MidiEvent::NoteOn(key.as_int(), vel.as_int()),
                    )),
                    MidiMessage::NoteOn { key, .. } | MidiMessage::NoteOff { key, .. } => Some(
                        Item::Event(channel.as_int(), MidiEvent::NoteOff(key.as_int())),
                    ),
                    MidiMessage::PitchBend { bend } => Some(Item::Event(
                        channel.as_int(),
                        MidiEvent::PitchBend(bend.0.as_int()),
                    )),
                    MidiMessage::Controller { controller, value } => Some(Item::Event(
                        channel.as_int(),
                        MidiEvent::Controller(controller.as_int(), value.as_int()),
                    )),
                    MidiMessage::ChannelAftertouch { vel } => Some(Item::Event(
                        channel.as_int(),
                        MidiEvent::Pressure(vel.as_int()),
                    )),
                    _ => None,
                },
                _ => None,
            };
            if let Some(item) = item {
                items.push((tick, t, k, item));
            }
        }
    }
    items.sort_by_key(|(tick, t, k, _)| (*tick, *t, *k));
    // Seconds per tick: metrical files follow the tempo (default 120 bpm), timecode files
    // count frames.
    let (ticks_per_beat, fixed_tick_s) = match smf.header.timing {
        Timing::Metrical(tpb) => (tpb.as_int().max(1) as f64, None),
        Timing::Timecode(fps, sub) => (1.0, Some(1.0 / (fps.as_f32() as f64 * sub.max(1) as f64))),
    };
    let mut tick_s = fixed_tick_s.unwrap_or(0.5 / ticks_per_beat);
    let (mut last_tick, mut seconds) = (0u64, 0.0f64);
    let mut out = Vec::new();
    if fixed_tick_s.is_none() {
        // A metrical file plays at 120 bpm until its tempo says otherwise.
        out.push(Timed {
            sample: 0,
            channel: 0,
            event: MidiEvent::Tempo(500_000),
        });
    }
    for (tick, _, _, item) in items {
        seconds += (tick - last_tick) as f64 * tick_s;
        last_tick = tick;
        match item {
            Item::Tempo(us) if fixed_tick_s.is_none() => {
                tick_s = us.max(1) as f64 * 1e-6 / ticks_per_beat;
                out.push(Timed {
                    sample: (seconds * sample_rate_hz).round() as u64,
                    channel: 0,
                    event: MidiEvent::Tempo(us.max(1)),
                });
            }
            Item::Tempo(_) => {}
            Item::Event(channel, event) => out.push(Timed {
                sample: (seconds * sample_rate_hz).round() as u64,
                channel,
                event,
            }),
        }
    }
    if !out.iter().any(|e| matches!(e.event, MidiEvent::NoteOn(..))) {
        return Err(match track {
            Some(t) => format!("track {t} has no notes"),
            None => "the file has no notes".into(),
        });
    }
    Ok(out)
}

/// How a file is played.
#[derive(Debug, Clone, PartialEq)]
pub struct Performance {
    pub setup: Setup,
    pub bow: BowControl,
    /// Linear output gain (the plugin's `gain` parameter).
    pub gain: f64,
    pub sample_rate_hz: f64,
    /// Samples per block (the performer's setup and sleep are renewed each block).
    pub block: usize,
    /// A bridge for the thermal model of `setup.instrument` instead of the shipped one
    /// (`render --bridge`).
    pub bridge: Option<colophony::dsp::bridge_data::BridgeModes>,
}

impl Performance {
    /// The plugin at its default parameters playing `instrument` with `point_law` (`None`:
    /// paper B's thermal model), unity gain, in blocks of 512 at `sample_rate_hz`.
    pub fn plugin_defaults(
        instrument: colophony::dsp::vocabulary::InstrumentKind,
        point_law: Option<colophony::dsp::friction::FrictionModel>,
        sample_rate_hz: f64,
    ) -> Self {
        let params = colophony::params::ColophonyParams::default();
        let mut setup = params.setup();
        setup.instrument = instrument;
        setup.point_law = point_law;
        Self {
            setup,
            bow: params.bow(),
            gain: 1.0,
            sample_rate_hz,
            block: 512,
            bridge: None,
        }
    }
}

/// Plays `events` and returns the output the plugin would give on each channel, through
/// the last event and the ring-out (until silent or below [`QUIET_LEVEL`] for
/// [`QUIET_S`], at most [`MAX_TAIL_S`]). `progress` is
/// told the samples done and the total so far.
pub fn perform(
    events: &[Timed],
    how: &Performance,
    progress: impl FnMut(u64, u64),
) -> Result<Vec<f32>, String> {
    perform_until(events, how, None, progress)
}

/// [`perform`], stopped at the first block boundary at or after `limit` samples when
/// given (the renderer's `--seconds`: the tail past it would be cut anyway).
pub fn perform_until(
    events: &[Timed],
    how: &Performance,
    limit: Option<u64>,
    progress: impl FnMut(u64, u64),
) -> Result<Vec<f32>, String> {
    perform_probing(events, how, limit, progress, None)
}

/// [`perform`], with the contact probe as the editor records it (the string at the bow,
/// [`ContactSample`]) beside each output sample: what the repertoire test measures.
pub fn perform_probed(
    events: &[Timed],
    how: &Performance,
) -> Result<(Vec<f32>, Vec<ContactSample>), String> {
    let mut probe = Vec::new();
    let out = perform_probing(events, how, None, |_, _| {}, Some(&mut probe))?;
    Ok((out, probe))
}

fn perform_probing(
    events: &[Timed],
    how: &Performance,
    limit: Option<u64>,
    mut progress: impl FnMut(u64, u64),
    mut probe: Option<&mut Vec<ContactSample>>,
) -> Result<Vec<f32>, String> {
    let block = how.block.max(1);
    let mut setup = how.setup.clone();
    // The file's tempo reaches the performer as a host's transport tempo does: at the
    // start of each block.
    let mut tempo_next = 0;
    let mut performer = Performer::new(how.setup.instrument);
    performer.set_user_bridge(how.setup.instrument, how.bridge.clone());
    performer.activate(&how.setup, how.sample_rate_hz)?;
    let last = events.last().map_or(0, |e| e.sample);
    let hard_end = last + (MAX_TAIL_S * how.sample_rate_hz) as u64;
    let mut out = Vec::with_capacity(last as usize + block);
    let mut next = 0;
    let mut done = 0u64;
    let quiet_needed = (QUIET_S * how.sample_rate_hz) as u64;
    let mut quiet = 0u64;
    let mut buffer = vec![0.0f32; block];
    loop {
        // As the plugin plays a host block.
        while let Some(e) = events.get(tempo_next).filter(|e| e.sample <= done) {
            if let MidiEvent::Tempo(us) = e.event {
                setup.tempo_bpm = Some(60e6 / us as f64);
            }
            tempo_next += 1;
        }
        performer.configure(&setup);
        let end = done + block as u64;
        let probing = probe.is_some();
        let mut record = |frame: &Frame, played: &BowControl, _: &Performer| {
            if let Some(p) = probe.as_deref_mut() {
                p.push(ContactSample::new(frame, played));
            }
        };
        let live: Option<&mut dyn FnMut(&Frame, &BowControl, &Performer)> = match probing {
            true => Some(&mut record),
            false => None,
        };
        let status = performer.render_block(
            &mut [&mut buffer[..]],
            || loop {
                let e = events.get(next).filter(|e| e.sample < end)?;
                next += 1;
                if let Some(event) = event_of(e) {
                    return Some(((e.sample.max(done) - done) as usize, event));
                }
            },
            || (how.bow, how.gain),
            || true,
            live,
        );
        for &y in &buffer {
            quiet = if y.abs() < QUIET_LEVEL { quiet + 1 } else { 0 };
        }
        out.extend_from_slice(&buffer);
        if let Some(p) = probe.as_deref_mut() {
            // A silent block is skipped without frames: the probe reads rest there.
            p.resize(out.len(), ContactSample::default());
        }
        done = end;
        progress(done, last.max(done));
        if limit.is_some_and(|n| done >= n) {
            break;
        }
        let finished = next >= events.len() && done > last;
        if finished && (status == Status::Normal || quiet >= quiet_needed || done >= hard_end) {
            break;
        }
    }
    Ok(out)
}

/// The performer's event for a file's (values as nice-plug hands them to the plugin:
/// 0..=1 in f32); `None` for the tempo, which is no event.
fn event_of(e: &Timed) -> Option<Event> {
    let channel = e.channel;
    Some(match e.event {
        MidiEvent::NoteOn(note, v) => Event::NoteOn {
            channel,
            note,
            velocity: v as f32 / 127.0,
        },
        MidiEvent::NoteOff(note) => Event::NoteOff { note },
        MidiEvent::PitchBend(raw) => Event::PitchWheel {
            channel,
            value: raw as f32 / 16383.0,
        },
        MidiEvent::Controller(cc, v) => Event::Controller {
            channel,
            cc,
            value: v as f32 / 127.0,
        },
        MidiEvent::Pressure(v) => Event::ChannelPressure {
            channel,
            pressure: v as f32 / 127.0,
        },
        // The tempo is the transport's, set at each block.
        MidiEvent::Tempo(_) => return None,
    })
}

/// `colophony render --midi FILE`: reads `midi`, plays it as [`perform`] (blocks of 512),
/// with a progress bar on a terminal, and writes `out` as the renderer does (no partial
/// file on failure). `tail_s` shortens the ring-out after the last event (the renderer's
/// `--tail`, 0 ..= [`MAX_TAIL_S`]).
pub fn render_file(
    midi: &std::path::Path,
    track: Option<usize>,
    tail_s: Option<f64>,
    how: &Performance,
    out: &std::path::Path,
) -> Result<String, String> {
    if let Some(t) = tail_s {
        if !(t.is_finite() && (0.0..=MAX_TAIL_S).contains(&t)) {
            return Err(format!("--tail must be within 0..={MAX_TAIL_S} s, got {t}"));
        }
    }
    let bytes = std::fs::read(midi).map_err(|e| format!("cannot read {}: {e}", midi.display()))?;
    let events = read_events(&bytes, track, how.sample_rate_hz)
        .map_err(|e| format!("{}: {e}", midi.display()))?;
    let notes = events
        .iter()
        .filter(|e| matches!(e.event, MidiEvent::NoteOn(..)))
        .count();
    let last = events.last().map_or(0, |e| e.sample);
    let frames = tail_s.map(|t| (last + (t * how.sample_rate_hz).round() as u64) as usize);
    let (seconds, _) = render_events(&events, how, frames, out)?;
    Ok(format!(
        "wrote {} ({notes} notes, {seconds:.1} s, from {})",
        out.display(),
        midi.display()
    ))
}

/// Plays `events` as [`perform`] with a progress bar, cut to `frames` samples if given,
/// and writes the WAV to `out` (no partial file on error). Returns the seconds written and
/// the peak sample.
pub fn render_events(
    events: &[Timed],
    how: &Performance,
    frames: Option<usize>,
    out: &std::path::Path,
) -> Result<(f64, f32), String> {
    let bar = indicatif::ProgressBar::new(events.last().map_or(0, |e| e.sample));
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{elapsed_precise} [{bar:40}] {percent} % of the file, eta {eta}",
    ) {
        bar.set_style(style);
    }
    let mut audio = perform_until(events, how, frames.map(|n| n as u64), |done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    if let Some(n) = frames {
        audio.truncate(n);
    }
    let seconds = audio.len() as f64 / how.sample_rate_hz;
    let peak = audio.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let rendered = crate::render::Rendered {
        sample_rate_hz: how.sample_rate_hz,
        audio: audio.into_iter().map(f64::from).collect(),
        bow_point_velocity_m_per_s: Vec::new(),
        friction_force_n: Vec::new(),
        newton: Default::default(),
    };
    crate::render::write_wav(out, &rendered, false).map_err(|e| e.to_string())?;
    Ok((seconds, peak))
}

#[cfg(test)]
mod tests {
    use super::*;
    use midly::num::{u15, u24, u28, u4, u7};
    use midly::{Format, Header, TrackEvent};

    fn file(timing: Timing, tracks: Vec<Vec<TrackEvent<'static>>>) -> Vec<u8> {
        let mut smf = Smf::new(Header::new(Format::Parallel, timing));
        smf.tracks = tracks;
        let mut bytes = Vec::new();
        smf.write_std(&mut bytes).unwrap();
        bytes
    }

    fn ev(delta: u32, kind: TrackEventKind<'static>) -> TrackEvent<'static> {
        TrackEvent {
            delta: u28::new(delta),
            kind,
        }
    }

    fn note(on: bool, key: u8, vel: u8) -> TrackEventKind<'static> {
        let (key, vel) = (u7::new(key), u7::new(vel));
        TrackEventKind::Midi {
            channel: u4::new(0),
            message: if on {
                MidiMessage::NoteOn { key, vel }
            } else {
                MidiMessage::NoteOff { key, vel }
            },
        }
    }

    /// A synced tremolo in a file follows the file's tempo, as it follows a host's: at
    /// 90 bpm a sixteenth lasts 1/6 s, so the bow turns 6 times a second (free, at the
    /// default rate, 12). Counted on the probe's friction, its sign over 5 ms windows
    /// (the mean friction force points along the bow's motion), over 3 s of cello D3.
    /// Tolerance 2 reversals: the window straddling a turn, at either end.
    #[test]
    fn a_synced_tremolo_follows_the_files_tempo() {
        let tempo = |us| TrackEventKind::Meta(MetaMessage::Tempo(u24::new(us)));
        let bytes = file(
            Timing::Metrical(u15::new(480)),
            vec![vec![
                ev(0, tempo(666_667)),
                ev(0, note(true, 50, 100)),
                ev(4 * 480 + 240, note(false, 50, 0)),
            ]],
        );
        let events = read_events(&bytes, None, 48_000.0).unwrap();
        let reversals = |sync| {
            let mut how = Performance::plugin_defaults(
                colophony::dsp::vocabulary::InstrumentKind::Cello,
                Some(colophony::dsp::friction::FrictionModel::Hyperbolic),
                48_000.0,
            );
            how.setup.articulation = colophony::performer::Articulation::Tremolo;
            how.setup.tremolo_sync = sync;
            let (_, probe) = perform_probed(&events, &how).unwrap();
            let signs: Vec<bool> = probe[..3 * 48_000]
                .chunks(240)
                .map(|w| w.iter().map(|c| c.mu as f64).sum::<f64>() > 0.0)
                .collect();
            signs.windows(2).filter(|p| p[0] != p[1]).count()
        };
        let synced = reversals(colophony::performer::articulation::TremoloSync::Sixteenths);
        let free = reversals(colophony::performer::articulation::TremoloSync::Free);
        eprintln!("tremolo over 3 s: synced to 90 bpm {synced} reversals, free {free}");
        assert!((synced as i64 - 18).abs() <= 2, "{synced}");
        assert!((free as i64 - 36).abs() <= 2, "{free}");
    }

    #[test]
    fn the_tempo_map_of_any_track_times_the_notes() {
        // 480 ticks a beat; 120 bpm, then 60 bpm from beat 1 (set in track 0); notes in
        // track 1 at beats 0, 1 and 2 fall at 0, 0.5 and 1.5 s.
        let tempo = |us| TrackEventKind::Meta(MetaMessage::Tempo(u24::new(us)));
        let bytes = file(
            Timing::Metrical(u15::new(480)),
            vec![
                vec![ev(0, tempo(500_000)), ev(480, tempo(1_000_000))],
                vec![
                    ev(0, note(true, 50, 100)),
                    ev(480, note(false, 50, 0)),
                    ev(0, note(true, 52, 90)),
                    ev(480, note(true, 52, 0)),
                ],
            ],
        );
        let got = read_events(&bytes, None, 48_000.0).unwrap();
        // The tempo goes with them: 120 bpm from the start (a metrical file's default,
        // then track 0's own), 60 bpm from beat 1.
        let want = [
            (0, MidiEvent::Tempo(500_000)),
            (0, MidiEvent::Tempo(500_000)),
            (0, MidiEvent::NoteOn(50, 100)),
            (24_000, MidiEvent::Tempo(1_000_000)),
            (24_000, MidiEvent::NoteOff(50)),
            (24_000, MidiEvent::NoteOn(52, 90)),
            // A note-on of velocity 0 is a note-off.
            (72_000, MidiEvent::NoteOff(52)),
        ];
        let got: Vec<(u64, MidiEvent)> = got.iter().map(|t| (t.sample, t.event)).collect();
        assert_eq!(got, want);
        // Track 0 alone has no notes; track 5 does not exist.
        assert_eq!(
            read_events(&bytes, Some(0), 48_000.0).unwrap_err(),
            "track 0 has no notes"
        );
        assert!(read_events(&bytes, Some(5), 48_000.0)
            .unwrap_err()
            .contains("no track 5"));
    }

    #[test]
    fn broken_files_are_refused_in_one_line() {
        for bad in [&b""[..], b"MThd", b"RIFF0000WAVEfmt ", &[0xff; 64]] {
            let e = read_events(bad, None, 48_000.0).unwrap_err();
            assert!(
                e.starts_with("not a standard MIDI file") && !e.contains('\n'),
                "{e}"
            );
        }
    }
}
