//! Where the notes go: building the engines at activation, following the setup each block
//! (instrument, friction law, quality, bridge), and switching sources with the held notes
//! moved over while the old source rings on.

use super::*;

impl Performer {
    /// Plays `kind` on `bridge` (a fitted or measured modal bridge,
    /// [`crate::dsp::bridge_data`]) instead of the shipped one: paper B's thermal
    /// instrument on the bridge itself, the point-bow instrument with the bridge's passive
    /// reduction as its body ([`crate::dsp::body::body_from_bridge`]). `None` goes back to
    /// the shipped bridge and the generic body. Takes effect at the next
    /// [`Performer::activate`] (it builds the engines: not for the audio thread).
    pub fn set_user_bridge(&mut self, kind: InstrumentKind, bridge: Option<BridgeModes>) {
        self.user_bridges[kind.index()] = bridge;
    }

    /// [`Performer::activate`], falling back to the shipped bridges when a chosen bridge
    /// cannot run at this rate: a host is never refused for a bridge. `Ok` carries what
    /// was given up (a line for the log), `Err` what failed even on the shipped bridges.
    pub fn activate_or_shipped(
        &mut self,
        setup: &Setup,
        sample_rate_hz: f64,
    ) -> Result<Option<String>, String> {
        match self.activate(setup, sample_rate_hz) {
            Ok(()) => Ok(None),
            Err(e) => {
                self.user_bridges = Default::default();
                self.activate(setup, sample_rate_hz)?;
                Ok(Some(format!("{e}; playing the shipped bridges")))
            }
        }
    }

    /// Allocates every engine for `sample_rate_hz`; nothing allocates after this.
    pub fn activate(&mut self, setup: &Setup, sample_rate_hz: f64) -> Result<(), String> {
        self.setup = *setup;
        let fs = sample_rate_hz;
        self.instrument = Instrument::new(setup.instrument, fs);
        // The point-bow strings play a chosen bridge as their body: its passive
        // reduction to the bowing direction's strongest modes.
        for (k, kind) in InstrumentKind::ALL.into_iter().enumerate() {
            if let Some(user) = &self.user_bridges[k] {
                let (modes, _) = crate::dsp::body::body_from_bridge(&user.modes);
                self.instrument.set_body(kind, Some(&modes));
            }
        }
        let settings = self.thermal_settings();
        self.thermal.clear();
        for (k, kind) in InstrumentKind::ALL.into_iter().enumerate() {
            let shipped;
            let bridge = match &self.user_bridges[k] {
                Some(user) => user,
                None => {
                    shipped = bridge_data::shipped_bridge(kind);
                    &shipped
                }
            };
            let engine = ThermalInstrument::new(kind, &bridge.modes, fs, settings)
                .map_err(|e| format!("cannot build the thermal {}: {e}", kind.name()))?;
            self.thermal.push(engine);
        }
        self.rubbed = RubbedInstrument::new(fs);
        self.source = Source::Strings;
        self.held = [false; 128];
        self.sample_rate_hz = fs;
        self.tail = None;
        self.gesture = Gesture::new(fs);
        self.stroke = Stroke::new(fs);
        self.catch = None;
        self.direct = DirectBow::new(fs);
        self.steady = None;
        self.configured = false;
        Ok(())
    }

    /// Applies a block's setup: instrument, laws, tolerances, tuning, string choice, the
    /// thermal bow's settings and the source; then what is quiet sleeps.
    pub fn configure(&mut self, setup: &Setup) {
        // The same setup as the last block: every setting below would be a no-op (the
        // strings' kind is the one condition that waits on the engines' state).
        if self.configured && *setup == self.setup && self.instrument.kind() == setup.instrument {
            for engine in self.engines() {
                engine.update_sleep();
            }
            self.refresh_others();
            return;
        }
        self.configured = true;
        if setup.vibrato_rate_hz != self.setup.vibrato_rate_hz {
            self.gesture.cc_rate_hz = None;
        }
        if setup.articulation != self.setup.articulation {
            self.articulation_midi = None;
        }
        if setup.con_sordino != self.setup.con_sordino {
            self.con_sordino_midi = None;
        }

        let range_was = self.bend_range();
        self.setup = *setup;
        if self.bend_range() != range_was {
            self.set_bend(self.gesture.wheel_position * self.bend_range());
        }
        let wanted = Source::of(setup);
        // The waveguide strings change instrument at once (silenced) only while they are
        // what the notes play; ringing on behind another source, they finish first.
        if wanted == Source::Strings || !self.instrument.is_sounding() {
            self.instrument.set_kind(setup.instrument);
        }
        // The rubbed objects keep the last point law while the thermal model is chosen.
        if let Some(friction) = setup.point_law {
            self.instrument.set_friction_model(friction);
            self.rubbed.set_friction_model(friction);
        }
        self.instrument.set_string_weighting(setup.string_weight);
        self.instrument
            .set_newton_tolerance(setup.newton_tolerance_m_per_s);
        self.rubbed
            .set_newton_tolerance(setup.newton_tolerance_m_per_s);
        let settings = self.thermal_settings();
        for engine in self.engines() {
            engine.set_reference_pitch(setup.reference_hz);
            engine.set_preferred_string(setup.preferred_string);
        }
        for engine in &mut self.thermal {
            engine.set_string_weighting(setup.string_weight);
            engine.set_settings(settings);
        }
        self.follow_tremolo();
        self.apply_mute();
        self.apply_source(wanted);
        // The guard's bow belongs to the law and the instrument, and the gesture's steady
        // factors to the guard: both worked out again from the next sample.
        self.gesture.guarded = self.guarded_bow(self.gesture.bow_scale);
        self.steady = None;
        for engine in self.engines() {
            engine.update_sleep();
        }
        self.refresh_others();
    }

