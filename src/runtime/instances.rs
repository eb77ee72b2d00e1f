//! A player's instances: a slab of simulations with generation-checked handles, and the
//! per-instance copy of the effect (its seed and its emitters placed in the world).

use glam::{EulerRot, Mat4};

use crate::effect::Effect;
use crate::sim::GpuSim;

/// A handle to one instance of a [`crate::Player`]'s effect. It stays valid until the
/// instance is removed; a handle of a removed instance is refused, never aliased to a
/// later one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct InstanceId {
    index: u32,
    generation: u32,
}

/// Where an instance's particles live.
pub(crate) enum Backing {
    /// A segment of a batch of the player's (`batch` index, `slot` in it).
    Batched { batch: usize, slot: u32 },
    /// A simulation of its own (effects with tiny-state or stateless emitters).
    Own(Box<GpuSim>),
}

/// One instance: its own state, seed and placement.
pub(crate) struct Instance {
    /// The particles.
    pub state: Backing,
    /// The effect with this instance's seed and its emitters' world transforms.
    effect: Effect,
    /// Changes whenever `effect` does (the planner rebuilds its cached parameter blocks).
    revision: u64,
    /// Where the effect's origin is in the world.
    pub world_from_effect: Mat4,
}

impl Instance {
    /// An instance of `effect` (already placed) backed by `state`.
    pub fn new(state: Backing, effect: Effect, world_from_effect: Mat4) -> Self {
        Self {
            state,
            effect,
            revision: crate::sim::gpu_sim::next_generation(),
            world_from_effect,
        }
    }

    /// The effect with this instance's seed and place.
    pub fn effect(&self) -> &Effect {
        &self.effect
    }

    /// The effect, to change (a new revision).
    pub fn effect_mut(&mut self) -> &mut Effect {
        self.revision = crate::sim::gpu_sim::next_generation();
        &mut self.effect
    }

    /// The state, to change, and the effect.
    pub fn state_mut(&mut self) -> (&mut Backing, &Effect) {
        (&mut self.state, &self.effect)
    }

    /// The state and the effect, to change (a new revision).
    pub fn parts_mut(&mut self) -> (&mut Backing, &mut Effect) {
        self.revision = crate::sim::gpu_sim::next_generation();
        (&mut self.state, &mut self.effect)
    }

    /// The effect and its revision, a value that changes whenever the effect does.
    pub fn revised_effect(&self) -> (&Effect, u64) {
        (&self.effect, self.revision)
    }

    /// `template` placed by `world_from_effect`, with `seed`.
    pub fn effect_for(template: &Effect, world_from_effect: Mat4, seed: u32) -> Effect {
        let mut effect = template.clone();
        effect.seed = seed;
        place(&mut effect, template, world_from_effect);
        effect
    }

    /// Moves this instance: new particles spawn at the new place; living ones keep their
    /// world-space motion.
    pub fn set_transform(&mut self, template: &Effect, world_from_effect: Mat4) {
        self.world_from_effect = world_from_effect;
        place(self.effect_mut(), template, world_from_effect);
    }
}

/// Sets `effect`'s emitter transforms to `template`'s composed with `world_from_effect`
/// (rotation and translation; a scale is ignored — sizes are the preset's).
fn place(effect: &mut Effect, template: &Effect, world_from_effect: Mat4) {
    let (_, rotation, translation) = world_from_effect.to_scale_rotation_translation();
    let outer = Mat4::from_rotation_translation(rotation.normalize(), translation);
    for (e, t) in effect.emitters.iter_mut().zip(&template.emitters) {
        let world = outer * t.transform.world_from_emitter();
        let (_, r, p) = world.to_scale_rotation_translation();
        let (z, y, x) = r.to_euler(EulerRot::ZYX);
        e.transform.position_m = p.into();
        e.transform.rotation_deg = [x, y, z].map(f32::to_degrees);
    }
}

