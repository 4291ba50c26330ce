//! The editor driven headless by egui_kittest: the real [`EditorUi`] with the real
//! nice-plug `ParamSetter`, whose host side (`GuiContextInner`) is a recorder that logs every
//! begin/set/end call and applies the values to the parameters as a host would.

use colophony::editor::bridge::{BRIDGE_FILE_LABEL, LOAD_BRIDGE_LABEL, SHIPPED_BRIDGE_LABEL};
use colophony::editor::mapping::PadMapping;
use colophony::editor::nodes::NodeRecord;
use colophony::editor::pad::{pad_value_text, PAD_LABEL};
use colophony::editor::presets::{PRESET_LABEL, PRESET_NAME_LABEL, SAVE_LABEL};
use colophony::editor::view::THERMAL_LABEL;
use colophony::editor::{EditorLink, EditorUi};
use colophony::measure::contact::ContactSample;
use colophony::params::{
    ColophonyParams, FrictionChoice, InstrumentChoice, QualityChoice, StringChoice,
};
use egui::{pos2, vec2, Pos2, Rect};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use nice_plug::context::gui::GuiContext;
use nice_plug::prelude::{GuiContextInner, Param, ParamPtr, PluginApi, PluginState};
use std::sync::{Arc, Mutex};

#[derive(Debug, Clone, PartialEq)]
enum Call {
    Begin(String),
    Set(String, f32),
    End(String),
}

/// The host side of the `ParamSetter`: logs the calls and applies each value at once;
/// serves a saved state and keeps the states the editor hands back.
#[derive(Default)]
struct Recorder {
    calls: Mutex<Vec<Call>>,
    states: Mutex<Vec<PluginState>>,
    restarts: Mutex<usize>,
}

impl Recorder {
    fn calls(&self) -> Vec<Call> {
        self.calls.lock().unwrap().clone()
    }
}

/// The state the recorder serves: the defaults, with the window size and version fields a
/// real state carries.
fn served_state() -> PluginState {
    PluginState {
        version: "0.1.0".into(),
        params: colophony::presets::Preset::parse(r#"{"name": "defaults", "params": {}}"#)
            .unwrap()
            .state_params()
            .unwrap(),
        fields: [
            (
                "editor-state".to_owned(),
                r#"{"width":900.0,"height":700.0}"#.to_owned(),
            ),
            ("state-version".to_owned(), "1".to_owned()),
        ]
        .into(),
    }
}

fn name(param: ParamPtr) -> String {
    // SAFETY: every pointer the editor passes points into the test's live parameters.
    unsafe { param.name() }.to_owned()
}

impl GuiContextInner for Recorder {
    fn plugin_api(&self) -> PluginApi {
        PluginApi::Clap
    }

    unsafe fn raw_begin_set_parameter(&self, param: ParamPtr) {
        self.calls.lock().unwrap().push(Call::Begin(name(param)));
    }

    unsafe fn raw_set_parameter_normalized(&self, param: ParamPtr, normalized: f32) {
        self.calls
            .lock()
            .unwrap()
            .push(Call::Set(name(param), normalized));
        // SAFETY: as above; the test thread is the only one touching the parameters.
        unsafe { param._internal_set_normalized_value(normalized) };
    }

    unsafe fn raw_end_set_parameter(&self, param: ParamPtr) {
        self.calls.lock().unwrap().push(Call::End(name(param)));
    }

    fn get_state(&self) -> PluginState {
        served_state()
    }

    fn set_state(&self, state: PluginState) {
        self.states.lock().unwrap().push(state);
    }

    fn request_restart(&self) {
        *self.restarts.lock().unwrap() += 1;
    }
}

struct Fixture {
    params: Arc<ColophonyParams>,
    recorder: Arc<Recorder>,
    link: Arc<EditorLink>,
    editor: EditorUi,
}

fn fixture() -> Fixture {
    let params = Arc::new(ColophonyParams::default());
    let recorder = Arc::new(Recorder::default());
    let link = Arc::new(EditorLink::default());
    let editor = EditorUi::new(
        params.clone(),
        link.clone(),
        GuiContext::new(recorder.clone()),
    );
    Fixture {
        params,
        recorder,
        link,
        editor,
    }
}

fn harness(editor: &mut EditorUi) -> Harness<'_> {
    let mut harness = Harness::builder()
        .with_size(vec2(820.0, 540.0))
        .build_ui(move |ui| editor.ui(ui));
    harness.run();
    harness
}

