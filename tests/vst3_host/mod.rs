//! A headless VST3 host for the tests, on the `vst3` crate's bindings (the ones nice-plug's
//! wrapper is built on): it loads the plugin library, creates the audio component from its
//! factory, sets it up as a DAW does (stereo output bus, event input bus,
//! `setupProcessing`, `setActive`, `setProcessing`) and calls `IAudioProcessor::process`
//! with the host's own event list and parameter changes.
//!
//! Events come from the CLAP host's [`Score`], so one score plays through both formats:
//! notes become VST3 note events, parameter changes become points of a parameter queue at
//! their sample offset, and MIDI controllers, channel pressure and pitch bend become
//! points on the wrapper's hidden MIDI parameters, which is how a VST3 host sends them.
//!
//! Everything the plugin calls back during `process` (the event list, the parameter
//! queues) only reads memory the host filled before the call: nothing allocates there,
//! so the plugin build's `assert_process_allocs` checks the whole audio-thread call.

use std::cell::{Cell, RefCell};
use std::ffi::c_void;
use std::path::Path;
use std::ptr;

use vst3::Steinberg::Vst::{
    AudioBusBuffers, AudioBusBuffers__type0, BusDirections_, Event as VstEvent,
    Event_::EventTypes_, Event__type0, IAudioProcessor, IAudioProcessorTrait, IComponent,
    IComponentTrait, IEditController, IEditControllerTrait, IEventList, IEventListTrait,
    IParamValueQueue, IParamValueQueueTrait, IParameterChanges, IParameterChangesTrait,
    MediaTypes_, NoteExpressionValueEvent, NoteOffEvent, NoteOnEvent, ParamID, ParamValue,
    ParameterInfo, ParameterInfo_::ParameterFlags_, ProcessContext, ProcessData, ProcessModes_,
    ProcessSetup, SpeakerArr, SpeakerArrangement, SymbolicSampleSizes_,
};
use vst3::Steinberg::{
    int32, int64, kInvalidArgument, kResultFalse, kResultOk, tresult, IBStream, IBStreamTrait,
    IPluginBaseTrait, IPluginFactory, IPluginFactoryTrait, PClassInfo,
};
use vst3::{Class, ComPtr, ComWrapper, Interface};

use super::host::{Event, Score};

/// nice-plug's VST3 wrapper registers 130 hidden parameters per MIDI channel (128 CCs,
/// channel pressure, pitch bend) for `MidiConfig::MidiCCs`, ending at `1 << 31`.
pub const MIDI_PARAMS_PER_CHANNEL: u32 = 130;
pub const MIDI_PARAMS_END: u32 = 1 << 31;
pub const MIDI_PARAMS_START: u32 = MIDI_PARAMS_END - 16 * MIDI_PARAMS_PER_CHANNEL;

/// The hidden parameter that carries controller `cc` (0..=127; 128 channel pressure, 129
/// pitch bend) of MIDI channel `channel`.
pub fn midi_param(channel: u8, cc: u32) -> ParamID {
    MIDI_PARAMS_START + cc + channel as u32 * MIDI_PARAMS_PER_CHANNEL
}

/// One parameter as the plugin describes it over VST3.
#[derive(Debug, Clone, PartialEq)]
pub struct Vst3Param {
    pub id: ParamID,
    pub title: String,
    pub flags: i32,
    pub default: f64,
}

impl Vst3Param {
    pub fn hidden(&self) -> bool {
        self.flags & ParameterFlags_::kIsHidden != 0
    }

    pub fn automatable(&self) -> bool {
        self.flags & ParameterFlags_::kCanAutomate != 0
    }
}

/// The host's input event list for one block.
struct EventList {
    events: RefCell<Vec<VstEvent>>,
}

impl Class for EventList {
    type Interfaces = (IEventList,);
}

impl IEventListTrait for EventList {
    unsafe fn getEventCount(&self) -> int32 {
        self.events.borrow().len() as int32
    }

