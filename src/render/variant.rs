//! Pipeline variants of the draw paths: which look modules an emitter's pipelines compile
//! in ([`LookVariant`]) and how they read its state ([`StateVariant`]), as override
//! constants.

use crate::effect::{BlendMode, Look};
use crate::gpu::types::StateLayout;

/// How look.wgsl reads an emitter's state: its layout and whether positions are closed
/// form (stateless). Pipeline constants of both draw paths, not branches: a CPU adapter
/// would run every layout's code for every particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct StateVariant {
    /// The state layout (how a slot is stored).
    pub layout: StateLayout,
    /// Closed-form (stateless) positions.
    pub stateless: bool,
}

impl StateVariant {
    /// The override constants `STATE_LAYOUT` and `STATELESS`.
    pub fn constants(self) -> [(&'static str, f64); 2] {
        [
            ("STATE_LAYOUT", f64::from(self.layout.index())),
            ("STATELESS", if self.stateless { 1.0 } else { 0.0 }),
        ]
    }
}

/// Which billboard pipeline variant draws an emitter: the look modules it uses (each is
/// compiled out of the others).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LookVariant {
    /// Premultiplied alpha, drawn through the sort order (else additive).
    pub alpha: bool,
    /// Flipbook atlas lookup.
    pub flipbook: bool,
    /// Cross-fade between flipbook frames.
    pub flip_blend: bool,
    /// Velocity-stretched quads.
    pub streak: bool,
    /// Ground-plane depth fade.
    pub soft: bool,
    /// Fade against the host's depth buffer (replaces the ground-plane fade).
    pub soft_depth: bool,
    /// The motion pass: screen-space motion weighted by visibility, added up.
    pub motion: bool,
    /// The trail's ribbon (segments between recorded positions) instead of the sprite.
    pub trail: bool,
    /// How the shaders read the emitter's state (both draw paths).
    pub state: StateVariant,
    /// Lit smoke: six-way maps under the slot's `LitUniform` (`lit.wgsl`).
    pub lit: bool,
    /// Heat haze: drawn only into the distortion target, as summed screen offsets.
    pub haze: bool,
    /// Billboards cut to an octagon (eight vertices) instead of a rectangle: for sprites
    /// that leave their rectangle's corners empty (`sprite_trim.rs`).
    pub octagon: bool,
}

impl LookVariant {
    /// The variant a look needs, for state read as `state`.
    pub fn of(look: &Look, state: StateVariant) -> Self {
        Self {
            alpha: look.blend == BlendMode::Alpha,
            flipbook: look.flipbook.is_some(),
            flip_blend: look.flipbook.as_ref().is_some_and(|f| f.blend_frames),
            streak: look.streak.is_some(),
            soft: look.soft_ground_m > 0.0,
            soft_depth: false,
            motion: false,
            trail: false,
            state,
            lit: look.lit.is_some() && look.blend == BlendMode::Alpha,
            haze: look.heat_haze.is_some(),
            octagon: false,
        }
    }

    /// The ribbon variant of this look (no flipbook, no streak: a ribbon samples the
    /// sprite's middle column across its width).
    pub fn with_trail(self) -> Self {
        Self {
            trail: true,
            flipbook: false,
            flip_blend: false,
            streak: false,
            lit: false,
            octagon: false,
            ..self
        }
    }

    /// This variant's motion pass.
    pub fn with_motion(self) -> Self {
        Self {
            motion: true,
            ..self
        }
    }

    /// The plain variant of a blend mode (full state, no look modules).
    pub fn basic(alpha: bool) -> Self {
        Self {
            alpha,
            flipbook: false,
            flip_blend: false,
            streak: false,
            soft: false,
            soft_depth: false,
            motion: false,
            trail: false,
            state: StateVariant::default(),
            lit: false,
            haze: false,
            octagon: false,
        }
    }

    /// The override constants of this variant's billboard pipeline.
    pub fn constants(self) -> [(&'static str, f64); 13] {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let [layout, stateless] = self.state.constants();
        [
            ("SORTED", b(self.alpha)),
            ("FLIPBOOK", b(self.flipbook)),
            ("FLIP_BLEND", b(self.flip_blend)),
            ("STREAK", b(self.streak)),
            ("SOFT", b(self.soft && !self.soft_depth)),
            ("SOFT_DEPTH", b(self.soft && self.soft_depth)),
            ("MOTION", b(self.motion)),
            ("TRAIL", b(self.trail)),
            ("LIT", b(self.lit)),
            ("HAZE", b(self.haze)),
            ("OCTAGON", b(self.octagon)),
            layout,
            stateless,
        ]
    }
}

/// The pipeline constants of look variant `v` for the compute draw paths (tiles.wgsl,
/// splat.wgsl: sprites only — no motion pass, ribbons or haze), with the host depth test
/// of `target`.
pub(crate) fn compute_constants(
    v: LookVariant,
    target: crate::render::billboard::DrawTarget,
) -> Vec<(&'static str, f64)> {
    let mut constants: Vec<(&str, f64)> = v
        .constants()
        .into_iter()
        .filter(|(name, _)| !["MOTION", "TRAIL", "HAZE", "OCTAGON"].contains(name))
        .collect();
    constants.push(("DEPTH_TEST", crate::render::depth_test(target)));
    constants
}
