#[cfg(feature = "editor")]
use vst3::Steinberg::FIDString;
use vst3::Steinberg::Vst::TChar;

/// When `Plugin::MIDI_INPUT` is set to `MidiConfig::MidiCCs` or higher then we'll register 130*16
/// additional parameters to handle MIDI CCs, channel pressure, and pitch bend, in that order.
/// vst3 doesn't expose these constants.
pub const VST3_MIDI_CCS: u32 = 130;
pub const VST3_MIDI_CHANNELS: u32 = 16;
/// The number of parameters we'll need to register if the plugin accepts MIDI CCs.
pub const VST3_MIDI_NUM_PARAMS: u32 = VST3_MIDI_CCS * VST3_MIDI_CHANNELS;
/// The start of the MIDI CC parameter ranges. We'll print an assertion failure if any of the
/// plugin's parameters overlap with this range. The mapping to a parameter index is
/// `VST3_MIDI_PARAMS_START + (cc_idx + (channel * VST3_MIDI_CCS))`.
pub const VST3_MIDI_PARAMS_START: u32 = VST3_MIDI_PARAMS_END - VST3_MIDI_NUM_PARAMS;
/// The (exclusive) end of the MIDI CC parameter range. Anything above this is reserved by the host.
pub const VST3_MIDI_PARAMS_END: u32 = 1 << 31;

/// Early exit out of a VST3 function when one of the passed pointers is null
macro_rules! check_null_ptr {
    ($ptr:expr $(, $ptrs:expr)* $(, )?) => {
        check_null_ptr_msg!("Null pointer passed to function", $ptr $(, $ptrs)*)
    };
}

/// The same as [`check_null_ptr!`], but with a custom message.
macro_rules! check_null_ptr_msg {
    ($msg:expr, $ptr:expr $(, $ptrs:expr)* $(, )?) => {
        if $ptr.is_null() $(|| $ptrs.is_null())* {
            crate::nice_debug_assert_failure!($msg);
            return kInvalidArgument;
        }
    };
}

/// The same as [`strlcpy()`], but for VST3's fun UTF-16 strings instead. Encodes straight
/// into `dest` without allocating: hosts query parameter names and values thousands of
/// times, some of them once per parameter per lookup.
pub fn u16strlcpy(dest: &mut [TChar], src: &str) {
    if dest.is_empty() {
        return;
    }

    // Make sure there's always room for a null terminator. Like a C string, the copy ends at
    // an interior null.
    let capacity = dest.len() - 1;
    let mut copy_len = 0;
    for (slot, unit) in dest[..capacity]
        .iter_mut()
        .zip(src.encode_utf16().take_while(|&unit| unit != 0))
    {
        *slot = unit as TChar;
        copy_len += 1;
    }
    dest[copy_len] = 0;
}

/// The title of the hidden parameter for MIDI controller `controller` (0-127 the CCs, 128
/// channel pressure, 129 pitch bend) on the 0-based `channel`: `MIDI CC <channel>|<controller>`,
/// the names JUCE's VST3 wrapper gives the same parameters, which JUCE-based hosts recognise
/// and leave out of their parameter lists. Written into `dest` without allocating.
pub fn write_midi_param_title(dest: &mut [TChar], channel: u32, controller: u32) {
    use std::io::Write;

    let mut buffer = [0u8; 32];
    let capacity = buffer.len();
    let mut cursor = &mut buffer[..];
    // "MIDI CC 15|129" is 14 bytes: the buffer cannot overflow.
    let _ = write!(cursor, "MIDI CC {channel}|{controller}");
    let len = capacity - cursor.len();
    u16strlcpy(dest, std::str::from_utf8(&buffer[..len]).unwrap_or_default());
}

/// Compare a host-provided [`FIDString`] to one of the SDK's string constants. These are plain C
/// string pointers, so pointer equality is not sufficient.
#[cfg(feature = "editor")]
pub unsafe fn fid_matches(type_: FIDString, expected: FIDString) -> bool {
    use std::ffi::CStr;

    unsafe { !type_.is_null() && CStr::from_ptr(type_) == CStr::from_ptr(expected) }
}

#[cfg(test)]
mod miri {
    use widestring::U16CStr;

    use super::*;

    #[test]
    fn u16strlcpy_normal() {
        let mut dest = [0; 256];
        u16strlcpy(&mut dest, "Hello, world!");

        assert_eq!(
            unsafe { U16CStr::from_ptr_str(dest.as_ptr() as *const u16) }
                .to_string()
                .unwrap(),
            "Hello, world!"
        );
    }

    #[test]
    fn u16strlcpy_overflow() {
        let mut dest = [0; 6];
        u16strlcpy(&mut dest, "Hello, world!");

        assert_eq!(
            unsafe { U16CStr::from_ptr_str(dest.as_ptr() as *const u16) }
                .to_string()
                .unwrap(),
            "Hello"
        );
    }
}