fn pad_rect(harness: &Harness<'_>) -> Rect {
    harness.get_by_label(PAD_LABEL).rect()
}

fn pad_value(harness: &Harness<'_>) -> String {
    harness
        .get_by_label(PAD_LABEL)
        .value()
        .expect("the pad reports its values")
}

/// Presses at `from`, moves in `steps` frames to `to`, releases there.
fn drag(harness: &mut Harness<'_>, from: Pos2, to: Pos2, steps: usize) {
    harness.hover_at(from);
    harness.step();
    harness.drag_at(from);
    harness.step();
    for k in 1..=steps {
        harness.hover_at(from.lerp(to, k as f32 / steps as f32));
        harness.step();
    }
    harness.drop_at(to);
    harness.run();
}

/// Indices of the calls for `param` of each kind.
fn positions(calls: &[Call], param: &str) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let (mut begins, mut sets, mut ends) = (vec![], vec![], vec![]);
    for (i, call) in calls.iter().enumerate() {
        match call {
            Call::Begin(p) if p == param => begins.push(i),
            Call::Set(p, _) if p == param => sets.push(i),
            Call::End(p) if p == param => ends.push(i),
            _ => {}
        }
    }
    (begins, sets, ends)
}

/// One gesture for `param`: one begin, then at least one set, then one end.
fn assert_one_gesture(calls: &[Call], param: &str) -> usize {
    let (begins, sets, ends) = positions(calls, param);
    assert_eq!(begins.len(), 1, "{param}: one begin in {calls:?}");
    assert_eq!(ends.len(), 1, "{param}: one end in {calls:?}");
    assert!(!sets.is_empty(), "{param}: no set in {calls:?}");
    assert!(
        begins[0] < sets[0] && *sets.last().unwrap() < ends[0],
        "{param}: begin before set before end, got {calls:?}"
    );
    sets.len()
}

#[test]
fn dragging_the_pad_sets_velocity_and_force_within_one_gesture_each() {
    let mut f = fixture();
    let (start, end, rect);
    {
        let mut h = harness(&mut f.editor);
        rect = pad_rect(&h);
        start = rect.center();
        end = pos2(
            rect.left() + 0.85 * rect.width(),
            rect.top() + 0.2 * rect.height(),
        );
        drag(&mut h, start, end, 12);
    }
    let calls = f.recorder.calls();
    let velocity_sets = assert_one_gesture(&calls, "Bow Velocity");
    let force_sets = assert_one_gesture(&calls, "Bow Force");
    // Measured 13 sets each over the 12 moves (a set on every move, docs/editor.md); at
    // least 5 tells that from a gesture that sets only at the press and the release.
    assert!(velocity_sets >= 5 && force_sets >= 5, "{calls:?}");
    // Nothing else was touched.
    assert!(calls.iter().all(|c| match c {
        Call::Begin(p) | Call::Set(p, _) | Call::End(p) => p == "Bow Velocity" || p == "Bow Force",
    }));

    // Both parameters are where the mapping puts the release point.
    let (v, force) = PadMapping::default().pos_to_values(rect, end);
    let p = &f.params;
    // The host keeps the value as a normalized f32 (the force on a skewed range): its
    // rounding is far below 1e-3.
    assert!(
        (p.bow_velocity.value() - v).abs() < 1e-3,
        "velocity {} expected {v}",
        p.bow_velocity.value()
    );
    assert!(
        (p.bow_force.value() / force - 1.0).abs() < 1e-3,
        "force {} expected {force}",
        p.bow_force.value()
    );
    // Up and to the right of the default (0.1 m/s, 1 N). The release point maps to 1.05 m/s
    // (0.85 of the width) and 2.5 N (0.01 N x 1000^0.8, 0.8 of the height).
    assert!(p.bow_velocity.value() > 0.9 && p.bow_force.value() > 1.5);
}

