//! The plugin editor (nice-plug-egui): an XY pad for bow velocity and force with the
//! Schelleng window behind it, the bow position and the model selectors.
//!
//! * [`mapping`]: the pad's pixel <-> parameter mapping and the Schelleng curves (pure).
//! * [`pad`]: the pad widget and its begin/set/end gestures.
//! * [`view`]: the editor's contents, drawn into any `egui::Ui` ([`EditorUi`]).
//! * [`live`]: the live views and the wait-free ring that feeds them from the audio thread.
//! * [`nodes`]: the thermal bow's temperature and slip views and their wait-free ring.
//! * [`bridge`]: the instrument's bridge: load a fitted one, or the shipped one.
//! * [`midi_map_page`]: the MIDI map page: controllers to targets, ranges, curves, learn.
//! * [`presets`]: the preset selector and "save as" ([`crate::presets`]).
//! * [`crate::measure::regime`]: the regime the string is in, classified from the live samples (pure).
//! * This file: the window glue. [`ColophonyEditor`] is the plugin's `Editor`;
//!   [`EditorState`] is the window size saved with the plugin state
//!   (`#[persist = "editor-state"]` in [`crate::params::ColophonyParams`]); [`EditorLink`]
//!   carries what the audio thread tells the editor (the current note, the live samples).
//!
//! **Why a wrapper around `EguiEditor`.** nice-plug-egui 0.6's `EguiEditorState` has no
//! serde support and no way to set its size after creation, and `Plugin::editor` is called
//! once when the plugin is created, before the host loads the saved state. So the window
//! size lives in [`EditorState`] (persisted), every resize writes it, and
//! [`ColophonyEditor`] rebuilds its `EguiEditor` from it whenever they differ while the
//! window is closed (after a state load), before the host asks for the size or opens the
//! window.

pub mod bridge;
pub mod live;
pub mod mapping;
pub mod midi_map_page;
pub mod nodes;
pub mod pad;
pub mod presets;
pub mod view;

pub use crate::editor_state::{EditorSize, EditorState};
pub use view::EditorUi;

use crate::params::ColophonyParams;
use crate::performer::Articulation;
use nice_plug::context::gui::GuiContext;
use nice_plug::editor::dpi::{LogicalSize, NativeSize, Size};
use nice_plug::editor::{Editor, HostMethods, ParentWindowHandle, ResizeHint, SpawnedEditor};
use nice_plug::plugin::TrackInfo;
use nice_plug_egui::baseview::{HandlerError, WindowSize};
use nice_plug_egui::{
    create_egui_editor, EguiEditor, EguiEditorHandle, EguiEditorState, EguiNiceSettings, Frame,
    NiceEguiApp, RepaintNotifier,
};
use std::error::Error;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// What the audio thread tells the editor, lock-free: the note once per block, and the
/// live samples and the thermal bow's nodes only while an editor showing them is open.
#[derive(Debug)]
pub struct EditorLink {
    note: AtomicU8,
    /// The articulation notes play, its index in [`Articulation::ALL`].
    articulation: AtomicU8,
    listening: AtomicBool,
    /// The bow as played (after the strokes, the dynamics and the controllers): velocity
    /// and force as f32 bits in one word, [`Self::NO_BOW`] while nothing is bowed.
    played: AtomicU64,
    /// The probed string's contact, one sample per audio sample while listening.
    pub scope: live::Scope,
    /// The thermal bow's nodes on the probed string, one record every few ms while
    /// listening to the thermal instrument.
    pub nodes: nodes::NodeRing,
}

impl EditorLink {
    const NO_NOTE: u8 = u8::MAX;
    const NO_BOW: u64 = u64::MAX;

    /// Audio thread, once per block: the bow as the performer plays it (velocity m/s,
    /// force N), or `None` while no bow is on a string.
    pub fn set_played_bow(&self, bow: Option<(f32, f32)>) {
        let bits = bow.map_or(Self::NO_BOW, |(v, f)| {
            (v.to_bits() as u64) << 32 | f.to_bits() as u64
        });
        self.played.store(bits, Ordering::Relaxed);
    }