/// Items (a player's instances) in slots that are reused after removal; each slot's
/// generation tells a handle of its earlier occupant from one of the current.
pub(crate) struct Slab<T> {
    slots: Vec<(u32, Option<T>)>,
    free: Vec<u32>,
}

impl<T> Default for Slab<T> {
    fn default() -> Self {
        Self {
            slots: Vec::new(),
            free: Vec::new(),
        }
    }
}

impl<T> Slab<T> {
    /// Stores `item` and returns its handle.
    pub fn insert(&mut self, item: T) -> InstanceId {
        if let Some(index) = self.free.pop() {
            let slot = &mut self.slots[index as usize];
            slot.0 = slot.0.wrapping_add(1);
            slot.1 = Some(item);
            return InstanceId {
                index,
                generation: slot.0,
            };
        }
        self.slots.push((0, Some(item)));
        InstanceId {
            index: (self.slots.len() - 1) as u32,
            generation: 0,
        }
    }

    /// Takes the item `id` names out, if it is still there.
    pub fn remove(&mut self, id: InstanceId) -> Option<T> {
        let slot = self.slots.get_mut(id.index as usize)?;
        if slot.0 != id.generation {
            return None;
        }
        let item = slot.1.take()?;
        self.free.push(id.index);
        Some(item)
    }

    /// The item `id` names.
    pub fn get(&self, id: InstanceId) -> Option<&T> {
        let slot = self.slots.get(id.index as usize)?;
        (slot.0 == id.generation)
            .then_some(slot.1.as_ref())
            .flatten()
    }

    /// The item `id` names, mutably.
    pub fn get_mut(&mut self, id: InstanceId) -> Option<&mut T> {
        let slot = self.slots.get_mut(id.index as usize)?;
        (slot.0 == id.generation)
            .then_some(slot.1.as_mut())
            .flatten()
    }

    /// Every item, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        self.slots.iter().filter_map(|(_, i)| i.as_ref())
    }

    /// Every item with its handle, in slot order.
    pub fn iter_with_ids(&self) -> impl Iterator<Item = (InstanceId, &T)> {
        self.slots
            .iter()
            .enumerate()
            .filter_map(|(index, (generation, i))| {
                let id = InstanceId {
                    index: index as u32,
                    generation: *generation,
                };
                i.as_ref().map(|i| (id, i))
            })
    }

    /// Every item, mutably.
    pub fn iter_mut(&mut self) -> impl Iterator<Item = &mut T> {
        self.slots.iter_mut().filter_map(|(_, i)| i.as_mut())
    }

    /// How many items there are.
    pub fn len(&self) -> usize {
        self.slots.len() - self.free.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placing_composes_the_instance_with_each_emitter() {
        let template = Effect::default_campfire();
        let world = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            glam::vec3(10.0, 0.0, -2.0),
        );
        let placed = Instance::effect_for(&template, world, 42);
        assert_eq!(placed.seed, 42);
        for (p, t) in placed.emitters.iter().zip(&template.emitters) {
            let expected = world * t.transform.world_from_emitter();
            let got = p.transform.world_from_emitter();
            assert!(
                got.abs_diff_eq(expected, 1e-4),
                "{}: {got} vs {expected}",
                t.name
            );
        }
    }

    #[test]
    fn stale_handles_are_refused_and_slots_are_reused() {
        let mut slab = Slab::default();
        let a = slab.insert("a");
        let b = slab.insert("b");
        assert_eq!(slab.remove(a), Some("a"));
        assert_eq!(slab.remove(a), None, "removed twice");
        assert_eq!(slab.len(), 1, "a removed item is not counted");
        let c = slab.insert("c");
        assert_ne!(a, c, "the reused slot has a new generation");
        assert_eq!(
            slab.get(a),
            None,
            "a stale handle does not reach the new item"
        );
        assert_eq!(slab.get(c), Some(&"c"));
        assert_eq!(slab.get(b), Some(&"b"));
        assert_eq!(slab.len(), 2);
        assert_eq!(slab.iter().copied().collect::<Vec<_>>(), ["c", "b"]);
    }
}