#[test]
fn dragging_to_the_bottom_edge_lifts_the_bow_and_left_reverses_it() {
    let mut f = fixture();
    {
        let mut h = harness(&mut f.editor);
        let rect = pad_rect(&h);
        let end = pos2(rect.left() + 0.1 * rect.width(), rect.bottom() + 20.0);
        drag(&mut h, rect.center(), end, 8);
    }
    assert_one_gesture(&f.recorder.calls(), "Bow Velocity");
    assert_one_gesture(&f.recorder.calls(), "Bow Force");
    assert_eq!(f.params.bow_force.value(), 0.0);
    // 0.1 of the width maps to -1.2 m/s.
    assert!(f.params.bow_velocity.value() < -1.0);
}

#[test]
fn a_click_on_the_pad_is_one_complete_gesture() {
    let mut f = fixture();
    {
        let mut h = harness(&mut f.editor);
        let rect = pad_rect(&h);
        let at = pos2(
            rect.left() + 0.25 * rect.width(),
            rect.top() + 0.5 * rect.height(),
        );
        h.get_by_label(PAD_LABEL).hover();
        h.run();
        h.hover_at(at);
        h.step();
        h.drag_at(at);
        h.drop_at(at);
        h.run();
    }
    let calls = f.recorder.calls();
    assert_eq!(assert_one_gesture(&calls, "Bow Velocity"), 1, "{calls:?}");
    assert_eq!(assert_one_gesture(&calls, "Bow Force"), 1, "{calls:?}");
    // A quarter of the width maps to -0.75 m/s; the normalized f32 round trip rounds far
    // below 0.01.
    assert!((f.params.bow_velocity.value() + 0.75).abs() < 0.01);
}

#[test]
fn closing_the_editor_mid_drag_ends_the_gesture() {
    let mut f = fixture();
    {
        let mut h = harness(&mut f.editor);
        let rect = pad_rect(&h);
        h.hover_at(rect.center());
        h.step();
        h.drag_at(rect.center());
        h.step();
        h.hover_at(rect.center() + vec2(40.0, -30.0));
        h.step();
    }
    assert!(f.editor.pad().is_dragging());
    let before = f.recorder.calls();
    assert!(!before.iter().any(|c| matches!(c, Call::End(_))));
    drop(f.editor);
    let calls = f.recorder.calls();
    assert_one_gesture(&calls, "Bow Velocity");
    assert_one_gesture(&calls, "Bow Force");
}

#[test]
fn the_pad_follows_host_automation_when_not_dragged() {
    let mut f = fixture();
    let params = f.params.clone();
    let mut h = harness(&mut f.editor);
    assert_eq!(pad_value(&h), pad_value_text(0.1, 1.0));
    // The host moves both parameters (automation playback).
    unsafe {
        params
            .bow_velocity
            .as_ptr()
            ._internal_set_normalized_value(params.bow_velocity.preview_normalized(-0.4));
        params
            .bow_force
            .as_ptr()
            ._internal_set_normalized_value(params.bow_force.preview_normalized(2.5));
    }
    h.run();
    assert_eq!(pad_value(&h), pad_value_text(-0.4, 2.5));
    drop(h);
    assert!(f.recorder.calls().is_empty(), "the editor sent nothing");
}

/// Opens the selector labelled `label`, checks it shows `before`, picks `after`, closes
/// the editor, and checks the host saw one gesture with one value.
fn choose(f: &mut Fixture, label: &str, before: &str, after: &str) {
    {
        let mut h = harness(&mut f.editor);
        let combo = h.get_by_role_and_label(egui::Role::ComboBox, label);
        assert_eq!(combo.value().as_deref(), Some(before));
        combo.click();
        h.run();
        h.get_by_label(after).click();
        h.run();
    }
    let calls = f.recorder.calls();
    assert_eq!(assert_one_gesture(&calls, label), 1, "{calls:?}");
}