    /// The bow as played, for the pad's marker.
    pub fn played_bow(&self) -> Option<(f32, f32)> {
        match self.played.load(Ordering::Relaxed) {
            Self::NO_BOW => None,
            bits => Some((
                f32::from_bits((bits >> 32) as u32),
                f32::from_bits(bits as u32),
            )),
        }
    }

    /// Audio thread: the last note the strings took (`None` before any).
    pub fn set_note(&self, note: Option<u8>) {
        self.note
            .store(note.unwrap_or(Self::NO_NOTE), Ordering::Relaxed);
    }

    pub fn note(&self) -> Option<u8> {
        match self.note.load(Ordering::Relaxed) {
            Self::NO_NOTE => None,
            note => Some(note),
        }
    }

    /// Audio thread, once per block: the articulation notes play (the parameter's, or a
    /// keyswitch's or controller's over it).
    pub fn set_articulation(&self, articulation: Articulation) {
        let index = Articulation::ALL.iter().position(|&a| a == articulation);
        self.articulation
            .store(index.unwrap_or(0) as u8, Ordering::Relaxed);
    }

    pub fn articulation(&self) -> Articulation {
        let index = self.articulation.load(Ordering::Relaxed) as usize;
        Articulation::ALL.get(index).copied().unwrap_or_default()
    }

    /// Editor: whether it shows the live views (false when it closes).
    pub fn set_listening(&self, on: bool) {
        self.listening.store(on, Ordering::Relaxed);
    }

    /// Audio thread, once per block: whether to feed [`Self::scope`].
    pub fn is_listening(&self) -> bool {
        self.listening.load(Ordering::Relaxed)
    }
}

impl Default for EditorLink {
    fn default() -> Self {
        Self {
            note: AtomicU8::new(Self::NO_NOTE),
            articulation: AtomicU8::new(0),
            listening: AtomicBool::new(false),
            played: AtomicU64::new(Self::NO_BOW),
            scope: live::Scope::default(),
            nodes: nodes::node_ring(),
        }
    }
}

/// The nice-plug-egui app: builds an [`EditorUi`] when the window opens, drops it (ending
/// any open gesture) when it closes, and saves every resize in [`EditorState`].
pub struct EditorApp {
    params: Arc<ColophonyParams>,
    link: Arc<EditorLink>,
    ui: Option<EditorUi>,
}

impl NiceEguiApp for EditorApp {
    fn build(
        &mut self,
        _egui_ctx: egui::Context,
        nice_gui_ctx: GuiContext,
        _frame: &mut Frame,
    ) -> Result<(), HandlerError> {
        self.ui = Some(EditorUi::new(
            self.params.clone(),
            self.link.clone(),
            nice_gui_ctx,
        ));
        Ok(())
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut Frame) {
        if let Some(editor) = &mut self.ui {
            editor.ui(ui);
        }
    }

    fn resized(&mut self, new_size: WindowSize) {
        self.params.editor_state.set_size(EditorSize {
            width: new_size.logical.width as f32,
            height: new_size.logical.height as f32,
        });
    }

    fn editor_closed(&mut self) {
        self.ui = None;
    }
}

impl Drop for EditorUi {
    fn drop(&mut self) {
        self.end_gestures();
        self.stop_listening();
    }
}

struct Built {
    state: Arc<EguiEditorState>,
    editor: EguiEditor<EditorApp>,
}

impl Built {
    fn size(&self) -> Option<EditorSize> {
        match self.state.size() {
            Size::Logical(l) => Some(EditorSize {
                width: l.width as f32,
                height: l.height as f32,
            }),
            Size::Physical(_) => None,
        }
    }
}

/// The plugin's editor: an `EguiEditor` rebuilt from the persisted size when needed.
pub struct ColophonyEditor {
    params: Arc<ColophonyParams>,
    link: Arc<EditorLink>,
    built: Mutex<Built>,
}

impl ColophonyEditor {
    pub fn new(params: Arc<ColophonyParams>, link: Arc<EditorLink>) -> Self {
        let built = Mutex::new(Self::build(&params, &link));
        Self {
            params,
            link,
            built,
        }
    }