    /// Renews [`Performer::others_awake`].
    pub(super) fn refresh_others(&mut self) {
        self.others_awake =
            self.thermal.iter().any(|e| e.is_sounding()) || self.rubbed.is_sounding();
    }

    /// Every engine.
    pub(super) fn engines(&mut self) -> impl Iterator<Item = &mut dyn Engine> {
        std::iter::once(&mut self.instrument as &mut dyn Engine)
            .chain(self.thermal.iter_mut().map(|e| e as &mut dyn Engine))
            .chain(std::iter::once(&mut self.rubbed as &mut dyn Engine))
    }

    /// Applies a source: held notes move to the new source (its bow lands over the usual
    /// ramp) and the old one rings on, so there is no click.
    pub(super) fn apply_source(&mut self, choice: Source) {
        if choice == self.source {
            return;
        }
        let held = self.held;
        self.all_notes_off();
        self.source = choice;
        if let Source::Rubbed(preset) = choice {
            self.rubbed.set_preset(preset);
        }
        for (note, down) in held.iter().enumerate() {
            if *down {
                self.land(note as u8, None);
            }
        }
    }

    pub(super) fn thermal_settings(&self) -> ThermalSettings {
        ThermalSettings {
            nodes: match self.setup.thermal_nodes {
                ThermalNodes::Fixed(n) => n,
                ThermalNodes::Auto => self.auto_nodes,
            },
            width_m: self.setup.bow_width_m,
        }
    }

    /// `quality = auto`: the node count for a new note at the current bow position, kept
    /// if the current one is close enough ([`quality::auto_needs_rebuild`]).
    pub(super) fn choose_auto_nodes(&mut self, note: u8) {
        if self.setup.thermal_nodes != ThermalNodes::Auto {
            return;
        }
        let wanted = quality::auto_nodes(
            self.setup.instrument,
            midi_to_hz(note as f64),
            self.setup.bow_position_beta,
            self.setup.bow_width_m,
        );
        if quality::auto_needs_rebuild(self.auto_nodes, wanted) {
            self.auto_nodes = wanted;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::performer::testing::*;

    #[test]
    fn a_chosen_bridge_colours_the_point_bow_sound_and_leaves_the_string_alone() {
        // The point-bow body only colours what radiates (it feeds nothing back): with a
        // chosen bridge's reduction as the body the string moves exactly as with the
        // generic body, and the sound changes, towards the bridge's strongest horizontal
        // mode.
        let bow = BowControl::default();
        let play = |bridge: Option<BridgeModes>| {
            let setup = Setup::default();
            let mut p = Performer::new(InstrumentKind::Cello);
            p.set_user_bridge(InstrumentKind::Cello, bridge);
            p.activate(&setup, FS).unwrap();
            p.configure(&setup);
            p.note_on(50, 0.8);
            let frames: Vec<Frame> = (0..(0.5 * FS) as usize).map(|_| p.tick(bow)).collect();
            frames
        };
        let violin = bridge_data::shipped_bridge(InstrumentKind::Violin);
        let (modes, _) = crate::dsp::body::body_from_bridge(&violin.modes);
        let generic = play(None);
        let chosen = play(Some(violin));
        let probe = |f: &[Frame]| -> Vec<u64> {
            f.iter()
                .map(|x| x.bow_point_velocity_m_per_s.to_bits())
                .collect()
        };
        assert_eq!(probe(&generic), probe(&chosen), "the body moved the string");
        assert!(chosen.iter().all(|f| f.audio.is_finite()));
        let audio = |f: &[Frame]| -> Vec<f64> {
            f[(0.2 * FS) as usize..].iter().map(|x| x.audio).collect()
        };
        let (a, b) = (audio(&generic), audio(&chosen));
        assert_ne!(a, b, "the chosen bridge changed nothing");
        // The strongest kept mode's band carries more of the sound than with the generic
        // body (the D3 note's partials near it are lifted).
        let near = |x: &[f64]| {
            let f = modes[0].freq_hz;
            (0..5)
                .map(|k| {
                    crate::analysis::partial_amplitude(
                        x,
                        FS,
                        f * 2f64.powf((k as f64 - 2.0) / 24.0),
                    )
                })
                .fold(0.0, f64::max)
                / crate::analysis::rms(x)
        };
        assert!(
            near(&b) > near(&a),
            "{} vs {} at {} Hz",
            near(&b),
            near(&a),
            modes[0].freq_hz
        );
    }
}
