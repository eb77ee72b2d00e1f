//! `--edit-around-loss` (with `--lose-device-at N`, a recovery test): two edits before the
//! device is lost and an undo after it is recreated, as a user's would be — each edit an
//! undo step — and what the run ended with, for the report: the undo history and the
//! edited value in the panel and in the player.

use crate::effect::Effect;

use crate::editor::state::EditorState;

/// The emitter whose intensity is edited.
const EMITTER: &str = "flames";
/// The intensities the two edits set (frames N − 6 and N − 3); the undo (frame N + 10)
/// goes back to the first.
const EDITS: [f32; 2] = [0.3, 0.6];

/// Makes this frame's scripted edit, if any: before the UI runs, so that the frame's end
/// records it as an undo step (or applies the undo).
pub(crate) fn apply(state: &mut EditorState, frame: u64, lose_at: u32) {
    let at = |offset: i64| frame as i64 == i64::from(lose_at) + offset;
    let value = if at(-6) {
        EDITS[0]
    } else if at(-3) {
        EDITS[1]
    } else {
        if at(10) {
            state.undo();
        }
        return;
    };
    if let Some(e) = state.effect.emitters.iter_mut().find(|e| e.name == EMITTER) {
        e.look.intensity = value;
    }
}

/// What the run ended with: the undo steps left, and the edited intensity in the panel's
/// effect and in the one the player plays.
pub(crate) fn summary(state: &EditorState, playing: &Effect) -> String {
    let intensity = |e: &Effect| {
        e.emitters
            .iter()
            .find(|e| e.name == EMITTER)
            .map_or(f32::NAN, |e| e.look.intensity)
    };
    format!(
        "edits around the loss: {} undo step(s) left, {EMITTER} intensity {} in the panel, {} \
            playing",
        state.history.undo_len(),
        intensity(&state.effect),
        intensity(playing)
    )
}