    fn build(params: &Arc<ColophonyParams>, link: &Arc<EditorLink>) -> Built {
        let size = params.editor_state.size();
        let state = EguiEditorState::from_size(
            LogicalSize::new(size.width as f64, size.height as f64),
            1.0,
        );
        let settings = EguiNiceSettings::new()
            .with_tile("Colophony")
            .with_resize_hint(ResizeHint::resizable().with_min_max_logical_size(
                Some(LogicalSize::new(
                    EditorSize::MIN.width,
                    EditorSize::MIN.height,
                )),
                Some(LogicalSize::new(
                    EditorSize::MAX.width,
                    EditorSize::MAX.height,
                )),
            ));
        let app = EditorApp {
            params: params.clone(),
            link: link.clone(),
            ui: None,
        };
        let editor = create_egui_editor(state.clone(), RepaintNotifier::new(), settings, app)
            .expect("create_egui_editor always returns an editor");
        Built { state, editor }
    }

    /// The editor, rebuilt first if the persisted size changed while the window was closed.
    fn current(&self) -> MutexGuard<'_, Built> {
        let mut built = self
            .built
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if !built.state.is_open() && built.size() != Some(self.params.editor_state.size()) {
            *built = Self::build(&self.params, &self.link);
        }
        built
    }
}

impl Editor for ColophonyEditor {
    type Handle = EguiEditorHandle;

    fn spawn(
        &self,
        parent: Option<ParentWindowHandle>,
        wait_for_parent: bool,
        fallback_scale_factor: Option<f64>,
        gui_context: GuiContext,
        host: Option<HostMethods>,
    ) -> Result<SpawnedEditor<Self::Handle>, Box<dyn Error>> {
        self.current().editor.spawn(
            parent,
            wait_for_parent,
            fallback_scale_factor,
            gui_context,
            host,
        )
    }

    fn size(&self) -> NativeSize<u32> {
        self.current().editor.size()
    }

    fn resize_hint(&self) -> ResizeHint {
        self.current().editor.resize_hint()
    }

    fn track_info_updated(&self, info: TrackInfo) {
        self.current().editor.track_info_updated(info);
    }

    unsafe fn assume_standalone_in_process(&self) {
        // SAFETY: the caller upholds `Editor::assume_standalone_in_process`'s contract,
        // which is the inner editor's.
        unsafe { self.current().editor.assume_standalone_in_process() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nice_plug::prelude::Params;

    #[test]
    fn editor_size_is_saved_and_restored_with_the_plugin_state() {
        let saved = ColophonyParams::default();
        saved.editor_state.set_size(EditorSize {
            width: 1000.0,
            height: 700.0,
        });
        let fields = saved.serialize_fields();
        assert!(fields.contains_key("editor-state"), "{fields:?}");

        let loaded = ColophonyParams::default();
        assert_eq!(loaded.editor_state.size(), EditorSize::DEFAULT);
        loaded.deserialize_fields(&fields);
        assert_eq!(
            loaded.editor_state.size(),
            EditorSize {
                width: 1000.0,
                height: 700.0
            }
        );
    }

    #[test]
    fn editor_size_is_kept_within_limits() {
        let state = EditorState::default();
        state.set_size(EditorSize {
            width: 10.0,
            height: 1e6,
        });
        assert_eq!(
            state.size(),
            EditorSize {
                width: EditorSize::MIN.width,
                height: EditorSize::MAX.height
            }
        );
        state.set_size(EditorSize {
            width: f32::NAN,
            height: 500.0,
        });
        assert_eq!(state.size(), EditorSize::DEFAULT);
    }

    #[test]
    fn editor_is_rebuilt_at_the_loaded_size() {
        let params = Arc::new(ColophonyParams::default());
        let editor = ColophonyEditor::new(params.clone(), Arc::new(EditorLink::default()));
        assert_eq!(editor.current().size(), Some(EditorSize::DEFAULT));
        let loaded = EditorSize {
            width: 900.0,
            height: 600.0,
        };
        params.editor_state.set_size(loaded);
        assert_eq!(editor.current().size(), Some(loaded));
        assert!(editor.resize_hint().can_resize);
    }

    #[test]
    fn editor_link_carries_the_note() {
        let link = EditorLink::default();
        assert_eq!(link.note(), None);
        link.set_note(Some(50));
        assert_eq!(link.note(), Some(50));
        link.set_note(None);
        assert_eq!(link.note(), None);
    }
}