    unsafe fn getEvent(&self, index: int32, e: *mut VstEvent) -> tresult {
        match self.events.borrow().get(index as usize) {
            Some(event) if !e.is_null() => {
                // SAFETY: the caller hands a pointer to an `Event` to fill.
                unsafe { *e = *event };
                kResultOk
            }
            _ => kInvalidArgument,
        }
    }

    unsafe fn addEvent(&self, _e: *mut VstEvent) -> tresult {
        // The input list is the host's; a plugin does not add to it.
        kResultFalse
    }
}

/// The points of one parameter in one block.
struct ParamQueue {
    id: Cell<ParamID>,
    points: RefCell<Vec<(int32, ParamValue)>>,
}

impl Class for ParamQueue {
    type Interfaces = (IParamValueQueue,);
}

impl IParamValueQueueTrait for ParamQueue {
    unsafe fn getParameterId(&self) -> ParamID {
        self.id.get()
    }

    unsafe fn getPointCount(&self) -> int32 {
        self.points.borrow().len() as int32
    }

    unsafe fn getPoint(
        &self,
        index: int32,
        sample_offset: *mut int32,
        value: *mut ParamValue,
    ) -> tresult {
        match self.points.borrow().get(index as usize) {
            Some(&(offset, v)) if !sample_offset.is_null() && !value.is_null() => {
                // SAFETY: the caller hands two pointers to fill.
                unsafe {
                    *sample_offset = offset;
                    *value = v;
                }
                kResultOk
            }
            _ => kInvalidArgument,
        }
    }

    unsafe fn addPoint(&self, _offset: int32, _value: ParamValue, _index: *mut int32) -> tresult {
        kResultFalse
    }
}

/// The host's input parameter changes for one block: one queue per parameter that moves.
/// Queues are created by the host before `process` (it may allocate then) and reused.
struct ParamChanges {
    queues: RefCell<Vec<ComWrapper<ParamQueue>>>,
    used: Cell<usize>,
}

impl ParamChanges {
    fn clear(&self) {
        for q in self.queues.borrow().iter().take(self.used.get()) {
            q.points.borrow_mut().clear();
        }
        self.used.set(0);
    }

    /// Adds a point, in the order of the block (points of one queue must be in time order).
    fn add(&self, id: ParamID, offset: i32, value: f64) {
        let used = self.used.get();
        let mut queues = self.queues.borrow_mut();
        let index = match queues[..used].iter().position(|q| q.id.get() == id) {
            Some(i) => i,
            None => {
                if used == queues.len() {
                    queues.push(ComWrapper::new(ParamQueue {
                        id: Cell::new(id),
                        points: RefCell::new(Vec::new()),
                    }));
                }
                queues[used].id.set(id);
                self.used.set(used + 1);
                used
            }
        };
        queues[index].points.borrow_mut().push((offset, value));
    }
}

impl Class for ParamChanges {
    type Interfaces = (IParameterChanges,);
}

impl IParameterChangesTrait for ParamChanges {
    unsafe fn getParameterCount(&self) -> int32 {
        self.used.get() as int32
    }

    unsafe fn getParameterData(&self, index: int32) -> *mut IParamValueQueue {
        if index < 0 || index as usize >= self.used.get() {
            return ptr::null_mut();
        }
        // The host keeps the queue; the plugin borrows it for the call (no reference added).
        self.queues.borrow()[index as usize]
            .as_com_ref::<IParamValueQueue>()
            .map_or(ptr::null_mut(), |r| r.as_ptr())
    }

    unsafe fn addParameterData(
        &self,
        _id: *const ParamID,
        _index: *mut int32,
    ) -> *mut IParamValueQueue {
        ptr::null_mut()
    }
}

/// A memory stream for the plugin state (`IBStream`): seekable, growing on write.
struct MemoryStream {
    bytes: RefCell<Vec<u8>>,
    pos: Cell<usize>,
}

impl Class for MemoryStream {
    type Interfaces = (IBStream,);
}

