//! What a frame draws: the simulations of a group of instances ([`Scene`]) and one
//! emitter of such a group with the path chosen for it ([`DrawItem`]).

use std::sync::Arc;

use crate::effect::{BlendMode, Effect};
use crate::render::sort::SortJob;
use crate::render::sprites::SpriteTexture;
use crate::sim::gpu_sim::SimState;

use super::variant::LookVariant;

/// One simulation to draw: its state and the effect it runs (one instance of a player).
#[derive(Clone, Copy)]
pub struct Scene<'a> {
    /// The particles.
    pub sim: &'a dyn SimState,
    /// The effect they follow (looks, forces for closed-form emitters).
    pub effect: &'a Effect,
}

/// Instances drawn together, one draw per emitter: their pools are segments of one set
/// of state buffers (a batch; `members[k]` owns segment k, `None` an empty segment), or
/// one instance's own buffers.
pub type SceneGroup<'a> = [Option<Scene<'a>>];

/// Looks one draw reads at most (a batch's instances).
pub const LOOKS_PER_DRAW: usize = crate::sim::batch::BATCH_SLOTS as usize;

/// One emitter of a group of instances to draw this frame.
#[derive(Clone, Debug)]
pub struct DrawItem {
    /// Emitter index in its effect (the colour ramp's row).
    pub index: usize,
    /// The look uniform slot of the group's first instance (the others follow).
    pub look_slot: usize,
    /// The group of instances it draws (its index in the frame; items of one group
    /// share their instances, member by member).
    pub group: usize,
    /// Instances (segments) the draw covers.
    pub members: u32,
    /// Key of the cached particle bind group.
    pub key: (u64, usize, bool),
    /// Slots of each instance's pool.
    pub capacity: u32,
    /// Quads per instance: the widest live window of the group.
    pub width: u32,
    /// The back-to-front sort of the group's slots (alpha-blended emitters).
    pub sort: Option<SortJob>,
    /// Blend mode.
    pub blend: BlendMode,
    /// The path chosen for this frame: the compute splat.
    pub splat: bool,
    /// The path chosen for this frame: the compute tile rasteriser (`tiles.rs`).
    pub tiles: bool,
    /// The billboard pipeline variant.
    pub variant: LookVariant,
    /// The sprite texture.
    pub sprite: Arc<SpriteTexture>,
    /// The particles' largest size on screen at the emitter's distance, pixels.
    pub size_px: f32,
    /// The trail's ribbon: segments per particle, and whether the sprite is drawn too.
    pub trail: Option<(u32, bool)>,
}

impl DrawItem {
    /// Whether the billboards draw it (neither the splat nor the tiles do).
    pub fn is_billboard(&self) -> bool {
        !self.splat && !self.tiles
    }

    /// The order of a frame's draws: alpha-blended layers first, as given (back to
    /// front), then the light by emitter (each emitter's instances share a pipeline and a
    /// sprite; light adds up in any order).
    pub fn draw_key(&self) -> (u8, usize) {
        match self.blend {
            BlendMode::Alpha => (0, 0),
            BlendMode::Additive => (1, self.index),
        }
    }

    /// A large additive billboard that a draft render draws at half resolution
    /// (streaks stay sharp: they are thin however long).
    pub fn is_glow(&self) -> bool {
        !self.splat && !self.tiles && glow_sized(self.blend, self.variant.streak, self.size_px)
    }
}

/// Whether particles of `blend`, streaked or not, up to `size_px` on screen are glow when
/// drawn as billboards: additive, not streaks (thin however long), at least
/// [`GLOW_MIN_PX`].
pub fn glow_sized(blend: BlendMode, streak: bool, size_px: f32) -> bool {
    blend == BlendMode::Additive && !streak && size_px >= GLOW_MIN_PX
}

/// Billboards at least this large on screen (pixels at full resolution) count as glow.
pub const GLOW_MIN_PX: f32 = 12.0;