#[test]
fn choosing_an_instrument_is_one_gesture() {
    let mut f = fixture();
    choose(&mut f, "Instrument", "Cello", "Violin");
    assert_eq!(f.params.instrument.value(), InstrumentChoice::Violin);
}

#[test]
fn choosing_a_string_is_one_gesture() {
    let mut f = fixture();
    choose(&mut f, "String", "Auto", "IV (lowest)");
    assert_eq!(f.params.string.value(), StringChoice::IV);
}

#[test]
fn choosing_a_quality_is_one_gesture() {
    let mut f = fixture();
    choose(&mut f, "Quality", "Good", "Reference");
    assert_eq!(f.params.quality.value(), QualityChoice::Reference);
}

/// Whether some label shows exactly `text`.
fn assert_shows(harness: &Harness<'_>, text: &str) {
    assert!(
        harness.query_all_by_value(text).next().is_some(),
        "no label shows {text:?}"
    );
}

#[test]
fn the_schelleng_numbers_follow_the_note_the_audio_thread_reports() {
    let mut f = fixture();
    let link = f.link.clone();
    let mut h = harness(&mut f.editor);
    // No note yet: cello D (Z0 0.506 kg/s); F_max at 0.1 m/s and beta 0.1 is 5.06 N on
    // the string, which String Weight (on) bows with 0.506 / 0.2 = 2.53 times the force
    // parameter: the window shows the parameter's 2.000 N.
    assert_shows(&h, "0.506 kg/s");
    assert_shows(&h, "2.000 N");
    assert_shows(&h, "x 2.53 (the force below is the parameter's)");
    assert_shows(&h, "D3 (no note yet), 146.8 Hz");
    // The strings took G2 (the G string, Z0 0.833 kg/s).
    link.set_note(Some(43));
    h.run();
    assert_shows(&h, "0.833 kg/s");
    assert_shows(&h, "G2 (last note), 98.0 Hz");
    assert_shows(&h, "G string");
    // The player asks for the lowest string: G2 sul C (Z0 1.91 kg/s).
    let params = f.params.clone();
    unsafe {
        params
            .string
            .as_ptr()
            ._internal_set_normalized_value(params.string.preview_normalized(StringChoice::IV));
    }
    h.run();
    assert_shows(&h, "1.910 kg/s");
    assert_shows(&h, "C string");
}

/// Paper B's strings are weighted against their own reference (1 kg/s) and bowed with
/// its friction coefficients (0.8 cold, 0.5 hot): cello D's `F_max` at 0.1 m/s and beta
/// 0.1 is `2 x 0.506 x 0.1 / (0.1 x 0.3)` = 3.373 N on the string, bowed with 0.506 times
/// the force parameter, so the window shows the parameter's 6.667 N.
#[test]
fn the_thermal_models_window_is_in_the_force_parameters_units() {
    let mut f = fixture();
    play_thermal(&f);
    let h = harness(&mut f.editor);
    assert_shows(&h, "0.506 kg/s");
    assert_shows(&h, "6.667 N");
}

#[test]
fn live_views_are_fed_only_while_an_open_editor_shows_them() {
    let mut f = fixture();
    let link = f.link.clone();
    assert!(
        !link.is_listening(),
        "nothing is fed before the editor opens"
    );
    {
        let mut h = harness(&mut f.editor);
        assert!(link.is_listening());
        // Samples arriving from the audio thread are drawn without any input.
        for i in 0..4000 {
            let phase = (i % 327) as f32 / 327.0;
            link.scope.push(ContactSample {
                string_velocity: if phase < 0.9 { 0.1 } else { -0.9 },
                relative_velocity: if phase < 0.9 { 0.0 } else { -1.0 },
                mu: if phase < 0.9 { 0.3 } else { 0.2 },
            });
        }
        h.run();
        let live = h.get_by_role_and_label(egui::Role::CheckBox, "Live views");
        live.click();
        h.run();
        assert!(!link.is_listening(), "hidden live views are not fed");
        h.get_by_role_and_label(egui::Role::CheckBox, "Live views")
            .click();
        h.run();
        assert!(link.is_listening());
    }
    drop(f.editor);
    assert!(!link.is_listening(), "a closed editor is not fed");
}

