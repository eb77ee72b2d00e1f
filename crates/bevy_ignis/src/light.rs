//! The fire lights the scene: an effect entity with [`IgnisLight`] gets a `PointLight`
//! child that follows its effect's light (`ignis::EffectLight`: where the emissive
//! particles are, their colour and power, estimated on the GPU from the particles alive
//! and read back a couple of frames later), so it flickers as the flames do.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use bevy::prelude::*;

/// Lights the scene with the entity's effect: a `PointLight` child placed, coloured and
/// dimmed each frame by the effect's own light.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct IgnisLight {
    /// Bevy lumens per unit of the effect's light power (HDR colour × m² of emitting
    /// sprite): the campfire gives about 0.33 units, 65,000 lm at the default.
    pub lumens_per_unit: f32,
    /// The point light's range, metres.
    pub range_m: f32,
    /// Whether the light casts shadows.
    pub shadows: bool,
}

impl Default for IgnisLight {
    fn default() -> Self {
        Self {
            lumens_per_unit: 200_000.0,
            range_m: 12.0,
            shadows: false,
        }
    }
}

/// The light child of an effect entity.
#[derive(Component, Clone, Copy, Debug)]
pub struct IgnisLightOf(pub Entity);

/// The effects' lights as the render world last read them, by main-world entity (shared
/// by both worlds).
#[derive(Resource, Clone, Default)]
pub struct EffectLights(pub Arc<Mutex<HashMap<Entity, ignis::EffectLight>>>);

/// Main world: makes, moves and sets every [`IgnisLight`]'s point light; removes those of
/// entities that lost it.
pub fn update_lights(
    mut commands: Commands,
    lights: Res<EffectLights>,
    effects: Query<(Entity, &IgnisLight, &GlobalTransform, Option<&Children>)>,
    mut children: Query<(&IgnisLightOf, &mut PointLight, &mut Transform)>,
    orphans: Query<(Entity, &IgnisLightOf)>,
) {
    let Ok(latest) = lights.0.lock().map(|l| l.clone()) else {
        return;
    };
    for (entity, settings, global, kids) in &effects {
        let child = kids.and_then(|k| k.iter().find(|c| children.contains(*c)));
        let Some(light) = latest.get(&entity) else {
            continue;
        };
        let local = global
            .affine()
            .inverse()
            .transform_point3(Vec3::from_array(light.position.to_array()));
        let [r, g, b] = light.color;
        let point = PointLight {
            color: Color::linear_rgb(r, g, b),
            intensity: light.power * settings.lumens_per_unit,
            range: settings.range_m,
            radius: light.radius_m.min(1.0),
            shadow_maps_enabled: settings.shadows,
            ..default()
        };
        match child.and_then(|c| children.get_mut(c).ok()) {
            Some((_, mut p, mut t)) => {
                *p = point;
                t.translation = local;
            }
            None => {
                commands.spawn((
                    point,
                    Transform::from_translation(local),
                    IgnisLightOf(entity),
                    ChildOf(entity),
                ));
            }
        }
    }
    for (light, of) in &orphans {
        if !effects.contains(of.0) {
            commands.entity(light).despawn();
        }
    }
}
