//! Bow-string friction contacts: the static hyperbolic curve (here), the static Stribeck
//! curve ([`stribeck`]), LuGre and elasto-plastic bristle models solved by the K-method
//! ([`bristle`]), and [`AnyFriction`], which switches between them without allocating.
//!
//! A contact sits between a bow (a velocity source pressed with a normal force) and a
//! resonator that tells it, each sample, its *load line*: the velocity it would have at the
//! contact with no force (`v_h`, from incoming waves or free modal motion) and its
//! instantaneous admittance `Y`, so that with a friction force `F` it moves at
//! `v_s = v_h + Y F`. For a waveguide string bowed at one point `Y = 1 / (2 Z0)`.
//! Every friction law implements [`FrictionContact`]; the resonator does not know which.
//!
//! Sign convention: `F` is the force of the bow on the resonator; it acts along the
//! relative (sliding) velocity `dv = v_b - v_s`.
//!
//! | symbol | meaning | unit | source |
//! |---|---|---|---|
//! | `mu_s` | static friction coefficient | 1 | Serafin et al. (paper A): 0.4 |
//! | `mu_d` | dynamic (fast-sliding) friction coefficient | 1 | paper A: 0.2 |
//! | `v0` | velocity scale of the hyperbolic curve | m/s | paper A's Stribeck `v_s` = 0.1 |
//! | `F_N` | bow normal force | N | player |
//! | `Y` | admittance of the resonator at the contact | s/kg | resonator |
//!
//! ```
//! use colophony::dsp::friction::{BowInput, FrictionContact, HyperbolicFriction, LoadLine};
//! let mut contact = HyperbolicFriction::default();
//! let load = LoadLine { free_velocity_m_per_s: 0.0, admittance_s_per_kg: 1.0 };
//! let bow = BowInput { velocity_m_per_s: 0.1, normal_force_n: 1.0 };
//! // Small relative velocity, large force: the bow sticks and drags the string along.
//! let f = contact.solve(load, bow);
//! assert!((load.free_velocity_m_per_s + f * load.admittance_s_per_kg - 0.1).abs() < 1e-12);
//! ```

pub mod bristle;
pub mod stribeck;

use bristle::{BristleFriction, BristleLaw, BristleParams};
use stribeck::StribeckFriction;

/// What the resonator offers the contact this sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadLine {
    /// Velocity at the contact if no force acted this sample (`v_h`), m/s.
    pub free_velocity_m_per_s: f64,
    /// Instantaneous admittance at the contact (`Y`), s/kg: `v_s = v_h + Y F`.
    pub admittance_s_per_kg: f64,
}

/// What the player does with the bow this sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowInput {
    pub velocity_m_per_s: f64,
    pub normal_force_n: f64,
}

/// A friction law with its solver: given the load line and the bow, the force (N) of the bow
/// on the resonator, found without inserting any delay in the loop.
pub trait FrictionContact {
    fn solve(&mut self, load: LoadLine, bow: BowInput) -> f64;
    /// Whether the contact stuck on the last sample.
    fn is_sticking(&self) -> bool;
    fn reset(&mut self);
}

/// Static hyperbolic friction curve `mu(dv) = mu_d + (mu_s - mu_d) v0 / (v0 + |dv|)` (the
/// curve of JOS's bowed-string junction, CLM `strad` and SuperCollider `DWGBowed`), solved
/// exactly each sample by Friedlander's construction: the load line `F = (dv_stick - dv) / Y`
/// meets the sliding branch where a quadratic in `|dv|` vanishes.
///
/// **Three crossings.** Where the curve is steeper than the load line, the line can cross
/// the sticking segment (`dv = 0`, `|F| <= mu_s F_N`) and the sliding branch twice. The
/// rule (McIntyre, Schumacher and Woodhouse's hysteresis): the contact keeps its state while
/// that state's crossing exists: a sticking contact sticks while `|F_stick| <= mu_s F_N`; a
/// slipping contact keeps slipping on the outer (stable, largest `|dv|`) crossing; the
/// middle crossing is unstable and never taken. It changes state only when its crossing
/// disappears.
#[derive(Debug, Clone, Copy)]
pub struct HyperbolicFriction {
    pub mu_s: f64,
    pub mu_d: f64,
    pub v0_m_per_s: f64,
    sticking: bool,
}

impl Default for HyperbolicFriction {
    fn default() -> Self {
        Self {
            mu_s: 0.4,
            mu_d: 0.2,
            v0_m_per_s: 0.1,
            sticking: false,
        }
    }
}

impl HyperbolicFriction {
    /// Sets the sticking state (for a hand-over from another contact).
    pub fn set_sticking(&mut self, sticking: bool) {
        self.sticking = sticking;
    }

