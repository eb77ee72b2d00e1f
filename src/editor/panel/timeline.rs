//! The timeline under the viewport: play/pause, step, restart, a step back, the playback
//! speed, a loop region, and a scrub bar over the effect's time with its bursts marked.
//! Dragging or clicking the bar seeks: the player replays to that time as fast as the GPU
//! goes (`Player::seek`: from the nearest earlier snapshot with fixed steps; a frame-delta
//! effect replays the frames played), so the state shown is exactly the one playing would
//! reach. While parked (paused after a seek), an edit re-simulates to the same time. The
//! frame loop applies the requests with [`play`], on the editor's player.

use egui::{Color32, Sense, Stroke, Ui, vec2};

use crate::effect::{Effect, TimeMode};
use crate::runtime::{InstanceId, Player};

use crate::editor::state::{EditorState, Playback};

/// The frame rate seeks replay at (the frame-delta mode's frame time).
pub const SEEK_FRAME_DT_SECS: f64 = 1.0 / 60.0;

/// The timeline's length: the last burst plus the longest lifetime (at least 1 s).
pub fn span_secs(effect: &Effect) -> f64 {
    (effect.last_burst_secs() + effect.longest_lifetime_secs()).max(1.0)
}

/// The frames of `played` (wall-clock durations) that end at or before simulated time `t`
/// (to within a microsecond), then 1/60 s frames up to `t`: what a frame-delta effect
/// replays to reach `t`. A frame's simulated time is its duration times the effect's
/// speed, clamped to its longest frame (as the player steps it).
pub fn frames_until(played: &[f64], t: f64, time: &crate::effect::TimeSettings) -> Vec<f64> {
    let sim = |d: f64| (d * f64::from(time.speed)).min(f64::from(time.max_frame_dt_secs));
    let mut out = Vec::new();
    let mut end = 0.0;
    for &d in played {
        if end + sim(d) > t + 1e-6 {
            break;
        }
        end += sim(d);
        out.push(d);
    }
    let dt = SEEK_FRAME_DT_SECS;
    if sim(dt) > 0.0 {
        while end + sim(dt) <= t + 1e-6 && out.len() < 10_000_000 {
            end += sim(dt);
            out.push(dt);
        }
    }
    out
}

/// One step of the effect's clock (a frame in frame-delta mode).
pub fn step_secs(effect: &Effect) -> f64 {
    match effect.time.mode {
        TimeMode::FixedStep => f64::from(effect.time.step_secs),
        TimeMode::FrameDelta => SEEK_FRAME_DT_SECS,
    }
}

/// Play/Pause, Step and Restart (the timeline's and the Time section's).
pub fn playback_buttons_ui(ui: &mut Ui, playback: &mut crate::editor::state::Playback) {
    let pause_text = if playback.is_paused { "Play" } else { "Pause" };
    if ui
        .button(pause_text)
        .on_hover_text("Pause or resume the simulation (Space)")
        .clicked()
    {
        playback.is_paused = !playback.is_paused;
    }
    if ui
        .button("Step")
        .on_hover_text("Run one step and pause (.)")
        .clicked()
    {
        playback.step_requested = true;
    }
    if ui
        .button("Restart")
        .on_hover_text("Kill every particle and restart time (R)")
        .clicked()
    {
        playback.restart_requested = true;
    }
}

/// The timeline strip.
pub fn timeline_ui(ui: &mut Ui, state: &mut EditorState) {
    let now = state.stats.sim_time_secs;
    let span = span_secs(&state.running).max(now);
    let step = step_secs(&state.running);
    let playback = &mut state.playback;
    ui.horizontal(|ui| {
        playback_buttons_ui(ui, playback);
        if ui
            .button("Step back")
            .on_hover_text("One step back (replayed from the start)")
            .clicked()
        {
            playback.seek_to = Some((now - step).max(0.0));
        }
        ui.add(
            egui::DragValue::new(&mut playback.speed)
                .range(0.1..=4.0)
                .speed(0.01)
                .fixed_decimals(2)
                .suffix("×"),
        )
        .on_hover_text("Playback speed (the viewer's; the effect's time settings stay)");
        let mut looping = playback.loop_region.is_some();
        if ui
            .checkbox(&mut looping, "Loop")
            .on_hover_text("Play a span of the effect's time over and over")
            .changed()
        {
            playback.loop_region = looping.then_some((0.0, span));
        }
        if let Some((a, b)) = &mut playback.loop_region {
            ui.add(
                egui::DragValue::new(a)
                    .range(0.0..=*b)
                    .speed(0.01)
                    .suffix(" s"),
            );
            ui.add(
                egui::DragValue::new(b)
                    .range(*a..=3600.0)
                    .speed(0.01)
                    .suffix(" s"),
            );
        }
        ui.monospace(format!("{now:6.2} s"));
        let width = ui.available_width() - 8.0;
        let (rect, response) =
            ui.allocate_exact_size(vec2(width.max(40.0), 18.0), Sense::click_and_drag());
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Slider, true, "Timeline"));
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 3.0, Color32::from_gray(40));
        let x_of = |t: f64| rect.left() + (t / span).clamp(0.0, 1.0) as f32 * rect.width();
        if let Some((a, b)) = playback.loop_region {
            painter.rect_filled(
                egui::Rect::from_x_y_ranges(x_of(a)..=x_of(b), rect.y_range()),
                3.0,
                Color32::from_rgb(45, 60, 80),
            );
        }
        for burst in state.running.emitters.iter().flat_map(|e| &e.bursts) {
            let x = x_of(f64::from(burst.time_secs));
            painter.line_segment(
                [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
                Stroke::new(2.0, Color32::from_rgb(240, 150, 60)),
            );
        }
        let x = x_of(now);
        painter.rect_filled(
            egui::Rect::from_min_max(rect.left_top(), egui::pos2(x, rect.bottom())),
            3.0,
            Color32::from_rgb(120, 70, 30),
        );
        painter.line_segment(
            [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
            Stroke::new(2.0, Color32::WHITE),
        );
        if let Some(p) = response.interact_pointer_pos()
            && (response.clicked() || response.dragged())
        {
            let t = f64::from((p.x - rect.left()) / rect.width()).clamp(0.0, 1.0) * span;
            // Whole steps (the editor's seeks land on steps).
            playback.seek_to = Some((t / step).round() * step);
        }
        response.on_hover_text(format!(
            "Seek: click or drag (0 – {span:.2} s: the last burst plus the longest lifetime)"
        ));
    });
}