/// Pushes `periods` periods of a stick-slip train into the scope: `slips` equal slips per
/// 327-sample period (cello D3 at 48 kHz) with friction `mu` (0: the bow is lifted).
fn push_stick_slip(link: &EditorLink, periods: usize, slips: usize, mu: f32) {
    let spacing = 327 / slips;
    for i in 0..periods * 327 {
        let slipping = (i % 327) % spacing < 30 && (i % 327) < slips * spacing;
        link.scope.push(ContactSample {
            string_velocity: if slipping { -0.9 } else { 0.1 },
            relative_velocity: if slipping { -1.0 } else { 0.0 },
            mu,
        });
    }
}

#[test]
fn the_detected_regime_is_shown_beside_the_predicted_one() {
    let mut f = fixture();
    let link = f.link.clone();
    let mut h = harness(&mut f.editor);
    assert_shows(&h, "Predicted: Helmholtz motion");
    assert_shows(&h, "Detected: (waiting for audio)");
    push_stick_slip(&link, 10, 1, 0.3);
    h.run();
    assert_shows(&h, "Detected: Helmholtz motion (1 slip per period)");
    push_stick_slip(&link, 10, 3, 0.3);
    h.run();
    assert_shows(&h, "Detected: multiple slips (3 per period)");
    // The bow lifted: no friction.
    push_stick_slip(&link, 10, 1, 0.0);
    h.run();
    assert_shows(&h, "Detected: silent");
    h.get_by_role_and_label(egui::Role::CheckBox, "Live views")
        .click();
    h.run();
    assert_shows(&h, "Detected: (live views off)");
}

#[test]
fn the_thermal_bow_views_show_the_audio_threads_node_records_only_with_the_thermal_model() {
    let mut f = fixture();
    let link = f.link.clone();
    let params = f.params.clone();
    // Two records from the audio thread: 4 nodes, the second warmer and slipping more.
    for (t, s) in [(1.0f32, 0.25f32), (4.5, 0.5)] {
        let mut record = NodeRecord {
            count: 4,
            ..NodeRecord::default()
        };
        record.temperature_kelvin[..4].copy_from_slice(&[t - 1.0, t, t, t - 1.0]);
        record.slip_fraction[..4].fill(s);
        link.nodes.push(&record);
    }
    let mut h = harness(&mut f.editor);
    assert!(
        h.query_by_label(THERMAL_LABEL).is_none(),
        "not shown with a point law"
    );
    unsafe {
        params
            .friction_model
            .as_ptr()
            ._internal_set_normalized_value(
                params
                    .friction_model
                    .preview_normalized(FrictionChoice::Thermal),
            );
    }
    h.run();
    assert_eq!(
        h.get_by_label(THERMAL_LABEL).value().as_deref(),
        Some("4 nodes, hottest 4.5 K above ambient, slipping 50 % of the time")
    );
}

#[test]
fn choosing_a_preset_hands_the_host_one_whole_state_and_keeps_the_window() {
    let mut f = fixture();
    {
        let mut h = harness(&mut f.editor);
        let combo = h.get_by_role_and_label(egui::Role::ComboBox, PRESET_LABEL);
        combo.click();
        h.run();
        h.get_by_label("Violin detache").click();
        h.run();
    }
    let states = f.recorder.states.lock().unwrap().clone();
    assert_eq!(states.len(), 1, "one state change");
    let expected = colophony::presets::find("violin-detache")
        .unwrap()
        .state_params()
        .unwrap();
    assert_eq!(format!("{:?}", states[0].params), format!("{expected:?}"));
    assert_eq!(
        states[0].fields,
        served_state().fields,
        "window size and version kept"
    );
    // A preset is one state change, not a stream of parameter gestures.
    assert!(f.recorder.calls().is_empty());
}