    /// Friction coefficient at sliding speed `|dv|`.
    pub fn mu(&self, abs_dv: f64) -> f64 {
        self.mu_d + (self.mu_s - self.mu_d) * self.v0_m_per_s / (self.v0_m_per_s + abs_dv)
    }

    /// The outer sliding root `|dv| > 0` for a stick velocity `|dv_stick|`, if one exists.
    fn outer_slip_root(&self, abs_dv_stick: f64, two_z: f64, f_n: f64) -> Option<f64> {
        // two_z (|dv_stick| - u) (v0 + u) = f_n (mu_d (v0 + u) + (mu_s - mu_d) v0), i.e.
        // two_z u^2 + b u + c = 0:
        let v0 = self.v0_m_per_s;
        let b = two_z * v0 + f_n * self.mu_d - two_z * abs_dv_stick;
        let c = v0 * (f_n * self.mu_s - two_z * abs_dv_stick);
        let disc = b * b - 4.0 * two_z * c;
        if disc < 0.0 {
            return None;
        }
        // Larger root, in the form that avoids cancellation.
        let sq = disc.sqrt();
        let u = if b <= 0.0 {
            (-b + sq) / (2.0 * two_z)
        } else {
            -2.0 * c / (b + sq)
        };
        (u > 0.0).then_some(u)
    }
}

impl FrictionContact for HyperbolicFriction {
    #[inline]
    fn solve(&mut self, load: LoadLine, bow: BowInput) -> f64 {
        let f_n = bow.normal_force_n;
        if f_n <= 0.0 {
            self.sticking = false;
            return 0.0;
        }
        let two_z = 1.0 / load.admittance_s_per_kg;
        let dv_stick = bow.velocity_m_per_s - load.free_velocity_m_per_s;
        let f_stick = two_z * dv_stick;
        let can_stick = f_stick.abs() <= self.mu_s * f_n;
        let slip = if can_stick && self.sticking {
            None
        } else {
            self.outer_slip_root(dv_stick.abs(), two_z, f_n)
        };
        match slip {
            Some(u) => {
                self.sticking = false;
                dv_stick.signum() * f_n * self.mu(u)
            }
            None => {
                // Without a sliding crossing the sticking one exists (the quadratic's
                // constant term is then non-negative).
                self.sticking = true;
                f_stick
            }
        }
    }

    fn is_sticking(&self) -> bool {
        self.sticking
    }

    fn reset(&mut self) {
        self.sticking = false;
    }
}

/// The friction laws the instrument can switch between.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrictionModel {
    /// Static hyperbolic curve (the foundation's default).
    Hyperbolic,
    /// Static Stribeck curve (the bristle models' limit).
    Stribeck,
    LuGre,
    ElastoPlastic,
}

impl FrictionModel {
    pub const ALL: [FrictionModel; 4] = [
        FrictionModel::Hyperbolic,
        FrictionModel::Stribeck,
        FrictionModel::LuGre,
        FrictionModel::ElastoPlastic,
    ];