/// The timeline's requests — restart, seek, step, speed, loop — then this frame's advance
/// of `player` (its `instance` is the one whose clock the loop region watches); `edited`:
/// the effect or a shader changed this frame (a parked view is re-simulated to its time).
pub fn play(
    player: &mut Player,
    instance: InstanceId,
    playback: &mut Playback,
    edited: bool,
    frame_dt_secs: f64,
) {
    if playback.restart_requested {
        playback.restart_requested = false;
        playback.parked_at = None;
        playback.frame_times.clear();
        player.restart();
    }
    if !playback.is_paused {
        playback.parked_at = None;
    }
    // The timeline's seek, or an edit while parked: replayed to that time.
    let seek_to = playback
        .seek_to
        .take()
        .or(playback.parked_at.filter(|_| edited));
    if let Some(t) = seek_to {
        playback.is_paused = true;
        playback.parked_at = Some(t);
        seek(player, playback, t);
    }
    if playback.step_requested {
        playback.step_requested = false;
        playback.is_paused = true;
        match playback.parked_at {
            // Parked after a seek: a seek one step later (an edit then keeps it).
            Some(t) => {
                let t = t + step_secs(player.effect());
                playback.parked_at = Some(t);
                seek(player, playback, t);
            }
            None => player.step(),
        }
    }
    player.set_paused(playback.is_paused);
    let dt = frame_dt_secs * f64::from(playback.speed.clamp(0.05, 8.0));
    player.advance(dt);
    if !playback.is_paused {
        if player.effect().time.mode == crate::effect::TimeMode::FrameDelta {
            playback.frame_times.push(dt);
        }
        // The loop region: back to its start once the clock passes its end.
        let now = player.time_secs(instance).unwrap_or_default();
        if let Some((a, _)) = playback.loop_region.filter(|(a, b)| b > a && now >= *b) {
            seek(player, playback, a);
        }
    }
}

/// Puts `player` at `t`: a fixed-step effect seeks (from the snapshot before it); a
/// frame-delta effect replays the frames played so far up to `t` (then 1/60 s frames),
/// the only way to reach the same state.
fn seek(player: &mut Player, playback: &mut Playback, t: f64) {
    let time = player.effect().time.clone();
    let speed = f64::from(time.speed).max(1e-6);
    if time.mode == crate::effect::TimeMode::FixedStep {
        // One frame per step: the seek lands on the step nearest `t`.
        let step = f64::from(time.step_secs);
        player.seek(t / speed, step / speed);
        playback.frame_times.clear();
        return;
    }
    let frames = frames_until(&playback.frame_times, t, &time);
    player.replay(&frames);
    playback.frame_times = frames;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_delta_seeks_replay_the_played_frames_then_sixtieths() {
        let mut time = crate::effect::TimeSettings {
            mode: TimeMode::FrameDelta,
            ..Default::default()
        };
        time.speed = 1.0;
        time.max_frame_dt_secs = 1.0;
        let played = [0.02, 0.015, 0.03, 0.01];
        assert_eq!(frames_until(&played, 0.035, &time), [0.02, 0.015]);
        assert_eq!(frames_until(&played, 0.0, &time), Vec::<f64>::new());
        let beyond = frames_until(&played, 0.075 + 2.0 / 60.0, &time);
        assert_eq!(&beyond[..4], &played);
        assert_eq!(beyond.len(), 6);
        // Simulated time: the speed scales each frame, the longest frame clamps it.
        time.speed = 2.0;
        assert_eq!(frames_until(&played, 0.07, &time), [0.02, 0.015]);
        time.speed = 1.0;
        time.max_frame_dt_secs = 0.012;
        assert_eq!(frames_until(&played, 0.036, &time), [0.02, 0.015, 0.03]);
    }

    #[test]
    fn the_span_is_the_last_burst_plus_the_longest_lifetime() {
        let mut effect = Effect::default_campfire();
        let longest = effect
            .emitters
            .iter()
            .map(|e| e.lifetime_secs.max)
            .fold(0.0, f32::max);
        assert!((span_secs(&effect) - f64::from(longest)).abs() < 1e-9);
        effect.emitters[0].bursts.push(crate::effect::Burst {
            time_secs: 3.0,
            count: 10,
        });
        assert!((span_secs(&effect) - (3.0 + f64::from(longest))).abs() < 1e-6);
    }
}