impl IBStreamTrait for MemoryStream {
    unsafe fn read(&self, buffer: *mut c_void, num_bytes: int32, num_read: *mut int32) -> tresult {
        let bytes = self.bytes.borrow();
        let pos = self.pos.get().min(bytes.len());
        let n = (num_bytes.max(0) as usize).min(bytes.len() - pos);
        // SAFETY: the caller hands a buffer of `num_bytes` bytes.
        unsafe {
            std::ptr::copy_nonoverlapping(bytes[pos..].as_ptr(), buffer as *mut u8, n);
            if !num_read.is_null() {
                *num_read = n as int32;
            }
        }
        self.pos.set(pos + n);
        kResultOk
    }

    unsafe fn write(
        &self,
        buffer: *mut c_void,
        num_bytes: int32,
        num_written: *mut int32,
    ) -> tresult {
        let n = num_bytes.max(0) as usize;
        // SAFETY: the caller hands `num_bytes` bytes.
        let data = unsafe { std::slice::from_raw_parts(buffer as *const u8, n) };
        let mut bytes = self.bytes.borrow_mut();
        let pos = self.pos.get();
        if bytes.len() < pos + n {
            bytes.resize(pos + n, 0);
        }
        bytes[pos..pos + n].copy_from_slice(data);
        self.pos.set(pos + n);
        if !num_written.is_null() {
            // SAFETY: as above.
            unsafe { *num_written = n as int32 };
        }
        kResultOk
    }

    unsafe fn seek(&self, pos: int64, mode: int32, result: *mut int64) -> tresult {
        let len = self.bytes.borrow().len() as int64;
        // kIBSeekSet, kIBSeekCur, kIBSeekEnd
        let base = match mode {
            0 => 0,
            1 => self.pos.get() as int64,
            2 => len,
            _ => return kInvalidArgument,
        };
        let to = (base + pos).clamp(0, len);
        self.pos.set(to as usize);
        if !result.is_null() {
            // SAFETY: the caller hands a pointer to fill.
            unsafe { *result = to };
        }
        kResultOk
    }

    unsafe fn tell(&self, pos: *mut int64) -> tresult {
        if pos.is_null() {
            return kInvalidArgument;
        }
        // SAFETY: checked above.
        unsafe { *pos = self.pos.get() as int64 };
        kResultOk
    }
}

/// The loaded library; `ModuleExit` runs when it is dropped, after every object is released.
struct Module {
    library: libloading::Library,
}

impl Drop for Module {
    fn drop(&mut self) {
        // SAFETY: the symbol has this signature in every VST3 module for Linux.
        unsafe {
            if let Ok(exit) = self
                .library
                .get::<unsafe extern "C" fn() -> bool>(b"ModuleExit")
            {
                exit();
            }
        }
    }
}

/// A loaded VST3 plugin: [`load`](Self::load), [`activate`](Self::activate), then
/// [`render`](Self::render) as often as needed (renders continue from the current state).
pub struct Vst3Plugin {
    // Field order matters for drop: the objects go before the module.
    processor: ComPtr<IAudioProcessor>,
    controller: ComPtr<IEditController>,
    component: ComPtr<IComponent>,
    events: ComWrapper<EventList>,
    changes: ComWrapper<ParamChanges>,
    params: Vec<Vst3Param>,
    active: Option<(f64, usize)>,
    project_time: i64,
    pub class_name: String,
    _module: Module,
}

fn wide_to_string(s: &[u16]) -> String {
    let end = s.iter().position(|&c| c == 0).unwrap_or(s.len());
    String::from_utf16_lossy(&s[..end])
}