    /// Its place in [`Self::ALL`] (the intonation table's row, with paper B's thermal bow
    /// after the point laws: [`crate::dsp::intonation::TunedModel`]).
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Command-line and preset name.
    pub fn name(self) -> &'static str {
        match self {
            FrictionModel::Hyperbolic => "hyperbolic",
            FrictionModel::Stribeck => "static",
            FrictionModel::LuGre => "lugre",
            FrictionModel::ElastoPlastic => "elasto-plastic",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// One contact of each kind, with the active one chosen at run time. Switching hands the
/// last force and stick state over so the force does not jump (no click).
#[derive(Debug, Clone)]
pub struct AnyFriction {
    model: FrictionModel,
    hyperbolic: HyperbolicFriction,
    stribeck: StribeckFriction,
    bristle: BristleFriction,
    last_force_n: f64,
}

impl AnyFriction {
    pub fn new(
        model: FrictionModel,
        bristle: BristleParams,
        sample_rate_hz: f64,
    ) -> Result<Self, String> {
        let law = if model == FrictionModel::LuGre {
            BristleLaw::LuGre
        } else {
            BristleLaw::ElastoPlastic
        };
        Ok(Self {
            model,
            hyperbolic: HyperbolicFriction::default(),
            stribeck: StribeckFriction::default(),
            bristle: BristleFriction::new(bristle, law, sample_rate_hz)?,
            last_force_n: 0.0,
        })
    }

    pub fn model(&self) -> FrictionModel {
        self.model
    }

    pub fn bristle(&self) -> &BristleFriction {
        &self.bristle
    }

    pub fn bristle_mut(&mut self) -> &mut BristleFriction {
        &mut self.bristle
    }

    /// The friction force this law tends to as the sliding speed grows, N, under
    /// `normal_force_n`: `mu_d F_N` for the static curves (hyperbolic, Stribeck), which
    /// fall toward it from above; unbounded for the bristle laws with viscous friction
    /// (`sigma2 > 0`, steady force `h(v) + sigma2 v`), `mu_d F_N` without. A body pushed
    /// with more than this against the contact runs away.
    pub fn high_speed_friction_n(&self, normal_force_n: f64) -> f64 {
        let f_n = normal_force_n.max(0.0);
        match self.model {
            FrictionModel::Hyperbolic => self.hyperbolic.mu_d * f_n,
            FrictionModel::Stribeck => self.stribeck.mu_d * f_n,
            FrictionModel::LuGre | FrictionModel::ElastoPlastic => {
                let p = self.bristle.params();
                if p.sigma2_kg_per_s > 0.0 && f_n > 0.0 {
                    f64::INFINITY
                } else {
                    p.mu_d * f_n
                }
            }
        }
    }

    /// Runs the contact at `sample_rate_hz` from now on (the bristle laws' time step; the
    /// static curves have none). Real-time safe; the state is reset.
    pub fn set_sample_rate(&mut self, sample_rate_hz: f64) {
        self.bristle.set_sample_rate(sample_rate_hz);
        self.reset();
    }

    /// Switches the law, handing over the current force and stick state.
    pub fn set_model(&mut self, model: FrictionModel) {
        if model == self.model {
            return;
        }
        let sticking = self.is_sticking();
        match model {
            FrictionModel::Hyperbolic => self.hyperbolic.set_sticking(sticking),
            FrictionModel::Stribeck => self.stribeck.set_sticking(sticking),
            FrictionModel::LuGre | FrictionModel::ElastoPlastic => {
                let law = if model == FrictionModel::LuGre {
                    BristleLaw::LuGre
                } else {
                    BristleLaw::ElastoPlastic
                };
                if !matches!(
                    self.model,
                    FrictionModel::LuGre | FrictionModel::ElastoPlastic
                ) {
                    self.bristle.take_over(self.last_force_n);
                }
                self.bristle.set_law(law);
            }
        }
        self.model = model;
    }
}

impl AnyFriction {
    /// The hyperbolic law's coefficients (the static and sliding friction and the
    /// velocity of the fall between them), used while the model is
    /// [`FrictionModel::Hyperbolic`].
    pub fn set_hyperbolic_coefficients(&mut self, mu_s: f64, mu_d: f64, v0_m_per_s: f64) {
        self.hyperbolic.mu_s = mu_s;
        self.hyperbolic.mu_d = mu_d;
        self.hyperbolic.v0_m_per_s = v0_m_per_s;
    }
}

/// [`KnownLaw`]'s laws: which of [`AnyFriction`]'s contacts it solves with.
pub mod law {
    pub const HYPERBOLIC: u8 = 0;
    pub const STRIBECK: u8 = 1;
    /// LuGre or elasto-plastic: the bristle contact.
    pub const BRISTLE: u8 = 2;
    /// Whichever the contact's model says, asked each sample.
    pub const ANY: u8 = 3;
    /// The bits that name the law; a caller may use the others for its own flags.
    pub const MASK: u8 = 3;
}

/// An [`AnyFriction`] whose law is known where the code is compiled (`LAW`, one of
/// [`law`]'s, under [`law::MASK`]): the same solve, without asking the model each
/// sample, for a block in which the law does not change.
pub struct KnownLaw<'a, const LAW: u8>(pub &'a mut AnyFriction);

impl AnyFriction {
    /// The [`law`] that solves this contact.
    pub fn law(&self) -> u8 {
        match self.model {
            FrictionModel::Hyperbolic => law::HYPERBOLIC,
            FrictionModel::Stribeck => law::STRIBECK,
            FrictionModel::LuGre | FrictionModel::ElastoPlastic => law::BRISTLE,
        }
    }
}

impl<const LAW: u8> FrictionContact for KnownLaw<'_, LAW> {
    #[inline(always)]
    fn solve(&mut self, load: LoadLine, bow: BowInput) -> f64 {
        let contact = &mut *self.0;
        let f = match LAW & law::MASK {
            law::HYPERBOLIC => contact.hyperbolic.solve(load, bow),
            law::STRIBECK => contact.stribeck.solve(load, bow),
            law::BRISTLE => contact.bristle.solve(load, bow),
            _ => return contact.solve(load, bow),
        };
        debug_assert_eq!(
            contact.law(),
            LAW & law::MASK,
            "the block's law is its contacts'"
        );
        contact.last_force_n = f;
        f
    }

    fn is_sticking(&self) -> bool {
        self.0.is_sticking()
    }

    fn reset(&mut self) {
        self.0.reset();
    }
}

