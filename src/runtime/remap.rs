//! Following structural edits of the emitter list (add, duplicate, remove, reorder, undo
//! of those) on the GPU, so the particles of every surviving emitter keep burning.

use crate::effect::Effect;

/// For each emitter of `new`, the index of the emitter of `old` whose pool it should take
/// over (`None`: a fresh pool). Returns `None` when the list kept its structure (every
/// emitter stays where it was), so no remapping is needed.
///
/// Emitters are matched by name first (names are unique in a valid effect), then a
/// renamed emitter keeps the pool at its own index when that pool is otherwise unclaimed.
pub fn emitter_sources(old: &Effect, new: &Effect) -> Option<Vec<Option<usize>>> {
    let mut claimed = vec![false; old.emitters.len()];
    let mut sources: Vec<Option<usize>> = new
        .emitters
        .iter()
        .map(|e| {
            let found = old.emitters.iter().position(|o| o.name == e.name);
            if let Some(i) = found {
                if claimed[i] {
                    return None;
                }
                claimed[i] = true;
            }
            found
        })
        .collect();
    for (i, source) in sources.iter_mut().enumerate() {
        if source.is_none() && i < old.emitters.len() && !claimed[i] {
            let old_name_survives = new.emitters.iter().any(|e| e.name == old.emitters[i].name);
            if !old_name_survives {
                claimed[i] = true;
                *source = Some(i);
            }
        }
    }
    let identity = sources.len() == old.emitters.len()
        && sources.iter().enumerate().all(|(i, s)| *s == Some(i));
    (!identity).then_some(sources)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(effect: &mut Effect, names: &[&str]) {
        let template = effect.emitters[0].clone();
        effect.emitters = names
            .iter()
            .map(|n| {
                let mut e = template.clone();
                e.name = (*n).to_owned();
                e
            })
            .collect();
    }

    #[test]
    fn unchanged_and_renamed_lists_need_no_remap() {
        let old = Effect::default_campfire();
        assert_eq!(emitter_sources(&old, &old), None);
        let mut renamed = old.clone();
        renamed.emitters[1].name = "fire".into();
        assert_eq!(emitter_sources(&old, &renamed), None);
    }

    #[test]
    fn reorder_remove_and_insert_follow_the_names() {
        let mut old = Effect::default_campfire();
        names(&mut old, &["a", "b", "c"]);
        let mut new = old.clone();
        names(&mut new, &["b", "a", "c"]);
        assert_eq!(
            emitter_sources(&old, &new),
            Some(vec![Some(1), Some(0), Some(2)])
        );
        names(&mut new, &["a", "c"]);
        assert_eq!(emitter_sources(&old, &new), Some(vec![Some(0), Some(2)]));
        names(&mut new, &["a", "a copy", "b", "c"]);
        assert_eq!(
            emitter_sources(&old, &new),
            Some(vec![Some(0), None, Some(1), Some(2)])
        );
        names(&mut new, &["a", "b", "c", "d"]);
        assert_eq!(
            emitter_sources(&old, &new),
            Some(vec![Some(0), Some(1), Some(2), None])
        );
    }
}
