//! The DSP core. It never imports the plugin framework: it takes plain settings in SI
//! units. Parts: friction contacts ([`friction`]), resonators ([`waveguide`]), the body
//! ([`body`]) on one delay line ([`delay`]), the instrument that wires them to notes and a
//! bow ([`instrument`]); paper B's finite-width thermal bow ([`thermal`]) and its
//! four-string instrument at the modal bridge ([`thermal_instrument`]). Both instruments
//! are one [`strings::FourStrings`] (notes, fingers, the bow on each string, sleep,
//! resampling) over their own [`strings::StringBank`]. The types and constants they all
//! speak in are [`vocabulary`]'s.

pub mod body;
pub mod bounce;
pub mod bridge;
pub mod bridge_data;
pub mod delay;
pub mod engine;
pub mod fastmath;
pub mod filters;
pub mod fingering;
pub mod friction;
pub mod halfband;
pub mod instrument;
pub mod intonation;
pub mod modal;
pub mod radiation;
pub mod resample;
pub mod rubbed;
pub mod strings;
pub mod thermal;
pub mod thermal_instrument;
pub mod vocabulary;
pub mod waveguide;

/// Whether this CPU runs the vector paths (AVX2, detected at run time; the thermal
/// string's node and grid loops, the thermal instrument's sample and the modal bridge
/// choose their AVX code by it, each giving the same bits as its portable path).
pub(crate) fn detect_wide_simd() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
