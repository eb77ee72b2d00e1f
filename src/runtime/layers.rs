//! [`Layers`]: which of a player's particles one draw call draws, so a host can send the
//! soft layers to reduced-resolution targets of its own.

use crate::effect::BlendMode;
use crate::render::DrawItem;

/// A set of particle layers. [`Player::draw`](crate::Player::draw) draws
/// [`Layers::ALL`]; [`Player::draw_layers`](crate::Player::draw_layers) draws a subset,
/// and [`Player::drawn_layers`](crate::Player::drawn_layers) says which hold anything.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Layers(u8);

impl Layers {
    /// Nothing.
    pub const NONE: Self = Self(0);
    /// Alpha-blended emitters (smoke), back to front. Soft: a host may draw them at a
    /// reduced resolution and add the result in its composite.
    pub const BLENDED: Self = Self(1);
    /// Additive emitters whose particles are small or thin on screen (sparks, embers,
    /// streaks, and the compute splat's light).
    pub const LIGHT: Self = Self(2);
    /// Additive emitters whose particles are large on screen (flame tongues, glow):
    /// soft enough for half resolution.
    pub const GLOW: Self = Self(4);
    /// Every layer.
    pub const ALL: Self = Self(7);

    /// Whether every layer of `other` is in `self`.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether `self` and `other` share a layer.
    pub fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }

    /// The layers of `self` that are not in `other`.
    pub fn without(self, other: Self) -> Self {
        Self(self.0 & !other.0)
    }

    /// The layer a billboard draw belongs to.
    pub(crate) fn of(item: &DrawItem) -> Self {
        match item.blend {
            BlendMode::Alpha => Self::BLENDED,
            BlendMode::Additive if item.is_glow() => Self::GLOW,
            BlendMode::Additive => Self::LIGHT,
        }
    }
}

/// Which of the compute draw paths' resolves a draw of the layers draws in its render
/// pass (the others are resolved by compute into the image).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Resolves {
    /// The tiles' shaded pixels.
    pub tiles: bool,
    /// The splat's light.
    pub splat: bool,
}

impl Resolves {
    /// Both drawn in the pass.
    pub const DRAWN: Self = Self {
        tiles: true,
        splat: true,
    };
}

impl std::ops::BitOr for Layers {
    type Output = Self;

    fn bitor(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

impl std::ops::BitOrAssign for Layers {
    fn bitor_assign(&mut self, other: Self) {
        self.0 |= other.0;
    }
}

impl super::Player {
    /// Tells the player which `layers` the host draws into targets of reduced resolution
    /// (with [`Player::draw_layers`](super::Player::draw_layers)), from the next
    /// [`record`](super::Player::record) on; none by default. The tile rasteriser resolves
    /// at the host's full size, so the alpha-blended emitters of a reduced
    /// [`Layers::BLENDED`] and the large additive emitters of a reduced [`Layers::GLOW`]
    /// are drawn by the billboards: at a quarter or a sixteenth of the pixels their fill is
    /// small, and the reduction is what the host asked for.
    pub fn set_reduced_layers(&mut self, layers: Layers) {
        self.frame.blended_reduced = layers.contains(Layers::BLENDED);
        self.frame.glow_reduced = layers.contains(Layers::GLOW);
    }
}

#[cfg(test)]
mod tests {
    use super::Layers;

    #[test]
    fn layer_sets_combine() {
        let soft = Layers::BLENDED | Layers::GLOW;
        assert!(Layers::ALL.contains(soft));
        assert!(!soft.contains(Layers::LIGHT));
        assert_eq!(Layers::ALL.without(soft), Layers::LIGHT);
        assert!(soft.intersects(Layers::GLOW));
        assert!(!Layers::NONE.intersects(Layers::ALL));
    }

    #[test]
    fn a_layer_added_twice_is_there_once() {
        assert_eq!(Layers::GLOW | Layers::GLOW, Layers::GLOW);
        assert_eq!(Layers::BLENDED | Layers::ALL, Layers::ALL);
        let mut drawn = Layers::NONE;
        drawn |= Layers::LIGHT;
        drawn |= Layers::LIGHT;
        assert_eq!(drawn, Layers::LIGHT);
        drawn |= Layers::GLOW;
        assert_eq!(drawn, Layers::LIGHT | Layers::GLOW);
    }
}
