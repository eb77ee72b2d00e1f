//! bevy_ignis