fn c_to_string(s: &[std::ffi::c_char]) -> String {
    let bytes: Vec<u8> = s
        .iter()
        .take_while(|&&c| c != 0)
        .map(|&c| c as u8)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

impl Vst3Plugin {
    /// Loads the VST3 module at `path` (the shared library inside a `.vst3` bundle) and
    /// creates its first audio component ("Audio Module Class"), initialised.
    pub fn load(path: &Path) -> Self {
        // SAFETY: loading a shared library runs its initialisers; we only load our own
        // plugin builds. The entry points have the VST3 SDK's signatures.
        unsafe {
            let library = libloading::Library::new(path)
                .unwrap_or_else(|e| panic!("loading {}: {e}", path.display()));
            if let Ok(entry) =
                library.get::<unsafe extern "C" fn(*mut c_void) -> bool>(b"ModuleEntry")
            {
                assert!(entry(ptr::null_mut()), "ModuleEntry failed");
            }
            let module = Module { library };
            let get_factory = module
                .library
                .get::<unsafe extern "system" fn() -> *mut c_void>(b"GetPluginFactory")
                .expect("the library exports GetPluginFactory");
            let factory = ComPtr::<IPluginFactory>::from_raw(get_factory() as *mut IPluginFactory)
                .expect("GetPluginFactory returned a factory");
            let mut info: PClassInfo = std::mem::zeroed();
            let class = (0..factory.countClasses())
                .find_map(|i| {
                    (factory.getClassInfo(i, &mut info) == kResultOk
                        && c_to_string(&info.category) == "Audio Module Class")
                        .then_some(info)
                })
                .expect("the factory has an audio component class");
            let mut obj: *mut c_void = ptr::null_mut();
            let result = factory.createInstance(
                class.cid.as_ptr(),
                IComponent::IID.as_ptr() as *const std::ffi::c_char,
                &mut obj,
            );
            assert_eq!(result, kResultOk, "createInstance failed");
            let component =
                ComPtr::<IComponent>::from_raw(obj as *mut IComponent).expect("a component");
            // nice-plug's component ignores the host context; a null one is allowed.
            assert_eq!(component.initialize(ptr::null_mut()), kResultOk);
            // nice-plug's plugins are single-component: processor and controller are the
            // same object.
            let processor = component
                .cast::<IAudioProcessor>()
                .expect("IAudioProcessor");
            let controller = component
                .cast::<IEditController>()
                .expect("IEditController");
            let params = (0..controller.getParameterCount())
                .map(|i| {
                    let mut p: ParameterInfo = std::mem::zeroed();
                    assert_eq!(controller.getParameterInfo(i, &mut p), kResultOk);
                    Vst3Param {
                        id: p.id,
                        title: wide_to_string(&p.title),
                        flags: p.flags,
                        default: p.defaultNormalizedValue,
                    }
                })
                .collect();
            Vst3Plugin {
                processor,
                controller,
                component,
                events: ComWrapper::new(EventList {
                    events: RefCell::new(Vec::new()),
                }),
                changes: ComWrapper::new(ParamChanges {
                    queues: RefCell::new(Vec::new()),
                    used: Cell::new(0),
                }),
                params,
                active: None,
                project_time: 0,
                class_name: c_to_string(&class.name),
                _module: module,
            }
        }
    }

    /// Every parameter the controller lists, hidden ones included.
    pub fn params(&self) -> &[Vst3Param] {
        &self.params
    }

    /// The parameter titled `title`.
    pub fn param(&self, title: &str) -> &Vst3Param {
        self.params
            .iter()
            .find(|p| p.title == title)
            .unwrap_or_else(|| panic!("no VST3 parameter titled {title:?}"))
    }

    /// The normalised value the plugin holds for `title`.
    pub fn normalized(&self, title: &str) -> f64 {
        let id = self.param(title).id;
        // SAFETY: a plain controller call on the main thread.
        unsafe { self.controller.getParamNormalized(id) }
    }

    /// Sets up processing at `sample_rate` for blocks of up to `max_block` frames with a
    /// stereo output and the event input, activates and starts processing (as a DAW does
    /// when the transport starts).
    pub fn activate(&mut self, sample_rate: f64, max_block: usize) {
        self.deactivate();
        // SAFETY: the calls of a host's set-up sequence, with valid pointers.
        unsafe {
            let mut out: SpeakerArrangement = SpeakerArr::kStereo;
            // No input bus; the wrapper wants a valid pointer all the same.
            let mut no_input: SpeakerArrangement = 0;
            assert_eq!(
                self.processor
                    .setBusArrangements(&mut no_input, 0, &mut out, 1),
                kResultOk,
                "the plugin accepts a stereo output"
            );
            let buses = [
                (MediaTypes_::kAudio, BusDirections_::kOutput),
                (MediaTypes_::kEvent, BusDirections_::kInput),
            ];
            for (media, dir) in buses {
                if self.component.getBusCount(media as i32, dir as i32) > 0 {
                    assert_eq!(
                        self.component.activateBus(media as i32, dir as i32, 0, 1),
                        kResultOk
                    );
                }
            }
            let mut setup = ProcessSetup {
                processMode: ProcessModes_::kRealtime as i32,
                symbolicSampleSize: SymbolicSampleSizes_::kSample32 as i32,
                maxSamplesPerBlock: max_block as i32,
                sampleRate: sample_rate,
            };
            assert_eq!(self.processor.setupProcessing(&mut setup), kResultOk);
            assert_eq!(
                self.component.setActive(1),
                kResultOk,
                "setActive(true) failed at {sample_rate} Hz"
            );
            assert_eq!(self.processor.setProcessing(1), kResultOk);
        }
        self.active = Some((sample_rate, max_block));
        self.project_time = 0;
    }

    pub fn deactivate(&mut self) {
        if self.active.take().is_some() {
            // SAFETY: the host's tear-down sequence.
            unsafe {
                self.processor.setProcessing(0);
                self.component.setActive(0);
            }
        }
    }

    /// The plugin's state, as a host saves it with a project (`IComponent::getState`).
    pub fn save_state(&self) -> Vec<u8> {
        let stream = ComWrapper::new(MemoryStream {
            bytes: RefCell::new(Vec::new()),
            pos: Cell::new(0),
        });
        let ptr = stream.as_com_ref::<IBStream>().unwrap().as_ptr();
        // SAFETY: the stream lives across the call.
        let result = unsafe { self.component.getState(ptr) };
        assert_eq!(result, kResultOk, "getState failed");
        let bytes = stream.bytes.borrow().clone();
        bytes
    }

    /// Loads a saved state as a host reopening a project does (`IComponent::setState`,
    /// then the controller's `setComponentState`); `Err` if the plugin refuses it.
    pub fn load_state(&self, bytes: &[u8]) -> Result<(), tresult> {
        let stream = ComWrapper::new(MemoryStream {
            bytes: RefCell::new(bytes.to_vec()),
            pos: Cell::new(0),
        });
        let ptr = stream.as_com_ref::<IBStream>().unwrap().as_ptr();
        // SAFETY: the stream lives across the calls.
        unsafe {
            let result = self.component.setState(ptr);
            if result != kResultOk {
                return Err(result);
            }
            stream.pos.set(0);
            self.controller.setComponentState(ptr);
        }
        Ok(())
    }

    /// The text the plugin shows for parameter `title` at its current value.
    pub fn value_text(&self, title: &str) -> String {
        let id = self.param(title).id;
        let mut text = [0u16; 128];
        // SAFETY: plain controller calls with a buffer of the size VST3 defines.
        unsafe {
            let value = self.controller.getParamNormalized(id);
            assert_eq!(
                self.controller.getParamStringByValue(id, value, &mut text),
                kResultOk
            );
        }
        wide_to_string(&text)
    }

    /// The plugin's latency in samples, as a VST3 host asks for it.
    pub fn latency(&self) -> u32 {
        // SAFETY: a plain processor call.
        unsafe { self.processor.getLatencySamples() }
    }

    /// Fills the host's event list and parameter queues for one block.
    fn stage(&self, offset: i32, event: Event) {
        let note = |on: bool, key: u8, velocity: f64, channel: i16| {
            let mut e = VstEvent {
                busIndex: 0,
                sampleOffset: offset,
                ppqPosition: 0.0,
                flags: 0,
                r#type: if on {
                    EventTypes_::kNoteOnEvent as u16
                } else {
                    EventTypes_::kNoteOffEvent as u16
                },
                // SAFETY: every union member is plain data.
                __field0: unsafe { std::mem::zeroed::<Event__type0>() },
            };
            // The note id is the key: one note per key, as the score has it.
            if on {
                e.__field0.noteOn = NoteOnEvent {
                    channel,
                    pitch: key as i16,
                    tuning: 0.0,
                    velocity: velocity as f32,
                    length: 0,
                    noteId: key as i32,
                };
            } else {
                e.__field0.noteOff = NoteOffEvent {
                    channel,
                    pitch: key as i16,
                    velocity: 0.0,
                    noteId: key as i32,
                    tuning: 0.0,
                };
            }
            self.events.events.borrow_mut().push(e);
        };
        match event {
            Event::NoteOn { key, velocity } => note(true, key, velocity, 0),
            Event::NoteOff { key } => note(false, key, 0.0, 0),
            Event::Param { id, value } => self.changes.add(u32::from(id), offset, value),
            Event::Controller { cc, value } => self.changes.add(
                midi_param(0, cc as u32 & 0x7f),
                offset,
                value as f64 / 127.0,
            ),
            Event::PitchBend { amount } => {
                let v = (8192.0 + amount * 8192.0).round().clamp(0.0, 16383.0);
                self.changes.add(midi_param(0, 129), offset, v / 16383.0)
            }
            Event::Midi([status, a, b]) => {
                let channel = status & 0x0f;
                match status & 0xf0 {
                    0x90 if b > 0 => note(true, a, b as f64 / 127.0, channel as i16),
                    0x80 | 0x90 => note(false, a, 0.0, channel as i16),
                    0xb0 => self.changes.add(
                        midi_param(channel, a as u32 & 0x7f),
                        offset,
                        b as f64 / 127.0,
                    ),
                    0xd0 => self
                        .changes
                        .add(midi_param(channel, 128), offset, a as f64 / 127.0),
                    0xe0 => {
                        let v = ((b as u32) << 7 | a as u32) as f64;
                        self.changes
                            .add(midi_param(channel, 129), offset, v / 16383.0)
                    }
                    _ => panic!("the VST3 host does not send MIDI status {status:#x}"),
                }
            }
            Event::Tuning { key, semitones } => {
                self.note_expression(offset, key, 2, 0.5 + semitones / 240.0)
            }
            // kBrightnessTypeID, 0..1.
            Event::Brightness { key, value } => self.note_expression(offset, key, 5, value),
        }
    }

    /// A VST3 note expression value event: `type_id` (kTuningTypeID 2: +-120 semitones
    /// over 0..1; kBrightnessTypeID 5) on the note of `key`, at `offset`.
    fn note_expression(&self, offset: i32, key: u8, type_id: u32, value: f64) {
        let mut e = VstEvent {
            busIndex: 0,
            sampleOffset: offset,
            ppqPosition: 0.0,
            flags: 0,
            r#type: EventTypes_::kNoteExpressionValueEvent as u16,
            // SAFETY: every union member is plain data.
            __field0: unsafe { std::mem::zeroed::<Event__type0>() },
        };
        e.__field0.noteExpressionValue = NoteExpressionValueEvent {
            typeId: type_id,
            noteId: key as i32,
            value,
        };
        self.events.events.borrow_mut().push(e);
    }

    /// Renders `frames` frames in blocks of `block` frames, each event of `score` in the
    /// block that holds its sample (as [`super::host::HostedPlugin::render`] does). A
    /// `block` of 0 is not allowed; see [`flush`](Self::flush) for a parameter flush.
    pub fn render(&mut self, frames: usize, block: usize, score: &Score) -> Vec<Vec<f32>> {
        let (sample_rate, max_block) = self.active.expect("activate the plugin before rendering");
        assert!(
            block >= 1 && block <= max_block,
            "block size {block} outside 1..={max_block}"
        );
        let events = score.events();
        let mut out = vec![Vec::with_capacity(frames); 2];
        let mut buffers = vec![vec![0.0f32; block]; 2];
        let mut next = 0;
        let mut pos = 0usize;
        while pos < frames {
            let n = block.min(frames - pos);
            self.events.events.borrow_mut().clear();
            self.changes.clear();
            while next < events.len() && (events[next].0 as usize) < pos + n {
                let (at, event) = events[next];
                self.stage((at as usize - pos) as i32, event);
                next += 1;
            }
            for b in &mut buffers {
                // The plugin must overwrite every sample; NaN shows any it leaves.
                b[..n].fill(f32::NAN);
            }
            self.process(sample_rate, n, Some(&mut buffers));
            for (o, b) in out.iter_mut().zip(&buffers) {
                o.extend_from_slice(&b[..n]);
            }
            pos += n;
        }
        assert!(next == events.len(), "events past the end of the render");
        out
    }

    /// A parameter flush: a `process` call of zero samples and no audio buffers carrying
    /// `score`'s events (all at offset 0), as some DAWs send while stopped.
    pub fn flush(&mut self, score: &Score) {
        let (sample_rate, _) = self.active.expect("activate the plugin first");
        self.events.events.borrow_mut().clear();
        self.changes.clear();
        for &(_, event) in score.events() {
            self.stage(0, event);
        }
        self.process(sample_rate, 0, None);
    }

    fn process(&mut self, sample_rate: f64, n: usize, buffers: Option<&mut Vec<Vec<f32>>>) {
        let mut channel_ptrs: Vec<*mut f32> = match buffers {
            Some(b) => b.iter_mut().map(|c| c.as_mut_ptr()).collect(),
            None => Vec::new(),
        };
        let mut bus = AudioBusBuffers {
            numChannels: channel_ptrs.len() as i32,
            silenceFlags: 0,
            __field0: AudioBusBuffers__type0 {
                channelBuffers32: channel_ptrs.as_mut_ptr(),
            },
        };
        // SAFETY: a zeroed context is a valid "nothing known" context; fields set below.
        let mut context: ProcessContext = unsafe { std::mem::zeroed() };
        context.sampleRate = sample_rate;
        context.projectTimeSamples = self.project_time;
        context.continousTimeSamples = self.project_time;
        context.tempo = 120.0;
        context.timeSigNumerator = 4;
        context.timeSigDenominator = 4;
        // kPlaying | kTempoValid | kTimeSigValid | kContTimeValid
        context.state = 2 | 1024 | 8192 | 131072;
        let has_audio = !channel_ptrs.is_empty();
        let mut data = ProcessData {
            processMode: ProcessModes_::kRealtime as i32,
            symbolicSampleSize: SymbolicSampleSizes_::kSample32 as i32,
            numSamples: n as i32,
            numInputs: 0,
            numOutputs: has_audio as i32,
            inputs: ptr::null_mut(),
            outputs: if has_audio { &mut bus } else { ptr::null_mut() },
            inputParameterChanges: self
                .changes
                .as_com_ref::<IParameterChanges>()
                .unwrap()
                .as_ptr(),
            outputParameterChanges: ptr::null_mut(),
            inputEvents: self.events.as_com_ref::<IEventList>().unwrap().as_ptr(),
            outputEvents: ptr::null_mut(),
            processContext: &mut context,
        };
        // SAFETY: every pointer in `data` lives until the call returns.
        let result = unsafe { self.processor.process(&mut data) };
        assert_eq!(result, kResultOk, "process failed");
        self.project_time += n as i64;
    }
}

impl Drop for Vst3Plugin {
    fn drop(&mut self) {
        self.deactivate();
        // SAFETY: the last call before releasing the component.
        unsafe {
            self.component.terminate();
        }
    }
}