#[test]
fn saving_a_preset_writes_the_current_values_to_the_user_folder() {
    let dir = std::env::temp_dir().join(format!("colophony-editor-presets-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut f = fixture();
    f.editor.presets_mut().set_user_dir(Some(dir.clone()));
    {
        let mut h = harness(&mut f.editor);
        h.get_by_role_and_label(egui::Role::TextInput, PRESET_NAME_LABEL)
            .click();
        h.run();
        h.get_by_role_and_label(egui::Role::TextInput, PRESET_NAME_LABEL)
            .type_text("My bow");
        h.run();
        h.get_by_label(SAVE_LABEL).click();
        h.run();
    }
    let saved = colophony::presets::Preset::load(&dir.join("my-bow.json")).unwrap();
    assert_eq!(saved.name, "My bow");
    assert_eq!(
        format!("{:?}", saved.state_params().unwrap()),
        format!("{:?}", served_state().params)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn loading_a_bridge_keeps_it_in_the_project_and_restarts_and_a_bad_file_changes_nothing() {
    let cello = colophony::dsp::vocabulary::InstrumentKind::Cello;
    let fitted = workspace_file("assets/bridges/violin-generic.json");
    let broken = std::env::temp_dir().join(format!(
        "colophony-broken-bridge-{}.json",
        std::process::id()
    ));
    std::fs::write(&broken, "{").unwrap();
    let broken_path = broken.clone();
    let broken = broken.to_string_lossy().into_owned();
    for (path, loads, error) in [
        ("/no/such/bridge.json", false, "cannot read"),
        (broken.as_str(), false, "not a bridge JSON file"),
        (fitted.as_str(), true, ""),
    ] {
        let mut f = fixture();
        play_thermal(&f);
        {
            let mut h = harness(&mut f.editor);
            h.get_by_role_and_label(egui::Role::TextInput, BRIDGE_FILE_LABEL)
                .click();
            h.run();
            h.get_by_role_and_label(egui::Role::TextInput, BRIDGE_FILE_LABEL)
                .type_text(path);
            h.run();
            h.get_by_label(LOAD_BRIDGE_LABEL).click();
            h.run();
        }
        let chosen = colophony::user_bridges::chosen_name(&f.params.user_bridges, cello);
        let restarts = *f.recorder.restarts.lock().unwrap();
        let status = f.editor.bridge_status().unwrap_or_default().to_owned();
        if loads {
            assert_eq!(chosen.as_deref(), Some("violin-generic.json"), "{status}");
            assert_eq!(restarts, 1);
            // And back to the shipped bridge: one more restart.
            let mut h = harness(&mut f.editor);
            h.get_by_label(SHIPPED_BRIDGE_LABEL).click();
            h.run();
            drop(h);
            assert_eq!(
                colophony::user_bridges::chosen_name(&f.params.user_bridges, cello),
                None
            );
            assert_eq!(*f.recorder.restarts.lock().unwrap(), 2);
        } else {
            assert_eq!(chosen, None, "{path}: the shipped bridge stays");
            assert_eq!(restarts, 0);
            assert!(status.contains(error), "{path}: {status}");
        }
    }
    std::fs::remove_file(&broken_path).unwrap();
}

/// The thermal model, as a host would set it (the bridge row shows with the strings).
fn play_thermal(f: &Fixture) {
    // SAFETY: the pointer is into the fixture's live parameters.
    unsafe {
        f.params
            .friction_model
            .as_ptr()
            ._internal_set_normalized_value(
                f.params
                    .friction_model
                    .preview_normalized(FrictionChoice::Thermal),
            );
    }
}

fn workspace_file(path: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(path)
        .to_string_lossy()
        .into_owned()
}

#[test]
fn the_pad_marks_the_bow_as_played_where_it_leaves_the_parameters() {
    let mut f = fixture();
    // The performer plays the default bow scaled by the dynamics (CC11 at half): slower
    // and lighter than the parameters say.
    f.link.set_played_bow(Some((0.03, 0.3)));
    {
        let _h = harness(&mut f.editor);
    }
    assert_eq!(f.editor.pad().played_marker(), Some((0.03, 0.3)));
    // On the handle, or with no bow on a string: no marker.
    f.link.set_played_bow(Some((0.1, 1.0)));
    {
        let _h = harness(&mut f.editor);
    }
    assert_eq!(f.editor.pad().played_marker(), None);
    f.link.set_played_bow(None);
    {
        let _h = harness(&mut f.editor);
    }
    assert_eq!(f.editor.pad().played_marker(), None);
    assert!(
        f.recorder.calls().is_empty(),
        "marking sends nothing to the host"
    );
}

#[test]
fn the_midi_map_page_learns_a_controller_and_edits_the_shared_map() {
    use colophony::editor::midi_map_page::{
        ADD_MAPPING_LABEL, DEFAULT_MAP_LABEL, LEARNING_LABEL, LEARN_LABEL, REMOVE_LABEL,
    };
    use colophony::performer::midi_map::{MidiMap, Target};
    let mut f = fixture();
    f.editor.show_midi_map = true;
    let params = f.params.clone();
    let map = || params.midi_map.snapshot();
    assert_eq!(map(), MidiMap::default());
    {
        let mut h = harness(&mut f.editor);
        // Learn on the first row (CC1, vibrato depth), then a controller arrives.
        h.get_all_by_label(LEARN_LABEL).next().unwrap().click();
        h.run();
        assert!(h.query_by_label(LEARNING_LABEL).is_some(), "the row waits");
        f.params.last_controller.record(74);
        h.run();
        assert!(
            h.query_by_label(LEARNING_LABEL).is_none(),
            "the row stopped waiting"
        );
    }
    let first = map().get(0).unwrap();
    assert_eq!((first.cc, first.target), (74, Target::VibratoDepth));
    assert_eq!(
        f.editor.midi_map_page().status(),
        Some("Vibrato depth learned CC 74")
    );
    // Remove it, add a new one, and go back to the defaults.
    {
        let mut h = harness(&mut f.editor);
        h.get_all_by_label(REMOVE_LABEL).next().unwrap().click();
        h.run();
    }
    assert_eq!(map().get(0), None);
    assert_eq!(
        map().mappings().count(),
        MidiMap::default().mappings().count() - 1
    );
    {
        let mut h = harness(&mut f.editor);
        // Under the rows: the page scrolls to it, as a player would.
        h.get_by_label(ADD_MAPPING_LABEL).scroll_to_me();
        h.run();
        h.get_by_label(ADD_MAPPING_LABEL).click();
        h.run();
    }
    assert_eq!(
        map().mappings().count(),
        MidiMap::default().mappings().count()
    );
    {
        let mut h = harness(&mut f.editor);
        // Under the rows: the page scrolls to it, as a player would.
        h.get_by_label(DEFAULT_MAP_LABEL).scroll_to_me();
        h.run();
        h.get_by_label(DEFAULT_MAP_LABEL).click();
        h.run();
    }
    assert_eq!(map(), MidiMap::default());
    assert!(
        f.recorder.calls().is_empty(),
        "the map is not a host parameter"
    );
}

#[test]
fn the_bridge_picker_lists_a_folders_bridges_and_chooses_one() {
    use colophony::editor::bridge::{bridge_entries, BROWSE_LABEL};
    let folder = workspace_file("assets/bridges");
    // The shipped folder: its four bridges, no CSV, sorted.
    let names: Vec<String> = bridge_entries(std::path::Path::new(&folder))
        .iter()
        .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "cello-generic.json",
            "double-bass-generic.json",
            "viola-generic.json",
            "violin-generic.json"
        ]
    );
    let mut f = fixture();
    play_thermal(&f);
    f.editor.bridge_mut().set_path(&folder);
    {
        let mut h = harness(&mut f.editor);
        h.get_by_label(BROWSE_LABEL).click();
        h.run();
        h.get_by_label("violin-generic.json").click();
        h.run();
        h.get_by_label(LOAD_BRIDGE_LABEL).click();
        h.run();
    }
    assert!(f
        .editor
        .bridge_mut()
        .path()
        .ends_with("violin-generic.json"));
    let cello = colophony::dsp::vocabulary::InstrumentKind::Cello;
    assert_eq!(
        colophony::user_bridges::chosen_name(&f.params.user_bridges, cello).as_deref(),
        Some("violin-generic.json")
    );
}