impl FrictionContact for AnyFriction {
    #[inline(always)]
    fn solve(&mut self, load: LoadLine, bow: BowInput) -> f64 {
        let f = match self.model {
            FrictionModel::Hyperbolic => self.hyperbolic.solve(load, bow),
            FrictionModel::Stribeck => self.stribeck.solve(load, bow),
            FrictionModel::LuGre | FrictionModel::ElastoPlastic => self.bristle.solve(load, bow),
        };
        self.last_force_n = f;
        f
    }

    fn is_sticking(&self) -> bool {
        match self.model {
            FrictionModel::Hyperbolic => self.hyperbolic.is_sticking(),
            FrictionModel::Stribeck => self.stribeck.is_sticking(),
            FrictionModel::LuGre | FrictionModel::ElastoPlastic => self.bristle.is_sticking(),
        }
    }

    fn reset(&mut self) {
        self.hyperbolic.reset();
        self.stribeck.reset();
        self.bristle.reset();
        self.last_force_n = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOAD_Y: f64 = 1.0 / (2.0 * 0.506); // cello D, two half-strings

    fn residual(c: &HyperbolicFriction, load: LoadLine, bow: BowInput, f: f64) -> f64 {
        let v_s = load.free_velocity_m_per_s + load.admittance_s_per_kg * f;
        let dv = bow.velocity_m_per_s - v_s;
        f - dv.signum() * bow.normal_force_n * c.mu(dv.abs())
    }

    #[test]
    fn slipping_force_lies_on_the_friction_curve() {
        let mut c = HyperbolicFriction::default();
        // |v_b - v_h| >= 0.6 m/s: the sticking force 2 Z0 |dv| exceeds mu_s F_N = 0.44 N.
        for &v_h in &[-1.0, -0.5, 0.7, 1.2] {
            let load = LoadLine {
                free_velocity_m_per_s: v_h,
                admittance_s_per_kg: LOAD_Y,
            };
            let bow = BowInput {
                velocity_m_per_s: 0.1,
                normal_force_n: 1.1,
            };
            let f = c.solve(load, bow);
            assert!(!c.is_sticking());
            // exact quadratic root: residual at rounding level
            assert!(residual(&c, load, bow, f).abs() < 1e-12, "v_h = {v_h}");
        }
    }

    #[test]
    fn sticking_force_stays_within_static_limit_and_moves_string_with_bow() {
        let mut c = HyperbolicFriction::default();
        c.sticking = true;
        let load = LoadLine {
            free_velocity_m_per_s: 0.05,
            admittance_s_per_kg: LOAD_Y,
        };
        let bow = BowInput {
            velocity_m_per_s: 0.1,
            normal_force_n: 1.1,
        };
        let f = c.solve(load, bow);
        assert!(c.is_sticking());
        assert!(f.abs() <= 0.4 * 1.1);
        // Sticking solves v_s = v_b: f64 rounding at 0.1 m/s (an ulp is 1.4e-17).
        assert!((0.05 + LOAD_Y * f - 0.1).abs() < 1e-15);
    }

    #[test]
    fn hysteresis_keeps_state_where_the_load_line_crosses_three_times() {
        // Steep curve (F_N mu_s-mu_d / v0 = 10 N s/m > 2 Z0): at this stick velocity both a
        // stick crossing and two slip crossings exist.
        let load = |v_h| LoadLine {
            free_velocity_m_per_s: v_h,
            admittance_s_per_kg: LOAD_Y,
        };
        let bow = BowInput {
            velocity_m_per_s: 0.1,
            normal_force_n: 5.0,
        };
        let mut c = HyperbolicFriction::default();
        // |dv_stick| = 1.9 m/s: sticking needs 2 Z0 1.9 = 1.92 N <= mu_s F_N = 2 N.
        let probe = load(-1.8);
        assert!(c.outer_slip_root(1.9, 2.0 * 0.506, 5.0).is_some());
        assert!(
            (2.0 * 0.506 * 1.9) <= 0.4 * 5.0,
            "stick crossing exists too"
        );
        c.sticking = true;
        c.solve(probe, bow);
        assert!(c.is_sticking(), "a sticking contact stays stuck");
        c.sticking = false;
        c.solve(probe, bow);
        assert!(!c.is_sticking(), "a slipping contact keeps slipping");
    }

    #[test]
    fn lifted_bow_exerts_no_force() {
        let mut c = HyperbolicFriction::default();
        let load = LoadLine {
            free_velocity_m_per_s: 0.3,
            admittance_s_per_kg: LOAD_Y,
        };
        assert_eq!(
            c.solve(
                load,
                BowInput {
                    velocity_m_per_s: 0.1,
                    normal_force_n: 0.0
                }
            ),
            0.0
        );
    }
}
