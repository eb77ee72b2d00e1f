//! Undo/redo of effect edits, grouped so that one gesture (a slider drag, a typed value)
//! is one step.

use crate::effect::Effect;

/// How many undo steps are kept.
const MAX_UNDO_STEPS: usize = 256;

/// Snapshots of the effect before each committed edit.
///
/// The editor calls [`UndoHistory::observe`] once per frame. While the user is in the
/// middle of a gesture (a pointer button is down, or a text field has focus) nothing is
/// recorded; once the gesture ends and the effect differs from the last snapshot, the
/// snapshot becomes an undo step. A whole slider drag is therefore one step.
#[derive(Clone, Debug)]
pub struct UndoHistory {
    undo: Vec<Effect>,
    redo: Vec<Effect>,
    /// The effect as of the last committed step.
    baseline: Effect,
}

impl UndoHistory {
    /// Starts a history whose first state is `effect`.
    pub fn new(effect: &Effect) -> Self {
        Self {
            undo: Vec::new(),
            redo: Vec::new(),
            baseline: effect.clone(),
        }
    }

    /// Records an undo step if `current` changed since the last one and no gesture is in
    /// progress (`is_interacting` is false). Returns true when a step was recorded.
    pub fn observe(&mut self, current: &Effect, is_interacting: bool) -> bool {
        if is_interacting || *current == self.baseline {
            return false;
        }
        self.commit(current);
        true
    }

    fn commit(&mut self, current: &Effect) {
        let previous = std::mem::replace(&mut self.baseline, current.clone());
        self.undo.push(previous);
        if self.undo.len() > MAX_UNDO_STEPS {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// Restores the state before the last step (an edit still in progress counts as a
    /// step). Returns false when there is nothing to undo.
    pub fn undo(&mut self, current: &mut Effect) -> bool {
        if *current != self.baseline {
            self.commit(current);
        }
        let Some(previous) = self.undo.pop() else {
            return false;
        };
        self.redo
            .push(std::mem::replace(&mut self.baseline, previous));
        current.clone_from(&self.baseline);
        true
    }

    /// Re-applies the last undone step. Returns false when there is nothing to redo (a
    /// new edit clears the redo steps).
    pub fn redo(&mut self, current: &mut Effect) -> bool {
        if *current != self.baseline {
            // An uncommitted edit invalidates the redo branch.
            self.commit(current);
            return false;
        }
        let Some(next) = self.redo.pop() else {
            return false;
        };
        self.undo.push(std::mem::replace(&mut self.baseline, next));
        current.clone_from(&self.baseline);
        true
    }

    /// Number of steps that can be undone.
    pub fn undo_len(&self) -> usize {
        self.undo.len()
    }

    /// Number of steps that can be redone.
    pub fn redo_len(&self) -> usize {
        self.redo.len()
    }

    /// Forgets every step; `effect` becomes the new starting point.
    pub fn reset(&mut self, effect: &Effect) {
        *self = Self::new(effect);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The history keeps the last `MAX_UNDO_STEPS` steps, the oldest dropped first, and
    /// `reset` forgets every step.
    #[test]
    fn the_history_keeps_the_last_steps_and_reset_forgets_them() {
        let mut effect = Effect::default_campfire();
        let mut history = UndoHistory::new(&effect);
        for k in 0..MAX_UNDO_STEPS + 10 {
            effect.seed = 1000 + k as u32;
            assert!(history.observe(&effect, false));
            assert_eq!(history.undo_len(), (k + 1).min(MAX_UNDO_STEPS));
        }
        let mut undone = 0;
        while history.undo(&mut effect) {
            undone += 1;
        }
        assert_eq!(undone, MAX_UNDO_STEPS);
        assert_eq!(effect.seed, 1009, "the ten oldest steps were dropped");
        assert_eq!(history.redo_len(), MAX_UNDO_STEPS);
        history.reset(&effect);
        assert_eq!((history.undo_len(), history.redo_len()), (0, 0));
    }

    #[test]
    fn one_gesture_is_one_step() {
        let mut effect = Effect::default_campfire();
        let original = effect.clone();
        let mut history = UndoHistory::new(&effect);
        for k in 0..10 {
            effect.seed = 100 + k;
            assert!(!history.observe(&effect, true));
        }
        assert!(history.observe(&effect, false));
        assert_eq!(history.undo_len(), 1);
        assert!(history.undo(&mut effect));
        assert_eq!(effect, original);
        assert!(history.redo(&mut effect));
        assert_eq!(effect.seed, 109);
        assert!(!history.redo(&mut effect));
    }

    #[test]
    fn a_new_edit_clears_redo() {
        let mut effect = Effect::default_campfire();
        let mut history = UndoHistory::new(&effect);
        effect.seed = 5;
        history.observe(&effect, false);
        history.undo(&mut effect);
        assert_eq!(history.redo_len(), 1);
        effect.seed = 6;
        history.observe(&effect, false);
        assert_eq!(history.redo_len(), 0);
        assert_eq!(history.undo_len(), 1);
    }
}
